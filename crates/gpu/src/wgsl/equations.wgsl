// The equations of the paper's model, each with the name of its Rust reference.

// ---- the equations ----

// phasefield::EnergyCoefficients::area_factor
fn area_factor(area: f32) -> f32 {
    return -kc.area * (1.0 - area * kc.inv_target_area);
}

// phasefield::EnergyCoefficients::free_energy_derivative
fn free_energy_derivative(phi: f32, lap: f32, af: f32, others_sq: f32) -> f32 {
    let ch = kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi) - kc.gradient * lap;
    return ch + af * phi + prm.repulsion * phi * others_sq;
}

// mechanics::equations::shape_tensor_density
fn shape_tensor_density(grad: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(0.5 * (grad.y * grad.y - grad.x * grad.x), -(grad.x * grad.y));
}

// mechanics::equations::pressure_cell_part
fn pressure_cell_part(phi: f32, lap: f32, af: f32) -> f32 {
    if (PAPER == 1u) {
        return -prm.repulsion * (phi * phi) * phi
            - kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi)
            + kc.gradient * lap - af * phi;
    }
    return -prm.repulsion * (phi * phi) * (phi * phi);
}

// mechanics::equations::pressure
fn pressure(s1: f32, s2: f32, u: f32) -> f32 {
    if (PAPER == 1u) {
        return prm.repulsion * s1 * s2 + u;
    }
    return prm.repulsion * s2 * s2 + u;
}

// The same pressure regrouped for f32: the repulsion's cross term from the sums,
// (2κ/λ)(s1 s2 − s3) (paper) or (2κ/λ)(s2² − s4) (interaction), which is exactly zero where one
// cell is alone, and `own = Σ_i pressure_own_part`. In f32 the form of `pressure`, whose two
// repulsion terms cancel where one cell is alone, is off by about 1e-6 of the largest P.
fn pressure_regrouped(s1: f32, s2: f32, s3: f32, s4: f32, own: f32) -> f32 {
    if (PAPER == 1u) {
        return prm.repulsion * (s1 * s2 - s3) + own;
    }
    return prm.repulsion * (s2 * s2 - s4) + own;
}

// `pressure_cell_part` less its repulsion term −(2κ/λ)φ³ (paper) or −(2κ/λ)φ⁴ (interaction).
fn pressure_own_part(phi: f32, lap: f32, af: f32) -> f32 {
    if (PAPER == 1u) {
        return -kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi)
            + kc.gradient * lap - af * phi;
    }
    return 0.0;
}

// mechanics::equations::pressure_self_part
fn pressure_self_part(phi: f32) -> f32 {
    if (PAPER == 1u) {
        return -(kc.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi));
    }
    return 0.0;
}

// mechanics::equations::force_density
fn force_density(p_cell: f32, zeta: f32, q: vec2<f32>, grad: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(
        p_cell * grad.x + zeta * (q.x * grad.x + q.y * grad.y),
        p_cell * grad.y + zeta * (q.y * grad.x - q.x * grad.y),
    );
}

// mechanics::equations::velocity
fn velocity(force: vec2<f32>, xi: f32) -> vec2<f32> {
    return force / xi;
}

// mechanics::equations::rhs
fn rhs(v: vec2<f32>, grad: vec2<f32>, dfdphi: f32) -> f32 {
    return -v.x * grad.x - v.y * grad.y - dfdphi;
}


// mechanics::equations::heun_predictor
fn heun_predictor(phi_old: f32, dt: f32, r_old: f32) -> f32 {
    return phi_old + dt * r_old;
}

// mechanics::equations::heun_corrector
fn heun_corrector(phi_old: f32, dt: f32, r_old: f32, r_new: f32) -> f32 {
    return phi_old + 0.5 * dt * (r_old + r_new);
}

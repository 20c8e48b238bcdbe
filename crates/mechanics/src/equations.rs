//! The equations of docs/model.md §3–4, one named function each, at one lattice node.
//!
//! The kernels ([`crate::Tissue::step`], [`crate::TissueFields`]) are built from these
//! functions and nothing else, so that each formula exists once. All are
//! `#[inline(always)]`: they are called inside the SIMD loops of the kernels, where a call
//! would stop the vectorisation.
//!
//! Notation: `φ = φ_i(x)` is cell i's field at node x, `∂φ = (∂_x φ, ∂_y φ)` its central
//! differences, `∇²φ` its five-point Laplacian, all on the cell's periodic patch;
//! `s_n = Σ_k φ_k^n` are sums over all cells at the node.
//! The free-energy derivative `δF/δφ_i` is
//! [`phasefield::EnergyCoefficients::free_energy_derivative`].

use phasefield::EnergyCoefficients;

use crate::params::PressureKind;

/// The integrand of the deformation tensor (docs/model.md §3):
///
/// ```text
/// S_i = −Σ_x [ ∇φ_i ∇φ_iᵀ − ½ |∇φ_i|² 𝕀 ],   so   S_xx = Σ_x ½(∂_yφ² − ∂_xφ²),  S_xy = −Σ_x ∂_xφ ∂_yφ
/// ```
///
/// returned as `[S_xx, S_xy]` (`S_yy = −S_xx`). An elongated cell has its positive
/// eigenvector along its long axis.
#[inline(always)]
pub fn shape_tensor_density(grad: [f64; 2]) -> [f64; 2] {
    let [dx, dy] = grad;
    [0.5 * (dy * dy - dx * dx), -(dx * dy)]
}

/// Cell i's contribution `φ_i S_i` to the nematic field `Q(x) = Σ_i φ_i(x) S_i`
/// (docs/model.md §3), as `[Q_xx, Q_xy]`.
#[inline(always)]
pub fn nematic_density(phi: f64, shape: [f64; 2]) -> [f64; 2] {
    [phi * shape[0], phi * shape[1]]
}

/// The part `U_i` of the pressure that depends on cell i's field alone; the scatter sums it
/// over cells into `U = Σ_i U_i`, and [`pressure`] adds the cross term.
///
/// Paper: `U_i = −(2κ/λ) φ³ − (8γ/λ) φ(1−φ)(1−2φ) + 2γλ ∇²φ − a_i φ`, with
/// `a_i` the cell's [`EnergyCoefficients::area_factor`]; summed over cells, together with
/// `(2κ/λ) s1 s2`, it is
/// `P = (2κ/λ)(s1 s2 − s3) − (8γ/λ)(s1 − 3 s2 + 2 s3) + 2γλ Σ_i ∇²φ_i + (4μ/πR²)(s1 − sA/πR²)`.
/// The Laplacians are taken on each cell's patch: on the full domain this is `2γλ ∇² s1`,
/// and on patches it is the form whose self term `Σ_x ∇²φ_i ∂φ_i` vanishes exactly, so that an
/// isolated cell feels no force.
///
/// Interaction: `U_i = −(2κ/λ) φ⁴`, so that `P = (2κ/λ)(s2² − s4)`.
#[inline(always)]
pub fn pressure_cell_part(
    kind: PressureKind,
    coef: &EnergyCoefficients,
    phi: f64,
    laplacian: f64,
    area_factor: f64,
) -> f64 {
    match kind {
        PressureKind::Paper => {
            -coef.repulsion * (phi * phi) * phi
                - coef.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi)
                + coef.gradient * laplacian
                - area_factor * phi
        }
        PressureKind::Interaction => -coef.repulsion * (phi * phi) * (phi * phi),
    }
}

/// The tissue pressure `P` at a node from its sums `s1 = Σ φ_i`, `s2 = Σ φ_i²` and
/// `U = Σ_i U_i` ([`pressure_cell_part`]) (docs/model.md §3):
/// `P = (2κ/λ) s1 s2 + U` (paper) or `P = (2κ/λ) s2² + U` (interaction).
///
/// This is the one formula of the pressure: the force kernel, [`crate::TissueFields`] and
/// the docs all use it.
#[inline(always)]
pub fn pressure(kind: PressureKind, coef: &EnergyCoefficients, s1: f64, s2: f64, u: f64) -> f64 {
    match kind {
        PressureKind::Paper => coef.repulsion * s1 * s2 + u,
        PressureKind::Interaction => coef.repulsion * s2 * s2 + u,
    }
}

/// The part of `P` that cell i's own double-well term puts there, `−(8γ/λ) φ(1−φ)(1−2φ)` in
/// the paper form (zero in the interaction form), which the force on cell i leaves out.
///
/// Its contribution to `F_i` is the integral of a gradient, zero in the continuum, but its
/// central-difference sum is not zero on the lattice and would propel an isolated cell
/// (|v| ~ 2e-7 off the lattice's symmetry points). The other self terms (`∇²φ_i ∂φ_i` with
/// the patch Laplacian, and `φ_i ∂φ_i`) already sum to zero exactly on a periodic patch.
#[inline(always)]
pub fn pressure_self_part(kind: PressureKind, coef: &EnergyCoefficients, phi: f64) -> f64 {
    pressure_self_part_with(pressure_self_coefficient(kind, coef), phi)
}

/// The coefficient `c` of [`pressure_self_part`] `= −c φ(1−φ)(1−2φ)`: `8γ/λ` (paper) or 0
/// (interaction).
#[inline(always)]
pub fn pressure_self_coefficient(kind: PressureKind, coef: &EnergyCoefficients) -> f64 {
    match kind {
        PressureKind::Paper => coef.double_well,
        PressureKind::Interaction => 0.0,
    }
}

/// [`pressure_self_part`] from its coefficient ([`pressure_self_coefficient`]), for loops that
/// compute the coefficient once.
#[inline(always)]
pub fn pressure_self_part_with(c_self: f64, phi: f64) -> f64 {
    -(c_self * phi * (1.0 - phi) * (1.0 - 2.0 * phi))
}

/// The integrand of the interface force on cell i (docs/model.md §3), the divergence of the
/// stress `σ = −P𝕀 − ζQ` against `φ_i`, integrated by parts:
///
/// ```text
/// F_i = Σ_x [ (P − P_i^self) ∂φ_i + ζ Q·∂φ_i ],   Q·∂φ = (Q_xx ∂_xφ + Q_xy ∂_yφ, Q_xy ∂_xφ − Q_xx ∂_yφ)
/// ```
///
/// with `p_cell = P − P_i^self` ([`pressure_self_part`]) and `q = [Q_xx, Q_xy]`.
#[inline(always)]
pub fn force_density(p_cell: f64, zeta: f64, q: [f64; 2], grad: [f64; 2]) -> [f64; 2] {
    let [qxx, qxy] = q;
    let [dx, dy] = grad;
    [
        p_cell * dx + zeta * (qxx * dx + qxy * dy),
        p_cell * dy + zeta * (qxy * dx - qxx * dy),
    ]
}

/// The velocity of a cell from the force on it, overdamped on the substrate:
/// `ξ v_i = F_i` (docs/model.md §3).
#[inline(always)]
pub fn velocity(force: [f64; 2], xi: f64) -> [f64; 2] {
    [force[0] / xi, force[1] / xi]
}

/// The right-hand side of the dynamics at a node (docs/model.md §4):
/// `R_i = ∂_t φ_i = −v_i·∂φ_i − δF/δφ_i`, advection by the cell's velocity plus the
/// relaxation of the free energy.
///
/// Written `−v_x ∂_xφ − v_y ∂_yφ − δF/δφ`, which rounds exactly as `−(v·∂φ) − δF/δφ` (negation
/// is exact): in that form LLVM's SLP vectoriser paired `v_x ∂_xφ` with `v_y ∂_yφ` across the
/// lanes of a chunk, with 8 blends and spills, 99 instructions per chunk of 8 nodes against 86
/// in this one (x86-64-v3).
#[inline(always)]
pub fn rhs(velocity: [f64; 2], grad: [f64; 2], dfdphi: f64) -> f64 {
    -velocity[0] * grad[0] - velocity[1] * grad[1] - dfdphi
}

/// The adhesion coefficient `c = 2ωλ` of the cell–cell adhesion energy
/// `F_adh = ωλ Σ_{i≠j} Σ_x ∇φ_i·∇φ_j` (docs/model.md §11.2).
#[inline(always)]
pub fn adhesion_coefficient(omega: f64, lambda: f64) -> f64 {
    2.0 * omega * lambda
}

/// The adhesion part of `δF/δφ_i` at a node: `−c (∇²s1 − ∇²φ_i) = −c Σ_{j≠i} ∇²φ_j`, with
/// `c` = [`adhesion_coefficient`], `lap_s1` the lattice Laplacian of `s1 = Σ φ_j` and
/// `lap_self` the Laplacian of `φ_i` on its patch.
#[inline(always)]
pub fn adhesion_derivative(c: f64, lap_s1: f64, lap_self: f64) -> f64 {
    -c * (lap_s1 - lap_self)
}

/// Cell i's single-cell part of the adhesion pressure, `+c φ_i ∇²φ_i`, which the scatter adds
/// to `U`; with [`adhesion_pressure`] the adhesion adds the φ-weighted sum of its derivative,
/// `Σ_i φ_i δF_adh/δφ_i = −c (s1 ∇²s1 − Σ_i φ_i ∇²φ_i)`, to the pressure in both forms (the
/// paper form's unweighted sum would be `−c (N − 1) ∇²s1`, which does not vanish away from
/// the contacts; docs/model.md §11.2).
#[inline(always)]
pub fn adhesion_pressure_cell_part(c: f64, phi: f64, laplacian: f64) -> f64 {
    c * phi * laplacian
}

/// The cross part of the adhesion pressure, `−c s1 ∇²s1` (see
/// [`adhesion_pressure_cell_part`]).
#[inline(always)]
pub fn adhesion_pressure(c: f64, s1: f64, lap_s1: f64) -> f64 {
    -c * s1 * lap_s1
}

/// The wall coefficients `[2κ_w/λ, 2ω_wλ]` of the wall energy
/// `F_wall = Σ_i Σ_x [(κ_w/λ) φ_i² w² + 2ω_wλ ∇φ_i·∇w]` (docs/model.md §11.4), with `w` the
/// static wall field (`phasefield::WallField`).
#[inline(always)]
pub fn wall_coefficients(kappa_w: f64, omega_w: f64, lambda: f64) -> [f64; 2] {
    [2.0 * kappa_w / lambda, 2.0 * omega_w * lambda]
}

/// The wall part of `δF/δφ_i` at a node: `(2κ_w/λ) φ_i w² − 2ω_wλ ∇²w`, with `c` =
/// [`wall_coefficients`] and `lap_w` the lattice Laplacian of `w`.
#[inline(always)]
pub fn wall_derivative(c: [f64; 2], phi: f64, w: f64, lap_w: f64) -> f64 {
    c[0] * phi * (w * w) - c[1] * lap_w
}

/// The wall part of the pressure, the φ-weighted sum of [`wall_derivative`] over the cells,
/// `Σ_i φ_i δF_wall/δφ_i = (2κ_w/λ) w² s2 − 2ω_wλ ∇²w s1`, in both pressure forms (the
/// reference code's: wall terms are interaction terms; the paper form's unweighted sum would
/// put `−2ω_wλ N ∇²w` wherever the wall field curves, cells there or not).
#[inline(always)]
pub fn wall_pressure(c: [f64; 2], s1: f64, s2: f64, w: f64, lap_w: f64) -> f64 {
    c[0] * (w * w) * s2 - c[1] * lap_w * s1
}

/// The Heun predictor (a forward-Euler step): `φ* = φⁿ + Δt R(φⁿ)` (docs/model.md §4).
#[inline(always)]
pub fn heun_predictor(phi_old: f64, dt: f64, r_old: f64) -> f64 {
    phi_old + dt * r_old
}

/// The Heun corrector (the trapezoidal rule on the predicted state):
/// `φⁿ⁺¹ = φⁿ + ½Δt [R(φⁿ) + R(φ*)]` (docs/model.md §4). Applied `npc` times, each on the latest
/// state; with `npc = 0` the step is forward Euler.
#[inline(always)]
pub fn heun_corrector(phi_old: f64, dt: f64, r_old: f64, r_new: f64) -> f64 {
    phi_old + 0.5 * dt * (r_old + r_new)
}

#[cfg(test)]
mod tests {
    use super::*;
    use phasefield::EnergyParams;

    /// The paper pressure of one cell alone at a node is its own part plus the cross term of
    /// `φ` with itself, `(2κ/λ) φ³`; so `P − P_self` there is the rest of `U_i`, exactly.
    #[test]
    fn the_pressure_of_one_cell_is_its_own_terms() {
        let coef = EnergyParams::paper().coefficients();
        for &phi in &[0.0, 0.3, 0.5, 0.9, 1.0] {
            let (lap, a) = (0.07, -0.01);
            let u = pressure_cell_part(PressureKind::Paper, &coef, phi, lap, a);
            let p = pressure(PressureKind::Paper, &coef, phi, phi * phi, u);
            let expected = coef.gradient * lap
                - a * phi
                - coef.double_well * phi * (1.0 - phi) * (1.0 - 2.0 * phi);
            assert!((p - expected).abs() <= 1e-15, "{p} {expected}");
            let u = pressure_cell_part(PressureKind::Interaction, &coef, phi, lap, a);
            let p = pressure(PressureKind::Interaction, &coef, phi, phi * phi, u);
            assert!(
                p.abs() <= 1e-16,
                "one cell has no interaction pressure: {p}"
            );
        }
    }

    /// The identity the force kernel relies on to evaluate both forms without a branch: the
    /// interaction pressure is the paper formula with `s2` in the place of `s1`, and its self
    /// part is zero. Exact, bit for bit.
    #[test]
    fn the_interaction_form_is_the_paper_form_with_s2_for_s1() {
        let coef = EnergyParams::paper().coefficients();
        for &(s1, s2, u, phi) in &[
            (1.2, 0.9, -0.3, 0.4),
            (0.1, 0.01, 0.002, 0.97),
            (2.0, 1.5, 0.7, 0.0),
        ] {
            let i = pressure(PressureKind::Interaction, &coef, s1, s2, u);
            assert_eq!(i, pressure(PressureKind::Paper, &coef, s2, s2, u));
            let self_i = pressure_self_part(PressureKind::Interaction, &coef, phi);
            assert_eq!(
                self_i,
                0.0 * pressure_self_part(PressureKind::Paper, &coef, phi)
            );
        }
    }

    /// The force density is rotation-covariant: rotating ∂φ by θ and Q by 2θ rotates the
    /// density by θ, to round-off.
    #[test]
    fn the_force_density_rotates_with_the_fields() {
        let (p, zeta, q, g) = (0.3, 0.01, [0.2, -0.7], [0.4, 1.1]);
        let f = force_density(p, zeta, q, g);
        for &theta in &[0.3f64, 1.0, 2.5] {
            let (c, s) = (theta.cos(), theta.sin());
            let (c2, s2) = ((2.0 * theta).cos(), (2.0 * theta).sin());
            let gr = [c * g[0] - s * g[1], s * g[0] + c * g[1]];
            let qr = [c2 * q[0] - s2 * q[1], s2 * q[0] + c2 * q[1]];
            let fr = force_density(p, zeta, qr, gr);
            let expected = [c * f[0] - s * f[1], s * f[0] + c * f[1]];
            assert!((fr[0] - expected[0]).abs() < 1e-15 && (fr[1] - expected[1]).abs() < 1e-15);
        }
    }
}

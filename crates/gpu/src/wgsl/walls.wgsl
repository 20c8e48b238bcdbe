// Walls (docs/model.md, walls): the lattice pass adds their pressure and the force pass their
// derivative, from the static wall field (w, ∇²w per node, `wall`), with the coefficients
// `Params::wall_repulsion` and `wall_adhesion`.
override WALLS: u32 = 0u;

// mechanics::equations::wall_derivative, with the coefficients of `prm`
fn wall_derivative(phi: f32, w: f32, lap_w: f32) -> f32 {
    return prm.wall_repulsion * phi * (w * w) - prm.wall_adhesion * lap_w;
}

// mechanics::equations::wall_pressure, with the coefficients of `prm`
fn wall_pressure(s1: f32, s2: f32, w: f32, lap_w: f32) -> f32 {
    return prm.wall_repulsion * (w * w) * s2 - prm.wall_adhesion * lap_w * s1;
}

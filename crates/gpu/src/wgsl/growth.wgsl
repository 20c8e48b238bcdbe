// The division clock's growth phase: per slot, the time its target area starts to grow, less
// the growth's origin (`Params::growth_now`, `growth`).
override GROWTH: u32 = 0u;

// The factor 1 + clamp((t − t_g0)/T_g, 0, 1) of a growing cell's target area (mechanics::division)
// at the time t of the step's start, as the host's `target_scale`.
fn growth_factor(c: u32) -> f32 {
    let now = prm.growth_now + f32(atomicLoad(&status.steps)) * prm.dt;
    return 1.0 + clamp((now - growth[c / CELL_STRIDE]) / prm.growth_time, 0.0, 1.0);
}

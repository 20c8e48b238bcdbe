//! Derived lattice fields and scalar observables (docs/model.md §7).

use phasefield::Lattice;

/// Vorticity `ω = ∂x v_y − ∂y v_x` with central differences on the periodic lattice.
///
/// # Panics
/// If a slice is not `lattice.len()` long.
pub fn vorticity(lattice: Lattice, vx: &[f64], vy: &[f64]) -> Vec<f64> {
    let (lx, ly) = (lattice.lx, lattice.ly);
    assert!(vx.len() == lattice.len() && vy.len() == lattice.len());
    let mut w = vec![0.0; lattice.len()];
    for x in 0..lx {
        let (xm, xp) = ((x + lx - 1) % lx, (x + 1) % lx);
        for y in 0..ly {
            let (ym, yp) = ((y + ly - 1) % ly, (y + 1) % ly);
            w[x * ly + y] = 0.5 * (vy[xp * ly + y] - vy[xm * ly + y])
                - 0.5 * (vx[x * ly + yp] - vx[x * ly + ym]);
        }
    }
    w
}

/// `sqrt(⟨Σ_c f_c²⟩)` over the lattice of a field with components `f_c`.
pub fn rms(components: &[&[f64]]) -> f64 {
    let n = components.first().map_or(0, |c| c.len()).max(1) as f64;
    (components
        .iter()
        .flat_map(|c| c.iter())
        .map(|v| v * v)
        .sum::<f64>()
        / n)
        .sqrt()
}

/// `S_rms = sqrt(mean_i (S_xx² + S_xy²))` over cells, from `[S_xx, S_xy]` per cell.
pub fn s_rms(shape_tensors: &[[f64; 2]]) -> f64 {
    let n = shape_tensors.len().max(1) as f64;
    (shape_tensors
        .iter()
        .map(|s| s[0] * s[0] + s[1] * s[1])
        .sum::<f64>()
        / n)
        .sqrt()
}

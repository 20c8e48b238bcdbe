//! Topological defects of a nematic field `Q` on the periodic lattice (docs/model.md §7).
//!
//! **Axes.** x is the first lattice index, y the second, and the frame is right-handed:
//! angles are measured counterclockwise from +x towards +y. Image data with y pointing down
//! is left-handed in these terms and flips the sign of every charge and angle.
//!
//! **Charge.** The director angle is `θ = ½ atan2(Q_xy, Q_xx)`. Around each plaquette
//! `(x, y) → (x+1, y) → (x+1, y+1) → (x, y+1) → (x, y)` the differences of `θ` are wrapped
//! into `[−π/2, π/2)` and summed; the sum over `2π` is the charge, a multiple of ½. A defect
//! sits at the plaquette centre `(x + ½, y + ½)`.
//!
//! **Orientation** (Vromans & Giomi, Soft Matter 12, 6490, 2016), for `k = ±½`:
//! `ψ = k/(1−k) · atan2(⟨sgn(k) ∂x Q_xy − ∂y Q_xx⟩, ⟨∂x Q_xx + sgn(k) ∂y Q_xy⟩)`,
//! with central differences averaged over the four nodes of the plaquette. For `+½`, `ψ` is
//! the direction of `∇·Q` (the comet's head to tail axis, in `(−π, π]`); for `−½` it is the
//! direction of one of the three arms, defined modulo `2π/3` and returned in `[−π/3, π/3]`.

use phasefield::Lattice;
use std::f64::consts::PI;

/// A defect found in a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Defect {
    /// Position along x (plaquette centre).
    pub x: f64,
    /// Position along y.
    pub y: f64,
    /// Topological charge, a multiple of ½ (±½ in practice; others are reported too).
    pub charge: f64,
    /// Orientation `ψ` for charges ±½ (see the module docs); NaN for other charges.
    pub angle: f64,
}

#[inline]
fn wrap_half_pi(d: f64) -> f64 {
    // into [−π/2, π/2)
    d - PI * ((d + 0.5 * PI) / PI).floor()
}

/// All defects of `Q = (Q_xx, Q_xy)` (lattice-sized, index `x * ly + y`), in plaquette order
/// (x slow, y fast).
///
/// # Panics
/// If a slice is not `lattice.len()` long.
pub fn detect(lattice: Lattice, qxx: &[f64], qxy: &[f64]) -> Vec<Defect> {
    let (lx, ly) = (lattice.lx, lattice.ly);
    assert!(qxx.len() == lattice.len() && qxy.len() == lattice.len());
    let theta: Vec<f64> = qxx
        .iter()
        .zip(qxy)
        .map(|(a, b)| 0.5 * b.atan2(*a))
        .collect();
    let mut out = Vec::new();
    for x in 0..lx {
        let xp = (x + 1) % lx;
        for y in 0..ly {
            let yp = (y + 1) % ly;
            let corners = [
                lattice.index(x, y),
                lattice.index(xp, y),
                lattice.index(xp, yp),
                lattice.index(x, yp),
            ];
            let mut w = 0.0;
            for e in 0..4 {
                w += wrap_half_pi(theta[corners[(e + 1) % 4]] - theta[corners[e]]);
            }
            let charge = (w / PI).round() * 0.5;
            if charge != 0.0 {
                let angle = if charge.abs() == 0.5 {
                    orientation(lattice, qxx, qxy, &corners, charge)
                } else {
                    f64::NAN
                };
                out.push(Defect {
                    x: (x as f64 + 0.5) % lx as f64,
                    y: (y as f64 + 0.5) % ly as f64,
                    charge,
                    angle,
                });
            }
        }
    }
    out
}

fn orientation(lattice: Lattice, qxx: &[f64], qxy: &[f64], corners: &[usize; 4], k: f64) -> f64 {
    let (lx, ly) = (lattice.lx, lattice.ly);
    let sgn = k.signum();
    let (mut num, mut den) = (0.0, 0.0);
    for &n in corners {
        let (x, y) = (n / ly, n % ly);
        let xp = lattice.index((x + 1) % lx, y);
        let xm = lattice.index((x + lx - 1) % lx, y);
        let yp = lattice.index(x, (y + 1) % ly);
        let ym = lattice.index(x, (y + ly - 1) % ly);
        let dx_qxx = 0.5 * (qxx[xp] - qxx[xm]);
        let dy_qxx = 0.5 * (qxx[yp] - qxx[ym]);
        let dx_qxy = 0.5 * (qxy[xp] - qxy[xm]);
        let dy_qxy = 0.5 * (qxy[yp] - qxy[ym]);
        num += sgn * dx_qxy - dy_qxx;
        den += dx_qxx + sgn * dy_qxy;
    }
    k / (1.0 - k) * num.atan2(den)
}

/// Sum of the charges (zero on a periodic lattice, by construction of the winding).
pub fn net_charge(defects: &[Defect]) -> f64 {
    defects.iter().map(|d| d.charge).sum()
}

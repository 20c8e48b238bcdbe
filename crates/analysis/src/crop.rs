//! Fields averaged in the frame of each defect (docs/model.md §7; the paper's figure 4).
//!
//! Around a defect at `p` with orientation `ψ`, the crop samples every field at
//! `p + R(ψ)·(u, v)` for `u, v = −h, ..., h` (side `2h + 1`), by bilinear interpolation on
//! the periodic lattice, and rotates the components into the defect's frame: vectors by
//! `R(−ψ)`, symmetric tensors by `R(−ψ) T R(ψ)`. In the defect frame a `+½` defect's axis
//! (`∇·Q`) is `+u`, and one `−½` arm is `+u`. Crops are summed per charge and divided by the
//! number of defects.

use phasefield::Lattice;
use rayon::prelude::*;

use crate::defects::Defect;

/// The fields to crop, each lattice-sized with index `x * ly + y`.
#[derive(Debug, Clone, Copy)]
pub struct CropFields<'a> {
    /// Velocity x.
    pub vx: &'a [f64],
    /// Velocity y.
    pub vy: &'a [f64],
    /// Stress xx.
    pub sigma_xx: &'a [f64],
    /// Stress yy.
    pub sigma_yy: &'a [f64],
    /// Stress xy.
    pub sigma_xy: &'a [f64],
    /// Pressure.
    pub pressure: &'a [f64],
    /// Q xx.
    pub qxx: &'a [f64],
    /// Q xy (`Q_yy = −Q_xx`).
    pub qxy: &'a [f64],
}

/// Names of the averaged components, in storage order.
pub const COMPONENTS: [&str; 8] = [
    "vx", "vy", "sigma_xx", "sigma_yy", "sigma_xy", "pressure", "qxx", "qxy",
];

/// Running sums of cropped fields for `+½` and `−½` defects.
#[derive(Debug, Clone)]
pub struct DefectAverage {
    side: usize,
    plus: Vec<f64>,
    minus: Vec<f64>,
    /// `+½` defects added.
    pub n_plus: usize,
    /// `−½` defects added.
    pub n_minus: usize,
}

fn bilinear(lattice: Lattice, f: &[f64], x: f64, y: f64) -> f64 {
    let (lx, ly) = (lattice.lx, lattice.ly);
    let (fx, fy) = (x.floor(), y.floor());
    let (tx, ty) = (x - fx, y - fy);
    let x0 = lattice.wrap_x(fx as i64);
    let y0 = lattice.wrap_y(fy as i64);
    let (x1, y1) = ((x0 + 1) % lx, (y0 + 1) % ly);
    let g = |a: usize, b: usize| f[a * ly + b];
    (1.0 - tx) * ((1.0 - ty) * g(x0, y0) + ty * g(x0, y1))
        + tx * ((1.0 - ty) * g(x1, y0) + ty * g(x1, y1))
}

impl DefectAverage {
    /// Empty sums for crops of odd side `side`.
    ///
    /// # Panics
    /// If `side` is even.
    pub fn new(side: usize) -> Self {
        assert!(side % 2 == 1, "the crop side must be odd");
        let n = side * side * COMPONENTS.len();
        Self {
            side,
            plus: vec![0.0; n],
            minus: vec![0.0; n],
            n_plus: 0,
            n_minus: 0,
        }
    }

    /// Side of the crops.
    pub fn side(&self) -> usize {
        self.side
    }

    /// Adds the crops around every `±½` defect of a frame (others are skipped).
    pub fn add(&mut self, lattice: Lattice, fields: &CropFields<'_>, defects: &[Defect]) {
        let h = (self.side / 2) as f64;
        let side = self.side;
        for d in defects {
            let sums = if d.charge == 0.5 {
                self.n_plus += 1;
                &mut self.plus
            } else if d.charge == -0.5 {
                self.n_minus += 1;
                &mut self.minus
            } else {
                continue;
            };
            let (s, c) = d.angle.sin_cos();
            // Rows of the crop are disjoint slices of the sums: parallel and deterministic.
            sums.par_chunks_mut(side * COMPONENTS.len())
                .enumerate()
                .for_each(|(iu, row)| {
                    let u = iu as f64 - h;
                    for iv in 0..side {
                        let v = iv as f64 - h;
                        let x = d.x + c * u - s * v;
                        let y = d.y + s * u + c * v;
                        let at = |f: &[f64]| bilinear(lattice, f, x, y);
                        let (vx, vy) = (at(fields.vx), at(fields.vy));
                        let (sxx, syy, sxy) = (
                            at(fields.sigma_xx),
                            at(fields.sigma_yy),
                            at(fields.sigma_xy),
                        );
                        let (qxx, qxy) = (at(fields.qxx), at(fields.qxy));
                        let rot = |txx: f64, tyy: f64, txy: f64| {
                            (
                                c * c * txx + 2.0 * c * s * txy + s * s * tyy,
                                s * s * txx - 2.0 * c * s * txy + c * c * tyy,
                                -c * s * txx + (c * c - s * s) * txy + c * s * tyy,
                            )
                        };
                        let (rsxx, rsyy, rsxy) = rot(sxx, syy, sxy);
                        let (rqxx, _, rqxy) = rot(qxx, -qxx, qxy);
                        let vals = [
                            c * vx + s * vy,
                            -s * vx + c * vy,
                            rsxx,
                            rsyy,
                            rsxy,
                            at(fields.pressure),
                            rqxx,
                            rqxy,
                        ];
                        let base = iv * COMPONENTS.len();
                        for (k, val) in vals.iter().enumerate() {
                            row[base + k] += val;
                        }
                    }
                });
        }
    }

    /// The average crop of component `name` (one of [`COMPONENTS`]) for charge `+½`
    /// (`plus = true`) or `−½`, as a `side × side` array indexed `[u * side + v]`.
    /// All NaN when no defect of that charge was added.
    ///
    /// # Panics
    /// If `name` is not a component.
    pub fn average(&self, plus: bool, name: &str) -> Vec<f64> {
        let k = COMPONENTS
            .iter()
            .position(|c| *c == name)
            .expect("a known component");
        let (sums, n) = if plus {
            (&self.plus, self.n_plus)
        } else {
            (&self.minus, self.n_minus)
        };
        let inv = 1.0 / n as f64;
        (0..self.side * self.side)
            .map(|i| sums[i * COMPONENTS.len() + k] * inv)
            .collect()
    }
}

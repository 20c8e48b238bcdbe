//! Centre of mass on a periodic lattice by Fourier phase (docs/model.md §5):
//! `c_s = L_s/(2π) · arg( Σ_x φ(x) e^{2πi s/L_s} )`, taken in `[0, L_s)`.
//!
//! For a field that is mirror-symmetric about a node or a half-node this is exact to
//! round-off, wherever the field sits on the torus.

use crate::lattice::Lattice;
use crate::PatchShape;

/// Precomputed `cos` and `sin` of `2π s / L_s` for every lattice coordinate.
#[derive(Debug, Clone)]
pub struct ComTable {
    lattice: Lattice,
    cos_x: Vec<f64>,
    sin_x: Vec<f64>,
    cos_y: Vec<f64>,
    sin_y: Vec<f64>,
}

impl ComTable {
    /// Bytes of heap memory held by the table.
    pub fn heap_bytes(&self) -> usize {
        (self.cos_x.capacity()
            + self.sin_x.capacity()
            + self.cos_y.capacity()
            + self.sin_y.capacity())
            * std::mem::size_of::<f64>()
    }

    /// Tables for `lattice`.
    pub fn new(lattice: Lattice) -> Self {
        let tab = |l: usize| -> (Vec<f64>, Vec<f64>) {
            (0..l)
                .map(|s| {
                    let t = 2.0 * std::f64::consts::PI * s as f64 / l as f64;
                    (t.cos(), t.sin())
                })
                .unzip()
        };
        let (cos_x, sin_x) = tab(lattice.lx);
        let (cos_y, sin_y) = tab(lattice.ly);
        Self {
            lattice,
            cos_x,
            sin_x,
            cos_y,
            sin_y,
        }
    }

    /// The centre of mass of cell `cell_idx` of `cells`.
    pub fn cell_centre<T: crate::Real>(
        &self,
        cells: &crate::Cells<T>,
        cell_idx: usize,
    ) -> [f64; 2] {
        let shape = cells.shape();
        self.centre_of_mass(
            cells.cell_phi(cell_idx),
            shape,
            cells.map().cell_x(shape, cell_idx),
            cells.map().cell_y(shape, cell_idx),
        )
    }

    /// The centre of mass of one cell's patch, given its values in storage order and the
    /// lattice coordinates of its storage columns and rows.
    pub fn centre_of_mass<T: crate::Real>(
        &self,
        phi: &[T],
        shape: &PatchShape,
        xs: &[u32],
        ys: &[u32],
    ) -> [f64; 2] {
        // In blocks of rows, so that the sums are element-wise loops over a column (which
        // compile to SIMD instructions) into row-indexed partial sums:
        // rows[j] = Σ_a φ(a, b), xr[j] = Σ_a φ(a, b) cos(2π x_a/L_x), and likewise xi.
        const BLOCK: usize = 64;
        let ny = shape.ny;
        let (mut xr, mut xi, mut yr, mut yi) = (0.0, 0.0, 0.0, 0.0);
        for b0 in (0..ny).step_by(BLOCK) {
            let n = BLOCK.min(ny - b0);
            let (mut rows, mut rx, mut ix) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
            let (rows, rx, ix) = (&mut rows[..n], &mut rx[..n], &mut ix[..n]);
            for (a, &x) in xs.iter().enumerate() {
                let col = &phi[a * ny + b0..a * ny + b0 + n];
                let (c, s) = (self.cos_x[x as usize], self.sin_x[x as usize]);
                for j in 0..n {
                    let p = col[j].to_f64();
                    rows[j] += p;
                    rx[j] += p * c;
                    ix[j] += p * s;
                }
            }
            for (j, &y) in ys[b0..b0 + n].iter().enumerate() {
                yr += rows[j] * self.cos_y[y as usize];
                yi += rows[j] * self.sin_y[y as usize];
                xr += rx[j];
                xi += ix[j];
            }
        }
        [
            phase_to_coordinate(xi.atan2(xr), self.lattice.lx),
            phase_to_coordinate(yi.atan2(yr), self.lattice.ly),
        ]
    }
}

fn phase_to_coordinate(theta: f64, l: usize) -> f64 {
    crate::lattice::wrap_real(theta / (2.0 * std::f64::consts::PI) * l as f64, l as f64)
}

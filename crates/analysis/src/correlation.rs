//! Normalised autocorrelation functions on the periodic lattice (docs/model.md §7), by FFT.
//!
//! For a field with components `f_c`, the correlation at displacement `d` is
//! `A(d) = (1/N) Σ_x Σ_c f_c(x) f_c(x + d)`, computed by Wiener–Khinchin as
//! `A = IFFT(Σ_c |FFT f_c|²) / N²` with rustfft's unnormalised transforms (forward
//! `F_k = Σ_x f(x) e^{−2πi k·x/L}`, inverse without `1/N`). The correlation function is
//! `C(d) = Ā(d) / Ā(0)`, where `Ā` averages `A` over frames (a ratio of averages, so frames
//! with stronger fields weigh more), and `C(r)` averages `C(d)` over the displacements with
//! `round(|d|) = r` (minimum image), for `r = 0, 1, ..., min(lx, ly)/2`.

use std::sync::Arc;

use phasefield::{min_image, Lattice};
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};

/// Accumulates autocorrelations of one field over frames.
pub struct Correlator {
    lattice: Lattice,
    fft_x: Arc<dyn Fft<f64>>,
    fft_y: Arc<dyn Fft<f64>>,
    ifft_x: Arc<dyn Fft<f64>>,
    ifft_y: Arc<dyn Fft<f64>>,
    buf: Vec<Complex64>,
    tbuf: Vec<Complex64>,
    power: Vec<f64>,
    scratch: Vec<Complex64>,
    sum: Vec<f64>,
    n_frames: usize,
}

impl std::fmt::Debug for Correlator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Correlator")
            .field("lattice", &self.lattice)
            .field("n_frames", &self.n_frames)
            .finish()
    }
}

impl Correlator {
    /// Plans the transforms for `lattice`.
    pub fn new(lattice: Lattice) -> Self {
        let mut planner = FftPlanner::new();
        let fft_x = planner.plan_fft_forward(lattice.lx);
        let fft_y = planner.plan_fft_forward(lattice.ly);
        let ifft_x = planner.plan_fft_inverse(lattice.lx);
        let ifft_y = planner.plan_fft_inverse(lattice.ly);
        let scratch_len = [&fft_x, &fft_y, &ifft_x, &ifft_y]
            .iter()
            .map(|f| f.get_inplace_scratch_len())
            .max()
            .unwrap_or(0);
        let n = lattice.len();
        Self {
            lattice,
            fft_x,
            fft_y,
            ifft_x,
            ifft_y,
            buf: vec![Complex64::default(); n],
            tbuf: vec![Complex64::default(); n],
            power: vec![0.0; n],
            scratch: vec![Complex64::default(); scratch_len],
            sum: vec![0.0; n],
            n_frames: 0,
        }
    }

    /// Adds one frame of a field given by its components (e.g. `[vx, vy]`, `[ω]`,
    /// `[Qxx, Qxy]`), each `lattice.len()` long, index `x * ly + y`.
    ///
    /// # Panics
    /// If a component has the wrong length.
    pub fn add(&mut self, components: &[&[f64]]) {
        let (lx, ly) = (self.lattice.lx, self.lattice.ly);
        let n = self.lattice.len();
        self.power.iter_mut().for_each(|p| *p = 0.0);
        for c in components {
            assert_eq!(c.len(), n);
            for (b, &v) in self.buf.iter_mut().zip(c.iter()) {
                *b = Complex64::new(v, 0.0);
            }
            self.fft_y
                .process_with_scratch(&mut self.buf, &mut self.scratch);
            transpose(&self.buf, &mut self.tbuf, lx, ly);
            self.fft_x
                .process_with_scratch(&mut self.tbuf, &mut self.scratch);
            for (p, b) in self.power.iter_mut().zip(&self.tbuf) {
                *p += b.norm_sqr();
            }
        }
        // Inverse of the power spectrum (real and even, so the result is real).
        for (b, &p) in self.tbuf.iter_mut().zip(&self.power) {
            *b = Complex64::new(p, 0.0);
        }
        self.ifft_x
            .process_with_scratch(&mut self.tbuf, &mut self.scratch);
        transpose(&self.tbuf, &mut self.buf, ly, lx);
        self.ifft_y
            .process_with_scratch(&mut self.buf, &mut self.scratch);
        let norm = 1.0 / (n as f64 * n as f64);
        for (s, b) in self.sum.iter_mut().zip(&self.buf) {
            *s += b.re * norm;
        }
        self.n_frames += 1;
    }

    /// Frames added so far.
    pub fn n_frames(&self) -> usize {
        self.n_frames
    }

    /// The frame-averaged correlation `Ā(d)` at every displacement (index `dx * ly + dy`),
    /// not normalised.
    pub fn raw(&self) -> Vec<f64> {
        let k = 1.0 / self.n_frames.max(1) as f64;
        self.sum.iter().map(|s| s * k).collect()
    }

    /// The normalised, radially averaged `C(r)` for `r = 0..=min(lx, ly)/2`; `C(0) = 1`
    /// unless the field is zero everywhere (then all values are NaN).
    pub fn radial(&self) -> Vec<f64> {
        radial_average(self.lattice, &self.raw())
    }
}

/// `out[y * lx + x] = a[x * ly + y]` for an `lx × ly` array stored x-major.
fn transpose(a: &[Complex64], out: &mut [Complex64], lx: usize, ly: usize) {
    for x in 0..lx {
        for y in 0..ly {
            out[y * lx + x] = a[x * ly + y];
        }
    }
}

/// Radial average of a displacement-indexed correlation, normalised by its value at `d = 0`.
pub fn radial_average(lattice: Lattice, corr: &[f64]) -> Vec<f64> {
    let r_max = lattice.lx.min(lattice.ly) / 2;
    let mut sum = vec![0.0; r_max + 1];
    let mut count = vec![0usize; r_max + 1];
    for dx in 0..lattice.lx {
        let mx = min_image(dx as f64, lattice.lx as f64);
        for dy in 0..lattice.ly {
            let my = min_image(dy as f64, lattice.ly as f64);
            let r = mx.hypot(my).round() as usize;
            if r <= r_max {
                sum[r] += corr[lattice.index(dx, dy)];
                count[r] += 1;
            }
        }
    }
    let c0 = corr[0];
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| s / c as f64 / c0)
        .collect()
}

/// The position of the first local minimum of `c` (sampled at `r = 0, 1, ...`), refined by the
/// vertex of the parabola through the three samples around it. `None` if `c` has no interior
/// minimum.
///
/// Rings of lattice nodes hold few nodes at small `r`: for a strongly anisotropic field (a
/// single plane wave, say) the ring average is noisy at the 0.05 level and can show a spurious
/// local minimum a node or two early. Turbulent fields averaged over frames are isotropic
/// enough for this not to matter; check `correlations.csv` when in doubt.
pub fn first_minimum(c: &[f64]) -> Option<f64> {
    (1..c.len().saturating_sub(1))
        .find(|&k| c[k] < c[k - 1] && c[k] <= c[k + 1])
        .map(|k| {
            let (a, b, d) = (c[k - 1], c[k], c[k + 1]);
            let curv = a - 2.0 * b + d;
            if curv > 0.0 {
                k as f64 + 0.5 * (a - d) / curv
            } else {
                k as f64
            }
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direct(lattice: Lattice, comps: &[&[f64]]) -> Vec<f64> {
        let n = lattice.len();
        let mut out = vec![0.0; n];
        for dx in 0..lattice.lx {
            for dy in 0..lattice.ly {
                let mut s = 0.0;
                for x in 0..lattice.lx {
                    for y in 0..lattice.ly {
                        let a = lattice.index(x, y);
                        let b = lattice.index((x + dx) % lattice.lx, (y + dy) % lattice.ly);
                        for c in comps {
                            s += c[a] * c[b];
                        }
                    }
                }
                out[lattice.index(dx, dy)] = s / n as f64;
            }
        }
        out
    }

    #[test]
    fn fft_correlation_equals_the_direct_sum() {
        let lattice = Lattice::new(12, 10);
        let a: Vec<f64> = (0..120).map(|k| ((k * 37) % 17) as f64 - 8.0).collect();
        let b: Vec<f64> = (0..120).map(|k| ((k * 11) % 7) as f64 * 0.3).collect();
        let mut c = Correlator::new(lattice);
        c.add(&[&a, &b]);
        let d = direct(lattice, &[&a, &b]);
        let scale = d[0];
        for (x, y) in c.raw().iter().zip(&d) {
            // FFT round-off: ~ε log N relative to the largest value.
            assert!((x - y).abs() < 1e-12 * scale, "{x} vs {y}");
        }
    }

    /// A single Fourier mode `cos(2π k x / L)` has `C(d) = cos(2π k d_x / L)` exactly.
    #[test]
    fn single_mode_correlation_is_a_cosine() {
        let lattice = Lattice::new(32, 24);
        let k = 3.0;
        let f: Vec<f64> = (0..lattice.len())
            .map(|i| (2.0 * std::f64::consts::PI * k * (i / 24) as f64 / 32.0 + 0.4).cos())
            .collect();
        let mut c = Correlator::new(lattice);
        c.add(&[&f]);
        let raw = c.raw();
        for dx in 0..32 {
            for dy in 0..24 {
                let want = 0.5 * (2.0 * std::f64::consts::PI * k * dx as f64 / 32.0).cos();
                assert!((raw[lattice.index(dx, dy)] - want).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn first_minimum_of_a_parabola_is_its_vertex() {
        let c: Vec<f64> = (0..10).map(|r| (r as f64 - 4.3).powi(2)).collect();
        assert!((first_minimum(&c).unwrap() - 4.3).abs() < 1e-12);
        assert!(first_minimum(&[1.0, 0.5, 0.2]).is_none());
    }
}

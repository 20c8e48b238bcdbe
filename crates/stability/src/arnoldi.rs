//! The leading eigenvalues of the map's Jacobian by Arnoldi iteration, with the small
//! Hessenberg eigenproblem solved by faer.

use faer::Mat;

use crate::growth::start_vector;
use crate::map::{dot, norm, Operator};
use crate::StabilityError;

/// Options of [`arnoldi`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArnoldiOptions {
    /// Krylov dimension k: Jacobian–vector products (each one application of the map).
    pub krylov: usize,
    /// The finite-difference step ε of `J v ≈ (M(x₀ + εv) − M(x₀))/ε`, for a unit `v`.
    pub eps: f64,
    /// Seed of the starting vector.
    pub seed: u64,
}

impl Default for ArnoldiOptions {
    fn default() -> Self {
        Self {
            krylov: 24,
            eps: 1e-5,
            seed: 1,
        }
    }
}

/// One Ritz pair's eigenvalue, as a rate.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ritz {
    /// `μ` of the map, real part.
    pub mu_re: f64,
    /// `μ` of the map, imaginary part.
    pub mu_im: f64,
    /// Growth rate `σ = ln|μ|/τ`.
    pub sigma: f64,
    /// Angular frequency `ω = arg μ/τ`.
    pub omega: f64,
    /// Residual estimate `|h_{k+1,k}| |e_kᵀ y|` of the Ritz pair, as a rate (divided by τ).
    pub residual: f64,
}

/// The leading part of the spectrum.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spectrum {
    /// The Ritz values, largest σ first.
    pub ritz: Vec<Ritz>,
    /// The real part of the leading Ritz vector on the reference layout (unit norm).
    pub mode: Vec<f64>,
    /// The Krylov dimension reached (smaller than asked when the space became invariant).
    pub krylov: usize,
}

impl Spectrum {
    /// The leading growth rate.
    pub fn sigma(&self) -> f64 {
        self.ritz.first().map_or(f64::NAN, |r| r.sigma)
    }
}

/// Arnoldi on an [`Operator`] (in the study `J`, the map's Jacobian at its base, the uniform translations projected out
/// before and after), from `start` (on the reference layout, e.g. the leading mode at a nearby
/// activity, with a random part mixed in: [`crate::start_vector`]) or, without one, from a
/// random vector from `opts.seed`.
///
/// # Errors
/// [`StabilityError::Step`] when a step fails, [`StabilityError::Eigen`] when faer's
/// eigensolver does not converge.
pub fn arnoldi<O: Operator + ?Sized>(
    map: &mut O,
    opts: &ArnoldiOptions,
    start: Option<&[f64]>,
) -> Result<Spectrum, StabilityError> {
    let n = map.dim();
    let k = opts.krylov.max(1);
    let first = start_vector(map, start, opts.seed);
    let mut basis: Vec<Vec<f64>> = vec![first];
    let mut h = Mat::<f64>::zeros(k + 1, k);
    let mut w = vec![0.0; n];
    let mut dim = k;
    for j in 0..k {
        map.apply(&basis[j], opts.eps, &mut w)?;
        map.project(&mut w);
        // Modified Gram–Schmidt, twice (the second pass restores orthogonality lost to
        // cancellation).
        for _ in 0..2 {
            for (i, q) in basis.iter().enumerate() {
                let c = dot(q, &w);
                h[(i, j)] += c;
                w.iter_mut().zip(q).for_each(|(x, y)| *x -= c * y);
            }
        }
        let size = norm(&w);
        h[(j + 1, j)] = size;
        if size < 1e-12 {
            dim = j + 1;
            break;
        }
        basis.push(w.iter().map(|x| x / size).collect());
    }
    let hk = Mat::<f64>::from_fn(dim, dim, |i, j| h[(i, j)]);
    let eig = hk
        .eigen()
        .map_err(|e| StabilityError::Eigen(format!("{e:?}")))?;
    let (s, u) = (eig.S(), eig.U());
    let tau = map.horizon();
    let beta = h[(dim, dim - 1)];
    let mut order: Vec<usize> = (0..dim).collect();
    let modulus = |i: usize| s[i].re.hypot(s[i].im);
    order.sort_by(|&a, &b| modulus(b).total_cmp(&modulus(a)));
    let ritz = order
        .iter()
        .map(|&i| {
            let mu = s[i];
            let col_norm = (0..dim)
                .map(|r| u[(r, i)].re.powi(2) + u[(r, i)].im.powi(2))
                .sum::<f64>()
                .sqrt();
            let last = u[(dim - 1, i)];
            Ritz {
                mu_re: mu.re,
                mu_im: mu.im,
                sigma: modulus(i).ln() / tau,
                omega: mu.im.atan2(mu.re) / tau,
                residual: beta * last.re.hypot(last.im) / col_norm / tau,
            }
        })
        .collect();
    let lead = order[0];
    let mut mode = vec![0.0; n];
    for (r, q) in basis.iter().take(dim).enumerate() {
        let c = u[(r, lead)].re;
        mode.iter_mut().zip(q).for_each(|(m, x)| *m += c * x);
    }
    let m = norm(&mode);
    if m > 0.0 {
        mode.iter_mut().for_each(|x| *x /= m);
    }
    Ok(Spectrum {
        ritz,
        mode,
        krylov: dim,
    })
}

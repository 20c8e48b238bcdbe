//! The leading growth rate by perturbation growth: a tiny random perturbation is integrated
//! beside the base and renormalised after every application of the map (power iteration in
//! time).

use rand::Rng;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use faer::Mat;

use crate::map::{dot, norm, Operator};
use crate::StabilityError;

/// Options of [`growth_rate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthOptions {
    /// Norm of the perturbation, renormalised to it after every application of the map.
    pub amplitude: f64,
    /// Applications of the map.
    pub intervals: usize,
    /// Perturbations integrated together (1: plain power iteration).
    pub vectors: usize,
    /// Seed of the random initial perturbation.
    pub seed: u64,
}

impl Default for GrowthOptions {
    fn default() -> Self {
        Self {
            amplitude: 1e-5,
            intervals: 40,
            vectors: 6,
            seed: 1,
        }
    }
}

/// The measured growth rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Growth {
    /// σ: the last interval's rate plus the geometric tail of its approach (see [`settle`]).
    pub sigma: f64,
    /// Its error: the size of that tail (the extrapolation is trusted to within itself), or,
    /// when the rates do not approach monotonically, half their range over the last quarter.
    pub sigma_err: f64,
    /// The change of the rate over the last quarter of the intervals: near zero once the
    /// leading mode dominates.
    pub drift: f64,
    /// The rate `ln(|δ_k|/|δ_{k−1}|)/τ` of every interval.
    pub rates: Vec<f64>,
    /// The direction of the perturbation at the end (unit norm, reference layout): the start of
    /// the next measurement at a nearby activity.
    pub direction: Vec<f64>,
}

/// A random unit vector, reproducible from `seed`: each component uniform in ±½ times the
/// operator's [`Operator::weight`], neutral directions removed.
pub fn random_direction<O: Operator + ?Sized>(op: &O, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut v: Vec<f64> = (0..op.dim())
        .map(|k| op.weight(k) * (rng.random::<f64>() - 0.5))
        .collect();
    op.project(&mut v);
    let n = norm(&v);
    v.iter_mut().for_each(|x| *x /= n);
    v
}

/// A unit start vector: `start` (on the reference layout) with a random part of a third of
/// its norm mixed in, so that a mode that `start` lacks can still grow (a start that is one
/// mode exactly would keep the iteration on it, even where another leads); without `start`, a
/// random vector from `seed`. The uniform translations are removed.
pub fn start_vector<O: Operator + ?Sized>(map: &O, start: Option<&[f64]>, seed: u64) -> Vec<f64> {
    let random = random_direction(map, seed);
    match start {
        Some(s) if s.len() == random.len() => {
            let size = norm(s);
            let mut v: Vec<f64> = s
                .iter()
                .zip(&random)
                .map(|(a, r)| a / size + r / 3.0)
                .collect();
            map.project(&mut v);
            let size = norm(&v);
            v.iter_mut().for_each(|x| *x /= size);
            v
        }
        _ => random,
    }
}

/// The leading growth rate of perturbations about the base of `map` (any [`Operator`]; a
/// [`crate::StepMap`] in the study) by power iteration in time
/// (simultaneous iteration): `opts.vectors` orthonormal perturbations of norm
/// `opts.amplitude` are integrated over one application of the map, their differences with the
/// base's image `M(x₀)` measured, the leading eigenvalue of the small matrix `Vᵀ J V` taken
/// (Rayleigh–Ritz, by faer) and the perturbations re-orthonormalised, `opts.intervals` times.
/// With one vector this is plain power iteration, whose rate converges to σ₁ only as
/// `e^{−(σ₁−σ₂)t}`; with p vectors the leading Ritz value converges as `e^{−(σ₁−σ_{p+1})t}`,
/// which matters here because the leading modes come in a dense band.
///
/// The base is the same rest state at every interval (as for [`crate::arnoldi`]): a base
/// integrated alongside would leave the rest state above the threshold, where its residual
/// forcing makes it drift, and measure the state it drifted to. The first perturbation starts
/// along `start` (see [`start_vector`]) or, without one, in a random direction from
/// `opts.seed`; the others are random.
///
/// # Errors
/// [`StabilityError::Step`] when a step fails, [`StabilityError::Eigen`] when the small
/// eigenproblem fails.
pub fn growth_rate<O: Operator + ?Sized>(
    map: &mut O,
    opts: &GrowthOptions,
    start: Option<&[f64]>,
) -> Result<Growth, StabilityError> {
    let n = map.dim();
    let p = opts.vectors.max(1);
    let mut block: Vec<Vec<f64>> = vec![start_vector(map, start, opts.seed)];
    for j in 1..p {
        block.push(random_direction(
            map,
            opts.seed.wrapping_add(1000 + j as u64),
        ));
    }
    orthonormalise(&mut block);
    let mut images = vec![vec![0.0; n]; p];
    let tau = map.horizon();
    let mut rates = Vec::with_capacity(opts.intervals);
    let mut lead = vec![0.0; p];
    for _ in 0..opts.intervals {
        for (v, w) in block.iter().zip(images.iter_mut()) {
            map.apply(v, opts.amplitude, w)?;
            map.project(w);
        }
        let b = Mat::<f64>::from_fn(p, p, |i, j| dot(&block[i], &images[j]));
        let eig = b
            .eigen()
            .map_err(|e| StabilityError::Eigen(format!("{e:?}")))?;
        let (s, u) = (eig.S(), eig.U());
        let k = (0..p)
            .max_by(|&a, &b| s[a].re.hypot(s[a].im).total_cmp(&s[b].re.hypot(s[b].im)))
            .unwrap_or(0);
        rates.push(s[k].re.hypot(s[k].im).ln() / tau);
        for (i, l) in lead.iter_mut().enumerate() {
            *l = u[(i, k)].re;
        }
        // The leading Ritz vector first, then the images: the next block spans J V with the
        // current best guess of the mode in front.
        let mut ritz = vec![0.0; n];
        for (c, w) in lead.iter().zip(&images) {
            ritz.iter_mut().zip(w).for_each(|(r, x)| *r += c * x);
        }
        images.swap(0, k.min(p - 1));
        block.clear();
        block.push(ritz);
        block.extend(images.iter().skip(1).cloned());
        orthonormalise(&mut block);
    }
    let (sigma, sigma_err, drift) = settle(&rates);
    Ok(Growth {
        sigma,
        sigma_err,
        drift,
        rates,
        direction: block.swap_remove(0),
    })
}

/// Modified Gram–Schmidt, twice.
fn orthonormalise(block: &mut [Vec<f64>]) {
    for j in 0..block.len() {
        for _ in 0..2 {
            for i in 0..j {
                let c = dot(&block[i], &block[j]);
                let (head, tail) = block.split_at_mut(j);
                tail[0]
                    .iter_mut()
                    .zip(&head[i])
                    .for_each(|(x, y)| *x -= c * y);
            }
        }
        let size = norm(&block[j]);
        block[j].iter_mut().for_each(|x| *x /= size);
    }
}

/// The settled rate of a power iteration from its per-interval rates `r_k`: once one mode
/// leads, `r_k → σ₁` geometrically, `r_{k+1} − r_k ≈ ρ (r_k − r_{k−1})` with
/// `ρ = e^{−(σ₁ − σ₂)τ}`, so the rest of the approach after the last rate is
/// `d ρ/(1 − ρ)` (d the last difference, ρ the median ratio of the last quarter's successive
/// differences). Returns `(σ, error, drift)`, the error being twice that tail (a band of modes
/// approaches with several ratios, not one; at ζ = 0.004 on the 6 × 10 packing the tail
/// alone fell 20 % short of the distance to Arnoldi's σ₁); when the differences
/// change sign or do not shrink (ρ ∉ (0, 0.98)), σ is the mean of the last quarter and the
/// error half its range.
pub fn settle(rates: &[f64]) -> (f64, f64, f64) {
    let n = rates.len();
    if n < 4 {
        let (m, s) = mean_sd(rates);
        return (m, s, f64::NAN);
    }
    let q = (n / 4).max(3).min(n - 1);
    let tail = &rates[n - q..];
    let drift = tail[tail.len() - 1] - tail[0];
    let d: Vec<f64> = tail.windows(2).map(|w| w[1] - w[0]).collect();
    let mut ratios: Vec<f64> = d.windows(2).map(|w| w[1] / w[0]).collect();
    ratios.sort_by(f64::total_cmp);
    let rho = ratios[ratios.len() / 2];
    let same_sign = d.iter().all(|x| x.signum() == d[0].signum() && *x != 0.0);
    if same_sign && rho > 0.0 && rho < 0.98 {
        let rest = d[d.len() - 1] * rho / (1.0 - rho);
        (rates[n - 1] + rest, 2.0 * rest.abs(), drift)
    } else {
        let lo = tail.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = tail.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (mean_sd(tail).0, 0.5 * (hi - lo), drift)
    }
}

pub(crate) fn mean_sd(x: &[f64]) -> (f64, f64) {
    if x.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = if x.len() > 1 {
        x.iter().map(|y| (y - m) * (y - m)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, v.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A geometric approach is extrapolated to its limit; its error is the tail added.
    #[test]
    fn settle_extrapolates_a_geometric_approach() {
        let sigma = 3.6e-3;
        let rates: Vec<f64> = (0..20).map(|k| sigma - 4e-4 * 0.85f64.powi(k)).collect();
        let (s, e, drift) = settle(&rates);
        assert!((s - sigma).abs() < 1e-12, "{s}");
        assert!(e > 0.0 && e < 8e-4 && drift > 0.0);
        // Rates that oscillate are averaged, with half their range as the error.
        let rates: Vec<f64> = (0..20)
            .map(|k| sigma + 1e-5 * if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let (s, e, _) = settle(&rates);
        assert!((s - sigma).abs() <= 2.1e-6 && (e - 1e-5).abs() < 1e-12);
    }
}

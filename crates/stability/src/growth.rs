//! The leading growth rate by perturbation growth: a tiny random perturbation is integrated
//! beside the base and renormalised after every application of the map (power iteration in
//! time).

use rand::Rng;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::map::{norm, StepMap};
use crate::StabilityError;

/// Options of [`growth_rate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthOptions {
    /// Norm of the perturbation, renormalised to it after every application of the map.
    pub amplitude: f64,
    /// Applications of the map.
    pub intervals: usize,
    /// Seed of the random initial perturbation.
    pub seed: u64,
}

impl Default for GrowthOptions {
    fn default() -> Self {
        Self {
            amplitude: 1e-5,
            intervals: 40,
            seed: 1,
        }
    }
}

/// The measured growth rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Growth {
    /// σ: the mean of the per-interval rates over the second half of the intervals.
    pub sigma: f64,
    /// The standard error of that mean (the rates of successive intervals are correlated, so
    /// this is a lower bound; [`Growth::drift`] shows whether they have settled).
    pub sigma_err: f64,
    /// The difference between the means of the last and the third quarter: near zero once the
    /// leading mode dominates.
    pub drift: f64,
    /// The rate `ln(|δ_k|/|δ_{k−1}|)/τ` of every interval.
    pub rates: Vec<f64>,
    /// The direction of the perturbation at the end (unit norm, reference layout): the start of
    /// the next measurement at a nearby activity.
    pub direction: Vec<f64>,
}

/// A random unit vector with the uniform translations removed, reproducible from `seed`.
pub fn random_direction(map: &StepMap, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Only where a cell is: perturbing the far tail of a field would start with modes that
    // the double well kills at once.
    let mut v: Vec<f64> = map
        .base()
        .cells()
        .phi()
        .iter()
        .map(|&p| {
            let w = (4.0 * p * (1.0 - p)).max(0.0);
            w * (rng.random::<f64>() - 0.5)
        })
        .collect();
    map.project(&mut v);
    let n = norm(&v);
    v.iter_mut().for_each(|x| *x /= n);
    v
}

/// The leading growth rate of perturbations about `map`'s base, by integrating a perturbed
/// copy beside it and renormalising after each application of the map. The perturbation starts
/// along `start` (on the reference layout; the uniform translations are removed) or, without
/// one, in a random direction from `opts.seed`.
///
/// # Errors
/// [`StabilityError::Step`] when a step fails.
pub fn growth_rate(
    map: &mut StepMap,
    opts: &GrowthOptions,
    start: Option<&[f64]>,
) -> Result<Growth, StabilityError> {
    let n = map.len();
    let mut dir = match start {
        Some(s) if s.len() == n => {
            let mut v = s.to_vec();
            map.project(&mut v);
            let size = norm(&v);
            v.iter_mut().for_each(|x| *x /= size);
            v
        }
        _ => random_direction(map, opts.seed),
    };
    let mut base = map.base().clone();
    let mut on_base = vec![0.0; n];
    map.to_layout_of(&base, &dir, &mut on_base);
    let mut pert = map.displaced(&base, &on_base, opts.amplitude)?;
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    let tau = map.horizon();
    let mut rates = Vec::with_capacity(opts.intervals);
    for _ in 0..opts.intervals {
        map.advance(&mut base)?;
        map.advance(&mut pert)?;
        map.sample(&pert, &mut a);
        map.sample(&base, &mut b);
        for (d, (x, y)) in dir.iter_mut().zip(a.iter().zip(&b)) {
            *d = x - y;
        }
        map.project(&mut dir);
        let size = norm(&dir);
        rates.push((size / opts.amplitude).ln() / tau);
        dir.iter_mut().for_each(|x| *x /= size);
        map.to_layout_of(&base, &dir, &mut on_base);
        pert = map.displaced(&base, &on_base, opts.amplitude)?;
    }
    let half = &rates[rates.len() / 2..];
    let (sigma, sd) = mean_sd(half);
    let q = rates.len() / 4;
    let (third, _) = mean_sd(&rates[rates.len() / 2..rates.len() - q]);
    let (last, _) = mean_sd(&rates[rates.len() - q..]);
    Ok(Growth {
        sigma,
        sigma_err: sd / (half.len() as f64).sqrt(),
        drift: last - third,
        rates,
        direction: dir,
    })
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

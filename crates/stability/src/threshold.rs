//! The activity threshold: where the leading growth rate crosses zero, by bisection.

use mechanics::{ModelParams, StepParams, Tissue};

use crate::{
    arnoldi, growth_rate, ArnoldiOptions, GrowthOptions, Spectrum, StabilityError, StepMap,
};

/// Narrowing rounds of [`bisect`] before plain halving.
pub const NARROWING_ROUNDS: usize = 3;

/// A threshold found by bisection.
#[derive(Debug, Clone, PartialEq)]
pub struct Bisection {
    /// The midpoint of the final bracket.
    pub zeta: f64,
    /// Half the width of the final bracket.
    pub err: f64,
    /// Every evaluation `(ζ, σ)`, in the order made.
    pub evaluations: Vec<(f64, f64)>,
}

/// The ζ in `[lo, hi]` where `sigma(ζ)` changes sign from negative to positive, to within
/// `tol` (half the final bracket).
///
/// When `narrow > 0`, the bracket is first narrowed, up to [`NARROWING_ROUNDS`] times while it
/// is wider than `4·narrow`: σ is evaluated at the root of the straight line through the
/// bracket's ends, ± `narrow`, and the bracket becomes the smallest interval between evaluated
/// points across which σ changes sign (σ(ζ) is nearly straight, so this saves several halvings;
/// it is still a bracket, never an extrapolation). Then it is halved.
///
/// # Errors
/// [`StabilityError::NoCrossing`] when σ has the same sign at both ends, and whatever `sigma`
/// returns.
pub fn bisect(
    mut sigma: impl FnMut(f64) -> Result<f64, StabilityError>,
    lo: f64,
    hi: f64,
    tol: f64,
    narrow: f64,
) -> Result<Bisection, StabilityError> {
    let mut evaluations = Vec::new();
    let sa = sigma(lo)?;
    evaluations.push((lo, sa));
    let sb = sigma(hi)?;
    evaluations.push((hi, sb));
    if !(sa < 0.0 && sb > 0.0) {
        return Err(StabilityError::NoCrossing {
            lo,
            hi,
            sigma_lo: sa,
            sigma_hi: sb,
        });
    }
    let (mut a, mut b, mut sa, mut sb) = (lo, hi, sa, sb);
    let mut rounds = 0;
    while 0.5 * (b - a) > tol {
        let points: Vec<f64> = if narrow > 0.0 && rounds < NARROWING_ROUNDS && b - a > 4.0 * narrow
        {
            rounds += 1;
            let guess = a - sa * (b - a) / (sb - sa);
            [guess - narrow, guess + narrow]
                .into_iter()
                .filter(|z| *z > a && *z < b)
                .collect()
        } else {
            vec![0.5 * (a + b)]
        };
        for z in points {
            if z <= a || z >= b {
                continue;
            }
            let s = sigma(z)?;
            evaluations.push((z, s));
            if s < 0.0 {
                (a, sa) = (z, s);
            } else {
                (b, sb) = (z, s);
            }
        }
    }
    Ok(Bisection {
        zeta: 0.5 * (a + b),
        err: 0.5 * (b - a),
        evaluations,
    })
}

/// How the leading growth rate is measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Perturbation growth ([`growth_rate`]), each evaluation started from the last one's
    /// final direction (the first, from a random one, runs three times as many intervals).
    Growth(GrowthOptions),
    /// Arnoldi ([`arnoldi`]), each evaluation started from the last one's leading mode.
    Arnoldi(ArnoldiOptions),
}

impl Method {
    /// `growth` or `arnoldi`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Growth(_) => "growth",
            Self::Arnoldi(_) => "arnoldi",
        }
    }
}

/// The settings of [`threshold`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThresholdOptions {
    /// The time step of the map.
    pub step: StepParams,
    /// Steps per application of the map (its horizon τ = `steps · dt`).
    pub steps: usize,
    /// The bracket's lower end (σ must be negative there).
    pub lo: f64,
    /// The bracket's upper end (σ must be positive there).
    pub hi: f64,
    /// Half the final bracket.
    pub tol: f64,
    /// Half-width of the narrowed first bracket (see [`bisect`]); 0 for plain bisection.
    pub narrow: f64,
}

/// One evaluation of σ(ζ).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Evaluation {
    /// The activity.
    pub zeta: f64,
    /// The leading growth rate.
    pub sigma: f64,
    /// Its error: the Ritz residual (Arnoldi), or the tail of the rates' approach
    /// ([`crate::settle`], growth).
    pub sigma_err: f64,
}

/// The threshold of one configuration by one method (serialisable, so that a study can keep
/// each one as it finishes).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Threshold {
    /// ζ_cr.
    pub zeta_cr: f64,
    /// Its error: half the final bracket and the σ error at the bracket's ends over the slope
    /// `dσ/dζ`, in quadrature.
    pub err: f64,
    /// `dσ/dζ`, the least-squares slope through every evaluation.
    pub slope: f64,
    /// Every evaluation, in the order made.
    pub evaluations: Vec<Evaluation>,
    /// The spectrum at the last evaluation (Arnoldi only).
    pub spectrum: Option<Spectrum>,
}

/// ζ_cr of the rest state `base` (relaxed at ζ = 0) under `params` (its ζ replaced by each
/// evaluation's) by `method`.
///
/// # Errors
/// [`StabilityError::NoCrossing`] when σ does not change sign in the bracket, and whatever
/// a step or the eigensolver returns.
pub fn threshold(
    base: &Tissue<f64>,
    params: &ModelParams,
    method: &Method,
    opts: &ThresholdOptions,
) -> Result<Threshold, StabilityError> {
    let mut start: Option<Vec<f64>> = None;
    let mut evaluations = Vec::new();
    let mut spectrum = None;
    let b = bisect(
        |zeta| {
            let mut map = StepMap::new(base, &(*params).with_zeta(zeta), opts.step, opts.steps)?;
            let (sigma, err) = match method {
                Method::Growth(g) => {
                    // A cold start runs three times as long: it begins far from the mode.
                    let g = GrowthOptions {
                        intervals: if start.is_none() {
                            3 * g.intervals
                        } else {
                            g.intervals
                        },
                        ..*g
                    };
                    let r = growth_rate(&mut map, &g, start.as_deref())?;
                    start = Some(r.direction);
                    (r.sigma, r.sigma_err)
                }
                Method::Arnoldi(a) => {
                    let s = arnoldi(&mut map, a, start.as_deref())?;
                    start = Some(s.mode.clone());
                    let out = (s.sigma(), s.ritz[0].residual);
                    spectrum = Some(s);
                    out
                }
            };
            evaluations.push(Evaluation {
                zeta,
                sigma,
                sigma_err: err,
            });
            Ok(sigma)
        },
        opts.lo,
        opts.hi,
        opts.tol,
        opts.narrow,
    )?;
    let z: Vec<f64> = evaluations.iter().map(|e| e.zeta).collect();
    let s: Vec<f64> = evaluations.iter().map(|e| e.sigma).collect();
    let slope = crate::fit::line(&z, &s, None).map_or(f64::NAN, |f| f.coef[1]);
    // The σ error nearest the crossing.
    let near_err = evaluations
        .iter()
        .min_by(|p, q| (p.zeta - b.zeta).abs().total_cmp(&(q.zeta - b.zeta).abs()))
        .map_or(0.0, |e| e.sigma_err);
    Ok(Threshold {
        zeta_cr: b.zeta,
        err: b.err.hypot(near_err / slope.abs()),
        slope,
        evaluations,
        spectrum,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisection_finds_a_root_to_its_tolerance() {
        let root = 0.003_217;
        for narrow in [0.0, 4e-4] {
            let b = bisect(|z| Ok((z - root) * 7.0), 0.0, 0.016, 1e-5, narrow).unwrap();
            assert!((b.zeta - root).abs() <= b.err && b.err <= 1e-5);
        }
        // Narrowing around the straight line's root saves halvings on a straight σ.
        let plain = bisect(|z| Ok((z - root) * 7.0), 0.0, 0.016, 1e-5, 0.0).unwrap();
        let narrowed = bisect(|z| Ok((z - root) * 7.0), 0.0, 0.016, 1e-5, 4e-4).unwrap();
        assert!(narrowed.evaluations.len() < plain.evaluations.len());
        // A curved σ still ends in a true bracket.
        let b = bisect(
            |z| Ok((z - root) * (1.0 + 300.0 * z)),
            0.0,
            0.016,
            1e-5,
            4e-4,
        )
        .unwrap();
        assert!((b.zeta - root).abs() <= b.err);
    }

    #[test]
    fn no_sign_change_is_an_error() {
        let e = bisect(|z| Ok(z + 1.0), 0.0, 0.016, 1e-5, 0.0).unwrap_err();
        assert!(matches!(e, StabilityError::NoCrossing { .. }));
    }
}

//! The threshold of every Bloch wave, and from them those of the infinite tissue and of any
//! box (issue 54).
//!
//! For a wave vector `q`, `ζ_cr(q)` is where the leading growth rate of the Bloch map
//! ([`crate::BlochMap`]) crosses zero. A box of `n × m` primitive cells goes unstable at the
//! smallest `ζ_cr(q)` over the `q` it allows ([`crate::box_wavevectors`]); the infinite tissue at
//! the smallest over the Brillouin zone. σ(ζ) of one wave is nearly straight, so each `ζ_cr(q)`
//! is found by regula falsi from two activities, with rayon over the waves.

use mechanics::{ModelParams, StepParams};
use rayon::prelude::*;

use crate::{arnoldi, ArnoldiOptions, BlochMap, BlochTiling, StabilityError};

/// How [`wave_thresholds`] looks for each wave's crossing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaveOptions {
    /// The time step and the steps per application of the map (τ = steps · dt).
    pub step: StepParams,
    /// Steps per application.
    pub steps: usize,
    /// Arnoldi's settings for each σ.
    pub arnoldi: ArnoldiOptions,
    /// The two activities every wave is evaluated at first.
    pub start: [f64; 2],
    /// Regula-falsi steps after them.
    pub refine: usize,
    /// Stop refining a wave once its root moves by less than this.
    pub tol: f64,
}

/// One σ of one wave.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WavePoint {
    /// Activity.
    pub zeta: f64,
    /// The leading growth rate.
    pub sigma: f64,
    /// Its Ritz residual (a rate).
    pub residual: f64,
}

/// The threshold of one Bloch wave.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WaveThreshold {
    /// The wave vector, in units of the reciprocal vectors.
    pub q: [f64; 2],
    /// The supercell it was computed on.
    pub supercell: [usize; 2],
    /// Where σ crosses zero: the root of the straight line through the two evaluations nearest
    /// it on either side (or, without a sign change, through the last two: an extrapolation,
    /// and `bracketed` is false).
    pub zeta_cr: f64,
    /// Its error: the last move of the root (with two evaluations, its distance to the nearer),
    /// and the larger Ritz residual of the two evaluations the root is drawn through over the
    /// slope, whichever is larger.
    pub err: f64,
    /// Whether evaluations on both sides of zero bracket it.
    pub bracketed: bool,
    /// Every evaluation, in the order made.
    pub points: Vec<WavePoint>,
}

impl WaveThreshold {
    /// Whether the wave grows at ζ = 0 by more than two Ritz residuals: the rest state itself
    /// is unstable to it.
    pub fn unstable_at_rest(&self) -> bool {
        self.points
            .iter()
            .any(|p| p.zeta == 0.0 && p.sigma - 2.0 * p.residual > 0.0)
    }

    /// The threshold of wave `q` from its evaluations (as [`wave_thresholds`] makes it; a kept
    /// result is rebuilt from its points by this).
    pub fn from_points(q: [f64; 2], supercell: [usize; 2], points: Vec<WavePoint>) -> Self {
        let (zeta_cr, slope, bracketed, residual) = root(&points);
        // How far the line is trusted: the root's last move, or with two evaluations (the
        // root fell within the tolerance of one of them) its distance to the nearest.
        let last_move = if points.len() >= 3 {
            let (prev, _, _, _) = root(&points[..points.len() - 1]);
            (zeta_cr - prev).abs()
        } else {
            points
                .iter()
                .map(|p| (p.zeta - zeta_cr).abs())
                .fold(f64::INFINITY, f64::min)
        };
        let err = last_move.max(residual / slope.abs());
        Self {
            q,
            supercell,
            zeta_cr,
            err,
            bracketed,
            points,
        }
    }
}

/// The root of σ(ζ) from the evaluations: the line through the nearest points on either side of
/// zero, or through the last two; with its slope, whether it is bracketed, and the larger Ritz
/// residual of the two points.
fn root(points: &[WavePoint]) -> (f64, f64, bool, f64) {
    let below = points
        .iter()
        .filter(|p| p.sigma < 0.0)
        .max_by(|a, b| a.zeta.total_cmp(&b.zeta));
    let above = points
        .iter()
        .filter(|p| p.sigma >= 0.0)
        .min_by(|a, b| a.zeta.total_cmp(&b.zeta));
    let (a, b, bracketed) = match (below, above) {
        (Some(a), Some(b)) => (a, b, true),
        _ => {
            let n = points.len();
            (&points[n - 2], &points[n - 1], false)
        }
    };
    let slope = (b.sigma - a.sigma) / (b.zeta - a.zeta);
    (
        a.zeta - a.sigma / slope,
        slope,
        bracketed,
        a.residual.max(b.residual),
    )
}

fn sigma(
    tiling: &BlochTiling,
    params: &ModelParams,
    opts: &WaveOptions,
    q: [f64; 2],
    zeta: f64,
) -> Result<WavePoint, StabilityError> {
    let p = params.with_zeta(zeta);
    let mut map = BlochMap::new(
        tiling,
        &p,
        opts.step,
        opts.steps,
        tiling.supercell_for(q),
        q,
    )?;
    let s = arnoldi(&mut map, &opts.arnoldi, None)?;
    Ok(WavePoint {
        zeta,
        sigma: s.sigma(),
        residual: s.ritz.first().map_or(f64::NAN, |r| r.residual),
    })
}

/// `ζ_cr(q)` of every wave in `qs`, about `tiling`'s rest state with the model `params`:
/// σ at `opts.start`, then [`refine_waves`].
///
/// # Errors
/// Whatever a map or Arnoldi fails with.
pub fn wave_thresholds(
    tiling: &BlochTiling,
    params: &ModelParams,
    qs: &[[f64; 2]],
    opts: &WaveOptions,
) -> Result<Vec<WaveThreshold>, StabilityError> {
    let started: Vec<WaveThreshold> = qs
        .par_iter()
        .map(|&q| {
            let points = vec![
                sigma(tiling, params, opts, q, opts.start[0])?,
                sigma(tiling, params, opts, q, opts.start[1])?,
            ];
            Ok(WaveThreshold::from_points(
                q,
                tiling.supercell_for(q),
                points,
            ))
        })
        .collect::<Result<_, StabilityError>>()?;
    refine_waves(tiling, params, started, opts)
}

/// Up to `opts.refine` regula-falsi steps on each wave, from the evaluations it has, until its
/// root moves by less than `opts.tol`. A root below zero is evaluated at ζ = 0 instead: a wave
/// that grows there is unstable at rest ([`WaveThreshold::unstable_at_rest`]) and is left so.
/// A wave already refined is returned as it is, so that kept waves are completed, not redone.
///
/// # Errors
/// Whatever a map or Arnoldi fails with.
pub fn refine_waves(
    tiling: &BlochTiling,
    params: &ModelParams,
    waves: Vec<WaveThreshold>,
    opts: &WaveOptions,
) -> Result<Vec<WaveThreshold>, StabilityError> {
    waves
        .into_par_iter()
        .map(|w| {
            let mut points = w.points;
            while points.len() < 2 + opts.refine {
                let (z, _, _, _) = root(&points);
                if !z.is_finite() {
                    break;
                }
                let z = z.max(0.0);
                let nearest = points
                    .iter()
                    .map(|p| (p.zeta - z).abs())
                    .fold(f64::INFINITY, f64::min);
                if nearest < opts.tol {
                    break;
                }
                points.push(sigma(tiling, params, opts, w.q, z)?);
            }
            Ok(WaveThreshold::from_points(w.q, w.supercell, points))
        })
        .collect()
}

/// The threshold of a set of waves (a box's, or a grid over the zone): the smallest `ζ_cr(q)`
/// among them, with its wave.
pub fn lowest<'a>(waves: impl IntoIterator<Item = &'a WaveThreshold>) -> Option<&'a WaveThreshold> {
    waves
        .into_iter()
        .filter(|w| w.zeta_cr.is_finite())
        .min_by(|a, b| a.zeta_cr.total_cmp(&b.zeta_cr))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(zeta: f64, f: impl Fn(f64) -> f64, residual: f64) -> WavePoint {
        WavePoint {
            zeta,
            sigma: f(zeta),
            residual,
        }
    }

    /// On a straight σ(ζ) the root is exact and bracketed; its error is the residual over the
    /// slope; a line that does not turn within the evaluations is extrapolated and says so.
    #[test]
    fn a_wave_s_threshold_is_the_root_of_its_line() {
        let line = |z: f64| 0.5 * (z - 4e-4);
        let w = WaveThreshold::from_points(
            [0.0, 0.1],
            [1, 5],
            vec![
                at(3e-4, line, 1e-7),
                at(6e-4, line, 1e-6),
                at(4e-4, line, 2e-7),
            ],
        );
        assert!((w.zeta_cr - 4e-4).abs() < 1e-15, "{}", w.zeta_cr);
        assert!(w.bracketed);
        // The root is drawn through 3e-4 and 4e-4 (σ = 0 counts as above): residual 2e-7.
        assert!((w.err - 4e-7).abs() < 1e-12, "{}", w.err);
        let far = WaveThreshold::from_points(
            [0.0, 0.1],
            [1, 5],
            vec![at(1e-4, line, 1e-7), at(2e-4, line, 1e-7)],
        );
        assert!(!far.bracketed && (far.zeta_cr - 4e-4).abs() < 1e-15);
        assert!(
            (far.err - 2e-4).abs() < 1e-15,
            "the distance to the nearer: {}",
            far.err
        );
        let waves = [w, far];
        assert_eq!(lowest(&waves).map(|w| w.q), Some([0.0, 0.1]));
    }
}

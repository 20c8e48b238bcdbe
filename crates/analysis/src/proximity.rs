//! How close events (a cell's division or extrusion, at its centre) come to defects, against
//! points drawn where the tissue is: the statistic behind the published link between
//! extrusion and +½ defects (events nearer than random points are drawn to the defects).

use phasefield::Lattice;

/// The periodic distance from `p` to the nearest of `points` (infinite when there are none).
pub fn nearest(lattice: Lattice, p: [f64; 2], points: &[[f64; 2]]) -> f64 {
    points
        .iter()
        .map(|&q| lattice.distance(p, q))
        .fold(f64::INFINITY, f64::min)
}

/// The mean of [`nearest`] over the lattice nodes where `mask` holds (index `x * ly + y`),
/// every `stride`-th node along each axis: the distance a point placed at random in the
/// tissue has to the nearest of `points`. NaN when no sampled node is in the mask or there
/// are no points.
///
/// # Panics
/// If `mask` is not lattice-sized or `stride` is 0.
pub fn mean_nearest_over(
    lattice: Lattice,
    mask: &[bool],
    points: &[[f64; 2]],
    stride: usize,
) -> f64 {
    assert_eq!(mask.len(), lattice.len());
    assert!(stride > 0);
    if points.is_empty() {
        return f64::NAN;
    }
    let (mut sum, mut n) = (0.0, 0usize);
    for x in (0..lattice.lx).step_by(stride) {
        for y in (0..lattice.ly).step_by(stride) {
            if mask[x * lattice.ly + y] {
                sum += nearest(lattice, [x as f64, y as f64], points);
                n += 1;
            }
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// The share of the lattice nodes where `mask` holds (every `stride`-th along each axis) that
/// lie within `radius` (periodic distance, inclusive) of one of `points`: the chance that a
/// point placed at random in the tissue is near one, against which the share of events near
/// one is an enrichment. 0 without points; NaN when no sampled node is in the mask.
///
/// # Panics
/// If `mask` is not lattice-sized or `stride` is 0.
pub fn share_within(
    lattice: Lattice,
    mask: &[bool],
    points: &[[f64; 2]],
    radius: f64,
    stride: usize,
) -> f64 {
    assert_eq!(mask.len(), lattice.len());
    assert!(stride > 0);
    let (mut near, mut n) = (0usize, 0usize);
    for x in (0..lattice.lx).step_by(stride) {
        for y in (0..lattice.ly).step_by(stride) {
            if mask[x * lattice.ly + y] {
                n += 1;
                if nearest(lattice, [x as f64, y as f64], points) <= radius {
                    near += 1;
                }
            }
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        near as f64 / n as f64
    }
}

/// The enrichment of events near points: the number of events within the radius of one
/// (`near[k]` true), over the number expected if each event were a point of its frame's
/// tissue placed at random (the sum of `share[k]`, [`share_within`] of the event's frame).
/// 1 when events fall where random points would, above 1 when they gather near the points.
/// NaN without events, or when no event could have been near one (the shares sum to 0).
pub fn enrichment(near: &[bool], share: &[f64]) -> f64 {
    assert_eq!(near.len(), share.len(), "a share per event");
    let (hits, expected) = near
        .iter()
        .zip(share)
        .filter(|(_, s)| s.is_finite())
        .fold((0.0, 0.0), |(h, e), (&n, &s)| {
            (h + f64::from(u8::from(n)), e + s)
        });
    if expected > 0.0 {
        hits / expected
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distances wrap: a point at x = 1 is 2 from one at x = 63 on a 64-wide lattice.
    #[test]
    fn nearest_wraps() {
        let l = Lattice::new(64, 32);
        assert_eq!(nearest(l, [1.0, 5.0], &[[63.0, 5.0], [20.0, 5.0]]), 2.0);
        assert_eq!(nearest(l, [1.0, 5.0], &[]), f64::INFINITY);
    }

    /// One point at the centre of a 64² lattice, the mask everything: the mean distance of
    /// the nodes to it is the mean distance of a square's points to its centre,
    /// `L (√2 + ln(1 + √2))/6 = 0.3826 L` (24.49 for L = 64), to the lattice's discreteness
    /// (within 1 %); with the mask a disc of radius 10 around it, 2/3 of the radius (6.67,
    /// within 3 %).
    #[test]
    fn the_random_baseline_is_the_mean_distance() {
        let l = Lattice::new(64, 64);
        let all = vec![true; l.len()];
        let want = 64.0 * (2f64.sqrt() + (1.0 + 2f64.sqrt()).ln()) / 6.0;
        let got = mean_nearest_over(l, &all, &[[32.0, 32.0]], 1);
        assert!((got / want - 1.0).abs() < 0.01, "{got} {want}");
        let disc: Vec<bool> = (0..l.len())
            .map(|k| l.distance([(k / 64) as f64, (k % 64) as f64], [32.0, 32.0]) <= 10.0)
            .collect();
        let got = mean_nearest_over(l, &disc, &[[32.0, 32.0]], 1);
        assert!((got / (20.0 / 3.0) - 1.0).abs() < 0.03, "{got}");
        assert!(mean_nearest_over(l, &all, &[], 1).is_nan());
        assert!(mean_nearest_over(l, &vec![false; l.len()], &[[1.0, 1.0]], 1).is_nan());
    }

    /// The share within a radius is the disc's area over the tissue's: one point on a 64²
    /// lattice, radius 10, `π 10²/64² = 0.0767` (within 3 % on the lattice's nodes); wrapped
    /// across the edge the same; the mask halved, twice the share. Events placed where random
    /// points are have an enrichment of 1 in expectation, and events all near the points
    /// `1/share`.
    #[test]
    fn the_share_within_a_radius_and_the_enrichment() {
        let l = Lattice::new(64, 64);
        let all = vec![true; l.len()];
        let want = std::f64::consts::PI * 100.0 / 4096.0;
        let got = share_within(l, &all, &[[32.0, 32.0]], 10.0, 1);
        assert!((got / want - 1.0).abs() < 0.03, "{got} {want}");
        let wrapped = share_within(l, &all, &[[0.0, 0.0]], 10.0, 1);
        assert_eq!(got, wrapped);
        let left: Vec<bool> = (0..l.len()).map(|k| k / 64 < 32).collect();
        let half = share_within(l, &left, &[[16.0, 32.0]], 10.0, 1);
        assert!((half / got - 2.0).abs() < 1e-12, "{half} {got}");
        assert_eq!(share_within(l, &all, &[], 10.0, 1), 0.0);
        // Events at every node, each with the frame's share: enrichment 1 exactly.
        let points = [[32.0, 32.0]];
        let near: Vec<bool> = (0..l.len())
            .map(|k| nearest(l, [(k / 64) as f64, (k % 64) as f64], &points) <= 10.0)
            .collect();
        let share = vec![got; near.len()];
        assert!((enrichment(&near, &share) - 1.0).abs() < 1e-12);
        // Every event near: 1/share.
        let e = enrichment(&[true; 10], &[got; 10]);
        assert!((e - 1.0 / got).abs() < 1e-9, "{e}");
        assert!(enrichment(&[], &[]).is_nan());
        assert!(enrichment(&[false], &[0.0]).is_nan());
    }
}

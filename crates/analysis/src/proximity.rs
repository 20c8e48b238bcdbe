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
}

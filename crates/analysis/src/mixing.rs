//! How mixed two or more kinds of cells are: which cells touch, the demixing parameter, and a
//! rule for whether it grows in time (docs/model.md §11.3).
//!
//! Two cells touch when the regions they own (the nodes where a cell's `φ_i` is the largest and
//! above ½) share an edge of the lattice. The demixing parameter of a labelling is the
//! fraction of touching pairs with equal labels minus the fraction expected when the same labels
//! are dealt at random, `Σ_k n_k(n_k − 1) / (N(N − 1))`: 0 for a random mixture, positive when
//! like cells gather, negative when they avoid each other.

use phasefield::Lattice;

/// The pairs `[i, j]` (`i < j`, sorted, each once) of cells whose owned regions share a lattice
/// edge, from the owner map `owner` (index `x * ly + y`, −1 where no cell owns the node).
///
/// # Panics
/// If `owner.len()` is not the lattice's size.
pub fn contacts(lattice: Lattice, owner: &[i32]) -> Vec<[usize; 2]> {
    assert_eq!(owner.len(), lattice.len(), "an owner per node");
    let (lx, ly) = (lattice.lx, lattice.ly);
    let mut pairs = Vec::new();
    for x in 0..lx {
        for y in 0..ly {
            let a = owner[x * ly + y];
            if a < 0 {
                continue;
            }
            for b in [owner[(x + 1) % lx * ly + y], owner[x * ly + (y + 1) % ly]] {
                if b >= 0 && b != a {
                    let (i, j) = (a.min(b) as usize, a.max(b) as usize);
                    pairs.push([i, j]);
                }
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// How many cells each of `n` cells touches, from the touching pairs `pairs` ([`contacts`]):
/// its coordination in the tessellation of the owned regions, the dual of the triangulation
/// of the centres, whose 5- and 7-fold cells are the tissue's disclinations.
pub fn neighbour_counts(pairs: &[[usize; 2]], n: usize) -> Vec<usize> {
    let mut counts = vec![0; n];
    for &[i, j] in pairs {
        counts[i] += 1;
        counts[j] += 1;
    }
    counts
}

/// The demixing parameter of the labels `label` (by cell) over the touching pairs `pairs`
/// (see the module docs); NaN without pairs or with fewer than two cells.
pub fn demixing(pairs: &[[usize; 2]], label: &[usize]) -> f64 {
    let n = label.len();
    if pairs.is_empty() || n < 2 {
        return f64::NAN;
    }
    let like = pairs.iter().filter(|[i, j]| label[*i] == label[*j]).count() as f64;
    let kinds = label.iter().copied().max().unwrap_or(0) + 1;
    let mut counts = vec![0usize; kinds];
    for &l in label {
        counts[l] += 1;
    }
    let expected = counts
        .iter()
        .map(|&c| (c * c.saturating_sub(1)) as f64)
        .sum::<f64>()
        / (n * (n - 1)) as f64;
    like / pairs.len() as f64 - expected
}

/// Which cells lie on a free boundary of the tissue: those owning a node that shares a lattice
/// edge with the outside, the largest connected region (edges, periodic) of nodes that no cell
/// owns (`owner` −1, index `x * ly + y`), counted as outside only when it has at least
/// `min_nodes` nodes. The gaps of a confluent tissue are far smaller than a cell (set
/// `min_nodes` to a cell's area, `πR²`), so a confluent tissue has no free boundary: every
/// entry false. `cells` is the number of cells.
///
/// # Panics
/// If `owner.len()` is not the lattice's size.
pub fn free_boundary(lattice: Lattice, owner: &[i32], cells: usize, min_nodes: usize) -> Vec<bool> {
    assert_eq!(owner.len(), lattice.len(), "an owner per node");
    let (lx, ly) = (lattice.lx, lattice.ly);
    let neighbours = |k: usize| {
        let (x, y) = (k / ly, k % ly);
        [
            (x + 1) % lx * ly + y,
            (x + lx - 1) % lx * ly + y,
            x * ly + (y + 1) % ly,
            x * ly + (y + ly - 1) % ly,
        ]
    };
    // The connected regions of unowned nodes, by flood fill; keep the largest.
    let mut region = vec![usize::MAX; owner.len()];
    let (mut largest, mut largest_size) = (usize::MAX, 0usize);
    let mut stack = Vec::new();
    for start in 0..owner.len() {
        if owner[start] >= 0 || region[start] != usize::MAX {
            continue;
        }
        region[start] = start;
        stack.push(start);
        let mut size = 0;
        while let Some(k) = stack.pop() {
            size += 1;
            for m in neighbours(k) {
                if owner[m] < 0 && region[m] == usize::MAX {
                    region[m] = start;
                    stack.push(m);
                }
            }
        }
        if size > largest_size {
            (largest, largest_size) = (start, size);
        }
    }
    let mut on = vec![false; cells];
    if largest_size < min_nodes.max(1) {
        return on;
    }
    for (k, &o) in owner.iter().enumerate() {
        if o >= 0 && neighbours(k).iter().any(|&m| region[m] == largest) {
            on[o as usize] = true;
        }
    }
    on
}

/// The radial order of a population in a free cluster: the mean distance of its cells'
/// centres from the cluster's centre, less that of all cells, over the latter. `centres` are
/// the cells' centres in a periodic box of `lx × ly` (the cluster's centre is the circular
/// mean along each axis, so a cluster across the box's edge is whole). 0 in expectation for
/// labels dealt at random; negative when the cells of `kind` gather inside (Steinberg's more
/// cohesive population), positive when they surround the others. NaN without cells of `kind`.
pub fn radial_excess(centres: &[[f64; 2]], label: &[usize], kind: usize, lx: f64, ly: f64) -> f64 {
    assert_eq!(centres.len(), label.len(), "a label per cell");
    if !label.contains(&kind) {
        return f64::NAN;
    }
    let tau = std::f64::consts::TAU;
    let centre = |axis: usize, l: f64| {
        let (s, c) = centres.iter().fold((0.0, 0.0), |(s, c), p| {
            let a = tau * p[axis] / l;
            (s + a.sin(), c + a.cos())
        });
        s.atan2(c).rem_euclid(tau) * l / tau
    };
    let (cx, cy) = (centre(0, lx), centre(1, ly));
    let wrap = |d: f64, l: f64| d - l * (d / l).round();
    let r: Vec<f64> = centres
        .iter()
        .map(|p| wrap(p[0] - cx, lx).hypot(wrap(p[1] - cy, ly)))
        .collect();
    let mean = |it: &mut dyn Iterator<Item = f64>| {
        let (s, n) = it.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
        s / n as f64
    };
    let all = mean(&mut r.iter().copied());
    let own = mean(
        &mut r
            .iter()
            .zip(label)
            .filter(|(_, &l)| l == kind)
            .map(|(&r, _)| r),
    );
    (own - all) / all
}

/// Whether a quantity grows, falls or neither over time, decided from independent runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trend {
    /// The mean over runs of each run's least-squares slope.
    pub slope: f64,
    /// Its standard error (the runs' spread over √runs).
    pub se: f64,
    /// The verdict: `Some(true)` grows, `Some(false)` falls, `None` not established.
    pub grows: Option<bool>,
}

/// The trend of a quantity from independent runs, each a series of `(time, value)`: each run's
/// least-squares slope, their mean and standard error; it grows when the mean exceeds
/// `z` standard errors, falls when it is below −`z` of them, and is not established
/// otherwise (nor with fewer than two runs of at least three points). Non-finite values are
/// left out.
pub fn trend(runs: &[Vec<(f64, f64)>], z: f64) -> Trend {
    let slopes: Vec<f64> = runs
        .iter()
        .filter_map(|run| {
            let pts: Vec<(f64, f64)> = run
                .iter()
                .copied()
                .filter(|(t, v)| t.is_finite() && v.is_finite())
                .collect();
            if pts.len() < 3 {
                return None;
            }
            let n = pts.len() as f64;
            let (mt, mv) = pts
                .iter()
                .fold((0.0, 0.0), |(a, b), (t, v)| (a + t / n, b + v / n));
            let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |(a, b), (t, v)| {
                (a + (t - mt) * (v - mv), b + (t - mt) * (t - mt))
            });
            (sxx > 0.0).then(|| sxy / sxx)
        })
        .collect();
    let k = slopes.len();
    if k < 2 {
        return Trend {
            slope: slopes.first().copied().unwrap_or(f64::NAN),
            se: f64::NAN,
            grows: None,
        };
    }
    let mean = slopes.iter().sum::<f64>() / k as f64;
    let var = slopes.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (k - 1) as f64;
    let se = (var / k as f64).sqrt();
    let grows = if mean > z * se {
        Some(true)
    } else if mean < -z * se {
        Some(false)
    } else {
        None
    };
    Trend {
        slope: mean,
        se,
        grows,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A disc of cells (4 × 4 blocks within 20 nodes of the box's centre) in an empty periodic
    /// box has a free boundary, its ring of outer cells, and a confluent box (every node
    /// owned, or gaps of one node) has none. The radial excess of an inner core (radius < 12)
    /// is negative and of its ring positive, the same anywhere in the box (the disc moved
    /// across the box's corner: to 1e-12), and labels dealt at random average to 0 within 3
    /// standard errors.
    #[test]
    fn a_free_cluster_and_the_radial_order_of_its_populations() {
        let lattice = Lattice::new(64, 64);
        let mut owner = vec![-1i32; 64 * 64];
        let mut centres = Vec::new();
        for bx in 0..16 {
            for by in 0..16 {
                let c = [bx as f64 * 4.0 + 2.0, by as f64 * 4.0 + 2.0];
                if (c[0] - 32.0).hypot(c[1] - 32.0) < 20.0 {
                    let id = centres.len() as i32;
                    centres.push(c);
                    for x in bx * 4..bx * 4 + 4 {
                        for y in by * 4..by * 4 + 4 {
                            owner[x * 64 + y] = id;
                        }
                    }
                }
            }
        }
        let n = centres.len();
        let on = free_boundary(lattice, &owner, n, 50);
        let ring = on.iter().filter(|&&b| b).count();
        assert!(ring > 10 && ring < n / 2, "{ring} of {n} on the boundary");
        let mut confluent: Vec<i32> = (0..64 * 64)
            .map(|k: i32| (k / 64) / 4 * 16 + (k % 64) / 4)
            .collect();
        confluent[5 * 64 + 5] = -1;
        assert!(free_boundary(lattice, &confluent, 256, 50)
            .iter()
            .all(|&b| !b));
        let core: Vec<usize> = centres
            .iter()
            .map(|c| usize::from((c[0] - 32.0).hypot(c[1] - 32.0) >= 12.0))
            .collect();
        let inside = radial_excess(&centres, &core, 0, 64.0, 64.0);
        let outside = radial_excess(&centres, &core, 1, 64.0, 64.0);
        assert!(inside < -0.3 && outside > 0.1, "{inside} {outside}");
        let moved: Vec<[f64; 2]> = centres
            .iter()
            .map(|c| [(c[0] + 32.0) % 64.0, (c[1] + 32.0) % 64.0])
            .collect();
        assert!((radial_excess(&moved, &core, 0, 64.0, 64.0) - inside).abs() < 1e-12);
        let mut state = 7u64;
        let draws: Vec<f64> = (0..400)
            .map(|_| {
                let label: Vec<usize> = (0..n)
                    .map(|_| {
                        state ^= state << 13;
                        state ^= state >> 7;
                        state ^= state << 17;
                        (state >> 63) as usize
                    })
                    .collect();
                radial_excess(&centres, &label, 0, 64.0, 64.0)
            })
            .collect();
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        let sd = (draws.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (draws.len() - 1) as f64)
            .sqrt();
        assert!(
            mean.abs() < 3.0 * sd / (draws.len() as f64).sqrt(),
            "{mean} ± {sd}"
        );
    }

    /// Square cells of 4 × 4 nodes on a 32 × 32 lattice (8 × 8 cells): each touches its four
    /// neighbours, 128 pairs. A checkerboard has no like pair (−E), two halves have all
    /// but the 16 pairs across the two boundaries, and a labelling dealt at random is within
    /// 4 standard errors of 0 over 200 draws.
    #[test]
    fn demixing_tells_sorted_from_mixed() {
        let lattice = Lattice::new(32, 32);
        let owner: Vec<i32> = (0..32 * 32)
            .map(|k: i32| (k / 32 / 4) * 8 + (k % 32) / 4)
            .collect();
        let pairs = contacts(lattice, &owner);
        assert_eq!(pairs.len(), 128);
        // Square cells on a torus are 4-fold; cell 9 merged into its neighbour 10 leaves 10
        // with 6 (its own 3 others and 9's 3), 9 with none, and the others with 4 (no cell
        // touched both).
        assert!(neighbour_counts(&pairs, 64).iter().all(|&c| c == 4));
        let merged: Vec<i32> = owner.iter().map(|&o| if o == 9 { 10 } else { o }).collect();
        let counts = neighbour_counts(&contacts(lattice, &merged), 64);
        assert_eq!((counts[9], counts[10], counts[1], counts[8]), (0, 6, 4, 4));
        let expected = 2.0 * (32.0 * 31.0) / (64.0 * 63.0);
        let checker: Vec<usize> = (0..64).map(|c| (c / 8 + c % 8) % 2).collect();
        assert!((demixing(&pairs, &checker) + expected).abs() < 1e-12);
        let halves: Vec<usize> = (0..64).map(|c| c / 32).collect();
        let d = demixing(&pairs, &halves);
        assert!((d - (112.0 / 128.0 - expected)).abs() < 1e-12, "{d}");
        let mut state = 99u64;
        let mut draws = Vec::new();
        for _ in 0..200 {
            let mut label: Vec<usize> = (0..64).map(|c| c / 32).collect();
            for i in (1..64).rev() {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                label.swap(i, (state % (i as u64 + 1)) as usize);
            }
            draws.push(demixing(&pairs, &label));
        }
        let m = draws.iter().sum::<f64>() / 200.0;
        let sd = (draws.iter().map(|d| (d - m).powi(2)).sum::<f64>() / 199.0).sqrt();
        assert!(
            m.abs() < 4.0 * sd / 200f64.sqrt(),
            "random labels: {m} ± {sd}"
        );
    }

    /// The trend rule gives each verdict on series built for it: five runs growing at 1e-4
    /// per unit time with noise 1e-3 grow, the same falling fall, and flat noisy runs are not
    /// established; one run decides nothing.
    #[test]
    fn the_trend_rule_gives_each_verdict() {
        let series = |slope: f64, seed: u64| {
            let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
            (0..50)
                .map(|k| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    let noise = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                    let t = 20.0 * k as f64;
                    (t, slope * t + 2e-3 * noise)
                })
                .collect::<Vec<_>>()
        };
        let runs = |slope| (1..=5).map(|s| series(slope, s)).collect::<Vec<_>>();
        assert_eq!(trend(&runs(1e-4), 3.0).grows, Some(true));
        assert_eq!(trend(&runs(-1e-4), 3.0).grows, Some(false));
        assert_eq!(trend(&runs(0.0), 3.0).grows, None);
        assert_eq!(trend(&runs(1e-4)[..1], 3.0).grows, None);
    }
}

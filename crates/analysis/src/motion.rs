//! How cells move and what shape they take: the mean squared displacement of tracked cells
//! in a periodic box, and the shape index `q = P/√A` of a cell's field.

use std::collections::HashMap;

/// One frame of tracked cells: its time, each cell's identity and centre.
#[derive(Debug, Clone, PartialEq)]
pub struct Positions {
    /// The frame's time.
    pub time: f64,
    /// Each cell's identity (the same cell keeps it from frame to frame).
    pub ids: Vec<usize>,
    /// Each cell's centre, in the order of `ids`.
    pub centres: Vec<[f64; 2]>,
}

/// The mean squared displacement at one lag.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MsdPoint {
    /// The lag, in the frames' time units: the mean of `t(b) − t(a)` over the samples
    /// averaged (each pair of frames weighted by the cells present in both, as the MSD is;
    /// a pair of frames with no cell in common gives no sample and no lag), so that it is
    /// the time the MSD belongs to also when cells divide, die or leave, or the frames are
    /// not equally spaced.
    pub lag: f64,
    /// `⟨|Δr_i − ⟨Δr⟩|²⟩` over cells and time origins, `Δr_i = r_i(t + lag) − r_i(t)` and
    /// `⟨Δr⟩` its mean over the cells present in both frames: the tissue's drift removed, so
    /// that a tissue that migrates as a whole has no MSD of its own (its rearrangements
    /// remain).
    pub msd: f64,
    /// `⟨|Δr_i|²⟩`, the drift kept.
    pub msd_raw: f64,
    /// How many (cell, origin) pairs were averaged.
    pub samples: usize,
}

/// The mean squared displacement of the cells of `frames` (in time order, equally spaced or
/// not) at each lag of `k` frames, `k = 1, 2, …` up to half the frames (`⌈(F − 1)/2⌉`, so
/// that every lag has at least as many time origins as frames in it), averaged over every
/// time origin and every cell present at both ends. The cost is O(F² N) for F frames of N
/// cells.
///
/// Positions are unwrapped in the periodic box `[lx, ly]` (a step between consecutive frames
/// is taken as the shortest periodic image, so a cell must move less than half the box
/// between frames); a side of `f64::INFINITY` is not periodic. Each point has the MSD with the
/// tissue's drift removed and kept ([`MsdPoint`]), from one pass over the pairs.
pub fn msd(frames: &[Positions], box_size: [f64; 2]) -> Vec<MsdPoint> {
    // Unwrapped positions by identity, frame by frame.
    let mut raw: HashMap<usize, [f64; 2]> = HashMap::new();
    let mut unwrapped: Vec<HashMap<usize, [f64; 2]>> = Vec::with_capacity(frames.len());
    let shortest = |d: f64, side: f64| {
        if side.is_finite() {
            d - side * (d / side).round()
        } else {
            d
        }
    };
    for f in frames {
        let mut now = HashMap::with_capacity(f.ids.len());
        for (&id, &c) in f.ids.iter().zip(&f.centres) {
            let u = match (raw.get(&id), unwrapped.last().and_then(|l| l.get(&id))) {
                (Some(r), Some(u)) => [
                    u[0] + shortest(c[0] - r[0], box_size[0]),
                    u[1] + shortest(c[1] - r[1], box_size[1]),
                ],
                _ => c,
            };
            now.insert(id, u);
        }
        raw = f
            .ids
            .iter()
            .copied()
            .zip(f.centres.iter().copied())
            .collect();
        unwrapped.push(now);
    }
    (1..=frames.len() / 2)
        .map(|k| {
            let (mut sum, mut sum_raw, mut n, mut lag) = (0.0, 0.0, 0usize, 0.0);
            // (Each pair's lag weighted by its samples: the frames' times are the MSD's.)
            let origins = frames.len() - k;
            for t in 0..origins {
                let (a, b) = (&unwrapped[t], &unwrapped[t + k]);
                // In the frame's order of cells, so that the sums are the same on every call
                // (a map's own order is not).
                let pairs: Vec<[f64; 2]> = frames[t]
                    .ids
                    .iter()
                    .filter_map(|id| {
                        let (p, q) = (a.get(id)?, b.get(id)?);
                        Some([q[0] - p[0], q[1] - p[1]])
                    })
                    .collect();
                if pairs.is_empty() {
                    continue;
                }
                let m = pairs.len() as f64;
                let mean = pairs
                    .iter()
                    .fold([0.0, 0.0], |s, d| [s[0] + d[0] / m, s[1] + d[1] / m]);
                for d in &pairs {
                    sum += (d[0] - mean[0]).powi(2) + (d[1] - mean[1]).powi(2);
                    sum_raw += d[0].powi(2) + d[1].powi(2);
                }
                n += pairs.len();
                lag += pairs.len() as f64 * (frames[t + k].time - frames[t].time);
            }
            MsdPoint {
                lag: if n == 0 { f64::NAN } else { lag / n as f64 },
                msd: if n == 0 { f64::NAN } else { sum / n as f64 },
                msd_raw: if n == 0 { f64::NAN } else { sum_raw / n as f64 },
                samples: n,
            }
        })
        .collect()
}

/// The perimeter and area of one cell from its field `φ` on an `nx × ny` patch (index
/// `u * ny + v`): the perimeter `∫|∇φ|` (central differences; by the coarea formula the mean
/// length of the level sets of φ between 0 and 1, which is that of the contour φ = ½ for an
/// interface symmetric about it) and the area inside the contour φ = ½, each node counted by
/// the share of it on the inner side, `clamp(½ + (φ − ½)/|∇φ|, 0, 1)` (the signed distance to
/// the contour in nodes, to first order). `∫φ` would add about `0.8 π w²` for a tanh interface
/// of width `w`. The patch's edge rows, where φ ≈ 0, count as outside.
///
/// # Panics
/// If `phi` is not `nx * ny` long.
pub fn perimeter_and_area(phi: &[f64], nx: usize, ny: usize) -> (f64, f64) {
    assert_eq!(
        phi.len(),
        nx * ny,
        "a value of φ for every node of the patch"
    );
    let (mut perimeter, mut area) = (0.0, 0.0);
    for u in 1..nx.saturating_sub(1) {
        for v in 1..ny.saturating_sub(1) {
            let c = phi[u * ny + v];
            let gx = (phi[(u + 1) * ny + v] - phi[(u - 1) * ny + v]) / 2.0;
            let gy = (phi[u * ny + v + 1] - phi[u * ny + v - 1]) / 2.0;
            let grad = gx.hypot(gy);
            perimeter += grad;
            area += if grad > 1e-12 {
                (0.5 + (c - 0.5) / grad).clamp(0.0, 1.0)
            } else if c >= 0.5 {
                1.0
            } else {
                0.0
            };
        }
    }
    (perimeter, area)
}

/// The shape index `q = P/√A` of a cell ([`perimeter_and_area`]): `2√π ≈ 3.545` for a disc,
/// larger for elongated or irregular cells (the vertex and Voronoi models' solid–liquid
/// transition is near `q = 3.81`).
pub fn shape_index(phi: &[f64], nx: usize, ny: usize) -> f64 {
    let (p, a) = perimeter_and_area(phi, nx, ny);
    p / a.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(time: f64, ids: &[usize], centres: &[[f64; 2]]) -> Positions {
        Positions {
            time,
            ids: ids.to_vec(),
            centres: centres.to_vec(),
        }
    }

    /// Issue 53: the lag of each point is the time between the frames its samples come from,
    /// also when cells divide and die and the frames are unevenly spaced. A hand count: frames
    /// at t = 0, 1, 3, 4, 10; cells 0 and 1 from the start, 1 dies after t = 1, 0 divides
    /// at t = 3 into 2 and 3, and 2 dies after t = 4. On main the lag was the sum over the
    /// pairs of frames that had a cell in common divided by every pair (a lag of 2 frames read
    /// 1.0, its one pair's 3 over three origins, for a true 3).
    #[test]
    fn the_lag_is_the_time_of_the_samples_with_divisions_and_deaths() {
        let at = |t: f64, ids: &[usize]| frame(t, ids, &vec![[1.0, 1.0]; ids.len()]);
        let frames = vec![
            at(0.0, &[0, 1]),
            at(1.0, &[0, 1]),
            at(3.0, &[0]),
            at(4.0, &[2, 3]),
            at(10.0, &[3]),
        ];
        let m = msd(&frames, [50.0, 50.0]);
        assert_eq!(m.len(), 2);
        // Lag 1 frame: (0,1): ids 0 and 1, Δt 1, two samples; (1,3): id 0, Δt 2; (3,4):
        // none; (4,10): id 3, Δt 6. Samples 4, lag (2·1 + 2 + 6)/4 = 2.5.
        assert_eq!(m[0].samples, 4);
        assert!((m[0].lag - 2.5).abs() < 1e-12, "{:?}", m[0]);
        // Lag 2 frames: (0,3): id 0, Δt 3; (1,4): none; (3,10): none. One sample, lag 3.
        assert_eq!(m[1].samples, 1);
        assert!((m[1].lag - 3.0).abs() < 1e-12, "{:?}", m[1]);
    }

    /// Ballistic motion across a periodic edge gives `v² t²` exactly (drift kept); a common
    /// drift is removed in `msd`, and a cell that leaves is left out of later lags.
    #[test]
    fn the_msd_of_ballistic_cells_across_the_edge_is_v2_t2() {
        let side = 10.0;
        let frames: Vec<Positions> = (0..6)
            .map(|k| {
                let t = k as f64;
                // Cell 0 moves at (3, 4)/s (speed 5) and crosses the edges; cell 7 rests.
                let x = (1.0 + 3.0 * t).rem_euclid(side);
                let y = (9.0 + 4.0 * t).rem_euclid(side);
                frame(t, &[0, 7], &[[x, y], [5.0, 5.0]])
            })
            .collect();
        let m = msd(&frames, [side, side]);
        // Lags of 1 to 3 frames (half of the 6 frames).
        assert_eq!(m.len(), 3);
        for (k, p) in m.iter().enumerate() {
            let lag = (k + 1) as f64;
            assert!((p.lag - lag).abs() < 1e-12);
            // Half the cells move at speed 5: ⟨d²⟩ = 25 lag²/2.
            assert!((p.msd_raw - 12.5 * lag * lag).abs() < 1e-9, "{p:?}");
            assert_eq!(p.samples, 2 * (6 - k - 1));
        }
        // Both cells drifting together: nothing left with the drift removed.
        let moving: Vec<Positions> = (0..4)
            .map(|k| {
                let s = 2.5 * k as f64;
                frame(
                    k as f64,
                    &[1, 2],
                    &[[(1.0 + s) % side, 2.0], [(4.0 + s) % side, 7.0]],
                )
            })
            .collect();
        let m = msd(&moving, [side, side]);
        assert!(m.iter().all(|p| p.msd.abs() < 1e-20));
        assert!((m[0].msd_raw - 6.25).abs() < 1e-12);
    }

    /// The same frames give the same bits on every call: the sums run in the frames' order
    /// of cells, not in a hash map's (which differs from map to map, and made the last digits
    /// of `msd.csv` change between two analyses of one run).
    #[test]
    fn the_msd_is_the_same_on_every_call() {
        let frames: Vec<Positions> = (0..12)
            .map(|k| {
                let ids: Vec<usize> = (0..60).collect();
                let centres: Vec<[f64; 2]> = ids
                    .iter()
                    .map(|&i| {
                        let a = 0.37 * (i * i + 3 * k) as f64;
                        [
                            (5.0 * i as f64 + 1.3 * a.sin()) % 100.0,
                            (7.0 * i as f64 + 0.9 * a.cos() * k as f64) % 100.0,
                        ]
                    })
                    .collect();
                frame(k as f64, &ids, &centres)
            })
            .collect();
        let bits = |m: Vec<MsdPoint>| -> Vec<(u64, u64)> {
            m.iter()
                .map(|p| (p.msd.to_bits(), p.msd_raw.to_bits()))
                .collect()
        };
        let first = bits(msd(&frames, [100.0, 100.0]));
        for _ in 0..5 {
            assert_eq!(bits(msd(&frames, [100.0, 100.0])), first);
        }
    }

    /// A cell that appears or leaves counts only where it is present at both ends.
    #[test]
    fn cells_count_only_where_present_at_both_ends() {
        let frames = [
            frame(0.0, &[1], &[[0.0, 0.0]]),
            frame(1.0, &[1, 2], &[[1.0, 0.0], [5.0, 5.0]]),
            frame(2.0, &[2], &[[5.0, 7.0]]),
        ];
        let m = msd(&frames, [f64::INFINITY; 2]);
        // One lag (half of three frames): cell 1 from 0 to 1 (d² = 1), cell 2 from 1 to 2
        // (d² = 4).
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].samples, 2);
        assert!((m[0].msd_raw - 2.5).abs() < 1e-12);
        // Two frames give their one lag; one frame none.
        assert_eq!(msd(&frames[..2], [f64::INFINITY; 2]).len(), 1);
        assert!(msd(&frames[..1], [f64::INFINITY; 2]).is_empty());
        // Five frames, cell 1 only at both ends of lag 2 from t = 0 to 2: absent, so NaN.
        let five = [
            frame(0.0, &[1], &[[0.0, 0.0]]),
            frame(1.0, &[2], &[[5.0, 5.0]]),
            frame(2.0, &[3], &[[5.0, 7.0]]),
            frame(3.0, &[4], &[[5.0, 7.0]]),
            frame(4.0, &[5], &[[5.0, 7.0]]),
        ];
        let m = msd(&five, [f64::INFINITY; 2]);
        assert_eq!(m.len(), 2);
        assert!(m
            .iter()
            .all(|p| p.samples == 0 && p.msd.is_nan() && p.msd_raw.is_nan()));
    }

    /// A tanh disc of radius 8 has q = 2√π to 0.5 % (0.1 % measured); an ellipse of the same area with semi-axes
    /// in the ratio 4 has Ramanujan's perimeter over √A to 2 %.
    #[test]
    fn the_shape_index_of_a_disc_and_an_ellipse() {
        let (nx, ny) = (49usize, 49usize);
        let field = |a: f64, b: f64| -> Vec<f64> {
            let mut phi = vec![0.0; nx * ny];
            for u in 0..nx {
                for v in 0..ny {
                    let (x, y) = (u as f64 - 24.0, v as f64 - 24.0);
                    // Distance to the ellipse, to first order: (ρ − 1)·(the local radius).
                    let rho = ((x / a).powi(2) + (y / b).powi(2)).sqrt();
                    let r = (x * x + y * y).sqrt();
                    let d = if r > 0.0 {
                        (rho - 1.0) * r / rho
                    } else {
                        -a.min(b)
                    };
                    phi[u * ny + v] = 0.5 * (1.0 - (d / 2.5).tanh());
                }
            }
            phi
        };
        let q = shape_index(&field(8.0, 8.0), nx, ny);
        let disc = 2.0 * std::f64::consts::PI.sqrt();
        assert!((q / disc - 1.0).abs() < 0.005, "{q} against {disc}");
        let (a, b): (f64, f64) = (16.0, 4.0);
        let h = ((a - b) / (a + b)).powi(2);
        let ramanujan =
            std::f64::consts::PI * (a + b) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt()));
        let exact = ramanujan / (std::f64::consts::PI * a * b).sqrt();
        let q = shape_index(&field(a, b), nx, ny);
        assert!((q / exact - 1.0).abs() < 0.02, "{q} against {exact}");
        assert!(q > disc * 1.2);
    }
}

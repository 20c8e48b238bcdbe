//! Defect tracking between frames, with creation and annihilation counted in pairs.
//!
//! Between consecutive frames, defects of the same charge are linked by the assignment that
//! minimises the total periodic distance (Kuhn–Munkres), among links no longer than
//! `max_link`. A defect left unlinked in the new frame is born, one left unlinked in the old
//! frame has died. Births are then paired `+½` with `−½` by the same optimal assignment within
//! `max_pair`: each pair is one *creation* at the pair's midpoint; deaths are paired likewise
//! into *annihilations* (at the old positions). Births or deaths left without a partner
//! (a defect that crossed the detection threshold alone, or moved farther than `max_link`)
//! are counted as unpaired and not reported as events.

use pathfinding::kuhn_munkres::kuhn_munkres_min;
use pathfinding::matrix::Matrix;
use phasefield::Lattice;

use crate::defects::Defect;

/// Tracking distances.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TrackParams {
    /// Longest link of one defect between consecutive frames (default R: a defect moves far
    /// less than a cell radius between frames at the usual output intervals, and defects are
    /// several radii apart). Larger values link defects that are not the same one.
    pub max_link: f64,
    /// Largest separation of a created or annihilated pair (default 2R). Larger values pair
    /// births and deaths that are unrelated.
    pub max_pair: f64,
}

impl TrackParams {
    /// The given distances.
    pub const fn new(max_link: f64, max_pair: f64) -> Self {
        Self { max_link, max_pair }
    }

    /// The defaults for cells of radius `radius`: links within R, pairs within 2R.
    pub fn for_radius(radius: f64) -> Self {
        Self::new(radius, 2.0 * radius)
    }
}

/// What happened to defects between two frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// A `+½`/`−½` pair appeared.
    Creation,
    /// A `+½`/`−½` pair vanished.
    Annihilation,
}

impl EventKind {
    /// The name used in `defect_events.csv`.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Creation => "creation",
            EventKind::Annihilation => "annihilation",
        }
    }
}

/// A creation or annihilation of a pair, at the pair's midpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Creation or annihilation.
    pub kind: EventKind,
    /// Midpoint x.
    pub x: f64,
    /// Midpoint y.
    pub y: f64,
}

/// The result of adding one frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameTracks {
    /// Track id of every defect of the frame, in the order given.
    pub track: Vec<u64>,
    /// Pair events since the previous frame.
    pub events: Vec<Event>,
    /// Births and deaths that found no partner.
    pub unpaired: usize,
}

/// Links defects frame after frame.
#[derive(Debug, Clone)]
pub struct Tracker {
    lattice: Lattice,
    params: TrackParams,
    prev: Vec<(u64, Defect)>,
    next_id: u64,
}

/// Integer costs for Kuhn–Munkres: distances in units of 1e-9 nodes; links that are too long
/// cost more than any allowed assignment can.
fn assign(a: &[[f64; 2]], b: &[[f64; 2]], lattice: Lattice, max: f64) -> Vec<(usize, usize)> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let forbidden: i64 = 1 << 50;
    let cost = |p: [f64; 2], q: [f64; 2]| {
        let d = lattice.distance(p, q);
        if d <= max {
            (d * 1e9).round() as i64
        } else {
            forbidden
        }
    };
    let transpose = a.len() > b.len();
    let (rows, cols) = if transpose { (b, a) } else { (a, b) };
    let m = Matrix::from_fn(rows.len(), cols.len(), |(i, j)| cost(rows[i], cols[j]));
    let (_, assignment) = kuhn_munkres_min(&m);
    assignment
        .into_iter()
        .enumerate()
        .filter(|&(i, j)| m[(i, j)] < forbidden)
        .map(|(i, j)| if transpose { (j, i) } else { (i, j) })
        .collect()
}

fn midpoint(lattice: Lattice, p: [f64; 2], q: [f64; 2]) -> [f64; 2] {
    lattice.wrap_point([
        p[0] + 0.5 * lattice.delta_x(p[0], q[0]),
        p[1] + 0.5 * lattice.delta_y(p[1], q[1]),
    ])
}

fn pos(d: &Defect) -> [f64; 2] {
    [d.x, d.y]
}

impl Tracker {
    /// A tracker with no history.
    pub fn new(lattice: Lattice, params: TrackParams) -> Self {
        Self {
            lattice,
            params,
            prev: Vec::new(),
            next_id: 0,
        }
    }

    /// Adds the defects of the next frame and links them to the previous one.
    pub fn push(&mut self, defects: &[Defect]) -> FrameTracks {
        let mut track = vec![u64::MAX; defects.len()];
        let mut prev_linked = vec![false; self.prev.len()];
        for sign in [0.5, -0.5] {
            let old: Vec<usize> = (0..self.prev.len())
                .filter(|&i| self.prev[i].1.charge == sign)
                .collect();
            let new: Vec<usize> = (0..defects.len())
                .filter(|&i| defects[i].charge == sign)
                .collect();
            let a: Vec<[f64; 2]> = old.iter().map(|&i| pos(&self.prev[i].1)).collect();
            let b: Vec<[f64; 2]> = new.iter().map(|&i| pos(&defects[i])).collect();
            for (i, j) in assign(&a, &b, self.lattice, self.params.max_link) {
                track[new[j]] = self.prev[old[i]].0;
                prev_linked[old[i]] = true;
            }
        }
        let mut out = FrameTracks::default();
        // Births and deaths of ±½ defects, paired into events.
        let born = |s: f64| -> Vec<[f64; 2]> {
            (0..defects.len())
                .filter(|&i| track[i] == u64::MAX && defects[i].charge == s)
                .map(|i| pos(&defects[i]))
                .collect()
        };
        let died = |s: f64| -> Vec<[f64; 2]> {
            (0..self.prev.len())
                .filter(|&i| !prev_linked[i] && self.prev[i].1.charge == s)
                .map(|i| pos(&self.prev[i].1))
                .collect()
        };
        for (kind, plus, minus) in [
            (EventKind::Creation, born(0.5), born(-0.5)),
            (EventKind::Annihilation, died(0.5), died(-0.5)),
        ] {
            let pairs = assign(&plus, &minus, self.lattice, self.params.max_pair);
            out.unpaired += plus.len() + minus.len() - 2 * pairs.len();
            for (i, j) in pairs {
                let m = midpoint(self.lattice, plus[i], minus[j]);
                out.events.push(Event {
                    kind,
                    x: m[0],
                    y: m[1],
                });
            }
        }
        for t in track.iter_mut() {
            if *t == u64::MAX {
                *t = self.next_id;
                self.next_id += 1;
            }
        }
        self.prev = track.iter().copied().zip(defects.iter().copied()).collect();
        out.track = track;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(x: f64, y: f64, charge: f64) -> Defect {
        Defect {
            x,
            y,
            charge,
            angle: 0.0,
        }
    }

    #[test]
    fn a_pair_is_created_moves_and_annihilates_across_the_edge() {
        let lattice = Lattice::new(50, 50);
        let mut t = Tracker::new(
            lattice,
            TrackParams {
                max_link: 4.0,
                max_pair: 10.0,
            },
        );
        let f0 = t.push(&[d(20.5, 20.5, 0.5)]);
        assert!(
            f0.events.is_empty() && f0.unpaired == 1,
            "the first frame's defects are unpaired births"
        );
        // A pair appears across the x edge, next to the old defect.
        let f1 = t.push(&[d(21.5, 20.5, 0.5), d(49.5, 3.5, 0.5), d(1.5, 3.5, -0.5)]);
        assert_eq!(
            f1.events,
            vec![Event {
                kind: EventKind::Creation,
                x: 0.5,
                y: 3.5
            }]
        );
        assert_eq!(f1.track[0], f0.track[0]);
        // They move apart and back, then vanish.
        let f2 = t.push(&[d(22.5, 20.5, 0.5), d(47.5, 3.5, 0.5), d(3.5, 4.5, -0.5)]);
        assert!(f2.events.is_empty() && f2.unpaired == 0);
        assert_eq!(&f2.track[1..], &f1.track[1..]);
        let f3 = t.push(&[d(22.5, 21.5, 0.5), d(49.5, 4.5, 0.5), d(0.5, 4.5, -0.5)]);
        assert!(f3.events.is_empty());
        let f4 = t.push(&[d(23.5, 21.5, 0.5)]);
        assert_eq!(f4.events.len(), 1);
        assert_eq!(f4.events[0].kind, EventKind::Annihilation);
        assert!((f4.events[0].x - 0.0).abs() < 1e-12 || (f4.events[0].x - 50.0).abs() < 1e-12);
        assert_eq!(f4.track[0], f0.track[0]);
        assert_eq!(f4.unpaired, 0);
    }
}

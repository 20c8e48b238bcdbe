//! Initial states (docs/model.md §6): cell positions (random, hexagonal or given) and discs with a
//! tanh profile of width λ, smaller than the target radius.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::lattice::Lattice;
use crate::walls::WallField;
use crate::PhaseFieldError;
use crate::{Cells, PatchShape};

/// The largest fraction of the domain the initial discs may cover.
///
/// Random sequential adsorption of discs jams near 54.7 % coverage; beyond half the domain
/// placement becomes very slow or impossible, so the same bound applies to every layout.
pub const MAX_INITIAL_COVERAGE: f64 = 0.5;

/// How cells are placed initially.
#[derive(Debug, Clone, PartialEq)]
pub enum Layout {
    /// Uniformly random centres, reproducible from the seed, with no two initial discs
    /// overlapping (random sequential adsorption).
    Random {
        /// Seed of the ChaCha8 generator.
        seed: u64,
    },
    /// A (near-)hexagonal packing filling the domain row by row.
    Hexagonal,
    /// Centres given by the user.
    Positions(Vec<[f64; 2]>),
}

/// Checks that `n_cells` discs of radius `disc_radius` cover at most
/// [`MAX_INITIAL_COVERAGE`] of `free_nodes` nodes.
fn check_fits_in(
    free_nodes: usize,
    n_cells: usize,
    disc_radius: f64,
) -> Result<(), PhaseFieldError> {
    let disc = std::f64::consts::PI * disc_radius * disc_radius;
    let room = MAX_INITIAL_COVERAGE * free_nodes as f64;
    if n_cells as f64 * disc > room {
        return Err(PhaseFieldError::TooManyCells {
            n_cells,
            max_cells: (room / disc).floor() as usize,
            disc_radius,
        });
    }
    Ok(())
}

/// Checks that `n_cells` discs of radius `disc_radius` fit in the domain.
///
/// # Errors
/// [`PhaseFieldError::TooManyCells`] when they would cover more than [`MAX_INITIAL_COVERAGE`].
pub fn check_fits(
    lattice: Lattice,
    n_cells: usize,
    disc_radius: f64,
) -> Result<(), PhaseFieldError> {
    check_fits_in(lattice.len(), n_cells, disc_radius)
}

/// The centres of `n_cells` cells for a layout, with initial discs of radius `disc_radius`.
///
/// # Errors
/// [`PhaseFieldError::TooManyCells`] if the discs do not fit, and
/// [`PhaseFieldError::BadPositions`] for given positions of the wrong count or off the domain.
pub fn positions(
    lattice: Lattice,
    n_cells: usize,
    disc_radius: f64,
    layout: &Layout,
) -> Result<Vec<[f64; 2]>, PhaseFieldError> {
    positions_clear_of(lattice, n_cells, disc_radius, layout, None)
}

/// The distance from a wall at which a centre may be placed: the initial disc and one node
/// more, so that no disc starts in a wall's solid.
pub fn wall_clearance(disc_radius: f64) -> f64 {
    disc_radius + 1.0
}

/// [`positions`] with walls: every centre at least [`wall_clearance`] from the solid of
/// `walls` (random and hexagonal layouts place only there; given positions are checked).
/// The coverage bound counts the free nodes only.
///
/// # Errors
/// As [`positions`], and [`PhaseFieldError::BadPositions`] for a given centre too close to a
/// wall.
pub fn positions_clear_of(
    lattice: Lattice,
    n_cells: usize,
    disc_radius: f64,
    layout: &Layout,
    walls: Option<&WallField>,
) -> Result<Vec<[f64; 2]>, PhaseFieldError> {
    let clear = |p: [f64; 2]| walls.is_none_or(|w| w.distance_at(p) >= wall_clearance(disc_radius));
    let free_nodes = walls.map_or(lattice.len(), |w| w.free_nodes());
    let fits = || check_fits_in(free_nodes, n_cells, disc_radius);
    match layout {
        Layout::Positions(p) => {
            if p.len() != n_cells {
                return Err(PhaseFieldError::BadPositions(format!(
                    "{} positions given for {} cells",
                    p.len(),
                    n_cells
                )));
            }
            for (i, q) in p.iter().enumerate() {
                if !(q[0].is_finite() && q[1].is_finite())
                    || q[0] < 0.0
                    || q[1] < 0.0
                    || q[0] >= lattice.lx as f64
                    || q[1] >= lattice.ly as f64
                {
                    return Err(PhaseFieldError::BadPositions(format!(
                        "position {i} = [{}, {}] lies outside the domain [0, {}) × [0, {})",
                        q[0], q[1], lattice.lx, lattice.ly
                    )));
                }
            }
            if let Some(i) = p.iter().position(|&q| !clear(q)) {
                return Err(PhaseFieldError::BadPositions(format!(
                    "position {i} = [{}, {}] is {:.1} nodes from a wall, closer than the initial disc ({:.1} nodes with its edge)",
                    p[i][0],
                    p[i][1],
                    walls.map_or(0.0, |w| w.distance_at(p[i])),
                    wall_clearance(disc_radius)
                )));
            }
            Ok(p.clone())
        }
        Layout::Random { seed } => {
            fits()?;
            let mut rng = ChaCha8Rng::seed_from_u64(*seed);
            let mut out: Vec<[f64; 2]> = Vec::with_capacity(n_cells);
            let min_dist = 2.0 * disc_radius;
            // Accepted centres binned in a grid of bins at least min_dist wide: a candidate
            // is checked against the 3 × 3 bins around it only, so placement is O(N).
            // Wider bins are still correct; at most about 4N bins, whatever the radius.
            let most = 2 * ((n_cells as f64).sqrt().ceil() as usize) + 1;
            let (bx, by) = (
                ((lattice.lx as f64 / min_dist).floor() as usize).clamp(1, most),
                ((lattice.ly as f64 / min_dist).floor() as usize).clamp(1, most),
            );
            let mut bins: Vec<Vec<usize>> = vec![Vec::new(); bx * by];
            let bin_of = |p: [f64; 2]| -> (usize, usize) {
                (
                    ((p[0] / lattice.lx as f64 * bx as f64) as usize).min(bx - 1),
                    ((p[1] / lattice.ly as f64 * by as f64) as usize).min(by - 1),
                )
            };
            let max_tries = 10_000 * (n_cells + 1);
            let mut tries = 0;
            while out.len() < n_cells {
                tries += 1;
                if tries > max_tries {
                    return Err(PhaseFieldError::TooManyCells {
                        n_cells,
                        max_cells: out.len(),
                        disc_radius,
                    });
                }
                let p = [
                    rng.random_range(0.0..lattice.lx as f64),
                    rng.random_range(0.0..lattice.ly as f64),
                ];
                if !clear(p) {
                    continue;
                }
                let (ix, iy) = bin_of(p);
                let mut free = true;
                'near: for dx in [bx - 1, 0, 1] {
                    for dy in [by - 1, 0, 1] {
                        let b = ((ix + dx) % bx) * by + (iy + dy) % by;
                        if bins[b]
                            .iter()
                            .any(|&q| lattice.distance(out[q], p) < min_dist)
                        {
                            free = false;
                            break 'near;
                        }
                    }
                }
                if free {
                    bins[ix * by + iy].push(out.len());
                    out.push(p);
                }
            }
            Ok(out)
        }
        Layout::Hexagonal => {
            fits()?;
            let len = lattice.len() as f64;
            if walls.is_none() {
                return Ok(hexagonal(lattice, n_cells, len));
            }
            // With walls: a packing of the domain at the density of the free area, made
            // denser step by step until enough of its sites are clear of the walls.
            let mut area = free_nodes as f64;
            for _ in 0..200 {
                let n_sites = ((n_cells as f64 * len / area).ceil() as usize).max(n_cells);
                let sites: Vec<_> = hexagonal(lattice, n_sites, len)
                    .into_iter()
                    .filter(|&p| clear(p))
                    .collect();
                if sites.len() >= n_cells {
                    return Ok(spread(sites, n_cells));
                }
                area *= 0.97;
            }
            Err(PhaseFieldError::TooManyCells {
                n_cells,
                max_cells: 0,
                disc_radius,
            })
        }
    }
}

/// `n` of `sites` spread evenly through the list (which runs row by row).
fn spread(sites: Vec<[f64; 2]>, n: usize) -> Vec<[f64; 2]> {
    let m = sites.len();
    (0..n).map(|k| sites[k * m / n]).collect()
}

/// A near-hexagonal packing of `n_cells` sites filling the domain row by row, at the density
/// `n_cells / area`.
fn hexagonal(lattice: Lattice, n_cells: usize, area: f64) -> Vec<[f64; 2]> {
    // Rows of spacing dy = dx·√3/2 with the aspect ratio of the domain.
    let (lx, ly) = (lattice.lx as f64, lattice.ly as f64);
    let per_cell = area / n_cells as f64;
    let dx = (2.0 * per_cell / 3f64.sqrt()).sqrt();
    let mut n_cols = ((lx / dx).round() as usize).max(1);
    let mut n_rows = n_cells.div_ceil(n_cols);
    if n_cols * n_rows < n_cells {
        n_cols += 1;
        n_rows = n_cells.div_ceil(n_cols);
    }
    let (sx, sy) = (lx / n_cols as f64, ly / n_rows as f64);
    let mut out = Vec::with_capacity(n_cells);
    'rows: for r in 0..n_rows {
        for c in 0..n_cols {
            if out.len() == n_cells {
                break 'rows;
            }
            let shift = if r % 2 == 1 { 0.5 } else { 0.0 };
            out.push(lattice.wrap_point([(c as f64 + 0.25 + shift) * sx, (r as f64 + 0.5) * sy]));
        }
    }
    out
}

/// Cells shaped as discs `φ = (1 − tanh((d − r₀)/λ))/2` of radius `r₀ = disc_radius` around
/// `centres`, each patch centred on the node nearest to its centre.
pub fn discs(
    lattice: Lattice,
    shape: PatchShape,
    centres: &[[f64; 2]],
    disc_radius: f64,
    lambda: f64,
) -> Cells {
    let mut cells = Cells::zeros(lattice, shape, centres);
    let (phi, map, shape) = cells.split_mut();
    let (nx, ny) = (shape.nx, shape.ny);
    for (i, c) in centres.iter().enumerate() {
        let xs = map.cell_x(shape, i);
        let ys = map.cell_y(shape, i);
        let cell = &mut phi[i * nx * ny..(i + 1) * nx * ny];
        for (a, &x) in xs.iter().enumerate() {
            let dx = lattice.delta_x(c[0], x as f64);
            for (b, &y) in ys.iter().enumerate() {
                let dy = lattice.delta_y(c[1], y as f64);
                let d = dx.hypot(dy);
                cell[a * ny + b] = 0.5 * (1.0 - ((d - disc_radius) / lambda).tanh());
            }
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_positions_are_reproducible_and_separated() {
        let lattice = Lattice::new(100, 100);
        let a = positions(lattice, 60, 4.0, &Layout::Random { seed: 7 }).unwrap();
        let b = positions(lattice, 60, 4.0, &Layout::Random { seed: 7 }).unwrap();
        let c = positions(lattice, 60, 4.0, &Layout::Random { seed: 8 }).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        for i in 0..a.len() {
            for j in 0..i {
                assert!(lattice.distance(a[i], a[j]) >= 8.0);
            }
        }
    }

    #[test]
    fn hexagonal_places_every_cell_inside() {
        let lattice = Lattice::new(100, 100);
        let p = positions(lattice, 60, 4.0, &Layout::Hexagonal).unwrap();
        assert_eq!(p.len(), 60);
        let mut dmin = f64::MAX;
        for i in 0..p.len() {
            for j in 0..i {
                dmin = dmin.min(lattice.distance(p[i], p[j]));
            }
        }
        assert!(dmin > 10.0, "cells too close: {dmin}");
    }

    #[test]
    fn too_many_cells_is_an_error() {
        let lattice = Lattice::new(50, 50);
        let e = positions(lattice, 200, 4.0, &Layout::Random { seed: 1 }).unwrap_err();
        assert!(matches!(e, PhaseFieldError::TooManyCells { .. }));
    }
}

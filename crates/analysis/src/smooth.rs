//! Smoothing by a periodic sliding box (docs/model.md §7: side `3R`, applied to `v`, `ω` and `Q`
//! before correlations and defects).
//!
//! The box mean `f̄(x, y) = (1/w²) Σ_{|i|,|j| ≤ h} f(x+i, y+j)`, `w = 2h + 1`, is separable:
//! a running sum along y, then along x, each updated in O(1) per node, so the cost is O(L²)
//! whatever the box side.

use phasefield::Lattice;

use crate::AnalysisError;

/// Box mean of side `side` (odd, at most the smaller lattice side) with periodic wrap.
///
/// # Errors
/// [`AnalysisError::BadBox`] for an even side or one larger than the lattice.
pub fn box_smooth(lattice: Lattice, field: &[f64], side: usize) -> Result<Vec<f64>, AnalysisError> {
    let mut out = vec![0.0; field.len()];
    box_smooth_into(lattice, field, side, &mut out, &mut vec![0.0; field.len()])?;
    Ok(out)
}

/// [`box_smooth`] into `out`, with a lattice-sized `scratch`; allocates nothing.
///
/// # Errors
/// As [`box_smooth`].
///
/// # Panics
/// If a slice is not `lattice.len()` long.
pub fn box_smooth_into(
    lattice: Lattice,
    field: &[f64],
    side: usize,
    out: &mut [f64],
    scratch: &mut [f64],
) -> Result<(), AnalysisError> {
    let (lx, ly) = (lattice.lx, lattice.ly);
    if side.is_multiple_of(2) || side > lx.min(ly) {
        return Err(AnalysisError::BadBox { side, lx, ly });
    }
    assert!(
        field.len() == lattice.len()
            && out.len() == lattice.len()
            && scratch.len() == lattice.len()
    );
    let h = side / 2;
    // Along y, row by row (contiguous).
    for x in 0..lx {
        let row = &field[x * ly..(x + 1) * ly];
        let dst = &mut scratch[x * ly..(x + 1) * ly];
        let mut s: f64 = (0..side).map(|j| row[(j + ly - h) % ly]).sum();
        for y in 0..ly {
            dst[y] = s;
            s += row[(y + h + 1) % ly] - row[(y + ly - h) % ly];
        }
    }
    // Along x.
    let norm = 1.0 / (side * side) as f64;
    for y in 0..ly {
        let mut s: f64 = (0..side)
            .map(|i| scratch[((i + lx - h) % lx) * ly + y])
            .sum();
        for x in 0..lx {
            out[x * ly + y] = s * norm;
            s += scratch[((x + h + 1) % lx) * ly + y] - scratch[((x + lx - h) % lx) * ly + y];
        }
    }
    Ok(())
}

/// The odd box side nearest to `3R`, as the paper smooths (docs/model.md §7).
pub fn paper_box_side(radius: f64) -> usize {
    let s = (3.0 * radius).round() as usize;
    if s.is_multiple_of(2) {
        s + 1
    } else {
        s.max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_smoothing_equals_the_direct_sum() {
        let lattice = Lattice::new(13, 10);
        let f: Vec<f64> = (0..130)
            .map(|k| ((k * 7919) % 101) as f64 / 101.0 - 0.3)
            .collect();
        for side in [1, 3, 5, 9] {
            let s = box_smooth(lattice, &f, side).unwrap();
            let h = side as i64 / 2;
            for x in 0..13 {
                for y in 0..10 {
                    let mut d = 0.0;
                    for i in -h..=h {
                        for j in -h..=h {
                            d += f[lattice
                                .index(lattice.wrap_x(x as i64 + i), lattice.wrap_y(y as i64 + j))];
                        }
                    }
                    d /= (side * side) as f64;
                    // Running sums accumulate round-off over one lattice side: ~L ε.
                    assert!(
                        (s[lattice.index(x, y)] - d).abs() < 1e-13,
                        "side {side} at ({x}, {y})"
                    );
                }
            }
        }
        assert!(box_smooth(lattice, &f, 4).is_err());
        assert!(box_smooth(lattice, &f, 11).is_err());
    }

    #[test]
    fn paper_box_is_odd() {
        assert_eq!(paper_box_side(8.0), 25);
        assert_eq!(paper_box_side(7.0), 21);
        assert_eq!(paper_box_side(6.0), 19);
    }
}

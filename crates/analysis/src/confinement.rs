//! Observables of confined tissues: how much of a region the cells cover (a wound's gap),
//! the flow profile across a channel and its shear, and the rotation of cells about a disc's centre.

/// The share of the nodes of `region` (a mask, index `x * ly + y`) where the cells' total
/// `s1 = Σ_i φ_i` is below ½: the open part of a wound. NaN for an empty region.
///
/// # Panics
/// If `s1` and `region` differ in length.
pub fn uncovered_fraction(s1: &[f64], region: &[bool]) -> f64 {
    assert_eq!(s1.len(), region.len(), "a value of s1 for every node");
    let (mut open, mut all) = (0usize, 0usize);
    for (&s, &r) in s1.iter().zip(region) {
        if r {
            all += 1;
            if s < 0.5 {
                open += 1;
            }
        }
    }
    if all == 0 {
        f64::NAN
    } else {
        open as f64 / all as f64
    }
}

/// The mean of a lattice field over x at each y (index `x * ly + y`, `lx * ly` long): the
/// profile `⟨v_x⟩(y)` across a channel along x.
///
/// # Panics
/// If the field is not `lx * ly` long.
pub fn mean_over_x(field: &[f64], lx: usize, ly: usize) -> Vec<f64> {
    assert_eq!(field.len(), lx * ly, "a value for every node");
    let mut out = vec![0.0; ly];
    for column in field.chunks_exact(ly) {
        for (o, v) in out.iter_mut().zip(column) {
            *o += v;
        }
    }
    out.iter_mut().for_each(|o| *o /= lx as f64);
    out
}

/// The shear across a channel along x from its profile `⟨v_x⟩(y)` (`ly` rows,
/// [`mean_over_x`]): half the difference of the mean over the rows above the middle line
/// `y = (ly − 1)/2` and the mean over the rows below it (the middle row of an odd `ly` is
/// left out). The antisymmetric part of the profile: zero for a plug flow and for any
/// profile symmetric about the middle; for a linear shear `v_x = s (y − (ly − 1)/2)` it is
/// `s·ly/4` (even `ly`) or `s·(ly + 1)/4` (odd): the mean speed of each half. Its sign is
/// that of `∂v_x/∂y`. NaN for fewer than two rows.
pub fn shear_across(profile: &[f64]) -> f64 {
    let ly = profile.len();
    let half = ly / 2;
    if half == 0 {
        return f64::NAN;
    }
    let lower: f64 = profile[..half].iter().sum::<f64>() / half as f64;
    let upper: f64 = profile[ly - half..].iter().sum::<f64>() / half as f64;
    0.5 * (upper - lower)
}

/// The angular order parameter of cells about `centre`:
/// `Ω = ⟨(r_i × v_i) / (|r_i| |v_i|)⟩` over the cells, `r_i` the cell's position from the
/// centre and `v_i` its velocity. `Ω = ±1` when every cell moves along its circle
/// (counterclockwise positive), 0 on average for undirected motion (its spread is then about
/// `1/√(2N)`, the sine of a uniform angle having variance ½). Cells at the centre or at rest
/// are left out; NaN when none is left.
///
/// # Panics
/// If `centres` and `velocities` differ in length.
pub fn angular_order(centres: &[[f64; 2]], velocities: &[[f64; 2]], centre: [f64; 2]) -> f64 {
    assert_eq!(centres.len(), velocities.len(), "a velocity for every cell");
    let (mut sum, mut n) = (0.0, 0usize);
    for (c, v) in centres.iter().zip(velocities) {
        let r = [c[0] - centre[0], c[1] - centre[1]];
        let norm = r[0].hypot(r[1]) * v[0].hypot(v[1]);
        if norm > 0.0 {
            sum += (r[0] * v[1] - r[1] * v[0]) / norm;
            n += 1;
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

    /// The shear of a linear profile is the mean speed of each half, exactly; a plug flow and
    /// a profile symmetric about the middle have none; reversing the profile reverses it.
    #[test]
    fn the_shear_is_the_antisymmetric_part_of_the_profile() {
        for ly in [8usize, 9, 30, 31] {
            let mid = (ly as f64 - 1.0) / 2.0;
            let s = 0.013;
            let linear: Vec<f64> = (0..ly).map(|y| s * (y as f64 - mid) + 0.2).collect();
            let want = s * (ly + ly % 2) as f64 / 4.0;
            assert!((shear_across(&linear) - want).abs() < 1e-15, "{ly}");
            let reversed: Vec<f64> = linear.iter().rev().copied().collect();
            assert!((shear_across(&reversed) + want).abs() < 1e-15);
            let poiseuille: Vec<f64> = (0..ly)
                .map(|y| 1.0 - ((y as f64 - mid) / mid).powi(2))
                .collect();
            assert!(shear_across(&poiseuille).abs() < 1e-15, "{ly}");
            assert_eq!(shear_across(&vec![0.7; ly]), 0.0);
        }
        assert!(shear_across(&[1.0]).is_nan());
    }

    #[test]
    fn the_angular_order_is_one_for_a_rigid_rotation_and_zero_for_a_radial_flow() {
        let centre = [10.0, 20.0];
        let angles: Vec<f64> = (0..7).map(|k| 0.9 * k as f64).collect();
        let at: Vec<[f64; 2]> = angles
            .iter()
            .enumerate()
            .map(|(k, a)| {
                let r = 1.0 + k as f64;
                [centre[0] + r * a.cos(), centre[1] + r * a.sin()]
            })
            .collect();
        // A rigid rotation ω ẑ × r, counterclockwise: Ω = +1; clockwise: −1.
        let spin = |w: f64| -> Vec<[f64; 2]> {
            at.iter()
                .map(|p| [-w * (p[1] - centre[1]), w * (p[0] - centre[0])])
                .collect()
        };
        assert!((angular_order(&at, &spin(0.3), centre) - 1.0).abs() < 1e-15);
        assert!((angular_order(&at, &spin(-2.0), centre) + 1.0).abs() < 1e-15);
        // Radial motion has no angular part.
        let radial: Vec<[f64; 2]> = at
            .iter()
            .map(|p| [p[0] - centre[0], p[1] - centre[1]])
            .collect();
        assert!(angular_order(&at, &radial, centre).abs() < 1e-15);
        // A cell at rest or at the centre is left out.
        let mut v = spin(1.0);
        v.push([0.0, 0.0]);
        let mut c = at.clone();
        c.push([0.0, 0.0]);
        assert!((angular_order(&c, &v, centre) - 1.0).abs() < 1e-15);
        assert!(angular_order(&[centre], &[[1.0, 0.0]], centre).is_nan());
    }

    #[test]
    fn the_uncovered_fraction_counts_the_region_only() {
        let s1 = [0.0, 1.0, 0.2, 0.9, 0.0, 0.0];
        let region = [true, true, true, true, false, false];
        assert_eq!(uncovered_fraction(&s1, &region), 0.5);
        assert!(uncovered_fraction(&s1, &[false; 6]).is_nan());
    }

    #[test]
    fn a_profile_averages_each_row() {
        // lx = 2, ly = 3: columns (1, 2, 3) and (3, 4, 5).
        let f = [1.0, 2.0, 3.0, 3.0, 4.0, 5.0];
        assert_eq!(mean_over_x(&f, 2, 3), vec![2.0, 3.0, 4.0]);
    }
}

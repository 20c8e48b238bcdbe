//! Observables of confined tissues: how much of a region the cells cover (a wound's gap),
//! and the flow profile across a channel.

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

#[cfg(test)]
mod tests {
    use super::*;

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

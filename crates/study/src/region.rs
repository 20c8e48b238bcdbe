//! Where the tissue is: the nodes where cells cover the smoothing box and `Q` is not noise,
//! and the defects there. `render` draws the director and defects only there, and `analyze`
//! counts only those defects, so both read this one rule.

use analysis::defects::detect;
use analysis::smooth::box_smooth;
use analysis::AnalysisError;

/// The least share of the smoothing box that cells must cover (box-smoothed `Σ φ_i`) for
/// `render` to draw the director and defects there: half, so that the thin gaps at cell
/// junctions count as tissue and the gaps between initial discs (a third covered at the
/// paper's density and R/2 discs) do not.
pub const TISSUE_COVER: f64 = 0.5;

/// The least smoothed `|Q|` where `render` draws the director and defects: a twentieth of the
/// deformation of a cell in a confluent tissue at the paper's parameters (`|S_i|` ≈ 1–2), far
/// above that of the round initial discs (zero but for the lattice's anisotropy).
pub const TISSUE_Q: f64 = 0.05;

/// Where `render` draws the director (a mask over the nodes) and which defects of the smoothed
/// `Q` (`qxx`, `qxy`) it draws: where cells cover at least [`TISSUE_COVER`] of the smoothing box
/// of side `side` (`phi_sum` is `Σ φ_i`), and `|Q|` is at least [`TISSUE_Q`], at the node for the
/// director and averaged over the box around a defect (`|Q|` vanishes at a defect's core).
///
/// # Errors
/// A box that does not fit the lattice.
pub fn in_tissue(
    l: phasefield::Lattice,
    side: usize,
    phi_sum: &[f64],
    qxx: &[f64],
    qxy: &[f64],
) -> Result<(Vec<bool>, Vec<analysis::defects::Defect>), AnalysisError> {
    let smooth = |v: &[f64]| box_smooth(l, v, side);
    let cover = smooth(phi_sum)?;
    let q_mag: Vec<f64> = qxx.iter().zip(qxy).map(|(a, b)| a.hypot(*b)).collect();
    let q_around = smooth(&q_mag)?;
    let tissue = (0..cover.len())
        .map(|k| cover[k] >= TISSUE_COVER && q_mag[k] >= TISSUE_Q)
        .collect();
    let defects = detect(l, qxx, qxy)
        .into_iter()
        .filter(|d| {
            let x = (d.x.round() as usize) % l.lx;
            let y = (d.y.round() as usize) % l.ly;
            let k = x * l.ly + y;
            cover[k] >= TISSUE_COVER && q_around[k] >= TISSUE_Q
        })
        .collect();
    Ok((tissue, defects))
}

#[cfg(test)]
mod tests {
    use super::*;
    use phasefield::Lattice;

    /// A `+½` defect near the centre of a 40² lattice: `Q = s (cos 2θ, sin 2θ)` with
    /// `θ = ½ atan2(y, x)` about it, `s` the magnitude.
    fn plus_half(l: Lattice, s: f64) -> (Vec<f64>, Vec<f64>) {
        let (mut qxx, mut qxy) = (vec![0.0; l.len()], vec![0.0; l.len()]);
        for x in 0..l.lx {
            for y in 0..l.ly {
                let phi = (y as f64 - 20.3).atan2(x as f64 - 20.3);
                qxx[x * l.ly + y] = s * phi.cos();
                qxy[x * l.ly + y] = s * phi.sin();
            }
        }
        (qxx, qxy)
    }

    /// The defect is drawn in covered, ordered tissue; not where cells cover a third of the
    /// box (the gaps between initial discs), nor where `|Q|` is below the threshold (round
    /// discs); the director mask follows the same rules node by node.
    #[test]
    fn defects_and_the_director_are_drawn_only_in_tissue() {
        let l = Lattice::new(40, 40);
        let full = vec![1.0; l.len()];
        let sparse = vec![0.3; l.len()];
        let (qxx, qxy) = plus_half(l, 1.0);
        let (mask, d) = in_tissue(l, 9, &full, &qxx, &qxy).unwrap();
        // Every defect of the field is kept (the periodic seams add three to the one placed).
        assert_eq!(d, detect(l, &qxx, &qxy));
        assert!(d
            .iter()
            .any(|d| (d.x - 20.5).abs() < 1.0 && (d.charge - 0.5).abs() < 1e-12));
        assert!(mask.iter().filter(|&&m| m).count() > l.len() - 10);
        let (mask, d) = in_tissue(l, 9, &sparse, &qxx, &qxy).unwrap();
        assert!(d.is_empty() && mask.iter().all(|&m| !m));
        let (weak_xx, weak_xy) = plus_half(l, 0.5 * TISSUE_Q);
        let (mask, d) = in_tissue(l, 9, &full, &weak_xx, &weak_xy).unwrap();
        assert!(d.is_empty() && mask.iter().all(|&m| !m));
    }
}

//! The check of the `[[population]]` tables.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// The `[[population]]` tables: counts that add up, each override in range, polarity keys only with `[polarity]`.
pub(crate) fn population(file: &SceneFile) -> Result<(), SceneError> {
    if !file.population.is_empty() {
        let total: usize = file.population.iter().map(|p| p.count).sum();
        if total != file.cells.count {
            return Err(invalid(
                "population",
                "count",
                total,
                format!(
                    "the populations' counts add up to {total}, but [cells] count = {}",
                    file.cells.count
                ),
                format!(
                    "make the counts add up to {}, or set [cells] count = {total}",
                    file.cells.count
                ),
            ));
        }
        for (k, p) in file.population.iter().enumerate() {
            let which = format!("population {k} ({})", p.name(k));
            let checks: [(&'static str, Option<f64>, bool, &str); 12] = [
                (
                    "gamma",
                    p.gamma,
                    p.gamma.is_none_or(|v| v.is_finite() && v >= 0.0),
                    "zero or positive (paper: 0.01)",
                ),
                (
                    "mu",
                    p.mu,
                    p.mu.is_none_or(|v| v.is_finite() && v >= 0.0),
                    "zero or positive (paper: 3)",
                ),
                (
                    "radius",
                    p.radius,
                    p.radius.is_none_or(|v| v.is_finite() && v >= 1.0),
                    "at least one node (paper: 8)",
                ),
                (
                    "xi",
                    p.xi,
                    p.xi.is_none_or(|v| v.is_finite() && v > 0.0),
                    "positive (paper: 2)",
                ),
                (
                    "zeta",
                    p.zeta,
                    p.zeta.is_none_or(f64::is_finite),
                    "a finite number, e.g. between -0.01 and 0.01",
                ),
                (
                    "alpha",
                    p.alpha,
                    p.alpha.is_none_or(f64::is_finite),
                    "a finite number, e.g. 0.04",
                ),
                (
                    "rotational_diffusion",
                    p.rotational_diffusion,
                    p.rotational_diffusion
                        .is_none_or(|v| v.is_finite() && v >= 0.0),
                    "zero or positive",
                ),
                (
                    "align_rate",
                    p.align_rate,
                    p.align_rate.is_none_or(|v| v.is_finite() && v >= 0.0),
                    "zero or positive",
                ),
                (
                    "nematic_zeta",
                    p.nematic_zeta,
                    p.nematic_zeta.is_none_or(f64::is_finite),
                    "a finite number, e.g. between -0.01 and 0.01",
                ),
                (
                    "nematic_align_rate",
                    p.nematic_align_rate,
                    p.nematic_align_rate
                        .is_none_or(|v| v.is_finite() && v >= 0.0),
                    "zero or positive",
                ),
                (
                    "nematic_elastic",
                    p.nematic_elastic,
                    p.nematic_elastic.is_none_or(|v| v.is_finite() && v >= 0.0),
                    "zero or positive",
                ),
                (
                    "nematic_rotational_diffusion",
                    p.nematic_rotational_diffusion,
                    p.nematic_rotational_diffusion
                        .is_none_or(|v| v.is_finite() && v >= 0.0),
                    "zero or positive",
                ),
            ];
            for (key, value, ok, want) in checks {
                if !ok {
                    return Err(invalid(
                        "population",
                        key,
                        value.unwrap_or(f64::NAN),
                        format!("in {which}, {key} must be {want}"),
                        format!("give {key} = a value {want}, or remove it to take the scene's"),
                    ));
                }
            }
            if file.polarity.is_none() {
                let polar = [
                    ("alpha", p.alpha),
                    ("rotational_diffusion", p.rotational_diffusion),
                    ("align_rate", p.align_rate),
                ];
                if let Some((key, Some(v))) = polar.into_iter().find(|(_, v)| v.is_some()) {
                    return Err(invalid(
                        "population",
                        key,
                        v,
                        format!("{which} sets a polarity parameter, but the scene has no [polarity]"),
                        "add a [polarity] table (alpha = 0 for cells that do not propel themselves), or remove the key",
                    ));
                }
            }
            let keys = [
                "nematic_zeta",
                "nematic_align_rate",
                "nematic_elastic",
                "nematic_rotational_diffusion",
            ];
            let own = keys
                .iter()
                .zip(p.nematic_values())
                .find_map(|(k, v)| v.map(|v| (*k, v)));
            if let (None, Some((key, v))) = (&file.nematic, own) {
                return Err(invalid(
                    "population",
                    key,
                    v,
                    format!("{which} sets a parameter of the cells' nematic, but the scene has no [nematic]"),
                    "add a [nematic] table (zeta = 0 for the other populations), or remove the key",
                ));
            }
        }
    }
    Ok(())
}

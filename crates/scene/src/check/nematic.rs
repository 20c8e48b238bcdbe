//! The check of `[nematic]`.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// `[nematic]`: each key in range, and an alignment rate only with a target.
pub(crate) fn nematic(file: &SceneFile) -> Result<(), SceneError> {
    let Some(n) = &file.nematic else {
        return Ok(());
    };
    let checks: [(&str, f64, bool, &str); 6] = [
        (
            "zeta",
            n.zeta,
            n.zeta.is_finite(),
            "the nematic's activity must be a finite number: give one of the order of [model] zeta (e.g. 0.005 extensile, -0.005 contractile)",
        ),
        (
            "order",
            n.order,
            n.order.is_finite() && n.order >= 0.0,
            "the magnitude S of each cell's nematic must be zero or positive: use 1",
        ),
        (
            "align_rate",
            n.align_rate,
            n.align_rate.is_finite() && n.align_rate >= 0.0,
            "the alignment rate must be zero or positive: use a rate of order 0.1, or 0 for none",
        ),
        (
            "elastic",
            n.elastic,
            n.elastic.is_finite() && n.elastic >= 0.0,
            "the elastic constant must be zero or positive (a negative one turns a nematic away from its neighbours'): use a rate of order 0.01, or 0 for none",
        ),
        (
            "vorticity",
            n.vorticity,
            n.vorticity.is_finite(),
            "the coupling to the flow's rotation must be a finite number: 1 corotates the nematic with the flow, 0 ignores it",
        ),
        (
            "rotational_diffusion",
            n.rotational_diffusion,
            n.rotational_diffusion.is_finite() && n.rotational_diffusion >= 0.0,
            "the rotational diffusion constant must be zero or positive: use 1/(persistence time), or 0 for none",
        ),
    ];
    for (key, value, ok, why) in checks {
        if !ok {
            let (problem, fix) = why.split_once(": ").expect("a problem and a fix");
            return Err(invalid("nematic", key, value, problem, fix));
        }
    }
    super::alignment("nematic", n.align, n.align_rate)?;
    super::initial_angle("nematic", n.angle)
}

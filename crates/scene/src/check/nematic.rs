//! The check of `[nematic]`.

use crate::error::{invalid, SceneError};
use crate::file::{AlignKind, SceneFile};

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
    if n.align_rate > 0.0 && n.align == AlignKind::None {
        return Err(invalid(
            "nematic",
            "align_rate",
            n.align_rate,
            "an alignment rate with align = \"none\" aligns to nothing",
            "set align = \"velocity\", \"force\" or \"shape\", or remove align_rate",
        ));
    }
    if let Some(a) = n.angle.filter(|a| !a.is_finite()) {
        return Err(invalid(
            "nematic",
            "angle",
            a,
            "the initial angle must be a finite number",
            "give it in radians (0 is along +x), or remove it for random angles",
        ));
    }
    Ok(())
}

/// `[friction]`: ξ_c zero or positive, and a tolerance the solver can reach.
pub(crate) fn friction(file: &SceneFile) -> Result<(), SceneError> {
    let Some(f) = &file.friction else {
        return Ok(());
    };
    if !(f.cells.is_finite() && f.cells >= 0.0) {
        return Err(invalid(
            "friction",
            "cells",
            f.cells,
            "the friction between cells must be zero or positive",
            "use ξ_c of order 0.01-1 per node of overlap (two touching cells of R = 8 overlap by about 2 nodes), or remove [friction]",
        ));
    }
    if !(f.tolerance > 1e-15 && f.tolerance <= 1e-3) {
        return Err(invalid(
            "friction",
            "tolerance",
            f.tolerance,
            "the solver's relative residual must be between 1e-15 and 1e-3",
            "use the default, 1e-10",
        ));
    }
    Ok(())
}

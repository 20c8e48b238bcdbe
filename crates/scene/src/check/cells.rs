//! The check of `[cells]`.

use crate::error::{invalid, SceneError};
use crate::file::{InitKind, SceneFile};
use phasefield::Lattice;

/// The cells: count, radius, initial radius, and the layout's keys (`positions`, `from`).
pub(crate) fn cells(file: &SceneFile) -> Result<(), SceneError> {
    let d = &file.domain;
    let c = &file.cells;
    if c.count == 0 {
        return Err(invalid(
            "cells",
            "count",
            0,
            "a scene needs at least one cell",
            "set count to 1 or more",
        ));
    }
    if !(c.radius.is_finite() && c.radius > 0.0) {
        return Err(invalid(
            "cells",
            "radius",
            c.radius,
            "the radius must be positive",
            "use a radius of a few nodes (paper: 8)",
        ));
    }
    if c.radius.is_finite() && c.radius < 1.0 {
        return Err(invalid(
            "cells",
            "radius",
            c.radius,
            "a cell smaller than one node cannot be resolved",
            "use a radius of a few nodes (paper: 8)",
        ));
    }
    let r0 = file.init_radius();
    if c.init_radius.is_none() && r0 < 1.0 {
        return Err(invalid(
            "cells",
            "radius",
            c.radius,
            format!(
                "the initial discs (radius R/2 = {r0} by default) must be at least one node wide"
            ),
            "use a radius of 2 or more (paper: 8), or set init_radius = 1",
        ));
    }
    if !(r0.is_finite() && r0 >= 1.0 && r0 <= c.radius) {
        return Err(invalid(
            "cells",
            "init_radius",
            r0,
            "the initial disc radius must be at least one node (a smaller disc covers no node) and at most the radius",
            format!(
                "leave it out (default R/2) or choose a value in [1, {}]",
                c.radius
            ),
        ));
    }
    if let (InitKind::Positions, Some(p)) = (c.init, &c.positions) {
        if p.len() != c.count {
            return Err(invalid(
                "cells",
                "positions",
                format!("[{} pairs]", p.len()),
                format!("count = {} cells but {} positions", c.count, p.len()),
                "give one [x, y] pair per cell, or set count to the number of positions",
            ));
        }
        // Two discs whose centres are closer than their radius start stacked: nothing
        // separates two identical fields at one place (the force between them is zero by
        // symmetry), so the run would go on with one cell on top of another.
        let periodic = Lattice::new(d.lx, d.ly);
        for i in 0..p.len() {
            for j in 0..i {
                let dist = periodic.distance(p[i], p[j]);
                if dist < r0 {
                    return Err(invalid(
                        "cells",
                        "positions",
                        format!("[..., {:?}, ..., {:?}, ...]", p[j], p[i]),
                        format!(
                            "cells {j} and {i} are {dist:.3} nodes apart (periodically), closer than the initial radius {r0}: they would start stacked"
                        ),
                        format!("place the centres at least {r0} apart (2R = {} for cells that just touch)", 2.0 * c.radius),
                    ));
                }
            }
        }
    }
    match (c.init, &c.positions) {
        (InitKind::Positions, None) => {
            return Err(invalid(
                "cells",
                "init",
                "\"positions\"",
                "no positions are given",
                "add positions = [[x, y], ...] with one pair per cell",
            ));
        }
        (InitKind::Random | InitKind::Hexagonal | InitKind::Frame, Some(_)) => {
            return Err(invalid(
                "cells",
                "positions",
                "[...]",
                "positions are only read with init = \"positions\"",
                "set init = \"positions\" or remove positions",
            ));
        }
        _ => {}
    }
    match (c.init, c.from.as_deref()) {
        (InitKind::Frame, None) => {
            return Err(invalid(
                "cells",
                "init",
                "\"frame\"",
                "no saved state is given",
                "add from = \"RUN/frames/frame_STEP.npz\" (or a checkpoint, RUN/checkpoints/checkpoint_STEP.npz)",
            ));
        }
        (InitKind::Frame, Some(f)) if f.trim().is_empty() => {
            return Err(invalid(
                "cells",
                "from",
                "\"\"",
                "the path is empty",
                "give the frame or checkpoint to start from, e.g. from = \"out/relaxed/frames/frame_00001000.npz\"",
            ));
        }
        (InitKind::Random | InitKind::Hexagonal | InitKind::Positions, Some(f)) => {
            return Err(invalid(
                "cells",
                "from",
                format!("{f:?}"),
                "a saved state is only read with init = \"frame\"",
                "set init = \"frame\" or remove from",
            ));
        }
        _ => {}
    }
    Ok(())
}

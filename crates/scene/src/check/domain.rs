//! The check of `[domain]`.

use crate::error::{invalid, SceneError, MAX_SIDE};
use crate::file::SceneFile;

/// The lattice: each side at least 8 nodes and at most [`MAX_SIDE`].
pub(crate) fn domain(file: &SceneFile) -> Result<(), SceneError> {
    let d = &file.domain;
    for (key, v) in [("lx", d.lx), ("ly", d.ly)] {
        if v < 8 {
            return Err(invalid(
                "domain",
                key,
                v,
                "the domain is too small",
                "use at least 8 nodes per side (the paper uses 100)",
            ));
        }
        if v > MAX_SIDE {
            return Err(invalid(
                "domain",
                key,
                v,
                format!("a side of more than {MAX_SIDE} nodes cannot be simulated (a {MAX_SIDE}² lattice alone takes tens of GB)"),
                "use at most 65536 nodes per side (the paper uses 100; 3840 cells fit in 800²)",
            ));
        }
    }
    Ok(())
}

//! The check of `[walls]`.

use crate::error::{invalid, SceneError};
use crate::file::SceneFile;

/// A wound needs a relaxation to open after (the geometry is checked when the walls are built, `crate::walls::walls_of`).
pub(crate) fn walls(file: &SceneFile) -> Result<(), SceneError> {
    if let Some(spec) = &file.walls {
        if spec.kind == crate::file::WallKind::Wound && file.run.relax_time <= 0.0 {
            return Err(invalid(
                "run",
                "relax_time",
                file.run.relax_time,
                "a wound ([walls] kind = \"wound\") is the band the cells relax beside, removed when the relaxation ends; with no relaxation it is removed before the first step, so the run would have no wound at all",
                "set [run] relax_time > 0 (scenes/wound.toml uses 200), or remove [walls] for a run without a wound",
            ));
        }
    }
    Ok(())
}

//! The file paths a scene names, made absolute so that the resolved scene names the same
//! files from anywhere.

use std::path::Path;

/// The scene's file paths, `[cells] from` and `[walls] mask`, made absolute, as overrides
/// appended to `set`: a relative path given with `--set KEY=P` is taken from the current
/// directory, one in the scene file from the scene file's directory, so that the resolved
/// scene (`DIR/scene.toml`, a sweep's points, a SLURM task) names the same file from anywhere.
///
/// A scene that does not parse is left as it is (its validation reports it).
///
/// # Errors
/// The current directory cannot be read.
pub fn absolute_paths(
    scene_path: &Path,
    text: &str,
    set: &[String],
) -> std::io::Result<Vec<String>> {
    const KEYS: [&str; 2] = ["cells.from", "walls.mask"];
    let mut set = set.to_vec();
    let cwd = std::env::current_dir()?;
    let quoted = |key: &str, p: &Path| {
        let s = p.to_string_lossy();
        let escaped = s.replace('\\', "\\\\").replace('"', "\\\"");
        format!("{key}=\"{escaped}\"")
    };
    for o in &mut set {
        if let Some((k, v)) = o.split_once('=') {
            let k = k.trim();
            if KEYS.contains(&k) {
                let v = v.trim().trim_matches('"');
                // An empty path is left for the validation to name.
                if !v.is_empty() && Path::new(v).is_relative() {
                    *o = quoted(k, &cwd.join(v));
                }
            }
        }
    }
    if let Ok(file) = crate::SceneFile::parse(text, &set) {
        let base = scene_path.parent().unwrap_or(Path::new(""));
        let paths = [
            file.cells.from.as_deref(),
            file.walls.as_ref().and_then(|w| w.mask.as_deref()),
        ];
        for (key, path) in KEYS.iter().zip(paths) {
            if let Some(p) = path {
                if !p.trim().is_empty() && Path::new(p).is_relative() {
                    set.push(quoted(key, &cwd.join(base).join(p)));
                }
            }
        }
    }
    Ok(set)
}

//! What a sweep was asked, kept in its directory (`sweep/scene.toml` and `sweep/args.txt`),
//! so that `monolayer sweep --collect DIR` needs nothing else.

use std::fmt;
use std::path::Path;

use crate::plan::{plan, Point, Seeds, Vary};
use crate::SweepError;

/// A sweep's scene text, overrides, axes and seeds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SweepSpec {
    /// The scene file's text.
    pub scene_text: String,
    /// `--set` overrides, applied to every point.
    pub sets: Vec<String>,
    /// The axes.
    pub varies: Vec<Vary>,
    /// The seeds.
    pub seeds: Option<Seeds>,
}

impl fmt::Display for Vary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.key, self.values.join(","))
    }
}

impl fmt::Display for Seeds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}-{}", self.first, self.last)
    }
}

impl SweepSpec {
    /// The points of the sweep ([`plan`]).
    ///
    /// # Errors
    /// As [`plan`].
    pub fn plan(&self) -> Result<Vec<Point>, SweepError> {
        plan(&self.scene_text, &self.sets, &self.varies, self.seeds)
    }

    /// The keys of the axes, the first columns of `summary.csv`.
    pub fn keys(&self) -> Vec<String> {
        self.varies.iter().map(|v| v.key.clone()).collect()
    }

    /// Writes the spec into `dir/sweep/`.
    ///
    /// # Errors
    /// When the files cannot be written.
    pub fn save(&self, dir: &Path) -> Result<(), SweepError> {
        let d = dir.join("sweep");
        let io = |path: &Path, source| SweepError::write("the sweep's record", path, source);
        std::fs::create_dir_all(&d).map_err(|e| io(&d, e))?;
        let mut args = String::new();
        for s in &self.sets {
            args += &format!("--set {s}\n");
        }
        for v in &self.varies {
            args += &format!("--vary {v}\n");
        }
        if let Some(s) = self.seeds {
            args += &format!("--seeds {s}\n");
        }
        let (scene, list) = (d.join("scene.toml"), d.join("args.txt"));
        std::fs::write(&scene, &self.scene_text).map_err(|e| io(&scene, e))?;
        std::fs::write(&list, args).map_err(|e| io(&list, e))
    }

    /// Reads the spec that [`SweepSpec::save`] wrote into `dir/sweep/`.
    ///
    /// # Errors
    /// [`SweepError::NoRecord`] when `dir` holds no sweep, or a malformed record.
    pub fn load(dir: &Path) -> Result<Self, SweepError> {
        let d = dir.join("sweep");
        let none = || SweepError::NoRecord {
            dir: dir.to_path_buf(),
        };
        let scene_text = std::fs::read_to_string(d.join("scene.toml")).map_err(|_| none())?;
        let args = std::fs::read_to_string(d.join("args.txt")).map_err(|_| none())?;
        let mut spec = Self {
            scene_text,
            sets: Vec::new(),
            varies: Vec::new(),
            seeds: None,
        };
        for line in args.lines() {
            match line.split_once(' ') {
                Some(("--set", v)) => spec.sets.push(v.to_string()),
                Some(("--vary", v)) => spec.varies.push(v.parse()?),
                Some(("--seeds", v)) => spec.seeds = Some(v.parse()?),
                _ => return Err(none()),
            }
        }
        Ok(spec)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_saved_spec_loads_back_equal() {
        let dir = tempfile::tempdir().unwrap();
        let spec = SweepSpec {
            scene_text: "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 2\n".into(),
            sets: vec!["run.time=3".into(), "model.pressure=interaction".into()],
            varies: vec![
                "model.zeta=0,0.01".parse().unwrap(),
                "model.gamma=0.02".parse().unwrap(),
            ],
            seeds: Some("2-4".parse().unwrap()),
        };
        spec.save(dir.path()).unwrap();
        assert_eq!(SweepSpec::load(dir.path()).unwrap(), spec);
        let e = SweepSpec::load(&dir.path().join("nothing"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("holds no sweep"), "{e}");
    }
}

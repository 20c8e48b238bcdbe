//! The grid of a sweep: `--vary KEY=V1,V2,...` axes times a seed range, each point a valid
//! scene.

use std::str::FromStr;

use scene::Scene;

use crate::SweepError;

/// One axis of a sweep: a scene key and its values, as written (`model.zeta=0.004,0.006`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Vary {
    /// The key, `section.key`.
    pub key: String,
    /// The values, as TOML text.
    pub values: Vec<String>,
}

impl Vary {
    /// A key and its values, each given whole (from Python, say), checked as
    /// [`Vary::from_str`] checks `--vary KEY=V1,V2`; a value cannot hold a comma, which
    /// separates the values of `--vary` and of the sweep's saved arguments.
    ///
    /// # Errors
    /// [`SweepError::BadVary`], naming the key and what to change.
    pub fn new(key: &str, values: Vec<String>) -> Result<Self, SweepError> {
        let arg = format!("{key}={}", values.join(","));
        let bad = |why: &str| SweepError::BadVary {
            arg: arg.clone(),
            why: why.to_string(),
        };
        if let Some(v) = values.iter().find(|v| v.contains(',')) {
            return Err(bad(&format!(
                "the value {v:?} holds a ',', which separates a sweep's values; sweep a key whose values have no comma"
            )));
        }
        let key = key.trim();
        if !key.contains('.') || key.starts_with('.') || key.ends_with('.') {
            return Err(bad("the key needs a section, e.g. model.zeta"));
        }
        let values: Vec<String> = values.iter().map(|v| v.trim().to_string()).collect();
        if values.is_empty() {
            return Err(bad("no value: give at least one"));
        }
        if values.iter().any(|v| v.is_empty()) {
            return Err(bad("a value is empty"));
        }
        if values
            .iter()
            .any(|v| v.contains(['/', '\\', ' ', '_']) || v.chars().any(char::is_control))
        {
            return Err(bad(
                "values name run directories: no '/', '\\', '_' or spaces",
            ));
        }
        let mut seen = values.clone();
        seen.sort();
        seen.dedup();
        if seen.len() != values.len() {
            return Err(bad("a value is repeated"));
        }
        Ok(Self {
            key: key.to_string(),
            values,
        })
    }
}

impl FromStr for Vary {
    type Err = SweepError;

    fn from_str(s: &str) -> Result<Self, SweepError> {
        let (key, values) = s.split_once('=').ok_or_else(|| SweepError::BadVary {
            arg: s.to_string(),
            why: "no '='".to_string(),
        })?;
        Self::new(key, values.split(',').map(str::to_string).collect()).map_err(|e| match e {
            SweepError::BadVary { why, .. } => SweepError::BadVary {
                arg: s.to_string(),
                why,
            },
            other => other,
        })
    }
}

/// A range of seeds, `A-B` (inclusive) or `A`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Seeds {
    /// The first seed.
    pub first: u64,
    /// The last seed (inclusive).
    pub last: u64,
}

impl FromStr for Seeds {
    type Err = SweepError;

    fn from_str(s: &str) -> Result<Self, SweepError> {
        let bad = || SweepError::BadSeeds { arg: s.to_string() };
        let (a, b) = s.split_once('-').unwrap_or((s, s));
        let (first, last): (u64, u64) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if last < first || last - first >= 10_000 {
            return Err(bad());
        }
        Ok(Self { first, last })
    }
}

/// One run of a sweep: its directory name, its values on each axis, its seed and its scene.
#[derive(Debug, Clone)]
pub struct Point {
    /// The name of its directory under `runs/`: `key=value` for each axis, then `seed=S`,
    /// joined by `_`.
    pub name: String,
    /// The value on each axis, in the order of the axes.
    pub values: Vec<String>,
    /// The seed (`[run] seed`).
    pub seed: u64,
    /// The valid scene.
    pub scene: Scene,
}

/// The points of a sweep of `scene_text` (with the overrides `sets` applied first) over the
/// axes `varies` and the seeds: the last axis varies fastest, seeds fastest of all. Without
/// seeds, the scene's own `[run] seed` is used.
///
/// # Errors
/// A repeated axis, or a point whose scene is invalid (the error names the point).
pub fn plan(
    scene_text: &str,
    sets: &[String],
    varies: &[Vary],
    seeds: Option<Seeds>,
) -> Result<Vec<Point>, SweepError> {
    for (i, v) in varies.iter().enumerate() {
        if varies[..i].iter().any(|w| w.key == v.key) || v.key == "run.seed" {
            return Err(SweepError::BadVary {
                arg: v.key.clone(),
                why: "each key may be varied once, and seeds go in --seeds".into(),
            });
        }
    }
    let base = Scene::parse(scene_text, sets).map_err(|source| SweepError::Scene {
        point: "the base scene".into(),
        source: Box::new(source),
    })?;
    let seed_list: Vec<u64> = match seeds {
        Some(s) => (s.first..=s.last).collect(),
        None => vec![base.file().run.seed],
    };
    let mut combos: Vec<Vec<String>> = vec![Vec::new()];
    for v in varies {
        combos = combos
            .into_iter()
            .flat_map(|c| {
                v.values.iter().map(move |x| {
                    let mut c = c.clone();
                    c.push(x.clone());
                    c
                })
            })
            .collect();
    }
    let mut points = Vec::with_capacity(combos.len() * seed_list.len());
    for combo in combos {
        for &seed in &seed_list {
            let mut overrides = sets.to_vec();
            let mut parts = Vec::new();
            for (v, x) in varies.iter().zip(&combo) {
                overrides.push(format!("{}={x}", v.key));
                parts.push(format!("{}={x}", v.key));
            }
            overrides.push(format!("run.seed={seed}"));
            parts.push(format!("seed={seed}"));
            let name = parts.join("_");
            let scene =
                Scene::parse(scene_text, &overrides).map_err(|source| SweepError::Scene {
                    point: name.clone(),
                    source: Box::new(source),
                })?;
            points.push(Point {
                name,
                values: combo.clone(),
                seed,
                scene,
            });
        }
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "[domain]\nlx = 64\nly = 64\n[cells]\ncount = 2\n[run]\ntime = 1\n";

    #[test]
    fn the_grid_is_the_product_of_the_axes_and_the_seeds_in_order() {
        let varies: Vec<Vary> = ["model.zeta=0.001,0.002", "model.gamma=0.01,0.02,0.03"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let seeds: Seeds = "3-4".parse().unwrap();
        let points = plan(SCENE, &[], &varies, Some(seeds)).unwrap();
        assert_eq!(points.len(), 2 * 3 * 2);
        assert_eq!(points[0].name, "model.zeta=0.001_model.gamma=0.01_seed=3");
        assert_eq!(points[1].name, "model.zeta=0.001_model.gamma=0.01_seed=4");
        assert_eq!(points[2].name, "model.zeta=0.001_model.gamma=0.02_seed=3");
        assert_eq!(points[11].name, "model.zeta=0.002_model.gamma=0.03_seed=4");
        let last = points[11].scene.file();
        assert_eq!(
            (last.model.zeta, last.model.gamma, last.run.seed),
            (0.002, 0.03, 4)
        );
        let mut names: Vec<_> = points.iter().map(|p| p.name.clone()).collect();
        names.dedup();
        assert_eq!(names.len(), 12, "every point has its own directory");
    }

    /// The resolved scene of a point parses back to itself: a run of `runs/NAME/scene.toml`
    /// (the SLURM backend's) is the run of the point, and its `complete` mark matches.
    #[test]
    fn a_points_resolved_scene_is_a_fixed_point() {
        let v: Vec<Vary> = vec!["model.pressure=paper,interaction".parse().unwrap()];
        for p in plan(SCENE, &["model.zeta=0.003".into()], &v, None).unwrap() {
            let text = p.scene.to_toml();
            assert_eq!(Scene::parse(&text, &[]).unwrap().to_toml(), text);
        }
    }

    #[test]
    fn bad_axes_and_seeds_are_refused_with_the_argument() {
        for bad in [
            "zeta=1,2",
            "model.zeta",
            "model.zeta=1,,2",
            "model.zeta=1,1",
            "model.zeta=a/b",
        ] {
            let e = bad.parse::<Vary>().unwrap_err();
            assert!(e.to_string().contains(bad), "{e}");
        }
        for bad in ["x", "4-3", "1-2-3", "-1"] {
            assert!(bad.parse::<Seeds>().is_err(), "{bad}");
        }
        let twice: Vec<Vary> = ["model.zeta=1", "model.zeta=2"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        assert!(plan(SCENE, &[], &twice, None).is_err());
        // A point whose scene is invalid names the point and the key.
        let v: Vec<Vary> = vec!["model.lambda=2.5,-1".parse().unwrap()];
        let e = plan(SCENE, &[], &v, None).unwrap_err().to_string();
        assert!(
            e.contains("model.lambda=-1_seed=1") && e.contains("lambda"),
            "{e}"
        );
    }
}

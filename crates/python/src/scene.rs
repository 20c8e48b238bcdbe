//! `monolayer.Scene`: a scene file, its overrides and the validated scene, with the command
//! line's messages as `ValueError`s; and the points of a sweep.

use std::path::{Path, PathBuf};

use pyo3::exceptions::{PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// A scene: the text it was read from, the overrides set on it since, and the scene they
/// make, validated.
#[pyclass(module = "monolayer._native", name = "Scene", from_py_object)]
#[derive(Clone)]
pub struct PyScene {
    /// The scene file's text.
    pub(crate) text: String,
    /// The file it was read from, which relative paths in it are taken from.
    pub(crate) path: Option<PathBuf>,
    /// `section.key=value` overrides, in the order set.
    pub(crate) set: Vec<String>,
    /// The validated scene.
    pub(crate) scene: ::scene::Scene,
}

/// A scene error as the command line words it, as a `ValueError`.
pub(crate) fn scene_error(context: Option<&Path>, e: impl std::fmt::Display) -> PyErr {
    match context {
        Some(p) => PyValueError::new_err(format!("in scene {}: {e}", p.display())),
        None => PyValueError::new_err(e.to_string()),
    }
}

impl PyScene {
    fn build(text: String, path: Option<PathBuf>, set: Vec<String>) -> PyResult<Self> {
        let resolved = match &path {
            Some(p) => ::scene::absolute_paths(p, &text, &set).map_err(|e| {
                PyOSError::new_err(format!("cannot read the current directory: {e}"))
            })?,
            None => set.clone(),
        };
        let scene =
            ::scene::Scene::parse(&text, &resolved).map_err(|e| scene_error(path.as_deref(), e))?;
        Ok(Self {
            text,
            path,
            set,
            scene,
        })
    }
}

/// The kind of a NumPy scalar or 0-d array (`'b'`, `'i'`, `'u'`, `'f'`, ...), read from its
/// `dtype` without importing NumPy; `None` for anything else.
pub(crate) fn numpy_kind(v: &Bound<'_, PyAny>) -> Option<char> {
    let ndim: usize = v.getattr("ndim").ok()?.extract().ok()?;
    if ndim != 0 {
        return None;
    }
    let kind: String = v
        .getattr("dtype")
        .ok()?
        .getattr("kind")
        .ok()?
        .extract()
        .ok()?;
    kind.chars().next()
}

/// A Python value as a TOML value: bool, int, float, str, and lists and dicts of them, with
/// NumPy's scalars as the Python types they stand for.
fn to_toml(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let k: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("{key}: the keys of a table are strings"))
            })?;
            let sub = if key.is_empty() {
                k.clone()
            } else {
                format!("{key}.{k}")
            };
            t.insert(k, to_toml(&x, &sub)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, x) in v.try_iter()?.enumerate() {
            out.push(to_toml(&x?, &format!("{key}[{i}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    // NumPy scalars (and 0-d arrays) by their dtype's kind, so that `np.int64(60)` is an
    // integer and `np.bool_(True)` a bool where the scene takes one, as their Python types.
    if let Some(kind) = numpy_kind(v) {
        return match kind {
            'b' => Ok(toml::Value::Boolean(v.call_method0("__bool__")?.extract()?)),
            'i' | 'u' => Ok(toml::Value::Integer(
                v.call_method0("__index__")?.extract().map_err(|_| {
                    PyValueError::new_err(format!(
                        "{key}: {} does not fit a 64-bit integer",
                        v.str().map(|s| s.to_string()).unwrap_or_default()
                    ))
                })?,
            )),
            _ => Ok(toml::Value::Float(v.extract()?)),
        };
    }
    // Other numbers (`fractions.Fraction`, `decimal.Decimal`).
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    Err(PyTypeError::new_err(format!(
        "{key}: a {} is not a scene value; give a bool, int, float, str, list or dict",
        v.get_type().name()?
    )))
}

#[pymethods]
impl PyScene {
    /// A scene read from a TOML file; relative paths in it (`[cells] from`, `[walls] mask`)
    /// are taken from the file's directory.
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path).map_err(|e| {
            PyOSError::new_err(format!("cannot read scene file {}: {e}", path.display()))
        })?;
        Self::build(text, Some(path), Vec::new())
    }

    /// The resolved scene of a run directory (`DIR/scene.toml`), read to look at the run, not
    /// to step it: a `[terms.NAME]` table whose term this program does not register is kept
    /// (building a `Simulation` of it is refused by name).
    #[staticmethod]
    fn read_run(path: PathBuf) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path).map_err(|e| {
            PyOSError::new_err(format!("cannot read scene file {}: {e}", path.display()))
        })?;
        let scene = ::scene::SceneFile::parse(&text, &[])
            .and_then(|f| f.validate_for_reading())
            .map_err(|e| scene_error(Some(&path), e))?;
        Ok(Self {
            text,
            path: Some(path),
            set: Vec::new(),
            scene,
        })
    }

    /// A scene from TOML text.
    #[staticmethod]
    fn from_text(text: String) -> PyResult<Self> {
        Self::build(text, None, Vec::new())
    }

    /// A scene from a dict of tables, `{"domain": {"lx": 100, ...}, ...}`, as the TOML file
    /// would have them (a list of dicts for `population`).
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Self> {
        let toml::Value::Table(t) = to_toml(d.as_any(), "")? else {
            unreachable!("a dict is a table")
        };
        let text = toml::to_string(&t).map_err(|e| PyValueError::new_err(e.to_string()))?;
        Self::build(text, None, Vec::new())
    }

    /// Sets `key` (`section.key`, as `--set`) to `value`, validating the scene again;
    /// returns the scene, so that calls chain. A bad value raises `ValueError` and leaves the
    /// scene as it was.
    fn set<'py>(
        mut slf: PyRefMut<'py, Self>,
        key: &str,
        value: &Bound<'py, PyAny>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let v = to_toml(value, key)?;
        let mut set = slf.set.clone();
        set.push(format!("{key}={v}"));
        let next = Self::build(slf.text.clone(), slf.path.clone(), set)?;
        *slf = next;
        Ok(slf)
    }

    /// Sets several keys at once (`{"domain.lx": 50, "cells.count": 15}`), validating the
    /// scene once, after all of them; returns the scene.
    fn update<'py>(
        mut slf: PyRefMut<'py, Self>,
        values: &Bound<'py, PyDict>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let mut set = slf.set.clone();
        for (k, v) in values.iter() {
            let key: String = k.extract()?;
            set.push(format!("{key}={}", to_toml(&v, &key)?));
        }
        let next = Self::build(slf.text.clone(), slf.path.clone(), set)?;
        *slf = next;
        Ok(slf)
    }

    /// A copy of the scene, to change without changing this one.
    fn copy(&self) -> Self {
        self.clone()
    }

    /// The resolved scene as TOML: every key with its value, what `DIR/scene.toml` holds.
    fn to_toml(&self) -> String {
        self.scene.to_toml()
    }

    /// The model time at the end of the run, `relax_time + time`.
    #[getter]
    fn end_time(&self) -> f64 {
        self.scene.end_time()
    }

    /// The overrides set on the scene, as `section.key=value`.
    #[getter]
    fn overrides(&self) -> Vec<String> {
        self.set.clone()
    }

    /// Pickling (a process pool's arguments): the resolved scene's text, which names its
    /// files by absolute paths.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let cls = py.get_type::<PyScene>().getattr("from_text")?;
        Ok((cls, (self.scene.to_toml(),)))
    }

    fn __repr__(&self) -> String {
        let f = self.scene.file();
        format!(
            "Scene({}{} cells on {}×{}, to t = {})",
            self.path
                .as_ref()
                .map(|p| format!("{}: ", p.display()))
                .unwrap_or_default(),
            f.cells.count,
            f.domain.lx,
            f.domain.ly,
            self.scene.end_time()
        )
    }
}

/// The points of a sweep of `scene` over the axes `vary` (`{"model.zeta": [0.001, 0.002]}`)
/// and the seeds `first..=last`, with the sweep's description written into `out` (as
/// `monolayer sweep` writes it): `(name, scene, run directory)` for each point.
#[pyfunction]
#[pyo3(signature = (scene, vary, seeds=None, out=None))]
pub fn sweep_points(
    scene: &PyScene,
    vary: &Bound<'_, PyDict>,
    seeds: Option<(u64, u64)>,
    out: Option<PathBuf>,
) -> PyResult<Vec<(String, PyScene, Option<PathBuf>)>> {
    let bad = |e: study::SweepError| PyValueError::new_err(e.to_string());
    let mut varies = Vec::new();
    for (k, values) in vary.iter() {
        let key: String = k.extract()?;
        let mut texts = Vec::new();
        for v in values.try_iter()? {
            let v = to_toml(&v?, &key)?;
            texts.push(match v {
                toml::Value::String(s) => s,
                // As the command line's `--vary model.zeta=0,0.005` names its points: the
                // shortest decimal (`0`, not `0.0`), so that both front ends name a point
                // alike.
                toml::Value::Float(f) => format!("{f}"),
                other => other.to_string(),
            });
        }
        varies.push(study::Vary::new(&key, texts).map_err(bad)?);
    }
    let seeds = match seeds {
        Some((a, b)) => Some(format!("{a}-{b}").parse::<study::Seeds>().map_err(bad)?),
        None => None,
    };
    let sets = match &scene.path {
        Some(p) => ::scene::absolute_paths(p, &scene.text, &scene.set)
            .map_err(|e| PyOSError::new_err(e.to_string()))?,
        None => scene.set.clone(),
    };
    let spec = study::SweepSpec {
        scene_text: scene.text.clone(),
        sets,
        varies,
        seeds,
    };
    let points = spec.plan().map_err(bad)?;
    if let Some(dir) = &out {
        std::fs::create_dir_all(dir)
            .map_err(|e| PyOSError::new_err(format!("cannot create {}: {e}", dir.display())))?;
        spec.save(dir).map_err(bad)?;
    }
    Ok(points
        .into_iter()
        .map(|p| {
            let run = out.as_ref().map(|d| study::run_dir(d, &p));
            let py = PyScene {
                text: p.scene.to_toml(),
                path: None,
                set: Vec::new(),
                scene: p.scene,
            };
            (p.name, py, run)
        })
        .collect())
}

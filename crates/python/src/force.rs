//! A whole-cell force written in Python: a [`CellTerm`] whose [`CellTerm::forces`] calls a
//! Python function once per evaluation (both stages of Heun's step) with every cell's columns,
//! and adds the `(n, 2)` array it returns to the interface forces, `ξ v_i = F_i + f_i`.

use std::sync::{Arc, Mutex};

use mechanics::terms::{CellBatch, CellTerm};
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::cells::{column, int_column};

/// The first error of a Python function called inside a run, kept for the caller to raise
/// once the run has stopped (the step sees non-finite forces and stops at the last good
/// state).
pub(crate) type ErrorSlot = Arc<Mutex<Option<PyErr>>>;

/// A force from a Python function `f(t, cells) -> (n, 2) array`.
#[derive(Debug)]
pub(crate) struct PyForce {
    pub(crate) name: String,
    pub(crate) func: Py<PyAny>,
    pub(crate) error: ErrorSlot,
}

impl PyForce {
    /// The cells' columns the function receives: `id`, `population`, `x`, `y` (the position
    /// in the state evaluated), `vx`, `vy` (the last evaluation's velocity), `area`.
    fn call(&self, py: Python<'_>, cells: &CellBatch<'_>, out: &mut [[f64; 2]]) -> PyResult<()> {
        let n = cells.len();
        let contexts: Vec<_> = (0..n).map(|s| cells.context(s)).collect();
        let d = PyDict::new(py);
        d.set_item(
            "id",
            int_column(py, contexts.iter().map(|c| c.id as i64).collect())?,
        )?;
        d.set_item(
            "population",
            int_column(py, contexts.iter().map(|c| c.population as i64).collect())?,
        )?;
        d.set_item(
            "x",
            column(py, (0..n).map(|s| cells.position(s)[0]).collect())?,
        )?;
        d.set_item(
            "y",
            column(py, (0..n).map(|s| cells.position(s)[1]).collect())?,
        )?;
        d.set_item(
            "vx",
            column(py, contexts.iter().map(|c| c.state.velocity.x).collect())?,
        )?;
        d.set_item(
            "vy",
            column(py, contexts.iter().map(|c| c.state.velocity.y).collect())?,
        )?;
        d.set_item(
            "area",
            column(py, contexts.iter().map(|c| c.state.area).collect())?,
        )?;
        let r = self.func.bind(py).call1((cells.time(), d))?;
        let np = py.import("numpy")?;
        let r = np.call_method1("ascontiguousarray", (r, "float64"))?;
        let a: PyReadonlyArray2<'_, f64> = r.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "force {:?}: return an array of shape ({n}, 2), one (fx, fy) row per cell; got shape {}",
                self.name,
                r.getattr("shape").map_or("?".into(), |s| s.to_string())
            ))
        })?;
        if a.shape() != [n, 2] {
            return Err(PyValueError::new_err(format!(
                "force {:?}: return an array of shape ({n}, 2), one (fx, fy) row per cell in the order of cells[\"id\"]; got shape {:?}",
                self.name,
                a.shape()
            )));
        }
        let v = a.as_slice()?;
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "force {:?}: the force on cell {} is not finite ({}) at t = {}",
                self.name,
                contexts[k / 2].id,
                v[k],
                cells.time()
            )));
        }
        for (o, f) in out.iter_mut().zip(v.chunks_exact(2)) {
            *o = [f[0], f[1]];
        }
        Ok(())
    }
}

impl CellTerm for PyForce {
    fn name(&self) -> &str {
        &self.name
    }

    fn forces(&self, cells: &CellBatch<'_>, _x: &[f64], out: &mut [[f64; 2]]) {
        let failed = Python::attach(|py| self.call(py, cells, out).err());
        if let Some(e) = failed {
            // NaN stops the step at the last good state; the caller raises `e`.
            out.fill([f64::NAN; 2]);
            let mut slot = self.error.lock().unwrap_or_else(|p| p.into_inner());
            slot.get_or_insert(e);
        }
    }
}

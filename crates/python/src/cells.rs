//! Snapshots of a tissue as NumPy arrays, every one a copy: the cells' columns (one row per
//! living cell, in increasing identity, as a frame has them), the fields on their patches,
//! and the lattice fields.

use mechanics::{Tissue, Workspace};
use numpy::{PyArray1, PyArrayMethods};
use phasefield::Real;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A 1-D float64 array, read-only.
pub(crate) fn column<'py>(py: Python<'py>, v: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    frozen(PyArray1::from_vec(py, v).into_any())
}

/// A 1-D int64 array, read-only.
pub(crate) fn int_column<'py>(py: Python<'py>, v: Vec<i64>) -> PyResult<Bound<'py, PyAny>> {
    frozen(PyArray1::from_vec(py, v).into_any())
}

/// An array of `shape` from its values in C order, read-only.
pub(crate) fn shaped<'py>(
    py: Python<'py>,
    v: Vec<f64>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let a = PyArray1::from_vec(py, v).reshape(shape.to_vec())?;
    frozen(a.into_any())
}

/// `a` made read-only (`a.flags.writeable = False`): a snapshot, not a handle on the state.
fn frozen(a: Bound<'_, PyAny>) -> PyResult<Bound<'_, PyAny>> {
    let kwargs = PyDict::new(a.py());
    kwargs.set_item("write", false)?;
    a.call_method("setflags", (), Some(&kwargs))?;
    Ok(a)
}

/// The cells' columns of `tissue` (whose derived quantities `ws` holds): `id`, `population`,
/// `x`, `y`, `vx`, `vy`, `fx`, `fy` (interface force), `cell_fx`, `cell_fy` (the terms'
/// whole-cell force), `area`, `s_xx`, `s_xy` (deformation tensor), then each extension's
/// per-cell arrays under their frame names (a 2-column array as `NAME.x`, `NAME.y`).
pub(crate) fn cells_dict<'py, T: Real>(
    py: Python<'py>,
    tissue: &Tissue<T>,
    ws: &Workspace<T>,
) -> PyResult<Bound<'py, PyDict>> {
    let slots = tissue.slots();
    let ids: Vec<usize> = slots.iter().map(|&s| tissue.cell_ids()[s]).collect();
    let cs = ws.cell_states();
    let by = |f: &dyn Fn(usize) -> f64| -> Vec<f64> { slots.iter().map(|&s| f(s)).collect() };
    let d = PyDict::new(py);
    d.set_item(
        "id",
        int_column(py, ids.iter().map(|&i| i as i64).collect())?,
    )?;
    let pops = tissue.populations();
    d.set_item(
        "population",
        int_column(py, ids.iter().map(|&i| pops.population(i) as i64).collect())?,
    )?;
    let centres = ws.centres();
    let columns: [(&str, &dyn Fn(usize) -> f64); 11] = [
        ("x", &|s| centres[s][0]),
        ("y", &|s| centres[s][1]),
        ("vx", &|s| cs[s].velocity.x),
        ("vy", &|s| cs[s].velocity.y),
        ("fx", &|s| cs[s].force.x),
        ("fy", &|s| cs[s].force.y),
        ("cell_fx", &|s| cs[s].cell_force.x),
        ("cell_fy", &|s| cs[s].cell_force.y),
        ("area", &|s| cs[s].area),
        ("s_xx", &|s| cs[s].shape.components()[0]),
        ("s_xy", &|s| cs[s].shape.components()[1]),
    ];
    for (name, f) in columns {
        d.set_item(name, column(py, by(f))?)?;
    }
    for array in tissue.extensions().frame_arrays() {
        if array.name == "population" {
            continue;
        }
        let w = array.columns;
        for k in 0..w {
            let values: Vec<f64> = ids.iter().map(|&i| array.values[i * w + k]).collect();
            let name = match (w, k) {
                (1, _) => array.name.clone(),
                (2, 0) => format!("{}.x", array.name),
                (2, _) => format!("{}.y", array.name),
                _ => format!("{}.{k}", array.name),
            };
            if array.integer {
                d.set_item(
                    name,
                    int_column(py, values.iter().map(|&v| v as i64).collect())?,
                )?;
            } else {
                d.set_item(name, column(py, values)?)?;
            }
        }
    }
    Ok(d)
}

/// Every cell's field on its patch, `(n, nx, ny)` float64, with the patches' origins on the
/// lattice `(n, 2)` and the identities, in increasing identity.
pub(crate) fn phi_arrays<'py, T: Real>(
    py: Python<'py>,
    tissue: &Tissue<T>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let slots = tissue.slots();
    let shape = tissue.cells().shape();
    let (nx, ny) = (shape.nx, shape.ny);
    let mut phi = vec![0.0; slots.len() * nx * ny];
    for (chunk, &slot) in phi.chunks_exact_mut(nx * ny).zip(&slots) {
        tissue.cells().unrolled_into(slot, chunk);
    }
    let origin = &tissue.cells().map().origin;
    let origins: Vec<f64> = slots
        .iter()
        .flat_map(|&s| [origin[s][0] as f64, origin[s][1] as f64])
        .collect();
    let ids: Vec<i64> = slots.iter().map(|&s| tissue.cell_ids()[s] as i64).collect();
    Ok((
        shaped(py, phi, &[slots.len(), nx, ny])?,
        shaped(py, origins, &[slots.len(), 2])?.call_method1("astype", ("int64",))?,
        int_column(py, ids)?,
    ))
}

/// The lattice fields `f` of a state on lattice `l`, each `(lx, ly)` or `(lx, ly, k)`:
/// `phi_sum` (`Σ φ_i`), `velocity` (`Σ φ_i v_i`), `Q` (`Q_xx`, `Q_xy`), `pressure`, and the
/// stress `sigma` (`σ_xx`, `σ_yy`, `σ_xy`).
pub(crate) fn fields_dict<'py>(
    py: Python<'py>,
    l: phasefield::Lattice,
    f: mechanics::TissueFields,
    phi_sum: Vec<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let pair = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).flat_map(|(x, y)| [*x, *y]).collect()
    };
    let d = PyDict::new(py);
    d.set_item("phi_sum", shaped(py, phi_sum, &[l.lx, l.ly])?)?;
    d.set_item(
        "velocity",
        shaped(py, pair(&f.vx, &f.vy), &[l.lx, l.ly, 2])?,
    )?;
    d.set_item("Q", shaped(py, pair(&f.qxx, &f.qxy), &[l.lx, l.ly, 2])?)?;
    if let Some([mxx, mxy]) = &f.cell_nematic {
        d.set_item("M", shaped(py, pair(mxx, mxy), &[l.lx, l.ly, 2])?)?;
    }
    let sigma: Vec<f64> = (0..l.len())
        .flat_map(|k| [f.sigma_xx[k], f.sigma_yy[k], f.sigma_xy[k]])
        .collect();
    d.set_item("pressure", shaped(py, f.pressure, &[l.lx, l.ly])?)?;
    d.set_item("sigma", shaped(py, sigma, &[l.lx, l.ly, 3])?)?;
    Ok(d)
}

//! The native module of the Python package `monolayer` (`monolayer._native`): scenes,
//! simulations stepped from Python with the interpreter's lock released, forces written in
//! Python, run directories written as the command line writes them, sweeps and pictures.
//!
//! The Python layer (`python/monolayer/__init__.py`) wraps this module with the progress bar,
//! the run-directory reader and the images; `python/monolayer/_native.pyi` types it.
//!
//! Every array handed to Python is a copy, owned by Python: nothing changes under the user's
//! feet when the simulation steps.

mod cells;
mod force;
mod interrupt;
mod scene;
mod simulation;

use pyo3::prelude::*;

/// The module `monolayer._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::PyScene>()?;
    m.add_class::<simulation::PySimulation>()?;
    m.add_class::<simulation::PyObservation>()?;
    m.add_class::<simulation::PyEdit>()?;
    m.add_function(wrap_pyfunction!(simulation::run_dir, m)?)?;
    m.add_function(wrap_pyfunction!(simulation::resume_dir, m)?)?;
    m.add_function(wrap_pyfunction!(simulation::render_dir, m)?)?;
    m.add_function(wrap_pyfunction!(scene::sweep_points, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

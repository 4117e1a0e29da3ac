//! `sagcal._sagcal`: the Python extension module of sagcal (PyO3), re-exported
//! by the pure-Python package `sagcal` (`python/sagcal/__init__.py`).
//!
//! A thin layer: numpy arrays and paths in, the library's jobs run exactly as
//! the `sagcal` command runs them (`src/cli/`), numpy arrays and plain Python
//! objects out. Every `sagcal::Error` becomes a [`SagcalError`] whose message
//! is the error's `Display`, the text the command prints after `error: `.

mod arrays;
mod calibrate;
mod data;
mod diagnose;
mod json;
mod localize;
mod options;
mod plan;
mod robot;
mod simulate;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

pyo3::create_exception!(
    sagcal,
    SagcalError,
    PyValueError,
    "A sagcal error: bad input (file, row, field), an invalid robot, no static equilibrium, ...\n\n\
     The message is exactly what the `sagcal` command prints after `error: `."
);

/// A Python exception for a sagcal error, with the command's message.
pub(crate) fn to_py(error: sagcal::Error) -> PyErr {
    SagcalError::new_err(error.to_string())
}

/// A [`SagcalError`] for invalid input given through Python (`invalid input: ...`).
pub(crate) fn invalid(message: impl Into<String>) -> PyErr {
    to_py(sagcal::Error::InvalidInput(message.into()))
}

/// Ask the running jobs to stop (`sagcal::cancel::request`): the package calls it on Ctrl-C.
#[pyfunction]
fn _cancel() {
    sagcal::cancel::request();
}

/// Clear a stop request before a new job (`sagcal::cancel::reset`).
#[pyfunction]
fn _reset_cancel() {
    sagcal::cancel::reset();
}

/// The module `sagcal._sagcal`.
#[pymodule]
fn _sagcal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    sagcal::simd::check_switch().map_err(pyo3::exceptions::PyValueError::new_err)?;
    m.add("SagcalError", m.py().get_type::<SagcalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "MEASUREMENT_COLUMNS",
        pyo3::types::PyTuple::new(m.py(), data::columns())?,
    )?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<calibrate::Calibration>()?;
    m.add_class::<diagnose::Diagnosis>()?;
    m.add_class::<localize::Localization>()?;
    m.add_class::<plan::PosePlan>()?;
    m.add_class::<simulate::Simulation>()?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(localize::localize, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(data::read_measurements, m)?)?;
    m.add_function(wrap_pyfunction!(data::write_measurements, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(_cancel, m)?)?;
    m.add_function(wrap_pyfunction!(_reset_cancel, m)?)?;
    Ok(())
}

//! `sagcal._sagcal`: the Python extension module of sagcal (PyO3), re-exported
//! by the pure-Python package `sagcal` (`python/sagcal/__init__.py`).
//!
//! A thin layer: numpy arrays and paths in, the library's jobs run exactly as
//! the `sagcal` command runs them (`src/cli/`), numpy arrays and plain Python
//! objects out. Every `sagcal::Error` becomes a [`SagcalError`] whose message
//! is the error's `Display`, the text the command prints after `error: `; its
//! class tells the kind ([`to_py`]), and a calibration that failed on a step
//! carries that step's error as `__cause__`.

mod arrays;
mod calibrate;
mod calibrate_suspended;
mod check;
mod data;
mod diagnose;
mod diagnose_suspended;
mod init;
mod json;
mod localize;
mod localize_suspended;
mod options;
mod plan;
mod plan_suspended;
mod progress;
mod robot;
mod simulate;
mod suspended;
mod verify_suspended;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

pyo3::create_exception!(
    sagcal,
    SagcalError,
    PyValueError,
    "A sagcal error: bad input (file, row, field), an invalid robot, no static equilibrium, ...\n\n\
     The message is exactly what the `sagcal` command prints after `error: `."
);

pyo3::create_exception!(
    sagcal,
    FileError,
    SagcalError,
    "A file cannot be read or written, or one of its rows or fields is wrong (the message names the file, row and field)."
);
pyo3::create_exception!(
    sagcal,
    RobotError,
    SagcalError,
    "A robot description is invalid (coincident anchors, an unknown reference cable, implausible weights, ...)."
);
pyo3::create_exception!(
    sagcal,
    InvalidInputError,
    SagcalError,
    "An argument is out of range or not understood (the message names the keyword argument)."
);
pyo3::create_exception!(
    sagcal,
    EquilibriumError,
    SagcalError,
    "The kineto-statics have no solution with positive cable tensions."
);
pyo3::create_exception!(
    sagcal,
    SolverError,
    SagcalError,
    "The solver failed (nothing to solve, a factor undefined at the solution, a singular information matrix)."
);
pyo3::create_exception!(
    sagcal,
    CalibrationError,
    SagcalError,
    "A calibration gave no result: readings off by a unit, or a step failed (its error is the `__cause__`)."
);
pyo3::create_exception!(
    sagcal,
    CalibrationRefused,
    CalibrationError,
    "The fit fails its own consistency tests (`accept_inconsistent=True` returns it anyway)."
);
pyo3::create_exception!(sagcal, FigureError, SagcalError, "A figure could not be rendered.");
pyo3::create_exception!(sagcal, CancelledError, SagcalError, "The job was stopped on request.");

/// A Python exception for a sagcal error, with the command's message; its
/// class names the kind, a subclass of [`SagcalError`], so that a caller can
/// catch a refused calibration apart from a file error.
pub(crate) fn to_py(error: sagcal::Error) -> PyErr {
    use sagcal::error::CalibrationError as Calibration;
    use sagcal::Error as E;
    let message = error.to_string();
    match error {
        E::Io { .. } | E::Format { .. } | E::Field { .. } => FileError::new_err(message),
        E::Robot { .. } => RobotError::new_err(message),
        E::InvalidInput(_) | E::Parse(_) | E::EffectSpec(_) => InvalidInputError::new_err(message),
        E::NoEquilibrium(_) => EquilibriumError::new_err(message),
        E::Solver(_) => SolverError::new_err(message),
        E::Calibration(Calibration::Refused { .. }) => CalibrationRefused::new_err(message),
        E::NotWritten { cause, .. } => {
            let error = CalibrationError::new_err(message);
            Python::attach(|py| error.set_cause(py, Some(to_py(*cause))));
            error
        }
        E::Calibration(_) => CalibrationError::new_err(message),
        E::Png(_) => FigureError::new_err(message),
        E::Cancelled => CancelledError::new_err(message),
        _ => SagcalError::new_err(message),
    }
}

/// The exception classes of [`to_py`], by name.
fn add_exceptions(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SagcalError", py.get_type::<SagcalError>())?;
    m.add("FileError", py.get_type::<FileError>())?;
    m.add("RobotError", py.get_type::<RobotError>())?;
    m.add("InvalidInputError", py.get_type::<InvalidInputError>())?;
    m.add("EquilibriumError", py.get_type::<EquilibriumError>())?;
    m.add("SolverError", py.get_type::<SolverError>())?;
    m.add("CalibrationError", py.get_type::<CalibrationError>())?;
    m.add("CalibrationRefused", py.get_type::<CalibrationRefused>())?;
    m.add("FigureError", py.get_type::<FigureError>())?;
    m.add("CancelledError", py.get_type::<CancelledError>())?;
    Ok(())
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
    sagcal::simd::check_switch().map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    add_exceptions(m)?;
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
    m.add_class::<plan_suspended::SuspendedPlan>()?;
    m.add_class::<simulate::Simulation>()?;
    m.add_class::<suspended::SuspendedRobot>()?;
    m.add_class::<suspended::SuspendedSimulation>()?;
    m.add_class::<calibrate_suspended::SuspendedCalibration>()?;
    m.add_class::<localize_suspended::SuspendedLocalization>()?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose_suspended::diagnose_suspended, m)?)?;
    m.add_function(wrap_pyfunction!(verify_suspended::verify_suspended, m)?)?;
    m.add_function(wrap_pyfunction!(localize::localize, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(suspended::simulate_suspended, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_suspended::calibrate_suspended, m)?)?;
    m.add_function(wrap_pyfunction!(localize_suspended::localize_suspended, m)?)?;
    m.add_function(wrap_pyfunction!(data::read_measurements, m)?)?;
    m.add_function(wrap_pyfunction!(data::write_measurements, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(plan_suspended::plan_suspended, m)?)?;
    m.add_function(wrap_pyfunction!(init::init_robot, m)?)?;
    m.add_function(wrap_pyfunction!(check::check, m)?)?;
    m.add_function(wrap_pyfunction!(_cancel, m)?)?;
    m.add_function(wrap_pyfunction!(_reset_cancel, m)?)?;
    Ok(())
}

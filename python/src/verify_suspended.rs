//! `sagcal.verify_suspended`: a robot file of 3 to 8 cables, held as it is,
//! against measurements, exactly as `sagcal verify` reports it for such a
//! robot (`sagcal::diagnose::suspended::verify_suspended`, shared with
//! `src/cli/verify_suspended.rs`).

use pyo3::prelude::*;
use sagcal::calib::suspended::suspended_options;
use sagcal::calib::SolverSettings;
use sagcal::diagnose::suspended::verify_suspended as verify_library;
use sagcal::error::FrontEnd;

use crate::calibrate_suspended::suspended_measurements;
use crate::json::to_python;
use crate::options::noise_preset;
use crate::suspended::SuspendedRobot;
use crate::to_py;

/// Verify ``robot`` (its anchors, offsets and weights held) against
/// ``measurements``, exactly as ``sagcal verify --json`` does for a robot
/// of 3 to 8 cables: each row's pose and cable forces fitted to its
/// readings weighed by the ``noise`` (``"paper"`` or ``"authors"``), the
/// file's, each row's and each reading's test at ``false_alarm``, and per
/// encoder and load cell the residuals and the smallest error found with
/// 80 % power.
///
/// ``measurements`` is an array in the columns of
/// :attr:`SuspendedRobot.columns` or the path of a measurement file.
/// Returns the command's JSON report as a dict (``report["passes"]``,
/// ``report["rows"]``, ``report["suspect_readings"]``,
/// ``report["summaries"]``).
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (robot, measurements, noise = "paper", *, false_alarm = 1e-3))]
pub fn verify_suspended<'py>(
    py: Python<'py>,
    robot: &SuspendedRobot,
    measurements: &Bound<'py, PyAny>,
    noise: &str,
    false_alarm: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let held = robot.inner.clone();
    let options =
        suspended_options(&SolverSettings::new(noise_preset(noise)?), &held, FrontEnd::Python).map_err(to_py)?;
    let (data, path) = suspended_measurements(measurements, &held)?;
    let label = path.display().to_string();
    let report = py
        .detach(|| verify_library(&held, &label, &data, &options, false_alarm))
        .map_err(|e| match e {
            sagcal::Error::InvalidInput(m) if m.starts_with("false-alarm") => {
                crate::invalid(format!("false_alarm: {m}"))
            }
            other => to_py(other),
        })?;
    to_python(py, &report)
}

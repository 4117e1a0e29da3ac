//! `sagcal.localize_suspended`: every row's pose and forces on a calibrated
//! robot of 3 to 8 cables, the library's job
//! (`sagcal::localize::localize_suspended_rows`) with the report of `sagcal
//! localize --json` for such a robot.

use pyo3::prelude::*;
use sagcal::localize::{localize_suspended_rows, SuspendedLocalizationReport};

use crate::arrays::out2;
use crate::calibrate_suspended::suspended_measurements;
use crate::json::to_python;
use crate::options::noise_preset;
use crate::progress::Progress;
use crate::suspended::SuspendedRobot;
use crate::{invalid, to_py};

/// The result of :func:`localize_suspended`: one entry per row.
///
/// ``report`` holds it as ``sagcal localize --json`` prints it; the arrays
/// have one row per input row, ``nan`` where a row has no equilibrium.
#[pyclass(module = "sagcal", name = "SuspendedLocalization", frozen)]
pub struct SuspendedLocalization {
    report: SuspendedLocalizationReport,
    json: serde_json::Value,
}

/// One 3-vector per row, `nan` where the row has none.
fn per_row(
    report: &SuspendedLocalizationReport,
    pick: impl Fn(&sagcal::localize::SuspendedRowReport) -> Option<[f64; 3]>,
) -> Vec<[f64; 3]> {
    report.rows.iter().map(|r| pick(r).unwrap_or([f64::NAN; 3])).collect()
}

#[pymethods]
impl SuspendedLocalization {
    /// Platform positions, world frame, metres: an (M, 3) array.
    #[getter]
    fn positions_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &per_row(&self.report, |r| r.position_m))
    }

    /// ``(roll, pitch, yaw)`` degrees, ``R = Rz(yaw) Ry(pitch) Rx(roll)``: an (M, 3) array.
    #[getter]
    fn roll_pitch_yaw_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &per_row(&self.report, |r| r.roll_pitch_yaw_deg))
    }

    /// 1-sigma of each position from the reading noise, metres: an (M, 3) array.
    #[getter]
    fn position_sigma_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &per_row(&self.report, |r| r.position_sigma_m))
    }

    /// Whether each row passes its chi-square test and is a stable equilibrium.
    #[getter]
    fn ok(&self) -> Vec<bool> {
        self.report.rows.iter().map(|r| r.flag.is_none()).collect()
    }

    /// The rows flagged.
    #[getter]
    fn rows_flagged(&self) -> usize {
        self.report.rows_flagged
    }

    /// The whole report as ``sagcal localize --json`` prints it (a dict).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json)
    }

    fn __repr__(&self) -> String {
        format!(
            "SuspendedLocalization(robot={:?}, cables={}, rows={}, flagged={})",
            self.report.robot,
            self.report.cables,
            self.report.rows.len(),
            self.report.rows_flagged
        )
    }
}

/// Localise every row of ``measurements`` on a calibrated robot of 3 to 8
/// cables, as ``sagcal localize`` does for such a robot: each row's pose
/// and every cable's forces from its encoders and load cells (its localiser
/// columns are only compared with), the 1-sigma of its position from the
/// reading noise (``"paper"`` or ``"authors"``), its chi-square tested at
/// ``false_alarm`` and its stability. ``measurements``: as for
/// :func:`calibrate_suspended`. ``progress``: an optional
/// ``callable(done, total, what)``.
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (robot, measurements, noise = "paper", *, false_alarm = 1e-3, progress = None))]
pub fn localize_suspended(
    py: Python<'_>,
    robot: &SuspendedRobot,
    measurements: &Bound<'_, PyAny>,
    noise: &str,
    false_alarm: f64,
    progress: Option<Py<PyAny>>,
) -> PyResult<SuspendedLocalization> {
    let robot = robot.inner.clone();
    let sigmas = noise_preset(noise)?.sigmas(robot.platform_weight_n);
    sagcal::calib::check_false_alarm(false_alarm, "false_alarm", sagcal::error::FrontEnd::Python).map_err(to_py)?;
    if [sigmas.encoder_sigma_m, sigmas.load_cell_sigma_n]
        .iter()
        .any(|s| *s <= 0.0)
    {
        return Err(invalid(
            "noise: the readings need sigmas to be weighed: paper or authors",
        ));
    }
    let (rows, _) = suspended_measurements(measurements, &robot)?;
    let progress = Progress::new(progress);
    let report = py.detach(|| {
        localize_suspended_rows(&robot, &rows, &sigmas, false_alarm, &mut |done, total| {
            progress.report(done, total, "localize")
        })
    });
    progress.finish()?;
    let json =
        serde_json::to_value(&report).map_err(|e| invalid(format!("cannot serialise the report as JSON: {e}")))?;
    Ok(SuspendedLocalization { report, json })
}

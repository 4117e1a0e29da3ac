//! `sagcal.diagnose_suspended`: what the model of a robot of 3 to 8 cables
//! gets wrong, exactly as `sagcal diagnose` reports it for such a robot
//! (`sagcal::diagnose::suspended`, shared with `src/cli/diagnose_suspended.rs`).

use pyo3::prelude::*;
use sagcal::calib::suspended::suspended_options;
use sagcal::diagnose::suspended::{
    diagnose_suspended as diagnose_library, errors_against_truth, extensions_named, suspended_catalogue,
    SuspendedDiagnoseSettings,
};
use sagcal::error::FrontEnd;

use crate::calibrate_suspended::suspended_measurements;
use crate::json::to_python;
use crate::options::SolverArgs;
use crate::progress::Progress;
use crate::suspended::SuspendedRobot;
use crate::to_py;

/// Diagnose ``measurements`` of a robot of 3 to 8 cables, exactly as
/// ``sagcal diagnose --json`` does for such a robot: the baseline's
/// chi-square test, each extension of the model (``"elastic"``,
/// ``"cable-weight"``, ``"platform-weight"``, ``"encoder-scale"``,
/// ``"loadcell-gain"``, ``"loadcell-bias"``, and for each cable K
/// ``"drum-gain-K"`` and ``"cable-weight-K"``; all by default, or those
/// ``candidates`` names, ``"drum-gain"`` for every drum's) fitted, tested by its likelihood ratio at the
/// search's ``false_alarm`` rate and scored on poses held out of its
/// calibration (``folds``-fold), and the verdict.
///
/// ``measurements`` is an array in the columns of
/// :attr:`SuspendedRobot.columns` or the path of a measurement file;
/// ``progress`` an optional ``callable(done, total, what)``; ``truth`` the
/// robot the readings were made with, where it is known (a simulation),
/// fills ``report["against_truth"]``: each model's calibrated anchors and
/// offsets against it (``sagcal diagnose --truth``). Returns the
/// command's JSON report as a dict (``report["verdict"]["kind"]`` is one of
/// ``consistent``, ``named``, ``partial``, ``stand_in``,
/// ``indistinguishable``, ``unexplained``).
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (
    robot,
    measurements,
    noise = "paper",
    *,
    candidates = None,
    folds = 5,
    false_alarm = 1e-3,
    orientation_prior = "auto",
    progress = None,
    truth = None,
))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose_suspended<'py>(
    py: Python<'py>,
    robot: &SuspendedRobot,
    measurements: &Bound<'py, PyAny>,
    noise: &str,
    candidates: Option<Vec<String>>,
    folds: usize,
    false_alarm: f64,
    orientation_prior: &str,
    progress: Option<Py<PyAny>>,
    truth: Option<&SuspendedRobot>,
) -> PyResult<Bound<'py, PyAny>> {
    let nominal = robot.inner.clone();
    let solver = SolverArgs {
        model: "catenary",
        noise,
        encoder_sigma_m: None,
        load_cell_sigma_n: None,
        position_sigma_m: None,
        orientation_prior,
        robust_encoder: "none",
        robust_load_cell: "none",
        robust_pose: "none",
    }
    .settings()?;
    let options = suspended_options(&solver, &nominal, FrontEnd::Python).map_err(to_py)?;
    let extensions = match candidates {
        None => suspended_catalogue(&nominal),
        Some(names) => {
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            extensions_named(&nominal, &names).map_err(|e| crate::invalid(format!("candidates: {e}")))?
        }
    };
    let settings = SuspendedDiagnoseSettings {
        extensions,
        folds,
        false_alarm,
    };
    let (data, _) = suspended_measurements(measurements, &nominal)?;
    let progress = Progress::new(progress);
    let truth = truth.map(|t| t.inner.clone());
    let diagnosis = py
        .detach(|| {
            let mut diagnosis = diagnose_library(&nominal, &data, &settings, &options, &|done, total| {
                progress.report(done, total, "fitting the extensions")
            })?;
            if let Some(truth) = &truth {
                let models = diagnosis.fitted_models();
                diagnosis.against_truth = errors_against_truth(&nominal, &data, &models, truth, &options)?;
            }
            Ok::<_, sagcal::Error>(diagnosis)
        })
        .map_err(to_py)?;
    progress.finish()?;
    to_python(py, &diagnosis)
}

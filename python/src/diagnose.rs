//! `sagcal.diagnose`: what the calibration model gets wrong (`sagcal
//! diagnose`), with the same options, checked by the library
//! (`sagcal::diagnose::DiagnoseSettings`), and the same report.

use pyo3::prelude::*;
use sagcal::diagnose::DiagnoseSettings;
use sagcal::error::FrontEnd;

use crate::arrays::out2;
use crate::json::to_python;
use crate::options::SolverArgs;
use crate::progress::Progress;
use crate::robot::Robot;
use crate::{invalid, to_py};

/// The result of :func:`diagnose`: the verdict (which effects the data show),
/// the selected model's calibrated robot, and the whole report.
#[pyclass(module = "sagcal", name = "Diagnosis", frozen)]
pub struct Diagnosis {
    inner: sagcal::diagnose::Diagnosis,
    json: serde_json::Value,
}

#[pymethods]
impl Diagnosis {
    /// The causes named, joined by ``+`` (``"elastic+encoder-gain"``);
    /// ``"none"`` when nothing is wrong; ``"unexplained"`` when something is
    /// wrong that the catalogue does not hold, or the causes and
    /// ``"+unexplained"`` when they explain part of it; ``"X|Y"`` names one
    /// of two hypotheses the data do not tell apart.
    #[getter]
    fn verdict(&self) -> String {
        self.inner.verdict.clone()
    }

    /// Whether the final model explains the data: it passes every sensor's
    /// chi-square test at the false-alarm rate and holds no stand-in.
    #[getter]
    fn explained(&self) -> bool {
        self.inner.explanation.explained
    }

    /// The final model's hypotheses that fit only as proxies (an estimate no
    /// real robot could have, an effect that leaves its own sensor
    /// inconsistent, or freed orientations), each a sentence saying what it
    /// stands in for.
    #[getter]
    fn stand_ins(&self) -> Vec<String> {
        self.inner.explanation.stand_ins.iter().map(|s| s.sentence()).collect()
    }

    /// Why, in one sentence.
    #[getter]
    fn reason(&self) -> String {
        self.inner.reason.clone()
    }

    /// The final model's effects (stand-ins included): a list of dicts with ``effect`` and ``params``
    /// (each ``name``, ``value``, ``sigma``).
    #[getter]
    fn effects<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.inner.effects)
    }

    /// The final model's calibrated robot (anchors, offsets and the
    /// estimated effects); the baseline calibration's when it has no hypothesis.
    #[getter]
    fn robot(&self) -> Robot {
        Robot::new(self.inner.robot_after.clone())
    }

    /// Whether the baseline model's chi-square is within its 99.9 % quantile.
    #[getter]
    fn baseline_consistent(&self) -> bool {
        self.inner.baseline_consistent
    }

    /// The residual plotted against its strongest driver: a dict with
    /// ``residual``, ``driver`` (names), ``before`` and ``after`` ((K, 2)
    /// arrays of ``(driver, residual / sigma)``; ``after`` is ``None`` for the verdict ``"none"``).
    #[getter]
    fn series<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let s = &self.inner.series;
        let points = |p: &[(f64, f64)]| -> Vec<[f64; 2]> { p.iter().map(|&(d, r)| [d, r]).collect() };
        let dict = pyo3::types::PyDict::new(py);
        dict.set_item("residual", &s.residual)?;
        dict.set_item("driver", &s.driver)?;
        dict.set_item("before", out2(py, &points(&s.before))?)?;
        dict.set_item("after", s.after.as_ref().map(|a| out2(py, &points(a))).transpose()?)?;
        Ok(dict.into_any())
    }

    /// The whole diagnosis as ``sagcal diagnose --json`` prints it (a dict).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json)
    }

    fn __repr__(&self) -> String {
        format!(
            "Diagnosis(robot={:?}, verdict={:?}, poses_used={})",
            self.inner.robot, self.inner.verdict, self.inner.poses_used
        )
    }
}

/// Find what the calibration model gets wrong, as ``sagcal diagnose`` does:
/// calibrate with the baseline model, test the normalised residuals against
/// the stated noise, correlate them with physical drivers, and search the
/// catalogue of effects by forward selection with likelihood-ratio tests at
/// ``false_alarm``, with ``folds``-fold cross-validation of the gain.
///
/// ``robot`` is the initial guess (its ``effects`` are known inputs);
/// ``measurements`` an (N, 11) array or a path, as for :func:`calibrate`;
/// ``truth`` an optional true robot (simulations) for anchor and offset
/// errors before and after; ``candidates`` a list of effect names (default:
/// the whole catalogue, as ``sagcal diagnose --candidates`` lists it; the
/// effects of time and motion, ``encoder-drift``, ``encoder-backlash``,
/// ``loadcell-drift`` and ``loadcell-friction``, only for rows in the order
/// taken: an array or a sagcal file); ``progress`` an
/// optional ``callable(done, total, what)`` called before each fit. The
/// solver keywords are those of :func:`calibrate`.
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (
    robot,
    measurements,
    noise = "paper",
    *,
    truth = None,
    candidates = None,
    orientation_hypothesis = true,
    folds = 5,
    false_alarm = 1e-3,
    progress = None,
    model = "catenary",
    encoder_sigma_m = None,
    load_cell_sigma_n = None,
    position_sigma_m = None,
    orientation_prior = "auto",
    robust_encoder = "none",
    robust_load_cell = "none",
    robust_pose = "none",
))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose(
    py: Python<'_>,
    robot: &Robot,
    measurements: &Bound<'_, PyAny>,
    noise: &str,
    truth: Option<&Robot>,
    candidates: Option<Vec<String>>,
    orientation_hypothesis: bool,
    folds: usize,
    false_alarm: f64,
    progress: Option<Py<PyAny>>,
    model: &str,
    encoder_sigma_m: Option<f64>,
    load_cell_sigma_n: Option<f64>,
    position_sigma_m: Option<f64>,
    orientation_prior: &str,
    robust_encoder: &str,
    robust_load_cell: &str,
    robust_pose: &str,
) -> PyResult<Diagnosis> {
    let nominal = robot.inner.clone();
    let truth = truth.map(|t| t.inner.clone());
    let data = crate::data::measurements(measurements, nominal.reference_cable)?;
    let options = DiagnoseSettings {
        solver: SolverArgs {
            model,
            noise,
            encoder_sigma_m,
            load_cell_sigma_n,
            position_sigma_m,
            orientation_prior,
            robust_encoder,
            robust_load_cell,
            robust_pose,
        }
        .settings()?,
        candidates,
        orientation_hypothesis,
        folds,
        false_alarm,
        rows_in_time_order: data.rows_in_time_order,
    }
    .options(&nominal, FrontEnd::Python)
    .map_err(to_py)?;
    let progress = Progress::new(progress);
    let diagnosis = py
        .detach(|| {
            sagcal::diagnose::diagnose(
                &nominal,
                &data.poses,
                truth.as_ref(),
                &options,
                &mut |done, total, what| progress.report(done, total, what),
            )
        })
        .map_err(to_py)?;
    progress.finish()?;
    let json =
        serde_json::to_value(&diagnosis).map_err(|e| invalid(format!("cannot serialise the report as JSON: {e}")))?;
    Ok(Diagnosis { inner: diagnosis, json })
}

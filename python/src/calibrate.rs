//! `sagcal.calibrate`: anchors and encoder offsets from measurements, the
//! checked calibration of `sagcal calibrate`: the library's job
//! (`sagcal::calib::calibrate_job`), with the same options, the same report
//! and the same errors, a refusal naming `accept_inconsistent=True`.

use pyo3::prelude::*;
use sagcal::calib::gross_errors::Verdict;
use sagcal::calib::report::CalibrationReport;
use sagcal::calib::{calibrate_job_with_progress, CalibrationResult, CalibrationSettings, ParameterUncertainty};
use sagcal::error::FrontEnd;
use sagcal::model::DataRow;

use crate::arrays::{out1, out2, out3};
use crate::json::to_python;
use crate::options::SolverArgs;
use crate::progress::Progress;
use crate::robot::Robot;
use crate::to_py;

/// The result of :func:`calibrate`: the calibrated robot, the uncertainty of
/// its anchors and offsets, the solver's account, the residual statistics
/// and the gross-error tests.
///
/// ``report`` holds all of it as ``sagcal calibrate --json`` prints it (the
/// same keys and numbers); the other attributes are numpy arrays and plain
/// values taken from it.
#[pyclass(module = "sagcal", name = "Calibration", frozen)]
pub struct Calibration {
    robot: sagcal::model::Robot,
    result: CalibrationResult,
    report: CalibrationReport,
    json: serde_json::Value,
    verdict: Verdict,
    rows: Vec<DataRow>,
}

#[pymethods]
impl Calibration {
    /// The calibrated robot (the nominal robot with the estimated anchors and offsets).
    #[getter]
    fn robot(&self) -> Robot {
        Robot::new(self.robot.clone())
    }

    /// Calibrated anchors of cables 1..4, world frame, metres: a (4, 3) array.
    #[getter]
    fn anchors_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.report.anchors_m)
    }

    /// Calibrated encoder length offsets of cables 1..4, metres: a (4,) array.
    #[getter]
    fn length_offsets_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out1(py, &self.report.length_offsets_m)
    }

    /// Per anchor, the 3x3 covariance of its position, m^2: a (4, 3, 3)
    /// array; ``None`` when some direction is not observable from these poses
    /// (see ``report["uncertainty"]["directions"]``).
    #[getter]
    fn anchor_covariance_m2<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.result.uncertainty {
            ParameterUncertainty::Full {
                anchor_covariance_m2, ..
            } => out3(py, anchor_covariance_m2).map(Some),
            ParameterUncertainty::RankDeficient { .. } => Ok(None),
        }
    }

    /// 1-sigma of each anchor coordinate, metres: a (4, 3) array, or ``None`` (not observable).
    #[getter]
    fn anchor_sigma_m<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.report.anchor_sigma_m.as_ref().map(|s| out2(py, s)).transpose()
    }

    /// 1-sigma of each length offset, metres: a (4,) array, or ``None`` (not observable).
    #[getter]
    fn offset_sigma_m<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.report.offset_sigma_m.as_ref().map(|s| out1(py, s)).transpose()
    }

    /// Per factor type, the normalised residuals ``r / sigma`` at the
    /// solution: a list of dicts with ``kind``, ``factors``, ``components``,
    /// ``rms`` (about 1 when the stated noise is right), ``max_abs`` and ``chi_square``.
    #[getter]
    fn factor_statistics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.report.factor_statistics)
    }

    /// The solver stages in order (``rigid``, ``catenary``, ...), each a dict
    /// with ``name`` and the solver's ``summary``.
    #[getter]
    fn stages<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.report.stages)
    }

    /// Why the final solver stage stopped, in words (``"cost converged"``, ...).
    #[getter]
    fn termination(&self) -> String {
        self.report.termination.to_string()
    }

    /// Whether the final stage stopped at a minimum.
    #[getter]
    fn converged(&self) -> bool {
        self.report.converged
    }

    /// Solver iterations over all stages.
    #[getter]
    fn iterations(&self) -> usize {
        self.report.iterations
    }

    /// Cost of the final stage (half the sum of squared whitened residuals).
    #[getter]
    fn final_cost(&self) -> f64 {
        self.report.final_cost
    }

    /// Number of poses in the final solve.
    #[getter]
    fn poses_used(&self) -> usize {
        self.report.poses_used
    }

    /// Poses left out because no positive-tension equilibrium is near them:
    /// a list of dicts with ``row`` (1-based) and ``line`` (the file's line,
    /// ``None`` for an array).
    #[getter]
    fn excluded_poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.report.excluded_poses)
    }

    /// Readings left out as gross errors, in the order found: a list of dicts
    /// with the reading's ``test`` (``row`` 1-based, ``line`` (``None`` for
    /// an array), ``sensor``, ``cable`` (1-based, encoders), ``axis``
    /// (localiser), ``residual``, ``sigma``, ``redundancy``, ``w``,
    /// ``estimated_error``) and an ``explanation`` (a common mistake that
    /// explains it, or ``None``).
    #[getter]
    fn excluded_readings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json["gross_errors"]["excluded_readings"])
    }

    /// Common mistakes recognised in the data (units, swapped cables,
    /// re-homing, poses outside the frame): a list of dicts with ``kind``,
    /// ``message`` and ``rows`` (dicts with ``row``, 1-based, and ``line``).
    #[getter]
    fn mistakes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json["gross_errors"]["mistakes"])
    }

    /// Whether the fit passes its own consistency tests with the stated noise
    /// (after the exclusions); ``False`` only with ``accept_inconsistent=True``.
    #[getter]
    fn consistent(&self) -> bool {
        self.verdict == Verdict::Consistent
    }

    /// Why the fit fails its consistency tests, naming the sensors; ``None`` when it passes.
    #[getter]
    fn inconsistency(&self) -> Option<String> {
        match &self.verdict {
            Verdict::Consistent => None,
            Verdict::Inconsistent { reason } => Some(reason.clone()),
        }
    }

    /// Row (1-based, in the measurements given) of each pose the fit used
    /// (rows outside the frame left out); ``measurements[rows - 1]`` are their readings.
    #[getter]
    fn rows(&self) -> Vec<usize> {
        self.rows.iter().map(|r| r.row).collect()
    }

    /// File line of each pose the fit used (as :attr:`rows`); ``None`` each for an array.
    #[getter]
    fn lines(&self) -> Vec<Option<usize>> {
        self.rows.iter().map(|r| r.line).collect()
    }

    /// Estimated platform positions, world frame, metres: an (M, 3) array, one row per pose in :attr:`rows`.
    #[getter]
    fn positions_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self.result.poses.iter().map(|p| p.position_m.into()).collect();
        out2(py, &rows)
    }

    /// Estimated platform orientations as ``(roll, pitch, yaw)`` degrees,
    /// ``R = Rz(yaw) Ry(pitch) Rx(roll)``: an (M, 3) array, one row per pose in :attr:`rows`.
    #[getter]
    fn roll_pitch_yaw_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self
            .result
            .poses
            .iter()
            .map(|p| {
                let (r, pi, y) = p.roll_pitch_yaw_deg();
                [r, pi, y]
            })
            .collect();
        out2(py, &rows)
    }

    /// Estimated reference-cable tension ``(f_h, f_v)`` at the platform per pose, newtons: an (M, 2) array.
    #[getter]
    fn reference_tensions_n<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.result.reference_tensions_n)
    }

    /// The whole report as ``sagcal calibrate --json`` prints it (a dict).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json)
    }

    fn __repr__(&self) -> String {
        format!(
            "Calibration(robot={:?}, poses_used={}, termination={:?}, consistent={}, excluded_readings={})",
            self.report.robot,
            self.report.poses_used,
            self.report.termination.to_string(),
            self.verdict == Verdict::Consistent,
            self.json["gross_errors"]["excluded_readings"]
                .as_array()
                .map_or(0, Vec::len)
        )
    }
}

/// Calibrate the anchors and encoder length offsets of ``robot`` from
/// ``measurements``, exactly as ``sagcal calibrate`` does: a staged
/// Levenberg-Marquardt solve of the factor graph (paper Sec. IV) from the
/// robot's anchors and offsets as the initial guess, with the gross-error
/// tests (data snooping) leaving out blunders and checking the fit against
/// the stated noise.
///
/// ``measurements`` is an (N, 11) array in the columns of
/// :data:`MEASUREMENT_COLUMNS` (``x_m, y_m, z_m, roll_deg, pitch_deg,
/// yaw_deg, l1_m .. l4_m, f_ref_n``), or the path of a file the command
/// reads (sagcal CSV, RecurDyn log). The keywords are the command's flags:
/// ``noise`` (``"paper"`` or ``"authors"``), ``model`` (``"catenary"`` or
/// ``"rigid"``), sigma overrides, ``orientation_prior`` (``"auto"``,
/// ``"on"``, ``"off"``), robust kernels (``"none"``, ``"huber[:k]"``,
/// ``"cauchy[:c]"``), ``false_alarm`` of the gross-error tests. A fit that
/// fails its own consistency tests raises, as the command refuses to write
/// it, unless ``accept_inconsistent=True``. ``progress`` is an optional
/// ``callable(done, total, what)`` called before each stage of each fit
/// (``done`` fits made of the ``total`` expected so far, which grows while
/// the gross-error search finds readings to leave out; ``what`` the fit and
/// its stage, ``"calibration: rigid"``), last with ``(fits, fits, "done")``.
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (
    robot,
    measurements,
    noise = "paper",
    *,
    model = "catenary",
    encoder_sigma_m = None,
    load_cell_sigma_n = None,
    position_sigma_m = None,
    orientation_prior = "auto",
    robust_encoder = "none",
    robust_load_cell = "none",
    robust_pose = "none",
    false_alarm = 1e-3,
    accept_inconsistent = false,
    progress = None,
))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate(
    py: Python<'_>,
    robot: &Robot,
    measurements: &Bound<'_, PyAny>,
    noise: &str,
    model: &str,
    encoder_sigma_m: Option<f64>,
    load_cell_sigma_n: Option<f64>,
    position_sigma_m: Option<f64>,
    orientation_prior: &str,
    robust_encoder: &str,
    robust_load_cell: &str,
    robust_pose: &str,
    false_alarm: f64,
    accept_inconsistent: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Calibration> {
    let nominal = robot.inner.clone();
    let data = crate::data::measurements(measurements, nominal.reference_cable)?;
    let settings = CalibrationSettings {
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
        false_alarm,
        accept_inconsistent,
    };
    let source = data.label.display().to_string();
    let progress = Progress::new(progress);
    let mut job = py
        .detach(|| {
            calibrate_job_with_progress(
                &nominal,
                &data.poses,
                &source,
                &settings,
                FrontEnd::Python,
                &mut |done, total, what| progress.report(done, total, what),
            )
        })
        .map_err(to_py)?;
    if let Some(refusal) = job.refusal.take() {
        return Err(to_py(refusal));
    }
    progress.finish()?;
    let json = serde_json::to_value(&job.report)
        .map_err(|e| crate::invalid(format!("cannot serialise the report as JSON: {e}")))?;
    // Every attribute is read off the one report the command prints.
    let rows = job
        .checked
        .rows
        .iter()
        .map(|&row| DataRow::at(row, data.poses[row].line))
        .collect();
    Ok(Calibration {
        robot: job.checked.result.robot.clone(),
        result: job.checked.result,
        report: job.report.report,
        json,
        verdict: job.report.gross_errors.verdict,
        rows,
    })
}

//! `sagcal.calibrate_suspended`: anchors and encoder offsets of a robot of
//! 3 to 8 cables, the library's calibration (`sagcal::calib::suspended`)
//! with the options, report and refusal of `sagcal calibrate` for such a
//! robot.

use std::path::PathBuf;

use numpy::ndarray::Array3;
use pyo3::prelude::*;
use sagcal::calib::gross_errors::GrossErrorOptions;
use sagcal::calib::suspended::{
    calibrate_suspended as calibrate_library, suspended_options, SuspendedCalibration as LibraryCalibration,
    SuspendedCalibrationReport,
};
use sagcal::calib::{check_false_alarm, refusal, ParameterUncertainty};
use sagcal::error::FrontEnd;
use sagcal::io::suspended_measurements::{
    read_suspended_measurements, suspended_header, suspended_measurement_from_values,
};
use sagcal::model::suspended::SuspendedMeasurement;

use crate::arrays::{dynamic_rows, frozen, out1, out2, out3};
use crate::data::{as_path, ARRAY_LABEL};
use crate::json::to_python;
use crate::options::SolverArgs;
use crate::progress::Progress;
use crate::suspended::SuspendedRobot;
use crate::to_py;

/// The result of :func:`calibrate_suspended`: the calibrated robot, the
/// uncertainty of its anchors and offsets, the residual statistics, the
/// solver's account and the chi-square test of the fit.
///
/// ``report`` holds all of it as ``sagcal calibrate --json`` prints it for
/// such a robot (the same keys and numbers); the other attributes are numpy
/// arrays and plain values taken from it.
#[pyclass(module = "sagcal", name = "SuspendedCalibration", frozen)]
pub struct SuspendedCalibration {
    result: LibraryCalibration,
    report: SuspendedCalibrationReport,
    json: serde_json::Value,
}

#[pymethods]
impl SuspendedCalibration {
    /// The calibrated robot (the nominal robot with the estimated anchors and offsets).
    #[getter]
    fn robot(&self) -> SuspendedRobot {
        SuspendedRobot {
            inner: self.result.robot.clone(),
        }
    }

    /// Calibrated anchors of cables 1..N, world frame, metres: an (N, 3) array.
    #[getter]
    fn anchors_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.report.anchors_m)
    }

    /// Calibrated encoder length offsets of cables 1..N, metres: an (N,) array.
    #[getter]
    fn length_offsets_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out1(py, &self.report.length_offsets_m)
    }

    /// Per anchor, the 3x3 covariance of its position, m^2: an (N, 3, 3)
    /// array; ``None`` when some direction is not observable from these poses.
    #[getter]
    fn anchor_covariance_m2<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.result.uncertainty {
            ParameterUncertainty::Full {
                anchor_covariance_m2, ..
            } => out3(py, anchor_covariance_m2).map(Some),
            ParameterUncertainty::RankDeficient { .. } => Ok(None),
        }
    }

    /// 1-sigma of each anchor coordinate, metres: an (N, 3) array, or ``None`` (not observable).
    #[getter]
    fn anchor_sigma_m<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.report.anchor_sigma_m.as_ref().map(|s| out2(py, s)).transpose()
    }

    /// 1-sigma of each length offset, metres: an (N,) array, or ``None`` (not observable).
    #[getter]
    fn offset_sigma_m<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.report.offset_sigma_m.as_ref().map(|s| out1(py, s)).transpose()
    }

    /// Estimated platform positions, world frame, metres: an (M, 3) array, one row per measurement.
    #[getter]
    fn positions_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self.result.poses.iter().map(|p| p.position_m.into()).collect();
        out2(py, &rows)
    }

    /// Estimated forces ``(f_h, f_v)`` of every cable at its attachment,
    /// newtons: an (M, N, 2) array.
    #[getter]
    fn forces_n<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let forces = &self.result.forces;
        let cables = forces.first().map_or(0, Vec::len);
        let flat: Vec<f64> = forces
            .iter()
            .flatten()
            .flat_map(|t| [t.horizontal_n, t.vertical_n])
            .collect();
        frozen(
            py,
            Array3::from_shape_vec((forces.len(), cables, 2), flat).expect("two forces per cable and pose"),
        )
    }

    /// The fit's chi-square, ``sum (r / sigma)^2``.
    #[getter]
    fn chi_square(&self) -> f64 {
        self.report.chi_square
    }

    /// Its degrees of freedom: residual rows minus the unknowns the
    /// readings determine (the undetermined force directions counted out).
    #[getter]
    fn degrees_of_freedom(&self) -> usize {
        self.report.degrees_of_freedom
    }

    /// The poses whose cable forces the readings do not determine: dicts
    /// with ``pose`` (1-based) and ``directions`` (force combinations that
    /// change no reading); empty when every force is determined.
    #[getter]
    fn undetermined_forces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json["undetermined_forces"])
    }

    /// Whether the fit passes its chi-square test at 99.9 % and the solver
    /// converged; ``False`` only with ``accept_inconsistent=True``.
    #[getter]
    fn consistent(&self) -> bool {
        self.report.consistent
    }

    /// Why the fit fails its test; ``None`` when it passes.
    #[getter]
    fn inconsistency(&self) -> Option<String> {
        self.report.inconsistency()
    }

    /// The readings left out as gross errors, in the order found: dicts
    /// with ``row``, ``line``, ``reading`` (``{"encoder": i}``,
    /// ``{"load_cell": i}``, ``{"position": axis}``, ``{"orientation":
    /// axis}``, 0-based), ``residual``, ``sigma``, ``redundancy``, ``w``
    /// and ``critical``.
    #[getter]
    fn readings_left_out<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json["readings_left_out"])
    }

    /// The whole report as ``sagcal calibrate --json`` prints it (a dict).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json)
    }

    fn __repr__(&self) -> String {
        format!(
            "SuspendedCalibration(robot={:?}, cables={}, poses_used={}, chi_square={:.1}, consistent={})",
            self.report.robot,
            self.report.cables,
            self.report.poses_used,
            self.report.chi_square,
            self.report.consistent
        )
    }
}

/// The measurements of `robot` in `value`: a path (the file the command
/// reads) or an (M, 6 + cables + load cells) array in the columns of
/// :attr:`SuspendedRobot.columns`, each row checked as a file's row is.
pub(crate) fn suspended_measurements(
    value: &Bound<'_, PyAny>,
    robot: &sagcal::model::suspended::SuspendedRobot,
) -> PyResult<(Vec<SuspendedMeasurement>, PathBuf)> {
    if let Some(path) = as_path(value) {
        return read_suspended_measurements(&path, robot)
            .map(|rows| (rows, path))
            .map_err(to_py);
    }
    let header = suspended_header(robot);
    let label = PathBuf::from(ARRAY_LABEL);
    let rows = dynamic_rows(value, header.len(), &header.join(", "), ARRAY_LABEL)?;
    let measurements = rows
        .iter()
        .enumerate()
        .map(|(i, row)| suspended_measurement_from_values(&label, robot, i + 1, row))
        .collect::<sagcal::Result<Vec<_>>>()
        .map_err(to_py)?;
    Ok((measurements, label))
}

/// Calibrate the anchors and encoder length offsets of a robot of 3 to 8
/// cables from ``measurements``, exactly as ``sagcal calibrate`` does for
/// such a robot: straight cables from the robot's anchors as the guess, then
/// every pose's equilibrium, then the catenary graph in which every cable's
/// forces are unknowns of its pose.
///
/// ``measurements`` is an (M, 6 + cables + load cells) array in the columns
/// of :attr:`SuspendedRobot.columns`, or the path of the file ``sagcal
/// simulate`` writes for the robot. The keywords are the command's flags:
/// ``noise`` (``"paper"`` or ``"authors"``), sigma overrides,
/// ``orientation_prior`` (``"off"`` leaves the localiser's orientation out;
/// ``"auto"`` and ``"on"`` use it), robust kernels (``"none"``,
/// ``"huber[:k]"``, ``"cauchy[:c]"``), ``false_alarm`` of the tests for
/// single gross errors (a reading they find is left out and named in
/// ``report["readings_left_out"]``). A fit that fails its chi-square test
/// raises, as the command refuses to write it, unless
/// ``accept_inconsistent=True``. ``progress`` is an optional
/// ``callable(done, total, what)`` called before each of the three stages.
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (
    robot,
    measurements,
    noise = "paper",
    *,
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
pub fn calibrate_suspended(
    py: Python<'_>,
    robot: &SuspendedRobot,
    measurements: &Bound<'_, PyAny>,
    noise: &str,
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
) -> PyResult<SuspendedCalibration> {
    let nominal = robot.inner.clone();
    let settings = SolverArgs {
        model: "catenary",
        noise,
        encoder_sigma_m,
        load_cell_sigma_n,
        position_sigma_m,
        orientation_prior,
        robust_encoder,
        robust_load_cell,
        robust_pose,
    }
    .settings()?;
    let options = suspended_options(&settings, &nominal, FrontEnd::Python).map_err(to_py)?;
    let tests = GrossErrorOptions {
        false_alarm: check_false_alarm(false_alarm, "false_alarm", FrontEnd::Python).map_err(to_py)?,
        ..GrossErrorOptions::default()
    };
    let (data, label) = suspended_measurements(measurements, &nominal)?;
    let progress = Progress::new(progress);
    let result = py
        .detach(|| {
            let mut done = 0;
            calibrate_library(&nominal, &data, &options, Some(&tests), &mut |stage| {
                // A reading left out adds a solve to the three stages.
                progress.report(done, (done + 1).max(3), stage);
                done += 1;
            })
        })
        .map_err(to_py)?;
    let solves = result.stages.len();
    progress.report(solves, solves, "done");
    let report = SuspendedCalibrationReport::new(&nominal, &result);
    if let Some(reason) = report.inconsistency().filter(|_| !accept_inconsistent) {
        return Err(to_py(refusal(&label.display().to_string(), &reason, FrontEnd::Python)));
    }
    progress.finish()?;
    let json = serde_json::to_value(&report)
        .map_err(|e| crate::invalid(format!("cannot serialise the report as JSON: {e}")))?;
    Ok(SuspendedCalibration { result, report, json })
}

//! `sagcal.plan`: the calibration poses that make the anchors observable, in
//! a short visiting order, compared with random poses, exactly as `sagcal
//! plan` plans them (`sagcal::experiments::pose_plan`, shared with
//! `src/cli/plan.rs`).

use pyo3::prelude::*;
use sagcal::calib::OrientationPrior;
use sagcal::error::FrontEnd;
use sagcal::experiments::pose_plan::{
    parse_workspace, plan_calibration, workspace_from_bounds, CandidateSource, PlanSettings, PlannedCalibration,
};
use sagcal::model::robot::Workspace;
use sagcal::model::PoseMeasurement;
use sagcal::plan::information::noise_free_reading;
use sagcal::plan::Criterion;

use crate::arrays::{any_vector, out1, out2, out3};
use crate::data::{as_path, to_array};
use crate::json::to_python;
use crate::options::{noise_preset, parse};
use crate::progress::Progress;
use crate::robot::Robot;
use crate::{invalid, to_py};

/// The result of :func:`plan`: the chosen poses in visiting order (arrays
/// with one row per pose), the Cramer-Rao bound of the plan against random
/// pose sets of the same candidates, and the whole report as ``sagcal plan
/// --json`` prints it.
#[pyclass(module = "sagcal", name = "PosePlan", frozen)]
pub struct PosePlan {
    planned: PlannedCalibration,
    /// The plan as noise-free readings of the nominal model, in visiting order.
    readings: Vec<PoseMeasurement>,
}

#[pymethods]
impl PosePlan {
    /// Commanded platform positions in visiting order, metres: an (N, 3) array.
    #[getter]
    fn positions_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self.planned.report.plan.iter().map(|p| p.position_m).collect();
        out2(py, &rows)
    }

    /// The nominal model's orientation at each position ``(roll, pitch, yaw)``,
    /// degrees, ``R = Rz(yaw) Ry(pitch) Rx(roll)``: an (N, 3) array.
    #[getter]
    fn roll_pitch_yaw_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self.planned.report.plan.iter().map(|p| p.roll_pitch_yaw_deg).collect();
        out2(py, &rows)
    }

    /// The nominal model's cable lengths at each pose, cables 1..4, metres: an (N, 4) array.
    #[getter]
    fn cable_lengths_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 4]> = self.planned.report.plan.iter().map(|p| p.cable_lengths_m).collect();
        out2(py, &rows)
    }

    /// The smallest horizontal cable tension at each pose, newtons: an (N,) array.
    #[getter]
    fn min_horizontal_tension_n<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let values: Vec<f64> = self
            .planned
            .report
            .plan
            .iter()
            .map(|p| p.min_horizontal_tension_n)
            .collect();
        out1(py, &values)
    }

    /// The plan as an (N, 11) measurement array in visiting order (the
    /// columns of :data:`MEASUREMENT_COLUMNS`): commanded positions with the
    /// nominal model's orientation, encoder readings and reference tension,
    /// what ``sagcal plan --out`` writes.
    #[getter]
    fn measurements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_array(py, &self.readings)
    }

    /// The kept candidates' positions, metres: an (M, 3) array.
    #[getter]
    fn candidates_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self
            .planned
            .report
            .candidates
            .equilibria
            .iter()
            .map(|e| e.pose.position_m.into())
            .collect();
        out2(py, &rows)
    }

    /// The chosen candidates in visiting order: 0-based rows of :attr:`candidates_m`.
    #[getter]
    fn order(&self) -> Vec<usize> {
        self.planned.plan.order.clone()
    }

    /// The plan's bound on the anchors: per anchor its 3x3 covariance, m^2, a (4, 3, 3) array.
    #[getter]
    fn anchor_covariance_m2<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out3(py, &self.planned.plan.bound.anchor_covariance_m2)
    }

    /// The plan's bound, RMS per anchor (the Cramer-Rao bound at the nominal robot), metres.
    #[getter]
    fn anchor_bound_m(&self) -> f64 {
        self.planned.report.anchor_bound_m
    }

    /// The plan's bound, RMS per encoder offset, metres.
    #[getter]
    fn offset_bound_m(&self) -> f64 {
        self.planned.report.offset_bound_m
    }

    /// The mean bound of 100 random sets of as many candidates, RMS per anchor, metres.
    #[getter]
    fn random_anchor_bound_m(&self) -> f64 {
        self.planned.report.random_anchor_bound_m
    }

    /// The mean bound of 100 random sets of as many candidates, RMS per offset, metres.
    #[getter]
    fn random_offset_bound_m(&self) -> f64 {
        self.planned.report.random_offset_bound_m
    }

    /// The mean bound of 100 random sets of 35 candidates (the paper's
    /// largest Table II column), RMS per anchor, metres; ``None`` with fewer
    /// than 35 candidates.
    #[getter]
    fn random35_anchor_bound_m(&self) -> Option<f64> {
        self.planned.report.random35_anchor_bound_m
    }

    /// Length of the visiting path, metres.
    #[getter]
    fn path_length_m(&self) -> f64 {
        self.planned.report.path_length_m
    }

    /// The random seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.planned.report.seed
    }

    /// The whole plan as ``sagcal plan --json`` prints it (a dict).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.planned.report)
    }

    fn __repr__(&self) -> String {
        let report = &self.planned.report;
        format!(
            "PosePlan(robot={:?}, poses={}, anchor_bound_m={:.4}, random_anchor_bound_m={:.4}, seed={})",
            report.robot, report.poses, report.anchor_bound_m, report.random_anchor_bound_m, report.seed
        )
    }
}

/// Plan the calibration of ``robot`` (the nominal model), as ``sagcal plan``
/// does: choose the ``poses`` static poses whose readings best determine the
/// anchors and encoder offsets (the A- or D-optimal design on each
/// candidate's Fisher information, its own pose and tension eliminated),
/// order them into a short path (nearest neighbour + 2-opt), and compare
/// their Cramer-Rao bound with random sets of the same candidates.
///
/// ``candidates`` is the number of candidate poses to draw (1000, as the
/// command draws; ``None`` means the same; each a level
/// equilibrium that keeps the tension and clearance margins and hangs
/// stably), or poses already logged: the path of a file the command reads with
/// ``--from`` (sagcal CSV, RecurDyn log) or an (N, 11) measurement array.
/// Drawn candidates come from ``workspace`` (``x0, x1, y0, y1, z0, z1`` in
/// metres, six numbers or the command's text), else the robot file's
/// ``[workspace]``, else the frame below the anchors. ``noise`` (``"paper"``,
/// ``"authors"``) is the noise the bound assumes; ``criterion`` ``"a"``
/// (trace of the anchors' covariance) or ``"d"`` (log-determinant of the
/// information); ``orientation_prior`` ``"on"`` or ``"off"``/``"auto"``;
/// ``seed`` draws the candidates and the random sets (same seed, same plan);
/// ``progress`` an optional ``callable(done, total, what)`` called as the
/// plan goes (the candidates drawn so far, the poses chosen; ``what`` names
/// the stage, ``done`` counts within it), last with ``(1, 1, "done")``.
///
/// Raises :class:`SagcalError` with the command's message.
#[pyfunction]
#[pyo3(signature = (
    robot,
    poses,
    *,
    candidates = None,
    workspace = None,
    noise = "paper",
    criterion = "a",
    seed = 1,
    orientation_prior = "off",
    progress = None,
), text_signature = "(robot, poses, *, candidates=1000, workspace=None, noise='paper', criterion='a', seed=1, orientation_prior='off', progress=None)")]
#[allow(clippy::too_many_arguments)]
pub fn plan(
    py: Python<'_>,
    robot: &Robot,
    poses: usize,
    candidates: Option<&Bound<'_, PyAny>>,
    workspace: Option<&Bound<'_, PyAny>>,
    noise: &str,
    criterion: &str,
    seed: u64,
    orientation_prior: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<PosePlan> {
    let robot = robot.inner.clone();
    let workspace = workspace.map(workspace_argument).transpose()?;
    let settings = PlanSettings {
        poses,
        noise: noise_preset(noise)?,
        candidates: candidate_source(candidates, workspace, robot.reference_cable)?,
        seed,
        criterion: parse("criterion", criterion, Criterion::parse)?,
        orientation_prior: parse("orientation_prior", orientation_prior, OrientationPrior::parse)?,
        front_end: FrontEnd::Python,
    };
    let progress = Progress::new(progress);
    let planned = py
        .detach(|| {
            plan_calibration(&robot, &settings, &mut |step| {
                let (done, total, what) = step.counts();
                progress.report(done, total, &what)
            })
        })
        .map_err(to_py)?;
    progress.finish()?;
    let candidates = &planned.report.candidates.equilibria;
    let readings = planned
        .plan
        .order
        .iter()
        .map(|&k| noise_free_reading(&robot, &candidates[k]))
        .collect();
    Ok(PosePlan { planned, readings })
}

/// The workspace: the command's text `x0,x1,y0,y1,z0,z1`, or six numbers.
pub(crate) fn workspace_argument(value: &Bound<'_, PyAny>) -> PyResult<Workspace> {
    let checked = match value.extract::<String>() {
        Ok(text) => parse_workspace(&text),
        Err(_) => {
            let bounds = any_vector(value, "workspace")?;
            let text = bounds.iter().map(f64::to_string).collect::<Vec<_>>().join(",");
            workspace_from_bounds(&bounds, &text)
        }
    };
    checked.map_err(|e| invalid(format!("workspace: {e}")))
}

/// The candidates: a count to draw (default the command's), or logged poses (a path or an array).
fn candidate_source(
    value: Option<&Bound<'_, PyAny>>,
    workspace: Option<Workspace>,
    reference_cable: usize,
) -> PyResult<CandidateSource> {
    let count = match value {
        None => Some(sagcal::experiments::pose_plan::DEFAULT_CANDIDATES),
        Some(v) if as_path(v).is_some() => None,
        Some(v) if v.is_instance_of::<pyo3::types::PyBool>() => {
            return Err(invalid(
                "candidates: a count of poses to draw, a path or an (N, 11) array, not a bool",
            ));
        }
        Some(v) => match v.extract::<i64>() {
            Ok(n) => Some(usize::try_from(n).map_err(|_| {
                invalid(format!(
                    "candidates: a count of poses to draw cannot be negative, got {n}"
                ))
            })?),
            Err(_) => None,
        },
    };
    if let Some(count) = count {
        return Ok(CandidateSource::Drawn { workspace, count });
    }
    if workspace.is_some() {
        return Err(invalid(
            "workspace goes with drawn candidates (a count); logged poses bring their own positions",
        ));
    }
    let data = crate::data::measurements(value.expect("a value that is not a count"), reference_cable)?;
    Ok(CandidateSource::Logged {
        poses: data.poses,
        label: data.label.display().to_string(),
    })
}

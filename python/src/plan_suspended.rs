//! `sagcal.plan_suspended`: the calibration poses of a robot of 3 to 8
//! cables, exactly as `sagcal plan` plans them for such a robot
//! (`sagcal::experiments::suspended_plan`, shared with
//! `src/cli/plan_suspended.rs`).

use numpy::ndarray::Array2;
use pyo3::prelude::*;
use sagcal::calib::OrientationPrior;
use sagcal::error::FrontEnd;
use sagcal::experiments::pose_plan::DEFAULT_CANDIDATES;
use sagcal::experiments::suspended_plan::{
    plan_suspended as plan_n_cables, LoggedPoses, SuspendedPlanSettings, SuspendedPlanned,
};
use sagcal::io::suspended_measurements::{row_values, suspended_header};
use sagcal::model::suspended::SuspendedMeasurement;
use sagcal::plan::suspended_information::noise_free_suspended_reading;
use sagcal::plan::Criterion;

use crate::arrays::{frozen, out1, out2, out3};
use crate::calibrate_suspended::suspended_measurements;
use crate::json::to_python;
use crate::options::{noise_preset, parse};
use crate::plan::workspace_argument;
use crate::progress::Progress;
use crate::suspended::SuspendedRobot;
use crate::{invalid, to_py};

/// A plan of a robot of 3 to 8 cables: the chosen poses in visiting order,
/// their Cramer-Rao bound and the bound of random sets of as many poses.
#[pyclass(module = "sagcal", name = "SuspendedPlan", frozen)]
pub struct SuspendedPlan {
    planned: SuspendedPlanned,
    readings: Vec<SuspendedMeasurement>,
    header_width: usize,
}

#[pymethods]
impl SuspendedPlan {
    /// The chosen positions in visiting order, metres: a (poses, 3) array.
    #[getter]
    fn positions_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self.planned.report.plan.iter().map(|p| p.position_m).collect();
        out2(py, &rows)
    }

    /// The lengths the drums pay out at each pose, metres: a (poses, N) array.
    #[getter]
    fn cable_lengths_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let plan = &self.planned.report.plan;
        let n = self.planned.report.cables;
        let flat: Vec<f64> = plan.iter().flat_map(|p| p.cable_lengths_m.iter().copied()).collect();
        frozen(
            py,
            Array2::from_shape_vec((plan.len(), n), flat).expect("N lengths a pose"),
        )
    }

    /// Each pose's smallest horizontal cable tension, newtons: a (poses,) array.
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

    /// The nominal model's noise-free readings at the poses in visiting
    /// order, in the columns of :attr:`SuspendedRobot.columns` (what
    /// ``sagcal plan --out`` writes).
    #[getter]
    fn measurements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<f64> = self.readings.iter().flat_map(row_values).collect();
        frozen(
            py,
            Array2::from_shape_vec((self.readings.len(), self.header_width), flat).expect("rows of the header's width"),
        )
    }

    /// The candidates' indices in visiting order.
    #[getter]
    fn order(&self) -> Vec<usize> {
        self.planned.plan.order.clone()
    }

    /// Each anchor's 3x3 covariance of the bound, m^2: an (N, 3, 3) array.
    #[getter]
    fn anchor_covariance_m2<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out3(py, &self.planned.plan.bound.anchor_covariance_m2)
    }

    /// The plan's bound, RMS per anchor, metres.
    #[getter]
    fn anchor_bound_m(&self) -> f64 {
        self.planned.report.anchor_bound_m
    }

    /// The plan's bound, RMS per offset, metres.
    #[getter]
    fn offset_bound_m(&self) -> f64 {
        self.planned.report.offset_bound_m
    }

    /// The mean bound of random sets of as many poses, RMS per anchor, metres.
    #[getter]
    fn random_anchor_bound_m(&self) -> f64 {
        self.planned.report.random_anchor_bound_m
    }

    /// The visiting path's length, metres.
    #[getter]
    fn path_length_m(&self) -> f64 {
        self.planned.report.path_length_m
    }

    /// The report as ``sagcal plan --json`` prints it (a dict).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.planned.report)
    }

    fn __repr__(&self) -> String {
        let report = &self.planned.report;
        format!(
            "SuspendedPlan(robot={:?}, cables={}, poses={}, anchor_bound_m={:.4}, random_anchor_bound_m={:.4}, seed={})",
            report.robot, report.cables, report.poses, report.anchor_bound_m, report.random_anchor_bound_m, report.seed
        )
    }
}

/// Plan the calibration of a robot of 3 to 8 cables: ``poses`` poses among
/// ``candidates`` level equilibria drawn in ``workspace`` (the robot file's
/// by default), as ``sagcal plan --robot`` plans them; ``progress(done,
/// total, what)`` follows the draw and the choice. ``candidates`` may
/// instead be poses already logged, as ``sagcal plan --from`` reads them:
/// the path of a measurement file of the robot or an array in the columns
/// of :attr:`SuspendedRobot.columns` (each row the nominal model's
/// equilibrium at its logged position).
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
pub fn plan_suspended(
    py: Python<'_>,
    robot: &SuspendedRobot,
    poses: usize,
    candidates: Option<&Bound<'_, PyAny>>,
    workspace: Option<&Bound<'_, PyAny>>,
    noise: &str,
    criterion: &str,
    seed: u64,
    orientation_prior: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<SuspendedPlan> {
    let robot = robot.inner.clone();
    let (candidates, logged) = candidate_source(candidates, &robot)?;
    let settings = SuspendedPlanSettings {
        poses,
        noise: noise_preset(noise)?,
        candidates,
        logged,
        workspace: workspace.map(workspace_argument).transpose()?,
        seed,
        criterion: parse("criterion", criterion, Criterion::parse)?,
        orientation_prior: parse("orientation_prior", orientation_prior, OrientationPrior::parse)?,
        front_end: FrontEnd::Python,
    };
    let progress = Progress::new(progress);
    let planned = py
        .detach(|| {
            plan_n_cables(&robot, &settings, &mut |step| {
                let (done, total, what) = step.counts();
                progress.report(done, total, &what)
            })
        })
        .map_err(to_py)?;
    progress.finish()?;
    let readings = planned
        .plan
        .order
        .iter()
        .map(|&k| noise_free_suspended_reading(&robot, &planned.candidates[k]))
        .collect();
    Ok(SuspendedPlan {
        header_width: suspended_header(&robot).len(),
        planned,
        readings,
    })
}

/// ``candidates``: a count to draw (the command's 1000 without one), or
/// logged poses (a path or an array).
fn candidate_source(
    candidates: Option<&Bound<'_, PyAny>>,
    robot: &sagcal::model::suspended::SuspendedRobot,
) -> PyResult<(usize, Option<LoggedPoses>)> {
    let Some(value) = candidates else {
        return Ok((DEFAULT_CANDIDATES, None));
    };
    if let Ok(count) = value.extract::<i64>() {
        return usize::try_from(count).map(|n| (n, None)).map_err(|_| {
            invalid(format!(
                "candidates: {count}: the number of candidates to draw, at least the poses asked for"
            ))
        });
    }
    let (rows, path) = suspended_measurements(value, robot)?;
    let label = path.display().to_string();
    Ok((DEFAULT_CANDIDATES, Some(LoggedPoses { rows, label })))
}

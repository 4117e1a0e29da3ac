//! `sagcal.SuspendedRobot` and `sagcal.simulate_suspended`: robots of 3 to
//! 8 cables and their simulated measurements, as `sagcal simulate` draws
//! them for such a robot (`src/cli/simulate_suspended.rs`): the same seed
//! gives the same numbers as the command's file.

use std::path::PathBuf;

use numpy::ndarray::Array2;
use pyo3::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::error::FrontEnd;
use sagcal::io::suspended_measurements::{row_values, suspended_header, write_suspended_measurements};
use sagcal::model::suspended::SuspendedMeasurement;
use sagcal::sim::closed_form::{Closure, Workspace};
use sagcal::sim::suspended::sample_suspended;
use sagcal::sim::suspended_effects::{effects_from_specs, simulate_readings};

use crate::arrays::frozen;
use crate::options::{noise_preset, parse};
use crate::to_py;

/// A robot of 3 to 8 sagging cables, each with its own weight per metre and
/// load cells on any of them (the robot file's ``load_cells``). Read one
/// with :meth:`SuspendedRobot.builtin` (``"three"``, ``"six"``,
/// ``"eight"``, and the paper's ``"large"`` and ``"small"``) or
/// :meth:`SuspendedRobot.from_file`.
#[pyclass(module = "sagcal", name = "SuspendedRobot", frozen)]
pub struct SuspendedRobot {
    pub(crate) inner: sagcal::model::suspended::SuspendedRobot,
}

#[pymethods]
impl SuspendedRobot {
    /// A built-in robot by name.
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        sagcal::model::suspended::SuspendedRobot::builtin(name)
            .map(|inner| Self { inner })
            .map_err(to_py)
    }

    /// A robot file of 3 to 8 cables, checked as ``sagcal simulate`` checks it.
    #[staticmethod]
    fn from_file(path: PathBuf) -> PyResult<Self> {
        sagcal::model::suspended::SuspendedRobot::from_file(&path)
            .map(|inner| Self { inner })
            .map_err(to_py)
    }

    /// The robot's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The number of cables.
    #[getter]
    fn cable_count(&self) -> usize {
        self.inner.cable_count()
    }

    /// The cables with a load cell, 1-based, ascending.
    #[getter]
    fn load_cells(&self) -> Vec<usize> {
        self.inner.load_cells.iter().map(|c| c + 1).collect()
    }

    /// The columns of this robot's measurements, in order: the pose,
    /// ``l1_m`` .. ``lN_m``, then ``f<k>_n`` for each load cell.
    #[getter]
    fn columns(&self) -> Vec<String> {
        suspended_header(&self.inner)
    }

    /// The anchors of cables 1..N, world frame, metres: an (N, 3) array.
    #[getter]
    fn anchors_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<[f64; 3]> = self.inner.anchors_m.iter().map(|a| (*a).into()).collect();
        crate::arrays::out2(py, &rows)
    }

    /// The encoder length offsets of cables 1..N, metres: an (N,) array.
    #[getter]
    fn length_offsets_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::arrays::out1(py, &self.inner.length_offsets_m)
    }

    /// Each cable's axial stiffness ``EA`` in newtons, ``None`` for an
    /// inextensible cable (the robot file's ``axial_stiffness_n``).
    #[getter]
    fn axial_stiffness_n(&self) -> Vec<Option<f64>> {
        self.inner
            .axial_stiffness_n
            .iter()
            .map(|ea| ea.is_finite().then_some(*ea))
            .collect()
    }

    /// The robot file's text (TOML), as ``sagcal calibrate --out`` writes it
    /// (without a covariance).
    fn toml(&self) -> PyResult<String> {
        self.inner.to_toml(None).map_err(to_py)
    }

    fn __repr__(&self) -> String {
        format!(
            "SuspendedRobot(name={:?}, cables={}, load_cells={:?})",
            self.inner.name,
            self.inner.cable_count(),
            self.load_cells()
        )
    }
}

/// The result of :func:`simulate_suspended`: the measurements, the robot and the seed.
#[pyclass(module = "sagcal", name = "SuspendedSimulation", frozen)]
pub struct SuspendedSimulation {
    rows: Vec<SuspendedMeasurement>,
    robot: sagcal::model::suspended::SuspendedRobot,
    seed: u64,
}

#[pymethods]
impl SuspendedSimulation {
    /// The measurements: an (N, 6 + cables + load cells) array in the
    /// columns of :attr:`SuspendedRobot.columns`.
    #[getter]
    fn measurements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let width = suspended_header(&self.robot).len();
        let flat: Vec<f64> = self.rows.iter().flat_map(row_values).collect();
        frozen(
            py,
            Array2::from_shape_vec((self.rows.len(), width), flat).expect("rows of the header's width"),
        )
    }

    /// The random seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.seed
    }

    /// Write the measurements as ``sagcal simulate`` writes them (atomically),
    /// each of ``comments`` a ``# ...`` line before the header.
    #[pyo3(signature = (path, comments = None))]
    fn write(&self, path: PathBuf, comments: Option<Vec<String>>) -> PyResult<()> {
        write_suspended_measurements(&path, &self.robot, &comments.unwrap_or_default(), &self.rows).map_err(to_py)
    }

    fn __repr__(&self) -> String {
        format!(
            "SuspendedSimulation(robot={:?}, cables={}, poses={}, seed={})",
            self.robot.name,
            self.robot.cable_count(),
            self.rows.len(),
            self.seed
        )
    }
}

/// Simulate ``poses`` static poses of a robot of 3 to 8 cables and what its
/// sensors read there, as ``sagcal simulate`` does with the same arguments:
/// positions drawn uniformly in the robot's workspace, each the equilibrium
/// its ``closure`` picks (``"level"``; ``"yaw"`` or ``"mixed"`` from four
/// cables on), stable and with every cable taut, readings with ``noise``
/// (``"paper"``, ``"authors"`` or ``"none"``). With ``effects`` (specs as
/// ``sagcal simulate --effect`` takes them, e.g. ``"elastic:ea_n=3e6"``)
/// the readings come from the discretised simulator with ``segments``
/// segments per cable, the robot commanded to each equilibrium's lengths.
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (robot, poses, seed = 1, noise = "paper", *, closure = "level", effects = None, segments = 100))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_suspended(
    py: Python<'_>,
    robot: &SuspendedRobot,
    poses: usize,
    seed: u64,
    noise: &str,
    closure: &str,
    effects: Option<Vec<String>>,
    segments: usize,
) -> PyResult<SuspendedSimulation> {
    let robot = robot.inner.clone();
    let noise = noise_preset(noise)?.sigmas(robot.platform_weight_n);
    let closure = parse("closure", closure, Closure::parse)?;
    let effects = effects_from_specs(&effects.unwrap_or_default(), FrontEnd::Python).map_err(to_py)?;
    let rows = py
        .detach(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let workspace = robot
                .workspace
                .unwrap_or_else(|| Workspace::around_anchor_points(&robot.anchors_m));
            let equilibria = sample_suspended(&robot, &workspace, poses, closure, &mut rng)?;
            simulate_readings(&robot, &effects, &equilibria, &noise, segments, &mut rng)
        })
        .map_err(to_py)?;
    Ok(SuspendedSimulation { rows, robot, seed })
}

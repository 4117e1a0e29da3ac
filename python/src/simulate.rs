//! `sagcal.simulate`: simulated measurements of a robot, drawn as `sagcal
//! simulate` draws them (`src/cli/simulate.rs`): the same seed gives the
//! same numbers as the command's file.

use pyo3::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::error::FrontEnd;
use sagcal::sim::closed_form::{measure, sample_equilibria_with, Closure, Workspace};
use sagcal::sim::effects::{measure_with_effects, simulation_truth};

use crate::data::to_array;
use crate::options::{noise_preset, parse};
use crate::robot::Robot;
use crate::to_py;

/// The result of :func:`simulate`: the measurements and the truth they came from.
#[pyclass(module = "sagcal", name = "Simulation", frozen)]
pub struct Simulation {
    measurements: Vec<sagcal::model::PoseMeasurement>,
    truth: sagcal::model::Robot,
    seed: u64,
}

#[pymethods]
impl Simulation {
    /// The simulated measurements: an (N, 11) array in the columns of
    /// :data:`MEASUREMENT_COLUMNS`, ready for :func:`calibrate`.
    #[getter]
    fn measurements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_array(py, &self.measurements)
    }

    /// The true robot (the robot given, with the effects applied): what a calibration should recover.
    #[getter]
    fn truth(&self) -> Robot {
        Robot::new(self.truth.clone())
    }

    /// The random seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.seed
    }

    fn __repr__(&self) -> String {
        format!(
            "Simulation(robot={:?}, poses={}, seed={})",
            self.truth.name,
            self.measurements.len(),
            self.seed
        )
    }
}

/// Simulate ``poses`` static poses of ``robot`` and what its sensors read
/// there, as ``sagcal simulate`` does with the same arguments: positions drawn
/// uniformly in the robot's workspace, each pose's equilibrium from the
/// closed-form catenary statics (closed by ``closure``: ``"level"``,
/// ``"yaw"`` or ``"mixed"``), readings with ``noise`` (``"paper"``,
/// ``"authors"``, ``"none"``). The robot's ``length_offsets_m`` are the
/// encoders' true offsets.
///
/// ``effects`` (optional) lists physical effects the closed-form model lacks, each
/// ``"NAME:PARAM=VALUE[,PARAM=VALUE...]"`` as ``--effect`` takes them
/// (``"elastic:ea_n=3e6"``, ``"pulley:radius_m=0.1"``, ...); with effects
/// (or a robot whose ``effects`` are set) the readings come from the
/// discretised simulator with ``segments`` per cable. The same ``seed`` gives
/// the same numbers, bit for bit, as the command's measurement file.
///
/// Raises :class:`SagcalError` with the message the command prints.
#[pyfunction]
#[pyo3(signature = (robot, poses, seed = 1, noise = "paper", *, effects = None, segments = 100, closure = "level"))]
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    py: Python<'_>,
    robot: &Robot,
    poses: usize,
    seed: u64,
    noise: &str,
    effects: Option<Vec<String>>,
    segments: usize,
    closure: &str,
) -> PyResult<Simulation> {
    let truth = simulation_truth(
        &robot.inner,
        poses,
        &effects.unwrap_or_default(),
        segments,
        FrontEnd::Python,
    )
    .map_err(to_py)?;
    let noise = noise_preset(noise)?.sigmas(truth.platform_weight_n);
    let closure = parse("closure", closure, Closure::parse)?;
    let measurements = py
        .detach(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let workspace = Workspace::default_for(&truth);
            let equilibria = sample_equilibria_with(&truth, &workspace, poses, closure, &mut rng)?;
            if truth.effects.is_none() {
                Ok(measure(&truth, &equilibria, &noise, &mut rng))
            } else {
                measure_with_effects(&truth, &truth.effects, &equilibria, &noise, segments, &mut rng)
            }
        })
        .map_err(to_py)?;
    Ok(Simulation {
        measurements,
        truth,
        seed,
    })
}

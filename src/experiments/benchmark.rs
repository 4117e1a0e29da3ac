//! The benchmark problem: one catenary calibration graph, reproducible from
//! `(poses, seed)`, shared by the solver-scaling benches (`benches/solver.rs`)
//! and the peer comparison (`peers/`), so that every solver sees the same
//! residuals, initial values, noise weights and cost.
//!
//! Data: `poses` static equilibria of the built-in large robot drawn in its
//! workspace ([`crate::sim::closed_form::sample_equilibria`]), read with the
//! authors' sensor noise. Initial guess: every anchor 0.1 m off the truth in
//! a random direction, every length offset 0.05 m off, the poses and
//! reference tensions from the per-pose statics at those anchors
//! ([`crate::calib::warm_start`]). The graph is the final catenary stage of
//! [`crate::calib::calibrate`] (catenary length, attachment height at 0.1 mm,
//! reference tension, pose prior with orientation), see
//! [`BenchmarkProblem::graph`].
//!
//! ```
//! use sagcal::experiments::benchmark::{BenchmarkProblem, OFFSET_PERTURBATION_M};
//! use sagcal::graph::FactorGraph;
//! let problem = BenchmarkProblem::new(5, 7)?;
//! for i in 0..4 {
//!     let moved = problem.initial.length_offsets_m[i] - problem.truth.length_offsets_m[i];
//!     assert!((moved.abs() - OFFSET_PERTURBATION_M).abs() < 1e-12);
//! }
//! let built = problem.graph();
//! // Per pose: catenary length (eq. 14, 4 rows), attachment height (eq. 15, 4),
//! // reference tension (eq. 16, 1) and pose prior (6); no tension guard.
//! for kind in ["catenary_length", "attachment_height", "reference_tension", "pose_prior"] {
//!     assert_eq!(built.graph.factors.iter().filter(|f| f.kind() == kind).count(), 5, "{kind}");
//! }
//! let rows: usize = built.graph.factors.iter().map(|f| f.residual_dim()).sum();
//! assert_eq!((built.graph.factors.len(), rows), (20, 5 * 15));
//! // The poses start on their statics at the initial anchors: the 0.1 mm height
//! // constraints hold there (cost far below one per row).
//! let values = &built.graph.values;
//! let heights = built.graph.factors.iter().filter(|f| f.kind() == "attachment_height");
//! let height_cost: f64 = heights.map(|f| FactorGraph::factor_cost(f.as_ref(), values).unwrap()).sum();
//! assert!(height_cost < 1e-6, "{height_cost}");
//! assert_eq!(BenchmarkProblem::stopping().max_iterations, 100);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::calib::{build_graph, warm_start, CableModel, CalibrationGraph, CalibrationOptions, OrientationPrior};
use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::NoisePreset;
use crate::model::statics::CableTension;
use crate::model::statics::{self, Equilibrium, StaticsOptions};
use crate::sim::closed_form::{measure, Workspace};
use crate::solver::LmParams;

/// Distance of every initial anchor from the truth, metres.
pub const ANCHOR_PERTURBATION_M: f64 = 0.1;
/// Distance of every initial length offset from the truth, metres.
pub const OFFSET_PERTURBATION_M: f64 = 0.05;

/// Largest platform rotation of a benchmark pose, radians (3 degrees).
pub const MAX_TILT_RAD: f64 = 3.0 * std::f64::consts::PI / 180.0;

/// A calibration problem with its truth and initial values.
#[derive(Debug, Clone)]
pub struct BenchmarkProblem {
    /// The robot that generated the data.
    pub truth: Robot,
    /// The initial guess of anchors and offsets.
    pub initial: Robot,
    /// The measurements.
    pub measurements: Vec<PoseMeasurement>,
    /// Initial platform poses.
    pub initial_poses: Vec<PlatformPose>,
    /// Initial reference tensions.
    pub initial_tensions: Vec<CableTension>,
    /// Noise weights and factor settings (orientation prior on).
    pub options: CalibrationOptions,
    /// The seed the data and the guess were drawn with.
    pub seed: u64,
}

impl BenchmarkProblem {
    /// Draw the problem with `poses` poses from `seed`.
    pub fn new(poses: usize, seed: u64) -> Result<Self> {
        let truth = Robot::builtin("large")?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let equilibria = sample_poses(&truth, poses, &mut rng)?;
        let noise = NoisePreset::Authors.sigmas(truth.platform_weight_n);
        let measurements = measure(&truth, &equilibria, &noise, &mut rng);
        let mut initial = truth.clone();
        for i in 0..CABLE_COUNT {
            let direction = loop {
                let v = Vector3::from_fn(|_, _| StandardNormal.sample(&mut rng));
                if v.norm() > 1e-3 {
                    break v.normalize();
                }
            };
            initial.anchors_m[i] += ANCHOR_PERTURBATION_M * direction;
            initial.length_offsets_m[i] += if rng.random_bool(0.5) {
                OFFSET_PERTURBATION_M
            } else {
                -OFFSET_PERTURBATION_M
            };
        }
        // Like the final stage of `calibrate`, which leaves out poses without an
        // equilibrium at its anchors: such poses are replaced by new draws.
        let (mut initial_poses, mut initial_tensions, mut failures) = warm_start(&initial, &measurements);
        let mut measurements = measurements;
        let mut rounds = 0;
        while !failures.is_empty() {
            rounds += 1;
            if rounds > 100 {
                return Err(Error::NoEquilibrium(
                    "benchmark poses keep failing the warm start at the initial anchors".into(),
                ));
            }
            let redrawn = measure(
                &truth,
                &sample_poses(&truth, failures.len(), &mut rng)?,
                &noise,
                &mut rng,
            );
            let (poses, tensions, still) = warm_start(&initial, &redrawn);
            for (j, &k) in failures.iter().enumerate() {
                measurements[k] = redrawn[j];
                initial_poses[k] = poses[j];
                initial_tensions[k] = tensions[j];
            }
            failures = still.iter().map(|&j| failures[j]).collect();
        }
        let mut options = CalibrationOptions::new(noise);
        options.orientation_prior = OrientationPrior::On;
        options.lm = Self::stopping();
        Ok(Self {
            truth,
            initial,
            measurements,
            initial_poses,
            initial_tensions,
            options,
            seed,
        })
    }

    /// The paper's factor graph at the initial values: per pose the catenary
    /// length (eq. 14), attachment height (eq. 15), reference tension (eq. 16)
    /// and pose prior factors, the anchors and offsets global. It is the final
    /// catenary stage of [`crate::calib::calibrate`] without its tension guard
    /// (a one-sided path constraint, zero on these poses, that the peers
    /// would have to model as a hinge). Its local groups (pose and reference
    /// tension) stay: [`BenchmarkProblem::stopping`] turns their nonlinear
    /// refinement off (plain Levenberg-Marquardt, as the peers run), and the
    /// linear solver eliminates them block by block.
    pub fn graph(&self) -> CalibrationGraph {
        let mut built = build_graph(
            &self.initial,
            &self.measurements,
            &self.initial_poses,
            &self.initial_tensions,
            CableModel::Catenary,
            &self.options,
        );
        built.graph.factors.retain(|f| f.kind() != "tension_guard");
        built
    }

    /// The stopping rule of every solver in the benchmarks: at most 100
    /// iterations; stop when an accepted step lowers the cost by less than
    /// 1e-10 of itself (or the gradient's largest component falls below
    /// 1e-10, or the step below 1e-12 of the variables' scale); no local
    /// refinement.
    pub fn stopping() -> LmParams {
        LmParams {
            max_iterations: 100,
            relative_cost_tolerance: 1e-10,
            gradient_tolerance: 1e-10,
            relative_step_tolerance: 1e-12,
            local_refinement: false,
            ..LmParams::default()
        }
    }
}

/// `count` static equilibria at uniform positions in the robot's workspace,
/// each with a reference-tension magnitude within 5 % of the straight-cable
/// guess ([`statics::reference_tension_magnitude_guess`]) and a platform within
/// [`MAX_TILT_RAD`] of level (as a robot commanding a level platform holds
/// it; strongly tilted members of the equilibrium family have a nearly slack
/// cable). One statics solve per draw (the
/// level search of [`crate::sim::closed_form::sample_equilibria`] takes ~70,
/// too slow for 10 000 poses); positions without an equilibrium are redrawn.
fn sample_poses(robot: &Robot, count: usize, rng: &mut impl Rng) -> Result<Vec<Equilibrium>> {
    let workspace = Workspace::default_for(robot);
    let options = StaticsOptions::default();
    let mut equilibria = Vec::with_capacity(count);
    let mut attempts = 0;
    while equilibria.len() < count {
        attempts += 1;
        if attempts > 100 * count + 1000 {
            return Err(Error::NoEquilibrium(format!(
                "only {} of {count} benchmark poses found in {workspace:?}",
                equilibria.len()
            )));
        }
        let position = Vector3::from_fn(|i, _| rng.random_range(workspace.min_m[i]..=workspace.max_m[i]));
        let magnitude = statics::reference_tension_magnitude_guess(robot, position) * rng.random_range(0.95..=1.05);
        match statics::solve_with_reference_tension(robot, position, magnitude, None, &options) {
            Ok(eq) if eq.pose.rotation.angle() < MAX_TILT_RAD => equilibria.push(eq),
            _ => {}
        }
    }
    Ok(equilibria)
}

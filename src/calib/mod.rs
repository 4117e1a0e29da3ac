//! Self-calibration (paper Sec. IV): estimate the four anchors and the four
//! encoder length offsets from the robot's own sensors at static poses.
//!
//! The factor graph has, per pose `k`, the platform pose `X_k` and the
//! reference-cable tension `(f_h, f_v)_k`, and globally the anchors `p_a,i`
//! and offsets `l_i^0`. Factors: catenary length (eq. 14), attachment height
//! (eq. 15), reference tension (eq. 16), pose prior, and a positivity guard
//! on every cable's horizontal tension (inactive at the optimum).
//!
//! **Orientation.** The paper adds an orientation-correction variable
//! `Delta R_k` so that the statics, not the localiser's orientation, decide
//! how the platform hangs. sagcal's pose variable already carries the full
//! orientation, and the pose prior's orientation part is switchable
//! ([`OrientationPrior`]). Where the localiser's orientation agrees with the
//! statics it is information (on the small robot it halves the anchor error);
//! where it does not (the RecurDyn log is ~1.9 degrees off the model's
//! equilibria, 3 sigma under the paper's noise and 20 under the authors') a
//! tight prior would fight the statics and bias the anchors by metres. The
//! default, [`OrientationPrior::Auto`], decides from the data: it calibrates
//! with the prior, tests the orientation residuals by chi-square, and if they
//! are inconsistent calibrates again without it, which is the paper's
//! `Delta R` with no prior on it. The decision is in
//! [`CalibrationResult::orientation_check`].
//!
//! **Initialisation** ([`calibrate`]): (1) a rigid massless-cable calibration
//! from the initial guess (a benign trilateration-like problem), (2) a per-pose
//! warm-up: the statics (problem (a)) at each measured position and load-cell
//! tension with the stage-1 anchors gives every pose a consistent orientation
//! and tension, (3) the full catenary graph. Eq. (17)-(18) alone often start
//! with negative tensions in other cables; this sequence does not.
//!
//! **Solving.** Each pose's variables (platform pose, reference tension) form
//! a local group of the graph: after every trial step the solver re-fits each
//! pose to its own factors with the anchors and offsets held, so a step of
//! the anchors is judged with every pose back on its statics. Without it the
//! 0.1 mm attachment-height constraint bends the valley so sharply that LM
//! creeps along it (the small robot, with its nearly vertical cables, hit
//! 500 iterations in most trials).

pub mod effect_factors;
pub mod factors;
pub mod report;

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::graph::{whitened_squared_norm, FactorGraph, RobustKernel, Values, VariableId, VariableValue};
use crate::model::effects::{EffectKind, Effects};
use crate::model::measurement::PoseMeasurement;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::model::statics::{self, CableTension, Equilibrium, StaticsOptions};
use crate::solver::{marginal_covariance, optimize, Covariance, LmParams, SolveSummary, UnobservableDirection};
use crate::stats::chi_square_quantile_999;

use effect_factors::{EffectVariables, ExtendedHeightFactor, ExtendedLengthFactor, LoadCellFactor};
use factors::{
    AttachmentHeightFactor, CalibrationVariables, CatenaryLengthFactor, PosePriorFactor, PoseVariables,
    ReferenceTensionFactor, RigidLengthFactor, SlotOrder, TensionGuardFactor,
};

/// The cable model of the length factor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CableModel {
    /// Heavy inextensible cable (paper eq. 1-4, 14-16). The default.
    Catenary,
    /// Massless straight cable (the paper's Sec. VI-A baseline).
    Rigid,
}

impl CableModel {
    /// Parse `catenary` or `rigid`.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        match text {
            "catenary" => Ok(CableModel::Catenary),
            "rigid" => Ok(CableModel::Rigid),
            other => Err(format!("unknown cable model `{other}` (catenary, rigid)")),
        }
    }
}

/// Whether the localiser's orientation enters the calibration as a prior.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OrientationPrior {
    /// Position-only pose priors: the statics alone decide the orientation
    /// (the paper's orientation correction `Delta R` with no prior on it).
    Off,
    /// Full pose priors with the noise's orientation sigma.
    On,
    /// Calibrate with the orientation prior, test whether the localiser's
    /// orientations agree with the fitted statics (chi-square of the
    /// orientation residuals at 99.9 %), and drop the prior if they do not.
    /// The default.
    Auto,
}

impl OrientationPrior {
    /// Parse `auto`, `on` or `off`.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        match text {
            "auto" => Ok(OrientationPrior::Auto),
            "on" => Ok(OrientationPrior::On),
            "off" => Ok(OrientationPrior::Off),
            other => Err(format!("unknown orientation prior `{other}` (auto, on, off)")),
        }
    }
}

impl std::fmt::Display for OrientationPrior {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            OrientationPrior::Off => "off",
            OrientationPrior::On => "on",
            OrientationPrior::Auto => "auto",
        })
    }
}

/// The consistency test of the localiser's orientations with the fitted
/// statics, and what the calibration did with it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OrientationCheck {
    /// Whether the final calibration used the orientation prior.
    pub prior_used: bool,
    /// `sum |log(R_measured^T R_fitted)|^2 / sigma^2` over the poses, with the prior on.
    pub chi_square: f64,
    /// Number of orientation residual components (3 per pose).
    pub components: usize,
    /// The 99.9 % quantile of chi-square with `components` degrees of freedom
    /// (Wilson-Hilferty); above it the orientations are declared inconsistent.
    pub limit: f64,
    /// Mean angle between measured and fitted orientations, degrees.
    pub mean_angle_deg: f64,
}

/// Robust kernels per factor type.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct RobustKernels {
    /// On the encoder (length) factors.
    pub encoder: RobustKernel,
    /// On the load-cell factor.
    pub load_cell: RobustKernel,
    /// On the pose priors.
    pub pose_prior: RobustKernel,
}

/// How to calibrate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibrationOptions {
    /// Cable model of the final stage.
    pub model: CableModel,
    /// Sensor sigmas used as the factors' noise.
    pub noise: SensorNoise,
    /// Constrain the orientation by the localiser too (default: decide by a
    /// consistency test, see the module docs). The rigid model always uses
    /// it: without statics nothing else fixes the orientation.
    pub orientation_prior: OrientationPrior,
    /// Sigma of the attachment-height constraint, metres (a model equation: tight).
    pub height_sigma_m: f64,
    /// Robust kernels.
    pub robust: RobustKernels,
    /// Solver settings.
    pub lm: LmParams,
    /// An effect of the catalogue whose parameters are estimated too (the
    /// extended model, [`effect_factors`]); `None`: the effects of the robot
    /// file (`[effects]`, default none) are known inputs, held fixed.
    pub free_effect: Option<EffectKind>,
}

impl CalibrationOptions {
    /// Catenary model, automatic orientation prior, 0.1 mm height constraint, no robust kernels.
    pub fn new(noise: SensorNoise) -> Self {
        Self {
            model: CableModel::Catenary,
            noise,
            orientation_prior: OrientationPrior::Auto,
            height_sigma_m: 1e-4,
            robust: RobustKernels::default(),
            lm: LmParams::default(),
            free_effect: None,
        }
    }
}

/// One solver stage of a calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageSummary {
    /// `rigid`, `catenary`.
    pub name: String,
    /// The solver's account.
    pub summary: SolveSummary,
}

/// Normalised residuals `r / sigma` of one factor type at the solution.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FactorStatistics {
    /// Factor type.
    pub kind: String,
    /// Number of factors.
    pub factors: usize,
    /// Number of residual components.
    pub components: usize,
    /// Root mean square of `r / sigma` (about 1 when the stated noise is right).
    pub rms: f64,
    /// Largest `|r / sigma|`.
    pub max_abs: f64,
    /// Sum of `(r / sigma)^2`.
    pub chi_square: f64,
}

/// What the data say about the calibrated parameters' uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ParameterUncertainty {
    /// The information matrix is full rank.
    Full {
        /// Per anchor, its 3x3 covariance, m^2 (row-major).
        anchor_covariance_m2: Vec<[[f64; 3]; 3]>,
        /// Per anchor, the 1-sigma of x, y, z, metres.
        anchor_sigma_m: Vec<[f64; 3]>,
        /// Per offset, its 1-sigma, metres.
        offset_sigma_m: Vec<f64>,
    },
    /// Some directions of parameter space are not observable from these poses.
    RankDeficient {
        /// The unobservable directions.
        directions: Vec<UnobservableDirection>,
    },
}

/// The result of a calibration.
#[derive(Debug, Clone)]
pub struct CalibrationResult {
    /// The calibrated robot (anchors and length offsets replaced).
    pub robot: Robot,
    /// Uncertainty of anchors and offsets.
    pub uncertainty: ParameterUncertainty,
    /// Solver stages in order.
    pub stages: Vec<StageSummary>,
    /// Residual statistics per factor type at the solution.
    pub factor_statistics: Vec<FactorStatistics>,
    /// Estimated platform poses.
    pub poses: Vec<PlatformPose>,
    /// Estimated reference tensions `(f_h, f_v)` (catenary model), newtons.
    pub reference_tensions_n: Vec<[f64; 2]>,
    /// Indices (into the measurements) of poses left out of the final stage:
    /// no positive-tension equilibrium near them with the calibrated anchors.
    pub excluded_poses: Vec<usize>,
    /// The orientation consistency test (catenary model with
    /// [`OrientationPrior::Auto`]; `None` otherwise).
    pub orientation_check: Option<OrientationCheck>,
    /// The estimated effect ([`CalibrationOptions::free_effect`]), with 1-sigma.
    pub effect_estimate: Option<EffectEstimate>,
}

impl EffectEstimate {
    /// Report values (gains as `1 + error`) from the effect variable's contents.
    pub fn values_from_variable(kind: EffectKind, raw: &[f64]) -> Vec<f64> {
        match kind {
            EffectKind::EncoderScale => raw.iter().map(|g| 1.0 + g).collect(),
            EffectKind::LoadCell => vec![raw[0], 1.0 + raw[1]],
            _ => raw.to_vec(),
        }
    }

    /// The effect variable's contents (gain errors) for these estimates: the
    /// inverse of [`EffectEstimate::values_from_variable`].
    pub fn variable_values(&self) -> Vec<f64> {
        match self.effect {
            EffectKind::EncoderScale => self.values.iter().map(|g| g - 1.0).collect(),
            EffectKind::LoadCell => vec![self.values[0], self.values[1] - 1.0],
            _ => self.values.clone(),
        }
    }
}

/// An effect's estimated parameters with their 1-sigma uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectEstimate {
    /// The effect.
    pub effect: EffectKind,
    /// Parameter names ([`EffectKind::parameter_names`]).
    pub names: Vec<String>,
    /// Estimates, in the units of the names (gains as `1 + error`).
    pub values: Vec<f64>,
    /// 1-sigma of each estimate (NaN where the information matrix is singular).
    pub sigmas: Vec<f64>,
}

impl CalibrationResult {
    /// The last stage's summary.
    pub fn final_stage(&self) -> &SolveSummary {
        &self
            .stages
            .last()
            .expect("a calibration has at least one stage")
            .summary
    }

    /// Whether the last stage stopped at a minimum.
    pub fn converged(&self) -> bool {
        self.final_stage().termination.converged()
    }

    /// The estimated reference tensions as [`CableTension`]s (one per pose used).
    pub fn reference_tensions(&self) -> Vec<CableTension> {
        self.reference_tensions_n
            .iter()
            .map(|t| CableTension {
                horizontal_n: t[0],
                vertical_n: t[1],
            })
            .collect()
    }
}

/// The minimum number of poses: each adds 8 unknowns (pose, reference tension)
/// and 12 equations (4 encoders, 1 load cell, 3 position priors, 4 heights),
/// so `4 N >= 16` global unknowns.
pub const MIN_POSES: usize = 4;

/// Check the measurements before building a problem.
pub fn validate_measurements(measurements: &[PoseMeasurement]) -> Result<()> {
    if measurements.len() < MIN_POSES {
        return Err(Error::InvalidInput(format!(
            "{} poses cannot determine 12 anchor coordinates and 4 offsets: each pose adds 4 independent equations, so at least {MIN_POSES} distinct poses are needed (the paper uses 9 to 35)",
            measurements.len()
        )));
    }
    let first = Vector3::from(measurements[0].position_m);
    let spread = measurements
        .iter()
        .map(|m| (Vector3::from(m.position_m) - first).norm())
        .fold(0.0, f64::max);
    if spread < 1e-3 {
        return Err(Error::InvalidInput(format!(
            "all {} poses are at the same position ({:?}): the anchors are not observable from one place; move the platform across the workspace",
            measurements.len(),
            measurements[0].position_m
        )));
    }
    for m in measurements {
        let fields = m
            .position_m
            .iter()
            .chain(&m.encoder_lengths_m)
            .chain([&m.roll_deg, &m.pitch_deg, &m.yaw_deg]);
        if fields.into_iter().any(|v| !v.is_finite())
            || !(m.reference_tension_n.is_finite() && m.reference_tension_n > 0.0)
        {
            return Err(Error::InvalidInput(format!(
                "pose at line {}: values must be finite and the tension positive",
                m.line
            )));
        }
    }
    Ok(())
}

fn measured_pose(m: &PoseMeasurement) -> PlatformPose {
    PlatformPose::from_roll_pitch_yaw_deg(Vector3::from(m.position_m), m.roll_deg, m.pitch_deg, m.yaw_deg)
}

/// The graph and its variable ids.
pub struct CalibrationGraph {
    /// The graph.
    pub graph: FactorGraph,
    /// Anchors and offsets.
    pub globals: CalibrationVariables,
    /// Per pose.
    pub poses: Vec<PoseVariables>,
    /// The effect parameters, when the graph uses the extended model (the
    /// robot has `[effects]`, or one is estimated); `None`: the baseline factors.
    pub effects: Option<EffectVariables>,
}

/// Build the graph for `model` with initial values: anchors/offsets from
/// `robot`, poses from `poses`, reference tensions from `tensions`.
pub fn build_graph(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    poses: &[PlatformPose],
    tensions: &[CableTension],
    model: CableModel,
    options: &CalibrationOptions,
) -> CalibrationGraph {
    let mut graph = FactorGraph::new();
    let anchors = std::array::from_fn(|i| {
        graph.values.insert(
            format!("anchor {}", i + 1),
            VariableValue::Vector(DVector::from_column_slice(robot.anchors_m[i].as_slice())),
        )
    });
    let length_offsets = std::array::from_fn(|i| {
        graph.values.insert(
            format!("length offset {}", i + 1),
            VariableValue::Vector(DVector::from_element(1, robot.length_offsets_m[i])),
        )
    });
    let globals = CalibrationVariables {
        anchors,
        length_offsets,
    };
    let extended = model == CableModel::Catenary && (!robot.effects.is_none() || options.free_effect.is_some());
    let effect_variables = extended.then(|| insert_effect_variables(&mut graph.values, robot, options.free_effect));
    let mut slot_order = SlotOrder::new(robot);
    if extended {
        // The vertical centre-of-mass shift is a known input (see `EffectVariables::com_shift`).
        slot_order.com_offset_m.z += robot.effects.com_shift_m[2];
    }
    let slots = Arc::new(slot_order);
    let noise = &options.noise;
    let mut pose_variables = Vec::with_capacity(measurements.len());
    for (k, m) in measurements.iter().enumerate() {
        let pose = graph
            .values
            .insert(format!("pose {}", k + 1), VariableValue::Pose(poses[k]));
        let reference_tension = graph.values.insert(
            format!("reference tension {}", k + 1),
            VariableValue::Vector(DVector::from_row_slice(&[
                tensions[k].horizontal_n,
                tensions[k].vertical_n,
            ])),
        );
        let vars = PoseVariables {
            pose,
            reference_tension,
        };
        let orientation_sigma = (options.orientation_prior == OrientationPrior::On || model == CableModel::Rigid)
            .then_some(noise.orientation_sigma_rad);
        graph.add(PosePriorFactor::new(
            pose,
            &measured_pose(m),
            noise.position_sigma_m,
            orientation_sigma,
            options.robust.pose_prior,
        ));
        match model {
            CableModel::Rigid => {
                graph.values.set_fixed(reference_tension, true);
                graph.add(RigidLengthFactor::new(
                    slots.clone(),
                    globals,
                    vars,
                    &m.encoder_lengths_m,
                    noise.encoder_sigma_m,
                    options.robust.encoder,
                ));
            }
            CableModel::Catenary => {
                if let Some(effects) = effect_variables {
                    graph.add(ExtendedLengthFactor::new(
                        slots.clone(),
                        globals,
                        effects,
                        vars,
                        &m.encoder_lengths_m,
                        noise.encoder_sigma_m,
                        options.robust.encoder,
                    ));
                    graph.add(ExtendedHeightFactor::new(
                        slots.clone(),
                        globals,
                        effects,
                        vars,
                        options.height_sigma_m,
                    ));
                    graph.add(LoadCellFactor::new(
                        reference_tension,
                        effects.load_cell,
                        m.reference_tension_n,
                        noise.load_cell_sigma_n,
                        options.robust.load_cell,
                    ));
                } else {
                    graph.add(CatenaryLengthFactor::new(
                        slots.clone(),
                        globals,
                        vars,
                        &m.encoder_lengths_m,
                        noise.encoder_sigma_m,
                        options.robust.encoder,
                    ));
                    graph.add(AttachmentHeightFactor::new(
                        slots.clone(),
                        globals,
                        vars,
                        options.height_sigma_m,
                    ));
                    graph.add(ReferenceTensionFactor::new(
                        reference_tension,
                        m.reference_tension_n,
                        noise.load_cell_sigma_n,
                        options.robust.load_cell,
                    ));
                }
                graph.add(TensionGuardFactor::new(
                    slots.clone(),
                    globals,
                    vars,
                    0.01 * robot.platform_weight_n / CABLE_COUNT as f64,
                    0.01 * robot.platform_weight_n / CABLE_COUNT as f64,
                ));
            }
        }
        pose_variables.push(vars);
        graph.local_groups.push(vec![vars.pose, vars.reference_tension]);
    }
    CalibrationGraph {
        graph,
        globals,
        poses: pose_variables,
        effects: effect_variables,
    }
}

/// The effect-parameter variables with the values of `robot.effects`, all
/// fixed except those of `free`.
fn insert_effect_variables(values: &mut Values, robot: &Robot, free: Option<EffectKind>) -> EffectVariables {
    let e = &robot.effects;
    let mut vector =
        |name: &str, data: &[f64]| values.insert(name, VariableValue::Vector(DVector::from_column_slice(data)));
    let variables = EffectVariables {
        axial_compliance: vector("axial compliance (1/MN)", &[e.axial_compliance_per_mn()]),
        pulley_radius: vector("pulley radius", &[e.pulley_radius_m]),
        encoder_gain_errors: vector("encoder gain errors", &e.encoder_gain.map(|g| g - 1.0)),
        load_cell: vector(
            "load cell bias and gain error",
            &[e.load_cell_bias_n, e.load_cell_gain - 1.0],
        ),
        com_shift: vector("centre of mass shift", &e.com_shift_m[..2]),
    };
    for kind in EffectKind::ALL {
        values.set_fixed(variables.of(kind), Some(kind) != free);
    }
    variables
}

/// The effects held in the graph's effect variables (the inverse of
/// [`insert_effect_variables`]); a compliance `<= 0` reads as an inextensible cable.
pub fn effects_from_graph(template: &Robot, built: &CalibrationGraph) -> Option<Effects> {
    let vars = built.effects?;
    let values = &built.graph.values;
    let compliance = values.vector(vars.axial_compliance)[0];
    let gains = values.vector(vars.encoder_gain_errors);
    let cell = values.vector(vars.load_cell);
    let com = values.vector(vars.com_shift);
    Some(Effects {
        axial_stiffness_n: (compliance > 0.0).then(|| 1e6 / compliance),
        pulley_radius_m: values.vector(vars.pulley_radius)[0],
        encoder_gain: std::array::from_fn(|i| 1.0 + gains[i]),
        load_cell_bias_n: cell[0],
        load_cell_gain: 1.0 + cell[1],
        com_shift_m: [com[0], com[1], template.effects.com_shift_m[2]],
    })
}

/// The robot with the graph's current anchors and offsets.
pub fn robot_from_graph(template: &Robot, built: &CalibrationGraph) -> Robot {
    let mut robot = template.clone();
    for i in 0..CABLE_COUNT {
        let a = built.graph.values.vector(built.globals.anchors[i]);
        robot.anchors_m[i] = Vector3::new(a[0], a[1], a[2]);
        robot.length_offsets_m[i] = built.graph.values.vector(built.globals.length_offsets[i])[0];
    }
    if let Some(effects) = effects_from_graph(template, built) {
        robot.effects = effects;
    }
    robot
}

/// Eq. (17)-(18): `f_v = m_e g / 4`, `f_h = f_v / tan(alpha)`, alpha the angle
/// between the reference cable's chord and the horizontal. Only a fallback.
fn paper_initial_tension(robot: &Robot, pose: &PlatformPose) -> CableTension {
    let geometry = statics::cable_geometry(robot, pose)[robot.reference_cable];
    let vertical = robot.platform_weight_n / CABLE_COUNT as f64;
    let alpha = geometry.height_difference_m.atan2(geometry.span_m).max(1e-3);
    CableTension {
        horizontal_n: vertical / alpha.tan(),
        vertical_n: vertical,
    }
}

/// Step (2) of the initialisation for a given robot: every pose's static
/// equilibrium at its measured position and load-cell tension (the poses and
/// reference tensions `(f_h, f_v)` to start the catenary graph from). Poses
/// without an equilibrium start from the measured pose and eq. (17)-(18);
/// their indices are the third element.
pub fn warm_start(
    robot: &Robot,
    measurements: &[PoseMeasurement],
) -> (Vec<PlatformPose>, Vec<CableTension>, Vec<usize>) {
    let warm = warm_up(robot, measurements);
    (warm.poses, warm.tensions, warm.failures)
}

/// The per-pose warm-up: a start for every pose.
struct WarmUp {
    poses: Vec<PlatformPose>,
    tensions: Vec<CableTension>,
    /// Poses without an equilibrium (their start is the measured pose and eq. 17-18).
    failures: Vec<usize>,
    equilibria: Vec<Option<Equilibrium>>,
    /// Poses with an equilibrium, filled by the caller.
    feasible: Vec<usize>,
}

/// Per-pose warm-up: the static equilibrium at each measured position and
/// load-cell tension for `robot`'s current anchors (or, where that tension has
/// none, the nearest tension that has one). Poses without any start from the
/// measured pose and eq. (17)-(18) and are listed as failures.
fn warm_up(robot: &Robot, measurements: &[PoseMeasurement]) -> WarmUp {
    let options = StaticsOptions::default();
    let mut warm = WarmUp {
        poses: Vec::with_capacity(measurements.len()),
        tensions: Vec::with_capacity(measurements.len()),
        failures: Vec::new(),
        equilibria: Vec::with_capacity(measurements.len()),
        feasible: Vec::new(),
    };
    for (k, m) in measurements.iter().enumerate() {
        let measured = measured_pose(m);
        let solved = statics::solve_with_reference_tension(
            robot,
            measured.position_m,
            m.reference_tension_n,
            Some(measured.rotation),
            &options,
        )
        .or_else(|_| {
            statics::feasible_start(robot, measured.position_m, Some(measured.rotation), &options).map(|(_, eq)| eq)
        });
        match solved {
            Ok(eq) => {
                warm.poses.push(eq.pose);
                warm.tensions.push(eq.tensions[robot.reference_cable]);
                warm.equilibria.push(Some(eq));
            }
            Err(_) => {
                warm.failures.push(k);
                warm.poses.push(measured);
                warm.tensions.push(paper_initial_tension(robot, &measured));
                warm.equilibria.push(None);
            }
        }
    }
    warm
}

fn solve_stage(name: &str, built: &mut CalibrationGraph, lm: &LmParams) -> Result<StageSummary> {
    let summary = optimize(&mut built.graph, lm).map_err(|e| Error::InvalidInput(format!("{name} stage: {e}")))?;
    Ok(StageSummary {
        name: name.to_string(),
        summary,
    })
}

/// Closed-form length offsets for fixed geometry: the offsets enter the
/// encoder factors linearly, so the least-squares value is the mean of
/// `encoder - catenary length` over the poses.
fn offsets_in_closed_form(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    equilibria: &[Option<Equilibrium>],
) -> [f64; CABLE_COUNT] {
    std::array::from_fn(|i| {
        let differences: Vec<f64> = measurements
            .iter()
            .zip(equilibria)
            .filter_map(|(m, eq)| eq.as_ref().map(|eq| m.encoder_lengths_m[i] - eq.cable_lengths_m[i]))
            .collect();
        if differences.is_empty() {
            robot.length_offsets_m[i]
        } else {
            differences.iter().sum::<f64>() / differences.len() as f64
        }
    })
}

/// Calibrate anchors and length offsets from `measurements`, starting from `initial`.
///
/// Stages (see the module docs): for the catenary model, (1) per-pose statics
/// at the initial anchors and the closed-form offsets, (2) the full graph. If
/// the initial anchors are so far off that most poses have no equilibrium, a
/// rigid-cable calibration first moves them closer. For the rigid model, the
/// rigid graph alone.
pub fn calibrate(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    validate_measurements(measurements)?;
    if options.orientation_prior != OrientationPrior::Auto || options.model == CableModel::Rigid {
        return calibrate_once(initial, measurements, options);
    }
    let with_prior = CalibrationOptions {
        orientation_prior: OrientationPrior::On,
        ..*options
    };
    let without_prior = CalibrationOptions {
        orientation_prior: OrientationPrior::Off,
        ..*options
    };
    let Ok(mut result) = calibrate_once(initial, measurements, &with_prior) else {
        return calibrate_once(initial, measurements, &without_prior);
    };
    let mut check = orientation_check(&result, measurements, options.noise.orientation_sigma_rad);
    if check.chi_square <= check.limit {
        result.orientation_check = Some(check);
        return Ok(result);
    }
    let mut result = calibrate_once(initial, measurements, &without_prior)?;
    check.prior_used = false;
    result.orientation_check = Some(check);
    Ok(result)
}

/// Chi-square of the localiser's orientations against the fitted poses of a
/// calibration made with the orientation prior. Conservative: the fitted
/// orientation is pulled towards the measured one, so consistent data give
/// less than the `3 N` degrees of freedom tested against.
fn orientation_check(result: &CalibrationResult, measurements: &[PoseMeasurement], sigma_rad: f64) -> OrientationCheck {
    let used = (0..measurements.len()).filter(|k| !result.excluded_poses.contains(k));
    let angles: Vec<f64> = used
        .zip(&result.poses)
        .map(|(k, fitted)| measured_pose(&measurements[k]).rotation.angle_to(&fitted.rotation))
        .collect();
    let chi_square = angles.iter().map(|a| (a / sigma_rad).powi(2)).sum();
    let components = 3 * angles.len();
    OrientationCheck {
        prior_used: true,
        chi_square,
        components,
        limit: chi_square_quantile_999(components),
        mean_angle_deg: angles.iter().sum::<f64>() / angles.len().max(1) as f64 * 180.0 / std::f64::consts::PI,
    }
}

impl CalibrationOptions {
    /// These options with [`OrientationPrior::Auto`] resolved to what `result`
    /// used (`On` if it kept the prior, else `Off`): the options under which
    /// to compare `result` with its Cramer-Rao bound.
    pub fn as_used_by(&self, result: &CalibrationResult) -> CalibrationOptions {
        let orientation_prior = match (self.orientation_prior, result.orientation_check) {
            (OrientationPrior::Auto, Some(check)) if check.prior_used => OrientationPrior::On,
            (OrientationPrior::Auto, _) => OrientationPrior::Off,
            (other, _) => other,
        };
        CalibrationOptions {
            orientation_prior,
            ..*self
        }
    }
}

/// One calibration with the orientation prior as given (`Auto` counts as `Off`).
fn calibrate_once(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    let measured: Vec<PlatformPose> = measurements.iter().map(measured_pose).collect();
    let mut stages = Vec::new();
    if options.model == CableModel::Rigid {
        let placeholder: Vec<CableTension> = measured.iter().map(|p| paper_initial_tension(initial, p)).collect();
        let mut start = initial.clone();
        let chords: Vec<Option<Equilibrium>> = vec![None; measurements.len()];
        start.length_offsets_m = rigid_offsets_in_closed_form(initial, measurements, &measured, &chords);
        let mut rigid = build_graph(
            &start,
            measurements,
            &measured,
            &placeholder,
            CableModel::Rigid,
            options,
        );
        stages.push(solve_stage("rigid", &mut rigid, &options.lm)?);
        return finish(initial, rigid, stages, Vec::new());
    }
    // Two candidate starts: the initial guess, and a rigid-cable calibration
    // from it (close on robots whose cables barely sag, biased where they sag
    // a lot). Each is warmed up (per-pose statics, closed-form offsets); the
    // one with the lower relaxed catenary cost wins.
    let relaxed_options = CalibrationOptions {
        height_sigma_m: options.height_sigma_m.max(options.noise.encoder_sigma_m),
        ..*options
    };
    let placeholder: Vec<CableTension> = measured.iter().map(|p| paper_initial_tension(initial, p)).collect();
    let mut rigid_start = initial.clone();
    rigid_start.length_offsets_m = rigid_offsets_in_closed_form(initial, measurements, &measured, &[]);
    let mut rigid = build_graph(
        &rigid_start,
        measurements,
        &measured,
        &placeholder,
        CableModel::Rigid,
        options,
    );
    let rigid_stage = solve_stage("rigid", &mut rigid, &options.lm)?;
    let rigid_robot = robot_from_graph(initial, &rigid);
    let mut best: Option<(f64, Robot, WarmUp)> = None;
    for candidate in [initial.clone(), rigid_robot] {
        let mut warm = warm_up(&candidate, measurements);
        let mut start = candidate;
        start.length_offsets_m = offsets_in_closed_form(&start, measurements, &warm.equilibria);
        let feasible: Vec<usize> = (0..measurements.len())
            .filter(|k| warm.equilibria[*k].is_some())
            .collect();
        if feasible.len() < MIN_POSES {
            continue;
        }
        let chosen: Vec<PoseMeasurement> = feasible.iter().map(|&k| measurements[k]).collect();
        let poses: Vec<PlatformPose> = feasible.iter().map(|&k| warm.poses[k]).collect();
        let tensions: Vec<CableTension> = feasible.iter().map(|&k| warm.tensions[k]).collect();
        let graph = build_graph(
            &start,
            &chosen,
            &poses,
            &tensions,
            CableModel::Catenary,
            &relaxed_options,
        );
        // Compare per pose, so that a start with more feasible poses is not penalised.
        let Some(cost) = graph.graph.cost(&graph.graph.values) else {
            continue;
        };
        let score = cost / feasible.len() as f64 * (1.0 + (measurements.len() - feasible.len()) as f64);
        warm.feasible = feasible;
        if best.as_ref().is_none_or(|(b, _, _)| score < *b) {
            best = Some((score, start, warm));
        }
    }
    stages.push(rigid_stage);
    let Some((_, start, warm)) = best else {
        return Err(Error::NoEquilibrium(format!(
            "fewer than {MIN_POSES} of {} poses have a positive-tension equilibrium at the initial anchors or at a rigid-cable calibration of them: the initial guess is too far off",
            measurements.len()
        )));
    };
    let WarmUp {
        poses,
        tensions,
        feasible,
        ..
    } = warm;
    // Continuation on the statics constraint: a tight attachment-height sigma
    // makes the cost a narrow curved valley that Gauss-Newton follows in tiny
    // steps from far away; solving first with it relaxed to the encoder sigma
    // brings the estimate close, then the tight constraint converges in a few
    // steps. Poses without an equilibrium at the initial anchors sit out the
    // relaxed stage and are warmed up again with its anchors.
    let subset = |indices: &[usize]| -> (Vec<PoseMeasurement>, Vec<PlatformPose>, Vec<CableTension>) {
        (
            indices.iter().map(|&k| measurements[k]).collect(),
            indices.iter().map(|&k| poses[k]).collect(),
            indices.iter().map(|&k| tensions[k]).collect(),
        )
    };
    let (relaxed_measurements, relaxed_poses, relaxed_tensions) = subset(&feasible);
    let mut relaxed = build_graph(
        &start,
        &relaxed_measurements,
        &relaxed_poses,
        &relaxed_tensions,
        CableModel::Catenary,
        &relaxed_options,
    );
    stages.push(solve_stage("catenary (relaxed statics)", &mut relaxed, &options.lm)?);
    let relaxed_robot = robot_from_graph(initial, &relaxed);
    // Final stage: the relaxed solution, plus the poses that sat out, warmed up
    // with the relaxed anchors (left out if they still have no equilibrium).
    let WarmUp {
        poses: rewarmed_poses,
        tensions: rewarmed_tensions,
        failures: still_failing,
        ..
    } = warm_up(&relaxed_robot, measurements);
    let mut final_poses = Vec::new();
    let mut final_tensions = Vec::new();
    let mut final_measurements = Vec::new();
    let mut excluded = Vec::new();
    for k in 0..measurements.len() {
        if let Some(slot) = feasible.iter().position(|&f| f == k) {
            let vars = relaxed.poses[slot];
            let t = relaxed.graph.values.vector(vars.reference_tension);
            final_poses.push(*relaxed.graph.values.pose(vars.pose));
            final_tensions.push(CableTension {
                horizontal_n: t[0],
                vertical_n: t[1],
            });
        } else if still_failing.contains(&k) {
            excluded.push(k);
            continue;
        } else {
            final_poses.push(rewarmed_poses[k]);
            final_tensions.push(rewarmed_tensions[k]);
        }
        final_measurements.push(measurements[k]);
    }
    if final_measurements.len() < MIN_POSES {
        return Err(Error::NoEquilibrium(format!(
            "only {} of {} poses have a positive-tension equilibrium at the calibrated anchors",
            final_measurements.len(),
            measurements.len()
        )));
    }
    let mut full = build_graph(
        &relaxed_robot,
        &final_measurements,
        &final_poses,
        &final_tensions,
        CableModel::Catenary,
        options,
    );
    stages.push(solve_stage("catenary", &mut full, &options.lm)?);
    finish(initial, full, stages, excluded)
}

/// Closed-form offsets for the straight-cable model: mean of `encoder - chord`.
fn rigid_offsets_in_closed_form(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    poses: &[PlatformPose],
    _equilibria: &[Option<Equilibrium>],
) -> [f64; CABLE_COUNT] {
    std::array::from_fn(|i| {
        measurements
            .iter()
            .zip(poses)
            .map(|(m, p)| {
                let attachment = p.position_m + p.rotation_matrix() * robot.attachments_m[i];
                m.encoder_lengths_m[i] - (robot.anchors_m[i] - attachment).norm()
            })
            .sum::<f64>()
            / measurements.len() as f64
    })
}

fn finish(
    template: &Robot,
    built: CalibrationGraph,
    stages: Vec<StageSummary>,
    excluded_poses: Vec<usize>,
) -> Result<CalibrationResult> {
    let robot = robot_from_graph(template, &built);
    let uncertainty = parameter_uncertainty(&built)?;
    let factor_statistics = factor_statistics(&built.graph);
    let poses = built.poses.iter().map(|p| *built.graph.values.pose(p.pose)).collect();
    let reference_tensions_n = built
        .poses
        .iter()
        .map(|p| {
            let t = built.graph.values.vector(p.reference_tension);
            [t[0], t[1]]
        })
        .collect();
    Ok(CalibrationResult {
        robot,
        uncertainty,
        stages,
        factor_statistics,
        poses,
        reference_tensions_n,
        excluded_poses,
        orientation_check: None,
        effect_estimate: None,
    })
}

/// Re-estimate anchors, offsets and the parameters of `options.free_effect`
/// with the extended model, starting from `baseline` (its anchors, offsets,
/// poses and tensions; its excluded poses stay out). `options` should be the
/// ones `baseline` was made with, resolved by [`CalibrationOptions::as_used_by`].
pub fn refine_with_effect(
    baseline: &CalibrationResult,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    let kind = options
        .free_effect
        .ok_or_else(|| Error::InvalidInput("refine_with_effect: no effect to estimate".into()))?;
    let used: Vec<PoseMeasurement> = (0..measurements.len())
        .filter(|k| !baseline.excluded_poses.contains(k))
        .map(|k| measurements[k])
        .collect();
    if used.len() != baseline.poses.len() {
        return Err(Error::InvalidInput(format!(
            "refine_with_effect: {} measurements used but the baseline has {} poses",
            used.len(),
            baseline.poses.len()
        )));
    }
    let mut built = build_graph(
        &baseline.robot,
        &used,
        &baseline.poses,
        &baseline.reference_tensions(),
        CableModel::Catenary,
        options,
    );
    let mut stages = baseline.stages.clone();
    stages.push(solve_stage(&format!("extended ({kind})"), &mut built, &options.lm)?);
    let estimate = effect_estimate(&built, kind)?;
    let mut result = finish(&baseline.robot, built, stages, baseline.excluded_poses.clone())?;
    result.orientation_check = baseline.orientation_check;
    result.effect_estimate = Some(estimate);
    Ok(result)
}

/// The fitted parameters of `kind` in `built` with 1-sigma from the marginal covariance.
fn effect_estimate(built: &CalibrationGraph, kind: EffectKind) -> Result<EffectEstimate> {
    let vars = built
        .effects
        .ok_or_else(|| Error::InvalidInput("the graph has no effect parameters".into()))?;
    let id = vars.of(kind);
    let raw = built.graph.values.vector(id).clone();
    let values = EffectEstimate::values_from_variable(kind, raw.as_slice());
    let sigmas = match marginal_covariance(&built.graph, &[id]).map_err(Error::InvalidInput)? {
        Covariance::Full(c) => (0..raw.len()).map(|k| c[(k, k)].max(0.0).sqrt()).collect(),
        Covariance::RankDeficient(_) => vec![f64::NAN; raw.len()],
    };
    Ok(EffectEstimate {
        effect: kind,
        names: kind.parameter_names().iter().map(|n| n.to_string()).collect(),
        values,
        sigmas,
    })
}

/// Marginal covariance of anchors and offsets at the graph's current values.
pub fn parameter_uncertainty(built: &CalibrationGraph) -> Result<ParameterUncertainty> {
    let selected: Vec<VariableId> = built
        .globals
        .anchors
        .iter()
        .chain(&built.globals.length_offsets)
        .copied()
        .collect();
    let covariance = marginal_covariance(&built.graph, &selected).map_err(Error::InvalidInput)?;
    Ok(match covariance {
        Covariance::Full(c) => uncertainty_from_covariance(&c),
        Covariance::RankDeficient(directions) => ParameterUncertainty::RankDeficient { directions },
    })
}

fn uncertainty_from_covariance(c: &DMatrix<f64>) -> ParameterUncertainty {
    let anchor_covariance_m2: Vec<[[f64; 3]; 3]> = (0..CABLE_COUNT)
        .map(|i| std::array::from_fn(|r| std::array::from_fn(|col| c[(3 * i + r, 3 * i + col)])))
        .collect();
    let anchor_sigma_m = anchor_covariance_m2
        .iter()
        .map(|m| std::array::from_fn(|k| m[k][k].max(0.0).sqrt()))
        .collect();
    let offset_sigma_m = (0..CABLE_COUNT).map(|i| c[(12 + i, 12 + i)].max(0.0).sqrt()).collect();
    ParameterUncertainty::Full {
        anchor_covariance_m2,
        anchor_sigma_m,
        offset_sigma_m,
    }
}

/// Per factor type: count, RMS and max of the normalised residuals.
pub fn factor_statistics(graph: &FactorGraph) -> Vec<FactorStatistics> {
    let mut stats: Vec<FactorStatistics> = Vec::new();
    for factor in &graph.factors {
        let Some(residual) = factor.evaluate(&graph.values, None) else {
            continue;
        };
        let sigmas = factor.sigmas();
        let s = whitened_squared_norm(&residual, sigmas);
        let max_abs = residual
            .iter()
            .zip(sigmas.iter())
            .map(|(r, s)| (r / s).abs())
            .fold(0.0, f64::max);
        let entry = match stats.iter_mut().find(|e| e.kind == factor.kind()) {
            Some(e) => e,
            None => {
                stats.push(FactorStatistics {
                    kind: factor.kind().to_string(),
                    factors: 0,
                    components: 0,
                    rms: 0.0,
                    max_abs: 0.0,
                    chi_square: 0.0,
                });
                stats.last_mut().expect("just pushed")
            }
        };
        entry.factors += 1;
        entry.components += residual.len();
        entry.chi_square += s;
        entry.max_abs = entry.max_abs.max(max_abs);
    }
    for e in &mut stats {
        e.rms = (e.chi_square / e.components.max(1) as f64).sqrt();
    }
    stats
}

/// The Cramer-Rao bound of anchors and offsets: the inverse Fisher information
/// `(J^T Sigma^-1 J)^-1` at the true parameters and true equilibria, for the
/// factors of `options` (no robust kernels).
pub fn cramer_rao_bound(
    truth: &Robot,
    equilibria: &[Equilibrium],
    options: &CalibrationOptions,
) -> Result<ParameterUncertainty> {
    let measurements: Vec<PoseMeasurement> = equilibria
        .iter()
        .map(|eq| {
            let (roll_deg, pitch_deg, yaw_deg) = eq.pose.roll_pitch_yaw_deg();
            PoseMeasurement {
                line: 0,
                position_m: eq.pose.position_m.into(),
                roll_deg,
                pitch_deg,
                yaw_deg,
                encoder_lengths_m: std::array::from_fn(|i| eq.cable_lengths_m[i] + truth.length_offsets_m[i]),
                reference_tension_n: eq.tensions[truth.reference_cable].magnitude_n(),
            }
        })
        .collect();
    let poses: Vec<PlatformPose> = equilibria.iter().map(|e| e.pose).collect();
    let tensions: Vec<CableTension> = equilibria.iter().map(|e| e.tensions[truth.reference_cable]).collect();
    let plain = CalibrationOptions {
        robust: RobustKernels::default(),
        ..*options
    };
    let built = build_graph(truth, &measurements, &poses, &tensions, options.model, &plain);
    parameter_uncertainty(&built)
}

/// Anchor and offset errors of a calibrated robot against the truth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CalibrationError {
    /// Mean over anchors of the Euclidean error, metres (the authors' program's metric).
    pub anchor_mean_euclidean_m: f64,
    /// Mean absolute error over the 12 anchor coordinates, metres.
    pub anchor_coordinate_mae_m: f64,
    /// Largest Euclidean anchor error, metres.
    pub anchor_max_euclidean_m: f64,
    /// Mean absolute offset error, metres.
    pub offset_mae_m: f64,
}

impl CalibrationError {
    /// Compare `estimate` with `truth`.
    pub fn between(estimate: &Robot, truth: &Robot) -> Self {
        let anchor: Vec<Vector3<f64>> = (0..CABLE_COUNT)
            .map(|i| estimate.anchors_m[i] - truth.anchors_m[i])
            .collect();
        let euclid: Vec<f64> = anchor.iter().map(|d| d.norm()).collect();
        Self {
            anchor_mean_euclidean_m: euclid.iter().sum::<f64>() / CABLE_COUNT as f64,
            anchor_coordinate_mae_m: anchor.iter().map(|d| d.abs().sum()).sum::<f64>() / (3 * CABLE_COUNT) as f64,
            anchor_max_euclidean_m: euclid.iter().copied().fold(0.0, f64::max),
            offset_mae_m: (0..CABLE_COUNT)
                .map(|i| (estimate.length_offsets_m[i] - truth.length_offsets_m[i]).abs())
                .sum::<f64>()
                / CABLE_COUNT as f64,
        }
    }
}

/// Per anchor, `sqrt(trace Sigma_i)`: the RMS Euclidean error the bound allows, metres.
pub fn anchor_rms_bound_m(uncertainty: &ParameterUncertainty) -> Option<Vec<f64>> {
    match uncertainty {
        ParameterUncertainty::Full {
            anchor_covariance_m2, ..
        } => Some(
            anchor_covariance_m2
                .iter()
                .map(|m| Matrix3::from_fn(|r, c| m[r][c]).trace().max(0.0).sqrt())
                .collect(),
        ),
        ParameterUncertainty::RankDeficient { .. } => None,
    }
}

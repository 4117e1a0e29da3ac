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
//! **Basins.** The rigid stage fits, cable by cable, one anchor and one
//! offset to that cable's lengths (the poses are held by their priors): it
//! knows nothing of the statics. Where the cables are nearly vertical and the
//! poses form a narrow column under the anchors (the authors' small robot,
//! `robots/small-authors.toml`: anchors 4.7 m apart in x, poses 9 to 24 m
//! below them), the lengths barely change when an anchor slides along its
//! mean cable direction (the offset takes up the difference) or turns about
//! the column, so the rigid fit of a guess several metres off can leave one
//! anchor tens of metres along that valley or on the wrong side of the
//! column. The platform's force balance and orientation would tell, but only
//! the catenary stages see them, and LM from such a start ends in a minimum
//! whose cost is hundreds of times what the noise allows. Three remedies, none
//! with a tuned constant:
//! - the start with the lower warm-up cost is solved first and kept if its
//!   minimum passes the chi-square test of its cost (99.9 % quantile at the
//!   redundancy; the common case, one solve); otherwise both starts (the
//!   guess and the rigid fit) are solved to the end and the lower final cost
//!   wins (a converged solve first, then the one leaving out fewer poses): a
//!   start's warm-up cost says little about its basin;
//! - if the two did not reach one minimum and the better fails the
//!   chi-square test of its cost (99.9 % quantile at the redundancy), or no
//!   start had an equilibrium at enough poses, the anchors mixed cable by
//!   cable from the guess and the rigid fit are solved too (14 more starts):
//!   a wrong rigid minimum for one cable then does not spoil the others;
//! - with [`OrientationPrior::Auto`] a failed orientation test can be a wrong
//!   basin of the fit with the prior rather than a localiser at odds with the
//!   statics, so the fit with the prior is repeated from the fit without it
//!   before the prior is dropped (`orientation.rs`).
//!
//! What stays lost: a guess whose anchors are on the wrong side of the pose
//! column (a 10 m perturbation of a robot 4.7 m wide swaps anchors or puts
//! them below the poses), so that neither the guess, the rigid fit, nor any
//! mix of them holds the platform with positive tensions at enough poses; and
//! with few poses and no orientation prior, minima of equal depth along a
//! poorly observed direction.
//!
//! **Solving.** Each pose's variables (platform pose, reference tension) form
//! a local group of the graph: after every trial step the solver re-fits each
//! pose to its own factors with the anchors and offsets held, so a step of
//! the anchors is judged with every pose back on its statics. Without it the
//! 0.1 mm attachment-height constraint bends the valley so sharply that LM
//! creeps along it (the small robot, with its nearly vertical cables, hit
//! 500 iterations in most trials).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::{calibrate, CalibrationOptions};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let truth = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
//! let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 15, &mut rng)?;
//! let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
//! let data = measure(&truth, &equilibria, &noise, &mut rng);
//! // The operator's guess: anchor 2 measured 3 m off, every encoder offset 1 m off.
//! let mut guess = truth.clone();
//! guess.anchors_m[1].x += 3.0;
//! guess.length_offsets_m = [1.0; 4];
//! let result = calibrate(&guess, &data, &CalibrationOptions::new(noise))?;
//! let error_m = (result.robot.anchors_m[1] - truth.anchors_m[1]).norm();
//! assert!(error_m < 1.0, "anchor 2 is {error_m} m off after calibration");
//! # Ok::<(), sagcal::Error>(())
//! ```

pub mod effect_factors;
pub mod factors;
mod graph;
pub mod gross_errors;
mod init;
mod job;
mod load_cell_factor;
pub mod mistakes;
mod mounted_pose_prior;
mod options;
mod orientation;
mod predict;
mod prepared;
pub mod report;
mod result;
pub mod screen;
mod settings;
mod snooping;
mod system_scope;
mod uncertainty;

use crate::error::{Error, Result};
use crate::model::effect_kind::EffectKind;
use crate::model::effects::Effects;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::solver::{optimize_cached, LmParams};
use uncertainty::effect_estimate;

pub use graph::{
    build_graph, effects_from_graph, robot_from_graph, validate_measurements, CalibrationGraph, MIN_POSES,
};
pub use init::warm_start;
pub use job::{calibrate_job, refusal, CalibrationJob};
pub use options::{CableModel, CalibrationOptions, OrientationPrior, RobustKernels};
pub use orientation::OrientationCheck;
pub use predict::predict_with_effects;
pub use prepared::PreparedCalibration;
pub use result::{
    factor_statistics, CalibrationResult, EffectEstimate, FactorStatistics, ParameterUncertainty, StageSummary,
};
pub use settings::{check_false_alarm, CalibrationSettings, SolverSettings};
pub use uncertainty::{anchor_rms_bound_m, cramer_rao_bound, parameter_uncertainty, CalibrationError};

/// Calibrate anchors and length offsets from `measurements`, starting from `initial`.
///
/// Stages (see the module docs): for the catenary model, a rigid-cable
/// calibration from `initial`, then from both `initial` and that calibration
/// (and, if neither ends in a minimum consistent with the noise, from their
/// anchors mixed cable by cable) per-pose statics with closed-form offsets,
/// the relaxed-statics graph and the full graph; the lowest final cost wins.
/// For the rigid model, the rigid graph alone.
pub fn calibrate(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    let _shared_system = system_scope::Scope::enter();
    validate_measurements(measurements)?;
    if options.orientation_prior == OrientationPrior::Auto && options.model == CableModel::Catenary {
        return orientation::calibrate_testing_orientation(initial, measurements, options);
    }
    calibrate_once(initial, measurements, options)
}

/// One calibration with the orientation prior as given (`Auto` counts as `Off`):
/// the staged pipeline of the module docs.
fn calibrate_once(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    if options.model == CableModel::Rigid {
        let (rigid_stage, rigid) = rigid_calibration(initial, measurements, options)?;
        return finish(initial, rigid, vec![rigid_stage], Vec::new());
    }
    let prepared = CatenaryPreparation::new(initial, measurements, options)?;
    calibrate_prepared(initial, measurements, options, &prepared)
}

/// Stages (1) and (2) of the catenary pipeline, which the orientation prior
/// does not enter: the rigid calibration (its pose priors always hold the
/// localiser's orientation, whatever [`CalibrationOptions::orientation_prior`]
/// says) and the per-pose warm-ups of the two starts (the statics at the
/// measured positions and load-cell tensions). [`OrientationPrior::Auto`]
/// makes them once for its calibrations with and without the prior.
struct CatenaryPreparation {
    rigid_stage: StageSummary,
    rigid_robot: Robot,
    /// The initial guess and the rigid calibration, warmed up ([`init::warm_candidates`]).
    warmed: Vec<init::CatenaryStart>,
}

impl CatenaryPreparation {
    fn new(initial: &Robot, measurements: &[PoseMeasurement], options: &CalibrationOptions) -> Result<Self> {
        // (1) Rigid, massless cables from the initial guess: a second
        // candidate start for the catenary.
        let (rigid_stage, rigid) = rigid_calibration(initial, measurements, options)?;
        let rigid_robot = robot_from_graph(initial, &rigid);
        let warmed = init::warm_candidates([initial.clone(), rigid_robot.clone()], measurements);
        Ok(CatenaryPreparation {
            rigid_stage,
            rigid_robot,
            warmed,
        })
    }
}

/// The catenary stages (2)-(4) of [`calibrate_once`] under `options` from a
/// [`CatenaryPreparation`] made for the same initial guess and measurements.
fn calibrate_prepared(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    prepared: &CatenaryPreparation,
) -> Result<CalibrationResult> {
    let rigid_stage = prepared.rigid_stage.clone();
    // (2) Two warmed-up starts: the initial guess and the rigid calibration,
    // each with per-pose statics and closed-form offsets. Both are solved and
    // the lower final cost wins (see the module docs, "Basins").
    let relaxed_options = init::relaxed_statics(options);
    let starts = init::rank_starts(&prepared.warmed, measurements, &relaxed_options);
    // The start with the lower warm-up cost first: a minimum that fits the
    // data as well as the noise allows needs no other start (the common case,
    // at the cost of one solve). Otherwise it joins the other starts' solves.
    let mut solves = Vec::with_capacity(starts.len());
    if let Some(first) = starts.first() {
        match solve_catenary(initial, first, measurements, options, &relaxed_options) {
            Ok(solved) if solved.final_stage.summary.termination.converged() && solved.consistent_with_noise() => {
                return finish(
                    initial,
                    solved.full,
                    vec![rigid_stage, solved.relaxed_stage, solved.final_stage],
                    solved.excluded,
                );
            }
            other => solves.push(other),
        }
    }
    solves.extend(solve_starts(
        initial,
        starts.iter().skip(1).copied(),
        measurements,
        options,
        &relaxed_options,
    ));
    let agree = solves.len() == 2 && CatenarySolve::same_minimum(&solves[0], &solves[1]);
    let mut best = best_of(solves, measurements);
    // (2') If the starts did not lead to one minimum and the best fits the data
    // worse than the noise allows, the anchors mixed cable by cable from both.
    if !agree && !best.as_ref().is_ok_and(|b| b.consistent_with_noise()) {
        let mixed = init::catenary_starts(
            init::mixed_anchors(initial, &prepared.rigid_robot),
            measurements,
            &relaxed_options,
        );
        let more = best_of(
            solve_starts(initial, mixed.iter(), measurements, options, &relaxed_options),
            measurements,
        );
        best = match (best, more) {
            (Ok(a), Ok(b)) => Ok(if b.better_than(&a) { b } else { a }),
            (Ok(a), Err(_)) => Ok(a),
            (Err(_), Ok(b)) => Ok(b),
            (Err(e), Err(_)) => Err(e),
        };
    }
    let solved = best?;
    finish(
        initial,
        solved.full,
        vec![rigid_stage, solved.relaxed_stage, solved.final_stage],
        solved.excluded,
    )
}

/// The catenary stages solved from every start that can be solved.
fn solve_starts<'a>(
    initial: &Robot,
    starts: impl IntoIterator<Item = &'a init::CatenaryStart>,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    relaxed_options: &CalibrationOptions,
) -> Vec<Result<CatenarySolve>> {
    starts
        .into_iter()
        .map(|start| solve_catenary(initial, start, measurements, options, relaxed_options))
        .collect()
}

/// The best of `solves` (by [`CatenarySolve::better_than`]); the first error
/// if none succeeded, or the infeasible-start error if there were none.
fn best_of(solves: Vec<Result<CatenarySolve>>, measurements: &[PoseMeasurement]) -> Result<CatenarySolve> {
    let mut best: Option<CatenarySolve> = None;
    let mut first_error = None;
    for solved in solves {
        match solved {
            Ok(solved) => {
                if best.as_ref().is_none_or(|b| solved.better_than(b)) {
                    best = Some(solved);
                }
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    best.ok_or_else(|| {
        first_error.unwrap_or_else(|| {
            Error::NoEquilibrium(format!(
                "fewer than {MIN_POSES} of {} poses have a positive-tension equilibrium at the initial anchors or at a rigid-cable calibration of them: the initial guess is too far off",
                measurements.len()
            ))
        })
    })
}

/// The catenary stages solved from one start.
struct CatenarySolve {
    relaxed_stage: StageSummary,
    final_stage: StageSummary,
    full: CalibrationGraph,
    excluded: Vec<usize>,
}

impl CatenarySolve {
    /// Whether this solve is preferable to `other`: a converged solve beats
    /// one that stopped at its iteration limit, then fewer poses left out
    /// (costs of different pose sets do not compare), then the lower cost.
    fn better_than(&self, other: &CatenarySolve) -> bool {
        let key = |s: &CatenarySolve| (!s.final_stage.summary.termination.converged(), s.excluded.len());
        match key(self).cmp(&key(other)) {
            std::cmp::Ordering::Less => true,
            std::cmp::Ordering::Greater => false,
            std::cmp::Ordering::Equal => self.final_stage.summary.final_cost < other.final_stage.summary.final_cost,
        }
    }

    /// Whether two solves (both `Ok`) reached the same minimum: the same poses,
    /// anchors within 1 cm.
    fn same_minimum(a: &Result<CatenarySolve>, b: &Result<CatenarySolve>) -> bool {
        let (Ok(a), Ok(b)) = (a, b) else {
            return false;
        };
        let anchors = |s: &CatenarySolve| s.full.globals.anchors.map(|id| s.full.graph.values.vector(id).clone());
        let (pa, pb) = (anchors(a), anchors(b));
        a.excluded == b.excluded && (0..CABLE_COUNT).all(|i| (&pa[i] - &pb[i]).norm() < 0.01)
    }

    /// Whether the final cost is consistent with the stated noise: twice the
    /// cost (the whitened chi-square) within the 99.9 % quantile of
    /// chi-square with the redundancy (residual components less the
    /// variables' dimensions) as degrees of freedom. A minimum in a wrong
    /// basin fits the data far worse than the noise allows (hundreds of times
    /// the redundancy); model mismatch (finite-element data) can fail it too,
    /// which only costs the extra starts.
    fn consistent_with_noise(&self) -> bool {
        let graph = &self.full.graph;
        let components: usize = factor_statistics(graph).iter().map(|s| s.components).sum();
        let unknowns: usize = graph
            .values
            .iter()
            .filter(|(_, v)| !v.fixed)
            .map(|(_, v)| v.value.tangent_dim())
            .sum();
        let redundancy = components.saturating_sub(unknowns).max(1);
        2.0 * self.final_stage.summary.final_cost <= crate::stats::chi_square_quantile_999(redundancy)
    }
}

/// Stages (3) and (4) of [`calibrate_once`] from one warmed-up start.
fn solve_catenary(
    initial: &Robot,
    start: &init::CatenaryStart,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    relaxed_options: &CalibrationOptions,
) -> Result<CatenarySolve> {
    // (3) Continuation on the statics constraint: a tight attachment-height
    // sigma makes the cost a narrow curved valley that Gauss-Newton follows in
    // tiny steps from far away; solving first with it relaxed to the encoder
    // sigma brings the estimate close, then the tight constraint converges in
    // a few steps. Poses without an equilibrium at the start sit out.
    let (chosen, poses, tensions) = start.feasible_subset(measurements);
    let mut relaxed = build_graph(
        &start.robot,
        &chosen,
        &poses,
        &tensions,
        CableModel::Catenary,
        relaxed_options,
    );
    let relaxed_stage = solve_stage("catenary (relaxed statics)", &mut relaxed, &options.lm)?;
    // (4) The full catenary graph: the relaxed solution, plus the poses that
    // sat out, warmed up with the relaxed anchors (left out if they still have
    // no equilibrium).
    let relaxed_robot = robot_from_graph(initial, &relaxed);
    let last = init::final_start(&relaxed, &relaxed_robot, measurements, &start.feasible)?;
    let mut full = build_graph(
        &relaxed_robot,
        &last.measurements,
        &last.poses,
        &last.tensions,
        CableModel::Catenary,
        options,
    );
    let final_stage = solve_stage("catenary", &mut full, &options.lm)?;
    Ok(CatenarySolve {
        relaxed_stage,
        final_stage,
        full,
        excluded: last.excluded,
    })
}

/// The rigid-cable calibration from `initial` (the straight-cable offsets in
/// closed form, the measured poses): its stage and its solved graph.
fn rigid_calibration(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<(StageSummary, CalibrationGraph)> {
    let (start, measured, placeholder) = init::rigid_start(initial, measurements);
    let mut rigid = build_graph(
        &start,
        measurements,
        &measured,
        &placeholder,
        CableModel::Rigid,
        options,
    );
    let stage = solve_stage("rigid", &mut rigid, &options.lm)?;
    Ok((stage, rigid))
}

/// Solve one stage; errors name the stage.
fn solve_stage(name: &str, built: &mut CalibrationGraph, lm: &LmParams) -> Result<StageSummary> {
    let summary = system_scope::with_system_cache(|cache| optimize_cached(&mut built.graph, lm, cache))
        .map_err(|e| e.during(format!("{name} stage")))?;
    Ok(StageSummary {
        name: name.to_string(),
        summary,
    })
}

/// The result of a solved graph: the calibrated robot, its uncertainty and
/// residual statistics, the poses and tensions.
fn finish(
    template: &Robot,
    built: CalibrationGraph,
    stages: Vec<StageSummary>,
    excluded_poses: Vec<usize>,
) -> Result<CalibrationResult> {
    let mut robot = robot_from_graph(template, &built);
    let uncertainty = parameter_uncertainty(&built)?;
    robot.calibration_covariance_m2 = uncertainty.covariance();
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
        effect_estimates: Vec::new(),
    })
}

/// Re-estimate anchors, offsets and the parameters of `options.free_effects`
/// (none: the model of `options` as it is, e.g. without the orientation prior)
/// with the extended model, starting from `baseline` (its anchors, offsets,
/// poses, tensions and estimated effects; its excluded poses stay out).
/// `options` should be the ones `baseline` was made with, resolved by
/// [`CalibrationOptions::as_used_by`].
pub fn refine_with_effects(
    baseline: &CalibrationResult,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    let _shared_system = system_scope::Scope::enter();
    let kinds = options.free_effects;
    let used: Vec<PoseMeasurement> = (0..measurements.len())
        .filter(|k| !baseline.excluded_poses.contains(k))
        .map(|k| measurements[k])
        .collect();
    if used.len() != baseline.poses.len() {
        return Err(Error::InvalidInput(format!(
            "refine_with_effects: {} measurements used but the baseline has {} poses",
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
    set_effect_estimates(&mut built, &baseline.effect_estimates);
    let mut stages = baseline.stages.clone();
    let name = format!("extended ({kinds}, orientation prior {})", options.orientation_prior);
    stages.push(solve_stage(&name, &mut built, &options.lm)?);
    let estimates = kinds
        .iter()
        .map(|kind| effect_estimate(&built, kind))
        .collect::<Result<Vec<_>>>()?;
    let mut result = finish(&baseline.robot, built, stages, baseline.excluded_poses.clone())?;
    result.orientation_check = baseline.orientation_check;
    result.effect_estimates = estimates;
    Ok(result)
}

/// `effects` with the estimated effects back at their neutral values (a
/// common gain taken out of each drum's gain, where [`robot_from_graph`]
/// folded it in), so that a graph built from them takes `estimates` on top
/// ([`set_effect_estimates`]) without counting them twice.
pub fn without_estimated(effects: &Effects, estimates: &[EffectEstimate]) -> Effects {
    let neutral = Effects::default();
    let mut out = *effects;
    for estimate in estimates {
        match estimate.effect {
            EffectKind::Elastic => out.axial_stiffness_n = neutral.axial_stiffness_n,
            EffectKind::Pulley => out.pulley_radius_m = neutral.pulley_radius_m,
            EffectKind::EncoderScale => out.encoder_gain = neutral.encoder_gain,
            EffectKind::LoadCell => {
                out.load_cell_bias_n = neutral.load_cell_bias_n;
                out.load_cell_gain = neutral.load_cell_gain;
            }
            EffectKind::Com => {
                out.com_shift_m[0] = 0.0;
                out.com_shift_m[1] = 0.0;
            }
            EffectKind::CommonGain => {
                let common = estimate.values[0] - 1.0;
                out.encoder_gain = out.encoder_gain.map(|g| g - common);
            }
            EffectKind::Segments => out.cable_segments = neutral.cable_segments,
            EffectKind::LocaliserMount => out.localiser_mount_deg = neutral.localiser_mount_deg,
            EffectKind::PlatformWeight => out.platform_weight_scale = neutral.platform_weight_scale,
            EffectKind::CableWeight => out.cable_weight_scale = neutral.cable_weight_scale,
            EffectKind::EncoderDrift => out.encoder_drift_m_per_row = neutral.encoder_drift_m_per_row,
            EffectKind::EncoderBacklash => out.encoder_backlash_m = neutral.encoder_backlash_m,
            EffectKind::LoadCellDrift => out.load_cell_drift_n_per_row = neutral.load_cell_drift_n_per_row,
            EffectKind::LoadCellFriction => out.load_cell_friction = neutral.load_cell_friction,
            EffectKind::Attachments => out.attachment_shift_m = neutral.attachment_shift_m,
        }
    }
    out
}

/// Set the graph's effect variables to `estimates` (a fit's values, which
/// the robot's `[effects]` cannot always hold: a negative compliance).
pub fn set_effect_estimates(built: &mut CalibrationGraph, estimates: &[EffectEstimate]) {
    let Some(vars) = built.effects else {
        return;
    };
    for estimate in estimates {
        built.graph.values.set(
            vars.of(estimate.effect),
            crate::graph::VariableValue::Vector(nalgebra::DVector::from_vec(estimate.variable_values())),
        );
    }
}

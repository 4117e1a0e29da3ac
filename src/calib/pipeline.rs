//! The staged calibration of the module docs of [`crate::calib`]: the
//! rigid-cable stage from the initial guess, the per-pose warm-ups of the
//! two starts, the catenary solve (relaxed statics, then the full graph)
//! from each start, and the choice among the starts ("Basins"); and the
//! result of a solved graph.

use super::graph::{build_graph, robot_from_graph, CalibrationGraph, MIN_POSES};
use super::init;
use super::options::{CableModel, CalibrationOptions};
use super::result::{factor_statistics, CalibrationResult, StageSummary};
use super::system_scope;
use super::uncertainty::parameter_uncertainty;
use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::solver::{optimize_cached, LmParams};

/// One calibration with the orientation prior as given (`Auto` counts as `Off`):
/// the staged pipeline of the module docs; `stage` is told the name of each
/// stage before it is solved.
pub(super) fn calibrate_once(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<CalibrationResult> {
    if options.model == CableModel::Rigid {
        let (rigid_stage, rigid) = rigid_calibration(initial, measurements, options, stage)?;
        return finish(initial, rigid, vec![rigid_stage], Vec::new());
    }
    let prepared = CatenaryPreparation::new(initial, measurements, options, stage)?;
    calibrate_prepared(initial, measurements, options, &prepared, stage)
}

/// Stages (1) and (2) of the catenary pipeline, which the orientation prior
/// does not enter: the rigid calibration (its pose priors always hold the
/// localiser's orientation, whatever [`CalibrationOptions::orientation_prior`]
/// says) and the per-pose warm-ups of the two starts (the statics at the
/// measured positions and load-cell tensions). [`OrientationPrior::Auto`](super::OrientationPrior::Auto)
/// makes them once for its calibrations with and without the prior.
pub(super) struct CatenaryPreparation {
    rigid_stage: StageSummary,
    rigid_robot: Robot,
    /// The initial guess and the rigid calibration, warmed up ([`init::warm_candidates`]).
    warmed: Vec<init::CatenaryStart>,
}

impl CatenaryPreparation {
    /// The stages for `initial` and `measurements`; `stage` is told the name
    /// of each stage before it is solved.
    pub(super) fn new(
        initial: &Robot,
        measurements: &[PoseMeasurement],
        options: &CalibrationOptions,
        stage: &mut dyn FnMut(&str),
    ) -> Result<Self> {
        // (1) Rigid, massless cables from the initial guess: a second
        // candidate start for the catenary.
        let (rigid_stage, rigid) = rigid_calibration(initial, measurements, options, stage)?;
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
/// [`CatenaryPreparation`] made for the same initial guess and measurements;
/// `stage` is told the name of each stage before it is solved.
pub(super) fn calibrate_prepared(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    prepared: &CatenaryPreparation,
    stage: &mut dyn FnMut(&str),
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
        match solve_catenary(initial, first, measurements, options, &relaxed_options, stage) {
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
        "second start",
        measurements,
        options,
        &relaxed_options,
        stage,
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
            solve_starts(
                initial,
                mixed.iter(),
                "mixed start",
                measurements,
                options,
                &relaxed_options,
                stage,
            ),
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

/// The catenary stages solved from every start that can be solved; `stage`
/// is told each stage's name followed by the start's, `label` (numbered
/// `label k of n` when there are several).
fn solve_starts<'a>(
    initial: &Robot,
    starts: impl ExactSizeIterator<Item = &'a init::CatenaryStart>,
    label: &str,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    relaxed_options: &CalibrationOptions,
    stage: &mut dyn FnMut(&str),
) -> Vec<Result<CatenarySolve>> {
    let count = starts.len();
    starts
        .enumerate()
        .map(|(k, start)| {
            let which = match count {
                1 => label.to_string(),
                _ => format!("{label} {} of {count}", k + 1),
            };
            let mut named = |name: &str| stage(&format!("{name}, {which}"));
            solve_catenary(initial, start, measurements, options, relaxed_options, &mut named)
        })
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
    stage: &mut dyn FnMut(&str),
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
    stage(RELAXED_STAGE);
    let relaxed_stage = solve_stage(RELAXED_STAGE, &mut relaxed, &options.lm)?;
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
    stage(CATENARY_STAGE);
    let final_stage = solve_stage(CATENARY_STAGE, &mut full, &options.lm)?;
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
    stage: &mut dyn FnMut(&str),
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
    stage(RIGID_STAGE);
    let summary = solve_stage(RIGID_STAGE, &mut rigid, &options.lm)?;
    Ok((summary, rigid))
}

/// The stages' names, as the result's [`StageSummary`]s and a progress display give them.
const RIGID_STAGE: &str = "rigid";
/// See [`RIGID_STAGE`].
const RELAXED_STAGE: &str = "catenary (relaxed statics)";
/// See [`RIGID_STAGE`].
const CATENARY_STAGE: &str = "catenary";

/// Solve one stage; errors name the stage.
pub(super) fn solve_stage(name: &str, built: &mut CalibrationGraph, lm: &LmParams) -> Result<StageSummary> {
    let summary = system_scope::with_system_cache(|cache| optimize_cached(&mut built.graph, lm, cache))
        .map_err(|e| e.during(format!("{name} stage")))?;
    Ok(StageSummary {
        name: name.to_string(),
        summary,
    })
}

/// The result of a solved graph: the calibrated robot, its uncertainty and
/// residual statistics, the poses and tensions.
pub(super) fn finish(
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

//! The staged calibration of `N` cables ([`calibrate_suspended`]): straight
//! cables from the initial guess, then every pose's equilibrium for those
//! anchors with the offsets in closed form, then the catenary graph with the
//! anchors held, then the full graph. Where that minimum fails the
//! chi-square test at 99.9 % (or the solver stopped), a second start runs
//! the catenary stages from each cable's own trilateration at the
//! localiser's poses ([`super::anchors_by_trilateration`], many starts a
//! cable, independent of the guess) and the lower minimum is kept, if lower
//! by more than one in chi-square (another minimum, not the same one to
//! rounding): the joint straight-cable fit can lead a guess far from the
//! truth into another basin.

use super::graph::{
    build_suspended_graph, min_poses, pose_starts_from_graph, robot_from_suspended_graph, Exclusions, PoseStart,
    SuspendedGraph, SuspendedStage,
};
use super::gross_errors::{reading_count, worst_reading, SuspendedGrossError};
use super::start::{catenary_starts, offsets_in_closed_form, straight_offsets};
use super::trilateration::anchors_by_trilateration;
use crate::calib::options::{CalibrationOptions, GrossErrorOptions, OrientationPrior};
use crate::calib::result::{factor_statistics, FactorStatistics, ParameterUncertainty, StageSummary};
use crate::calib::uncertainty::anchor_and_offset_uncertainty_over_local_gauge;
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use crate::model::DataRow;
use crate::solver::optimize;
use crate::stats::chi_square_quantile_999;

/// A force combination at a pose whose 1-sigma from the readings exceeds
/// this many platform weights is undetermined: the readings say nothing of
/// it that the robot's own scale does not (a vague prior of this 1-sigma on
/// every force, [`anchor_and_offset_uncertainty_over_local_gauge`]).
pub const UNDETERMINED_FORCE_WEIGHTS: f64 = 100.0;

/// A calibration of `N` cables.
#[derive(Debug, Clone)]
pub struct SuspendedCalibration {
    /// The robot with the calibrated anchors and length offsets.
    pub robot: SuspendedRobot,
    /// Every measurement's platform pose at the solution.
    pub poses: Vec<PlatformPose>,
    /// Every measurement's cable forces at the solution, cable order.
    pub forces: Vec<Vec<CableTension>>,
    /// The solver stages, in order.
    pub stages: Vec<StageSummary>,
    /// The poses whose catenary start fell back to the measured pose (no
    /// equilibrium at its position for the straight-cable anchors).
    pub fell_back: Vec<usize>,
    /// Normalised residuals per factor type at the solution.
    pub statistics: Vec<FactorStatistics>,
    /// The anchors' and offsets' covariance at the solution, or the
    /// directions the poses leave unobservable.
    pub uncertainty: ParameterUncertainty,
    /// Residual rows minus the unknowns the readings determine (every
    /// unknown but the undetermined force directions): the degrees of
    /// freedom of the chi-square `2 * final_cost`.
    pub degrees_of_freedom: usize,
    /// `(pose, directions)`, 0-based, of each pose whose cable forces the
    /// readings do not determine: directions of its own variables (each a
    /// combination of its cables' forces the six equations of equilibrium
    /// allow) that change no reading, left out of the anchors' and
    /// offsets' covariance, which they do not touch
    /// ([`crate::solver::marginal_covariance_over_local_gauge`]).
    pub undetermined_forces: Vec<(usize, usize)>,
    /// The readings left out as gross errors, in the order found (empty
    /// without the tests).
    pub left_out: Vec<SuspendedGrossError>,
    /// Whether the tests still found a gross error when the most readings
    /// they may leave out were out: the model, not single readings, fails.
    pub search_exhausted: bool,
    /// The final cost `1/2 chi^2`.
    pub final_cost: f64,
}

/// The stages' names.
const STRAIGHT_STAGE: &str = "straight cables";
/// See [`STRAIGHT_STAGE`].
const HELD_ANCHORS_STAGE: &str = "catenary (anchors held)";
/// See [`STRAIGHT_STAGE`].
const CATENARY_STAGE: &str = "catenary";

/// Calibrate the anchors and length offsets of `initial` (its anchors the
/// guess, everything else known) from `measurements`, leaving out the
/// gross errors `gross_errors` finds (none without); `stage` is told the
/// name of each stage before it is solved. The localiser's orientation
/// enters as a prior unless `options.orientation_prior` is `Off`.
pub fn calibrate_suspended(
    initial: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    options: &CalibrationOptions,
    gross_errors: Option<&GrossErrorOptions>,
    stage: &mut dyn FnMut(&str),
) -> Result<SuspendedCalibration> {
    let with_orientation = options.orientation_prior != OrientationPrior::Off;
    validate(initial, measurements, with_orientation)?;
    // (1) Straight cables from the guess, the offsets in closed form.
    let mut start_robot = initial.clone();
    start_robot.length_offsets_m = straight_offsets(initial, measurements);
    let measured: Vec<PoseStart> = measurements
        .iter()
        .map(|m| PoseStart {
            pose: m.localiser_pose(),
            forces: Vec::new(),
        })
        .collect();
    let none = Exclusions::new();
    let build = |robot: &SuspendedRobot, starts: &[PoseStart], stage: SuspendedStage| {
        build_suspended_graph(robot, measurements, starts, stage, options, with_orientation, &none)
    };
    let mut straight = build(&start_robot, &measured, SuspendedStage::Straight);
    let mut stages = vec![solve(STRAIGHT_STAGE, &mut straight, options, stage)?];
    // (2) - (4) from the straight cables' anchors.
    let inputs = Inputs {
        template: initial,
        measurements,
        options,
        with_orientation,
    };
    let from_straight = robot_from_suspended_graph(initial, &straight);
    let (mut full, more, mut fell_back) = catenary_fit(&inputs, from_straight, "", stage)?;
    stages.extend(more);
    // A failed minimum: the catenary stages again from each cable's own
    // trilateration at the localiser's poses.
    if fails(&full, stages.last()) {
        let mut trilaterated = initial.clone();
        trilaterated.anchors_m = anchors_by_trilateration(initial, measurements);
        let first_cost = stages.last().map_or(f64::NAN, |s| s.summary.final_cost);
        match second_start(first_cost, catenary_fit(&inputs, trilaterated, ", second start", stage)) {
            SecondStart::Lower(second, more, second_fell_back) => {
                stages.extend(more);
                (full, fell_back) = (second, second_fell_back);
            }
            SecondStart::NotLower(more) => {
                // The first minimum stays: its stages last, as the report reads them.
                let first: Vec<StageSummary> = stages.drain(1..).collect();
                stages.extend(more);
                stages.extend(first);
            }
            SecondStart::Failed => {}
        }
    }
    // (5) Gross errors left out one at a time, each followed by a new solve.
    let mut left_out = Vec::new();
    let mut search_exhausted = false;
    if let Some(tests) = gross_errors {
        search_exhausted = leave_out_gross_errors(&inputs, tests, &mut full, &mut left_out, &mut stages, stage)?;
    }
    let solved = pose_starts_from_graph(&full);
    let (uncertainty, undetermined_forces) = anchor_and_offset_uncertainty_over_local_gauge(
        &full.graph,
        &full.anchors,
        &full.length_offsets,
        UNDETERMINED_FORCE_WEIGHTS * initial.platform_weight_n,
    )?;
    // A direction no reading sees takes no degree of freedom from the fit.
    let undetermined: usize = undetermined_forces.iter().map(|(_, d)| d).sum();
    Ok(SuspendedCalibration {
        uncertainty,
        degrees_of_freedom: degrees_of_freedom(&full, undetermined),
        undetermined_forces,
        robot: robot_from_suspended_graph(initial, &full),
        poses: solved.iter().map(|s| s.pose).collect(),
        forces: solved.into_iter().map(|s| s.forces).collect(),
        final_cost: stages.last().map_or(f64::NAN, |s| s.summary.final_cost),
        stages,
        fell_back,
        statistics: factor_statistics(&full.graph),
        left_out,
        search_exhausted,
    })
}

/// Stages (2) to (4) from `robot`'s anchors: each pose's equilibrium for
/// them with the offsets in closed form, the catenary graph with the
/// anchors held, then all free; each stage's name ends with `suffix`. The
/// solved full graph, its stages and the poses whose start fell back.
fn catenary_fit(
    inputs: &Inputs<'_>,
    mut robot: SuspendedRobot,
    suffix: &str,
    stage: &mut dyn FnMut(&str),
) -> Result<(SuspendedGraph, Vec<StageSummary>, Vec<usize>)> {
    let build = |robot: &SuspendedRobot, starts: &[PoseStart]| {
        build_suspended_graph(
            robot,
            inputs.measurements,
            starts,
            SuspendedStage::Catenary,
            inputs.options,
            inputs.with_orientation,
            &Exclusions::new(),
        )
    };
    // (2) Each pose's equilibrium for those anchors; offsets in closed form.
    let (starts, fell_back) = catenary_starts(&robot, inputs.measurements);
    robot.length_offsets_m = offsets_in_closed_form(&robot, inputs.measurements, &starts);
    // (3) The catenary graph with the anchors held, then (4) all free.
    let mut held = build(&robot, &starts);
    for &anchor in &held.anchors {
        held.graph.values.set_fixed(anchor, true);
    }
    let mut stages = vec![solve(
        &format!("{HELD_ANCHORS_STAGE}{suffix}"),
        &mut held,
        inputs.options,
        stage,
    )?];
    let robot = robot_from_suspended_graph(inputs.template, &held);
    let starts = pose_starts_from_graph(&held);
    let mut full = build(&robot, &starts);
    stages.push(solve(
        &format!("{CATENARY_STAGE}{suffix}"),
        &mut full,
        inputs.options,
        stage,
    )?);
    Ok((full, stages, fell_back))
}

/// Whether the solved `full` fails: its solver stopped short, or its
/// chi-square exceeds the 99.9 % quantile of its degrees of freedom counted
/// without undetermined force directions (a lower count, so a lower limit:
/// a fit the report passes may try the second start, never the reverse).
fn fails(full: &SuspendedGraph, last: Option<&StageSummary>) -> bool {
    last.is_none_or(|s| {
        !s.summary.termination.converged()
            || 2.0 * s.summary.final_cost > chi_square_quantile_999(degrees_of_freedom(full, 0).max(1))
    })
}

/// What the second start leaves of a failed first minimum.
enum SecondStart<T> {
    /// Its minimum is lower: the fit, its stages and its fallen-back poses
    /// replace the first's.
    Lower(T, Vec<StageSummary>, Vec<usize>),
    /// Its minimum is not lower: the first stays; its stages are reported.
    NotLower(Vec<StageSummary>),
    /// Its solver stopped with an error: the first minimum stays as found,
    /// reported (and tested) as the first start left it, never an error of
    /// the whole calibration.
    Failed,
}

/// Sort the second start's outcome `second` against the first minimum's
/// cost `first_cost` (`1/2 chi^2`): lower only where its chi-square is
/// lower by more than one (another minimum, not the same one to rounding).
fn second_start<T>(first_cost: f64, second: Result<(T, Vec<StageSummary>, Vec<usize>)>) -> SecondStart<T> {
    let Ok((fit, stages, fell_back)) = second else {
        return SecondStart::Failed;
    };
    let second_cost = stages.last().map_or(f64::NAN, |s| s.summary.final_cost);
    if 2.0 * (second_cost - first_cost) < -1.0 {
        SecondStart::Lower(fit, stages, fell_back)
    } else {
        SecondStart::NotLower(stages)
    }
}

/// What every solve of one calibration shares.
struct Inputs<'a> {
    template: &'a SuspendedRobot,
    measurements: &'a [SuspendedMeasurement],
    options: &'a CalibrationOptions,
    with_orientation: bool,
}

/// Stage (5): while the solved `full` has a reading whose `|w|` exceeds the
/// critical value of `tests`, leave it out (into `left_out`) and solve again
/// from where the last solve ended; at most `tests.max_excluded_fraction` of
/// the readings (and at least one). Whether a gross error was left in
/// because that many were out already.
fn leave_out_gross_errors(
    inputs: &Inputs<'_>,
    tests: &GrossErrorOptions,
    full: &mut SuspendedGraph,
    left_out: &mut Vec<SuspendedGrossError>,
    stages: &mut Vec<StageSummary>,
    stage: &mut dyn FnMut(&str),
) -> Result<bool> {
    let rows: Vec<DataRow> = inputs
        .measurements
        .iter()
        .enumerate()
        .map(|(k, m)| DataRow::at(k, m.line))
        .collect();
    let most = ((tests.max_excluded_fraction * reading_count(full) as f64).floor() as usize).max(1);
    let mut excluded = Exclusions::new();
    while let Some(found) = worst_reading(full, tests.false_alarm, &rows)? {
        if left_out.len() >= most {
            return Ok(true);
        }
        let pose = found.at.row - 1;
        excluded.insert((pose, found.reading));
        left_out.push(found);
        let robot = robot_from_suspended_graph(inputs.template, full);
        let starts = pose_starts_from_graph(full);
        *full = build_suspended_graph(
            &robot,
            inputs.measurements,
            &starts,
            SuspendedStage::Catenary,
            inputs.options,
            inputs.with_orientation,
            &excluded,
        );
        let name = format!("catenary without {} reading(s)", left_out.len());
        stages.push(solve(&name, full, inputs.options, stage)?);
    }
    Ok(false)
}

/// Enough distinct poses with finite readings, one per cable and load cell.
fn validate(robot: &SuspendedRobot, measurements: &[SuspendedMeasurement], with_orientation: bool) -> Result<()> {
    let needed = min_poses(robot, with_orientation);
    if measurements.len() < needed {
        return Err(Error::InvalidInput(format!(
            "{} poses cannot determine the {} anchor coordinates and {} offsets of {} cables with {} load cell(s): at least {needed} are needed",
            measurements.len(),
            3 * robot.cable_count(),
            robot.cable_count(),
            robot.cable_count(),
            robot.load_cells.len()
        )));
    }
    for (k, m) in measurements.iter().enumerate() {
        let row = crate::model::DataRow::at(k, m.line);
        if m.encoder_lengths_m.len() != robot.cable_count() || m.load_cell_tensions_n.len() != robot.load_cells.len() {
            return Err(Error::InvalidInput(format!(
                "{row}: {} encoder readings and {} load-cell readings, where the robot has {} cables and {} load cell(s)",
                m.encoder_lengths_m.len(),
                m.load_cell_tensions_n.len(),
                robot.cable_count(),
                robot.load_cells.len()
            )));
        }
        let finite = m
            .position_m
            .iter()
            .chain(&m.encoder_lengths_m)
            .chain(&m.load_cell_tensions_n)
            .chain([&m.roll_deg, &m.pitch_deg, &m.yaw_deg])
            .all(|v| v.is_finite());
        if !finite || m.load_cell_tensions_n.iter().any(|t| *t <= 0.0) {
            return Err(Error::InvalidInput(format!(
                "{row}: values must be finite and the tensions positive"
            )));
        }
    }
    Ok(())
}

/// Solve one stage; errors name it.
fn solve(
    name: &str,
    built: &mut SuspendedGraph,
    options: &CalibrationOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<StageSummary> {
    stage(name);
    let summary = optimize(&mut built.graph, &options.lm).map_err(|e| e.during(format!("{name} stage")))?;
    Ok(StageSummary {
        name: name.to_string(),
        summary,
    })
}

/// Residual rows minus the free variables' tangent dimensions (0 where
/// there are more unknowns than rows).
fn degrees_of_freedom(built: &SuspendedGraph, undetermined: usize) -> usize {
    let rows: usize = built.graph.factors.iter().map(|f| f.residual_dim()).sum();
    let values = &built.graph.values;
    let unknowns: usize = (0..values.len())
        .map(crate::graph::VariableId)
        .filter(|&id| !values.variable(id).fixed)
        .map(|id| values.tangent_dim(id))
        .sum();
    (rows + undetermined).saturating_sub(unknowns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::{SolveSummary, Termination};

    fn stages(final_cost: f64) -> Vec<StageSummary> {
        let summary = SolveSummary {
            initial_cost: 1e6,
            final_cost,
            iterations: 3,
            termination: Termination::CostConverged,
            history: Vec::new(),
        };
        vec![StageSummary {
            name: CATENARY_STAGE.to_string(),
            summary,
        }]
    }

    #[test]
    fn a_second_start_the_solver_cannot_finish_leaves_the_first_minimum() {
        let failed: Result<((), Vec<StageSummary>, Vec<usize>)> =
            Err(Error::from(crate::solver::SolverError::NothingToSolve));
        assert!(matches!(second_start(50.0, failed), SecondStart::Failed));
    }

    #[test]
    fn the_second_minimum_replaces_the_first_only_when_lower_by_more_than_one_in_chi_square() {
        // Costs are 1/2 chi^2: 0.6 lower is 1.2 lower in chi-square.
        assert!(matches!(
            second_start(50.0, Ok(((), stages(49.4), vec![2]))),
            SecondStart::Lower((), _, _)
        ));
        assert!(matches!(
            second_start(50.0, Ok(((), stages(49.6), vec![]))),
            SecondStart::NotLower(_)
        ));
        assert!(matches!(
            second_start(50.0, Ok(((), stages(80.0), vec![]))),
            SecondStart::NotLower(_)
        ));
    }
}

//! The job of `sagcal plan` on a robot of 3 to 8 cables ([`plan_suspended`]):
//! candidate poses drawn in the workspace (the level equilibria that
//! [`sample_suspended`] keeps: every cable taut and rising, the platform
//! stable at fixed lengths) and held to a tension margin, each one's
//! information about the `3N` anchor coordinates and `N` offsets
//! ([`suspended_candidate_information`]), and the plan of
//! [`crate::plan::plan_poses`] over them, as for four cables
//! ([`super::pose_plan`]): chosen for the Cramer-Rao bound at the nominal
//! robot, in a short visiting order, beside random sets of as many poses.
//! Poses already logged ([`LoggedPoses`], `sagcal plan --from`) serve as
//! the candidates instead: each one the nominal model's equilibrium at its
//! logged position (its yaw held at the logged yaw from four cables on,
//! the one equilibrium of three), kept where it is stable.
//!
//! ```
//! use sagcal::experiments::suspended_plan::{plan_suspended, SuspendedPlanSettings};
//! use sagcal::model::suspended::SuspendedRobot;
//! let six = SuspendedRobot::builtin("six")?;
//! let settings = SuspendedPlanSettings { candidates: 60, ..SuspendedPlanSettings::new(8) };
//! let planned = plan_suspended(&six, &settings, &mut |_| {})?;
//! assert_eq!(planned.report.plan.len(), 8);
//! // Chosen for the bound, the plan beats random sets of as many candidates.
//! assert!(planned.report.anchor_bound_m < planned.report.random_anchor_bound_m);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::pose_plan::{PlanProgress, DEFAULT_CANDIDATES};
use crate::calib::{CalibrationOptions, OrientationPrior};
use crate::error::{Error, FrontEnd, Result};
use crate::model::robot::Workspace;
use crate::model::sensors::NoisePreset;
use crate::model::suspended::{
    check_suspended, smallest_stiffness, solve_at, stiffness, Closure as Member, EquilibriumOptions,
    SuspendedEquilibrium, SuspendedMeasurement, SuspendedRobot,
};
use crate::model::DataRow;
use crate::plan::suspended_information::suspended_candidate_information;
use crate::plan::{plan_poses, Criterion, DesignOptions, Plan};
use crate::sim::closed_form::Closure;
use crate::sim::suspended::sample_suspended;

/// Candidates drawn together between two progress reports.
const BATCH: usize = 25;

/// What `sagcal plan` is asked for on a robot of `N` cables, with its
/// defaults in [`SuspendedPlanSettings::new`].
#[derive(Debug, Clone)]
pub struct SuspendedPlanSettings {
    /// Poses to choose.
    pub poses: usize,
    /// The sensor noise the bound assumes.
    pub noise: NoisePreset,
    /// Candidates to draw.
    pub candidates: usize,
    /// The box they are drawn in: `None`, the robot file's `[workspace]`,
    /// else the box around the anchors ([`Workspace::around_anchor_points`]).
    pub workspace: Option<Workspace>,
    /// Seed of the drawn candidates and of the random sets compared with.
    pub seed: u64,
    /// The design criterion (A- or D-optimal).
    pub criterion: Criterion,
    /// The localiser's orientation as a prior in the bound.
    pub orientation_prior: OrientationPrior,
    /// Who asks: a refused workspace is named as this front end spells it.
    pub front_end: FrontEnd,
    /// Poses already logged, the candidates instead of drawing
    /// `candidates` in `workspace` (`None`: draw them).
    pub logged: Option<LoggedPoses>,
}

/// Poses already logged, as a plan's candidates.
#[derive(Debug, Clone)]
pub struct LoggedPoses {
    /// The logged rows (their positions and yaws are read).
    pub rows: Vec<SuspendedMeasurement>,
    /// Where they came from, as the report names it (the file, as given).
    pub label: String,
}

impl SuspendedPlanSettings {
    /// `poses` poses with the command's defaults: paper noise,
    /// [`DEFAULT_CANDIDATES`] candidates in the default box, seed 1,
    /// A-optimal, no orientation prior.
    pub fn new(poses: usize) -> Self {
        Self {
            poses,
            noise: NoisePreset::Paper,
            candidates: DEFAULT_CANDIDATES,
            workspace: None,
            seed: 1,
            criterion: Criterion::A,
            orientation_prior: OrientationPrior::Off,
            front_end: FrontEnd::Cli,
            logged: None,
        }
    }
}

/// One pose of the plan, in visiting order.
#[derive(Debug, Clone, Serialize)]
pub struct SuspendedPlannedPose {
    /// 1-based position in the visiting order.
    pub visit: usize,
    /// Commanded platform position, metres.
    pub position_m: [f64; 3],
    /// The nominal model's orientation at that position, degrees.
    pub roll_pitch_yaw_deg: [f64; 3],
    /// The lengths the drums pay out there, cable order, metres.
    pub cable_lengths_m: Vec<f64>,
    /// The smallest horizontal cable tension, newtons.
    pub min_horizontal_tension_n: f64,
}

/// The report of `sagcal plan --json` on a robot of `N` cables.
#[derive(Debug, Clone, Serialize)]
pub struct SuspendedPlanReport {
    /// The robot's name.
    pub robot: String,
    /// Its cables.
    pub cables: usize,
    /// Its load cells, 1-based.
    pub load_cells: Vec<usize>,
    /// The seed.
    pub seed: u64,
    /// The sensor noise the bound assumes.
    pub noise: NoisePreset,
    /// The design criterion.
    pub criterion: Criterion,
    /// The localiser's orientation as a prior in the bound.
    pub orientation_prior: OrientationPrior,
    /// The box the candidates were drawn in.
    pub workspace: Workspace,
    /// Where the candidates came from, in words.
    pub candidates_from: String,
    /// Candidates drawn.
    pub examined: usize,
    /// Left out for a horizontal tension below the margin.
    pub outside_margins: usize,
    /// The margin: every cable's horizontal tension at least this, newtons
    /// (10 % of the platform's weight shared by `N` cables).
    pub min_horizontal_tension_n: f64,
    /// Poses chosen.
    pub poses: usize,
    /// The plan's bound, RMS per anchor, metres.
    pub anchor_bound_m: f64,
    /// The plan's bound, RMS per encoder offset, metres.
    pub offset_bound_m: f64,
    /// The mean bound of random sets of the same size, RMS per anchor, metres.
    pub random_anchor_bound_m: f64,
    /// The mean bound of random sets of the same size, RMS per offset, metres.
    pub random_offset_bound_m: f64,
    /// The mean bound of random sets of 35 poses, RMS per anchor, metres (with at least 35 candidates).
    pub random35_anchor_bound_m: Option<f64>,
    /// Length of the visiting path, metres.
    pub path_length_m: f64,
    /// The design's ridge (see [`crate::plan::Design`]).
    pub ridge: f64,
    /// The design's Fedorov exchanges.
    pub exchanges: usize,
    /// The chosen poses in visiting order.
    pub plan: Vec<SuspendedPlannedPose>,
}

/// A plan with its report and candidates: `candidates[k]` is the one
/// `plan.order` names by `k`.
#[derive(Debug, Clone)]
pub struct SuspendedPlanned {
    /// What `--json` prints.
    pub report: SuspendedPlanReport,
    /// The plan (indices into the candidates, bounds, random comparisons).
    pub plan: Plan,
    /// The candidates that kept the margin.
    pub candidates: Vec<SuspendedEquilibrium>,
}

/// Plan the calibration of `robot` (the nominal model) as `settings` ask
/// (module docs); `progress` is told how far the job is ([`PlanProgress`])
/// and changes nothing computed.
pub fn plan_suspended(
    robot: &SuspendedRobot,
    settings: &SuspendedPlanSettings,
    progress: &mut dyn FnMut(PlanProgress<'_>),
) -> Result<SuspendedPlanned> {
    check_counts(settings)?;
    let (drawn, workspace, candidates_from) = match &settings.logged {
        Some(logged) => logged_candidates(robot, logged)?,
        None => {
            let (workspace, from) = workspace(robot, settings);
            check_workspace(robot, &workspace, settings)?;
            let what = format!(
                "drawing {} candidate poses in {from}, seed {}",
                settings.candidates, settings.seed
            );
            let drawn = draw(robot, &workspace, settings, &mut |found| {
                progress(PlanProgress::Drawing {
                    what: &what,
                    found,
                    count: settings.candidates,
                })
            })?;
            (drawn, workspace, format!("{} drawn in {from}", settings.candidates))
        }
    };
    let margin_n = 0.1 * robot.platform_weight_n / robot.cable_count() as f64;
    let examined = drawn.len();
    let candidates: Vec<SuspendedEquilibrium> = drawn
        .into_iter()
        .filter(|eq| eq.tensions.iter().all(|t| t.horizontal_n >= margin_n))
        .collect();
    if candidates.len() < settings.poses {
        return Err(Error::InvalidInput(format!(
            "{} poses requested but only {} of {examined} candidates keep every horizontal tension above {margin_n:.1} N",
            settings.poses,
            candidates.len()
        )));
    }
    let mut options = CalibrationOptions::new(settings.noise.sigmas(robot.platform_weight_n));
    options.orientation_prior = settings.orientation_prior;
    let information = suspended_candidate_information(robot, &candidates, &options)?;
    let design = DesignOptions {
        criterion: settings.criterion,
        ..DesignOptions::new(settings.poses)
    };
    let poses: Vec<_> = candidates.iter().map(|eq| eq.pose).collect();
    let plan = plan_poses(
        &poses,
        &information,
        &design,
        &start_point(&candidates),
        settings.seed,
        &mut |step| progress(PlanProgress::Choosing(step)),
    )?;
    progress(PlanProgress::Done);
    let report = SuspendedPlanReport {
        robot: robot.name.clone(),
        cables: robot.cable_count(),
        load_cells: robot.load_cells.iter().map(|c| c + 1).collect(),
        seed: settings.seed,
        noise: settings.noise,
        criterion: settings.criterion,
        orientation_prior: settings.orientation_prior,
        workspace,
        candidates_from,
        examined,
        outside_margins: examined - candidates.len(),
        min_horizontal_tension_n: margin_n,
        poses: plan.order.len(),
        anchor_bound_m: plan.bound.anchor_rms_m,
        offset_bound_m: plan.bound.offset_rms_m,
        random_anchor_bound_m: plan.random.anchor_rms_m,
        random_offset_bound_m: plan.random.offset_rms_m,
        random35_anchor_bound_m: plan.random35.as_ref().map(|r| r.anchor_rms_m),
        path_length_m: plan.path_length_m,
        ridge: plan.design.ridge,
        exchanges: plan.design.exchanges,
        plan: planned_poses(robot, &candidates, &plan),
    };
    Ok(SuspendedPlanned {
        report,
        plan,
        candidates,
    })
}

/// At least one pose, and no more than the candidates to choose among.
fn check_counts(settings: &SuspendedPlanSettings) -> Result<()> {
    if settings.poses == 0 {
        return Err(Error::InvalidInput("poses = 0: a plan chooses at least 1 pose".into()));
    }
    if settings.logged.is_none() && settings.candidates < settings.poses {
        return Err(Error::InvalidInput(format!(
            "{} poses requested but only {} candidates to draw: a plan chooses its poses among the candidates",
            settings.poses, settings.candidates
        )));
    }
    Ok(())
}

/// The box the candidates are drawn in, and its name in the report.
fn workspace(robot: &SuspendedRobot, settings: &SuspendedPlanSettings) -> (Workspace, String) {
    match (settings.workspace, robot.workspace) {
        (Some(w), _) => (w, settings.front_end.option("workspace")),
        (None, Some(w)) => (w, "the robot file's [workspace]".into()),
        (None, None) => (
            Workspace::around_anchor_points(&robot.anchors_m),
            "the box below the anchors".into(),
        ),
    }
}

/// A box asked for (not the robot file's) below the anchors and inside
/// their footprint ([`check_suspended`]), refused under its own name.
fn check_workspace(robot: &SuspendedRobot, workspace: &Workspace, settings: &SuspendedPlanSettings) -> Result<()> {
    if settings.workspace.is_none() {
        return Ok(());
    }
    let mut boxed = robot.clone();
    boxed.workspace = Some(*workspace);
    check_suspended(&boxed).map_err(|e| {
        let why = e.strip_prefix("field `workspace`: ").unwrap_or(&e);
        Error::InvalidInput(format!(
            "{}: {workspace} for robot `{}`: {why}",
            settings.front_end.option("workspace"),
            robot.name
        ))
    })
}

/// `settings.candidates` level equilibria in `workspace`, drawn in batches
/// from one seeded stream (so the batches change nothing drawn),
/// `progress(found)` from 0 and after each batch.
fn draw(
    robot: &SuspendedRobot,
    workspace: &Workspace,
    settings: &SuspendedPlanSettings,
    progress: &mut dyn FnMut(usize),
) -> Result<Vec<SuspendedEquilibrium>> {
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let mut drawn = Vec::with_capacity(settings.candidates);
    progress(0);
    while drawn.len() < settings.candidates {
        let batch = BATCH.min(settings.candidates - drawn.len());
        let more = sample_suspended(robot, workspace, batch, Closure::Level, &mut rng).map_err(|e| {
            Error::InvalidInput(format!(
                "robot `{}`: no candidate poses in {workspace}: {e}",
                robot.name
            ))
        })?;
        drawn.extend(more);
        progress(drawn.len());
    }
    Ok(drawn)
}

/// The nominal model's stable equilibrium at each logged row's position
/// (module docs), the box the kept ones span, and the report's words for
/// them (naming the rows left out); an error where none is left.
fn logged_candidates(
    robot: &SuspendedRobot,
    logged: &LoggedPoses,
) -> Result<(Vec<SuspendedEquilibrium>, Workspace, String)> {
    let mut kept = Vec::with_capacity(logged.rows.len());
    let mut left_out = Vec::new();
    for (k, row) in logged.rows.iter().enumerate() {
        let measured = row.localiser_pose();
        let closure = if robot.cable_count() > 3 {
            Member::Yaw {
                yaw_rad: measured.yaw_rad(),
            }
        } else {
            Member::Level
        };
        let stable = |eq: &SuspendedEquilibrium| stiffness(robot, eq).is_some_and(|k| smallest_stiffness(&k) > 0.0);
        match solve_at(robot, measured.position_m, closure, &EquilibriumOptions::default()) {
            Ok(eq) if stable(&eq) => kept.push(eq),
            _ => left_out.push(DataRow::at(k, row.line).to_string()),
        }
    }
    if kept.is_empty() {
        return Err(Error::InvalidInput(format!(
            "{}: none of its {} rows has a stable equilibrium of robot `{}` at its logged position",
            logged.label,
            logged.rows.len(),
            robot.name
        )));
    }
    let corner = |pick: fn(f64, f64) -> f64, from: f64| {
        [0, 1, 2].map(|a| kept.iter().map(|eq| eq.pose.position_m[a]).fold(from, pick))
    };
    let span = Workspace {
        min_m: corner(f64::min, f64::INFINITY),
        max_m: corner(f64::max, f64::NEG_INFINITY),
    };
    let mut from = format!("{} logged poses of {}", logged.rows.len(), logged.label);
    if !left_out.is_empty() {
        from += &format!(
            " ({} without a stable equilibrium of the nominal model at the logged position left out: {})",
            left_out.len(),
            left_out.join(", ")
        );
    }
    Ok((kept, span, from))
}

/// Where the path starts: the point below the candidates' centre at the
/// lowest candidate's height (an operator's usual home position).
fn start_point(candidates: &[SuspendedEquilibrium]) -> Vector3<f64> {
    let n = candidates.len().max(1) as f64;
    let mut centre = candidates.iter().map(|e| e.pose.position_m).sum::<Vector3<f64>>() / n;
    centre.z = candidates
        .iter()
        .map(|e| e.pose.position_m.z)
        .fold(f64::INFINITY, f64::min);
    centre
}

/// The chosen candidates in visiting order, as the report lists them.
fn planned_poses(
    robot: &SuspendedRobot,
    candidates: &[SuspendedEquilibrium],
    plan: &Plan,
) -> Vec<SuspendedPlannedPose> {
    plan.order
        .iter()
        .enumerate()
        .map(|(visit, &k)| {
            let eq = &candidates[k];
            let (r, p, y) = eq.pose.roll_pitch_yaw_deg();
            SuspendedPlannedPose {
                visit: visit + 1,
                position_m: eq.pose.position_m.into(),
                roll_pitch_yaw_deg: [r, p, y],
                cable_lengths_m: eq.paid_out_lengths_m(robot),
                min_horizontal_tension_n: eq.tensions.iter().map(|t| t.horizontal_n).fold(f64::INFINITY, f64::min),
            }
        })
        .collect()
}

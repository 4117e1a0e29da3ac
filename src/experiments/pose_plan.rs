//! The job of `sagcal plan` (and of `sagcal.plan` in Python): a robot's
//! candidate poses (drawn in a workspace box, or poses already logged), the
//! plan of [`crate::plan::plan_poses`] over them, and its report exactly as
//! `sagcal plan --json` prints it.
//!
//! The bound is the Cramer-Rao bound of the calibration at the nominal robot
//! ([`crate::plan::bound`]); the candidates keep the tension and clearance
//! margins and hang in a stable equilibrium ([`super::plan_candidates`]).
//!
//! ```
//! use sagcal::experiments::pose_plan::{plan_calibration, CandidateSource, PlanSettings};
//! use sagcal::model::Robot;
//!
//! let robot = Robot::builtin("small")?;
//! let settings = PlanSettings {
//!     candidates: CandidateSource::Drawn { workspace: None, count: 40 },
//!     ..PlanSettings::new(6)
//! };
//! let planned = plan_calibration(&robot, &settings, &mut |_| {})?;
//! assert_eq!(planned.report.plan.len(), 6);
//! // Chosen for the bound, the plan beats random sets of as many candidates.
//! assert!(planned.report.anchor_bound_m < planned.report.random_anchor_bound_m);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;
use serde::Serialize;

use super::plan_candidates::{draw_candidates_with_progress, filter_candidates, frame_workspace, CandidateSet};
use super::table2::{pose_pool, Source};
use crate::calib::{CalibrationOptions, OrientationPrior, MIN_POSES};
use crate::error::{Error, FrontEnd, ParseError, Result};
use crate::model::geometry::check_workspace;
use crate::model::robot::{Robot, Workspace};
use crate::model::sensors::NoisePreset;
use crate::model::statics::Equilibrium;
use crate::model::PoseMeasurement;
use crate::plan::{
    candidate_information, distinct_poses, plan_poses, Criterion, DesignOptions, DesignProgress, Margins, Plan,
};

/// Candidates drawn when none are given (`sagcal plan --candidates`'s default).
pub const DEFAULT_CANDIDATES: usize = 1000;

/// Where the candidate poses come from.
#[derive(Debug, Clone)]
pub enum CandidateSource {
    /// `count` level equilibria drawn in `workspace`; `None`: the robot
    /// file's `[workspace]`, else [`frame_workspace`].
    Drawn {
        /// The box, metres.
        workspace: Option<Workspace>,
        /// Poses to draw.
        count: usize,
    },
    /// Poses already logged (the nominal model's equilibria at their logged
    /// positions, orientations and reference tensions, [`Source::Model`]).
    Logged {
        /// The logged poses.
        poses: Vec<PoseMeasurement>,
        /// Their source as the report names it (the file, as given).
        label: String,
    },
}

/// What `sagcal plan` is asked for: its flags, with its defaults in [`PlanSettings::new`].
#[derive(Debug, Clone)]
pub struct PlanSettings {
    /// Poses to choose.
    pub poses: usize,
    /// The sensor noise the bound assumes.
    pub noise: NoisePreset,
    /// The candidates.
    pub candidates: CandidateSource,
    /// Seed of the drawn candidates and of the random sets compared with.
    pub seed: u64,
    /// The design criterion (A- or D-optimal).
    pub criterion: Criterion,
    /// The localiser's orientation as a prior in the bound.
    pub orientation_prior: OrientationPrior,
    /// Who asks: a refused workspace is named as this front end spells it
    /// (the report's [`PlanReport::candidates_from`] is the command's words
    /// for both, so that the two reports are equal).
    pub front_end: FrontEnd,
}

impl PlanSettings {
    /// `poses` poses with the command's defaults: paper noise,
    /// [`DEFAULT_CANDIDATES`] drawn in the default box, seed 1, A-optimal, no
    /// orientation prior; messages for the command line.
    pub fn new(poses: usize) -> Self {
        Self {
            poses,
            noise: NoisePreset::Paper,
            candidates: CandidateSource::Drawn {
                workspace: None,
                count: DEFAULT_CANDIDATES,
            },
            seed: 1,
            criterion: Criterion::A,
            orientation_prior: OrientationPrior::Off,
            front_end: FrontEnd::Cli,
        }
    }
}

/// How far the job is, for a progress display ([`PlanProgress::counts`]).
/// Drawing the candidates is the long part (~30 ms of CPU each); choosing
/// the poses takes a second or more only for about a hundred poses among
/// 10 000 candidates; the candidates' information, the visiting order and
/// the random sets take milliseconds to a few tenths of a second and report
/// nothing.
#[derive(Debug, Clone, Copy)]
pub enum PlanProgress<'a> {
    /// Drawing candidates: `found` of the `count` asked for (reported from 0,
    /// then after each batch of [`draw_candidates_with_progress`]).
    Drawing {
        /// The draw in the command's words (how many, where, the seed).
        what: &'a str,
        /// Candidates found.
        found: usize,
        /// Candidates asked for.
        count: usize,
    },
    /// Choosing the poses among the candidates.
    Choosing(DesignProgress),
    /// The plan is made.
    Done,
}

impl PlanProgress<'_> {
    /// The report as `(done, total, what)`, as `sagcal plan` draws it and
    /// `sagcal.plan` passes it on (the form of the diagnosis' progress): the
    /// count within the stage `what` names, ending with `(1, 1, "done")`.
    ///
    /// ```
    /// use sagcal::experiments::pose_plan::PlanProgress;
    /// use sagcal::plan::DesignProgress;
    /// let drawing = PlanProgress::Drawing { what: "drawing 40 candidate poses", found: 21, count: 40 };
    /// assert_eq!(drawing.counts(), (21, 40, "drawing 40 candidate poses".to_string()));
    /// let greedy = PlanProgress::Choosing(DesignProgress::Greedy { chosen: 3, poses: 9 });
    /// assert_eq!(greedy.counts(), (3, 9, "choosing the poses one by one".to_string()));
    /// assert_eq!(PlanProgress::Done.counts(), (1, 1, "done".to_string()));
    /// ```
    pub fn counts(&self) -> (usize, usize, String) {
        match *self {
            PlanProgress::Drawing { what, found, count } => (found, count, what.to_string()),
            PlanProgress::Choosing(DesignProgress::Greedy { chosen, poses }) => {
                (chosen, poses, "choosing the poses one by one".to_string())
            }
            PlanProgress::Choosing(DesignProgress::Exchange {
                pass,
                max_passes,
                tried,
                poses,
            }) => (
                tried,
                poses,
                format!("exchanging poses, pass {pass} of at most {max_passes}"),
            ),
            PlanProgress::Done => (1, 1, "done".to_string()),
        }
    }
}

/// One pose of the plan, in visiting order.
#[derive(Debug, Clone, Serialize)]
pub struct PlannedPose {
    /// 1-based position in the visiting order.
    pub visit: usize,
    /// Commanded platform position, metres.
    pub position_m: [f64; 3],
    /// The nominal model's orientation at that position, degrees.
    pub roll_pitch_yaw_deg: [f64; 3],
    /// The nominal model's cable lengths, metres.
    pub cable_lengths_m: [f64; 4],
    /// The smallest horizontal cable tension, newtons.
    pub min_horizontal_tension_n: f64,
}

/// The report of `sagcal plan --json`.
#[derive(Debug, Clone, Serialize)]
pub struct PlanReport {
    /// The robot's name.
    pub robot: String,
    /// The seed.
    pub seed: u64,
    /// The sensor noise the bound assumes.
    pub noise: NoisePreset,
    /// The design criterion.
    pub criterion: Criterion,
    /// The localiser's orientation as a prior in the bound.
    pub orientation_prior: OrientationPrior,
    /// The box the candidates were drawn in (`None` for logged poses).
    pub workspace: Option<Workspace>,
    /// Where the candidates came from, in words.
    pub candidates_from: String,
    /// The candidates (their equilibria are not serialised) and what was left out.
    pub candidates: CandidateSet,
    /// The margins the candidates keep.
    pub margins: Margins,
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
    pub plan: Vec<PlannedPose>,
}

/// A plan with its report: `report.candidates.equilibria[k]` is the
/// candidate `plan.order` names by `k`.
#[derive(Debug, Clone)]
pub struct PlannedCalibration {
    /// What `--json` prints.
    pub report: PlanReport,
    /// The plan (indices into the candidates, bounds, random comparisons).
    pub plan: Plan,
}

/// A workspace from `x0,x1,y0,y1,z0,z1` (metres); `text` names the input in the message.
pub fn workspace_from_bounds(bounds: &[f64], text: &str) -> std::result::Result<Workspace, ParseError> {
    let v = bounds;
    if v.len() != 6 || v.iter().any(|x| !x.is_finite()) || v[0] >= v[1] || v[2] >= v[3] || v[4] >= v[5] {
        return Err(ParseError::NotABox {
            given: text.to_string(),
        });
    }
    Ok(Workspace {
        min_m: [v[0], v[2], v[4]],
        max_m: [v[1], v[3], v[5]],
    })
}

/// `x0,x1,y0,y1,z0,z1` in metres (`sagcal plan --workspace`).
pub fn parse_workspace(text: &str) -> std::result::Result<Workspace, ParseError> {
    let v: Vec<f64> = text
        .split(',')
        .map(|p| {
            p.trim().parse::<f64>().map_err(|_| ParseError::NotANumber {
                what: "number",
                given: p.to_string(),
            })
        })
        .collect::<std::result::Result<_, _>>()?;
    workspace_from_bounds(&v, text)
}

/// A plan's candidates, drawn or logged, as [`plan_among`] takes them:
/// the choice among one set under other noises or criteria needs one draw.
#[derive(Debug, Clone)]
pub struct PlanCandidates {
    /// The candidates kept and what was left out.
    pub set: CandidateSet,
    /// The box they were drawn in (`None` for logged poses).
    pub workspace: Option<Workspace>,
    /// Where they came from, in the report's words.
    pub from: String,
}

/// The candidates `settings` name, drawn (the long part, reported to
/// `progress`) or read from the logged poses and filtered.
pub fn plan_candidates(
    robot: &Robot,
    settings: &PlanSettings,
    progress: &mut dyn FnMut(PlanProgress<'_>),
) -> Result<PlanCandidates> {
    check_counts(settings)?;
    let (set, workspace, from) = candidates(robot, settings, &Margins::for_robot(robot), progress)?;
    Ok(PlanCandidates { set, workspace, from })
}

/// The candidates with the box they were drawn in and their description.
fn candidates(
    robot: &Robot,
    settings: &PlanSettings,
    margins: &Margins,
    progress: &mut dyn FnMut(PlanProgress<'_>),
) -> Result<(CandidateSet, Option<Workspace>, String)> {
    let (workspace, count) = match &settings.candidates {
        CandidateSource::Logged { poses, label } => {
            let pool = pose_pool(robot, poses, Source::Model)?;
            let equilibria: Vec<Equilibrium> = pool.iter().map(|p| p.equilibrium.clone()).collect();
            let groups = distinct_poses(&equilibria, MIN_POSES);
            if groups.len() < MIN_POSES {
                let lines: Vec<usize> = pool.iter().map(|p| p.line).collect();
                return Err(too_few_distinct(label, &lines, &groups));
            }
            let set = filter_candidates(robot, equilibria, margins);
            return Ok((set, None, label.clone()));
        }
        CandidateSource::Drawn { workspace, count } => (*workspace, *count),
    };
    let given = workspace.is_some();
    let (workspace, from) = match (workspace, robot.workspace) {
        (Some(w), _) => (w, "--workspace"),
        (None, Some(w)) => (w, "the robot file's [workspace]"),
        (None, None) => (
            frame_workspace(robot),
            "the frame below the anchors (10 % margin, z 5-75 % of the anchors' height)",
        ),
    };
    // A box the robot cannot hang its platform in is named before any pose is
    // drawn; a box the user gave, as the front end spells the option.
    check_workspace(robot, &workspace).map_err(|e| {
        let named = if given {
            settings.front_end.option("workspace")
        } else {
            from.to_string()
        };
        Error::InvalidInput(format!(
            "{named} {workspace} cannot give candidate poses for robot `{}`: {e}",
            robot.name
        ))
    })?;
    let what = format!("drawing {count} candidate poses in {from}, seed {}", settings.seed);
    progress(PlanProgress::Drawing {
        what: &what,
        found: 0,
        count,
    });
    let set = draw_candidates_with_progress(robot, &workspace, count, margins, settings.seed, &mut |found| {
        progress(PlanProgress::Drawing {
            what: &what,
            found,
            count,
        })
    })?;
    Ok((set, Some(workspace), format!("{count} drawn in {from}")))
}

/// The counts of a plan, checked before any candidate is drawn: at least one
/// pose, and no more poses than candidates to choose them from.
fn check_counts(settings: &PlanSettings) -> Result<()> {
    if settings.poses == 0 {
        return Err(Error::InvalidInput("poses = 0: a plan chooses at least 1 pose".into()));
    }
    if let CandidateSource::Drawn { count, .. } = settings.candidates {
        if count < settings.poses {
            return Err(Error::InvalidInput(format!(
                "{} poses requested but only {count} candidates to draw: a plan chooses its poses among the candidates",
                settings.poses
            )));
        }
    }
    Ok(())
}

/// The error for logged poses of fewer than [`MIN_POSES`] distinct poses
/// (`groups` from [`distinct_poses`]), naming the lines of each repeated one.
fn too_few_distinct(label: &str, lines: &[usize], groups: &[Vec<usize>]) -> Error {
    let repeated: Vec<String> = groups
        .iter()
        .filter(|g| g.len() > 1)
        .map(|g| {
            let named: Vec<String> = g.iter().map(|&k| lines[k].to_string()).collect();
            format!("lines {} are the same pose", named.join(", "))
        })
        .collect();
    Error::InvalidInput(format!(
        "{label}: the {} logged poses are only {} distinct pose{}{}: a plan needs at least {MIN_POSES} distinct poses, \
         each giving 4 equations for the 12 anchor coordinates and 4 offsets",
        lines.len(),
        groups.len(),
        if groups.len() == 1 { "" } else { "s" },
        if repeated.is_empty() { String::new() } else { format!(" ({})", repeated.join("; ")) }
    ))
}

/// Plan the calibration of `robot` (the nominal model): the candidates of
/// `settings`, each one's information, the chosen poses in visiting order
/// from the start point ([`start_point`]), and the comparison with random sets.
/// `progress` is told how far the job is ([`PlanProgress`]); it changes
/// nothing computed.
pub fn plan_calibration(
    robot: &Robot,
    settings: &PlanSettings,
    progress: &mut dyn FnMut(PlanProgress<'_>),
) -> Result<PlannedCalibration> {
    let candidates = plan_candidates(robot, settings, progress)?;
    plan_among(robot, settings, &candidates, progress)
}

/// The plan of `settings` among `candidates` ([`plan_candidates`] of
/// settings that draw or read the same poses): each candidate's
/// information, the choice, the visiting order and the random sets, as
/// [`plan_calibration`] makes them.
pub fn plan_among(
    robot: &Robot,
    settings: &PlanSettings,
    candidates: &PlanCandidates,
    progress: &mut dyn FnMut(PlanProgress<'_>),
) -> Result<PlannedCalibration> {
    check_counts(settings)?;
    let margins = Margins::for_robot(robot);
    let PlanCandidates { set, workspace, from } = candidates.clone();
    if set.equilibria.len() < settings.poses {
        return Err(Error::InvalidInput(format!(
            "{} poses requested but only {} candidates keep the margins and are stable ({} outside the margins, {} unstable)",
            settings.poses,
            set.equilibria.len(),
            set.outside_margins,
            set.unstable
        )));
    }
    let mut options = CalibrationOptions::new(settings.noise.sigmas(robot.platform_weight_n));
    options.orientation_prior = settings.orientation_prior;
    let information = candidate_information(robot, &set.equilibria, &options)?;
    let design = DesignOptions {
        criterion: settings.criterion,
        ..DesignOptions::new(settings.poses)
    };
    let start = start_point(&set.equilibria);
    let poses: Vec<_> = set.equilibria.iter().map(|eq| eq.pose).collect();
    let plan = plan_poses(&poses, &information, &design, &start, settings.seed, &mut |step| {
        progress(PlanProgress::Choosing(step))
    })?;
    progress(PlanProgress::Done);
    let report = PlanReport {
        robot: robot.name.clone(),
        seed: settings.seed,
        noise: settings.noise,
        criterion: settings.criterion,
        orientation_prior: settings.orientation_prior,
        workspace,
        candidates_from: from,
        margins,
        poses: plan.order.len(),
        anchor_bound_m: plan.bound.anchor_rms_m,
        offset_bound_m: plan.bound.offset_rms_m,
        random_anchor_bound_m: plan.random.anchor_rms_m,
        random_offset_bound_m: plan.random.offset_rms_m,
        random35_anchor_bound_m: plan.random35.as_ref().map(|r| r.anchor_rms_m),
        path_length_m: plan.path_length_m,
        ridge: plan.design.ridge,
        exchanges: plan.design.exchanges,
        plan: planned_poses(&set.equilibria, &plan),
        candidates: set,
    };
    Ok(PlannedCalibration { report, plan })
}

/// Where the path starts: the candidate nearest the middle of the floor of
/// the candidates' region (an operator's usual home position).
pub fn start_point(candidates: &[Equilibrium]) -> Vector3<f64> {
    let n = candidates.len().max(1) as f64;
    let mut centre = candidates.iter().map(|e| e.pose.position_m).sum::<Vector3<f64>>() / n;
    centre.z = candidates
        .iter()
        .map(|e| e.pose.position_m.z)
        .fold(f64::INFINITY, f64::min);
    centre
}

/// The chosen candidates in visiting order, as the report lists them.
fn planned_poses(candidates: &[Equilibrium], plan: &Plan) -> Vec<PlannedPose> {
    plan.order
        .iter()
        .enumerate()
        .map(|(visit, &k)| {
            let eq = &candidates[k];
            let (r, p, y) = eq.pose.roll_pitch_yaw_deg();
            PlannedPose {
                visit: visit + 1,
                position_m: eq.pose.position_m.into(),
                roll_pitch_yaw_deg: [r, p, y],
                cable_lengths_m: eq.cable_lengths_m,
                min_horizontal_tension_n: eq.tensions.iter().map(|t| t.horizontal_n).fold(f64::INFINITY, f64::min),
            }
        })
        .collect()
}

//! Candidate poses for `sagcal plan`: reachable static poses drawn densely in
//! a workspace box, kept when they hold positive tensions with a margin, keep
//! every cable clear of the floor ([`Margins`]) and hang in a stable
//! equilibrium (the stiffness at fixed cable lengths is positive definite,
//! [`crate::localize::stiffness`]).
//!
//! ```
//! use sagcal::experiments::plan_candidates::{draw_candidates, filter_candidates, frame_workspace};
//! use sagcal::model::Robot;
//! use sagcal::plan::Margins;
//! let robot = Robot::builtin("large")?;
//! // Anchors at x = +-125 m, y = +-110 m, z = 48 m: 10 % in from each side, z from 5 % to 75 % of 48 m.
//! let frame = frame_workspace(&robot);
//! let expected = [[-100.0, -88.0, 2.4], [100.0, 88.0, 36.0]];
//! for (got, want) in [frame.min_m, frame.max_m].iter().zip(&expected) {
//!     assert!((0..3).all(|i| (got[i] - want[i]).abs() < 1e-12), "{got:?}");
//! }
//! let margins = Margins::for_robot(&robot);
//! let set = draw_candidates(&robot, &frame, 4, &margins, 11)?;
//! assert_eq!(set.equilibria.len(), 4);
//! assert_eq!(set.examined, 4 + set.outside_margins + set.unstable);
//! assert!(set.equilibria.iter().all(|eq| margins.violation(&robot, eq).is_none()));
//! // Judged again, every kept pose stays. Candidate k comes from its own stream (seed, k):
//! // drawing one with the same seed gives the first again, whatever the thread count.
//! let again = filter_candidates(&robot, set.equilibria.clone(), &margins);
//! assert_eq!((again.equilibria.len(), again.outside_margins, again.unstable), (4, 0, 0));
//! let first = draw_candidates(&robot, &frame, 1, &margins, 11)?;
//! assert_eq!(first.equilibria[0].pose.position_m, set.equilibria[0].pose.position_m);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector2;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::localize::stiffness::{smallest_stiffness, stiffness};
use crate::localize::{model_at_pose, SlotRobot};
use crate::model::geometry::check_workspace;
use crate::model::robot::{Robot, Workspace};
use crate::model::statics::Equilibrium;
use crate::plan::Margins;
use crate::sim::closed_form::{sample_equilibria_counted, Closure, FIRST_DRAWS};

/// Draws per candidate before giving up on it (most of a frame is reachable).
pub const ATTEMPTS_PER_CANDIDATE: usize = 50;

/// The largest batch of candidates drawn together, per thread: about a
/// second of work at ~30 ms a candidate, so that the threads wait little
/// for a batch's last candidate and progress is reported often.
pub const BATCH_PER_THREAD: usize = 32;

/// Candidates and what was left out.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateSet {
    /// The kept poses.
    #[serde(skip)]
    pub equilibria: Vec<Equilibrium>,
    /// Poses examined (drawn or read).
    pub examined: usize,
    /// Left out for a margin (tension or clearance).
    pub outside_margins: usize,
    /// Left out as unstable at fixed cable lengths.
    pub unstable: usize,
}

/// The frame below the anchors with a margin: x and y within the anchors'
/// footprint shrunk by 10 % of its extent on each side, z from 5 % to 75 %
/// of the lowest anchor's height (the default box of `sagcal plan` when
/// neither `--workspace` nor the robot file's `[workspace]` gives one).
pub fn frame_workspace(robot: &Robot) -> Workspace {
    let first = robot.anchors_m[0];
    let (min, max) = robot
        .anchors_m
        .iter()
        .fold((first, first), |(lo, hi), a| (lo.inf(a), hi.sup(a)));
    let margin = 0.1 * (max - min);
    Workspace {
        min_m: [min.x + margin.x, min.y + margin.y, 0.05 * min.z],
        max_m: [max.x - margin.x, max.y - margin.y, 0.75 * min.z],
    }
}

/// Whether the platform is stable at `equilibrium` with its cable lengths held.
pub fn is_stable(robot: &Robot, slots: &SlotRobot, equilibrium: &Equilibrium) -> bool {
    let reference = equilibrium.tensions[robot.reference_cable];
    let reference_n = Vector2::new(reference.horizontal_n, reference.vertical_n);
    model_at_pose(slots, &equilibrium.pose, &reference_n)
        .is_some_and(|model| smallest_stiffness(&stiffness(robot, slots, &equilibrium.pose, &model)) > 0.0)
}

/// Why a pose is not a candidate, if it is not.
enum Verdict {
    Kept,
    Margin,
    Unstable,
}

fn judge(robot: &Robot, slots: &SlotRobot, margins: &Margins, eq: &Equilibrium) -> Verdict {
    if margins.violation(robot, eq).is_some() {
        Verdict::Margin
    } else if !is_stable(robot, slots, eq) {
        Verdict::Unstable
    } else {
        Verdict::Kept
    }
}

/// Keep the poses of `equilibria` that are candidates (e.g. a log's poses).
pub fn filter_candidates(robot: &Robot, equilibria: Vec<Equilibrium>, margins: &Margins) -> CandidateSet {
    let slots = SlotRobot::new(robot);
    let mut set = CandidateSet {
        equilibria: Vec::with_capacity(equilibria.len()),
        examined: equilibria.len(),
        outside_margins: 0,
        unstable: 0,
    };
    for eq in equilibria {
        match judge(robot, &slots, margins, &eq) {
            Verdict::Kept => set.equilibria.push(eq),
            Verdict::Margin => set.outside_margins += 1,
            Verdict::Unstable => set.unstable += 1,
        }
    }
    set
}

/// What drawing one candidate gave.
struct Drawn {
    /// The candidate, if one was found.
    equilibrium: Option<Equilibrium>,
    /// Poses drawn that broke a margin, and the first one's reason.
    margin: usize,
    first_margin: Option<String>,
    /// Poses drawn that were unstable.
    unstable: usize,
    /// Why no pose could be drawn at all (the box gave no equilibrium).
    no_equilibrium: Option<String>,
}

/// Candidate `k` of the stream `seed` (see [`draw_candidates`]).
fn draw_one(robot: &Robot, slots: &SlotRobot, workspace: &Workspace, margins: &Margins, seed: u64, k: usize) -> Drawn {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ k as u64);
    let mut drawn = Drawn {
        equilibrium: None,
        margin: 0,
        first_margin: None,
        unstable: 0,
        no_equilibrium: None,
    };
    // The candidate's positions in all, over its attempts: a box where
    // equilibria are rare costs at most FIRST_DRAWS draws, not that per attempt.
    let mut left = FIRST_DRAWS;
    for attempt in 0..ATTEMPTS_PER_CANDIDATE {
        if left == 0 {
            drawn.no_equilibrium = Some(format!(
                "{FIRST_DRAWS} positions drawn gave only {attempt} equilibria, none of them kept: \
                 equilibria are rare in this box"
            ));
            return drawn;
        }
        let mut one = match sample_equilibria_counted(robot, workspace, 1, Closure::Level, left, &mut rng) {
            Ok((one, draws)) => {
                left = left.saturating_sub(draws);
                one
            }
            Err(e) => {
                // No equilibrium in the draws left: more would not find one.
                drawn.no_equilibrium = Some(e.to_string());
                return drawn;
            }
        };
        let eq = one.remove(0);
        if let Some(reason) = margins.violation(robot, &eq) {
            drawn.margin += 1;
            drawn.first_margin.get_or_insert(reason);
        } else if !is_stable(robot, slots, &eq) {
            drawn.unstable += 1;
        } else {
            drawn.equilibrium = Some(eq);
            return drawn;
        }
    }
    drawn
}

/// Draw `count` candidates in `workspace`: candidate `k` draws level
/// equilibria ([`crate::sim::closed_form::sample_equilibria`]) from its own stream `(seed, k)` until
/// one keeps the margins and is stable, so the set does not depend on the
/// number of threads. Level equilibria: a robot commanded to a position
/// with a level platform hangs near the most level member of the family (the
/// member of the straight-cable tension estimate, one solve instead of the
/// scan, tilts up to 25 degrees at the frame's edges on the large robot).
///
/// The box is checked against the robot first
/// ([`crate::model::geometry::check_workspace`]), and the work is bounded:
/// a candidate gives up after [`ATTEMPTS_PER_CANDIDATE`] poses that break a
/// margin or are unstable, or when its positions drawn in all reach
/// [`crate::sim::closed_form::FIRST_DRAWS`] (a box where equilibria are rare:
/// a draw whose statics fail costs up to the whole reference-tension scan,
/// 0.1 s); candidates are drawn in
/// batches of 1, 4, 16, ... in candidate order, and the first batch with a
/// candidate that gave up ends the drawing with an error saying why (a
/// hopeless box fails on its first candidate, within [`ATTEMPTS_PER_CANDIDATE`]
/// poses); a batch holds at most [`BATCH_PER_THREAD`] candidates per thread,
/// so that progress is reported about every second.
pub fn draw_candidates(
    robot: &Robot,
    workspace: &Workspace,
    count: usize,
    margins: &Margins,
    seed: u64,
) -> Result<CandidateSet> {
    draw_candidates_with_progress(robot, workspace, count, margins, seed, &mut |_| {})
}

/// [`draw_candidates`], calling `progress` with the number of candidates
/// found after each batch.
pub fn draw_candidates_with_progress(
    robot: &Robot,
    workspace: &Workspace,
    count: usize,
    margins: &Margins,
    seed: u64,
    progress: &mut dyn FnMut(usize),
) -> Result<CandidateSet> {
    check_workspace(robot, workspace)
        .map_err(|e| Error::InvalidInput(format!("robot `{}`: no candidate pose can be drawn: {e}", robot.name)))?;
    let slots = SlotRobot::new(robot);
    let mut set = CandidateSet {
        equilibria: Vec::with_capacity(count),
        examined: 0,
        outside_margins: 0,
        unstable: 0,
    };
    let (mut start, mut batch) = (0, 1);
    while start < count {
        let end = count.min(start + batch);
        let drawn: Vec<Drawn> = (start..end)
            .into_par_iter()
            .map(|k| draw_one(robot, &slots, workspace, margins, seed, k))
            .collect();
        for (k, d) in (start..end).zip(drawn) {
            set.examined += d.margin + d.unstable + usize::from(d.equilibrium.is_some());
            set.outside_margins += d.margin;
            set.unstable += d.unstable;
            match d.equilibrium {
                Some(eq) => set.equilibria.push(eq),
                None => return Err(gave_up(robot, workspace, count, k, &d)),
            }
        }
        progress(set.equilibria.len());
        start = end;
        batch = (batch * 4).min(BATCH_PER_THREAD * rayon::current_num_threads());
    }
    Ok(set)
}

/// The error of candidate `k`, which found no pose.
fn gave_up(robot: &Robot, workspace: &Workspace, count: usize, k: usize, drawn: &Drawn) -> Error {
    let why = match (&drawn.no_equilibrium, &drawn.first_margin) {
        (Some(e), _) => e.clone(),
        (None, first) => format!(
            "its {ATTEMPTS_PER_CANDIDATE} poses drawn all failed: {} outside the margins{}, {} unstable at fixed cable lengths",
            drawn.margin,
            first.as_ref().map_or(String::new(), |r| format!(" (the first: {r})")),
            drawn.unstable
        ),
    };
    Error::InvalidInput(format!(
        "no candidate pose for robot `{}` in the box {workspace}: candidate {} of {count} found none ({why}), \
         so the drawing stopped there: check the box against the anchors",
        robot.name,
        k + 1
    ))
}

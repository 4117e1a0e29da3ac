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
use crate::model::robot::{Robot, Workspace};
use crate::model::statics::Equilibrium;
use crate::plan::Margins;
use crate::sim::closed_form::sample_equilibria;

/// Draws per candidate before giving up on it (most of a frame is reachable).
const ATTEMPTS_PER_CANDIDATE: usize = 50;

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

/// Draw `count` candidates in `workspace`: candidate `k` draws level
/// equilibria ([`sample_equilibria`]) from its own stream `(seed, k)` until
/// one keeps the margins and is stable, so the set does not depend on the
/// number of threads. Level equilibria: a robot commanded to a position
/// with a level platform hangs near the most level member of the family (the
/// member of the straight-cable tension estimate, one solve instead of the
/// scan, tilts up to 25 degrees at the frame's edges on the large robot).
pub fn draw_candidates(
    robot: &Robot,
    workspace: &Workspace,
    count: usize,
    margins: &Margins,
    seed: u64,
) -> Result<CandidateSet> {
    let slots = SlotRobot::new(robot);
    let drawn: Vec<(Option<Equilibrium>, usize, usize)> = (0..count)
        .into_par_iter()
        .map(|k| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ k as u64);
            let (mut margin, mut unstable) = (0, 0);
            for _ in 0..ATTEMPTS_PER_CANDIDATE {
                let Ok(mut one) = sample_equilibria(robot, workspace, 1, &mut rng) else {
                    continue;
                };
                let eq = one.remove(0);
                match judge(robot, &slots, margins, &eq) {
                    Verdict::Kept => return (Some(eq), margin, unstable),
                    Verdict::Margin => margin += 1,
                    Verdict::Unstable => unstable += 1,
                }
            }
            (None, margin, unstable)
        })
        .collect();
    let mut set = CandidateSet {
        equilibria: Vec::with_capacity(count),
        examined: 0,
        outside_margins: 0,
        unstable: 0,
    };
    for (eq, margin, unstable) in drawn {
        set.examined += 1 + margin + unstable;
        set.outside_margins += margin;
        set.unstable += unstable;
        if let Some(eq) = eq {
            set.equilibria.push(eq);
        } else {
            set.examined -= 1;
        }
    }
    if set.equilibria.len() < count {
        return Err(Error::InvalidInput(format!(
            "only {} of {count} candidate poses found in the workspace {:?}..{:?} ({} outside the margins, {} unstable): check the box against the anchors",
            set.equilibria.len(),
            workspace.min_m,
            workspace.max_m,
            set.outside_margins,
            set.unstable
        )));
    }
    Ok(set)
}

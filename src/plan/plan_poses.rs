//! The plan of a calibration ([`plan_poses`]): the chosen candidates in
//! visiting order with their bound, beside random sets of the same
//! candidates ([`Plan`]), and why chosen poses that leave the anchors or
//! offsets free are refused.

use nalgebra::Vector3;
use serde::Serialize;

use super::bound::{plan_bound, PlanBound};
use super::candidates::distinct_platform_poses;
use super::design::{choose_more_poses_with_progress, Design, DesignOptions, DesignProgress};
use super::information::PoseInformation;
use super::order::{path_length_m, visiting_order};
use super::random::{random_bounds, RandomBounds, RANDOM_DRAWS};
use crate::calib::MIN_POSES;
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;

/// A plan: the chosen candidates in visiting order, their bound, and random sets for comparison.
#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    /// Candidate indices in visiting order.
    pub order: Vec<usize>,
    /// The bound of the plan.
    pub bound: PlanBound,
    /// Random sets of the same size from the same candidates.
    pub random: RandomBounds,
    /// Random sets of 35 poses (the paper's largest Table II column), if there are that many candidates.
    pub random35: Option<RandomBounds>,
    /// Length of the visiting path, metres.
    pub path_length_m: f64,
    /// The search's details.
    pub design: Design,
}

/// Choose, order and compare (the [module docs](crate::plan)); `seed` draws the random sets,
/// `start_m` is where the path begins (the point nearest it is visited first).
/// `progress` follows the choice ([`DesignProgress`]), the one step that can
/// take seconds (choosing 100 of 10 000 candidates); the order and the
/// random sets take milliseconds.
pub fn plan_poses(
    candidates: &[PlatformPose],
    information: &[PoseInformation],
    options: &DesignOptions,
    start_m: &Vector3<f64>,
    seed: u64,
    progress: &mut dyn FnMut(DesignProgress),
) -> Result<Plan> {
    let design = choose_more_poses_with_progress(information, &[], options, progress)?;
    let cables = information.first().map_or(0, |p| p.cables);
    let bound =
        plan_bound(information, &design.chosen).ok_or_else(|| undetermined(candidates, &design.chosen, cables))?;
    let points: Vec<Vector3<f64>> = design.chosen.iter().map(|&k| candidates[k].position_m).collect();
    let order: Vec<usize> = visiting_order(&points, start_m)
        .into_iter()
        .map(|i| design.chosen[i])
        .collect();
    let ordered: Vec<Vector3<f64>> = order.iter().map(|&k| candidates[k].position_m).collect();
    Ok(Plan {
        path_length_m: path_length_m(&ordered),
        bound,
        random: random_bounds(information, options.poses, RANDOM_DRAWS, seed),
        random35: (information.len() >= 35).then(|| random_bounds(information, 35, RANDOM_DRAWS, seed ^ 35)),
        order,
        design,
    })
}

/// Why the poses `chosen` do not determine every anchor and offset: too
/// few, too few distinct, or an arrangement that leaves a direction free.
fn undetermined(candidates: &[PlatformPose], chosen: &[usize], cables: usize) -> Error {
    let poses: Vec<PlatformPose> = chosen.iter().map(|&k| candidates[k]).collect();
    let distinct = distinct_platform_poses(&poses, MIN_POSES).len();
    let why = if chosen.len() < MIN_POSES {
        format!("choose at least {MIN_POSES}")
    } else if distinct < MIN_POSES {
        format!("only {distinct} of them are distinct poses, and at least {MIN_POSES} are needed")
    } else {
        "their arrangement leaves a direction of the anchors or offsets free: draw the candidates over a wider box"
            .into()
    };
    Error::InvalidInput(format!(
        "the {} chosen poses do not determine every anchor and offset (each pose gives {cables} equations for the {} anchor coordinates and {cables} offsets): {why}",
        chosen.len(),
        3 * cables
    ))
}

//! What a robot of `N` cables must be to hang a platform, and what no real
//! one falls outside ([`check_suspended`]): the four-cable robot's rules
//! (`model::geometry`, `model::plausibility`) for `N` cables.

use super::robot::SuspendedRobot;
use crate::model::geometry::{Footprint, MIN_FOOTPRINT_WIDTH_FRACTION};
use crate::model::plausibility::{
    MAX_CABLE_TO_PLATFORM_WEIGHT, MAX_CABLE_WEIGHT_N_PER_M, MAX_PLATFORM_WEIGHT_N, MIN_PLATFORM_WEIGHT_N,
};

/// Check `robot`: anchors whose horizontal projections surround an area
/// (the pulls cancel only inside their footprint), every anchor above the
/// positions asked for (the workspace's top, else the attachments standing
/// on the floor), a workspace inside the footprint, and weights in the
/// plausible ranges of `model::plausibility` (the cables as long as the
/// anchors' spread weigh at most [`MAX_CABLE_TO_PLATFORM_WEIGHT`] platforms).
/// The error names the field and says why.
pub fn check_suspended(robot: &SuspendedRobot) -> Result<(), String> {
    let footprint = Footprint::of_anchors(&robot.anchors_m);
    if footprint.width_m <= MIN_FOOTPRINT_WIDTH_FRACTION * footprint.diameter_m {
        return Err(format!(
            "anchors: their horizontal projections are collinear (the footprint is {:.3} m wide across {:.3} m): a suspended \
             robot's cables pull its platform towards their anchors, and the pulls cancel only inside the anchors' footprint",
            footprint.width_m, footprint.diameter_m
        ));
    }
    let (lowest, z) = robot
        .anchors_m
        .iter()
        .enumerate()
        .map(|(i, a)| (i, a.z))
        .fold((0, f64::INFINITY), |low, (i, z)| if z < low.1 { (i, z) } else { low });
    match &robot.workspace {
        Some(workspace) => {
            if workspace.max_m[2] >= z {
                return Err(format!(
                    "field `workspace`: the box's top z = {} m is not below the anchor of cable {} (z = {z} m): the cables \
                     hold the platform up from above",
                    workspace.max_m[2],
                    lowest + 1
                ));
            }
            for corner in [[0, 0], [0, 1], [1, 0], [1, 1]] {
                let xy = nalgebra::Vector2::new(
                    [workspace.min_m[0], workspace.max_m[0]][corner[0]],
                    [workspace.min_m[1], workspace.max_m[1]][corner[1]],
                );
                if footprint.outside_m(&xy) > 0.0 {
                    return Err(format!(
                        "field `workspace`: the box's corner ({}, {}) m lies outside the anchors' footprint on the floor, \
                         where no cable pulls the platform back",
                        xy.x, xy.y
                    ));
                }
            }
        }
        None => {
            let needed = robot.attachments_m.iter().map(|b| b.z).fold(0.0, f64::max);
            if z <= needed {
                return Err(format!(
                    "cable {}: its anchor at z = {z} m is not above the platform standing on the floor (z > {needed} m); \
                     give a [workspace] if the floor is elsewhere",
                    lowest + 1
                ));
            }
        }
    }
    check_weights(robot, footprint.diameter_m)
}

/// The platform's and the cables' weights in the ranges of `model::plausibility`.
fn check_weights(robot: &SuspendedRobot, spread_m: f64) -> Result<(), String> {
    let w = robot.platform_weight_n;
    if !(MIN_PLATFORM_WEIGHT_N..=MAX_PLATFORM_WEIGHT_N).contains(&w) {
        return Err(format!(
            "field `platform_weight_n`: {w:e} N is outside the plausible {MIN_PLATFORM_WEIGHT_N:.3e} .. \
             {MAX_PLATFORM_WEIGHT_N:.3e} N (1 g .. 1000 t); the weight is m g in newtons"
        ));
    }
    if let Some((i, g_c)) = robot
        .cable_weights_n_per_m
        .iter()
        .enumerate()
        .find(|(_, g)| **g > MAX_CABLE_WEIGHT_N_PER_M)
    {
        return Err(format!(
            "cable {}: {g_c:e} N/m is above {MAX_CABLE_WEIGHT_N_PER_M:.0} N/m, the weight of a solid steel bar 200 mm \
             thick: no rope weighs more per metre",
            i + 1
        ));
    }
    let cables_n: f64 = robot.cable_weights_n_per_m.iter().sum::<f64>() * spread_m;
    if cables_n > MAX_CABLE_TO_PLATFORM_WEIGHT * w {
        return Err(format!(
            "fields `cable_weight_n_per_m` and `platform_weight_n`: the cables, as long as the anchors' {spread_m:.3} m \
             spread, weigh {cables_n:.4e} N, over {MAX_CABLE_TO_PLATFORM_WEIGHT} times the platform's {w} N: the platform \
             would hardly shape them"
        ));
    }
    Ok(())
}

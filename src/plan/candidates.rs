//! Which static poses a plan may use: positive cable tensions with a margin
//! and every cable inside the frame; and which of them are the same pose
//! ([`distinct_poses`]). (Stability at fixed cable lengths is the
//! third condition; it needs the localiser's stiffness and is checked where
//! candidates are drawn, `experiments::plan_candidates`.)
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::model::statics::{solve_level, StaticsOptions};
//! use sagcal::model::Robot;
//! use sagcal::plan::Margins;
//! let robot = Robot::builtin("large")?;
//! let margins = Margins::for_robot(&robot);
//! // 10 % of each cable's share of the 333.54 N platform.
//! assert!((margins.min_horizontal_tension_n - 0.1 * 333.54 / 4.0).abs() < 1e-12);
//! let eq = solve_level(&robot, Vector3::new(0.0, 0.0, 15.0), &StaticsOptions::default())?;
//! assert_eq!(margins.violation(&robot, &eq), None);
//! // Anchors 48 m up: every cable sags below them, so a 48 m clearance fails.
//! let high = Margins { min_cable_height_m: 48.0, ..margins };
//! assert!(high.violation(&robot, &eq).unwrap().contains("sags to"));
//! // The same pose twice is one distinct pose.
//! let groups = sagcal::plan::candidates::distinct_poses(&[eq.clone(), eq.clone()], 4);
//! assert_eq!(groups, vec![vec![0, 1]]);
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::Serialize;

use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{catenaries, Equilibrium};

/// The margins a candidate must keep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Margins {
    /// Every cable's horizontal tension `f_h` (paper eq. 7) at least this, newtons.
    pub min_horizontal_tension_n: f64,
    /// Every cable's lowest point at least this height, metres (the floor of the frame is `z = 0`).
    pub min_cable_height_m: f64,
}

impl Margins {
    /// 10 % of the platform's weight share per cable (`m_e g / 4`), and cables at least 0.5 m above the floor.
    pub fn for_robot(robot: &Robot) -> Self {
        Self {
            min_horizontal_tension_n: 0.1 * robot.platform_weight_n / CABLE_COUNT as f64,
            min_cable_height_m: 0.5,
        }
    }

    /// Why `equilibrium` breaks a margin, or `None` if it keeps them all.
    pub fn violation(&self, robot: &Robot, equilibrium: &Equilibrium) -> Option<String> {
        for (i, t) in equilibrium.tensions.iter().enumerate() {
            if t.horizontal_n.is_nan() || t.horizontal_n < self.min_horizontal_tension_n {
                return Some(format!(
                    "cable {}: horizontal tension {:.1} N below the {:.1} N margin",
                    i + 1,
                    t.horizontal_n,
                    self.min_horizontal_tension_n
                ));
            }
        }
        let cables = catenaries(robot, &equilibrium.pose, &equilibrium.tensions);
        for (i, cable) in cables.iter().enumerate() {
            let anchor_z = robot.anchors_m[i].z;
            let lowest = anchor_z + lowest_height_above_anchor_m(cable);
            if lowest.is_nan() || lowest < self.min_cable_height_m {
                return Some(format!(
                    "cable {}: sags to {lowest:.2} m, below the {:.2} m clearance",
                    i + 1,
                    self.min_cable_height_m
                ));
            }
        }
        None
    }
}

/// The lowest point of a catenary relative to its anchor, metres (`<= 0`):
/// its vertex if that lies within the span, else the attachment end.
fn lowest_height_above_anchor_m(cable: &crate::model::Catenary) -> f64 {
    // Sampled at 64 points: the vertex is interior only for nearly
    // horizontal cables, where the curve is flat and sampling is exact to mm.
    (0..=64)
        .map(|k| cable.height_above_anchor_m(cable.span_m * k as f64 / 64.0))
        .fold(0.0, f64::min)
}

/// Two candidates whose positions differ by at most this, metres, and whose
/// orientations by at most [`SAME_ORIENTATION_RAD`], are the same pose: a
/// micrometre, below any localiser's resolution.
pub const SAME_POSITION_M: f64 = 1e-6;
/// See [`SAME_POSITION_M`]: a microradian, radians.
pub const SAME_ORIENTATION_RAD: f64 = 1e-6;

/// The candidates grouped by pose ([`SAME_POSITION_M`],
/// [`SAME_ORIENTATION_RAD`]), each group the indices of one pose in the
/// order of first appearance; at most `limit` groups are formed (the
/// candidates beyond them are left out), so asking whether there are at
/// least `limit` distinct poses costs `limit` comparisons per candidate.
pub fn distinct_poses(candidates: &[Equilibrium], limit: usize) -> Vec<Vec<usize>> {
    let poses: Vec<PlatformPose> = candidates.iter().map(|eq| eq.pose).collect();
    distinct_platform_poses(&poses, limit)
}

/// [`distinct_poses`] of the platform poses themselves (a robot of any
/// number of cables).
pub fn distinct_platform_poses(poses: &[PlatformPose], limit: usize) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (k, pose) in poses.iter().enumerate() {
        let same = groups.iter().position(|g| {
            let first = &poses[g[0]];
            (first.position_m - pose.position_m).norm() <= SAME_POSITION_M
                && first.rotation.angle_to(&pose.rotation) <= SAME_ORIENTATION_RAD
        });
        match same {
            Some(g) => groups[g].push(k),
            None if groups.len() < limit => groups.push(vec![k]),
            None => {}
        }
    }
    groups
}

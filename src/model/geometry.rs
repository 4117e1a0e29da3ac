//! The geometry a suspended four-cable robot needs, checked when a robot
//! file is read ([`check_robot`]) and for every box poses are drawn in
//! ([`check_workspace`]). Each rule has a physical reason, stated in its
//! message:
//!
//! - **Anchors around the platform.** A cable pulls its platform
//!   horizontally towards its anchor; the pulls cancel, as gravity needs,
//!   only where the platform hangs inside the anchors' horizontal footprint
//!   (the convex hull of their projections on the floor). Anchors whose
//!   projections are collinear leave no such region: the footprint must be at
//!   least [`MIN_FOOTPRINT_WIDTH_FRACTION`] as wide (its narrowest extent) as
//!   it is long (the largest distance between two projections).
//! - **Anchors above the platform.** A cable holds its platform up only from
//!   above: every anchor must be above every position the robot is asked to
//!   reach. With a box of positions (the robot file's `[workspace]`, `sagcal
//!   plan --workspace`), the box's top must be below the lowest anchor.
//!   Without one, positions are taken between the floor (`z = 0`) and the
//!   anchors, so every anchor must be above the floor and above the
//!   platform's attachment points when it stands there.
//! - **A box under the anchors.** Outside the footprint by more than the
//!   platform's reach (its attachment points' largest distance from its
//!   origin), every cable pulls the platform the same way and no equilibrium
//!   exists: every horizontal corner of a box must be within that distance
//!   of the footprint.
//!
//! ```
//! use sagcal::model::geometry::{check_robot, check_workspace, Footprint};
//! use sagcal::model::robot::Workspace;
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! // Anchors at x = +-125 m, y = +-110 m: 220 m wide, 333 m across the diagonal.
//! let footprint = Footprint::of(&robot);
//! assert!((footprint.width_m - 220.0).abs() < 1e-9);
//! assert!((footprint.diameter_m - (250f64.powi(2) + 220f64.powi(2)).sqrt()).abs() < 1e-9);
//! assert!(check_robot(&robot).is_ok());
//! // Anchors on one line: no region where the cables' pulls cancel.
//! let mut line = robot.clone();
//! for (a, x) in line.anchors_m.iter_mut().zip([-125.0, -40.0, 40.0, 125.0]) {
//!     a.x = x;
//!     a.y = 0.0;
//! }
//! assert!(check_robot(&line).unwrap_err().contains("collinear"));
//! // A box reaching above the anchors (48 m), or beside the robot.
//! let high = Workspace { min_m: [-2.0, -2.0, 30.0], max_m: [2.0, 2.0, 50.0] };
//! assert!(check_workspace(&robot, &high).unwrap_err().contains("not below"));
//! let beside = Workspace { min_m: [200.0, 0.0, 3.0], max_m: [210.0, 10.0, 18.0] };
//! assert!(check_workspace(&robot, &beside).unwrap_err().contains("outside the anchors' horizontal footprint"));
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{Vector2, Vector3};

use crate::model::robot::{Robot, Workspace};

/// The narrowest extent of the anchors' footprint must be at least this
/// fraction of its largest (module docs): at 1 % the cables' pulls across
/// the footprint are a hundredth of those along it, the strip the platform
/// can hang in is a hundredth of the robot's size, and the positions across
/// it are determined a hundred times worse than along it; anchors closer to a
/// line than that are collinear for every purpose of a suspended robot.
pub const MIN_FOOTPRINT_WIDTH_FRACTION: f64 = 0.01;

/// The anchors' horizontal footprint: the convex hull of their projections
/// on the floor, its narrowest extent (width) and its largest (diameter).
#[derive(Debug, Clone, PartialEq)]
pub struct Footprint {
    /// The hull's corners, counter-clockwise (fewer than 3 when the anchors' projections are collinear).
    pub hull_m: Vec<Vector2<f64>>,
    /// The narrowest extent: the smallest distance between two parallel lines enclosing every projection, metres.
    pub width_m: f64,
    /// The largest distance between two projections, metres.
    pub diameter_m: f64,
}

impl Footprint {
    /// The footprint of `robot`'s anchors.
    pub fn of(robot: &Robot) -> Self {
        Self::of_anchors(&robot.anchors_m)
    }

    /// The footprint of these anchors.
    pub fn of_anchors(anchors_m: &[Vector3<f64>]) -> Self {
        let points: Vec<Vector2<f64>> = anchors_m.iter().map(|a| a.xy()).collect();
        let mut diameter_m = 0.0f64;
        let mut width_m = f64::INFINITY;
        for (i, p) in points.iter().enumerate() {
            for q in &points[i + 1..] {
                let along = q - p;
                let length = along.norm();
                diameter_m = diameter_m.max(length);
                if length > 0.0 {
                    // The extent of every projection across the line through p and q: the
                    // narrowest extent over all directions is reached across a hull edge.
                    let normal = Vector2::new(-along.y, along.x) / length;
                    let (low, high) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
                        let d = normal.dot(&(r - p));
                        (lo.min(d), hi.max(d))
                    });
                    width_m = width_m.min(high - low);
                }
            }
        }
        Self {
            hull_m: convex_hull(&points),
            width_m: if width_m.is_finite() { width_m } else { 0.0 },
            diameter_m,
        }
    }

    /// How far `point` lies outside the footprint, metres (a lower bound,
    /// exact where the nearest part of the hull is an edge); zero or
    /// negative inside.
    pub fn outside_m(&self, point: &Vector2<f64>) -> f64 {
        let hull = &self.hull_m;
        match hull.len() {
            0 => f64::INFINITY,
            1 => (point - hull[0]).norm(),
            2 => distance_to_segment(point, &hull[0], &hull[1]),
            n => (0..n)
                .map(|k| {
                    let (a, b) = (hull[k], hull[(k + 1) % n]);
                    let edge = b - a;
                    // Counter-clockwise hull: the outward normal is the edge turned clockwise.
                    let outward = Vector2::new(edge.y, -edge.x) / edge.norm();
                    outward.dot(&(point - a))
                })
                .fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

fn distance_to_segment(p: &Vector2<f64>, a: &Vector2<f64>, b: &Vector2<f64>) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (p - (a + t * ab)).norm()
}

/// The convex hull of `points`, counter-clockwise (Andrew's monotone chain;
/// collinear points are left out).
fn convex_hull(points: &[Vector2<f64>]) -> Vec<Vector2<f64>> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    sorted.dedup();
    if sorted.len() < 3 {
        return sorted;
    }
    let cross = |o: &Vector2<f64>, a: &Vector2<f64>, b: &Vector2<f64>| (a - o).perp(&(b - o));
    let mut hull: Vec<Vector2<f64>> = Vec::with_capacity(2 * sorted.len());
    for pass in [sorted.clone(), sorted.iter().rev().copied().collect()] {
        let start = hull.len();
        for p in pass {
            while hull.len() >= start + 2 && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], &p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The platform's reach: the largest distance of an attachment point from
/// the platform's origin, metres (how far the platform's cables can leave
/// from its position, whatever its orientation).
pub fn platform_reach_m(robot: &Robot) -> f64 {
    robot.attachments_m.iter().map(|b| b.norm()).fold(0.0, f64::max)
}

/// The lowest anchor: its 0-based cable index and height, metres.
fn lowest_anchor(robot: &Robot) -> (usize, f64) {
    robot
        .anchors_m
        .iter()
        .enumerate()
        .map(|(i, a)| (i, a.z))
        .fold((0, f64::INFINITY), |low, (i, z)| if z < low.1 { (i, z) } else { low })
}

/// Check that `robot` is a suspended robot (module docs): anchors whose
/// projections are not collinear, above its workspace (its `workspace` if it
/// has one, else above the floor and the platform's attachment points
/// standing on it), and a workspace under the anchors. The error says what
/// was found, the rule and why.
pub fn check_robot(robot: &Robot) -> Result<(), String> {
    let footprint = Footprint::of(robot);
    if footprint.width_m <= MIN_FOOTPRINT_WIDTH_FRACTION * footprint.diameter_m {
        return Err(format!(
            "anchors: their horizontal projections are collinear (the footprint is {:.3} m wide across {:.3} m, less than {} %): \
             a suspended robot's cables pull its platform towards their anchors, and the pulls cancel only inside the anchors' \
             footprint on the floor, so the anchors must surround the platform",
            footprint.width_m,
            footprint.diameter_m,
            100.0 * MIN_FOOTPRINT_WIDTH_FRACTION
        ));
    }
    match &robot.workspace {
        Some(workspace) => check_workspace(robot, workspace).map_err(|e| format!("field `workspace`: {e}")),
        None => {
            let (lowest, z) = lowest_anchor(robot);
            let attachments = robot
                .attachments_m
                .iter()
                .map(|b| b.z)
                .fold(f64::NEG_INFINITY, f64::max);
            let needed = attachments.max(0.0);
            if z > needed {
                return Ok(());
            }
            Err(format!(
                "cable {}: its anchor at z = {z} m is not above the platform: a suspended robot's cables hold the platform \
                 up from above, and without a [workspace] the platform's positions are taken between the floor (z = 0) and \
                 the anchors, so every anchor must be above the floor and the platform's attachment points standing on it \
                 (z > {needed} m); give a [workspace] if the floor is elsewhere",
                lowest + 1
            ))
        }
    }
}

/// Check that `workspace` is a box `robot` can hang its platform in (module
/// docs): finite corners with `min_m <= max_m`, its top below the lowest
/// anchor, and every horizontal corner within the platform's reach of the
/// anchors' footprint. The error describes the box and says why.
pub fn check_workspace(robot: &Robot, workspace: &Workspace) -> Result<(), String> {
    let Workspace { min_m, max_m } = *workspace;
    if !(0..3).all(|k| min_m[k].is_finite() && max_m[k].is_finite() && min_m[k] <= max_m[k]) {
        return Err(format!(
            "the box {workspace} needs finite corners with the lower <= the upper on every axis"
        ));
    }
    let (lowest, z) = lowest_anchor(robot);
    if max_m[2] >= z {
        return Err(format!(
            "the box's top z = {} m is not below the anchor of cable {} (z = {z} m): a suspended robot's cables hold \
             the platform up from above, so every position it is asked to reach must be below every anchor",
            max_m[2],
            lowest + 1
        ));
    }
    let footprint = Footprint::of(robot);
    let reach = platform_reach_m(robot);
    let corners = [
        (min_m[0], min_m[1]),
        (max_m[0], min_m[1]),
        (max_m[0], max_m[1]),
        (min_m[0], max_m[1]),
    ];
    for (x, y) in corners {
        let outside = footprint.outside_m(&Vector2::new(x, y));
        if outside > reach {
            return Err(format!(
                "the box's corner (x {x}, y {y}) m lies {outside:.3} m outside the anchors' horizontal footprint, \
                 more than the platform's reach ({reach:.3} m): there every cable pulls the platform the same way \
                 and no equilibrium exists, so the box must be under the anchors"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn large() -> Robot {
        Robot::builtin("large").unwrap()
    }

    #[test]
    fn the_footprint_of_a_rectangle_is_its_short_side_and_diagonal() {
        let f = Footprint::of(&large());
        assert_eq!(f.hull_m.len(), 4);
        assert!((f.width_m - 220.0).abs() < 1e-9 && (f.diameter_m - 333.016_516_106_8).abs() < 1e-6);
        // Inside: negative (the distance to the nearest edge); outside: the distance beyond the edge.
        assert!((f.outside_m(&Vector2::new(0.0, 0.0)) + 110.0).abs() < 1e-9);
        assert!((f.outside_m(&Vector2::new(130.0, 0.0)) - 5.0).abs() < 1e-9);
    }

    #[test]
    fn a_triangle_with_an_anchor_inside_keeps_three_corners() {
        let mut robot = large();
        robot.anchors_m[2] = Vector3::new(0.0, 0.0, 48.0);
        let f = Footprint::of(&robot);
        assert_eq!(f.hull_m.len(), 3);
        assert!(f.outside_m(&Vector2::new(0.0, 100.0)) > 0.0);
        assert!(check_robot(&robot).is_ok());
    }

    #[test]
    fn nearly_collinear_anchors_are_refused_at_one_percent() {
        let mut robot = large();
        let strip = |robot: &mut Robot, half_width: f64| {
            for (a, (x, s)) in
                robot
                    .anchors_m
                    .iter_mut()
                    .zip([(-125.0, -1.0), (125.0, -1.0), (125.0, 1.0), (-125.0, 1.0)])
            {
                (a.x, a.y) = (x, s * half_width);
            }
        };
        // 2 m wide across 250.008 m: 0.8 %.
        strip(&mut robot, 1.0);
        let message = check_robot(&robot).unwrap_err();
        assert!(message.contains("2.000 m wide across 250.008 m"), "{message}");
        strip(&mut robot, 2.0);
        assert!(check_robot(&robot).is_ok(), "4 m across 250 m is 1.6 %");
        // Anchors stacked above one point: a footprint of no size.
        for (a, z) in robot.anchors_m.iter_mut().zip([10.0, 20.0, 30.0, 40.0]) {
            *a = Vector3::new(0.0, 0.0, z);
        }
        assert!(check_robot(&robot).unwrap_err().contains("collinear"));
    }

    #[test]
    fn anchors_below_the_floor_need_a_workspace_below_them() {
        let mut robot = large();
        for a in &mut robot.anchors_m {
            a.z = -48.0;
        }
        let message = check_robot(&robot).unwrap_err();
        assert!(
            message.starts_with("cable 1: its anchor at z = -48 m is not above the platform"),
            "{message}"
        );
        robot.workspace = Some(Workspace {
            min_m: [-10.0, -10.0, -90.0],
            max_m: [10.0, 10.0, -50.0],
        });
        assert!(check_robot(&robot).is_ok());
        robot.workspace.as_mut().unwrap().max_m[2] = -48.0;
        assert!(check_robot(&robot).unwrap_err().contains("top z = -48 m is not below"));
    }

    #[test]
    fn a_box_may_leave_the_footprint_by_the_platforms_reach_only() {
        let robot = large();
        let reach = platform_reach_m(&robot);
        assert!((reach - (2.0 * 0.21f64.powi(2) + 0.011f64.powi(2)).sqrt()).abs() < 1e-12);
        let inside = Workspace {
            min_m: [-125.0 - 0.9 * reach, -110.0, 1.0],
            max_m: [125.0, 110.0, 40.0],
        };
        assert!(check_workspace(&robot, &inside).is_ok());
        let outside = Workspace {
            min_m: [-125.0 - 1.1 * reach, -110.0, 1.0],
            ..inside
        };
        assert!(check_workspace(&robot, &outside)
            .unwrap_err()
            .contains("corner (x -125.3"));
        let inverted = Workspace {
            min_m: [1.0, 0.0, 0.0],
            max_m: [0.0, 1.0, 1.0],
        };
        assert!(check_workspace(&robot, &inverted)
            .unwrap_err()
            .contains("lower <= the upper"));
    }
}

//! Whether a solved equilibrium is a pose of the suspended robot at all.
//!
//! The statics have solutions no suspended robot reaches: four 1 000 m
//! readings of a robot whose anchors are 48 m high are reproduced by a
//! platform hanging 933 m below the floor. Such a solution satisfies every
//! equation and may be stable, so [`Frame::check`] compares it with the
//! robot's frame:
//!
//! - **the floor**: the lowest height of the robot file's `[workspace]` if
//!   it gives one, else `z = 0` (the convention of the built-in robots and
//!   of the default pose box, `Workspace::around_anchors`: the world origin
//!   on the floor). The platform below it, or a cable whose lowest point
//!   lies below it (the cable would rest on the floor, slack there, which
//!   the free-hanging catenary does not model), is flagged;
//! - **the anchors' horizontal hull**: the cables pull the platform towards
//!   their anchors, so the horizontal forces balance only with the platform
//!   inside the anchors' convex hull, widened by the platform's size (its
//!   attachments' largest distance from its origin);
//! - **the anchors' height**: the weight is carried by the cables pulling up,
//!   which a hanging (convex) cable does only from an anchor above its
//!   attachment, so the platform cannot lie above every anchor (widened by
//!   the platform's size).
//!
//! Each comparison allows three standard deviations of the position (both
//! sources): a pose that far beyond the frame is not the reading noise
//! (a 3-sigma excursion has 0.3 % probability for a Gaussian).
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::localize::Frame;
//! use sagcal::model::statics::{solve_level, StaticsOptions};
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! let frame = Frame::of(&robot);
//! assert_eq!(frame.floor_z_m, 0.0);
//! let eq = solve_level(&robot, Vector3::new(2.0, -3.0, 15.0), &StaticsOptions::default())?;
//! assert_eq!(frame.check(&robot, &eq.pose, &eq.tensions, &Vector3::zeros()), None);
//! let mut below = eq.pose;
//! below.position_m.z = -900.0;
//! let why = frame.check(&robot, &below, &eq.tensions, &Vector3::zeros()).unwrap();
//! assert!(why.contains("below the floor"), "{why}");
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{Vector2, Vector3};

use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{cable_geometry, CableTension};

/// Standard deviations of the position a pose may lie beyond the frame (module docs).
const SIGMAS: f64 = 3.0;

/// The region a suspended robot's platform can hang in (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// The floor's height, metres.
    pub floor_z_m: f64,
    /// Where the floor comes from, for the messages.
    pub floor_source: &'static str,
    /// The anchors' horizontal convex hull, counter-clockwise (fewer than 3
    /// corners for collinear anchors: no hull test then).
    pub hull_m: Vec<Vector2<f64>>,
    /// The highest anchor, metres.
    pub top_z_m: f64,
    /// The platform's size: its attachments' largest distance from its origin, metres.
    pub platform_radius_m: f64,
}

/// Counter-clockwise convex hull of points (Andrew's monotone chain); collinear points dropped.
fn convex_hull(points: &[Vector2<f64>]) -> Vec<Vector2<f64>> {
    let mut p: Vec<Vector2<f64>> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let cross = |o: Vector2<f64>, a: Vector2<f64>, b: Vector2<f64>| (a - o).perp(&(b - o));
    let mut hull: Vec<Vector2<f64>> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        for &q in p.iter() {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0 {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
        if pass == 0 {
            p.reverse();
        }
    }
    hull
}

impl Frame {
    /// The frame of `robot` (module docs).
    pub fn of(robot: &Robot) -> Self {
        let (floor_z_m, floor_source) = match &robot.workspace {
            Some(w) => (w.min_m[2], "the lowest height of the robot file's [workspace]"),
            None => (
                0.0,
                "z = 0: the world origin on the floor, as the default workspace assumes; a [workspace] in the robot file sets another",
            ),
        };
        let hull_m = convex_hull(&robot.anchors_m.map(|a| a.xy()));
        Self {
            floor_z_m,
            floor_source,
            hull_m: if hull_m.len() >= 3 { hull_m } else { Vec::new() },
            top_z_m: robot.anchors_m.iter().map(|a| a.z).fold(f64::NEG_INFINITY, f64::max),
            platform_radius_m: robot.attachments_m.iter().map(|b| b.norm()).fold(0.0, f64::max),
        }
    }

    /// How far `point` lies outside the hull, metres (<= 0 inside; the
    /// largest distance beyond an edge's line, exact for a point beyond one
    /// edge and a lower bound beyond a corner).
    fn outside_hull_m(&self, point: Vector2<f64>) -> f64 {
        let n = self.hull_m.len();
        (0..n)
            .map(|k| {
                let (a, b) = (self.hull_m[k], self.hull_m[(k + 1) % n]);
                let edge = b - a;
                // Counter-clockwise: the outside is to the right of each edge.
                -edge.perp(&(point - a)) / edge.norm()
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Why the equilibrium `pose` with attachment tensions `tensions`
    /// (robot cable order) is not a pose of the suspended robot, or `None`
    /// (module docs); `sigma_m` is the position's 1-sigma per world axis.
    pub fn check(
        &self,
        robot: &Robot,
        pose: &PlatformPose,
        tensions: &[CableTension; CABLE_COUNT],
        sigma_m: &Vector3<f64>,
    ) -> Option<String> {
        let p = pose.position_m;
        let slack_z = SIGMAS * sigma_m.z;
        if p.z < self.floor_z_m - slack_z {
            return Some(format!(
                "outside the frame: the platform at z = {:.3} m is {:.3} m below the floor ({})",
                p.z,
                self.floor_z_m - p.z,
                self.floor_source
            ));
        }
        let slack_xy = SIGMAS * sigma_m.x.max(sigma_m.y);
        if !self.hull_m.is_empty() {
            let outside = self.outside_hull_m(p.xy());
            if outside > self.platform_radius_m + slack_xy {
                return Some(format!(
                    "outside the frame: the platform at ({:.3}, {:.3}) m is {outside:.3} m outside the anchors' horizontal hull, where no suspended platform is in equilibrium",
                    p.x, p.y
                ));
            }
        }
        if p.z > self.top_z_m + self.platform_radius_m + slack_z {
            return Some(format!(
                "outside the frame: the platform at z = {:.3} m is above every anchor (the highest at {:.3} m), where no suspended platform is in equilibrium",
                p.z, self.top_z_m
            ));
        }
        let geometry = cable_geometry(robot, pose);
        let g_c = robot.cable_weight_n_per_m;
        for (i, (cable, tension)) in geometry.iter().zip(tensions).enumerate() {
            let (f_h, f_v) = (tension.horizontal_n, tension.vertical_n);
            if !(f_h > 0.0 && f_h.is_finite() && f_v.is_finite()) {
                return Some(format!(
                    "slack cable {}: horizontal tension {f_h:.3} N is not positive",
                    i + 1
                ));
            }
            // The cable pulls the platform down (u < 0): a heavy cable dips
            // to a lowest point at f_h/g_c asinh(-u) from the attachment,
            // f_h/g_c (sqrt(1 + u^2) - 1) below it, if that is within the span.
            let u = f_v / f_h;
            let lowest = if u < 0.0 && g_c > 0.0 && f_h / g_c * (-u).asinh() < cable.span_m {
                cable.attachment_world_m.z - f_h / g_c * u * u / (1.0 + (1.0 + u * u).sqrt())
            } else {
                cable.attachment_world_m.z.min(robot.anchors_m[i].z)
            };
            if lowest < self.floor_z_m - slack_z {
                return Some(format!(
                    "slack cable {}: its lowest point at z = {lowest:.3} m is below the floor ({}), where the cable would lie on the floor",
                    i + 1,
                    self.floor_source
                ));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_rectangle_and_distances_outside() {
        let corners = [
            Vector2::new(-1.0, -1.0),
            Vector2::new(1.0, -1.0),
            Vector2::new(1.0, 1.0),
            Vector2::new(-1.0, 1.0),
        ];
        let hull = convex_hull(&corners);
        assert_eq!(hull.len(), 4);
        let frame = Frame {
            floor_z_m: 0.0,
            floor_source: "",
            hull_m: hull,
            top_z_m: 1.0,
            platform_radius_m: 0.0,
        };
        assert!((frame.outside_hull_m(Vector2::new(0.0, 0.0)) + 1.0).abs() < 1e-12);
        assert!((frame.outside_hull_m(Vector2::new(3.0, 0.0)) - 2.0).abs() < 1e-12);
        assert!((frame.outside_hull_m(Vector2::new(0.0, -1.5)) - 0.5).abs() < 1e-12);
        let collinear = convex_hull(&[Vector2::new(0.0, 0.0), Vector2::new(1.0, 1.0), Vector2::new(2.0, 2.0)]);
        assert!(collinear.len() < 3);
    }
}

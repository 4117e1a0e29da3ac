//! The static equilibrium of a platform on `N` cables at a given position
//! ([`solve_at`]).
//!
//! At a position the unknowns are the orientation (3) and the free force
//! components (`2N - 6`), against one attachment-height equation per cable
//! (paper eq. 15): `N - 3` more unknowns than equations (0 for three
//! cables, 1 for four, 5 for eight). A [`Closure`] picks one member of that
//! family: the one nearest a target, in the metric `M` below, with the
//! heights held exactly. The target is the orientation asked for and the
//! free components of the straight-cable minimum-norm tensions at it
//! (`(J^T)^+ w`, paper eq. 8 without sag); the metric weighs a radian of
//! rotation as 1 and a platform weight of force as [`FORCE_WEIGHT`], so the
//! orientation is kept first and the forces chosen among what remains.
//!
//! The solve is Gauss-Newton on the heights with the minimum-`M`-norm step
//! towards the target (the projection
//! `dx = (t - x) - M^-1 J^T (J M^-1 J^T)^-1 (h + J (t - x))`, whose fixed
//! points are the first-order conditions of `min |x - t|_M` subject to
//! `h(x) = 0`), halved until the heights fall; the Jacobian `J = dh/dx` by
//! central differences. The dependent three cables are chosen at the
//! target pose and kept through the solve. Every answer is an equilibrium
//! (heights within the tolerance, the six equations by construction, every
//! cable taut); where the iteration does not get there it fails.
//!
//! What is verified: four cables, where it is the four-cable solver's
//! equilibrium ([`crate::model::statics`]) at a held yaw, and the level
//! closure's member no more tilted than the four-cable solver's most level
//! one (to a thousandth of a degree), and the nearest to its target. Three
//! cables have one equilibrium at a position, at an orientation where the
//! dependent block is singular by construction: `three_cables.rs` solves
//! them in other unknowns. Not yet solved: from five cables on, the start
//! (straight cables' taut tensions over a grid of orientations) does not
//! bring the iteration home on every robot: an irregular eight-cable ring
//! stalls with heights of metres.

use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3};

use super::robot::SuspendedRobot;
use super::tension_distribution::taut_tensions;
use super::three_cables::ThreeCables;
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;

/// How much a platform weight of force counts against a radian of rotation
/// in the closure's metric (module docs): small, so the orientation asked
/// for is held wherever the heights allow it.
pub const FORCE_WEIGHT: f64 = 1e-6;

/// Which member of the equilibria at a position (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Closure {
    /// The platform as level as the heights allow, its yaw where the cables
    /// put it (weighed [`YAW_WEIGHT`] against the tilt): the most level
    /// member for four cables, the one equilibrium of three.
    Level,
    /// The yaw held at `yaw_rad` and the platform as level as the heights
    /// allow (exactly level from six cables on, where the yaw is one the
    /// cables can hold). Needs four cables or more: three fix the
    /// orientation at a position.
    Yaw {
        /// The platform's yaw about the world's vertical, radians.
        yaw_rad: f64,
    },
}

/// How much a radian of yaw counts against a radian of tilt in
/// [`Closure::Level`]'s metric: little, so the tilt is what is kept small.
pub const YAW_WEIGHT: f64 = 1e-3;

/// Iteration limits and tolerances of [`solve_at`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumOptions {
    /// Most Gauss-Newton iterations.
    pub max_iterations: usize,
    /// Largest attachment-height residual accepted, metres.
    pub height_tolerance_m: f64,
}

impl Default for EquilibriumOptions {
    /// 100 iterations, 1e-9 m height tolerance (the four-cable solver's).
    fn default() -> Self {
        Self {
            max_iterations: 100,
            height_tolerance_m: 1e-9,
        }
    }
}

/// A static equilibrium of a platform on `N` cables.
#[derive(Debug, Clone, PartialEq)]
pub struct SuspendedEquilibrium {
    /// The platform's pose.
    pub pose: PlatformPose,
    /// Each cable's forces at its attachment, in cable order.
    pub tensions: Vec<CableTension>,
    /// Each cable's catenary length (paper eq. 4), metres.
    pub cable_lengths_m: Vec<f64>,
    /// The attachment-height residuals left, metres.
    pub height_residuals_m: Vec<f64>,
    /// The three cables whose forces the balance gave (0-based).
    pub dependent: [usize; 3],
    /// Gauss-Newton iterations used.
    pub iterations: usize,
}

/// The problem of one position: the unknowns' meaning, the target and the metric.
struct Problem<'a> {
    robot: &'a SuspendedRobot,
    position_m: Vector3<f64>,
    /// The orientation the rotation unknowns turn from.
    base: UnitQuaternion<f64>,
    /// Rotation unknowns (2: roll and pitch about the base; 3: all).
    rotations: usize,
    dependent: [usize; 3],
    free: Vec<usize>,
    target: DVector<f64>,
    metric: DVector<f64>,
}

impl Problem<'_> {
    /// The pose of `x`: roll and pitch (and yaw, where free) added to the
    /// base's Euler angles, `R = Rz(yaw) Ry(pitch) Rx(roll)`, so that a held
    /// yaw is the pose's yaw exactly.
    fn pose(&self, x: &DVector<f64>) -> PlatformPose {
        let (_, _, base_yaw) = self.base.euler_angles();
        let yaw = base_yaw + if self.rotations == 3 { x[2] } else { 0.0 };
        PlatformPose::new(self.position_m, UnitQuaternion::from_euler_angles(x[0], x[1], yaw))
    }

    fn tensions(&self, x: &DVector<f64>) -> Result<Vec<CableTension>> {
        let weight = self.robot.platform_weight_n;
        let free: Vec<(usize, f64, f64)> = self
            .free
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let at = self.rotations + 2 * k;
                (i, x[at] * weight, x[at + 1] * weight)
            })
            .collect();
        self.robot.balance(&self.pose(x), &self.dependent, &free)
    }

    /// Set `x`'s free components to the straight cables' taut tensions at
    /// `x`'s orientation, scaled by the platform's weight.
    fn set_forces(&self, x: &mut DVector<f64>) {
        let straight = straight_cable_forces(self.robot, &self.pose(x));
        for (k, &i) in self.free.iter().enumerate() {
            x[self.rotations + 2 * k] = straight[2 * i] / self.robot.platform_weight_n;
            x[self.rotations + 2 * k + 1] = straight[2 * i + 1] / self.robot.platform_weight_n;
        }
    }

    /// The heights at `x`, or `None` where a cable goes slack or the balance fails.
    fn heights(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
        let tensions = self.tensions(x).ok()?;
        if !tensions.iter().all(CableTension::is_taut) {
            return None;
        }
        let h = DVector::from_vec(self.robot.height_residuals(&self.pose(x), &tensions));
        h.iter().all(|v| v.is_finite()).then_some(h)
    }

    /// `dh/dx` by central differences.
    fn jacobian(&self, x: &DVector<f64>) -> Option<DMatrix<f64>> {
        let mut jacobian = DMatrix::zeros(self.robot.cable_count(), x.len());
        for j in 0..x.len() {
            let step = 1e-7 * x[j].abs().max(1e-2);
            let (mut up, mut down) = (x.clone(), x.clone());
            up[j] += step;
            down[j] -= step;
            let column = (self.heights(&up)? - self.heights(&down)?) / (2.0 * step);
            jacobian.set_column(j, &column);
        }
        Some(jacobian)
    }

    /// The projected step of the module docs.
    fn step(&self, x: &DVector<f64>, h: &DVector<f64>, jacobian: &DMatrix<f64>) -> Option<DVector<f64>> {
        let towards = &self.target - x;
        let inverse_metric = self.metric.map(|m| 1.0 / m);
        let weighted = DMatrix::from_fn(jacobian.nrows(), jacobian.ncols(), |r, c| {
            jacobian[(r, c)] * inverse_metric[c]
        });
        let gram = &weighted * jacobian.transpose();
        let multipliers = gram.lu().solve(&(h + jacobian * &towards))?;
        Some(towards - weighted.transpose() * multipliers)
    }
}

/// The equilibrium at `position_m` that `closure` picks (module docs).
///
/// Fails with [`Error::InvalidInput`] for a yaw with three cables or a
/// non-finite input, and with [`Error::NoEquilibrium`] where no member
/// keeps every cable taut near the target or the iteration does not reach
/// the height tolerance.
pub fn solve_at(
    robot: &SuspendedRobot,
    position_m: Vector3<f64>,
    closure: Closure,
    options: &EquilibriumOptions,
) -> Result<SuspendedEquilibrium> {
    let mut problem = problem(robot, position_m, closure)?;
    let unsolved = |why: String| {
        Error::NoEquilibrium(format!(
            "position {:?} on {} cables: {why}",
            position_m.as_slice(),
            robot.cable_count()
        ))
    };
    if robot.cable_count() == 3 {
        return solve_three_cables(robot, position_m, options).ok_or_else(|| {
            unsolved("no taut equilibrium within 30 degrees of level reaches the height tolerance".into())
        });
    }
    let (mut x, mut h) = match problem.heights(&problem.target) {
        Some(h) => (problem.target.clone(), h),
        None => start(&mut problem).ok_or_else(|| {
            unsolved("a cable is slack at every orientation within 30 degrees of the target's".into())
        })?,
    };
    for iteration in 0..options.max_iterations {
        let jacobian = problem
            .jacobian(&x)
            .ok_or_else(|| unsolved("a cable goes slack next to the current estimate".into()))?;
        let dx = problem
            .step(&x, &h, &jacobian)
            .ok_or_else(|| unsolved("the heights' Jacobian lost its rank".into()))?;
        let feasible = h.amax() <= options.height_tolerance_m;
        if feasible && dx.amax() <= 1e-12 * x.amax().max(1.0) {
            return Ok(finish(&problem, &x, iteration));
        }
        let mut scale = 1.0;
        loop {
            let trial = &x + &dx * scale;
            if let Some(trial_h) = problem.heights(&trial) {
                if trial_h.amax() <= (h.amax() * (1.0 - 0.5 * scale)).max(options.height_tolerance_m) {
                    (x, h) = (trial, trial_h);
                    break;
                }
            }
            scale *= 0.5;
            if scale < 1e-12 {
                if feasible {
                    return Ok(finish(&problem, &x, iteration));
                }
                return Err(unsolved(format!("the heights stalled at {:.3e} m", h.amax())));
            }
        }
    }
    if h.amax() <= options.height_tolerance_m {
        return Ok(finish(&problem, &x, options.max_iterations));
    }
    Err(unsolved(format!(
        "{} iterations left a height residual of {:.3e} m",
        options.max_iterations,
        h.amax()
    )))
}

/// Three cables' one equilibrium at `position_m` ([`ThreeCables`]).
fn solve_three_cables(
    robot: &SuspendedRobot,
    position_m: Vector3<f64>,
    options: &EquilibriumOptions,
) -> Option<SuspendedEquilibrium> {
    let three = ThreeCables::new(robot, position_m);
    let (x, iterations) = three.solve(options.height_tolerance_m, options.max_iterations)?;
    let pose = three.pose(&x);
    let (tensions, _) = three.forces(&x)?;
    let cables = robot.catenaries(&pose, &tensions);
    Some(SuspendedEquilibrium {
        cable_lengths_m: cables.iter().map(|c| c.length_m()).collect(),
        height_residuals_m: robot.height_residuals(&pose, &tensions),
        pose,
        tensions,
        dependent: [0, 1, 2],
        iterations,
    })
}

/// The unknowns, target and metric of `closure` at `position_m`.
fn problem(robot: &SuspendedRobot, position_m: Vector3<f64>, closure: Closure) -> Result<Problem<'_>> {
    if !position_m.iter().all(|v| v.is_finite()) {
        return Err(Error::InvalidInput(format!(
            "the position must be finite, got {:?}",
            position_m.as_slice()
        )));
    }
    let (base, rotations) = match closure {
        Closure::Yaw { yaw_rad } if robot.cable_count() < 4 => {
            return Err(Error::InvalidInput(format!(
                "a yaw of {yaw_rad} rad cannot be held on three cables: they fix the orientation at a position \
                 (use the level closure)"
            )))
        }
        Closure::Yaw { yaw_rad } if !yaw_rad.is_finite() => {
            return Err(Error::InvalidInput(format!(
                "the yaw must be finite, got {yaw_rad} rad"
            )))
        }
        Closure::Yaw { yaw_rad } => (UnitQuaternion::from_euler_angles(0.0, 0.0, yaw_rad), 2),
        Closure::Level => (UnitQuaternion::identity(), 3),
    };
    let start = PlatformPose::new(position_m, base);
    let dependent = robot.dependent_cables(&start);
    let free: Vec<usize> = (0..robot.cable_count()).filter(|i| !dependent.contains(i)).collect();
    let straight = straight_cable_forces(robot, &start);
    let mut target = DVector::zeros(rotations + 2 * free.len());
    let mut metric = DVector::from_element(target.len(), FORCE_WEIGHT);
    metric.rows_mut(0, rotations).fill(1.0);
    if rotations == 3 {
        metric[2] = YAW_WEIGHT;
    }
    for (k, &i) in free.iter().enumerate() {
        target[rotations + 2 * k] = straight[2 * i] / robot.platform_weight_n;
        target[rotations + 2 * k + 1] = straight[2 * i + 1] / robot.platform_weight_n;
    }
    Ok(Problem {
        robot,
        position_m,
        base,
        rotations,
        dependent,
        free,
        target,
        metric,
    })
}

/// Every cable's `(f_h, f_v)` with straight cables at `pose`: the tensions
/// `t_i` along the attachment-to-anchor lines of [`taut_tensions`] about
/// the even share `t` (`sum t e_z,i = m_e g`), split into their horizontal
/// and vertical parts.
fn straight_cable_forces(robot: &SuspendedRobot, pose: &PlatformPose) -> DVector<f64> {
    let rotation = pose.rotation_matrix();
    let n = robot.cable_count();
    let mut lines = DMatrix::zeros(6, n);
    let mut split = Vec::with_capacity(n);
    for i in 0..n {
        let r = rotation * robot.attachments_m[i];
        let e = (robot.anchors_m[i] - pose.position_m - r).normalize();
        let moment = r.cross(&e);
        lines.set_column(i, &DVector::from_vec(vec![e.x, e.y, e.z, moment.x, moment.y, moment.z]));
        split.push((e.xy().norm(), e.z));
    }
    let wrench = DVector::from_column_slice(robot.gravity_wrench(pose).as_slice());
    let lift: f64 = split.iter().map(|(_, vertical)| vertical).sum();
    let even = robot.platform_weight_n / lift.max(1e-6);
    let tensions = taut_tensions(&lines, &wrench, even, robot.attachment_radius_m());
    DVector::from_fn(2 * n, |k, _| {
        let (horizontal, vertical) = split[k / 2];
        tensions[k / 2] * if k % 2 == 0 { horizontal } else { vertical }
    })
}

/// The start of the iteration: over a grid of orientations about the
/// base (every 5 degrees to 30 of tilt, and of yaw where it is free), the
/// straight cables' taut tensions at each ([`straight_cable_forces`]) as
/// the free components, and of those points where every cable is taut the
/// one with the smallest heights. The target's forces become the start's:
/// the forces at the base orientation may be no taut distribution at all.
fn start(problem: &mut Problem<'_>) -> Option<(DVector<f64>, DVector<f64>)> {
    let steps: Vec<f64> = (-6..=6).map(|k| (5.0 * k as f64).to_radians()).collect();
    let yaws: Vec<f64> = if problem.rotations == 3 {
        steps.clone()
    } else {
        vec![0.0]
    };
    let mut best: Option<(DVector<f64>, DVector<f64>)> = None;
    for &roll in &steps {
        for &pitch in &steps {
            for &yaw in &yaws {
                let mut x = problem.target.clone();
                x[0] = roll;
                x[1] = pitch;
                if problem.rotations == 3 {
                    x[2] = yaw;
                }
                problem.set_forces(&mut x);
                let Some(h) = problem.heights(&x) else {
                    continue;
                };
                if best.as_ref().is_none_or(|(_, b)| h.norm() < b.norm()) {
                    best = Some((x, h));
                }
            }
        }
    }
    let (x, h) = best?;
    let forces = problem.rotations..x.len();
    problem
        .target
        .rows_range_mut(forces.clone())
        .copy_from(&x.rows_range(forces));
    Some((x, h))
}

fn finish(problem: &Problem<'_>, x: &DVector<f64>, iterations: usize) -> SuspendedEquilibrium {
    let pose = problem.pose(x);
    let tensions = problem.tensions(x).expect("the last accepted estimate balances");
    let cables = problem.robot.catenaries(&pose, &tensions);
    SuspendedEquilibrium {
        cable_lengths_m: cables.iter().map(|c| c.length_m()).collect(),
        height_residuals_m: problem.robot.height_residuals(&pose, &tensions),
        pose,
        tensions,
        dependent: problem.dependent,
        iterations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::robot::Robot;
    use crate::model::statics::{solve_level, StaticsOptions};

    /// `n` anchors around a 20 m circle at about 15 m height, each at its
    /// own radius and height (a fixed pattern), attachments on a 0.5 m
    /// circle facing their anchors, 0.5 N/m cables, a 500 N platform whose
    /// centre of mass is off its axis.
    fn ring(n: usize) -> SuspendedRobot {
        let angle = |k: usize| std::f64::consts::TAU * k as f64 / n as f64;
        let anchor = |k: usize| {
            let r = 20.0 + 2.0 * (3.0 * k as f64).cos();
            Vector3::new(r * angle(k).cos(), r * angle(k).sin(), 15.0 + (2.0 * k as f64).sin())
        };
        SuspendedRobot::new(
            (0..n).map(anchor).collect(),
            (0..n)
                .map(|k| Vector3::new(0.5 * angle(k).cos(), 0.5 * angle(k).sin(), 0.2))
                .collect(),
            vec![0.5; n],
            Vector3::new(0.05, -0.03, -0.1),
            500.0,
        )
        .unwrap()
    }

    /// What every equilibrium holds: the heights, the six equations, taut cables.
    fn assert_equilibrium(robot: &SuspendedRobot, eq: &SuspendedEquilibrium) {
        let heights = robot.height_residuals(&eq.pose, &eq.tensions);
        assert!(heights.iter().all(|h| h.abs() < 1e-9), "{heights:?}");
        let wrench = robot.wrench_residual(&eq.pose, &eq.tensions);
        assert!(wrench.amax() < 1e-9 * robot.platform_weight_n, "{wrench}");
        assert!(eq.tensions.iter().all(CableTension::is_taut), "{:?}", eq.tensions);
    }

    fn tilt_deg(pose: &PlatformPose) -> f64 {
        let (roll, pitch, _) = pose.roll_pitch_yaw_deg();
        roll.hypot(pitch)
    }

    /// Four cables with the yaw held are the paper's square problem: the
    /// equilibrium of the four-cable solver at the same position and yaw;
    /// the level closure is its most level member, to the weight given yaw.
    #[test]
    fn four_cables_are_the_four_cable_solvers_equilibria() {
        let robot = Robot::builtin("large").unwrap();
        let suspended = SuspendedRobot::from_robot(&robot);
        for position in [Vector3::new(12.0, -8.0, 18.0), Vector3::new(-60.0, 40.0, 8.0)] {
            let paper = solve_level(&robot, position, &StaticsOptions::default()).unwrap();
            let closure = Closure::Yaw {
                yaw_rad: paper.pose.yaw_rad(),
            };
            let eq = solve_at(&suspended, position, closure, &EquilibriumOptions::default()).unwrap();
            assert_equilibrium(&suspended, &eq);
            let angle = eq.pose.rotation.angle_to(&paper.pose.rotation);
            assert!(angle < 1e-8, "{angle} rad from the four-cable solver's orientation");
            for (t, p) in eq.tensions.iter().zip(&paper.tensions) {
                assert!(
                    (t.magnitude_n() - p.magnitude_n()).abs() < 1e-6 * p.magnitude_n(),
                    "{t:?} {p:?}"
                );
            }
            for (l, p) in eq.cable_lengths_m.iter().zip(&paper.cable_lengths_m) {
                assert!((l - p).abs() < 1e-8, "{l} vs {p}");
            }
            let level = solve_at(&suspended, position, Closure::Level, &EquilibriumOptions::default()).unwrap();
            assert_equilibrium(&suspended, &level);
            println!(
                "{position:?}: tilt {:.6} deg (four-cable solver {:.6}), yaw {:.4} deg ({:.4})",
                tilt_deg(&level.pose),
                tilt_deg(&paper.pose),
                level.pose.yaw_rad().to_degrees(),
                paper.pose.yaw_rad().to_degrees()
            );
            assert!(tilt_deg(&level.pose) < tilt_deg(&paper.pose) + 1e-3);
        }
    }

    /// Three cables have one equilibrium at a position (its horizontal
    /// lines of action meeting in one point), found from a level start; a
    /// held yaw is refused.
    #[test]
    fn three_cables_hang_in_their_one_equilibrium() {
        let robot = ring(3);
        for position in [Vector3::new(1.0, -1.5, 5.0), Vector3::new(-4.0, 3.0, 9.0)] {
            let eq = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default()).unwrap();
            assert_equilibrium(&robot, &eq);
            println!(
                "three cables at {position:?}: tilt {:.3} deg, yaw {:.3} deg",
                tilt_deg(&eq.pose),
                eq.pose.yaw_rad().to_degrees()
            );
            assert!(tilt_deg(&eq.pose) < 30.0 && eq.pose.yaw_rad().abs() < 30f64.to_radians());
        }
        let refused = solve_at(
            &robot,
            Vector3::new(1.0, -1.5, 5.0),
            Closure::Yaw { yaw_rad: 0.0 },
            &EquilibriumOptions::default(),
        );
        assert!(
            matches!(&refused, Err(Error::InvalidInput(m)) if m.contains("three cables")),
            "{refused:?}"
        );
    }

    /// The level closure's answer is the member nearest its target: at the
    /// solution the metric-weighted offset from the target lies in the span
    /// of the heights' gradients (the first-order conditions). Four cables,
    /// five unknowns, four heights: one direction is free.
    #[test]
    fn the_level_equilibrium_is_the_nearest_to_its_target() {
        let robot = SuspendedRobot::from_robot(&Robot::builtin("large").unwrap());
        let position = Vector3::new(-20.0, 30.0, 15.0);
        let eq = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default()).unwrap();
        let mut problem = problem(&robot, position, Closure::Level).unwrap();
        if problem.heights(&problem.target).is_none() {
            start(&mut problem).unwrap();
        }
        let mut x = DVector::zeros(problem.target.len());
        let (roll, pitch, yaw) = eq.pose.rotation.euler_angles();
        (x[0], x[1], x[2]) = (roll, pitch, yaw);
        for (k, &i) in problem.free.iter().enumerate() {
            x[3 + 2 * k] = eq.tensions[i].horizontal_n / robot.platform_weight_n;
            x[4 + 2 * k] = eq.tensions[i].vertical_n / robot.platform_weight_n;
        }
        let jacobian = problem.jacobian(&x).unwrap();
        let gradient = (&x - &problem.target).component_mul(&problem.metric);
        // Least squares of J^T lambda = gradient: the remainder is what no height can explain.
        let lambda = jacobian.transpose().svd(true, true).solve(&gradient, 1e-14).unwrap();
        let remainder = &gradient - jacobian.transpose() * lambda;
        println!(
            "first-order remainder {:.3e} of a gradient {:.3e}",
            remainder.amax(),
            gradient.amax()
        );
        assert!(gradient.amax() > 0.0, "the target itself is no equilibrium here");
        assert!(remainder.amax() < 1e-6 * gradient.amax(), "{remainder} of {gradient}");
    }
}

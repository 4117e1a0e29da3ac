//! The static equilibrium of a platform on `N` cables at a given position
//! ([`solve_at`]).
//!
//! Each cable that reaches its attachment has one degree of freedom: given
//! its horizontal tension `f_h`, the catenary through its anchor and its
//! attachment fixes its vertical tension (paper eq. 1 at `x = span`,
//! inverted in closed form: [`vertical_for_height`]), so the attachment
//! heights (eq. 15) hold by construction. The unknowns at a position are
//! then the orientation (3) and the `N` horizontal tensions, against the
//! six equations of equilibrium (eq. 8): `N - 3` more unknowns than
//! equations (0 for three cables, 1 for four, 5 for eight). No set of
//! dependent forces is chosen, so none can be singular: with three cables
//! the horizontal rows `F_x`, `F_y`, `M_z` are homogeneous (gravity loads
//! none of them) and hold only where the cables' horizontal lines meet in
//! one point, which the orientation unknowns find.
//!
//! A [`Closure`] picks one member of that family: the one nearest a target
//! in the metric `M` below, the equations held exactly. The target is the
//! orientation asked for and the horizontal parts of the straight cables'
//! taut tension distribution there (`tension_distribution.rs`); the metric
//! weighs a radian of tilt as 1, of yaw as [`YAW_WEIGHT`] (level closure)
//! and a platform weight of horizontal tension as [`FORCE_WEIGHT`], so the
//! tilt is kept first and the tensions chosen among what remains.
//!
//! The solve first balances the platform from the target by Gauss-Newton
//! corrections (minimum-norm steps that balance the linearised equations,
//! in the metric, else in the unknowns' own units where the balance needs
//! a tilt the metric resists). It then moves along the equilibria towards
//! the target: a Newton step on the first-order conditions of
//! `min |x - t|_M` subject to `e(x) = 0` (sequential quadratic programming
//! with the Lagrangian's Hessian, Nocedal and Wright, *Numerical
//! Optimization*, 2nd ed., Sec. 18.1; its curvature term from second
//! differences), else the projected step
//! `dx = (t - x) - M^-1 J^T (J M^-1 J^T)^-1 (e + J (t - x))` (whose fixed
//! points are the same conditions), each halved until, balanced again, the
//! platform is nearer the target. Without the curvature term the
//! iteration converges only linearly where the metric is flat (the
//! tensions; the yaw of a regular ring, whose attachments face their
//! anchors), and stalled there; with it a few tens of iterations suffice.
//! The Jacobian `J = de/dx` is by central differences. The answer is a
//! nearest member (the problem is not convex: another start may find
//! another). Every answer is
//! an equilibrium: balanced to [`EquilibriumOptions::wrench_tolerance`],
//! the heights to rounding, every cable taut; where the iteration does not
//! get there it fails. Verified: the four-cable solver's equilibria
//! ([`crate::model::statics`]) at a held yaw; three to eight cables on an
//! irregular and on a regular ring; the first-order conditions at the answer.

use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3};

use super::robot::SuspendedRobot;
use super::tension_distribution::taut_tensions;
use crate::error::{Error, Result};
use crate::model::catenary::sinhc;
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;

/// How much a platform weight of force counts against a radian of rotation
/// in the closure's metric (module docs): small, so the orientation asked
/// for is held wherever the heights allow it.
pub const FORCE_WEIGHT: f64 = 1e-6;

/// Which member of the equilibria at a position (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Closure {
    /// The platform as level as the balance allows, its yaw where the cables
    /// put it (weighed [`YAW_WEIGHT`] against the tilt): the most level
    /// member for four cables, the one equilibrium of three.
    Level,
    /// The yaw held at `yaw_rad` and the platform as level as the balance
    /// allows (from six cables on, level to within what the tilt trades
    /// against the tensions at [`FORCE_WEIGHT`], where the yaw is one the
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
    /// Largest unbalanced force accepted, as a fraction of the platform's
    /// weight (moments: of its weight times its attachment radius).
    pub wrench_tolerance: f64,
}

impl Default for EquilibriumOptions {
    /// 100 iterations, 1e-9 of the platform's weight unbalanced (a
    /// micronewton on a kilonewton platform; rounding stops the iteration at
    /// about 1e-12 .. 1e-10).
    fn default() -> Self {
        Self {
            max_iterations: 100,
            wrench_tolerance: 1e-9,
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
    /// Gauss-Newton iterations used.
    pub iterations: usize,
}

impl SuspendedEquilibrium {
    /// The length each drum of `robot` pays out to hold this equilibrium:
    /// each cable's catenary length (paper eq. 4), less an elastic cable's
    /// stretch to first order in `1/EA` (Irvine's elastic catenary,
    /// `l (1 - T_top / EA)` with `T_top = |(f_h, f_v + g_c l)|`, as
    /// `generated::suspended_elastic_cable_residual` reads its encoder),
    /// metres. An inextensible cable's is its catenary length.
    pub fn paid_out_lengths_m(&self, robot: &SuspendedRobot) -> Vec<f64> {
        (0..self.cable_lengths_m.len())
            .map(|i| {
                let length = self.cable_lengths_m[i];
                let compliance_per_n = robot.axial_compliance_per_mn(i) * 1e-6;
                if compliance_per_n == 0.0 {
                    return length;
                }
                let t = &self.tensions[i];
                let top_n = t
                    .horizontal_n
                    .hypot(t.vertical_n + robot.cable_weights_n_per_m[i] * length);
                length * (1.0 - compliance_per_n * top_n)
            })
            .collect()
    }
}

/// The problem of one position: the unknowns' meaning, the target and the metric.
pub(super) struct Problem<'a> {
    robot: &'a SuspendedRobot,
    position_m: Vector3<f64>,
    /// The orientation the rotation unknowns turn from.
    base: UnitQuaternion<f64>,
    /// Rotation unknowns (2: roll and pitch about the base; 3: all).
    rotations: usize,
    /// The target `t` of the module docs.
    pub(super) target: DVector<f64>,
    /// The metric `M`'s diagonal.
    pub(super) metric: DVector<f64>,
}

/// The vertical tension at the attachment of a cable of weight
/// `weight_n_per_m` over `span_m` whose anchor is `height_difference_m`
/// above its attachment, at horizontal tension `horizontal_n` (paper eq. 1
/// at `x = span` inverted: `drop = span sinhc(lambda/2) sinh(A + lambda/2)`,
/// so `A = asinh(drop / (span sinhc(lambda/2))) - lambda/2` and
/// `f_v = f_h sinh A`, `lambda = g_c span / f_h`).
pub fn vertical_for_height(span_m: f64, height_difference_m: f64, horizontal_n: f64, weight_n_per_m: f64) -> f64 {
    let half = 0.5 * weight_n_per_m * span_m / horizontal_n;
    let a = (height_difference_m / (span_m * sinhc(half))).asinh() - half;
    horizontal_n * a.sinh()
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

    /// Every cable's forces at `x`: its horizontal tension from `x`, its
    /// vertical one the catenary's through its anchor and attachment;
    /// `None` where a cable is slack (`f_h <= 0`).
    fn tensions(&self, x: &DVector<f64>) -> Option<Vec<CableTension>> {
        let weight = self.robot.platform_weight_n;
        let runs = self.robot.runs(&self.pose(x));
        runs.iter()
            .zip(&self.robot.cable_weights_n_per_m)
            .enumerate()
            .map(|(i, (run, &cable_weight))| {
                let horizontal_n = x[self.rotations + i] * weight;
                (horizontal_n > 0.0).then(|| CableTension {
                    horizontal_n,
                    vertical_n: vertical_for_height(run.span_m, run.height_difference_m, horizontal_n, cable_weight),
                })
            })
            .collect()
    }

    /// The six equations of equilibrium at `x`, forces over the platform's
    /// weight and moments over its weight times the attachment radius.
    pub(super) fn equations(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
        let tensions = self.tensions(x)?;
        let residual = self.robot.wrench_residual(&self.pose(x), &tensions);
        let (weight, radius) = (self.robot.platform_weight_n, self.robot.attachment_radius_m());
        let e = DVector::from_fn(6, |r, _| residual[r] / if r < 3 { weight } else { weight * radius });
        e.iter().all(|v| v.is_finite()).then_some(e)
    }

    /// `de/dx` by central differences.
    pub(super) fn jacobian(&self, x: &DVector<f64>) -> Option<DMatrix<f64>> {
        let mut jacobian = DMatrix::zeros(6, x.len());
        for j in 0..x.len() {
            let step = 1e-7 * x[j].abs().max(1e-2);
            let (mut up, mut down) = (x.clone(), x.clone());
            up[j] += step;
            down[j] -= step;
            let column = (self.equations(&up)? - self.equations(&down)?) / (2.0 * step);
            jacobian.set_column(j, &column);
        }
        Some(jacobian)
    }
}

/// The equilibrium at `position_m` that `closure` picks (module docs).
///
/// Fails with [`Error::InvalidInput`] for a yaw with three cables or a
/// non-finite input, and with [`Error::NoEquilibrium`] where the iteration
/// meets a slack cable it cannot step around or does not balance the
/// platform to [`EquilibriumOptions::wrench_tolerance`].
pub fn solve_at(
    robot: &SuspendedRobot,
    position_m: Vector3<f64>,
    closure: Closure,
    options: &EquilibriumOptions,
) -> Result<SuspendedEquilibrium> {
    let problem = problem(robot, position_m, closure)?;
    let unsolved = |why: String| {
        Error::NoEquilibrium(format!(
            "position {:?} on {} cables: {why}",
            position_m.as_slice(),
            robot.cable_count()
        ))
    };
    let tolerance = options.wrench_tolerance;
    let start = problem.target.clone();
    let start_e = problem
        .equations(&start)
        .ok_or_else(|| unsolved("the straight cables' tensions leave a cable slack".into()))?;
    let mut budget = options.max_iterations;
    // Balanced first: from the target by corrections in the metric (which
    // keep the orientation asked for; 20 at most), else in the unknowns'
    // units (where the balance needs a tilt the metric resists).
    let mut metric_budget = budget.min(20);
    let (mut x, mut e) = problem
        .restore(start.clone(), start_e.clone(), tolerance, true, &mut metric_budget)
        .inspect(|_| budget -= budget.min(20) - metric_budget)
        .or_else(|_| problem.restore(start, start_e, tolerance, false, &mut budget))
        .map_err(|left| unsolved(format!("the balance stalled at {left:.3e} of the platform's weight")))?;
    let rank = || unsolved("the equations' Jacobian lost its rank".into());
    while budget > 0 {
        budget -= 1;
        let jacobian = problem
            .jacobian(&x)
            .ok_or_else(|| unsolved("a cable goes slack next to the current estimate".into()))?;
        let (dx, mu) = problem.step(&x, &e, &jacobian, true).ok_or_else(rank)?;
        let scale = x.amax().max(1.0);
        if dx.amax() <= 1e-10 * scale {
            break;
        }
        let newton = problem.newton_step(&x, &e, &jacobian, &mu);
        // Converged where the Newton step is below a millionth: the step
        // taken (quadratic convergence leaves about its square, below what
        // the difference Jacobian resolves) if it keeps the balance.
        if let Some(last) = newton.as_ref().filter(|step| step.amax() <= 1e-6 * scale) {
            let next = &x + last;
            if problem
                .equations(&next)
                .is_some_and(|next_e| next_e.amax() <= tolerance)
            {
                x = next;
            }
            break;
        }
        // The Newton step, else the projected step, halved until, balanced
        // again, the platform is nearer the target; where neither gets
        // nearer, the answer is as near as the iteration resolves.
        let here = problem.distance(&x);
        let nearer = newton.iter().chain([&dx]).find_map(|step| {
            let mut fraction = 1.0;
            while fraction >= 1e-6 {
                let trial = &x + step * fraction;
                let mut trial_budget = 8;
                let balanced = problem
                    .equations(&trial)
                    .and_then(|trial_e| problem.restore(trial, trial_e, tolerance, true, &mut trial_budget).ok());
                if let Some((trial, trial_e)) = balanced.filter(|(trial, _)| problem.distance(trial) < here) {
                    return Some((trial, trial_e));
                }
                fraction *= 0.5;
            }
            None
        });
        match nearer {
            Some(next) => (x, e) = next,
            None => break,
        }
    }
    if budget == 0 {
        return Err(unsolved(format!(
            "{} iterations did not settle on the nearest equilibrium",
            options.max_iterations
        )));
    }
    Ok(finish(&problem, &x, options.max_iterations - budget))
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
    let n = robot.cable_count();
    let straight = straight_cable_forces(robot, &PlatformPose::new(position_m, base));
    let mut target = DVector::zeros(rotations + n);
    let mut metric = DVector::from_element(target.len(), FORCE_WEIGHT);
    metric.rows_mut(0, rotations).fill(1.0);
    if rotations == 3 {
        metric[2] = YAW_WEIGHT;
    }
    for i in 0..n {
        target[rotations + i] = straight[2 * i] / robot.platform_weight_n;
    }
    Ok(Problem {
        robot,
        position_m,
        base,
        rotations,
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

fn finish(problem: &Problem<'_>, x: &DVector<f64>, iterations: usize) -> SuspendedEquilibrium {
    let pose = problem.pose(x);
    let tensions = problem.tensions(x).expect("the last accepted estimate is taut");
    let cables = problem.robot.catenaries(&pose, &tensions);
    SuspendedEquilibrium {
        cable_lengths_m: cables.iter().map(|c| c.length_m()).collect(),
        height_residuals_m: problem.robot.height_residuals(&pose, &tensions),
        pose,
        tensions,
        iterations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::robot::Robot;
    use crate::model::statics::{solve_level, StaticsOptions};

    /// The irregular ring of the tests, attachments 0.2 m up, the centre of
    /// mass off the platform's axis.
    fn ring(n: usize) -> SuspendedRobot {
        super::super::test_ring::ring(n, 0.2, Vector3::new(0.05, -0.03, -0.1))
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

    /// From six cables on the platform hangs level to a hundredth of a
    /// degree (the tensions take up what the balance leaves; the tilt left
    /// trades against their distance from the target at [`FORCE_WEIGHT`]);
    /// with three to five it tilts as it must.
    #[test]
    fn three_to_eight_cables_hang_in_equilibrium() {
        for n in 3..=8 {
            let robot = ring(n);
            for position in [Vector3::new(2.0, 1.0, 6.0), Vector3::new(-3.0, 2.0, 7.0)] {
                let eq = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default()).unwrap();
                assert_equilibrium(&robot, &eq);
                println!(
                    "{n} cables at {position:?}: tilt {:.3e} deg, yaw {:.3e} deg, {} iterations",
                    tilt_deg(&eq.pose),
                    eq.pose.yaw_rad().to_degrees(),
                    eq.iterations
                );
                if n >= 6 {
                    assert!(tilt_deg(&eq.pose) < 1e-2, "{n} cables tilt {} deg", tilt_deg(&eq.pose));
                }
            }
        }
    }

    /// On regular rings (three to eight cables, attachments facing their
    /// anchors, so the yaw and the tensions are the flattest directions of
    /// the closure's metric) the level closure converges in 3 to 26 iterations.
    /// (A held yaw is degenerate there: away from the level closure's yaw
    /// every cable twists the platform the same way and nothing balances the
    /// moment; at it, the moment about the vertical vanishes for any
    /// tensions, so four cables have a family of equilibria, not one.)
    #[test]
    fn regular_rings_converge() {
        for n in 3..=8 {
            let robot = super::super::test_ring::regular_ring(n);
            for position in [
                Vector3::new(1.0, -0.5, 6.0),
                Vector3::new(-4.0, 3.0, 9.0),
                Vector3::new(0.0, 0.0, 5.0),
            ] {
                let level = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default())
                    .unwrap_or_else(|e| panic!("{n} cables at {position:?}: {e}"));
                assert_equilibrium(&robot, &level);
                assert!(level.iterations <= 40, "{} iterations", level.iterations);
                println!(
                    "regular {n} cables at {position:?}: tilt {:.3e} deg, yaw {:.3e} deg, {} iterations",
                    tilt_deg(&level.pose),
                    level.pose.yaw_rad().to_degrees(),
                    level.iterations
                );
            }
        }
    }

    /// The closure's answer is the member nearest its target: at the
    /// solution the metric-weighted offset from the target lies in the span
    /// of the equations' gradients (the first-order conditions), for four
    /// cables (one free direction) and eight (five).
    #[test]
    fn the_level_equilibrium_is_the_nearest_to_its_target() {
        let large = SuspendedRobot::from_robot(&Robot::builtin("large").unwrap());
        for (robot, position) in [
            (large, Vector3::new(-20.0, 30.0, 15.0)),
            (ring(8), Vector3::new(-3.0, 2.0, 7.0)),
        ] {
            let eq = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default()).unwrap();
            let problem = problem(&robot, position, Closure::Level).unwrap();
            let mut x = DVector::zeros(problem.target.len());
            let (roll, pitch, yaw) = eq.pose.rotation.euler_angles();
            (x[0], x[1], x[2]) = (roll, pitch, yaw);
            for (i, t) in eq.tensions.iter().enumerate() {
                x[3 + i] = t.horizontal_n / robot.platform_weight_n;
            }
            let jacobian = problem.jacobian(&x).unwrap();
            let gradient = (&x - &problem.target).component_mul(&problem.metric);
            // Least squares of J^T lambda = gradient: the remainder is what no equation can explain.
            let lambda = jacobian.transpose().svd(true, true).solve(&gradient, 1e-14).unwrap();
            let remainder = &gradient - jacobian.transpose() * lambda;
            println!(
                "{} cables: first-order remainder {:.3e} of a gradient {:.3e}",
                robot.cable_count(),
                remainder.amax(),
                gradient.amax()
            );
            assert!(gradient.amax() > 0.0, "the target itself is no equilibrium here");
            assert!(remainder.amax() < 1e-6 * gradient.amax(), "{remainder} of {gradient}");
        }
    }

    /// The closed-form vertical tension puts the catenary's end at the
    /// attachment (the forward drop of `model::catenary`), light to heavy.
    #[test]
    fn the_vertical_tension_reaches_the_attachment() {
        for (span, drop, horizontal, weight) in [
            (30.0, 12.0, 400.0, 0.0),
            (30.0, 12.0, 400.0, 0.71),
            (120.0, -5.0, 150.0, 6.0),
        ] {
            let vertical_n = vertical_for_height(span, drop, horizontal, weight);
            let cable = crate::model::Catenary {
                span_m: span,
                horizontal_tension_n: horizontal,
                vertical_tension_n: vertical_n,
                cable_weight_n_per_m: weight,
            };
            assert!(
                (cable.drop_m() - drop).abs() < 1e-12 * span,
                "{} vs {drop}",
                cable.drop_m()
            );
        }
    }
}

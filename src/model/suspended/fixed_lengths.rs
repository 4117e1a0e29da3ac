//! The equilibrium of a platform on `N` cables of given lengths
//! ([`equilibrium_at_lengths`]): what localisation solves from the
//! encoders' readings (paper Sec. IV: each encoder reads its catenary's
//! length plus its offset, eq. 14).
//!
//! With every cable's length held, the pose is the unknown: at a pose each
//! cable's end forces follow from its arc length (eq. 4) and end height
//! (eq. 15), and the platform is in equilibrium where the generalised force
//! `Q` of the stiffness (`stiffness.rs`) vanishes: six equations in the six
//! coordinates of the pose. Newton's step is `xi = K^-1 Q` with `K` the
//! stiffness at fixed lengths (`K = -dQ/dxi`), halved until `|Q|` falls;
//! at a stable equilibrium `K` is positive definite, so the iteration
//! converges from a start near it. Where a cable cannot reach the start
//! (its length shorter than the distance between its ends: taut cables
//! have centimetres to spare), every cable is first paid out until each
//! reaches it with a percent to spare, the platform found hanging there,
//! and the cables reeled back in, a tenth of the payout at a time (halved
//! where a cable would not reach), each equilibrium the start of the next:
//! a continuation along the robot's own motion. It fails where the robot,
//! paid out, finds no stable way back: the eight-cable robot, whose short
//! cables pulled by a kilonewton have tens of micrometres of slack, from
//! any start 2 cm away (`tests/localize.rs`).

use nalgebra::Vector6;

use super::equilibrium::{solve_at, Closure, EquilibriumOptions, SuspendedEquilibrium};
use super::robot::SuspendedRobot;
use super::stiffness::{generalised_force, stiffness};
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;

/// Most Newton iterations of [`equilibrium_at_lengths`].
const MAX_ITERATIONS: usize = 50;

/// The equilibrium of `robot` with its cables `cable_lengths_m` long (the
/// catenaries' arc lengths, in cable order), by Newton from `start` (module
/// docs). The cables' forces start from the level equilibrium at the
/// start's position. `iterations` counts every Newton step. Fails with [`Error::NoEquilibrium`] where a cable has
/// no taut shape of its length along the way, or the iteration does not
/// balance the platform to `1e-9` of its weight; with
/// [`Error::InvalidInput`] for a wrong number of lengths, a length that is
/// not positive, or massless cables (whose lengths do not fix their forces).
pub fn equilibrium_at_lengths(
    robot: &SuspendedRobot,
    cable_lengths_m: &[f64],
    start: &PlatformPose,
) -> Result<SuspendedEquilibrium> {
    let n = robot.cable_count();
    if cable_lengths_m.len() != n || !cable_lengths_m.iter().all(|l| l.is_finite() && *l > 0.0) {
        return Err(Error::InvalidInput(format!(
            "{n} positive cable lengths are needed, got {cable_lengths_m:?}"
        )));
    }
    if robot.cable_weights_n_per_m.iter().any(|w| *w <= 0.0) {
        return Err(Error::InvalidInput(
            "a massless cable's length does not fix its forces: every cable needs a weight per metre".into(),
        ));
    }
    let unsolved = |why: String| Error::NoEquilibrium(format!("cable lengths {cable_lengths_m:?}: {why}"));
    let level = solve_at(robot, start.position_m, Closure::Level, &EquilibriumOptions::default())?;
    let mut iterate = SuspendedEquilibrium { pose: *start, ..level };
    // Where a cable cannot reach the start, paid out by `payout` (every
    // cable's length times 1 + payout) until each reaches it with a percent
    // of its length to spare, then reeled in, each
    // equilibrium the start of the next: a tenth of the payout at a time,
    // halved where a cable would not reach the last pose and doubled again
    // after a success (module docs).
    let reach = robot
        .runs(start)
        .iter()
        .zip(cable_lengths_m)
        .map(|(run, length)| run.span_m.hypot(run.height_difference_m) / length)
        .fold(0.0f64, f64::max);
    let payout = if reach < 1.0 { 0.0 } else { reach - 1.0 + 0.01 };
    let at = |stretch: f64| cable_lengths_m.iter().map(|l| l * (1.0 + stretch)).collect::<Vec<_>>();
    iterate.cable_lengths_m = at(payout);
    iterate = newton(robot, iterate).map_err(unsolved)?;
    let (mut stretch, mut step, mut total_iterations) = (payout, 0.1 * payout, iterate.iterations);
    while stretch > 0.0 {
        let next = (stretch - step).max(0.0);
        let trial = SuspendedEquilibrium {
            cable_lengths_m: at(next),
            ..iterate.clone()
        };
        match newton(robot, trial) {
            Ok(found) => {
                total_iterations += found.iterations;
                (iterate, stretch, step) = (found, next, (2.0 * step).min(0.1 * payout));
            }
            Err(why) if step < 1e-6 * payout => return Err(unsolved(why)),
            Err(_) => step *= 0.5,
        }
    }
    iterate.iterations = total_iterations;
    Ok(iterate)
}

/// Newton's iteration of the module docs from `iterate` (its pose, its
/// forces as the starts, its lengths held); the reason where it fails.
fn newton(
    robot: &SuspendedRobot,
    mut iterate: SuspendedEquilibrium,
) -> std::result::Result<SuspendedEquilibrium, String> {
    let balance = |eq: &SuspendedEquilibrium| generalised_force(robot, eq, &Vector6::zeros());
    let mut q = balance(&iterate).ok_or("a cable has no taut shape of its length at the start")?;
    let tolerance = 1e-9 * robot.platform_weight_n;
    for iteration in 0..MAX_ITERATIONS {
        iterate.tensions =
            super::stiffness::forces_at_pose(robot, &iterate).ok_or("a cable has no taut shape of its length")?;
        if q.amax() <= tolerance {
            iterate.iterations = iteration;
            iterate.height_residuals_m = robot.height_residuals(&iterate.pose, &iterate.tensions);
            return Ok(iterate);
        }
        let k = stiffness(robot, &iterate).ok_or("the stiffness is undefined")?;
        let step = k.lu().solve(&q).ok_or("the stiffness is singular")?;
        let mut scale = 1.0;
        loop {
            let moved = SuspendedEquilibrium {
                pose: iterate.pose.retract(&(step * scale)),
                ..iterate.clone()
            };
            if let Some(next) = balance(&moved).filter(|next| next.amax() < q.amax()) {
                (iterate, q) = (moved, next);
                break;
            }
            scale *= 0.5;
            if scale < 1e-6 {
                return Err(format!("the balance stalled at {:.3e} N", q.amax()));
            }
        }
    }
    Err(format!(
        "{MAX_ITERATIONS} Newton iterations left {:.3e} N unbalanced",
        q.amax()
    ))
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;

    /// The lengths of an equilibrium hold that equilibrium: from a start
    /// 0.4 m and a few degrees away, the pose comes back to 1e-9 m and
    /// 1e-9 rad, on the irregular ring wherever the level closure lets every
    /// cable rise (four of these positions: three and four cables; five to
    /// eight cables on the built-in robots' drawn poses in `tests/localize.rs`).
    #[test]
    fn the_lengths_of_an_equilibrium_give_it_back() {
        let mut total = 0;
        for n in 3..=8 {
            let robot = super::super::test_ring::ring(n, 0.2, Vector3::new(0.05, -0.03, -0.1));
            let mut solved = 0;
            for position in [
                Vector3::new(2.0, 1.0, 6.0),
                Vector3::new(-3.0, 2.0, 7.0),
                Vector3::new(0.5, -1.0, 5.0),
            ] {
                let truth = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default()).unwrap();
                // Only the equilibria a robot is driven to: every cable rising from the
                // platform (the level closure may pick one that sags kilometres below it).
                if truth.tensions.iter().any(|t| t.vertical_n <= 0.0) {
                    continue;
                }
                solved += 1;
                let start = truth.pose.retract(&Vector6::new(0.03, -0.04, 0.05, 0.25, -0.2, 0.22));
                let found = equilibrium_at_lengths(&robot, &truth.cable_lengths_m, &start).unwrap();
                let (moved_m, turned_rad) = (
                    (found.pose.position_m - truth.pose.position_m).norm(),
                    found.pose.rotation.angle_to(&truth.pose.rotation),
                );
                println!(
                    "{n} cables at {position:?}: {moved_m:.2e} m, {turned_rad:.2e} rad in {} iterations",
                    found.iterations
                );
                assert!(
                    moved_m < 1e-9 && turned_rad < 1e-9,
                    "{n} cables: {moved_m} m, {turned_rad} rad"
                );
                for (t, u) in found.tensions.iter().zip(&truth.tensions) {
                    assert!((t.magnitude_n() - u.magnitude_n()).abs() < 1e-6 * robot.platform_weight_n);
                }
            }
            total += solved;
        }
        assert!(total >= 4, "{total} equilibria with every cable rising");
    }

    #[test]
    fn wrong_lengths_are_refused() {
        let robot = super::super::test_ring::ring(5, 0.2, Vector3::new(0.0, 0.0, -0.5));
        let start = PlatformPose::from_position(Vector3::new(0.0, 0.0, 6.0));
        for lengths in [
            vec![20.0; 4],
            vec![20.0, 20.0, 20.0, 20.0, -1.0],
            vec![20.0, 20.0, f64::NAN, 20.0, 20.0],
        ] {
            let refused = equilibrium_at_lengths(&robot, &lengths, &start);
            assert!(
                matches!(refused, Err(Error::InvalidInput(_))),
                "{lengths:?}: {refused:?}"
            );
        }
    }
}

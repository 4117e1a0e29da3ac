//! Stability of an equilibrium on `N` cables ([`stiffness`]): the
//! platform's stiffness at fixed cable lengths.
//!
//! Hold every cable's length and move the platform by a tangent
//! `xi = [dtheta, dp]` ([`PlatformPose::retract`]): each cable's end forces
//! then follow from its own two equations, its arc length (paper eq. 4) and
//! its end height (eq. 15), solved for `(f_h, f_v)` in closed form up to
//! one monotone root ([`forces_at_length`]). The generalised force conjugate to `xi` is
//! `Q = [R^T tau; F]` with `[F; tau] = J^T f - w` (eq. 5-8: the cables'
//! pull and the weight), and the stiffness is `K = -dQ/dxi`, here by
//! central differences of the whole `Q`. The equilibrium is stable when the
//! symmetric part of `K` is positive definite (the Hessian of the potential
//! energy at fixed lengths, symmetric at an equilibrium up to the
//! differences). The four-cable test of `localize/stiffness.rs` takes the
//! derivatives in parts and handles massless cables; this one needs every
//! cable to weigh something (a massless cable of fixed length is a rigid
//! constraint, not a spring) and refuses otherwise.

use nalgebra::{Matrix6, Vector6};

use super::equilibrium::SuspendedEquilibrium;
use super::robot::SuspendedRobot;
use crate::model::catenary::sinhc;
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;

/// Step of the central differences of `Q`, radians and metres.
const STEP: f64 = 1e-6;

/// The end forces of a cable of `length_m` and weight `weight_n_per_m`
/// over `span_m` with its anchor `height_difference_m` above its end
/// (eq. 4 and eq. 15); `None` where the cable is no longer than the
/// distance between its ends.
///
/// Eq. (4) and eq. (15) in the forms of `model::catenary`,
/// `l = L sinhc(x) cosh(A + x)` and `d = L sinhc(x) sinh(A + x)` with
/// `x = g_c L / (2 f_h)`, give `sqrt(l^2 - d^2) = L sinhc(x)` (the
/// inextensible cable of Irvine, *Cable Structures*, 1981, Sec. 2.3):
/// `sinhc` increases from 1, so `x` is its one root above zero (bracketed,
/// then safeguarded Newton), `f_h = g_c L / (2 x)`, and `f_v` follows from
/// the height ([`super::vertical_for_height`]).
pub(super) fn forces_at_length(
    span_m: f64,
    height_difference_m: f64,
    length_m: f64,
    weight_n_per_m: f64,
) -> Option<CableTension> {
    let ratio = (length_m * length_m - height_difference_m * height_difference_m)
        .max(0.0)
        .sqrt()
        / span_m;
    if !(ratio > 1.0 && ratio.is_finite() && weight_n_per_m > 0.0) {
        return None;
    }
    // sinhc(x) = ratio: bracket, then Newton kept inside the bracket.
    let (mut low, mut high) = (0.0f64, 1.0f64);
    while sinhc(high) < ratio {
        (low, high) = (high, 2.0 * high);
        if high > 1e3 {
            return None;
        }
    }
    let mut x = (6.0 * (ratio - 1.0)).sqrt().clamp(low, high);
    for _ in 0..200 {
        let value = sinhc(x) - ratio;
        if value > 0.0 {
            high = x;
        } else {
            low = x;
        }
        // d sinhc / dx = (cosh x - sinhc x) / x, about x / 3 near zero.
        let slope = if x < 1e-3 { x / 3.0 } else { (x.cosh() - sinhc(x)) / x };
        let newton = x - value / slope;
        let next = if newton > low && newton < high {
            newton
        } else {
            0.5 * (low + high)
        };
        if (next - x).abs() <= 1e-15 * x {
            x = next;
            break;
        }
        x = next;
    }
    let horizontal_n = weight_n_per_m * span_m / (2.0 * x);
    Some(CableTension {
        horizontal_n,
        vertical_n: super::vertical_for_height(span_m, height_difference_m, horizontal_n, weight_n_per_m),
    })
}

/// Every cable's end forces at `pose` with the lengths of `eq`; `None`
/// where one has no shape of its length.
fn forces_at(robot: &SuspendedRobot, eq: &SuspendedEquilibrium, pose: &PlatformPose) -> Option<Vec<CableTension>> {
    robot
        .runs(pose)
        .iter()
        .enumerate()
        .map(|(i, run)| {
            forces_at_length(
                run.span_m,
                run.height_difference_m,
                eq.cable_lengths_m[i],
                robot.cable_weights_n_per_m[i],
            )
        })
        .collect()
}

/// The forces that hold `eq`'s cable lengths at `eq`'s own pose.
pub(super) fn forces_at_pose(robot: &SuspendedRobot, eq: &SuspendedEquilibrium) -> Option<Vec<CableTension>> {
    forces_at(robot, eq, &eq.pose)
}

/// `Q(xi)` of the module docs at `eq` moved by `xi`, the cable lengths held.
pub(super) fn generalised_force(
    robot: &SuspendedRobot,
    eq: &SuspendedEquilibrium,
    xi: &Vector6<f64>,
) -> Option<Vector6<f64>> {
    let pose: PlatformPose = eq.pose.retract(xi);
    let tensions = forces_at(robot, eq, &pose)?;
    let wrench = robot.wrench_residual(&pose, &tensions);
    let moment = pose.rotation.inverse() * wrench.fixed_rows::<3>(3).into_owned();
    Some(Vector6::new(
        moment.x, moment.y, moment.z, wrench[0], wrench[1], wrench[2],
    ))
}

/// The stiffness `K = -dQ/dxi` at the equilibrium `eq` of `robot` (module
/// docs); `None` for a cable without weight or where a moved cable has no
/// taut shape of its length.
pub fn stiffness(robot: &SuspendedRobot, eq: &SuspendedEquilibrium) -> Option<Matrix6<f64>> {
    if robot.cable_weights_n_per_m.iter().any(|w| *w <= 0.0) {
        return None;
    }
    let mut k = Matrix6::zeros();
    for j in 0..6 {
        let mut xi = Vector6::zeros();
        xi[j] = STEP;
        let up = generalised_force(robot, eq, &xi)?;
        let down = generalised_force(robot, eq, &(-xi))?;
        k.set_column(j, &(-(up - down) / (2.0 * STEP)));
    }
    Some(k)
}

/// The smallest eigenvalue of `K`'s symmetric part: positive for a stable
/// equilibrium.
pub fn smallest_stiffness(k: &Matrix6<f64>) -> f64 {
    (0.5 * (k + k.transpose())).symmetric_eigenvalues().min()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::suspended::{solve_at, Closure, EquilibriumOptions};
    use nalgebra::Vector3;

    /// The irregular ring of the tests with its centre of mass `com_z_m`
    /// above the attachments' plane.
    fn ring(n: usize, com_z_m: f64) -> SuspendedRobot {
        super::super::test_ring::ring(n, 0.0, Vector3::new(0.0, 0.0, com_z_m))
    }

    /// A platform hanging below its attachments is stable on three to eight
    /// cables, and its stiffness is symmetric (a Hessian).
    #[test]
    fn a_hanging_platform_is_stable() {
        for n in 3..=8 {
            let robot = ring(n, -1.0);
            let eq = solve_at(
                &robot,
                Vector3::new(1.0, -0.5, 6.0),
                Closure::Level,
                &EquilibriumOptions::default(),
            )
            .unwrap();
            let k = stiffness(&robot, &eq).unwrap();
            let asymmetry = (k - k.transpose()).amax() / k.amax();
            println!(
                "{n} cables: smallest stiffness {:.4e}, asymmetry {asymmetry:.1e}",
                smallest_stiffness(&k)
            );
            assert!(asymmetry < 1e-4, "{n} cables: asymmetry {asymmetry:e}\n{k}");
            assert!(smallest_stiffness(&k) > 0.0, "{n} cables\n{k}");
        }
    }

    /// A platform whose centre of mass sits high above its attachments
    /// tips over: the level equilibrium at the centre is unstable.
    #[test]
    fn a_top_heavy_platform_is_unstable() {
        let robot = ring(4, 5.0);
        let eq = solve_at(
            &robot,
            Vector3::new(0.0, 0.0, 6.0),
            Closure::Level,
            &EquilibriumOptions::default(),
        )
        .unwrap();
        let k = stiffness(&robot, &eq).unwrap();
        assert!(smallest_stiffness(&k) < 0.0, "{k}");
    }

    /// The forces at a length invert the catenary: light to heavy, nearly
    /// straight to deeply sagging, a cable that rises and one that falls to
    /// its end; a cable no longer than its chord has none.
    #[test]
    fn the_forces_at_a_length_invert_the_catenary() {
        for (span_m, horizontal_n, vertical_n, weight) in [
            (40.0, 300.0, 180.0, 2.0),
            (250.0, 20000.0, 900.0, 0.71),
            (12.0, 5.0, 2.0, 3.0),
            (30.0, 400.0, -50.0, 1.0),
        ] {
            let cable = crate::model::Catenary {
                span_m,
                horizontal_tension_n: horizontal_n,
                vertical_tension_n: vertical_n,
                cable_weight_n_per_m: weight,
            };
            let f = forces_at_length(span_m, cable.drop_m(), cable.length_m(), weight).unwrap();
            let error = (f.horizontal_n - horizontal_n)
                .abs()
                .max((f.vertical_n - vertical_n).abs());
            assert!(
                error < 1e-8 * horizontal_n.hypot(vertical_n),
                "{f:?} for {horizontal_n}, {vertical_n}"
            );
        }
        assert!(
            forces_at_length(30.0, 40.0, 50.0, 1.0).is_none(),
            "a 3-4-5 chord of 50 m"
        );
    }
}

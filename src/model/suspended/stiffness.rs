//! Stability of an equilibrium on `N` cables ([`stiffness`]): the
//! platform's stiffness at fixed cable lengths.
//!
//! Hold every cable's length and move the platform by a tangent
//! `xi = [dtheta, dp]` ([`PlatformPose::retract`]): each cable's end forces
//! then follow from its own two equations, its arc length (paper eq. 4) and
//! its end height (eq. 15), solved for `(f_h, f_v)` by Newton from the
//! equilibrium's. The generalised force conjugate to `xi` is
//! `Q = [R^T tau; F]` with `[F; tau] = J^T f - w` (eq. 5-8: the cables'
//! pull and the weight), and the stiffness is `K = -dQ/dxi`, here by
//! central differences of the whole `Q`. The equilibrium is stable when the
//! symmetric part of `K` is positive definite (the Hessian of the potential
//! energy at fixed lengths, symmetric at an equilibrium up to the
//! differences). The four-cable test of `localize/stiffness.rs` takes the
//! derivatives in parts and handles massless cables; this one needs every
//! cable to weigh something (a massless cable of fixed length is a rigid
//! constraint, not a spring) and refuses otherwise.

use nalgebra::{Matrix2, Matrix6, Vector2, Vector6};

use super::equilibrium::SuspendedEquilibrium;
use super::robot::SuspendedRobot;
use crate::model::catenary::Catenary;
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;

/// Step of the central differences of `Q`, radians and metres.
const STEP: f64 = 1e-6;

/// The end forces of a cable of `length_m` and weight `weight_n_per_m`
/// over `span_m` with its anchor `height_difference_m` above its end
/// (eq. 4 and eq. 15), by Newton from `start`; `None` where it does not
/// converge to a taut cable.
fn forces_at_length(
    span_m: f64,
    height_difference_m: f64,
    length_m: f64,
    weight_n_per_m: f64,
    start: CableTension,
) -> Option<CableTension> {
    let residual = |f: &Vector2<f64>| {
        let cable = Catenary {
            span_m,
            horizontal_tension_n: f[0],
            vertical_tension_n: f[1],
            cable_weight_n_per_m: weight_n_per_m,
        };
        Vector2::new(cable.length_m() - length_m, cable.drop_m() - height_difference_m)
    };
    let mut f = Vector2::new(start.horizontal_n, start.vertical_n);
    let scale = f.norm().max(1.0);
    for _ in 0..50 {
        let r = residual(&f);
        if r.amax() < 1e-12 * length_m.max(1.0) {
            return (f[0] > 0.0).then_some(CableTension {
                horizontal_n: f[0],
                vertical_n: f[1],
            });
        }
        let h = 1e-7 * scale;
        let jacobian = Matrix2::from_columns(&[
            (residual(&(f + Vector2::new(h, 0.0))) - residual(&(f - Vector2::new(h, 0.0)))) / (2.0 * h),
            (residual(&(f + Vector2::new(0.0, h))) - residual(&(f - Vector2::new(0.0, h)))) / (2.0 * h),
        ]);
        let step = jacobian.lu().solve(&(-r))?;
        // Keep the horizontal tension positive: halve a step that would not.
        let mut t = 1.0;
        while f[0] + t * step[0] <= 0.0 && t > 1e-6 {
            t *= 0.5;
        }
        f += step * t;
    }
    None
}

/// `Q(xi)` of the module docs at `eq` moved by `xi`, the cable lengths held.
fn generalised_force(robot: &SuspendedRobot, eq: &SuspendedEquilibrium, xi: &Vector6<f64>) -> Option<Vector6<f64>> {
    let pose: PlatformPose = eq.pose.retract(xi);
    let runs = robot.runs(&pose);
    let tensions = runs
        .iter()
        .enumerate()
        .map(|(i, run)| {
            forces_at_length(
                run.span_m,
                run.height_difference_m,
                eq.cable_lengths_m[i],
                robot.cable_weights_n_per_m[i],
                eq.tensions[i],
            )
        })
        .collect::<Option<Vec<_>>>()?;
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

    /// A cable of fixed length moved and moved back has its forces again.
    #[test]
    fn the_forces_at_a_length_invert_the_catenary() {
        let cable = Catenary {
            span_m: 40.0,
            horizontal_tension_n: 300.0,
            vertical_tension_n: 180.0,
            cable_weight_n_per_m: 2.0,
        };
        let start = CableTension {
            horizontal_n: 250.0,
            vertical_n: 150.0,
        };
        let f = forces_at_length(40.0, cable.drop_m(), cable.length_m(), 2.0, start).unwrap();
        assert!(
            (f.horizontal_n - 300.0).abs() < 1e-8 && (f.vertical_n - 180.0).abs() < 1e-8,
            "{f:?}"
        );
    }
}

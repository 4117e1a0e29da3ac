//! Stability of an equilibrium: the platform's stiffness at fixed cable lengths.
//!
//! Hold every cable's paid-out length and move the platform by a tangent
//! `xi = [dtheta, dp]`: each cable's end tensions then follow from its two
//! equations alone (paid-out length fixed, eq. 4; end height, eq. 15), so
//! `d f_i / d xi = -(d[paid, drop]/d[f_h, f_v])^-1 d[paid, drop - h]/d xi`.
//! The generalised force on the platform conjugate to `xi` is
//! `Q = [R^T tau; F]` with `[F; tau] = J^T(pose) f - w(pose)` (eq. 5-8: the
//! cables' pull and the weight), and the stiffness is `K = -dQ/dxi`. The
//! equilibrium is stable when `K`'s symmetric part is positive definite (the
//! Hessian of the potential energy at fixed cable lengths; `K` itself is
//! symmetric at an equilibrium up to the finite differences taken of `J^T`
//! and `w` at fixed tensions).
//!
//! A massless cable (`g_c = 0`, the straight-line limit) fixes `paid` and
//! `drop` through the ratio `f_v / f_h` alone: `d[paid, drop]/d[f_h, f_v]`
//! is singular and the cable is rigid, an inextensible constraint `c_i xi =
//! 0` (`c_i = u_2^T [d paid; d drop - dh]/dxi`, `u_2` its left singular
//! vector of the zero singular value) whose tension is a Lagrange
//! multiplier. A nearly massless one is the same up to a stiffness along
//! `c_i` that grows as `1/g_c`. For those cables the stability test is the
//! limit's: the symmetric part of the finite stiffness restricted to the
//! motions that keep the rigid cables' lengths must be positive definite
//! (the second-order condition of the constrained energy; the cables taut,
//! `f_h > 0`, as every solved model is).
//!
//! ```
//! use nalgebra::{Matrix6, Vector2, Vector3};
//! use sagcal::localize::stiffness::{smallest_stiffness, stiffness};
//! use sagcal::localize::{model_at_pose, SlotRobot};
//! use sagcal::model::statics::{solve_level, StaticsOptions};
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! let eq = solve_level(&robot, Vector3::new(3.0, 2.0, 12.0), &StaticsOptions::default())?;
//! let slots = SlotRobot::new(&robot);
//! let reference = eq.tensions[robot.reference_cable];
//! let model = model_at_pose(&slots, &eq.pose, &Vector2::new(reference.horizontal_n, reference.vertical_n)).unwrap();
//! let k = stiffness(&robot, &slots, &eq.pose, &model);
//! // A Hessian of the potential energy: symmetric at an equilibrium (up to the finite differences),
//! // and positive definite where the platform hangs stably.
//! assert!((k - k.transpose()).norm() < 1e-4 * k.norm());
//! assert!(smallest_stiffness(&k) > 0.0);
//! // The smallest eigenvalue of the symmetric part, closed form: [[2, 1], [1, 2]] has 1.
//! let mut two = Matrix6::identity() * 5.0;
//! two.fixed_view_mut::<2, 2>(0, 0).copy_from(&nalgebra::Matrix2::new(2.0, 0.0, 2.0, 2.0));
//! assert!((smallest_stiffness(&two) - 1.0).abs() < 1e-12);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{Matrix6, RowSVector, SMatrix, Vector3, Vector6};

use super::equations::{ModelAtPose, SlotRobot};
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{gravity_wrench, structure_matrix};

/// Step of the finite differences of `J^T` and `w` at fixed tensions.
const STEP: f64 = 1e-6;

/// `Q = [R^T tau; F]` at `pose` with tensions `f` (robot order, `(f_h, f_v)` per cable).
fn generalised_force(robot: &Robot, pose: &PlatformPose, f: &SMatrix<f64, 8, 1>) -> Vector6<f64> {
    let wrench = structure_matrix(robot, pose) * f - gravity_wrench(robot, pose);
    let torque = pose.rotation.inverse() * Vector3::new(wrench[3], wrench[4], wrench[5]);
    Vector6::new(torque.x, torque.y, torque.z, wrench[0], wrench[1], wrench[2])
}

/// The stiffness `K = -dQ/dxi` at fixed cable lengths (module docs); `robot`
/// is the calibrated robot with the `[effects]` centre of mass.
pub fn stiffness(robot: &Robot, slots: &SlotRobot, pose: &PlatformPose, model: &ModelAtPose) -> Matrix6<f64> {
    let mut f = SMatrix::<f64, 8, 1>::zeros();
    for (slot, &cable) in slots.cables.iter().enumerate() {
        f[2 * cable] = model.tensions_n[slot][0];
        f[2 * cable + 1] = model.tensions_n[slot][1];
    }
    // At fixed tensions: central differences of J^T f - w.
    let mut d_q = Matrix6::<f64>::zeros();
    for k in 0..6 {
        let mut xi = Vector6::zeros();
        xi[k] = STEP;
        let plus = generalised_force(robot, &pose.retract(&xi), &f);
        let minus = generalised_force(robot, &pose.retract(&-xi), &f);
        d_q.set_column(k, &((plus - minus) / (2.0 * STEP)));
    }
    // Through the tensions: dQ/df df/dxi, each cable on its own.
    let jt = structure_matrix(robot, pose);
    let inverse_rotation = pose.rotation.inverse().to_rotation_matrix();
    let mut d_q_d_f = SMatrix::<f64, 6, 8>::zeros();
    for c in 0..8 {
        let column = jt.column(c);
        let torque = inverse_rotation * Vector3::new(column[3], column[4], column[5]);
        d_q_d_f.set_column(
            c,
            &Vector6::new(torque.x, torque.y, torque.z, column[0], column[1], column[2]),
        );
    }
    let mut d_f = SMatrix::<f64, 8, 6>::zeros();
    let mut rigid = [None; CABLE_COUNT];
    for (slot, &cable) in slots.cables.iter().enumerate().take(CABLE_COUNT) {
        let partials = &model.cables[slot];
        let mut b = SMatrix::<f64, 2, 6>::zeros();
        b.set_row(0, &(partials.span_pose * partials.d_span[0]));
        b.set_row(1, &(partials.span_pose * partials.d_span[1] - partials.height_pose));
        let svd = partials.d_tension.svd(true, true);
        let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
            return Matrix6::from_element(f64::NAN);
        };
        // Singular values in decreasing order.
        let (s1, s2) = (svd.singular_values[0], svd.singular_values[1]);
        if !(s1 > 0.0 && s1.is_finite()) {
            return Matrix6::from_element(f64::NAN);
        }
        let block = if s2 < RIGID * s1 {
            // A (nearly) massless cable: keep the finite part and hold the
            // length along `u2^T b xi = 0` (module docs).
            rigid[slot] = Some(u.column(1).transpose() * b);
            -(v_t.row(0).transpose() * (u.column(0).transpose() * b)) / s1
        } else {
            let Some(inverse) = partials.d_tension.try_inverse() else {
                return Matrix6::from_element(f64::NAN);
            };
            -(inverse * b)
        };
        d_f.fixed_view_mut::<2, 6>(2 * cable, 0).copy_from(&block);
    }
    let k = -(d_q + d_q_d_f * d_f);
    if rigid.iter().all(Option::is_none) {
        return k;
    }
    restrict_to_rigid_constraints(&k, &rigid)
}

/// Ratio of `d[paid, drop]/d[f_h, f_v]`'s singular values below which a
/// cable counts as rigid: its length fixes `paid` and `drop` almost only
/// through the ratio `f_v / f_h`, the tension's magnitude moving them by
/// less than 1e-6 of that. Inverting such a matrix would lose the finite
/// part of the stiffness (relative error ~ eps / ratio^2), while treating the
/// cable as inextensible errs by about the ratio itself.
const RIGID: f64 = 1e-6;

/// The stiffness of a platform held by rigid cables (constraint rows
/// `c_i`, one per rigid cable) and finite parts `k`: `K_eff = Z (Z^T S Z)
/// Z^T + |S| Y Y^T` with `S` the symmetric part of `k`, `Z` an orthonormal
/// basis of the motions that keep every rigid cable's length (`c_i xi = 0`)
/// and `Y` its complement. A taut inextensible cable's stiffness along its
/// constraint is infinite; `K_eff` puts `|S|` there so the matrix stays
/// finite: its smallest eigenvalue has the sign of the limit's (those of
/// `Z^T S Z` and a positive one), which is what the stability test reads.
fn restrict_to_rigid_constraints(k: &Matrix6<f64>, rigid: &[Option<RowSVector<f64, 6>>; CABLE_COUNT]) -> Matrix6<f64> {
    if !k.iter().all(|v| v.is_finite()) {
        return Matrix6::from_element(f64::NAN);
    }
    let mut c_t_c = Matrix6::<f64>::zeros();
    let mut count = 0;
    for row in rigid.iter().flatten() {
        let norm = row.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            return Matrix6::from_element(f64::NAN);
        }
        let unit = row / norm;
        c_t_c += unit.transpose() * unit;
        count += 1;
    }
    let symmetric = (k + k.transpose()) * 0.5;
    let scale = symmetric.norm().max(f64::MIN_POSITIVE);
    let eigen = c_t_c.symmetric_eigen();
    let mut order: Vec<usize> = (0..6).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    let mut out = Matrix6::<f64>::zeros();
    // The 6 - count smallest eigenvalues of C^T C: the motions keeping the lengths.
    let free = 6 - count;
    let z = SMatrix::<f64, 6, 6>::from_fn(|r, c| {
        if c < free {
            eigen.eigenvectors[(r, order[c])]
        } else {
            0.0
        }
    });
    out += z * (z.transpose() * symmetric * z) * z.transpose();
    for &index in &order[free..] {
        let y = eigen.eigenvectors.column(index);
        out += y * y.transpose() * scale;
    }
    out
}

/// The smallest eigenvalue of `K`'s symmetric part (NaN if `K` is not finite);
/// units mixed (N m/rad and N/m), only its sign is meaningful.
pub fn smallest_stiffness(k: &Matrix6<f64>) -> f64 {
    if !k.iter().all(|v| v.is_finite()) {
        return f64::NAN;
    }
    let symmetric = (k + k.transpose()) * 0.5;
    symmetric.symmetric_eigenvalues().min()
}

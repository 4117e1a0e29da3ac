//! Platform pose and the one retraction convention used everywhere.
//!
//! A pose is `world_from_platform = (R, p)`: a rotation `R` (unit quaternion)
//! and the position `p_m` of the platform frame origin in the world frame.
//!
//! **Retraction** (shared by `codegen/`, the solvers and the finite-difference
//! tests): the tangent vector is `xi = [dtheta (3), dp (3)]` and
//!
//! ```text
//! retract((R, p), xi) = (R * Exp(dtheta), p + dp)
//! ```
//!
//! i.e. the rotation is perturbed on the right (in the platform frame) and the
//! position additively in the world frame. This is SymForce's `Pose3`
//! convention (product manifold SO(3) x R^3, rotation block first), so the
//! generated Jacobians (`residual.jacobian(rot)`, `residual.jacobian(pos)`)
//! are exactly the derivatives along this retraction.
//!
//! ```
//! use nalgebra::{Vector3, Vector6};
//! use sagcal::model::PlatformPose;
//! let pose = PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(1.0, 2.0, 3.0), 10.0, -5.0, 30.0);
//! let (roll, pitch, yaw) = pose.roll_pitch_yaw_deg();
//! assert!((roll - 10.0).abs() < 1e-12 && (pitch + 5.0).abs() < 1e-12 && (yaw - 30.0).abs() < 1e-12);
//! // The position moves additively in the world frame, the rotation by |dtheta| about its axis,
//! // and `local_coordinates` undoes `retract`.
//! let xi = Vector6::new(0.01, -0.02, 0.03, 0.5, -0.25, 1.0);
//! let moved = pose.retract(&xi);
//! assert!((moved.position_m - pose.position_m - Vector3::new(0.5, -0.25, 1.0)).norm() < 1e-12);
//! assert!((pose.angle_to_deg(&moved) - 0.0014f64.sqrt().to_degrees()).abs() < 1e-9);
//! assert!((pose.local_coordinates(&moved) - xi).norm() < 1e-12);
//! ```

use nalgebra::{Rotation3, UnitQuaternion, Vector3, Vector4, Vector6};

/// Dimension of the pose tangent space.
pub const POSE_TANGENT_DIM: usize = 6;

/// The platform's pose in the world frame (`world_from_platform`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlatformPose {
    /// Orientation of the platform frame in the world frame.
    pub rotation: UnitQuaternion<f64>,
    /// Position of the platform frame origin in the world frame, metres.
    pub position_m: Vector3<f64>,
}

impl PlatformPose {
    /// A pose from a position and a rotation.
    pub fn new(position_m: Vector3<f64>, rotation: UnitQuaternion<f64>) -> Self {
        Self { rotation, position_m }
    }

    /// A pose with identity orientation.
    pub fn from_position(position_m: Vector3<f64>) -> Self {
        Self::new(position_m, UnitQuaternion::identity())
    }

    /// Rotation built as `R = Rz(yaw) * Ry(pitch) * Rx(roll)`, angles in degrees
    /// (the convention of the RecurDyn data and of sagcal's CSV format).
    pub fn from_roll_pitch_yaw_deg(position_m: Vector3<f64>, roll: f64, pitch: f64, yaw: f64) -> Self {
        let rotation = UnitQuaternion::from_euler_angles(roll.to_radians(), pitch.to_radians(), yaw.to_radians());
        Self::new(position_m, rotation)
    }

    /// `(roll, pitch, yaw)` in degrees with `R = Rz(yaw) * Ry(pitch) * Rx(roll)`.
    pub fn roll_pitch_yaw_deg(&self) -> (f64, f64, f64) {
        let (r, p, y) = self.rotation.euler_angles();
        (r.to_degrees(), p.to_degrees(), y.to_degrees())
    }

    /// Yaw, radians in `(-pi, pi]`: the rotation about the world z axis, the
    /// `yaw` of `R = Rz(yaw) * Ry(pitch) * Rx(roll)` ([`Self::roll_pitch_yaw_deg`]),
    /// `atan2(R[1,0], R[0,0])`: the heading of the platform's x axis projected
    /// on the horizontal plane.
    pub fn yaw_rad(&self) -> f64 {
        self.rotation.euler_angles().2
    }

    /// The quaternion as SymForce stores it: `[x, y, z, w]`.
    pub fn rotation_xyzw(&self) -> Vector4<f64> {
        let q = self.rotation.quaternion();
        Vector4::new(q.i, q.j, q.k, q.w)
    }

    /// The rotation matrix `R`.
    pub fn rotation_matrix(&self) -> Rotation3<f64> {
        self.rotation.to_rotation_matrix()
    }

    /// `retract(self, xi) = (R * Exp(xi[0..3]), p + xi[3..6])` (see the module docs).
    pub fn retract(&self, tangent: &Vector6<f64>) -> Self {
        let dtheta = Vector3::new(tangent[0], tangent[1], tangent[2]);
        let dp = Vector3::new(tangent[3], tangent[4], tangent[5]);
        Self::new(
            self.position_m + dp,
            self.rotation * UnitQuaternion::from_scaled_axis(dtheta),
        )
    }

    /// Inverse of [`retract`](Self::retract): the tangent `xi` with `retract(self, xi) == other`.
    pub fn local_coordinates(&self, other: &Self) -> Vector6<f64> {
        let dtheta = (self.rotation.inverse() * other.rotation).scaled_axis();
        let dp = other.position_m - self.position_m;
        Vector6::new(dtheta.x, dtheta.y, dtheta.z, dp.x, dp.y, dp.z)
    }

    /// Angle of the relative rotation between two poses, degrees.
    pub fn angle_to_deg(&self, other: &Self) -> f64 {
        self.rotation.angle_to(&other.rotation).to_degrees()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn retract_then_local_is_identity() {
        let pose = PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(1.0, -2.0, 3.0), 10.0, -20.0, 30.0);
        let xi = Vector6::new(0.1, -0.2, 0.05, 0.3, 0.4, -0.5);
        let back = pose.local_coordinates(&pose.retract(&xi));
        assert!((back - xi).norm() < 1e-14, "{back} vs {xi}");
    }

    #[test]
    fn roll_pitch_yaw_is_z_y_x() {
        let pose = PlatformPose::from_roll_pitch_yaw_deg(Vector3::zeros(), 10.0, 20.0, 30.0);
        let expected = Rotation3::from_axis_angle(&Vector3::z_axis(), 30f64.to_radians())
            * Rotation3::from_axis_angle(&Vector3::y_axis(), 20f64.to_radians())
            * Rotation3::from_axis_angle(&Vector3::x_axis(), 10f64.to_radians());
        assert!((pose.rotation_matrix().matrix() - expected.matrix()).norm() < 1e-15);
        let (r, p, y) = pose.roll_pitch_yaw_deg();
        assert!((r - 10.0).abs() < 1e-12 && (p - 20.0).abs() < 1e-12 && (y - 30.0).abs() < 1e-12);
    }
}

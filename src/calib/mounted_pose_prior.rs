//! The pose prior of a localiser mounted with a rotation (the
//! `localiser-mount` effect, `generated::mounted_pose_prior_residual`).
//!
//! ```
//! use nalgebra::DVector;
//! use sagcal::calib::effect_factors::MountedPosePriorFactor;
//! use sagcal::graph::{Factor, RobustKernel, Values, VariableValue};
//! use sagcal::model::PlatformPose;
//! let mut values = Values::new();
//! let pose = PlatformPose::from_roll_pitch_yaw_deg(nalgebra::Vector3::new(1.0, 2.0, 3.0), 1.0, -2.0, 30.0);
//! let at = values.insert("pose", VariableValue::Pose(pose));
//! let mount = values.insert("mount", VariableValue::Vector(DVector::zeros(3)));
//! let factor = MountedPosePriorFactor::new(at, mount, &pose, 0.01, 0.005, RobustKernel::None);
//! // No mount, the prior at the pose: no residual.
//! assert!(factor.evaluate(&values, None).unwrap().amax() < 1e-12);
//! // A mount of 1 degree about z: the orientation rows are its rotation vector, radians.
//! values.set(mount, VariableValue::Vector(DVector::from_vec(vec![0.0, 0.0, 1.0])));
//! let r = factor.evaluate(&values, None).unwrap();
//! assert!((r[2] - 1f64.to_radians()).abs() < 1e-12 && r[0].abs() < 1e-12 && r.rows(3, 3).norm() < 1e-12);
//! ```

use nalgebra::{DMatrix, DVector, SMatrix, Vector3, Vector4};

use super::factors::{pose_arguments, EPSILON};
use crate::generated;
use crate::graph::{Factor, Noise, RobustKernel, Values, VariableId};

/// Pose prior factor of a localiser mounted with a rotation (the
/// `localiser-mount` effect): `[Log(M R_prior^-1 R); p - p_prior]` with
/// `M = Exp(m)`, `m` the mount variable in degrees
/// (`generated::mounted_pose_prior_residual`). With `m = 0` it equals
/// [`super::factors::PosePriorFactor`] with the orientation rows.
pub struct MountedPosePriorFactor {
    variables: [VariableId; 2],
    prior_position_m: Vector3<f64>,
    prior_rotation_xyzw: Vector4<f64>,
    noise: Noise,
}

impl MountedPosePriorFactor {
    /// The localiser's pose `prior` with position sigma `position_sigma_m` and
    /// orientation sigma `orientation_sigma_rad`; `mount` is the `[rx, ry, rz]` (degrees) variable.
    pub fn new(
        pose: VariableId,
        mount: VariableId,
        prior: &crate::model::PlatformPose,
        position_sigma_m: f64,
        orientation_sigma_rad: f64,
        kernel: RobustKernel,
    ) -> Self {
        let (rot, pos) = (orientation_sigma_rad, position_sigma_m);
        Self {
            variables: [pose, mount],
            prior_position_m: prior.position_m,
            prior_rotation_xyzw: prior.rotation_xyzw(),
            noise: Noise::new(DVector::from_row_slice(&[rot, rot, rot, pos, pos, pos]), kernel),
        }
    }
}

impl Factor for MountedPosePriorFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        6
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        let (position, rotation) = pose_arguments(values, self.variables[0]);
        let mount_rad = Vector3::from_iterator(values.vector(self.variables[1]).iter().map(|d| d.to_radians()));
        let mut j_pose = SMatrix::<f64, 6, 6>::zeros();
        let mut j_mount = SMatrix::<f64, 6, 3>::zeros();
        let want = jacobians.is_some();
        let r = generated::mounted_pose_prior_residual(
            &position,
            &rotation,
            &self.prior_position_m,
            &self.prior_rotation_xyzw,
            &mount_rad,
            EPSILON,
            want.then_some(&mut j_pose),
            want.then_some(&mut j_mount),
        );
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j_pose);
            // The variable is in degrees: d/d(deg) = d/d(rad) * pi / 180.
            blocks[1].copy_from(&(j_mount * 1f64.to_radians()));
        }
        Some(DVector::from_column_slice(r.as_slice()))
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "pose_prior"
    }
}

//! The calibration factors (paper Sec. IV-C): thin wrappers that gather the
//! variables, call the SymForce-generated residual, and split its Jacobian
//! into one block per variable.
//!
//! The generated functions take the cables in *slot order* (slot 0 = the
//! reference cable); [`SlotOrder`] maps the robot's cable numbering to slots
//! once, so the variables (anchors, offsets) keep the robot's numbering.
//!
//! ```
//! use std::sync::Arc;
//! use nalgebra::{DMatrix, DVector, Vector3};
//! use sagcal::calib::factors::{CalibrationVariables, PoseVariables, RigidLengthFactor, SlotOrder};
//! use sagcal::graph::{Factor, RobustKernel, Values, VariableValue};
//! use sagcal::model::{PlatformPose, Robot};
//! let mut robot = Robot::builtin("large")?;
//! robot.reference_cable = 2; // the load cell on cable 3: it takes slot 0
//! let slots = SlotOrder::new(&robot);
//! assert_eq!(slots.cables, [2, 0, 1, 3]);
//! let vector = |v: &[f64]| VariableValue::Vector(DVector::from_column_slice(v));
//! let mut values = Values::new();
//! let position = Vector3::new(10.0, -5.0, 20.0);
//! let pose = values.insert("pose", VariableValue::Pose(PlatformPose::from_position(position)));
//! let reference_tension = values.insert("tension", vector(&[100.0, 100.0]));
//! let anchors = std::array::from_fn(|i| values.insert(format!("anchor {i}"), vector(robot.anchors_m[i].as_slice())));
//! let length_offsets = std::array::from_fn(|i| values.insert(format!("offset {i}"), vector(&[0.5])));
//! // Straight cables of a level platform: reading = |anchor - (p + b)| + offset; cable 3 reads 1 cm long.
//! let mut readings: [f64; 4] =
//!     std::array::from_fn(|i| (robot.anchors_m[i] - (position + robot.attachments_m[i])).norm() + 0.5);
//! readings[2] += 0.01;
//! let factor = RigidLengthFactor::new(
//!     Arc::new(slots),
//!     CalibrationVariables { anchors, length_offsets },
//!     PoseVariables { pose, reference_tension },
//!     &readings,
//!     0.01,
//!     RobustKernel::None,
//! );
//! // Residuals and Jacobian blocks come back in the robot's cable order:
//! // one block per variable, [pose (6 columns), anchors 1-4 (3), offsets 1-4 (1)].
//! let dims = [6, 3, 3, 3, 3, 1, 1, 1, 1];
//! let mut blocks: Vec<DMatrix<f64>> = dims.iter().map(|&d| DMatrix::zeros(4, d)).collect();
//! let r = factor.evaluate(&values, Some(&mut blocks)).unwrap();
//! assert!((r - DVector::from_column_slice(&[0.0, 0.0, -0.01, 0.0])).norm() < 1e-9);
//! for i in 0..4 {
//!     assert_eq!(blocks[5 + i], DMatrix::from_fn(4, 1, |row, _| if row == i { 1.0 } else { 0.0 }));
//! }
//! // Moving anchor 3 along its cable lengthens only cable 3, by the unit vector's share.
//! let along = (robot.anchors_m[2] - (position + robot.attachments_m[2])).normalize();
//! assert!((blocks[3].row(2).transpose() - along).norm() < 1e-9 && blocks[3].row(0).norm() == 0.0);
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, SMatrix, Vector3, Vector4};

use crate::generated;
use crate::graph::{evaluate_through_into, Factor, Noise, RobustKernel, SlotMask, Values, VariableId};
use crate::model::robot::CABLE_COUNT;

mod catenary_call;
mod slots;
mod tension_guard;

pub use catenary_call::{CatenaryCall, CatenaryMemo, CatenaryRows};
pub use slots::{CalibrationVariables, PoseVariables, SlotOrder, EPSILON};
pub use tension_guard::{TensionGuardFactor, TensionSource};

use slots::split_offset_jacobian;
pub(super) use slots::{
    gather_anchors, gather_offsets, pose_arguments, rows_to_cables, slots_to_cables, split_anchor_jacobian,
    tension_argument, variable_list,
};

/// The evaluation methods of a factor whose residual is four rows of its
/// pose's shared call ([`CatenaryCall::four_rows`]), from row `$first`.
macro_rules! four_rows_evaluation {
    ($first:literal) => {
        fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
            evaluate_through_into(self, values, jacobians)
        }
        fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
            self.evaluate_slots(values, residual, jacobians, SlotMask::ALL)
        }
        fn evaluate_slots(
            &self,
            values: &Values,
            residual: &mut [f64],
            jacobians: Option<&mut [DMatrix<f64>]>,
            wanted: SlotMask,
        ) -> bool {
            self.call.four_rows(values, $first, residual, jacobians, wanted);
            true
        }
    };
}

/// Catenary length factor (paper eq. 14): `l_C,i + l_i^0 - z_i^enc` for the four
/// cables of one pose, the tensions of the non-reference cables from eq. (11).
/// Rows 0..4 of the pose's shared [`CatenaryCall`].
pub struct CatenaryLengthFactor {
    variables: Vec<VariableId>,
    call: CatenaryCall,
    noise: Noise,
}

impl CatenaryLengthFactor {
    /// The length rows of `call` (which holds the pose's encoder readings).
    pub fn new(call: CatenaryCall, sigma_m: f64, kernel: RobustKernel) -> Self {
        Self {
            variables: variable_list(&call.pose, &call.globals, true, true),
            call,
            noise: Noise::new(DVector::from_element(CABLE_COUNT, sigma_m), kernel),
        }
    }
}

impl Factor for CatenaryLengthFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    four_rows_evaluation!(0);
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "catenary_length"
    }
    /// Every entry: the four rows of every block, from the shared call.
    fn writes_every_jacobian_entry(&self) -> bool {
        true
    }
}

/// Cable attachment factor (paper eq. 15): the attachment height minus the
/// height the catenary from each anchor reaches, for the four cables of one
/// pose. Rows 4..8 of the pose's shared [`CatenaryCall`].
pub struct AttachmentHeightFactor {
    variables: Vec<VariableId>,
    call: CatenaryCall,
    noise: Noise,
}

impl AttachmentHeightFactor {
    /// A height factor with standard deviation `sigma_m` (a model constraint: small).
    pub fn new(call: CatenaryCall, sigma_m: f64) -> Self {
        Self {
            variables: variable_list(&call.pose, &call.globals, true, false),
            call,
            noise: Noise::gaussian(DVector::from_element(CABLE_COUNT, sigma_m)),
        }
    }
}

impl Factor for AttachmentHeightFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    four_rows_evaluation!(4);
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "attachment_height"
    }
    /// Every entry: the four rows of every block, from the shared call.
    fn writes_every_jacobian_entry(&self) -> bool {
        true
    }
}

/// Force measurement factor (paper eq. 16): `|(f_h, f_v)| - f_m` of the reference cable.
pub struct ReferenceTensionFactor {
    variables: [VariableId; 1],
    measured_tension_n: f64,
    noise: Noise,
}

impl ReferenceTensionFactor {
    /// A load-cell reading `measured_tension_n` with standard deviation `sigma_n`.
    pub fn new(tension: VariableId, measured_tension_n: f64, sigma_n: f64, kernel: RobustKernel) -> Self {
        Self {
            variables: [tension],
            measured_tension_n,
            noise: Noise::new(DVector::from_element(1, sigma_n), kernel),
        }
    }
}

impl Factor for ReferenceTensionFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        1
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        evaluate_through_into(self, values, jacobians)
    }
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        let tension = tension_argument(values, self.variables[0]);
        let mut j = SMatrix::<f64, 1, 2>::zeros();
        let want = jacobians.is_some();
        let r =
            generated::reference_tension_residual(&tension, self.measured_tension_n, EPSILON, want.then_some(&mut j));
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j);
        }
        residual[0] = r[0];
        true
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "reference_tension"
    }
    /// Every entry: its one 1 x 2 block.
    fn writes_every_jacobian_entry(&self) -> bool {
        true
    }
}

/// Pose prior factor: the localiser's pose. With `orientation` off only the
/// position rows are kept, so the statics, not the localiser, decide the
/// orientation (the role of the paper's orientation-correction variable).
pub struct PosePriorFactor {
    variables: [VariableId; 1],
    prior_position_m: Vector3<f64>,
    prior_rotation_xyzw: Vector4<f64>,
    with_orientation: bool,
    noise: Noise,
}

impl PosePriorFactor {
    /// A prior with position sigma `position_sigma_m` and, if `Some`, orientation sigma (radians).
    pub fn new(
        pose: VariableId,
        prior: &crate::model::PlatformPose,
        position_sigma_m: f64,
        orientation_sigma_rad: Option<f64>,
        kernel: RobustKernel,
    ) -> Self {
        let sigmas = match orientation_sigma_rad {
            Some(rot) => {
                DVector::from_row_slice(&[rot, rot, rot, position_sigma_m, position_sigma_m, position_sigma_m])
            }
            None => DVector::from_element(3, position_sigma_m),
        };
        Self {
            variables: [pose],
            prior_position_m: prior.position_m,
            prior_rotation_xyzw: prior.rotation_xyzw(),
            with_orientation: orientation_sigma_rad.is_some(),
            noise: Noise::new(sigmas, kernel),
        }
    }
}

impl Factor for PosePriorFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        self.noise.sigmas.len()
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        evaluate_through_into(self, values, jacobians)
    }
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        let (position, rotation) = pose_arguments(values, self.variables[0]);
        let mut j = SMatrix::<f64, 6, 6>::zeros();
        let want = jacobians.is_some();
        let r = generated::pose_prior_residual(
            &position,
            &rotation,
            &self.prior_position_m,
            &self.prior_rotation_xyzw,
            EPSILON,
            want.then_some(&mut j),
        );
        let first = if self.with_orientation { 0 } else { 3 };
        if let Some(blocks) = jacobians {
            if first == 0 {
                // Both column-major 6 x 6: one slice copy.
                blocks[0].as_mut_slice().copy_from_slice(j.as_slice());
            } else {
                blocks[0].copy_from(&j.rows(first, 6 - first));
            }
        }
        residual.copy_from_slice(&r.as_slice()[first..]);
        true
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "pose_prior"
    }
    /// Every entry: its one block.
    fn writes_every_jacobian_entry(&self) -> bool {
        true
    }
}

/// Rigid massless-cable length factor: `|a_i - (p + R b_i)| + l_i^0 - z_i^enc`
/// (the straight-cable baseline of the paper's Sec. VI-A).
pub struct RigidLengthFactor {
    variables: Vec<VariableId>,
    slots: Arc<SlotOrder>,
    globals: CalibrationVariables,
    pose: PoseVariables,
    encoder_lengths_m: Vector4<f64>,
    noise: Noise,
}

impl RigidLengthFactor {
    /// `encoder_lengths_m` in the robot's cable order.
    pub fn new(
        slots: Arc<SlotOrder>,
        globals: CalibrationVariables,
        pose: PoseVariables,
        encoder_lengths_m: &[f64; CABLE_COUNT],
        sigma_m: f64,
        kernel: RobustKernel,
    ) -> Self {
        Self {
            variables: variable_list(&pose, &globals, false, true),
            encoder_lengths_m: slots.to_slots(encoder_lengths_m),
            slots,
            globals,
            pose,
            noise: Noise::new(DVector::from_element(CABLE_COUNT, sigma_m), kernel),
        }
    }
}

impl Factor for RigidLengthFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        let (position, rotation) = pose_arguments(values, self.pose.pose);
        let anchors = gather_anchors(values, &self.slots, &self.globals);
        let offsets = gather_offsets(values, &self.slots, &self.globals);
        let s = &self.slots;
        let mut j_pose = SMatrix::<f64, 4, 6>::zeros();
        let mut j_anchors = SMatrix::<f64, 4, 12>::zeros();
        let mut j_offsets = SMatrix::<f64, 4, 4>::zeros();
        let want = jacobians.is_some();
        let r = generated::rigid_length_residual(
            &position,
            &rotation,
            &anchors,
            &s.attachments_m,
            &offsets,
            &self.encoder_lengths_m,
            EPSILON,
            want.then_some(&mut j_pose),
            want.then_some(&mut j_anchors),
            want.then_some(&mut j_offsets),
        );
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j_pose);
            split_anchor_jacobian(&j_anchors, s, &mut blocks[1..5]);
            split_offset_jacobian(&j_offsets, s, &mut blocks[5..9]);
            rows_to_cables(s, blocks);
        }
        Some(slots_to_cables(s, &r))
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "rigid_length"
    }
}

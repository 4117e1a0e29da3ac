//! Between the graph's variables, in the robot's cable order, and the
//! generated code, in slot order (slot 0 = the reference cable): the slot
//! order ([`SlotOrder`]), the variable groups every factor takes
//! ([`CalibrationVariables`], [`PoseVariables`]), the gathering of their
//! values into the generated functions' arguments, and the residuals and
//! Jacobian blocks put back into cable order.

use nalgebra::{DMatrix, DVector, Matrix3x4, SMatrix, Vector2, Vector3, Vector4};

use crate::graph::{Values, VariableId};
use crate::model::robot::{Robot, CABLE_COUNT};

/// The `epsilon` passed to the generated code (SymForce's default for f64).
pub const EPSILON: f64 = 10.0 * f64::EPSILON;

/// Robot constants shared by every factor, in slot order.
#[derive(Debug, Clone, PartialEq)]
pub struct SlotOrder {
    /// `cables[slot]` = the robot's cable index in that slot; `cables[0]` is the reference cable.
    pub cables: [usize; CABLE_COUNT],
    /// Attachment points, platform frame, column = slot.
    pub attachments_m: Matrix3x4<f64>,
    /// Centre of mass, platform frame.
    pub com_offset_m: Vector3<f64>,
    /// Platform weight, newtons.
    pub platform_weight_n: f64,
    /// Cable weight per metre, newtons per metre.
    pub cable_weight_n_per_m: f64,
}

impl SlotOrder {
    /// The slot order of `robot` (reference cable first, then the others in order).
    pub fn new(robot: &Robot) -> Self {
        let mut cables = [robot.reference_cable; CABLE_COUNT];
        let mut slot = 1;
        for cable in 0..CABLE_COUNT {
            if cable != robot.reference_cable {
                cables[slot] = cable;
                slot += 1;
            }
        }
        let mut attachments_m = Matrix3x4::zeros();
        for (slot, &cable) in cables.iter().enumerate() {
            attachments_m.set_column(slot, &robot.attachments_m[cable]);
        }
        Self {
            cables,
            attachments_m,
            com_offset_m: robot.com_offset_m,
            platform_weight_n: robot.platform_weight_n,
            cable_weight_n_per_m: robot.cable_weight_n_per_m,
        }
    }

    /// Permute per-cable values (robot order) into slot order.
    pub fn to_slots(&self, per_cable: &[f64; CABLE_COUNT]) -> Vector4<f64> {
        Vector4::from_fn(|slot, _| per_cable[self.cables[slot]])
    }
}

/// The variables of the global calibration parameters, in the robot's cable order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibrationVariables {
    /// Anchor `i` (3-vector, world frame, metres).
    pub anchors: [VariableId; CABLE_COUNT],
    /// Length offset `i` (1-vector, metres).
    pub length_offsets: [VariableId; CABLE_COUNT],
}

/// The variables of one static pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseVariables {
    /// Platform pose.
    pub pose: VariableId,
    /// Reference-cable tension `[f_h, f_v]` at its attachment, newtons.
    pub reference_tension: VariableId,
}

pub(crate) fn gather_anchors(values: &Values, slots: &SlotOrder, globals: &CalibrationVariables) -> SMatrix<f64, 3, 4> {
    let mut anchors = SMatrix::<f64, 3, 4>::zeros();
    for (slot, &cable) in slots.cables.iter().enumerate() {
        let a = values.vector(globals.anchors[cable]);
        anchors.set_column(slot, &Vector3::new(a[0], a[1], a[2]));
    }
    anchors
}

pub(crate) fn gather_offsets(values: &Values, slots: &SlotOrder, globals: &CalibrationVariables) -> Vector4<f64> {
    Vector4::from_fn(|slot, _| values.vector(globals.length_offsets[slots.cables[slot]])[0])
}

pub(crate) fn pose_arguments(values: &Values, pose: VariableId) -> (Vector3<f64>, Vector4<f64>) {
    let pose = values.pose(pose);
    (pose.position_m, pose.rotation_xyzw())
}

pub(crate) fn tension_argument(values: &Values, id: VariableId) -> Vector2<f64> {
    let t = values.vector(id);
    Vector2::new(t[0], t[1])
}

/// Variables `[pose, reference tension?, anchors (robot order), offsets (robot order)?]`.
pub(crate) fn variable_list(
    pose: &PoseVariables,
    globals: &CalibrationVariables,
    with_tension: bool,
    with_offsets: bool,
) -> Vec<VariableId> {
    let mut list = vec![pose.pose];
    if with_tension {
        list.push(pose.reference_tension);
    }
    list.extend(globals.anchors);
    if with_offsets {
        list.extend(globals.length_offsets);
    }
    list
}

/// Copy the slot-ordered anchor Jacobian (`rows x 12`) into per-anchor blocks (robot order).
pub(crate) fn split_anchor_jacobian<const R: usize>(
    jacobian: &SMatrix<f64, R, 12>,
    slots: &SlotOrder,
    blocks: &mut [DMatrix<f64>],
) {
    for (slot, &cable) in slots.cables.iter().enumerate() {
        blocks[cable].copy_from(&jacobian.fixed_columns::<3>(3 * slot));
    }
}

pub(super) fn split_offset_jacobian(jacobian: &SMatrix<f64, 4, 4>, slots: &SlotOrder, blocks: &mut [DMatrix<f64>]) {
    for (slot, &cable) in slots.cables.iter().enumerate() {
        blocks[cable].copy_from(&jacobian.fixed_columns::<1>(slot));
    }
}

/// Turn a slot-ordered residual into robot cable order.
pub(crate) fn slots_to_cables(slots: &SlotOrder, residual: &Vector4<f64>) -> DVector<f64> {
    // On the stack, then copied (`DVector::zeros` is a `calloc`).
    let mut out = [0.0; CABLE_COUNT];
    for (slot, &cable) in slots.cables.iter().enumerate() {
        out[cable] = residual[slot];
    }
    DVector::from_column_slice(&out)
}

/// Reorder the rows of Jacobian blocks from slot order to cable order.
pub(crate) fn rows_to_cables(slots: &SlotOrder, blocks: &mut [DMatrix<f64>]) {
    for block in blocks {
        for mut column in block.column_iter_mut() {
            let by_slot: [f64; CABLE_COUNT] = std::array::from_fn(|slot| column[slot]);
            for (slot, &cable) in slots.cables.iter().enumerate() {
                column[cable] = by_slot[slot];
            }
        }
    }
}

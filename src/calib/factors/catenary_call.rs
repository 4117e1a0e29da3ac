//! The one generated call a pose's catenary factors share (issue 18): the
//! length rows (eq. 14), height rows (eq. 15) and tensions (eq. 11) of
//! [`generated::catenary_cable_residuals`], made by the first factor
//! evaluated at a point and read by the others ([`SharedEvaluation`]).

use std::sync::Arc;

use nalgebra::{DMatrix, SMatrix, SVector, Vector4};

use super::{
    gather_anchors, gather_offsets, pose_arguments, tension_argument, CalibrationVariables, PoseVariables, SlotOrder,
    EPSILON,
};
use crate::generated;
use crate::graph::{SharedEvaluation, Values, VariableId};
use crate::model::robot::CABLE_COUNT;

/// The outputs of [`generated::catenary_cable_residuals`] at one point, slot
/// order: rows 0..4 the length errors (eq. 14), 4..8 the height errors
/// (eq. 15), 8..16 the tensions `[f_h0, f_v0, ...]` (eq. 11).
#[derive(Default)]
pub struct CatenaryRows {
    pub(super) rows: SVector<f64, 16>,
    pub(super) pose: SMatrix<f64, 16, 6>,
    pub(super) tension: SMatrix<f64, 16, 2>,
    pub(super) anchors: SMatrix<f64, 16, 12>,
    pub(super) offsets: SMatrix<f64, 16, 4>,
}

/// Inputs of the call that change with the variables (pose 7, reference
/// tension 2, anchors 12, offsets 4) and the pose's encoder readings (4).
const CATENARY_INPUTS: usize = 29;

/// The generated call that a pose's length, height and tension-guard factors
/// share ([`SharedEvaluation`]: the first factor evaluated at a point makes
/// it, the others read its rows). One per graph, shared by every pose.
pub type CatenaryMemo = SharedEvaluation<CATENARY_INPUTS, CatenaryRows>;

/// What one pose's catenary factors need to make the shared call.
#[derive(Clone)]
pub struct CatenaryCall {
    pub(super) slots: Arc<SlotOrder>,
    pub(super) globals: CalibrationVariables,
    pub(super) pose: PoseVariables,
    /// Encoder readings, slot order, metres.
    encoder_lengths_m: Vector4<f64>,
    memo: Arc<CatenaryMemo>,
}

impl CatenaryCall {
    /// The call for `pose` with its `encoder_lengths_m` (robot cable order), remembered in `memo`.
    pub fn new(
        slots: Arc<SlotOrder>,
        globals: CalibrationVariables,
        pose: PoseVariables,
        encoder_lengths_m: &[f64; CABLE_COUNT],
        memo: Arc<CatenaryMemo>,
    ) -> Self {
        Self {
            encoder_lengths_m: slots.to_slots(encoder_lengths_m),
            slots,
            globals,
            pose,
            memo,
        }
    }

    /// The pose's reference-tension variable.
    pub fn reference_tension(&self) -> VariableId {
        self.pose.reference_tension
    }

    /// `read` of the call's outputs at `values` (with Jacobians if `jacobians`).
    pub(super) fn read<R>(&self, values: &Values, jacobians: bool, read: impl FnOnce(&CatenaryRows) -> R) -> R {
        let (position, rotation) = pose_arguments(values, self.pose.pose);
        let tension = tension_argument(values, self.pose.reference_tension);
        let anchors = gather_anchors(values, &self.slots, &self.globals);
        let offsets = gather_offsets(values, &self.slots, &self.globals);
        let mut inputs = [0.0; CATENARY_INPUTS];
        inputs[..3].copy_from_slice(position.as_slice());
        inputs[3..7].copy_from_slice(rotation.as_slice());
        inputs[7..9].copy_from_slice(tension.as_slice());
        inputs[9..21].copy_from_slice(anchors.as_slice());
        inputs[21..25].copy_from_slice(offsets.as_slice());
        inputs[25..].copy_from_slice(self.encoder_lengths_m.as_slice());
        let s = &self.slots;
        let evaluate = |out: &mut CatenaryRows, want: bool| {
            out.rows = generated::catenary_cable_residuals(
                &position,
                &rotation,
                &tension,
                &anchors,
                &s.attachments_m,
                &s.com_offset_m,
                s.platform_weight_n,
                s.cable_weight_n_per_m,
                &offsets,
                &self.encoder_lengths_m,
                EPSILON,
                want.then_some(&mut out.pose),
                want.then_some(&mut out.tension),
                want.then_some(&mut out.anchors),
                want.then_some(&mut out.offsets),
            );
        };
        self.memo.read(&inputs, jacobians, evaluate, read)
    }

    /// Four rows from `first` of the call as a factor's residual (robot cable
    /// order) into `residual`, with its blocks `[pose, tension, anchors (4), offsets (4)?]`.
    pub(super) fn four_rows(
        &self,
        values: &Values,
        first: usize,
        residual: &mut [f64],
        jacobians: Option<&mut [DMatrix<f64>]>,
    ) {
        let s = &self.slots;
        self.read(values, jacobians.is_some(), |out| {
            if let Some(blocks) = jacobians {
                // Column-major blocks of `CABLE_COUNT` rows: entry (cable, c) at `cable + CABLE_COUNT * c`.
                let n = CABLE_COUNT;
                let (pose, tension) = (out.pose.as_slice(), out.tension.as_slice());
                let (anchors, offsets) = (out.anchors.as_slice(), out.offsets.as_slice());
                // The generated blocks are column-major with 16 rows: (row, c) at `row + 16 * c`.
                let at = |row: usize, c: usize| row + 16 * c;
                for (slot, &cable) in s.cables.iter().enumerate() {
                    let row = first + slot;
                    let pose_block = blocks[0].as_mut_slice();
                    for c in 0..6 {
                        pose_block[cable + n * c] = pose[at(row, c)];
                    }
                    let tension_block = blocks[1].as_mut_slice();
                    for c in 0..2 {
                        tension_block[cable + n * c] = tension[at(row, c)];
                    }
                    for (anchor_slot, &anchor_cable) in s.cables.iter().enumerate() {
                        let anchor_block = blocks[2 + anchor_cable].as_mut_slice();
                        for c in 0..3 {
                            anchor_block[cable + n * c] = anchors[at(row, 3 * anchor_slot + c)];
                        }
                        if let Some(offset_block) = blocks.get_mut(6 + anchor_cable) {
                            offset_block.as_mut_slice()[cable] = offsets[at(row, anchor_slot)];
                        }
                    }
                }
            }
            for (slot, &cable) in s.cables.iter().enumerate() {
                residual[cable] = out.rows[first + slot];
            }
        })
    }
}

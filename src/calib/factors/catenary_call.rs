//! The one generated call a pose's catenary factors share: the
//! length rows (eq. 14), height rows (eq. 15) and tensions (eq. 11) of
//! [`generated::catenary_cable_residuals`], made by the first factor
//! evaluated at a point and read by the others ([`SharedEvaluation`]).

use std::sync::Arc;

use nalgebra::{DMatrix, Matrix3x4, SMatrix, SVector, Vector2, Vector3, Vector4};

use super::slots::{
    gather_anchors, gather_offsets, pose_arguments, tension_argument, CalibrationVariables, PoseVariables, SlotOrder,
    EPSILON,
};
use crate::generated;
use crate::graph::{SharedEvaluation, SlotMask, Values, VariableId};
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
/// it, the others read its rows). One per graph, shared by every pose, or
/// one per pose (see `calib::graph`).
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
    /// Whether a memo miss by stamp compares the inputs (see [`CatenaryCall::comparing_inputs`]).
    compare_inputs: bool,
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
            compare_inputs: false,
        }
    }

    /// This call with a memo that, when the values' stamp has changed,
    /// compares the inputs before calling again: for a memo of its own,
    /// which then finds its last call after the values were copied or other
    /// poses moved (the solver's local refinement). A memo shared by every
    /// pose never meets its inputs again under another stamp.
    pub fn comparing_inputs(mut self) -> Self {
        self.compare_inputs = true;
        self
    }

    /// The pose's reference-tension variable.
    pub fn reference_tension(&self) -> VariableId {
        self.pose.reference_tension
    }

    /// `read` of the call's outputs at `values` (with Jacobians if `jacobians`).
    /// The memo is tested first by the values' stamp and the pose
    /// ([`Values::stamp`]: equal stamps, equal values), so the factors that
    /// read a call made in the same pass do not gather its inputs; then by
    /// the inputs themselves ([`SharedEvaluation::read_stamped`]).
    pub(super) fn read<R>(&self, values: &Values, jacobians: bool, read: impl FnOnce(&CatenaryRows) -> R) -> R {
        let stamp = [values.stamp(), self.pose.pose.0 as u64];
        let s = &self.slots;
        let inputs = || {
            let (position, rotation) = pose_arguments(values, self.pose.pose);
            let tension = tension_argument(values, self.pose.reference_tension);
            let anchors = gather_anchors(values, s, &self.globals);
            let offsets = gather_offsets(values, s, &self.globals);
            let mut inputs = [0.0; CATENARY_INPUTS];
            inputs[..3].copy_from_slice(position.as_slice());
            inputs[3..7].copy_from_slice(rotation.as_slice());
            inputs[7..9].copy_from_slice(tension.as_slice());
            inputs[9..21].copy_from_slice(anchors.as_slice());
            inputs[21..25].copy_from_slice(offsets.as_slice());
            inputs[25..].copy_from_slice(self.encoder_lengths_m.as_slice());
            inputs
        };
        let evaluate = |out: &mut CatenaryRows, want: bool, inputs: &[f64; CATENARY_INPUTS]| {
            let position = Vector3::from_column_slice(&inputs[..3]);
            let rotation = Vector4::from_column_slice(&inputs[3..7]);
            let tension = Vector2::from_column_slice(&inputs[7..9]);
            let anchors = Matrix3x4::from_column_slice(&inputs[9..21]);
            let offsets = Vector4::from_column_slice(&inputs[21..25]);
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
        if self.compare_inputs {
            self.memo.read_stamped(stamp, inputs, jacobians, evaluate, read)
        } else {
            let evaluate = |out: &mut CatenaryRows, want: bool| evaluate(out, want, &inputs());
            self.memo.read_by_stamp(stamp, jacobians, evaluate, read)
        }
    }

    /// Four rows from `first` of the call as a factor's residual (robot cable
    /// order) into `residual`, with its blocks `[pose, tension, anchors (4),
    /// offsets (4)?]`: the pose's and the tension's always, the anchors' and
    /// offsets' where `wanted` holds any of them (else they are left as they were).
    pub(super) fn four_rows(
        &self,
        values: &Values,
        first: usize,
        residual: &mut [f64],
        jacobians: Option<&mut [DMatrix<f64>]>,
        wanted: SlotMask,
    ) {
        let s = &self.slots;
        self.read(values, jacobians.is_some(), |out| {
            if let Some(blocks) = jacobians {
                let cables = &s.cables;
                // Row `r` of a factor's block (robot cable `r`) is the
                // generated row of the slot that holds cable `r`.
                let mut slot_of = [0; CABLE_COUNT];
                for (slot, &cable) in cables.iter().enumerate() {
                    slot_of[cable & (CABLE_COUNT - 1)] = slot;
                }
                copy_rows::<6>(out.pose.as_slice(), first, blocks[0].as_mut_slice(), &slot_of);
                copy_rows::<2>(out.tension.as_slice(), first, blocks[1].as_mut_slice(), &slot_of);
                // The anchors' and offsets' blocks only for a reader that
                // wants one of them (the refinement reads the pose's alone).
                if (2..blocks.len()).any(|slot| wanted.contains(slot)) {
                    let (anchors, offsets) = (out.anchors.as_slice(), out.offsets.as_slice());
                    for (anchor_slot, &cable) in cables.iter().enumerate() {
                        let columns = &anchors[3 * ROWS * anchor_slot..];
                        copy_rows::<3>(columns, first, blocks[2 + cable].as_mut_slice(), &slot_of);
                        if let Some(offset_block) = blocks.get_mut(6 + cable) {
                            let column = &offsets[ROWS * anchor_slot..];
                            copy_rows::<1>(column, first, offset_block.as_mut_slice(), &slot_of);
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

/// Rows of the generated call's outputs ([`CatenaryRows`]).
const ROWS: usize = 16;

// `copy_rows` masks slot indices with `CABLE_COUNT - 1`.
const _: () = assert!(CABLE_COUNT.is_power_of_two());

/// Copy rows `first..first + 4` (slot order) of the first `COLUMNS`
/// columns of a generated block (`from`: column-major, [`ROWS`] rows) into
/// a factor's block (`to`: column-major, one row per cable, robot order):
/// row `r` of `to` is row `first + slot_of[r]` of `from`. The sizes known
/// at compile time, the slices checked once: one load and one store per entry.
#[inline(always)]
fn copy_rows<const COLUMNS: usize>(from: &[f64], first: usize, to: &mut [f64], slot_of: &[usize; CABLE_COUNT]) {
    let from = &from[first..first + ROWS * (COLUMNS - 1) + CABLE_COUNT];
    let to = &mut to[..CABLE_COUNT * COLUMNS];
    for c in 0..COLUMNS {
        for (r, &slot) in slot_of.iter().enumerate() {
            // `slot_of` is a permutation of 0..4: the mask only spares the bounds check.
            to[CABLE_COUNT * c + r] = from[ROWS * c + (slot & (CABLE_COUNT - 1))];
        }
    }
}

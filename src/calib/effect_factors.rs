//! Factors of the extended model: the calibration factors with the
//! physical effects of [`crate::model::effects`] as extra parameter variables
//! ([`EffectVariables`]). The length and attachment factors chain two
//! generated functions (derived in `codegen/factors.py`):
//! `generated::cable_geometry` (each cable's span, end tensions and anchor
//! height from the pose, eq. 2 and 5-11) and `generated::extended_cable` (the
//! paid-out length and drop of an elastic catenary leaving a pulley); the
//! load-cell factor wraps `generated::load_cell_residual`.
//!
//! With every effect parameter at its neutral value (0) they equal the
//! baseline factors of [`super::factors`] (tested in `tests/extended_model.rs`).
//!
//! ```
//! use nalgebra::{DMatrix, DVector};
//! use sagcal::calib::effect_factors::LoadCellFactor;
//! use sagcal::graph::{Factor, RobustKernel, Values, VariableValue};
//! let vector = |v: &[f64]| VariableValue::Vector(DVector::from_column_slice(v));
//! let mut values = Values::new();
//! let tension = values.insert("reference tension", vector(&[300.0, 400.0])); // (f_h, f_v): |T| = 500 N
//! let cell = values.insert("load cell", vector(&[0.0, 0.0])); // [bias_n, gain_error], neutral
//! let factor = LoadCellFactor::new(tension, cell, 510.0, 5.0, RobustKernel::None);
//! // Neutral: the baseline force factor |T| - f_m = 500 - 510.
//! assert!((factor.evaluate(&values, None).unwrap()[0] + 10.0).abs() < 1e-12);
//! // A 2 N bias and a 1 % gain error: 2 + 1.01 * 500 - 510 = -3 N.
//! values.set(cell, vector(&[2.0, 0.01]));
//! let mut blocks = vec![DMatrix::zeros(1, 2), DMatrix::zeros(1, 2)];
//! let r = factor.evaluate(&values, Some(&mut blocks)).unwrap();
//! assert!((r[0] + 3.0).abs() < 1e-9);
//! // d r / d(f_h, f_v) = 1.01 (0.6, 0.8); d r / d(bias, gain_error) = (1, |T|).
//! assert!((blocks[0][(0, 0)] - 0.606).abs() < 1e-12 && (blocks[0][(0, 1)] - 0.808).abs() < 1e-12);
//! assert!((blocks[1][(0, 0)] - 1.0).abs() < 1e-12 && (blocks[1][(0, 1)] - 500.0).abs() < 1e-9);
//! ```

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3x4, SMatrix, Vector2, Vector3, Vector4};

use super::factors::{
    gather_anchors, gather_offsets, pose_arguments, rows_to_cables, slots_to_cables, split_anchor_jacobian,
    tension_argument, variable_list, CalibrationVariables, PoseVariables, SlotOrder, EPSILON,
};
use crate::generated;
use crate::graph::{Factor, Noise, RobustKernel, SharedEvaluation, Values, VariableId};
use crate::model::effect_kind::EffectKind;
use crate::model::measurement::ReadingOrder;
use crate::model::robot::CABLE_COUNT;

pub use super::load_cell_factor::LoadCellFactor;
pub use super::mounted_pose_prior::MountedPosePriorFactor;

/// The effect parameters of the extended model, one variable per effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectVariables {
    /// `[1e6 / EA]`, the cables' axial compliance in 1/MN (0: inextensible).
    pub axial_compliance: VariableId,
    /// `[r]`, the pulley radius, metres.
    pub pulley_radius: VariableId,
    /// `[g_1 .. g_4]`, encoder scale errors (reading = `(1 + g_i)` x paid-out length), robot cable order.
    pub encoder_gain_errors: VariableId,
    /// `[bias_n, gain_error]` of the load cell (reading = `bias + (1 + gain_error) |T|`).
    pub load_cell: VariableId,
    /// `[dx, dy]`, the horizontal centre-of-mass shift from the nominal one,
    /// platform frame, metres. A vertical shift is a known input only (added
    /// to the nominal centre of mass): its moment arm `(R b_com) x z` vanishes
    /// for a level platform, so nearly level poses cannot determine it.
    pub com_shift: VariableId,
    /// `[1/n^2]` of a cable of `n` straight elements (0: the smooth cable).
    pub inverse_segments_squared: VariableId,
    /// `[g]`, an encoder scale error shared by the four drums, added to each
    /// drum's own (reading = `(1 + g_i + g)` x paid-out length).
    pub common_gain_error: VariableId,
    /// `[rx, ry, rz]`, the localiser's mounting rotation vector, platform frame, degrees.
    pub localiser_mount: VariableId,
    /// `[s - 1]`, the platform's weight error as a share of the robot file's
    /// (true weight = `s` x `platform_weight_n`).
    pub platform_weight_error: VariableId,
    /// `[s - 1]`, the cables' weight-per-metre error as a share of the robot
    /// file's (true weight per metre = `s` x `cable_weight_n_per_m`).
    pub cable_weight_error: VariableId,
    /// `[d_1 .. d_4]`, each drum's encoder creep, millimetres per row
    /// (reading + `d_i row`), robot cable order.
    pub encoder_drift: VariableId,
    /// `[b_1 .. b_4]`, each drum's backlash, millimetres (reading + `b_i s_i`,
    /// `s_i` the direction of last motion), robot cable order.
    pub encoder_backlash: VariableId,
    /// `[e]`, the load cell's creep, newtons per row.
    pub load_cell_drift: VariableId,
    /// `[k]`, friction `mu theta` of a pulley before a drum-side load cell (reading `T (1 - k s)`).
    pub load_cell_friction: VariableId,
    /// `[dx_1, dy_1, .., dx_4, dy_4]`, each cable's attachment point moved
    /// horizontally from the robot file's, platform frame, metres, robot
    /// cable order (a vertical move is not identifiable from nearly level
    /// poses, as for the centre of mass).
    pub attachment_shift: VariableId,
}

impl EffectVariables {
    /// The variable holding `kind`'s parameters.
    pub fn of(&self, kind: EffectKind) -> VariableId {
        match kind {
            EffectKind::Elastic => self.axial_compliance,
            EffectKind::Pulley => self.pulley_radius,
            EffectKind::EncoderScale => self.encoder_gain_errors,
            EffectKind::LoadCell => self.load_cell,
            EffectKind::Com => self.com_shift,
            EffectKind::CommonGain => self.common_gain_error,
            EffectKind::Segments => self.inverse_segments_squared,
            EffectKind::LocaliserMount => self.localiser_mount,
            EffectKind::PlatformWeight => self.platform_weight_error,
            EffectKind::CableWeight => self.cable_weight_error,
            EffectKind::EncoderDrift => self.encoder_drift,
            EffectKind::EncoderBacklash => self.encoder_backlash,
            EffectKind::LoadCellDrift => self.load_cell_drift,
            EffectKind::LoadCellFriction => self.load_cell_friction,
            EffectKind::Attachments => self.attachment_shift,
        }
    }
}

/// The effect parameters read from `values`, in the generated functions' form.
struct EffectArguments {
    compliance_per_mn: f64,
    pulley_radius_m: f64,
    /// Slot order.
    gain_errors: Vector4<f64>,
    /// Nominal centre of mass plus the shift, platform frame.
    com_offset_m: Vector3<f64>,
    inverse_segments_squared: f64,
    /// The platform's weight, newtons, and its derivative by the weight error (the file's weight).
    platform_weight_n: f64,
    nominal_platform_weight_n: f64,
    /// The cables' weight per metre, N/m, and its derivative by the weight error (the file's).
    cable_weight_n_per_m: f64,
    nominal_cable_weight_n_per_m: f64,
    /// Encoder drift (mm per row) and backlash (mm), slot order.
    drift_mm_per_row: Vector4<f64>,
    backlash_mm: Vector4<f64>,
    /// The robot file's attachments moved by the shift, platform frame, column = slot.
    attachments_m: Matrix3x4<f64>,
}

fn effect_arguments(values: &Values, slots: &SlotOrder, effects: &EffectVariables) -> EffectArguments {
    let gains = values.vector(effects.encoder_gain_errors);
    let common = values.vector(effects.common_gain_error)[0];
    let shift = values.vector(effects.com_shift);
    EffectArguments {
        compliance_per_mn: values.vector(effects.axial_compliance)[0],
        pulley_radius_m: values.vector(effects.pulley_radius)[0],
        gain_errors: Vector4::from_fn(|slot, _| gains[slots.cables[slot]] + common),
        com_offset_m: slots.com_offset_m + Vector3::new(shift[0], shift[1], 0.0),
        inverse_segments_squared: values.vector(effects.inverse_segments_squared)[0],
        platform_weight_n: slots.platform_weight_n * (1.0 + values.vector(effects.platform_weight_error)[0]),
        nominal_platform_weight_n: slots.platform_weight_n,
        cable_weight_n_per_m: slots.cable_weight_n_per_m * (1.0 + values.vector(effects.cable_weight_error)[0]),
        nominal_cable_weight_n_per_m: slots.cable_weight_n_per_m,
        drift_mm_per_row: Vector4::from_fn(|slot, _| values.vector(effects.encoder_drift)[slots.cables[slot]]),
        backlash_mm: Vector4::from_fn(|slot, _| values.vector(effects.encoder_backlash)[slots.cables[slot]]),
        attachments_m: {
            let shift = values.vector(effects.attachment_shift);
            let mut moved = slots.attachments_m;
            for (slot, &cable) in slots.cables.iter().enumerate() {
                moved[(0, slot)] += shift[2 * cable];
                moved[(1, slot)] += shift[2 * cable + 1];
            }
            moved
        },
    }
}

/// Number of geometry columns chained through `generated::extended_cable`:
/// pose (6), reference tension (2), anchors (12, slot order), centre of mass (3),
/// then compliance (1), pulley radius (1), `1/n^2` (1), the platform's weight
/// error (1), the cables' weight error (1) and the attachments' horizontal
/// shifts (8, `[x, y]` per slot).
const CHAIN_COLUMNS: usize = 36;

/// The extended cable model of one pose: per slot the paid-out length and
/// `drop - h` (the attachment residual), with Jacobians by the chain rule
/// through `generated::cable_geometry` and `generated::extended_cable`.
/// Computed once per point for the pose's length and height factors
/// ([`ExtendedMemo`]).
pub struct ExtendedCables {
    /// Paid-out length per slot, metres.
    paid_out_m: Vector4<f64>,
    /// Attachment residual `drop - h` per slot, metres.
    height_residual_m: Vector4<f64>,
    /// `d paid_out / d [pose, tension, anchors, com, compliance, radius, 1/n^2,
    /// platform weight error, cable weight error]`.
    d_paid_out: SMatrix<f64, 4, CHAIN_COLUMNS>,
    /// `d height_residual / d [...]`, same columns.
    d_height: SMatrix<f64, 4, CHAIN_COLUMNS>,
}

impl Default for ExtendedCables {
    fn default() -> Self {
        Self {
            paid_out_m: Vector4::zeros(),
            height_residual_m: Vector4::zeros(),
            d_paid_out: SMatrix::zeros(),
            d_height: SMatrix::zeros(),
        }
    }
}

/// Inputs of [`extended_cables`] that change with the variables: pose 7,
/// reference tension 2, anchors 12, compliance, pulley radius, centre of mass 3, `1/n^2`,
/// the platform's and the cables' weights, the attachments' horizontal coordinates 8.
const EXTENDED_INPUTS: usize = 37;

/// The last [`ExtendedCables`] of a graph, read by the length and height
/// factors of the pose it was computed for (one call per pose and point
/// instead of one per factor; see [`crate::graph::SharedEvaluation`]).
pub type ExtendedMemo = SharedEvaluation<EXTENDED_INPUTS, ExtendedCables>;

/// `read` of [`extended_cables`] at `values`, through `memo`.
#[allow(clippy::too_many_arguments)]
fn shared_extended_cables<R>(
    memo: &ExtendedMemo,
    values: &Values,
    slots: &SlotOrder,
    globals: &CalibrationVariables,
    pose: &PoseVariables,
    effects: &EffectArguments,
    want_jacobians: bool,
    read: impl FnOnce(&ExtendedCables) -> R,
) -> R {
    let (position, rotation) = pose_arguments(values, pose.pose);
    let tension = tension_argument(values, pose.reference_tension);
    let anchors = gather_anchors(values, slots, globals);
    let mut inputs = [0.0; EXTENDED_INPUTS];
    inputs[..3].copy_from_slice(position.as_slice());
    inputs[3..7].copy_from_slice(rotation.as_slice());
    inputs[7..9].copy_from_slice(tension.as_slice());
    inputs[9..21].copy_from_slice(anchors.as_slice());
    inputs[21] = effects.compliance_per_mn;
    inputs[22] = effects.pulley_radius_m;
    inputs[23..26].copy_from_slice(effects.com_offset_m.as_slice());
    inputs[26] = effects.inverse_segments_squared;
    inputs[27] = effects.platform_weight_n;
    inputs[28] = effects.cable_weight_n_per_m;
    for slot in 0..CABLE_COUNT {
        inputs[29 + 2 * slot] = effects.attachments_m[(0, slot)];
        inputs[30 + 2 * slot] = effects.attachments_m[(1, slot)];
    }
    let evaluate = |out: &mut ExtendedCables, want: bool| {
        *out = extended_cables(values, slots, globals, pose, effects, want);
    };
    memo.read(&inputs, want_jacobians, evaluate, read)
}

/// The Jacobians of `generated::cable_geometry`'s 16 rows.
#[derive(Default)]
struct GeometryJacobians {
    pose: SMatrix<f64, 16, 6>,
    tension: SMatrix<f64, 16, 2>,
    anchors: SMatrix<f64, 16, 12>,
    attachments: SMatrix<f64, 16, 12>,
    com: SMatrix<f64, 16, 3>,
    weight: nalgebra::SVector<f64, 16>,
}

impl GeometryJacobians {
    /// Geometry row `row`'s columns `[pose 6, tension 2, anchors 12, com 3,
    /// platform weight error 1, attachments' horizontal coordinates 8 ([x, y]
    /// per slot)]`; the weight error scales the file's `nominal_platform_weight_n`.
    fn row(&self, row: usize, nominal_platform_weight_n: f64) -> SMatrix<f64, 1, 32> {
        let mut r = SMatrix::<f64, 1, 32>::zeros();
        r.fixed_columns_mut::<6>(0).copy_from(&self.pose.row(row));
        r.fixed_columns_mut::<2>(6).copy_from(&self.tension.row(row));
        r.fixed_columns_mut::<12>(8).copy_from(&self.anchors.row(row));
        r.fixed_columns_mut::<3>(20).copy_from(&self.com.row(row));
        r[23] = self.weight[row] * nominal_platform_weight_n;
        for s in 0..CABLE_COUNT {
            r[24 + 2 * s] = self.attachments[(row, 3 * s)];
            r[25 + 2 * s] = self.attachments[(row, 3 * s + 1)];
        }
        r
    }
}

fn extended_cables(
    values: &Values,
    slots: &SlotOrder,
    globals: &CalibrationVariables,
    pose: &PoseVariables,
    effects: &EffectArguments,
    want_jacobians: bool,
) -> ExtendedCables {
    let (position, rotation) = pose_arguments(values, pose.pose);
    let tension = tension_argument(values, pose.reference_tension);
    let anchors = gather_anchors(values, slots, globals);
    let mut j = GeometryJacobians::default();
    let w = want_jacobians;
    let geometry = generated::cable_geometry(
        &position,
        &rotation,
        &tension,
        &anchors,
        &effects.attachments_m,
        &effects.com_offset_m,
        effects.platform_weight_n,
        EPSILON,
        w.then_some(&mut j.pose),
        w.then_some(&mut j.tension),
        w.then_some(&mut j.anchors),
        w.then_some(&mut j.attachments),
        w.then_some(&mut j.com),
        w.then_some(&mut j.weight),
    );
    let mut out = ExtendedCables {
        paid_out_m: Vector4::zeros(),
        height_residual_m: Vector4::zeros(),
        d_paid_out: SMatrix::zeros(),
        d_height: SMatrix::zeros(),
    };
    for slot in 0..CABLE_COUNT {
        let row = 4 * slot;
        let (mut d_span, mut d_fh, mut d_fv) = (Vector2::zeros(), Vector2::zeros(), Vector2::zeros());
        let (mut d_compliance, mut d_radius, mut d_segments) = (Vector2::zeros(), Vector2::zeros(), Vector2::zeros());
        let mut d_cable_weight = Vector2::zeros();
        let cable = generated::extended_cable(
            geometry[row],
            geometry[row + 1],
            geometry[row + 2],
            effects.cable_weight_n_per_m,
            effects.compliance_per_mn,
            effects.pulley_radius_m,
            effects.inverse_segments_squared,
            EPSILON,
            w.then_some(&mut d_span),
            w.then_some(&mut d_fh),
            w.then_some(&mut d_fv),
            w.then_some(&mut d_compliance),
            w.then_some(&mut d_radius),
            w.then_some(&mut d_segments),
            w.then_some(&mut d_cable_weight),
        );
        out.paid_out_m[slot] = cable[0];
        out.height_residual_m[slot] = cable[1] - geometry[row + 3];
        if !w {
            continue;
        }
        let geometry_row = |k: usize| j.row(row + k, effects.nominal_platform_weight_n);
        let (g_span, g_fh, g_fv, g_h) = (geometry_row(0), geometry_row(1), geometry_row(2), geometry_row(3));
        let paid = g_span * d_span[0] + g_fh * d_fh[0] + g_fv * d_fv[0];
        let height = g_span * d_span[1] + g_fh * d_fh[1] + g_fv * d_fv[1] - g_h;
        out.d_paid_out
            .fixed_view_mut::<1, 23>(slot, 0)
            .copy_from(&paid.fixed_columns::<23>(0));
        out.d_height
            .fixed_view_mut::<1, 23>(slot, 0)
            .copy_from(&height.fixed_columns::<23>(0));
        out.d_paid_out[(slot, 26)] = paid[23];
        out.d_height[(slot, 26)] = height[23];
        out.d_paid_out
            .fixed_view_mut::<1, 8>(slot, 28)
            .copy_from(&paid.fixed_columns::<8>(24));
        out.d_height
            .fixed_view_mut::<1, 8>(slot, 28)
            .copy_from(&height.fixed_columns::<8>(24));
        out.d_paid_out[(slot, 27)] = d_cable_weight[0] * effects.nominal_cable_weight_n_per_m;
        out.d_height[(slot, 27)] = d_cable_weight[1] * effects.nominal_cable_weight_n_per_m;
        out.d_paid_out[(slot, 23)] = d_compliance[0];
        out.d_paid_out[(slot, 24)] = d_radius[0];
        out.d_height[(slot, 23)] = d_compliance[1];
        out.d_height[(slot, 24)] = d_radius[1];
        out.d_paid_out[(slot, 25)] = d_segments[0];
        out.d_height[(slot, 25)] = d_segments[1];
    }
    out
}

/// Where a factor keeps the effect blocks of its Jacobian.
struct EffectBlocks {
    compliance: usize,
    radius: usize,
    com: usize,
    segments: usize,
    platform_weight: usize,
    cable_weight: usize,
    attachments: usize,
}

/// Copy chained columns `[pose, tension, anchors, com, compliance, radius,
/// 1/n^2, platform weight error, cable weight error]`
/// into the blocks `[pose, tension, anchor x4 (robot order), ...]` and the
/// effect blocks at `at`.
fn split_chain(
    jacobian: &SMatrix<f64, 4, CHAIN_COLUMNS>,
    slots: &SlotOrder,
    blocks: &mut [DMatrix<f64>],
    at: EffectBlocks,
) {
    blocks[0].copy_from(&jacobian.fixed_columns::<6>(0));
    blocks[1].copy_from(&jacobian.fixed_columns::<2>(6));
    let anchors: SMatrix<f64, 4, 12> = jacobian.fixed_columns::<12>(8).into_owned();
    split_anchor_jacobian(&anchors, slots, &mut blocks[2..6]);
    blocks[at.com].copy_from(&jacobian.fixed_columns::<2>(20));
    blocks[at.compliance].copy_from(&jacobian.fixed_columns::<1>(23));
    blocks[at.radius].copy_from(&jacobian.fixed_columns::<1>(24));
    blocks[at.segments].copy_from(&jacobian.fixed_columns::<1>(25));
    blocks[at.platform_weight].copy_from(&jacobian.fixed_columns::<1>(26));
    blocks[at.cable_weight].copy_from(&jacobian.fixed_columns::<1>(27));
    // The attachments' shifts: chained in slot order, the variable in cable order.
    for (slot, &cable) in slots.cables.iter().enumerate() {
        for axis in 0..2 {
            blocks[at.attachments]
                .column_mut(2 * cable + axis)
                .copy_from(&jacobian.column(28 + 2 * slot + axis));
        }
    }
}

/// Extended length factor: `(1 + g_i) paid_out_i + l_i^0 - z_i^enc` with the
/// paid-out length of the elastic catenary leaving a pulley
/// (`generated::extended_cable` on `generated::cable_geometry`).
pub struct ExtendedLengthFactor {
    variables: Vec<VariableId>,
    slots: Arc<SlotOrder>,
    globals: CalibrationVariables,
    pose: PoseVariables,
    effects: EffectVariables,
    encoder_lengths_m: Vector4<f64>,
    /// The pose's row (0: order unknown), and each cable's direction of last motion, slot order.
    row: f64,
    direction: Vector4<f64>,
    noise: Noise,
    memo: Arc<ExtendedMemo>,
}

impl ExtendedLengthFactor {
    /// The factor of a pose at `order` (its row and directions of last
    /// motion): the encoder drift and backlash act on it. Without an order
    /// (the default) they do not.
    pub fn at(mut self, order: Option<ReadingOrder>) -> Self {
        if let Some(order) = order {
            self.row = order.row as f64;
            self.direction = Vector4::from_fn(|slot, _| f64::from(order.direction[self.slots.cables[slot]]));
        }
        self
    }

    /// `encoder_lengths_m` in the robot's cable order; `memo` shared with the pose's height factor.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        slots: Arc<SlotOrder>,
        globals: CalibrationVariables,
        effects: EffectVariables,
        pose: PoseVariables,
        encoder_lengths_m: &[f64; CABLE_COUNT],
        sigma_m: f64,
        kernel: RobustKernel,
        memo: Arc<ExtendedMemo>,
    ) -> Self {
        let mut variables = variable_list(&pose, &globals, true, true);
        variables.extend([
            effects.axial_compliance,
            effects.pulley_radius,
            effects.encoder_gain_errors,
            effects.com_shift,
            effects.inverse_segments_squared,
            effects.common_gain_error,
            effects.platform_weight_error,
            effects.cable_weight_error,
            effects.encoder_drift,
            effects.encoder_backlash,
            effects.attachment_shift,
        ]);
        Self {
            variables,
            encoder_lengths_m: slots.to_slots(encoder_lengths_m),
            row: 0.0,
            direction: Vector4::zeros(),
            slots,
            globals,
            pose,
            effects,
            noise: Noise::new(DVector::from_element(CABLE_COUNT, sigma_m), kernel),
            memo,
        }
    }
}

impl Factor for ExtendedLengthFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        let s = &self.slots;
        let e = effect_arguments(values, s, &self.effects);
        let offsets = gather_offsets(values, s, &self.globals);
        let want = jacobians.is_some();
        let read = |cables: &ExtendedCables| self.rows(cables, &e, &offsets, jacobians);
        shared_extended_cables(&self.memo, values, s, &self.globals, &self.pose, &e, want, read)
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "catenary_length"
    }
}

impl ExtendedLengthFactor {
    /// The residual (and blocks) from the pose's extended cables.
    fn rows(
        &self,
        cables: &ExtendedCables,
        e: &EffectArguments,
        offsets: &Vector4<f64>,
        jacobians: Option<&mut [DMatrix<f64>]>,
    ) -> Option<DVector<f64>> {
        let s = &self.slots;
        let scale = Vector4::from_fn(|slot, _| 1.0 + e.gain_errors[slot]);
        // Drift and backlash (`Effects::time_and_motion`), millimetres to metres.
        let time_and_motion = Vector4::from_fn(|slot, _| {
            1e-3 * (e.drift_mm_per_row[slot] * self.row + e.backlash_mm[slot] * self.direction[slot])
        });
        let residual = cables.paid_out_m.component_mul(&scale) + offsets + time_and_motion - self.encoder_lengths_m;
        if let Some(blocks) = jacobians {
            let mut chained = cables.d_paid_out;
            for slot in 0..CABLE_COUNT {
                chained.row_mut(slot).scale_mut(scale[slot]);
            }
            let at = EffectBlocks {
                compliance: 10,
                radius: 11,
                com: 13,
                segments: 14,
                platform_weight: 16,
                cable_weight: 17,
                attachments: 20,
            };
            split_chain(&chained, s, blocks, at);
            blocks[6..10].iter_mut().for_each(|b| b.fill(0.0));
            blocks[12].fill(0.0);
            blocks[18].fill(0.0);
            blocks[19].fill(0.0);
            for (slot, &cable) in s.cables.iter().enumerate() {
                blocks[6 + cable][(slot, 0)] = 1.0;
                blocks[12][(slot, cable)] = cables.paid_out_m[slot];
                blocks[15][(slot, 0)] = cables.paid_out_m[slot];
                blocks[18][(slot, cable)] = 1e-3 * self.row;
                blocks[19][(slot, cable)] = 1e-3 * self.direction[slot];
            }
            rows_to_cables(s, blocks);
        }
        Some(slots_to_cables(s, &residual))
    }
}

/// Extended attachment factor: eq. (15) with the elastic catenary leaving the
/// pulley's exit point (`drop - h` of `generated::extended_cable`).
pub struct ExtendedHeightFactor {
    variables: Vec<VariableId>,
    slots: Arc<SlotOrder>,
    globals: CalibrationVariables,
    pose: PoseVariables,
    effects: EffectVariables,
    noise: Noise,
    memo: Arc<ExtendedMemo>,
}

impl ExtendedHeightFactor {
    /// A height factor with standard deviation `sigma_m` (a model constraint:
    /// small); `memo` shared with the pose's length factor.
    pub fn new(
        slots: Arc<SlotOrder>,
        globals: CalibrationVariables,
        effects: EffectVariables,
        pose: PoseVariables,
        sigma_m: f64,
        memo: Arc<ExtendedMemo>,
    ) -> Self {
        let mut variables = variable_list(&pose, &globals, true, false);
        variables.extend([
            effects.axial_compliance,
            effects.pulley_radius,
            effects.com_shift,
            effects.inverse_segments_squared,
            effects.platform_weight_error,
            effects.cable_weight_error,
            effects.attachment_shift,
        ]);
        Self {
            variables,
            slots,
            globals,
            pose,
            effects,
            noise: Noise::gaussian(DVector::from_element(CABLE_COUNT, sigma_m)),
            memo,
        }
    }
}

impl Factor for ExtendedHeightFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        let s = &self.slots;
        let e = effect_arguments(values, s, &self.effects);
        let want = jacobians.is_some();
        let read = |cables: &ExtendedCables| {
            if let Some(blocks) = jacobians {
                let at = EffectBlocks {
                    compliance: 6,
                    radius: 7,
                    com: 8,
                    segments: 9,
                    platform_weight: 10,
                    cable_weight: 11,
                    attachments: 12,
                };
                split_chain(&cables.d_height, s, blocks, at);
                rows_to_cables(s, blocks);
            }
            Some(slots_to_cables(s, &cables.height_residual_m))
        };
        shared_extended_cables(&self.memo, values, s, &self.globals, &self.pose, &e, want, read)
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "attachment_height"
    }
}

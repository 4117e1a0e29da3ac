//! The localisation equations of one reading at one trial pose, with their
//! analytic Jacobians.
//!
//! The unknowns are the pose (tangent `[dtheta (3), dp (3)]` of the
//! retraction in `model::pose`) and the reference cable's tension
//! `(f_h, f_v)` (paper eq. 11 gives the other three cables' from it). Per
//! cable (slot order, slot 0 = the reference cable), `generated::cable_geometry`
//! gives the span, the end tensions (eq. 5-11) and the anchor's height above
//! the attachment `h`; `generated::extended_cable` the paid-out length and the
//! drop of the (possibly elastic, pulley-wrapped, segmented) catenary
//! (eq. 1-4). The equations are
//!
//! * the attachment heights, `drop_j - h_j = 0` (eq. 15), the model's equations;
//! * the encoders, `gain_j paid_out_j + l0_j - z_enc,j` (eq. 14 with the
//!   calibrated offsets `l0` and the `[effects]` encoder scale);
//! * the load cell, `bias + gain |f_ref| - f_m` (eq. 16 with the `[effects]`
//!   load-cell model), when a reading is given;
//! * the localiser prior `Log(R_prior^-1 R), p - p_prior` (Sec. IV-C.4), only
//!   with `--pose-prior`.
//!
//! The Jacobians are chained exactly as in the extended calibration model
//! (`calib::effect_factors`): `d/d[pose, f_ref]` of the geometry times
//! `d/d[span, f_h, f_v]` of the cable.

use nalgebra::{Matrix2, Matrix3x4, RowSVector, SMatrix, Vector2, Vector3, Vector4, Vector6};

use crate::generated;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};

/// The `epsilon` passed to the generated code (SymForce's default for f64).
pub const EPSILON: f64 = 10.0 * f64::EPSILON;

/// Unknowns of one localisation: pose tangent (6) and reference tension (2).
pub const UNKNOWNS: usize = 8;
/// Measurement rows at most: 4 encoders, the load cell, the 6 prior rows.
pub const MEASUREMENT_ROWS: usize = 11;

/// The calibrated robot in the generated functions' slot order, with its
/// `[effects]` in their argument form.
#[derive(Debug, Clone, PartialEq)]
pub struct SlotRobot {
    /// `cables[slot]` = the robot's cable index; `cables[0]` is the reference cable.
    pub cables: [usize; CABLE_COUNT],
    /// Anchors, world frame, column = slot, metres.
    pub anchors_m: Matrix3x4<f64>,
    /// Attachments, platform frame, column = slot, metres.
    pub attachments_m: Matrix3x4<f64>,
    /// Centre of mass plus the `[effects]` shift, platform frame, metres.
    pub com_offset_m: Vector3<f64>,
    /// Platform weight `m_e g`, newtons.
    pub platform_weight_n: f64,
    /// Cable weight per metre `g_c`, N/m.
    pub cable_weight_n_per_m: f64,
    /// Calibrated encoder offsets `l0`, slot order, metres.
    pub length_offsets_m: Vector4<f64>,
    /// Encoder scale `gain` (1: exact), slot order.
    pub encoder_gains: Vector4<f64>,
    /// `1e6 / EA`, 1/MN (0: inextensible).
    pub compliance_per_mn: f64,
    /// Pulley radius, metres.
    pub pulley_radius_m: f64,
    /// `1 / n^2` of a segmented cable (0: smooth).
    pub inverse_segments_squared: f64,
    /// Load-cell zero-point error, newtons.
    pub load_cell_bias_n: f64,
    /// Load-cell gain (1: exact).
    pub load_cell_gain: f64,
}

impl SlotRobot {
    /// The slot order of `robot` (reference cable first, then the others in
    /// order) with its offsets and `[effects]`.
    pub fn new(robot: &Robot) -> Self {
        let mut cables = [robot.reference_cable; CABLE_COUNT];
        for (slot, cable) in (1..).zip((0..CABLE_COUNT).filter(|&c| c != robot.reference_cable)) {
            cables[slot] = cable;
        }
        let effects = &robot.effects;
        Self {
            cables,
            anchors_m: Matrix3x4::from_fn(|r, s| robot.anchors_m[cables[s]][r]),
            attachments_m: Matrix3x4::from_fn(|r, s| {
                let shift = effects.attachment_shift_m[cables[s]];
                robot.attachments_m[cables[s]][r] + if r < 2 { shift[r] } else { 0.0 }
            }),
            com_offset_m: robot.com_offset_m + Vector3::from(effects.com_shift_m),
            platform_weight_n: robot.platform_weight_n * effects.platform_weight_scale,
            cable_weight_n_per_m: robot.cable_weight_n_per_m * effects.cable_weight_scale,
            length_offsets_m: Vector4::from_fn(|s, _| robot.length_offsets_m[cables[s]]),
            encoder_gains: Vector4::from_fn(|s, _| effects.encoder_gain[cables[s]]),
            compliance_per_mn: effects.axial_compliance_per_mn(),
            pulley_radius_m: effects.pulley_radius_m,
            inverse_segments_squared: effects.inverse_segments_squared(),
            load_cell_bias_n: effects.load_cell_bias_n,
            load_cell_gain: effects.load_cell_gain,
        }
    }

    /// Values in robot cable order -> slot order.
    pub fn to_slots(&self, per_cable: &[f64; CABLE_COUNT]) -> Vector4<f64> {
        Vector4::from_fn(|s, _| per_cable[self.cables[s]])
    }
}

/// What one cable's catenary depends on at the trial pose, for the stiffness
/// at fixed cable lengths (`super::stiffness`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CablePartials {
    /// `d [paid_out, drop] / d [f_h, f_v]`.
    pub d_tension: Matrix2<f64>,
    /// `d [paid_out, drop] / d span`.
    pub d_span: Vector2<f64>,
    /// `d span / d pose`.
    pub span_pose: RowSVector<f64, 6>,
    /// `d h / d pose` (`h` the anchor's height above the attachment).
    pub height_pose: RowSVector<f64, 6>,
}

/// The model at one trial pose and reference tension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelAtPose {
    /// Encoder readings the model predicts, slot order, metres.
    pub encoders_m: Vector4<f64>,
    /// Attachment-height residuals `drop - h` (eq. 15), slot order, metres.
    pub heights_m: Vector4<f64>,
    /// `(f_h, f_v)` at each attachment, slot order, newtons.
    pub tensions_n: [Vector2<f64>; CABLE_COUNT],
    /// The load-cell reading the model predicts, newtons.
    pub load_cell_n: f64,
    /// `d encoders / d [pose (6), f_ref (2)]`.
    pub d_encoders: SMatrix<f64, 4, UNKNOWNS>,
    /// `d heights / d [pose (6), f_ref (2)]`.
    pub d_heights: SMatrix<f64, 4, UNKNOWNS>,
    /// `d load_cell / d [pose (6), f_ref (2)]`.
    pub d_load_cell: RowSVector<f64, UNKNOWNS>,
    /// Per slot, the cable's partial derivatives.
    pub cables: [CablePartials; CABLE_COUNT],
}

/// One cable's `[paid_out, drop]` (eq. 1-4 with the `[effects]`) and its
/// derivatives in the span, `f_h` and `f_v` (`generated::extended_cable`).
fn extended_cable(
    robot: &SlotRobot,
    span: f64,
    f_h: f64,
    f_v: f64,
) -> (Vector2<f64>, Vector2<f64>, Vector2<f64>, Vector2<f64>) {
    let (mut d_span, mut d_fh, mut d_fv) = (Vector2::zeros(), Vector2::zeros(), Vector2::zeros());
    let cable = generated::extended_cable(
        span,
        f_h,
        f_v,
        robot.cable_weight_n_per_m,
        robot.compliance_per_mn,
        robot.pulley_radius_m,
        robot.inverse_segments_squared,
        EPSILON,
        Some(&mut d_span),
        Some(&mut d_fh),
        Some(&mut d_fv),
        None,
        None,
        None,
        None,
    );
    (cable, d_span, d_fh, d_fv)
}

/// Pose as the generated functions take it: position and `[x, y, z, w]`.
pub fn pose_arguments(pose: &PlatformPose) -> (Vector3<f64>, Vector4<f64>) {
    (pose.position_m, pose.rotation_xyzw())
}

/// Evaluate the model at `pose` with the reference tension `reference_n`
/// (`[f_h, f_v]`). `None` where it is undefined: a cable would push
/// (`f_h <= 0`, no catenary) or a value is not finite.
pub fn model_at_pose(robot: &SlotRobot, pose: &PlatformPose, reference_n: &Vector2<f64>) -> Option<ModelAtPose> {
    let (position, rotation) = pose_arguments(pose);
    let mut j_pose = SMatrix::<f64, 16, 6>::zeros();
    let mut j_tension = SMatrix::<f64, 16, 2>::zeros();
    let geometry = generated::cable_geometry(
        &position,
        &rotation,
        reference_n,
        &robot.anchors_m,
        &robot.attachments_m,
        &robot.com_offset_m,
        robot.platform_weight_n,
        EPSILON,
        Some(&mut j_pose),
        Some(&mut j_tension),
        None,
        None,
        None,
        None,
    );
    let mut out = ModelAtPose {
        encoders_m: Vector4::zeros(),
        heights_m: Vector4::zeros(),
        tensions_n: [Vector2::zeros(); CABLE_COUNT],
        load_cell_n: 0.0,
        d_encoders: SMatrix::zeros(),
        d_heights: SMatrix::zeros(),
        d_load_cell: RowSVector::zeros(),
        cables: [CablePartials {
            d_tension: Matrix2::zeros(),
            d_span: Vector2::zeros(),
            span_pose: RowSVector::zeros(),
            height_pose: RowSVector::zeros(),
        }; CABLE_COUNT],
    };
    let row = |k: usize| -> RowSVector<f64, UNKNOWNS> {
        let mut r = RowSVector::<f64, UNKNOWNS>::zeros();
        r.fixed_columns_mut::<6>(0).copy_from(&j_pose.row(k));
        r.fixed_columns_mut::<2>(6).copy_from(&j_tension.row(k));
        r
    };
    for slot in 0..CABLE_COUNT {
        let k = 4 * slot;
        let (span, f_h, f_v, h) = (geometry[k], geometry[k + 1], geometry[k + 2], geometry[k + 3]);
        if !(f_h > 0.0 && span.is_finite() && f_v.is_finite() && h.is_finite()) {
            return None;
        }
        let (cable, d_span, d_fh, d_fv) = extended_cable(robot, span, f_h, f_v);
        let gain = robot.encoder_gains[slot];
        out.encoders_m[slot] = gain * cable[0] + robot.length_offsets_m[slot];
        out.heights_m[slot] = cable[1] - h;
        out.tensions_n[slot] = Vector2::new(f_h, f_v);
        let (g_span, g_fh, g_fv, g_h) = (row(k), row(k + 1), row(k + 2), row(k + 3));
        let paid = g_span * d_span[0] + g_fh * d_fh[0] + g_fv * d_fv[0];
        out.d_encoders.set_row(slot, &(paid * gain));
        out.d_heights
            .set_row(slot, &(g_span * d_span[1] + g_fh * d_fh[1] + g_fv * d_fv[1] - g_h));
        out.cables[slot] = CablePartials {
            d_tension: Matrix2::new(d_fh[0], d_fv[0], d_fh[1], d_fv[1]),
            d_span,
            span_pose: j_pose.fixed_view::<1, 6>(k, 0).into_owned(),
            height_pose: j_pose.fixed_view::<1, 6>(k + 3, 0).into_owned(),
        };
    }
    if !(out.encoders_m.iter().chain(out.heights_m.iter()).all(|v| v.is_finite())) {
        return None;
    }
    let reference = out.tensions_n[0];
    let magnitude = reference.norm();
    out.load_cell_n = robot.load_cell_bias_n + robot.load_cell_gain * magnitude;
    let d_magnitude = row(1) * (reference[0] / magnitude) + row(2) * (reference[1] / magnitude);
    out.d_load_cell = d_magnitude * robot.load_cell_gain;
    Some(out)
}

/// The localiser prior's residual `[Log(R_prior^-1 R); p - p_prior]` and its
/// Jacobian in the pose tangent (`generated::pose_prior_residual`).
pub fn prior_residual(pose: &PlatformPose, prior: &PlatformPose) -> (Vector6<f64>, SMatrix<f64, 6, 6>) {
    let (position, rotation) = pose_arguments(pose);
    let (prior_position, prior_rotation) = pose_arguments(prior);
    let mut jacobian = SMatrix::<f64, 6, 6>::zeros();
    let r = generated::pose_prior_residual(
        &position,
        &rotation,
        &prior_position,
        &prior_rotation,
        EPSILON,
        Some(&mut jacobian),
    );
    (r, jacobian)
}

/// Number of calibrated parameters in slot order: the anchors of slots
/// 0..3 (x, y, z each), then the offsets of slots 0..3.
pub const PARAMETERS: usize = 16;

/// How the equations move with the calibrated parameters (slot order, see
/// [`PARAMETERS`]) at one pose: what carries the calibration's uncertainty
/// into the localised pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParameterPartials {
    /// `d encoders / d parameters`.
    pub d_encoders: SMatrix<f64, 4, PARAMETERS>,
    /// `d heights / d parameters` (the offsets do not enter the heights).
    pub d_heights: SMatrix<f64, 4, PARAMETERS>,
    /// `d load_cell / d parameters`.
    pub d_load_cell: RowSVector<f64, PARAMETERS>,
}

/// The equations' partial derivatives in the anchors and offsets at `pose`
/// and `reference_n`, chained as in [`model_at_pose`] through
/// `generated::cable_geometry`'s anchor Jacobian: `encoder_j = gain_j
/// paid_out_j(span, f_h, f_v) + l0_j` (eq. 14), `drop_j - h_j` (eq. 15),
/// `|f_ref|` (eq. 16). `None` where the model is undefined.
pub fn parameter_partials(
    robot: &SlotRobot,
    pose: &PlatformPose,
    reference_n: &Vector2<f64>,
) -> Option<ParameterPartials> {
    let (position, rotation) = pose_arguments(pose);
    let mut j_anchors = SMatrix::<f64, 16, 12>::zeros();
    let geometry = generated::cable_geometry(
        &position,
        &rotation,
        reference_n,
        &robot.anchors_m,
        &robot.attachments_m,
        &robot.com_offset_m,
        robot.platform_weight_n,
        EPSILON,
        None,
        None,
        Some(&mut j_anchors),
        None,
        None,
        None,
    );
    let mut out = ParameterPartials {
        d_encoders: SMatrix::zeros(),
        d_heights: SMatrix::zeros(),
        d_load_cell: RowSVector::zeros(),
    };
    let row = |k: usize| -> RowSVector<f64, PARAMETERS> {
        let mut r = RowSVector::<f64, PARAMETERS>::zeros();
        r.fixed_columns_mut::<12>(0).copy_from(&j_anchors.row(k));
        r
    };
    for slot in 0..CABLE_COUNT {
        let k = 4 * slot;
        let (span, f_h, f_v) = (geometry[k], geometry[k + 1], geometry[k + 2]);
        if !(f_h > 0.0 && span.is_finite() && f_v.is_finite()) {
            return None;
        }
        let (_, d_span, d_fh, d_fv) = extended_cable(robot, span, f_h, f_v);
        let (g_span, g_fh, g_fv, g_h) = (row(k), row(k + 1), row(k + 2), row(k + 3));
        let mut encoder = (g_span * d_span[0] + g_fh * d_fh[0] + g_fv * d_fv[0]) * robot.encoder_gains[slot];
        encoder[12 + slot] = 1.0;
        out.d_encoders.set_row(slot, &encoder);
        out.d_heights
            .set_row(slot, &(g_span * d_span[1] + g_fh * d_fh[1] + g_fv * d_fv[1] - g_h));
    }
    let (f_h, f_v) = (geometry[1], geometry[2]);
    let magnitude = f_h.hypot(f_v);
    out.d_load_cell = (row(1) * (f_h / magnitude) + row(2) * (f_v / magnitude)) * robot.load_cell_gain;
    Some(out)
}

//! Calls of every generated function (`generated/`) from one [`Point`] that holds all their
//! arguments, with the Jacobians requested into caller-supplied buffers (`Some`) or not (`None`).
//!
//! Shared by `tests/generated_jacobians.rs` and `benches/jacobians.rs` (each includes this file
//! with `#[path]`), so that the argument lists of the generated functions are written once.
//! `extended_cable` is called for the four cables of a point and stacked.

// Each includer uses a different part of this file.
#![allow(dead_code)]

use nalgebra::{DMatrix, Matrix3x4, SMatrix, SVector, Vector2, Vector3, Vector4};
use sagcal::calib::factors::EPSILON;
use sagcal::generated;
use sagcal::model::PlatformPose;

/// A fixed-size Jacobian block.
pub type M<const R: usize, const C: usize> = SMatrix<f64, R, C>;

/// All arguments of the generated functions.
#[derive(Clone, Debug)]
pub struct Point {
    pub pose: PlatformPose,
    pub reference_tension_n: Vector2<f64>,
    pub anchors_m: Matrix3x4<f64>,
    pub attachments_m: Matrix3x4<f64>,
    pub com_offset_m: Vector3<f64>,
    pub platform_weight_n: f64,
    pub cable_weight_n_per_m: f64,
    pub length_offsets_m: Vector4<f64>,
    pub encoder_lengths_m: Vector4<f64>,
    pub prior: PlatformPose,
    pub measured_tension_n: f64,
    /// Per slot the scalar arguments of `extended_cable`: span (m), `f_h`, `f_v` (N); the
    /// caller takes them from `cable_geometry` at this point.
    pub cable_spans_m: Vector4<f64>,
    pub cable_horizontal_tensions_n: Vector4<f64>,
    pub cable_vertical_tensions_n: Vector4<f64>,
    /// `1e6 / EA`, 1/MN, shared by the four cables.
    pub axial_compliance_per_mn: f64,
    /// Pulley radius, metres, shared by the four pulleys.
    pub pulley_radius_m: f64,
    /// `1/n^2` of a cable of `n` straight elements, shared by the four cables.
    pub inverse_segments_squared: f64,
    pub load_cell_bias_n: f64,
    pub load_cell_gain_error: f64,
    /// The localiser's mounting rotation vector, radians.
    pub localiser_mount_rad: Vector3<f64>,
}

// Each generated function at a point, with all its Jacobians (`Some`) or none.

pub fn tensions(p: &Point, j: Option<&mut (M<8, 6>, M<8, 2>, M<8, 12>)>) -> SVector<f64, 8> {
    let (pose, reference, anchors) = match j {
        Some((a, b, c)) => (Some(a), Some(b), Some(c)),
        None => (None, None, None),
    };
    generated::cable_tensions_from_reference(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.reference_tension_n,
        &p.anchors_m,
        &p.attachments_m,
        &p.com_offset_m,
        p.platform_weight_n,
        EPSILON,
        pose,
        reference,
        anchors,
    )
}

pub fn catenary_length(p: &Point, j: Option<&mut (M<4, 6>, M<4, 2>, M<4, 12>, M<4, 4>)>) -> SVector<f64, 4> {
    let (pose, reference, anchors, offsets) = match j {
        Some((a, b, c, d)) => (Some(a), Some(b), Some(c), Some(d)),
        None => (None, None, None, None),
    };
    generated::catenary_length_residual(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.reference_tension_n,
        &p.anchors_m,
        &p.attachments_m,
        &p.com_offset_m,
        p.platform_weight_n,
        p.cable_weight_n_per_m,
        &p.length_offsets_m,
        &p.encoder_lengths_m,
        EPSILON,
        pose,
        reference,
        anchors,
        offsets,
    )
}

/// The Jacobian blocks of `catenary_cable_residuals`: pose, reference tension, anchors, offsets.
pub type CatenaryCableJacobians = (M<16, 6>, M<16, 2>, M<16, 12>, M<16, 4>);

pub fn catenary_cable(p: &Point, j: Option<&mut CatenaryCableJacobians>) -> SVector<f64, 16> {
    let (pose, reference, anchors, offsets) = match j {
        Some((a, b, c, d)) => (Some(a), Some(b), Some(c), Some(d)),
        None => (None, None, None, None),
    };
    generated::catenary_cable_residuals(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.reference_tension_n,
        &p.anchors_m,
        &p.attachments_m,
        &p.com_offset_m,
        p.platform_weight_n,
        p.cable_weight_n_per_m,
        &p.length_offsets_m,
        &p.encoder_lengths_m,
        EPSILON,
        pose,
        reference,
        anchors,
        offsets,
    )
}

pub fn attachment_height(p: &Point, j: Option<&mut (M<4, 6>, M<4, 2>, M<4, 12>)>) -> SVector<f64, 4> {
    let (pose, reference, anchors) = match j {
        Some((a, b, c)) => (Some(a), Some(b), Some(c)),
        None => (None, None, None),
    };
    generated::attachment_height_residual(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.reference_tension_n,
        &p.anchors_m,
        &p.attachments_m,
        &p.com_offset_m,
        p.platform_weight_n,
        p.cable_weight_n_per_m,
        EPSILON,
        pose,
        reference,
        anchors,
    )
}

pub fn reference_tension(p: &Point, j: Option<&mut M<1, 2>>) -> SVector<f64, 1> {
    generated::reference_tension_residual(&p.reference_tension_n, p.measured_tension_n, EPSILON, j)
}

pub fn pose_prior(p: &Point, j: Option<&mut M<6, 6>>) -> SVector<f64, 6> {
    generated::pose_prior_residual(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.prior.position_m,
        &p.prior.rotation_xyzw(),
        EPSILON,
        j,
    )
}

pub fn mounted_pose_prior(p: &Point, j: Option<&mut (M<6, 6>, M<6, 3>)>) -> SVector<f64, 6> {
    let (pose, mount) = match j {
        Some((a, b)) => (Some(a), Some(b)),
        None => (None, None),
    };
    generated::mounted_pose_prior_residual(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.prior.position_m,
        &p.prior.rotation_xyzw(),
        &p.localiser_mount_rad,
        EPSILON,
        pose,
        mount,
    )
}

pub fn rigid_length(p: &Point, j: Option<&mut (M<4, 6>, M<4, 12>, M<4, 4>)>) -> SVector<f64, 4> {
    let (pose, anchors, offsets) = match j {
        Some((a, b, c)) => (Some(a), Some(b), Some(c)),
        None => (None, None, None),
    };
    generated::rigid_length_residual(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.anchors_m,
        &p.attachments_m,
        &p.length_offsets_m,
        &p.encoder_lengths_m,
        EPSILON,
        pose,
        anchors,
        offsets,
    )
}

/// The Jacobians of `cable_geometry`: pose, reference tension, anchors, centre of mass, platform weight.
pub type GeometryJacobians = (M<16, 6>, M<16, 2>, M<16, 12>, M<16, 12>, M<16, 3>, M<16, 1>);

pub fn geometry(p: &Point, j: Option<&mut GeometryJacobians>) -> SVector<f64, 16> {
    let (pose, reference, anchors, attachments, com, weight) = match j {
        Some((a, b, c, d, e, f)) => (Some(a), Some(b), Some(c), Some(d), Some(e), Some(f)),
        None => (None, None, None, None, None, None),
    };
    generated::cable_geometry(
        &p.pose.position_m,
        &p.pose.rotation_xyzw(),
        &p.reference_tension_n,
        &p.anchors_m,
        &p.attachments_m,
        &p.com_offset_m,
        p.platform_weight_n,
        EPSILON,
        pose,
        reference,
        anchors,
        attachments,
        com,
        weight,
    )
}

/// The Jacobians of [`geometry`] as dynamic blocks, in argument order.
pub fn geometry_blocks(j: &GeometryJacobians) -> Vec<DMatrix<f64>> {
    vec![
        dynamic(&j.0),
        dynamic(&j.1),
        dynamic(&j.2),
        dynamic(&j.3),
        dynamic(&j.4),
        dynamic(&j.5),
    ]
}

/// Per slot the 2x1 Jacobians of `extended_cable`: span, `f_h`, `f_v`, compliance, radius,
/// `1/n^2`, cable weight.
pub type ExtendedJacobians = [(M<2, 1>, M<2, 1>, M<2, 1>, M<2, 1>, M<2, 1>, M<2, 1>, M<2, 1>); 4];

/// `extended_cable` of the four slots stacked: `[paid_out_0, drop_0, paid_out_1, ...]`.
pub fn extended(p: &Point, mut j: Option<&mut ExtendedJacobians>) -> SVector<f64, 8> {
    let mut value = SVector::<f64, 8>::zeros();
    for s in 0..4 {
        let (span, horizontal, vertical, compliance, radius, segments, weight) = match j.as_deref_mut() {
            Some(j) => {
                let (a, b, c, d, e, f, g) = &mut j[s];
                (Some(a), Some(b), Some(c), Some(d), Some(e), Some(f), Some(g))
            }
            None => (None, None, None, None, None, None, None),
        };
        let cable = generated::extended_cable(
            p.cable_spans_m[s],
            p.cable_horizontal_tensions_n[s],
            p.cable_vertical_tensions_n[s],
            p.cable_weight_n_per_m,
            p.axial_compliance_per_mn,
            p.pulley_radius_m,
            p.inverse_segments_squared,
            EPSILON,
            span,
            horizontal,
            vertical,
            compliance,
            radius,
            segments,
            weight,
        );
        value.fixed_rows_mut::<2>(2 * s).copy_from(&cable);
    }
    value
}

/// The per-slot Jacobians of [`extended`] as blocks of the stacked value: span, `f_h` and `f_v`
/// (8x4, block diagonal), compliance, radius and `1/n^2` (8x1).
pub fn extended_blocks(j: &ExtendedJacobians) -> Vec<DMatrix<f64>> {
    let mut blocks = vec![DMatrix::zeros(8, 4), DMatrix::zeros(8, 4), DMatrix::zeros(8, 4)];
    blocks.extend([
        DMatrix::zeros(8, 1),
        DMatrix::zeros(8, 1),
        DMatrix::zeros(8, 1),
        DMatrix::zeros(8, 1),
    ]);
    for (s, (span, horizontal, vertical, compliance, radius, segments, weight)) in j.iter().enumerate() {
        for (b, d) in [span, horizontal, vertical].into_iter().enumerate() {
            blocks[b].view_mut((2 * s, s), (2, 1)).copy_from(d);
        }
        blocks[3].view_mut((2 * s, 0), (2, 1)).copy_from(compliance);
        blocks[4].view_mut((2 * s, 0), (2, 1)).copy_from(radius);
        blocks[5].view_mut((2 * s, 0), (2, 1)).copy_from(segments);
        blocks[6].view_mut((2 * s, 0), (2, 1)).copy_from(weight);
    }
    blocks
}

pub fn load_cell(p: &Point, j: Option<&mut (M<1, 2>, M<1, 1>, M<1, 1>)>) -> SVector<f64, 1> {
    let (reference, bias, gain) = match j {
        Some((a, b, c)) => (Some(a), Some(b), Some(c)),
        None => (None, None, None),
    };
    generated::load_cell_residual(
        &p.reference_tension_n,
        p.load_cell_bias_n,
        p.load_cell_gain_error,
        p.measured_tension_n,
        EPSILON,
        reference,
        bias,
        gain,
    )
}

/// A fixed-size block as a dynamic matrix.
pub fn dynamic<const R: usize, const C: usize>(m: &M<R, C>) -> DMatrix<f64> {
    DMatrix::from_column_slice(R, C, m.as_slice())
}

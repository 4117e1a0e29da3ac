//! Snapshots of the generated code (`generated/`) and of every generated function's outputs.
//!
//! The source snapshots make any change of the emitted Rust visible in review;
//! the output snapshots pin the values at one fixed large-robot configuration.
//! Numbers are printed with 12 significant digits (entries below `1e-9` of
//! their block's largest entry as 0), so that ulp-level differences between
//! platforms do not matter. Update with
//! `INSTA_UPDATE=always cargo test --test generated_snapshots` and review the diff.

use std::fmt::Write;

use nalgebra::{Matrix3x4, SMatrix, Vector2, Vector3, Vector4, Vector6};
use sagcal::generated;
use sagcal::model::{PlatformPose, Robot};

/// SymForce's default epsilon (`sym::kDefaultEpsilon`).
const EPSILON: f64 = 10.0 * f64::EPSILON;

#[test]
fn generated_sources() {
    let sources = [
        ("mod", include_str!("../generated/mod.rs")),
        (
            "cable_tensions_from_reference",
            include_str!("../generated/cable_tensions_from_reference.rs"),
        ),
        (
            "catenary_length_residual",
            include_str!("../generated/catenary_length_residual.rs"),
        ),
        (
            "attachment_height_residual",
            include_str!("../generated/attachment_height_residual.rs"),
        ),
        (
            "catenary_cable_residuals",
            include_str!("../generated/catenary_cable_residuals.rs"),
        ),
        (
            "reference_tension_residual",
            include_str!("../generated/reference_tension_residual.rs"),
        ),
        (
            "pose_prior_residual",
            include_str!("../generated/pose_prior_residual.rs"),
        ),
        (
            "mounted_pose_prior_residual",
            include_str!("../generated/mounted_pose_prior_residual.rs"),
        ),
        (
            "rigid_length_residual",
            include_str!("../generated/rigid_length_residual.rs"),
        ),
        ("cable_geometry", include_str!("../generated/cable_geometry.rs")),
        ("extended_cable", include_str!("../generated/extended_cable.rs")),
        ("load_cell_residual", include_str!("../generated/load_cell_residual.rs")),
        (
            "suspended_cable_residual",
            include_str!("../generated/suspended_cable_residual.rs"),
        ),
        (
            "suspended_elastic_cable_residual",
            include_str!("../generated/suspended_elastic_cable_residual.rs"),
        ),
        ("cable_wrench", include_str!("../generated/cable_wrench.rs")),
        (
            "platform_weight_wrench",
            include_str!("../generated/platform_weight_wrench.rs"),
        ),
        (
            "straight_cable_residual",
            include_str!("../generated/straight_cable_residual.rs"),
        ),
    ];
    for (name, source) in sources {
        insta::assert_snapshot!(format!("source_{name}"), source);
    }
}

/// The fixed inputs: the large robot in slot order, a pose off centre with a small rotation.
struct Inputs {
    pose: PlatformPose,
    prior: PlatformPose,
    reference_tension_n: Vector2<f64>,
    anchors_m: Matrix3x4<f64>,
    attachments_m: Matrix3x4<f64>,
    com_offset_m: Vector3<f64>,
    platform_weight_n: f64,
    cable_weight_n_per_m: f64,
    length_offsets_m: Vector4<f64>,
    encoder_lengths_m: Vector4<f64>,
    measured_tension_n: f64,
    axial_compliance_per_mn: f64,
    pulley_radius_m: f64,
    inverse_segments_squared: f64,
    load_cell_bias_n: f64,
    load_cell_gain_error: f64,
}

fn inputs() -> Inputs {
    let robot = Robot::builtin("large").unwrap();
    let reference = robot.reference_cable;
    let order: Vec<usize> = std::iter::once(reference)
        .chain((0..4).filter(|&c| c != reference))
        .collect();
    let pose = PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(5.0, -3.0, 10.0), 1.5, -2.0, 0.5);
    Inputs {
        pose,
        prior: pose.retract(&Vector6::new(0.01, -0.02, 0.005, 0.03, -0.01, 0.02)),
        reference_tension_n: Vector2::new(600.0, 90.0),
        anchors_m: Matrix3x4::from_columns(&[0, 1, 2, 3].map(|slot| robot.anchors_m[order[slot]])),
        attachments_m: Matrix3x4::from_columns(&[0, 1, 2, 3].map(|slot| robot.attachments_m[order[slot]])),
        com_offset_m: robot.com_offset_m,
        platform_weight_n: robot.platform_weight_n,
        cable_weight_n_per_m: robot.cable_weight_n_per_m,
        length_offsets_m: Vector4::new(0.5, -0.3, 0.2, 0.1),
        encoder_lengths_m: Vector4::new(175.0, 170.0, 160.0, 165.0),
        measured_tension_n: 610.0,
        axial_compliance_per_mn: 0.8,
        pulley_radius_m: 0.12,
        inverse_segments_squared: 1.0 / 400.0,
        load_cell_bias_n: 1.5,
        load_cell_gain_error: -0.02,
    }
}

/// A matrix with 12 significant digits, one row per line.
fn format_block<const R: usize, const C: usize>(out: &mut String, name: &str, m: &SMatrix<f64, R, C>) {
    let scale = m.amax();
    writeln!(out, "{name} ({R}x{C}):").unwrap();
    for row in m.row_iter() {
        let cells: Vec<String> = row
            .iter()
            .map(|&x| {
                if x.abs() <= 1e-9 * scale {
                    "0".to_string()
                } else {
                    format!("{x:.11e}")
                }
            })
            .collect();
        writeln!(out, "  {}", cells.join("  ")).unwrap();
    }
}

fn nan<const R: usize, const C: usize>() -> SMatrix<f64, R, C> {
    SMatrix::from_element(f64::NAN)
}

#[test]
fn cable_tensions_from_reference_outputs() {
    let x = inputs();
    let (mut pose, mut reference, mut anchors) = (nan::<8, 6>(), nan::<8, 2>(), nan::<8, 12>());
    let value = generated::cable_tensions_from_reference(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m,
        &x.attachments_m,
        &x.com_offset_m,
        x.platform_weight_n,
        EPSILON,
        Some(&mut pose),
        Some(&mut reference),
        Some(&mut anchors),
    );
    let mut out = String::new();
    format_block(&mut out, "tensions_n", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_reference_tension", &reference);
    format_block(&mut out, "jacobian_anchors", &anchors);
    insta::assert_snapshot!(out);
}

#[test]
fn catenary_cable_residuals_outputs() {
    let x = inputs();
    let (mut pose, mut reference, mut anchors, mut offsets) =
        (nan::<16, 6>(), nan::<16, 2>(), nan::<16, 12>(), nan::<16, 4>());
    let value = generated::catenary_cable_residuals(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m,
        &x.attachments_m,
        &x.com_offset_m,
        x.platform_weight_n,
        x.cable_weight_n_per_m,
        &x.length_offsets_m,
        &x.encoder_lengths_m,
        EPSILON,
        Some(&mut pose),
        Some(&mut reference),
        Some(&mut anchors),
        Some(&mut offsets),
    );
    let mut out = String::new();
    format_block(&mut out, "rows", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_reference_tension", &reference);
    format_block(&mut out, "jacobian_anchors", &anchors);
    format_block(&mut out, "jacobian_length_offsets", &offsets);
    insta::assert_snapshot!(out);
}

#[test]
fn catenary_length_residual_outputs() {
    let x = inputs();
    let (mut pose, mut reference, mut anchors, mut offsets) =
        (nan::<4, 6>(), nan::<4, 2>(), nan::<4, 12>(), nan::<4, 4>());
    let value = generated::catenary_length_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m,
        &x.attachments_m,
        &x.com_offset_m,
        x.platform_weight_n,
        x.cable_weight_n_per_m,
        &x.length_offsets_m,
        &x.encoder_lengths_m,
        EPSILON,
        Some(&mut pose),
        Some(&mut reference),
        Some(&mut anchors),
        Some(&mut offsets),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_reference_tension", &reference);
    format_block(&mut out, "jacobian_anchors", &anchors);
    format_block(&mut out, "jacobian_length_offsets", &offsets);
    insta::assert_snapshot!(out);
}

#[test]
fn attachment_height_residual_outputs() {
    let x = inputs();
    let (mut pose, mut reference, mut anchors) = (nan::<4, 6>(), nan::<4, 2>(), nan::<4, 12>());
    let value = generated::attachment_height_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m,
        &x.attachments_m,
        &x.com_offset_m,
        x.platform_weight_n,
        x.cable_weight_n_per_m,
        EPSILON,
        Some(&mut pose),
        Some(&mut reference),
        Some(&mut anchors),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_reference_tension", &reference);
    format_block(&mut out, "jacobian_anchors", &anchors);
    insta::assert_snapshot!(out);
}

#[test]
fn reference_tension_residual_outputs() {
    let x = inputs();
    let mut reference = nan::<1, 2>();
    let value = generated::reference_tension_residual(
        &x.reference_tension_n,
        x.measured_tension_n,
        EPSILON,
        Some(&mut reference),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_reference_tension", &reference);
    insta::assert_snapshot!(out);
}

#[test]
fn pose_prior_residual_outputs() {
    let x = inputs();
    let mut pose = nan::<6, 6>();
    let value = generated::pose_prior_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.prior.position_m,
        &x.prior.rotation_xyzw(),
        EPSILON,
        Some(&mut pose),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    insta::assert_snapshot!(out);
}

#[test]
fn mounted_pose_prior_residual_outputs() {
    let x = inputs();
    let (mut pose, mut mount) = (nan::<6, 6>(), nan::<6, 3>());
    let value = generated::mounted_pose_prior_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.prior.position_m,
        &x.prior.rotation_xyzw(),
        &Vector3::new(0.02, -0.01, 0.015),
        EPSILON,
        Some(&mut pose),
        Some(&mut mount),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_localiser_mount", &mount);
    insta::assert_snapshot!(out);
}

#[test]
fn rigid_length_residual_outputs() {
    let x = inputs();
    let (mut pose, mut anchors, mut offsets) = (nan::<4, 6>(), nan::<4, 12>(), nan::<4, 4>());
    let value = generated::rigid_length_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.anchors_m,
        &x.attachments_m,
        &x.length_offsets_m,
        &x.encoder_lengths_m,
        EPSILON,
        Some(&mut pose),
        Some(&mut anchors),
        Some(&mut offsets),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_anchors", &anchors);
    format_block(&mut out, "jacobian_length_offsets", &offsets);
    insta::assert_snapshot!(out);
}

#[test]
fn cable_geometry_outputs() {
    let x = inputs();
    let (mut pose, mut reference, mut anchors, mut attachments, mut com, mut weight) = (
        nan::<16, 6>(),
        nan::<16, 2>(),
        nan::<16, 12>(),
        nan::<16, 12>(),
        nan::<16, 3>(),
        nan::<16, 1>(),
    );
    let value = generated::cable_geometry(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m,
        &x.attachments_m,
        &x.com_offset_m,
        x.platform_weight_n,
        EPSILON,
        Some(&mut pose),
        Some(&mut reference),
        Some(&mut anchors),
        Some(&mut attachments),
        Some(&mut com),
        Some(&mut weight),
    );
    let mut out = String::new();
    format_block(&mut out, "geometry", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_reference_tension", &reference);
    format_block(&mut out, "jacobian_anchors", &anchors);
    format_block(&mut out, "jacobian_attachments", &attachments);
    format_block(&mut out, "jacobian_com_offset", &com);
    format_block(&mut out, "jacobian_platform_weight", &weight);
    insta::assert_snapshot!(out);
}

/// Every slot's cable at the fixed configuration (span and tensions from `cable_geometry`), with
/// the fixed compliance and pulley radius.
#[test]
fn extended_cable_outputs() {
    let x = inputs();
    let geometry = generated::cable_geometry(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m,
        &x.attachments_m,
        &x.com_offset_m,
        x.platform_weight_n,
        EPSILON,
        None,
        None,
        None,
        None,
        None,
        None,
    );
    let mut out = String::new();
    for slot in 0..4 {
        let (mut span, mut horizontal, mut vertical, mut compliance, mut radius, mut segments, mut weight) = (
            nan::<2, 1>(),
            nan::<2, 1>(),
            nan::<2, 1>(),
            nan::<2, 1>(),
            nan::<2, 1>(),
            nan::<2, 1>(),
            nan::<2, 1>(),
        );
        let value = generated::extended_cable(
            geometry[4 * slot],
            geometry[4 * slot + 1],
            geometry[4 * slot + 2],
            x.cable_weight_n_per_m,
            x.axial_compliance_per_mn,
            x.pulley_radius_m,
            x.inverse_segments_squared,
            EPSILON,
            Some(&mut span),
            Some(&mut horizontal),
            Some(&mut vertical),
            Some(&mut compliance),
            Some(&mut radius),
            Some(&mut segments),
            Some(&mut weight),
        );
        writeln!(out, "slot {slot}:").unwrap();
        format_block(&mut out, "cable", &value);
        format_block(&mut out, "jacobian_span", &span);
        format_block(&mut out, "jacobian_horizontal_tension", &horizontal);
        format_block(&mut out, "jacobian_vertical_tension", &vertical);
        format_block(&mut out, "jacobian_axial_compliance", &compliance);
        format_block(&mut out, "jacobian_pulley_radius", &radius);
        format_block(&mut out, "jacobian_inverse_segments_squared", &segments);
        format_block(&mut out, "jacobian_cable_weight", &weight);
    }
    insta::assert_snapshot!(out);
}

#[test]
fn load_cell_residual_outputs() {
    let x = inputs();
    let (mut reference, mut bias, mut gain) = (nan::<1, 2>(), nan::<1, 1>(), nan::<1, 1>());
    let value = generated::load_cell_residual(
        &x.reference_tension_n,
        x.load_cell_bias_n,
        x.load_cell_gain_error,
        x.measured_tension_n,
        EPSILON,
        Some(&mut reference),
        Some(&mut bias),
        Some(&mut gain),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_reference_tension", &reference);
    format_block(&mut out, "jacobian_load_cell_bias", &bias);
    format_block(&mut out, "jacobian_load_cell_gain_error", &gain);
    insta::assert_snapshot!(out);
}

#[test]
fn suspended_cable_residual_outputs() {
    let x = inputs();
    let (mut pose, mut tension, mut anchor, mut offset) = (nan::<2, 6>(), nan::<2, 2>(), nan::<2, 3>(), nan::<2, 1>());
    let value = generated::suspended_cable_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m.column(1).into_owned(),
        &x.attachments_m.column(1).into_owned(),
        x.cable_weight_n_per_m,
        x.length_offsets_m[1],
        x.encoder_lengths_m[1],
        EPSILON,
        Some(&mut pose),
        Some(&mut tension),
        Some(&mut anchor),
        Some(&mut offset),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_cable_tension", &tension);
    format_block(&mut out, "jacobian_anchor", &anchor);
    format_block(&mut out, "jacobian_length_offset", &offset);
    insta::assert_snapshot!(out);
}

#[test]
fn suspended_elastic_cable_residual_outputs() {
    let x = inputs();
    let (mut pose, mut tension, mut anchor, mut offset, mut compliance) = (
        nan::<2, 6>(),
        nan::<2, 2>(),
        nan::<2, 3>(),
        nan::<2, 1>(),
        nan::<2, 1>(),
    );
    let value = generated::suspended_elastic_cable_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m.column(1).into_owned(),
        &x.attachments_m.column(1).into_owned(),
        x.cable_weight_n_per_m,
        2.0,
        x.length_offsets_m[1],
        x.encoder_lengths_m[1],
        EPSILON,
        Some(&mut pose),
        Some(&mut tension),
        Some(&mut anchor),
        Some(&mut offset),
        Some(&mut compliance),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_cable_tension", &tension);
    format_block(&mut out, "jacobian_anchor", &anchor);
    format_block(&mut out, "jacobian_length_offset", &offset);
    format_block(&mut out, "jacobian_axial_compliance", &compliance);
    insta::assert_snapshot!(out);
}

#[test]
fn cable_wrench_outputs() {
    let x = inputs();
    let (mut pose, mut tension, mut anchor) = (nan::<6, 6>(), nan::<6, 2>(), nan::<6, 3>());
    let value = generated::cable_wrench(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.reference_tension_n,
        &x.anchors_m.column(1).into_owned(),
        &x.attachments_m.column(1).into_owned(),
        EPSILON,
        Some(&mut pose),
        Some(&mut tension),
        Some(&mut anchor),
    );
    let mut out = String::new();
    format_block(&mut out, "wrench", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_cable_tension", &tension);
    format_block(&mut out, "jacobian_anchor", &anchor);
    insta::assert_snapshot!(out);
}

#[test]
fn platform_weight_wrench_outputs() {
    let x = inputs();
    let mut rotation = nan::<6, 3>();
    let value = generated::platform_weight_wrench(
        &x.pose.rotation_xyzw(),
        &x.com_offset_m,
        x.platform_weight_n,
        Some(&mut rotation),
    );
    let mut out = String::new();
    format_block(&mut out, "wrench", &value);
    format_block(&mut out, "jacobian_rotation", &rotation);
    insta::assert_snapshot!(out);
}

#[test]
fn straight_cable_residual_outputs() {
    let x = inputs();
    let (mut pose, mut anchor, mut offset) = (nan::<1, 6>(), nan::<1, 3>(), nan::<1, 1>());
    let value = generated::straight_cable_residual(
        &x.pose.position_m,
        &x.pose.rotation_xyzw(),
        &x.anchors_m.column(1).into_owned(),
        &x.attachments_m.column(1).into_owned(),
        x.length_offsets_m[1],
        x.encoder_lengths_m[1],
        EPSILON,
        Some(&mut pose),
        Some(&mut anchor),
        Some(&mut offset),
    );
    let mut out = String::new();
    format_block(&mut out, "residual", &value);
    format_block(&mut out, "jacobian_pose", &pose);
    format_block(&mut out, "jacobian_anchor", &anchor);
    format_block(&mut out, "jacobian_length_offset", &offset);
    insta::assert_snapshot!(out);
}

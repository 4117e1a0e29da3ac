//! The evaluation floor of one iteration (issue 18): per pose, the generated
//! residuals of its factors with every Jacobian block, called once, as any
//! solver that uses them must per linearisation. Counted with callgrind
//! (`sagcal-peers --count floor`) and set against each solver's instructions
//! per pose per iteration.
//!
//! Per pose: `catenary_length_residual` (eq. 14) and
//! `attachment_height_residual` (eq. 15) — the two calls apex-solver makes and
//! sagcal made before issue 18 — or `catenary_cable_residuals`, the one call
//! that gives both (and the tensions of eq. 11); then `reference_tension_residual` (eq. 16) and
//! `pose_prior_residual`. The arguments are the benchmark's initial values.

use nalgebra::{SMatrix, Vector2, Vector3, Vector4};
use sagcal::calib::factors::{SlotOrder, EPSILON};
use sagcal::experiments::benchmark::BenchmarkProblem;
use sagcal::generated;
use sagcal::model::pose::PlatformPose;

/// The generated calls of every pose, once each with all Jacobians; returns a
/// checksum of the outputs (so that nothing is optimised away).
/// `fused`: the length and height rows by `catenary_cable_residuals`.
pub fn evaluate(problem: &BenchmarkProblem, fused: bool) -> f64 {
    let slots = SlotOrder::new(&problem.initial);
    let mut anchors = SMatrix::<f64, 3, 4>::zeros();
    for (slot, &cable) in slots.cables.iter().enumerate() {
        anchors.set_column(slot, &problem.initial.anchors_m[cable]);
    }
    let offsets = slots.to_slots(&problem.initial.length_offsets_m);
    let mut sum = 0.0;
    for (k, m) in problem.measurements.iter().enumerate() {
        let pose = &problem.initial_poses[k];
        let (position, rotation) = (pose.position_m, pose.rotation_xyzw());
        let tension = Vector2::new(problem.initial_tensions[k].horizontal_n, problem.initial_tensions[k].vertical_n);
        let encoders = slots.to_slots(&m.encoder_lengths_m);
        if fused {
            sum += fused_rows(&slots, &position, &rotation, &tension, &anchors, &offsets, &encoders);
        } else {
            sum += separate_rows(&slots, &position, &rotation, &tension, &anchors, &offsets, &encoders);
        }
        let mut j_t = SMatrix::<f64, 1, 2>::zeros();
        sum += generated::reference_tension_residual(&tension, m.reference_tension_n, EPSILON, Some(&mut j_t))[0];
        let prior = PlatformPose::from_roll_pitch_yaw_deg(Vector3::from(m.position_m), m.roll_deg, m.pitch_deg, m.yaw_deg);
        let mut j_p = SMatrix::<f64, 6, 6>::zeros();
        sum += generated::pose_prior_residual(
            &position,
            &rotation,
            &prior.position_m,
            &prior.rotation_xyzw(),
            EPSILON,
            Some(&mut j_p),
        )[0];
        sum += j_t[0] + j_p[0];
    }
    sum
}

/// The length and height rows by the two functions of eq. (14) and (15).
fn separate_rows(
    s: &SlotOrder,
    position: &Vector3<f64>,
    rotation: &Vector4<f64>,
    tension: &Vector2<f64>,
    anchors: &SMatrix<f64, 3, 4>,
    offsets: &Vector4<f64>,
    encoders: &Vector4<f64>,
) -> f64 {
    let mut j_pose = SMatrix::<f64, 4, 6>::zeros();
    let mut j_tension = SMatrix::<f64, 4, 2>::zeros();
    let mut j_anchors = SMatrix::<f64, 4, 12>::zeros();
    let mut j_offsets = SMatrix::<f64, 4, 4>::zeros();
    let length = generated::catenary_length_residual(
        position,
        rotation,
        tension,
        anchors,
        &s.attachments_m,
        &s.com_offset_m,
        s.platform_weight_n,
        s.cable_weight_n_per_m,
        offsets,
        encoders,
        EPSILON,
        Some(&mut j_pose),
        Some(&mut j_tension),
        Some(&mut j_anchors),
        Some(&mut j_offsets),
    );
    let mut h_pose = SMatrix::<f64, 4, 6>::zeros();
    let mut h_tension = SMatrix::<f64, 4, 2>::zeros();
    let mut h_anchors = SMatrix::<f64, 4, 12>::zeros();
    let height = generated::attachment_height_residual(
        position,
        rotation,
        tension,
        anchors,
        &s.attachments_m,
        &s.com_offset_m,
        s.platform_weight_n,
        s.cable_weight_n_per_m,
        EPSILON,
        Some(&mut h_pose),
        Some(&mut h_tension),
        Some(&mut h_anchors),
    );
    length[0] + height[0] + j_pose[0] + j_tension[0] + j_anchors[0] + j_offsets[0] + h_pose[0] + h_tension[0] + h_anchors[0]
}

/// The length and height rows by the one call of both.
fn fused_rows(
    s: &SlotOrder,
    position: &Vector3<f64>,
    rotation: &Vector4<f64>,
    tension: &Vector2<f64>,
    anchors: &SMatrix<f64, 3, 4>,
    offsets: &Vector4<f64>,
    encoders: &Vector4<f64>,
) -> f64 {
    let mut j_pose = SMatrix::<f64, 16, 6>::zeros();
    let mut j_tension = SMatrix::<f64, 16, 2>::zeros();
    let mut j_anchors = SMatrix::<f64, 16, 12>::zeros();
    let mut j_offsets = SMatrix::<f64, 16, 4>::zeros();
    let rows = generated::catenary_cable_residuals(
        position,
        rotation,
        tension,
        anchors,
        &s.attachments_m,
        &s.com_offset_m,
        s.platform_weight_n,
        s.cable_weight_n_per_m,
        offsets,
        encoders,
        EPSILON,
        Some(&mut j_pose),
        Some(&mut j_tension),
        Some(&mut j_anchors),
        Some(&mut j_offsets),
    );
    rows[0] + rows[4] + j_pose[0] + j_tension[0] + j_anchors[0] + j_offsets[0]
}

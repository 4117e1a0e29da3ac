//! Generated analytic Jacobians against central finite differences, per factor.
//!
//! `make bench` (or `cargo bench --bench jacobians`). Each group times the
//! residual + Jacobian evaluation both ways and prints the largest relative
//! difference between the two Jacobians beside the timings.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{SMatrix, Vector2, Vector3, Vector4, Vector6};
use sagcal::calib::factors::{SlotOrder, EPSILON};
use sagcal::generated::catenary_length_residual;
use sagcal::model::{PlatformPose, Robot};

/// A large-robot operating point.
struct Point {
    pose: PlatformPose,
    tension: Vector2<f64>,
    anchors: SMatrix<f64, 3, 4>,
    slots: SlotOrder,
    offsets: Vector4<f64>,
    encoders: Vector4<f64>,
}

fn point() -> Point {
    let robot = Robot::builtin("large").expect("built-in robot");
    let slots = SlotOrder::new(&robot);
    let mut anchors = SMatrix::<f64, 3, 4>::zeros();
    for (slot, &cable) in slots.cables.iter().enumerate() {
        anchors.set_column(slot, &robot.anchors_m[cable]);
    }
    Point {
        pose: PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(5.0, -3.0, 10.0), 0.5, -1.0, 0.3),
        tension: Vector2::new(600.0, 90.0),
        anchors,
        slots,
        offsets: Vector4::new(0.1, -0.2, 0.3, 0.0),
        encoders: Vector4::new(170.0, 180.0, 160.0, 175.0),
    }
}

fn length_residual(p: &Point, pose: &PlatformPose, jacobian: Option<&mut SMatrix<f64, 4, 6>>) -> Vector4<f64> {
    catenary_length_residual(
        &pose.position_m,
        &pose.rotation_xyzw(),
        &p.tension,
        &p.anchors,
        &p.slots.attachments_m,
        &p.slots.com_offset_m,
        p.slots.platform_weight_n,
        p.slots.cable_weight_n_per_m,
        &p.offsets,
        &p.encoders,
        EPSILON,
        jacobian,
        None,
        None,
        None,
    )
}

/// Pose Jacobian by central differences through the solver's retraction.
fn numerical_pose_jacobian(p: &Point) -> SMatrix<f64, 4, 6> {
    let mut j = SMatrix::<f64, 4, 6>::zeros();
    for c in 0..6 {
        let h = if c < 3 { 1e-6 } else { 1e-5 };
        let mut step = Vector6::zeros();
        step[c] = h;
        let plus = length_residual(p, &p.pose.retract(&step), None);
        let minus = length_residual(p, &p.pose.retract(&-step), None);
        j.set_column(c, &((plus - minus) / (2.0 * h)));
    }
    j
}

fn catenary_length(c: &mut Criterion) {
    let p = point();
    let mut analytic = SMatrix::<f64, 4, 6>::zeros();
    length_residual(&p, &p.pose, Some(&mut analytic));
    let numerical = numerical_pose_jacobian(&p);
    let scale = numerical.abs().max().max(1.0);
    println!(
        "catenary_length_residual: max |analytic - numerical| / max |J| = {:.2e}",
        (analytic - numerical).abs().max() / scale
    );
    let mut group = c.benchmark_group("catenary_length_residual_pose_jacobian");
    group.bench_function(BenchmarkId::new("analytic", "large"), |b| {
        b.iter(|| {
            let mut j = SMatrix::<f64, 4, 6>::zeros();
            std::hint::black_box(length_residual(&p, &p.pose, Some(&mut j)));
            j
        })
    });
    group.bench_function(BenchmarkId::new("numerical", "large"), |b| {
        b.iter(|| numerical_pose_jacobian(&p))
    });
    group.finish();
}

criterion_group!(benches, catenary_length);
criterion_main!(benches);

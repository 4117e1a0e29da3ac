//! The generated analytic Jacobians (`generated/`) against central finite differences.
//!
//! One criterion group per generated function, named after it, at one operating point of the
//! large robot (`robots/large.toml`), with two benchmarks:
//!
//! * `analytic/large`: the generated function with every Jacobian output requested;
//! * `numerical/large`: the same Jacobians by central differences `(f(x + h) - f(x - h)) / 2h` of
//!   the value-only call (every Jacobian output `None`) over every column of every Jacobian
//!   block: the pose through the retraction `(R * Exp(dtheta), p + dp)`, every other argument
//!   additively, with `h = 1e-6 * max(1, |x|)` (`x` the coordinate, 0 for `dtheta`).
//!
//! `extended_cable` is evaluated for the four cables of the point (spans and tensions from
//! `cable_geometry` there, compliance 0.5 1/MN, pulley radius 0.2 m), `load_cell_residual` with a
//! bias of 3 N and a gain error of 0.01. Before each group the largest relative difference
//! between the two Jacobians, `max |a - n| / max(1, max |n|)` per block and the maximum over the
//! blocks, is printed beside the function's name.
//!
//! After the groups the bench prints a summary table: per function criterion's median times of
//! this run (read back from criterion's `estimates.json`), their ratio, the Jacobian difference and
//! whether the targets (at least 10x faster, within 1e-6 relative) are met. `BENCHMARKS.md` quotes it.
//!
//! The point and the calls of the generated functions are `tests/common/generated_calls.rs`, shared
//! with the finite-difference tests (`tests/generated_jacobians.rs`).
//!
//! Run with `cargo bench --bench jacobians` (`make bench` runs every bench); add a filter such
//! as `-- catenary_length_residual` for one group.

use std::hint::black_box;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::SystemTime;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{DMatrix, DVector, Matrix3x4, SVector, Vector2, Vector3, Vector4, Vector6};
use sagcal::calib::factors::SlotOrder;
use sagcal::model::{PlatformPose, Robot};

#[path = "../tests/common/generated_calls.rs"]
mod generated_calls;

use generated_calls::{
    attachment_height, catenary_cable, catenary_length, dynamic, extended, extended_blocks, geometry, geometry_blocks,
    load_cell, mounted_pose_prior, pose_prior, reference_tension, rigid_length, tensions, Point,
};

/// A large-robot operating point where all four cables pull.
fn point() -> Point {
    let robot = Robot::builtin("large").expect("built-in robot");
    let slots = SlotOrder::new(&robot);
    let pose = PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(5.0, -3.0, 10.0), 0.5, -1.0, 0.3);
    let reference_tension_n = Vector2::new(600.0, 90.0);
    let mut p = Point {
        pose,
        reference_tension_n,
        anchors_m: Matrix3x4::from_columns(&slots.cables.map(|c| robot.anchors_m[c])),
        attachments_m: slots.attachments_m,
        com_offset_m: slots.com_offset_m,
        platform_weight_n: slots.platform_weight_n,
        cable_weight_n_per_m: slots.cable_weight_n_per_m,
        length_offsets_m: Vector4::new(0.1, -0.2, 0.3, 0.0),
        encoder_lengths_m: Vector4::new(170.0, 180.0, 160.0, 175.0),
        prior: pose.retract(&Vector6::new(0.01, -0.02, 0.015, 0.05, -0.03, 0.02)),
        measured_tension_n: reference_tension_n.norm() + 2.0,
        cable_spans_m: Vector4::zeros(),
        cable_horizontal_tensions_n: Vector4::zeros(),
        cable_vertical_tensions_n: Vector4::zeros(),
        axial_compliance_per_mn: 0.5,
        pulley_radius_m: 0.2,
        inverse_segments_squared: 1.0 / 400.0,
        load_cell_bias_n: 3.0,
        load_cell_gain_error: 0.01,
        localiser_mount_rad: Vector3::new(0.02, -0.01, 0.015),
    };
    let g = geometry(&p, None);
    p.cable_spans_m = Vector4::from_fn(|j, _| g[4 * j]);
    p.cable_horizontal_tensions_n = Vector4::from_fn(|j, _| g[4 * j + 1]);
    p.cable_vertical_tensions_n = Vector4::from_fn(|j, _| g[4 * j + 2]);
    assert!(
        p.cable_horizontal_tensions_n.min() > 0.0 && p.cable_vertical_tensions_n.min() > 0.0,
        "a slack or pushing cable: {g}"
    );
    p
}

/// Per group, the largest relative Jacobian difference, for the summary.
static DIFFERENCES: Mutex<Vec<(String, f64)>> = Mutex::new(Vec::new());

/// Criterion's output folder, found as criterion finds it: `$CRITERION_HOME`, else
/// `$CARGO_TARGET_DIR/criterion`, else this package's `target/criterion`.
fn criterion_home() -> PathBuf {
    if let Some(home) = std::env::var_os("CRITERION_HOME") {
        return home.into();
    }
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target"));
    target.join("criterion")
}

/// The median time (ns) of `group/function/large` if criterion wrote it after `since`.
fn median_ns(group: &str, function: &str, since: SystemTime) -> Option<f64> {
    let path = criterion_home()
        .join(group)
        .join(function)
        .join("large/new/estimates.json");
    let modified = std::fs::metadata(&path).and_then(|m| m.modified()).ok()?;
    if modified < since {
        return None;
    }
    let estimates: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).ok()?).ok()?;
    estimates["median"]["point_estimate"].as_f64()
}

/// The summary table of the groups that ran since `since` (a filter may skip some).
fn print_summary(since: SystemTime) {
    println!();
    println!(
        "Jacobian summary (criterion medians of this run; targets: numerical / analytic >= 10x, difference <= 1e-6):"
    );
    println!(
        "| function | analytic ns | numerical ns | numerical / analytic | max rel. Jacobian difference | targets |"
    );
    println!("|---|---:|---:|---:|---:|---|");
    for (name, difference) in DIFFERENCES.lock().expect("one bench thread").iter() {
        let (Some(analytic), Some(numerical)) =
            (median_ns(name, "analytic", since), median_ns(name, "numerical", since))
        else {
            continue;
        };
        let ratio = numerical / analytic;
        let met = if ratio >= 10.0 && *difference <= 1e-6 {
            "met"
        } else {
            "MISSED"
        };
        println!("| `{name}` | {analytic:.1} | {numerical:.1} | {ratio:.1}x | {difference:.1e} | {met} |");
    }
}

/// A differentiated argument block, in the column order of the generated Jacobians.
#[derive(Clone, Copy)]
enum Block {
    /// The pose, tangent `[dtheta, dp]` of the retraction `(R * Exp(dtheta), p + dp)`.
    Pose,
    /// Coordinates perturbed additively (matrices column by column).
    Additive(fn(&mut Point) -> &mut [f64]),
}

/// Central differences of `f` at `p`, one matrix per block, one column per block coordinate.
fn central_differences(p: &Point, blocks: &[Block], f: impl Fn(&Point) -> DVector<f64>) -> Vec<DMatrix<f64>> {
    let mut q = p.clone();
    let mut jacobians = Vec::with_capacity(blocks.len());
    for &block in blocks {
        let n = match block {
            Block::Pose => 6,
            Block::Additive(x) => x(&mut q).len(),
        };
        let mut columns = Vec::with_capacity(n);
        for k in 0..n {
            let (x0, magnitude) = match block {
                Block::Pose if k < 3 => (0.0, 0.0),
                Block::Pose => (0.0, p.pose.position_m[k - 3].abs()),
                Block::Additive(x) => {
                    let x0 = x(&mut q)[k];
                    (x0, x0.abs())
                }
            };
            let h = 1e-6 * magnitude.max(1.0);
            // `f` at `p` moved by `t` along coordinate `k`.
            let mut at = |t: f64| {
                match block {
                    Block::Pose => q.pose = p.pose.retract(&Vector6::ith(k, t)),
                    Block::Additive(x) => x(&mut q)[k] = x0 + t,
                }
                f(&q)
            };
            columns.push((at(h) - at(-h)) / (2.0 * h));
            match block {
                Block::Pose => q.pose = p.pose,
                Block::Additive(x) => x(&mut q)[k] = x0,
            }
        }
        jacobians.push(DMatrix::from_columns(&columns));
    }
    jacobians
}

/// The group `name` of the generated function `f`, whose Jacobians `J` are the blocks `blocks`
/// (`split` turns them into matrices): prints the largest relative difference between the
/// analytic and the numerical Jacobians, then times both.
fn group<J: Default, const R: usize>(
    c: &mut Criterion,
    name: &str,
    p: &Point,
    blocks: &[Block],
    f: impl Fn(&Point, Option<&mut J>) -> SVector<f64, R>,
    split: impl Fn(&J) -> Vec<DMatrix<f64>>,
) {
    let value = |q: &Point| DVector::from_column_slice(f(q, None).as_slice());
    let mut analytic = J::default();
    f(p, Some(&mut analytic));
    let numerical = central_differences(p, blocks, value);
    let difference = split(&analytic)
        .iter()
        .zip(&numerical)
        .map(|(a, n)| (a - n).amax() / n.amax().max(1.0))
        .fold(0.0, f64::max);
    println!("{name}: max relative Jacobian difference {difference:.1e}");
    DIFFERENCES
        .lock()
        .expect("one bench thread")
        .push((name.to_string(), difference));

    let mut group = c.benchmark_group(name);
    // The Jacobians are written into one buffer, as the solver does (`graph::LinearizationBuffers`).
    let mut jacobians = J::default();
    group.bench_function(BenchmarkId::new("analytic", "large"), |b| {
        b.iter(|| {
            let v = f(black_box(p), Some(&mut jacobians));
            black_box(&jacobians);
            v
        })
    });
    group.bench_function(BenchmarkId::new("numerical", "large"), |b| {
        b.iter(|| black_box(central_differences(black_box(p), blocks, value)))
    });
    group.finish();
}

fn jacobians(c: &mut Criterion) {
    use Block::{Additive, Pose};
    // Criterion's files are compared with this (minus a second of file-time granularity).
    let start = SystemTime::now() - std::time::Duration::from_secs(1);
    let p = point();
    let reference = Additive(|q| q.reference_tension_n.as_mut_slice());
    let anchors = Additive(|q| q.anchors_m.as_mut_slice());
    let offsets = Additive(|q| q.length_offsets_m.as_mut_slice());
    let com = Additive(|q| q.com_offset_m.as_mut_slice());
    // The blocks of eq. (11)'s functions: pose, reference tension, anchors.
    let statics = [Pose, reference, anchors];

    group(c, "cable_tensions_from_reference", &p, &statics, tensions, |j| {
        vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)]
    });
    group(
        c,
        "catenary_length_residual",
        &p,
        &[Pose, reference, anchors, offsets],
        catenary_length,
        |j| vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2), dynamic(&j.3)],
    );
    group(c, "attachment_height_residual", &p, &statics, attachment_height, |j| {
        vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)]
    });
    group(
        c,
        "catenary_cable_residuals",
        &p,
        &[Pose, reference, anchors, offsets],
        catenary_cable,
        |j| vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2), dynamic(&j.3)],
    );
    group(
        c,
        "reference_tension_residual",
        &p,
        &[reference],
        reference_tension,
        |j| vec![dynamic(j)],
    );
    group(c, "pose_prior_residual", &p, &[Pose], pose_prior, |j| vec![dynamic(j)]);
    let mount = Additive(|q| q.localiser_mount_rad.as_mut_slice());
    group(
        c,
        "mounted_pose_prior_residual",
        &p,
        &[Pose, mount],
        mounted_pose_prior,
        |j| vec![dynamic(&j.0), dynamic(&j.1)],
    );
    group(
        c,
        "rigid_length_residual",
        &p,
        &[Pose, anchors, offsets],
        rigid_length,
        |j| vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)],
    );
    group(
        c,
        "cable_geometry",
        &p,
        &[
            Pose,
            reference,
            anchors,
            Additive(|q| q.attachments_m.as_mut_slice()),
            com,
            Additive(|q| std::slice::from_mut(&mut q.platform_weight_n)),
        ],
        geometry,
        geometry_blocks,
    );
    let per_cable: [Block; 7] = [
        Additive(|q| q.cable_spans_m.as_mut_slice()),
        Additive(|q| q.cable_horizontal_tensions_n.as_mut_slice()),
        Additive(|q| q.cable_vertical_tensions_n.as_mut_slice()),
        Additive(|q| std::slice::from_mut(&mut q.axial_compliance_per_mn)),
        Additive(|q| std::slice::from_mut(&mut q.pulley_radius_m)),
        Additive(|q| std::slice::from_mut(&mut q.inverse_segments_squared)),
        Additive(|q| std::slice::from_mut(&mut q.cable_weight_n_per_m)),
    ];
    group(c, "extended_cable", &p, &per_cable, extended, extended_blocks);
    let load_cell_blocks: [Block; 3] = [
        reference,
        Additive(|q| std::slice::from_mut(&mut q.load_cell_bias_n)),
        Additive(|q| std::slice::from_mut(&mut q.load_cell_gain_error)),
    ];
    group(c, "load_cell_residual", &p, &load_cell_blocks, load_cell, |j| {
        vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)]
    });
    print_summary(start);
}

criterion_group!(benches, jacobians);
criterion_main!(benches);

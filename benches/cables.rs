//! Calibration time against the number of cables: the whole calibration of
//! a robot of `N` cables (`sagcal::calib::suspended::calibrate_suspended`:
//! straight cables, each pose's equilibrium, the catenary graph with the
//! anchors held, then free; no gross-error tests) from 35 noisy poses
//! (paper noise, seed 3, a yaw within +-5 degrees held from four cables on)
//! with every anchor of the guess 0.5 m off, for three to eight cables:
//! the built-in three-, six- and eight-cable robots, the paper's large robot
//! as four cables, and the six- and eight-cable robots without their last
//! cable as five and seven.
//!
//! The large robot is also calibrated from the same readings by the
//! four-cable pipeline (`sagcal::calib::calibrate`, the forces of three
//! cables from the reference cable's, eq. 11), to show what the general
//! graph costs where the specialised one applies.
//!
//! Before the timed runs, one calibration per robot prints its stages'
//! iterations, the final cost and the time, with its unknowns per pose.
//!
//! Run with `cargo bench --bench cables`.

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::calib::suspended::calibrate_suspended;
use sagcal::calib::{calibrate, CalibrationOptions, OrientationPrior};
use sagcal::model::measurement::PoseMeasurement;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use sagcal::model::Robot;
use sagcal::sim::closed_form::{Closure, Workspace};
use sagcal::sim::suspended::{measure_suspended, sample_suspended};

/// Poses per calibration.
const POSES: usize = 35;
/// Seed of the poses and the noise.
const SEED: u64 = 3;

/// One robot's calibration problem.
struct Problem {
    name: String,
    truth: SuspendedRobot,
    guess: SuspendedRobot,
    data: Vec<SuspendedMeasurement>,
    options: CalibrationOptions,
}

/// A built-in robot, the large one as four cables, or `five` / `seven`.
fn robot(name: &str) -> SuspendedRobot {
    match name {
        "large" => SuspendedRobot::from_robot(&Robot::builtin("large").expect("large")),
        "five" | "seven" => SuspendedRobot::builtin(if name == "five" { "six" } else { "eight" })
            .and_then(|robot| robot.without_last_cable(name))
            .expect("robot"),
        other => SuspendedRobot::builtin(other).expect("built-in robot"),
    }
}

fn problem(name: &str) -> Problem {
    let truth = robot(name);
    let workspace = match name {
        "large" => Workspace::default_for(&Robot::builtin("large").expect("large")),
        _ => truth
            .workspace
            .unwrap_or_else(|| Workspace::around_anchor_points(&truth.anchors_m)),
    };
    let closure = if truth.cable_count() > 3 {
        Closure::Yaw { max_yaw_deg: 5.0 }
    } else {
        Closure::Level
    };
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let equilibria = sample_suspended(&truth, &workspace, POSES, closure, &mut rng).expect("poses");
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let data = measure_suspended(&truth, &equilibria, &noise, &mut rng).unwrap();
    let mut guess = truth.clone();
    for (i, anchor) in guess.anchors_m.iter_mut().enumerate() {
        let angle = 1.3 * i as f64;
        *anchor += 0.5 * Vector3::new(angle.cos(), angle.sin(), 0.5).normalize();
    }
    let mut options = CalibrationOptions::new(noise);
    options.orientation_prior = OrientationPrior::On;
    Problem {
        name: name.into(),
        truth,
        guess,
        data,
        options,
    }
}

/// The large robot's readings as four-cable rows.
fn four_cable_rows(data: &[SuspendedMeasurement]) -> Vec<PoseMeasurement> {
    data.iter()
        .map(|m| PoseMeasurement {
            position_m: m.position_m,
            roll_deg: m.roll_deg,
            pitch_deg: m.pitch_deg,
            yaw_deg: m.yaw_deg,
            encoder_lengths_m: m.encoder_lengths_m.clone().try_into().expect("four encoders"),
            reference_tension_n: m.load_cell_tensions_n[0],
            line: 0,
            excluded: Default::default(),
            order: None,
        })
        .collect()
}

fn cables(c: &mut Criterion) {
    let problems: Vec<Problem> = ["three", "large", "five", "six", "seven", "eight"]
        .iter()
        .map(|name| problem(name))
        .collect();
    println!(
        "calibration of N cables, {POSES} poses, paper noise, seed {SEED}, anchors 0.5 m off (the timed runs follow)"
    );
    println!(
        "{:>7} {:>6} {:>16} {:>24} {:>14} {:>12}",
        "robot", "cables", "unknowns/pose", "iterations by stage", "final cost", "ms"
    );
    for p in &problems {
        let started = Instant::now();
        let result = calibrate_suspended(&p.guess, &p.data, &p.options, None, &mut |_| {}).expect("calibration");
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let iterations: Vec<String> = result.stages.iter().map(|s| s.summary.iterations.to_string()).collect();
        let worst = (0..p.truth.cable_count())
            .map(|i| (result.robot.anchors_m[i] - p.truth.anchors_m[i]).norm())
            .fold(0.0, f64::max);
        println!(
            "{:>7} {:>6} {:>16} {:>24} {:>14.6e} {:>12.1}   (worst anchor error {worst:.3} m)",
            p.name,
            p.truth.cable_count(),
            6 + 2 * p.truth.cable_count(),
            iterations.join(" + "),
            result.final_cost,
            ms
        );
    }
    let large = problems.iter().find(|p| p.name == "large").expect("large");
    let four = Robot::builtin("large").expect("large");
    let mut four_guess = four.clone();
    for i in 0..4 {
        four_guess.anchors_m[i] = large.guess.anchors_m[i];
    }
    let rows = four_cable_rows(&large.data);
    let started = Instant::now();
    let by_four = calibrate(&four_guess, &rows, &large.options).expect("four-cable calibration");
    let final_cost = by_four.stages.last().map_or(f64::NAN, |s| s.summary.final_cost);
    println!(
        "  large by the four-cable pipeline: final cost {final_cost:.6e}, {:.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );

    let mut group = c.benchmark_group("calibrate_cables");
    group.sample_size(10);
    for p in &problems {
        group.bench_with_input(BenchmarkId::new("n_cable_graph", &p.name), p, |b, p| {
            b.iter(|| {
                calibrate_suspended(black_box(&p.guess), &p.data, &p.options, None, &mut |_| {}).expect("calibration")
            })
        });
    }
    group.bench_function(BenchmarkId::new("four_cable_pipeline", "large"), |b| {
        b.iter(|| calibrate(black_box(&four_guess), &rows, &large.options).expect("calibration"))
    });
    group.finish();
}

criterion_group!(benches, cables);
criterion_main!(benches);

//! Localisation throughput (`sagcal::localize`, issue 16), one thread.
//!
//! A straight 10 m trajectory of the large robot (`robots/large.toml`),
//! 500 static poses, each the most level equilibrium at its position
//! (`model::statics::solve_level`); the readings are its four encoder
//! readings (lengths plus offsets) and the load cell. *Warm*: each row
//! starts from the previous row's pose, as a robot localised along its path;
//! *cold*: every row from the trilateration of its lengths. Before the timed
//! runs one pass of each prints poses per second against the target
//! of 10 000 poses/s on one core and the worst position error.
//!
//! The same pass runs for the robot with a recorded calibration covariance
//! (the pose's calibration sigma propagated on every row) and with each
//! `[effects]` entry in turn (elastic cable, pulley, segmented cable,
//! encoder scale, load-cell model, centre of mass shift). The readings stay
//! the plain model's, so with an effect the localised pose moves by the
//! effect (its error is printed, not a defect): what is measured is the cost.
//!
//! Run with `cargo bench --bench localize`.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use sagcal::localize::{Localizer, Readings};
use sagcal::model::pose::PlatformPose;
use sagcal::model::robot::ParameterCovariance;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::statics::{solve_level, Equilibrium, StaticsOptions};
use sagcal::model::{Robot, CABLE_COUNT};

/// Poses along the trajectory.
const POSES: usize = 500;
/// The target, poses per second on one core.
const TARGET_PER_SECOND: f64 = 10_000.0;

fn trajectory(robot: &Robot) -> Vec<(Equilibrium, Readings)> {
    let (from, to) = (Vector3::new(-5.0, -3.0, 12.0), Vector3::new(5.0, 3.0, 14.0));
    (0..POSES)
        .map(|k| {
            let position = from + (to - from) * (k as f64 / (POSES - 1) as f64);
            let eq = solve_level(robot, position, &StaticsOptions::default()).expect("level equilibrium");
            let readings = Readings {
                encoder_lengths_m: std::array::from_fn(|i| eq.cable_lengths_m[i] + robot.length_offsets_m[i]),
                load_cell_n: Some(eq.tensions[robot.reference_cable].magnitude_n()),
                localiser_pose: None,
            };
            (eq, readings)
        })
        .collect()
}

/// Localise the trajectory, warm-started or cold; the worst position error
/// and the Gauss-Newton iterations.
fn pass(localizer: &Localizer, rows: &[(Equilibrium, Readings)], warm: bool) -> (f64, usize) {
    let mut previous: Option<PlatformPose> = None;
    let mut worst = 0.0f64;
    let mut iterations = 0;
    for (eq, readings) in rows {
        let start = if warm { previous.as_ref() } else { None };
        let found = localizer.localize(readings, start).expect("localised");
        worst = worst.max((found.pose.position_m - eq.pose.position_m).norm());
        previous = Some(found.pose);
        iterations += found.iterations;
    }
    (worst, iterations)
}

/// The robot variants of the bench: plain, with a calibration covariance,
/// with each effect.
fn variants(robot: &Robot) -> Vec<(&'static str, Robot)> {
    let with = |name: &'static str, change: &dyn Fn(&mut Robot)| {
        let mut r = robot.clone();
        change(&mut r);
        (name, r)
    };
    vec![
        ("catenary", robot.clone()),
        with("+ calibration covariance", &|r| {
            r.calibration_covariance_m2 = Some(ParameterCovariance::identity() * 1e-4)
        }),
        with("+ elastic cable", &|r| r.effects.axial_stiffness_n = Some(3e6)),
        with("+ pulley 0.1 m", &|r| r.effects.pulley_radius_m = 0.1),
        with("+ 50 segments", &|r| r.effects.cable_segments = Some(50.0)),
        with("+ encoder scale", &|r| {
            r.effects.encoder_gain = [1.001, 0.999, 1.0005, 1.0]
        }),
        with("+ load-cell model", &|r| {
            r.effects.load_cell_bias_n = 2.0;
            r.effects.load_cell_gain = 1.01;
        }),
        with("+ centre of mass shift", &|r| {
            r.effects.com_shift_m = [0.05, -0.03, 0.0]
        }),
    ]
}

fn localize(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/large.toml");
    let mut robot = Robot::from_file(&path).expect("robot");
    robot.length_offsets_m = [1.25, -0.75, 3.5, 0.125];
    let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
    let localizer = Localizer::new(&robot, &noise).expect("localizer");
    let rows = trajectory(&robot);
    assert_eq!(rows[0].1.encoder_lengths_m.len(), CABLE_COUNT);
    println!("localisation, large robot, {POSES} poses on a straight 10 m line, encoders + load cell, one thread");
    for (variant, r) in variants(&robot) {
        let localizer = Localizer::new(&r, &noise).expect("localizer");
        for (name, warm) in [("warm", true), ("cold", false)] {
            let started = Instant::now();
            let (worst, iterations) = pass(&localizer, &rows, warm);
            let per_second = POSES as f64 / started.elapsed().as_secs_f64();
            println!(
                "{variant:<26} {name}: {per_second:>9.0} poses/s ({:.1} us/pose, {:.1} Gauss-Newton iterations/pose; target {TARGET_PER_SECOND:.0}/s: {}), worst position error {worst:.2e} m",
                1e6 / per_second,
                iterations as f64 / POSES as f64,
                if per_second >= TARGET_PER_SECOND { "met" } else { "NOT met" }
            );
        }
    }
    let mut group = c.benchmark_group("localize");
    group.sample_size(20);
    group.bench_function("warm trajectory (500 poses)", |b| {
        b.iter(|| pass(&localizer, black_box(&rows), true))
    });
    group.bench_function("cold (500 poses)", |b| {
        b.iter(|| pass(&localizer, black_box(&rows), false))
    });
    group.finish();
}

criterion_group!(benches, localize);
criterion_main!(benches);

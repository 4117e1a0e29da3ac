//! Pose planning speed (`sagcal::plan`, issue 17), one thread: choosing 35
//! poses from 10 000 candidates of the large robot (`robots/large.toml`),
//! A-optimal and D-optimal, greedy with rank-k updates then exchange passes.
//!
//! The candidates are drawn uniformly in the robot's default workspace, each
//! the equilibrium whose reference tension is the straight-cable estimate
//! (one statics solve: the setup is not timed, and the information of a pose
//! depends little on which member of its family it is). Their per-pose
//! information (paper noise, no orientation prior) is computed once, before
//! the timed runs; one untimed pass prints the wall time against the
//! issue's target of 1 s on one core.
//!
//! Run with `cargo bench --bench plan`.

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sagcal::calib::{CalibrationOptions, OrientationPrior};
use sagcal::model::robot::Workspace;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::statics::{reference_tension_magnitude_guess, solve_with_reference_tension, StaticsOptions};
use sagcal::model::Robot;
use sagcal::plan::{candidate_information, choose_poses, Criterion as Design, DesignOptions, PoseInformation};

/// Candidates to choose from.
const CANDIDATES: usize = 10_000;
/// Poses chosen.
const POSES: usize = 35;
/// The target, seconds on one core.
const TARGET_S: f64 = 1.0;

fn candidates(robot: &Robot) -> Vec<PoseInformation> {
    let workspace = Workspace::default_for(robot);
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let options = StaticsOptions::default();
    let mut equilibria = Vec::with_capacity(CANDIDATES);
    while equilibria.len() < CANDIDATES {
        let p = Vector3::from_fn(|i, _| rng.random_range(workspace.min_m[i]..=workspace.max_m[i]));
        let magnitude = reference_tension_magnitude_guess(robot, p);
        if let Ok(eq) = solve_with_reference_tension(robot, p, magnitude, None, &options) {
            equilibria.push(eq);
        }
    }
    let mut calibration = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
    calibration.orientation_prior = OrientationPrior::Off;
    candidate_information(robot, &equilibria, &calibration).expect("information of every candidate")
}

fn bench_plan(c: &mut Criterion) {
    // One thread, as the target says (the information above used all).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let robot = Robot::builtin("large").expect("built-in robot");
    let information = candidates(&robot);
    let mut group = c.benchmark_group("plan_35_of_10000");
    group.sample_size(10);
    for criterion in [Design::A, Design::D] {
        let options = DesignOptions {
            criterion,
            ..DesignOptions::new(POSES)
        };
        pool.install(|| {
            let started = Instant::now();
            let design = choose_poses(&information, &options).expect("a design");
            let seconds = started.elapsed().as_secs_f64();
            println!(
                "{criterion:?}-optimal, {POSES} of {CANDIDATES}: {seconds:.3} s on one core (target {TARGET_S} s), {} exchanges in {} passes",
                design.exchanges, design.passes
            );
        });
        group.bench_with_input(
            BenchmarkId::new(format!("{criterion:?}"), CANDIDATES),
            &options,
            |b, o| b.iter(|| pool.install(|| choose_poses(black_box(&information), o).expect("a design"))),
        );
    }
    group.finish();
}

criterion_group!(benches, bench_plan);
criterion_main!(benches);

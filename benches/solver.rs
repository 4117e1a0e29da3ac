//! Solver scaling: the full catenary calibration solve of
//! [`sagcal::experiments::benchmark::BenchmarkProblem`] (same data seed, same kind of
//! initial guess, the stopping rule of `BenchmarkProblem::stopping`) at 9,
//! 35, 1 000 and 10 000 poses, on one thread.
//!
//! Before the timed runs, one solve per size prints the iterations, the
//! final cost, the time per iteration and the time per pose, so that the
//! growth with the number of poses can be read directly (close to linear:
//! every iteration linearises each pose's factors once and eliminates each
//! pose's 8 variables in a fixed-size block). Criterion then times the
//! solve alone (the graph is built outside the measurement).
//!
//! Run with `cargo bench --bench solver` (`make bench` runs every bench).

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
use sagcal::experiments::benchmark::BenchmarkProblem;
use sagcal::solver::optimize;

/// Pose counts of the issue.
const POSES: [usize; 4] = [9, 35, 1_000, 10_000];
/// Seed of the data and the initial guess.
const SEED: u64 = 7;

fn solver_scaling(c: &mut Criterion) {
    let problems: Vec<BenchmarkProblem> = POSES
        .iter()
        .map(|&n| BenchmarkProblem::new(n, SEED).expect("benchmark problem"))
        .collect();
    println!("solver scaling, seed {SEED}: one solve per size (the timed runs follow)");
    println!(
        "{:>7} {:>10} {:>22} {:>12} {:>14} {:>12}",
        "poses", "iterations", "final cost", "solve ms", "ms/iteration", "us/pose"
    );
    for problem in &problems {
        let mut built = problem.graph();
        let started = Instant::now();
        let summary = optimize(&mut built.graph, &BenchmarkProblem::stopping()).expect("solve");
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let n = problem.measurements.len();
        println!(
            "{n:>7} {:>10} {:>22.12e} {ms:>12.3} {:>14.3} {:>12.2}  ({})",
            summary.iterations,
            summary.final_cost,
            ms / summary.iterations.max(1) as f64,
            1e3 * ms / n as f64,
            summary.termination
        );
    }
    let mut group = c.benchmark_group("solve");
    for problem in &problems {
        let n = problem.measurements.len();
        if n >= 1_000 {
            group.sample_size(10);
        }
        group.bench_with_input(BenchmarkId::new("catenary", n), problem, |b, problem| {
            b.iter_batched(
                || problem.graph(),
                |mut built| black_box(optimize(&mut built.graph, &BenchmarkProblem::stopping()).expect("solve")),
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, solver_scaling);
criterion_main!(benches);

//! One solve of the benchmark problem, stopped after a given number of
//! linearisations, for instruction counts (issue 18):
//!
//! ```text
//! cargo build --release --example solve_once
//! valgrind --tool=callgrind --toggle-collect=solve_once::counted_solve \
//!     target/release/examples/solve_once POSES ITERATIONS
//! ```
//!
//! The difference of two runs in both the pose count and the iteration
//! budget is the instructions per pose per iteration: the graph building,
//! the pattern analysis and the first linearisation cancel.

use sagcal::experiments::benchmark::BenchmarkProblem;
use sagcal::solver::{optimize, LmParams, SolveSummary};

/// The solve, the region callgrind counts.
#[inline(never)]
fn counted_solve(graph: &mut sagcal::graph::FactorGraph, params: &LmParams) -> SolveSummary {
    optimize(graph, params).expect("solve")
}

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).map(|a| a.parse().expect("a number")).collect();
    let (poses, iterations) = match args[..] {
        [poses, iterations] => (poses, iterations),
        _ => {
            eprintln!("usage: solve_once POSES ITERATIONS");
            std::process::exit(2);
        }
    };
    let problem = BenchmarkProblem::new(poses, 7).expect("benchmark problem");
    let mut built = problem.graph();
    let params = LmParams {
        max_iterations: iterations,
        ..BenchmarkProblem::stopping()
    };
    let summary = counted_solve(&mut built.graph, &params);
    let trials: usize = summary.history.iter().map(|h| h.trials).sum();
    println!(
        "{poses} poses: {} iterations ({trials} damping trials), cost {:.12e}",
        summary.iterations, summary.final_cost
    );
}

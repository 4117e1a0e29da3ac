//! `sagcal-peers`: sagcal's Levenberg-Marquardt against apex-solver and factrs
//! on the identical calibration problem (issue 5).
//!
//! Every solver gets [`BenchmarkProblem::new`]`(poses, seed)`: the same
//! residuals (apex calls sagcal's SymForce-generated functions with their
//! analytic Jacobians; factrs re-implements them generically over its dual
//! numbers), the same initial values, the same per-row sigmas, the cost
//! `sum 1/2 |r / sigma|^2`, and the stopping rule of
//! [`BenchmarkProblem::stopping`] as far as each peer can express it (the
//! modules document the mapping). Every solve runs on one thread and only the
//! solve is timed (median of `--repeats`). Each peer's solution is then
//! evaluated with sagcal's own cost function: equal costs show that the
//! problems were identical and that every solver reached the same minimum.
//!
//! `make bench-peers` runs it and writes `target/bench-peers/peers.json` and
//! `peers.svg` (solve time against poses).

mod apex;
mod common;
mod factrs_peer;
mod floor;

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use sagcal::experiments::benchmark::BenchmarkProblem;
use sagcal::solver::{optimize, LmParams};
use serde::Serialize;

use common::{sagcal_cost_at, PeerRun, Solution};

#[derive(Parser)]
#[command(about = "sagcal's solver against apex-solver and factrs on the same calibration problem")]
struct Args {
    /// Pose counts.
    #[arg(long, value_delimiter = ',', default_value = "9,35,1000,10000")]
    poses: Vec<usize>,
    /// Seed of the benchmark problem (data and initial guess).
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Rounds from 101 to 1000 poses; each round solves with every solver in
    /// turn (interleaved), the first solver of the round rotating.
    #[arg(long, default_value_t = 9)]
    repeats: usize,
    /// Rounds up to 100 poses, where a round takes milliseconds and a few
    /// rounds leave the median at the mercy of the machine's noise.
    #[arg(long, default_value_t = 41)]
    small_repeats: usize,
    /// Rounds above 1000 poses.
    #[arg(long, default_value_t = 5)]
    large_repeats: usize,
    /// A check in under a minute: 15 rounds up to 100 poses, 5 up to 1000, 2 above.
    #[arg(long)]
    quick: bool,
    /// Instead of the table: one solve of this solver (`sagcal`, `apex-solver`,
    /// `factrs`) at each `--poses`, stopped after `--iterations`
    /// linearisations, inside `counted_solve` (for `valgrind --tool=callgrind
    /// --toggle-collect=counted_solve`); or `floor` / `floor-fused`: every
    /// pose's generated residuals with all Jacobians once, inside
    /// `counted_floor` (length and height rows by two calls / by one).
    #[arg(long)]
    count: Option<String>,
    /// Linearisation budget of `--count`.
    #[arg(long, default_value_t = 2)]
    iterations: usize,
    /// Where to write peers.json and peers.svg.
    #[arg(long, default_value = "target/bench-peers")]
    out: PathBuf,
}

#[derive(Serialize, Clone)]
struct Row {
    poses: usize,
    solver: &'static str,
    iterations: usize,
    /// Median wall time of the solve over the rounds, seconds.
    solve_s: f64,
    /// Fastest and slowest round, seconds.
    min_s: f64,
    max_s: f64,
    /// Every round's solve time, seconds.
    solve_times_s: Vec<f64>,
    /// Building the solver's problem from the benchmark problem (last round), seconds.
    setup_s: f64,
    /// The final cost the solver reports (sagcal's convention).
    reported_cost: f64,
    /// sagcal's cost function at the solver's solution.
    sagcal_cost_at_solution: f64,
    /// `|cost - sagcal's final cost| / sagcal's final cost`.
    relative_cost_difference: f64,
    /// Per round, this solver's time over sagcal's in the same round: median, min, max.
    ratio_median: f64,
    ratio_min: f64,
    ratio_max: f64,
}

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// sagcal's own solve, in the peers' [`PeerRun`] form.
fn sagcal_solve(problem: &BenchmarkProblem, max_iterations: usize) -> Result<PeerRun, String> {
    let started = Instant::now();
    let mut built = problem.graph();
    let setup_seconds = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let params = LmParams {
        max_iterations,
        ..BenchmarkProblem::stopping()
    };
    let summary = optimize(&mut built.graph, &params)?;
    let solve_seconds = started.elapsed().as_secs_f64();
    if !summary.termination.converged() && max_iterations >= BenchmarkProblem::stopping().max_iterations {
        return Err(format!("sagcal did not converge: {}", summary.termination));
    }
    let values = &built.graph.values;
    let solution = Solution {
        anchors_m: std::array::from_fn(|i| {
            let a = values.vector(built.globals.anchors[i]);
            [a[0], a[1], a[2]]
        }),
        length_offsets_m: std::array::from_fn(|i| values.vector(built.globals.length_offsets[i])[0]),
        poses: built.poses.iter().map(|p| *values.pose(p.pose)).collect(),
        reference_tensions_n: built
            .poses
            .iter()
            .map(|p| {
                let t = values.vector(p.reference_tension);
                [t[0], t[1]]
            })
            .collect(),
    };
    Ok(PeerRun {
        reported_final_cost: summary.final_cost,
        iterations: summary.iterations,
        solve_seconds,
        setup_seconds,
        solution,
    })
}

type Solver = fn(&BenchmarkProblem, usize) -> Result<PeerRun, String>;

const SOLVERS: [(&str, Solver); 3] = [
    ("sagcal", sagcal_solve),
    ("apex-solver", apex::solve),
    ("factrs", factrs_peer::solve),
];

fn main() {
    let args = Args::parse();
    let outcome = match &args.count {
        Some(what) => count(&args, what),
        None => run(&args),
    };
    if let Err(e) = outcome {
        eprintln!("sagcal-peers: {e}");
        std::process::exit(1);
    }
}

/// The `--count` mode (see [`Args::count`]).
fn count(args: &Args, what: &str) -> Result<(), String> {
    for &poses in &args.poses {
        let problem = BenchmarkProblem::new(poses, args.seed).map_err(|e| e.to_string())?;
        if what == "floor" || what == "floor-fused" {
            let sum = counted_floor(&problem, what == "floor-fused");
            println!("{poses} poses: evaluation floor checksum {sum:.6e}");
            continue;
        }
        let Some(&(name, solve)) = SOLVERS.iter().find(|(name, _)| *name == what) else {
            return Err(format!("--count {what}: expected sagcal, apex-solver, factrs, floor or floor-fused"));
        };
        let run = counted_solve(solve, &problem, args.iterations)?;
        println!(
            "{poses} poses: {name} {} linearisations, cost {:.12e}",
            run.iterations, run.reported_final_cost
        );
    }
    Ok(())
}

/// One solve, the region `valgrind --toggle-collect=counted_solve` counts.
#[inline(never)]
fn counted_solve(solve: Solver, problem: &BenchmarkProblem, iterations: usize) -> Result<PeerRun, String> {
    solve(problem, iterations)
}

/// Every pose's generated residuals with all their Jacobians, once (the
/// evaluation floor of one iteration; see `floor::evaluate`).
#[inline(never)]
fn counted_floor(problem: &BenchmarkProblem, fused: bool) -> f64 {
    floor::evaluate(problem, fused)
}

fn run(args: &Args) -> Result<(), String> {
    let (small_repeats, repeats, large_repeats) = if args.quick {
        (15, 5, 2)
    } else {
        (args.small_repeats, args.repeats, args.large_repeats)
    };
    eprintln!(
        "sagcal-peers: seed {}, poses {:?}, {small_repeats} rounds up to 100 poses, {repeats} up to 1000, {large_repeats} above, after one untimed warm-up round; solvers interleaved in each round (the first one rotating), one thread per solve",
        args.seed, args.poses
    );
    let max_iterations = BenchmarkProblem::stopping().max_iterations;
    let mut rows: Vec<Row> = Vec::new();
    for &poses in &args.poses {
        let problem = BenchmarkProblem::new(poses, args.seed).map_err(|e| e.to_string())?;
        let rounds = match poses {
            0..=100 => small_repeats,
            101..=1000 => repeats,
            _ => large_repeats,
        }
        .max(1);
        let mut times = vec![Vec::with_capacity(rounds); SOLVERS.len()];
        let mut last: Vec<Option<PeerRun>> = vec![None; SOLVERS.len()];
        // Round 0 warms up (first use of the allocator, the caches, apex's
        // thread pool) and is not timed; from round 1 on, round r starts with
        // solver r mod 3, so that no solver always runs first or after the same one.
        for round in 0..=rounds {
            for step in 0..SOLVERS.len() {
                let k = (round + step) % SOLVERS.len();
                let (name, solve) = SOLVERS[k];
                let run = solve(&problem, max_iterations).map_err(|e| format!("{name} at {poses} poses: {e}"))?;
                if round > 0 {
                    times[k].push(run.solve_seconds);
                    last[k] = Some(run);
                }
            }
        }
        let reference_cost = last[0].as_ref().expect("a round").reported_final_cost;
        for (k, (name, _)) in SOLVERS.iter().enumerate() {
            let run = last[k].take().expect("a round");
            let at_solution = sagcal_cost_at(&problem, &run.solution).unwrap_or(f64::NAN);
            let ratios: Vec<f64> = times[k].iter().zip(&times[0]).map(|(t, s)| t / s).collect();
            eprintln!(
                "  {poses:>6} poses  {name:<12} {:>3} iterations  median {:.4} s  cost {:.12e}",
                run.iterations,
                median(times[k].clone()),
                run.reported_final_cost
            );
            rows.push(Row {
                poses,
                solver: name,
                iterations: run.iterations,
                solve_s: median(times[k].clone()),
                min_s: times[k].iter().cloned().fold(f64::INFINITY, f64::min),
                max_s: times[k].iter().cloned().fold(0.0, f64::max),
                solve_times_s: times[k].clone(),
                setup_s: run.setup_seconds,
                reported_cost: run.reported_final_cost,
                sagcal_cost_at_solution: at_solution,
                relative_cost_difference: (at_solution - reference_cost).abs() / reference_cost,
                ratio_median: median(ratios.clone()),
                ratio_min: ratios.iter().cloned().fold(f64::INFINITY, f64::min),
                ratio_max: ratios.iter().cloned().fold(0.0, f64::max),
            });
        }
    }
    print_table(&rows);
    let verdicts = targets(&rows, &args.poses);
    for line in &verdicts {
        println!("{line}");
    }
    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let json = serde_json::json!({
        "seed": args.seed,
        "small_rounds": small_repeats,
        "rounds": repeats,
        "large_rounds": large_repeats,
        "threads": 1,
        "rows": rows,
        "targets": verdicts,
    });
    let json_path = args.out.join("peers.json");
    std::fs::write(
        &json_path,
        serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?,
    )
    .map_err(|e| format!("{}: {e}", json_path.display()))?;
    let svg_path = args.out.join("peers.svg");
    std::fs::write(&svg_path, plot_svg(&rows)).map_err(|e| format!("{}: {e}", svg_path.display()))?;
    eprintln!("wrote {} and {}", json_path.display(), svg_path.display());
    Ok(())
}

fn print_table(rows: &[Row]) {
    println!("| poses | solver | iterations | solve ms min / median / max | ms / iteration (median) | time / sagcal per round: median (min - max) | final cost | sagcal cost at solution | rel. diff. to sagcal |");
    println!("|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        println!(
            "| {} | {} | {} | {:.2} / {:.2} / {:.2} | {:.3} | {:.2} ({:.2} - {:.2}) | {:.10e} | {:.10e} | {:.1e} |",
            r.poses,
            r.solver,
            r.iterations,
            1e3 * r.min_s,
            1e3 * r.solve_s,
            1e3 * r.max_s,
            1e3 * r.solve_s / r.iterations.max(1) as f64,
            r.ratio_median,
            r.ratio_min,
            r.ratio_max,
            r.reported_cost,
            r.sagcal_cost_at_solution,
            r.relative_cost_difference
        );
    }
}

/// The targets (issue 18): at every size sagcal at least 3x faster
/// than the fastest peer (median of the per-round ratios), every final cost
/// within 1e-9 of sagcal's; 10 000 poses under 0.5 s.
fn targets(rows: &[Row], poses: &[usize]) -> Vec<String> {
    let mut lines = Vec::new();
    for &n in poses {
        let at: Vec<&Row> = rows.iter().filter(|r| r.poses == n).collect();
        let Some(sagcal) = at.iter().find(|r| r.solver == "sagcal") else {
            continue;
        };
        let fastest_peer = at
            .iter()
            .filter(|r| r.solver != "sagcal")
            .min_by(|a, b| a.ratio_median.total_cmp(&b.ratio_median));
        if let Some(peer) = fastest_peer {
            lines.push(format!(
                "{n} poses: fastest peer {} takes {:.2}x sagcal's time (median of rounds; {:.2}x - {:.2}x) (target >= 3x: {})",
                peer.solver,
                peer.ratio_median,
                peer.ratio_min,
                peer.ratio_max,
                if peer.ratio_median >= 3.0 { "met" } else { "MISSED" }
            ));
        }
        let worst = at.iter().map(|r| r.relative_cost_difference).fold(0.0, f64::max);
        lines.push(format!(
            "{n} poses: largest relative final-cost difference to sagcal {worst:.1e} (target 1e-9: {})",
            if worst <= 1e-9 { "met" } else { "MISSED" }
        ));
        if n == 10_000 {
            lines.push(format!(
                "10000 poses: sagcal solves in {:.3} s median ({:.3} - {:.3}) on one thread (target < 0.5 s: {})",
                sagcal.solve_s,
                sagcal.min_s,
                sagcal.max_s,
                if sagcal.solve_s < 0.5 { "met" } else { "MISSED" }
            ));
        }
    }
    lines
}

/// Log-log plot of the median solve time against the number of poses.
fn plot_svg(rows: &[Row]) -> String {
    let (width, height) = (640.0, 420.0);
    let (left, right, top, bottom) = (70.0, 150.0, 30.0, 50.0);
    let xs: Vec<f64> = rows.iter().map(|r| (r.poses as f64).log10()).collect();
    let ys: Vec<f64> = rows.iter().map(|r| r.solve_s.max(1e-6).log10()).collect();
    let (x0, x1) = (
        xs.iter().cloned().fold(f64::INFINITY, f64::min).floor(),
        xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max).ceil(),
    );
    let (y0, y1) = (
        ys.iter().cloned().fold(f64::INFINITY, f64::min).floor(),
        ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max).ceil(),
    );
    let px = |x: f64| left + (x - x0) / (x1 - x0).max(1e-9) * (width - left - right);
    let py = |y: f64| height - bottom - (y - y0) / (y1 - y0).max(1e-9) * (height - top - bottom);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{}\" y=\"18\" text-anchor=\"middle\" font-size=\"14\">Solve time vs poses (one thread, median)</text>\n",
        (left + width - right) / 2.0
    );
    for decade in (x0 as i32)..=(x1 as i32) {
        let x = px(decade as f64);
        svg += &format!(
            "<line x1=\"{x:.1}\" y1=\"{top}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#ddd\"/><text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n",
            height - bottom,
            height - bottom + 16.0,
            10f64.powi(decade)
        );
    }
    for decade in (y0 as i32)..=(y1 as i32) {
        let y = py(decade as f64);
        svg += &format!(
            "<line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>\n",
            width - right,
            left - 6.0,
            y + 4.0,
            format_seconds(10f64.powi(decade))
        );
    }
    svg += &format!(
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">poses</text>\n<text x=\"16\" y=\"{:.1}\" text-anchor=\"middle\" transform=\"rotate(-90 16 {:.1})\">solve time</text>\n",
        (left + width - right) / 2.0,
        height - 12.0,
        (top + height - bottom) / 2.0,
        (top + height - bottom) / 2.0
    );
    let colours = [("sagcal", "#d62728"), ("apex-solver", "#1f77b4"), ("factrs", "#2ca02c")];
    for (k, (name, colour)) in colours.iter().enumerate() {
        let points: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.solver == *name)
            .map(|r| (px((r.poses as f64).log10()), py(r.solve_s.max(1e-6).log10())))
            .collect();
        if points.is_empty() {
            continue;
        }
        let path: Vec<String> = points.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        svg += &format!(
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>\n",
            path.join(" ")
        );
        for (x, y) in &points {
            svg += &format!("<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"3.5\" fill=\"{colour}\"/>\n");
        }
        let ly = top + 20.0 + 20.0 * k as f64;
        svg += &format!(
            "<line x1=\"{:.1}\" y1=\"{ly:.1}\" x2=\"{:.1}\" y2=\"{ly:.1}\" stroke=\"{colour}\" stroke-width=\"2\"/><text x=\"{:.1}\" y=\"{:.1}\">{name}</text>\n",
            width - right + 12.0,
            width - right + 36.0,
            width - right + 42.0,
            ly + 4.0
        );
    }
    svg += "</svg>\n";
    svg
}

fn format_seconds(s: f64) -> String {
    if s >= 1.0 {
        format!("{s:.0} s")
    } else if s >= 1e-3 {
        format!("{:.0} ms", s * 1e3)
    } else {
        format!("{:.0} us", s * 1e6)
    }
}

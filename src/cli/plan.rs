//! `sagcal plan`: choose the calibration poses that make the anchors
//! observable, order them into a short path, and compare with random poses;
//! its flags ([`PlanArgs`]) and the run.

use std::path::{Path, PathBuf};

use sagcal::error::FrontEnd;
use sagcal::experiments::pose_plan::{plan_calibration, CandidateSource, PlanProgress, PlanReport, PlanSettings};
use sagcal::io::measurements::{measurements_text, read_measurements, ReadOptions};
use sagcal::io::OutputSet;
use sagcal::model::robot::Workspace;
use sagcal::model::statics::Equilibrium;
use sagcal::model::Robot;
use sagcal::plan::information::noise_free_reading;
use sagcal::plan::Plan;
use sagcal::plot::figure_bytes;
use sagcal::plot::plan::{plan_plot_svg, PlanPlot};

use super::output::{print_json, progress_bar, Table};

#[derive(Debug, clap::Args)]
pub(super) struct PlanArgs {
    /// The nominal robot (TOML): the plan is computed at its anchors.
    #[arg(long)]
    robot: PathBuf,
    /// Poses to choose.
    #[arg(long)]
    poses: usize,
    /// Sensor noise the bound assumes: paper or authors.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    noise: sagcal::model::sensors::NoisePreset,
    /// The box candidates are drawn in, `x0,x1,y0,y1,z0,z1` metres (default: the
    /// robot file's `[workspace]`, else the frame below the anchors with a 10 % margin).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_workspace)]
    workspace: Option<sagcal::model::robot::Workspace>,
    /// Candidate poses from a file (sagcal CSV or RecurDyn log, e.g. poses already logged) instead of drawing them.
    #[arg(long)]
    from: Option<PathBuf>,
    /// Candidates to draw (without `--from`; each a level equilibrium, ~30 ms of CPU).
    #[arg(long, default_value_t = 1000)]
    candidates: usize,
    /// Random seed of the candidates and of the random sets compared with.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Design criterion: a (trace of the anchors' covariance) or d (log-determinant of the information).
    #[arg(long, default_value = "a", value_parser = sagcal::plan::Criterion::parse)]
    criterion: sagcal::plan::Criterion,
    /// The localiser's orientation as a prior in the bound: `on`, or `off`/`auto`
    /// (the statics alone decide the orientation; the bound reads `auto` as `off`).
    #[arg(long, default_value = "off", value_parser = sagcal::calib::OrientationPrior::parse)]
    orientation_prior: sagcal::calib::OrientationPrior,
    /// Write the plan (visiting order) as a sagcal measurement CSV (atomically).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the figure (PNG if the name ends in `.png`, SVG otherwise): frame, anchors, candidates,
    /// path, error ellipses plan vs random.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print JSON instead of the tables.
    #[arg(long)]
    json: bool,
}

/// `x0,x1,y0,y1,z0,z1` in metres (see `sagcal::experiments::pose_plan::parse_workspace`).
pub fn parse_workspace(text: &str) -> Result<Workspace, sagcal::error::ParseError> {
    sagcal::experiments::pose_plan::parse_workspace(text)
}

/// The settings of `args`; the candidates from `--from`, or drawn in
/// `--workspace`, the robot file's `[workspace]`, or the frame below the anchors.
fn settings(args: &PlanArgs, robot: &Robot) -> sagcal::Result<PlanSettings> {
    let candidates = match &args.from {
        Some(path) => CandidateSource::Logged {
            poses: read_measurements(
                path,
                &ReadOptions {
                    reference_cable: robot.reference_cable,
                    keep_rounded: false,
                },
            )?
            .poses,
            label: path.display().to_string(),
        },
        None => CandidateSource::Drawn {
            workspace: args.workspace,
            count: args.candidates,
        },
    };
    Ok(PlanSettings {
        poses: args.poses,
        noise: args.noise,
        candidates,
        seed: args.seed,
        criterion: args.criterion,
        orientation_prior: args.orientation_prior,
        front_end: FrontEnd::Cli,
    })
}

/// Plan, print the table (or JSON), write the CSV and the figure.
pub fn run(args: &PlanArgs) -> sagcal::Result<()> {
    let robot = Robot::from_file(&args.robot)?;
    eprintln!(
        "sagcal plan: seed {}, {} poses, {}-optimal",
        args.seed, args.poses, args.criterion
    );
    let settings = settings(args, &robot)?;
    let bar = progress_bar(1, "{msg} [{bar:30}] {pos}/{len}, {elapsed}");
    let planned = plan_calibration(&robot, &settings, &mut |step: PlanProgress<'_>| {
        let (done, total, what) = step.counts();
        bar.report(done, total, &what);
    });
    bar.finish_and_clear();
    let planned = planned?;
    let (report, plan) = (&planned.report, &planned.plan);
    let candidates = &report.candidates.equilibria;
    // All the files or none, none over an input.
    let mut outputs = OutputSet::new();
    outputs.input("--robot", &args.robot);
    if let Some(from) = &args.from {
        outputs.input("--from", from);
    }
    if let Some(path) = &args.out {
        outputs.file("--out", path, plan_csv(path, &robot, candidates, plan, args)?);
    }
    if let Some(path) = &args.plot {
        let svg = plot_svg(&robot, candidates, plan, report.workspace, args);
        outputs.file("--plot", path, figure_bytes(path, &svg)?);
    }
    outputs.write()?;
    if args.json {
        return print_json(report);
    }
    print_report(report, plan);
    Ok(())
}

/// The plan as a sagcal measurement CSV in visiting order (to be written to
/// `path`): commanded positions with the nominal model's orientation, lengths and tension.
fn plan_csv(
    path: &Path,
    robot: &Robot,
    candidates: &[Equilibrium],
    plan: &Plan,
    args: &PlanArgs,
) -> sagcal::Result<String> {
    let rows: Vec<_> = plan
        .order
        .iter()
        .map(|&k| noise_free_reading(robot, &candidates[k]))
        .collect();
    let comments = vec![
        format!(
            "sagcal plan: {} poses in visiting order ({}-optimal, seed {}, {} noise); path {:.1} m",
            plan.order.len(),
            args.criterion,
            args.seed,
            args.noise,
            plan.path_length_m
        ),
        format!(
            "bound (RMS per anchor): {:.3} m planned, {:.3} m for random sets of the same size",
            plan.bound.anchor_rms_m, plan.random.anchor_rms_m
        ),
        "orientation, lengths and tension: the nominal model's prediction at each commanded position".into(),
    ];
    measurements_text(path, &comments, &rows)
}

fn print_report(report: &PlanReport, plan: &Plan) {
    println!(
        "{} candidates ({}; {} outside the margins, {} unstable left out), {} chosen, {}-optimal, seed {}",
        report.candidates.equilibria.len(),
        report.candidates_from,
        report.candidates.outside_margins,
        report.candidates.unstable,
        report.poses,
        report.criterion,
        report.seed
    );
    let mut table = Table::new(["poses", "anchor bound m (RMS)", "offset bound m (RMS)"]);
    table.row([
        format!("plan, {}", report.poses),
        format!("{:.3}", report.anchor_bound_m),
        format!("{:.3}", report.offset_bound_m),
    ]);
    table.row([
        format!("random, {} (mean of {})", plan.random.poses, plan.random.draws),
        format!("{:.3}", plan.random.anchor_rms_m),
        format!("{:.3}", plan.random.offset_rms_m),
    ]);
    if let Some(r) = &plan.random35 {
        table.row([
            format!("random, 35 (mean of {})", r.draws),
            format!("{:.3}", r.anchor_rms_m),
            format!("{:.3}", r.offset_rms_m),
        ]);
    }
    println!("{table}");
    let mut path = Table::new(["visit", "x m", "y m", "z m", "min f_h N"]);
    for p in &report.plan {
        path.row([
            p.visit.to_string(),
            format!("{:.2}", p.position_m[0]),
            format!("{:.2}", p.position_m[1]),
            format!("{:.2}", p.position_m[2]),
            format!("{:.1}", p.min_horizontal_tension_n),
        ]);
    }
    println!("{path}");
    println!("path length {:.1} m (nearest neighbour + 2-opt)", report.path_length_m);
}

/// The figure (SVG; see `sagcal::plot::plan`).
fn plot_svg(
    robot: &Robot,
    candidates: &[Equilibrium],
    plan: &Plan,
    workspace: Option<Workspace>,
    args: &PlanArgs,
) -> String {
    let plot = PlanPlot {
        title: format!(
            "sagcal plan: {} poses for robot {} ({}-optimal, {} noise)",
            plan.order.len(),
            robot.name,
            args.criterion,
            args.noise
        ),
        caption: format!(
            "seed {}; {} candidates; bound (RMS per anchor) {:.3} m planned vs {:.3} m random {} (mean of {}){}; path {:.1} m",
            args.seed,
            candidates.len(),
            plan.bound.anchor_rms_m,
            plan.random.anchor_rms_m,
            plan.random.poses,
            plan.random.draws,
            plan.random35
                .as_ref()
                .map_or(String::new(), |r| format!(", {:.3} m random 35", r.anchor_rms_m)),
            plan.path_length_m
        ),
        anchors_m: robot.anchors_m.iter().map(|a| [a.x, a.y, a.z]).collect(),
        workspace_m: workspace.map(|w| (w.min_m, w.max_m)),
        candidates_m: candidates.iter().map(|e| e.pose.position_m.into()).collect(),
        path_m: plan.order.iter().map(|&k| candidates[k].pose.position_m.into()).collect(),
        plan_covariance_m2: plan.bound.anchor_covariance_m2.clone(),
        random_covariance_m2: plan.random.anchor_covariance_m2.clone(),
    };
    plan_plot_svg(&plot)
}

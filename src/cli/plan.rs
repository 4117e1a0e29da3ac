//! `sagcal plan`: choose the calibration poses that make the anchors
//! observable, order them into a short path, and compare with random poses;
//! the run on four cables (a robot of 3 to 8 cables goes to
//! [`super::plan_suspended`]).

use std::path::Path;

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

use super::output::{print_json, progress_bar};
use super::plan_args::PlanArgs;
use super::plan_tables::{plan_caption, print_plan_tables, Visit};
use super::robot_kind::{read_robot, AnyRobot};

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
    let robot = match read_robot(&args.robot)? {
        AnyRobot::Four(robot) => *robot,
        AnyRobot::Suspended(robot) => return super::plan_suspended::run(args, &robot),
    };
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
    let visits: Vec<Visit> = report
        .plan
        .iter()
        .map(|p| Visit {
            visit: p.visit,
            position_m: p.position_m,
            min_horizontal_tension_n: p.min_horizontal_tension_n,
        })
        .collect();
    print_plan_tables(plan, &visits);
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
        caption: plan_caption(plan, args.seed, candidates.len()),
        anchors_m: robot.anchors_m.iter().map(|a| [a.x, a.y, a.z]).collect(),
        workspace_m: workspace.map(|w| (w.min_m, w.max_m)),
        candidates_m: candidates.iter().map(|e| e.pose.position_m.into()).collect(),
        path_m: plan
            .order
            .iter()
            .map(|&k| candidates[k].pose.position_m.into())
            .collect(),
        plan_covariance_m2: plan.bound.anchor_covariance_m2.clone(),
        random_covariance_m2: plan.random.anchor_covariance_m2.clone(),
    };
    plan_plot_svg(&plot)
}

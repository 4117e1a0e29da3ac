//! `sagcal plan` on a robot of 3 to 8 cables
//! ([`sagcal::experiments::suspended_plan`]): the same table, JSON, CSV and
//! figure as for four cables, with a column per cable.

use std::path::Path;

use sagcal::error::FrontEnd;
use sagcal::experiments::pose_plan::PlanProgress;
use sagcal::experiments::suspended_plan::{plan_suspended, LoggedPoses, SuspendedPlanSettings, SuspendedPlanned};
use sagcal::io::suspended_measurements::{read_suspended_measurements, suspended_measurements_text};
use sagcal::io::OutputSet;
use sagcal::model::suspended::SuspendedRobot;
use sagcal::plan::suspended_information::noise_free_suspended_reading;
use sagcal::plot::figure_bytes;
use sagcal::plot::plan::{plan_plot_svg, PlanPlot};

use super::output::{print_json, progress_bar};
use super::plan_args::PlanArgs;
use super::plan_tables::{plan_caption, print_plan_tables, Visit};

/// Plan `robot` as `args` ask, print the table (or JSON), write the CSV and the figure.
pub(super) fn run(args: &PlanArgs, robot: &SuspendedRobot) -> sagcal::Result<()> {
    eprintln!(
        "sagcal plan: seed {}, {} poses, {}-optimal, {} cables",
        args.seed,
        args.poses,
        args.criterion,
        robot.cable_count()
    );
    let settings = SuspendedPlanSettings {
        poses: args.poses,
        noise: args.noise,
        candidates: args.candidates,
        workspace: args.workspace,
        seed: args.seed,
        criterion: args.criterion,
        orientation_prior: args.orientation_prior,
        front_end: FrontEnd::Cli,
        logged: match &args.from {
            Some(path) => Some(LoggedPoses {
                rows: read_suspended_measurements(path, robot)?,
                label: path.display().to_string(),
            }),
            None => None,
        },
    };
    let bar = progress_bar(1, "{msg} [{bar:30}] {pos}/{len}, {elapsed}");
    let planned = plan_suspended(robot, &settings, &mut |step: PlanProgress<'_>| {
        let (done, total, what) = step.counts();
        bar.report(done, total, &what);
    });
    bar.finish_and_clear();
    let planned = planned?;
    // All the files or none, none over an input.
    let mut outputs = OutputSet::new();
    outputs.input("--robot", &args.robot);
    if let Some(from) = &args.from {
        outputs.input("--from", from);
    }
    if let Some(path) = &args.out {
        outputs.file("--out", path, plan_csv(path, robot, &planned, args)?);
    }
    if let Some(path) = &args.plot {
        outputs.file("--plot", path, figure_bytes(path, &plot_svg(robot, &planned, args))?);
    }
    outputs.write()?;
    if args.json {
        return print_json(&planned.report);
    }
    print_report(&planned);
    Ok(())
}

/// The plan as a measurement CSV of `N` cables in visiting order: commanded
/// positions with the nominal model's orientation, paid-out lengths and tensions.
fn plan_csv(
    path: &Path,
    robot: &SuspendedRobot,
    planned: &SuspendedPlanned,
    args: &PlanArgs,
) -> sagcal::Result<String> {
    let plan = &planned.plan;
    let rows: Vec<_> = plan
        .order
        .iter()
        .map(|&k| noise_free_suspended_reading(robot, &planned.candidates[k]))
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
        "orientation, lengths and tensions: the nominal model's prediction at each commanded position".into(),
    ];
    suspended_measurements_text(path, robot, &comments, &rows)
}

fn print_report(planned: &SuspendedPlanned) {
    let (report, plan) = (&planned.report, &planned.plan);
    println!(
        "{} candidates ({}; {} below the {:.1} N tension margin left out), {} chosen, {}-optimal, seed {}",
        report.examined - report.outside_margins,
        report.candidates_from,
        report.outside_margins,
        report.min_horizontal_tension_n,
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
fn plot_svg(robot: &SuspendedRobot, planned: &SuspendedPlanned, args: &PlanArgs) -> String {
    let (plan, candidates) = (&planned.plan, &planned.candidates);
    let w = planned.report.workspace;
    let plot = PlanPlot {
        title: format!(
            "sagcal plan: {} poses for robot {} ({} cables, {}-optimal, {} noise)",
            plan.order.len(),
            robot.name,
            robot.cable_count(),
            args.criterion,
            args.noise
        ),
        caption: plan_caption(plan, args.seed, candidates.len()),
        anchors_m: robot.anchors_m.iter().map(|a| [a.x, a.y, a.z]).collect(),
        workspace_m: Some((w.min_m, w.max_m)),
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

//! `sagcal plan`: choose the calibration poses that make the anchors
//! observable, order them into a short path, and compare with random poses.

use std::path::Path;

use nalgebra::Vector3;
use serde::Serialize;

use sagcal::calib::{CalibrationOptions, OrientationPrior};
use sagcal::experiments::plan_candidates::{draw_candidates, filter_candidates, frame_workspace, CandidateSet};
use sagcal::experiments::table2::{pose_pool, Source};
use sagcal::io::measurements::{read_measurements, write_measurements, ReadOptions};
use sagcal::model::robot::Workspace;
use sagcal::model::statics::Equilibrium;
use sagcal::model::Robot;
use sagcal::plan::information::noise_free_reading;
use sagcal::plan::{candidate_information, plan_poses, DesignOptions, Margins, Plan};
use sagcal::plot::plan::{plan_plot_svg, PlanPlot};
use sagcal::plot::write_figure;

use super::output::{print_json, progress_bar, Table};
use super::PlanArgs;

/// One pose of the plan, in visiting order.
#[derive(Debug, Clone, Serialize)]
struct PlannedPose {
    /// 1-based position in the visiting order.
    visit: usize,
    /// Commanded platform position, metres.
    position_m: [f64; 3],
    /// The nominal model's orientation at that position, degrees.
    roll_pitch_yaw_deg: [f64; 3],
    /// The nominal model's cable lengths, metres.
    cable_lengths_m: [f64; 4],
    /// The smallest horizontal cable tension, newtons.
    min_horizontal_tension_n: f64,
}

#[derive(Debug, Clone, Serialize)]
struct Report {
    robot: String,
    seed: u64,
    noise: sagcal::model::sensors::NoisePreset,
    criterion: sagcal::plan::Criterion,
    orientation_prior: OrientationPrior,
    workspace: Option<Workspace>,
    candidates_from: String,
    candidates: CandidateSet,
    margins: Margins,
    poses: usize,
    anchor_bound_m: f64,
    offset_bound_m: f64,
    random_anchor_bound_m: f64,
    random_offset_bound_m: f64,
    random35_anchor_bound_m: Option<f64>,
    path_length_m: f64,
    ridge: f64,
    exchanges: usize,
    plan: Vec<PlannedPose>,
}

/// `x0,x1,y0,y1,z0,z1` in metres.
pub fn parse_workspace(text: &str) -> Result<Workspace, String> {
    let v: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|_| format!("`{p}` is not a number")))
        .collect::<Result<_, _>>()?;
    if v.len() != 6 || v.iter().any(|x| !x.is_finite()) || v[0] >= v[1] || v[2] >= v[3] || v[4] >= v[5] {
        return Err(format!(
            "`{text}`: a workspace is six finite numbers x0,x1,y0,y1,z0,z1 (metres) with x0 < x1, y0 < y1, z0 < z1"
        ));
    }
    Ok(Workspace {
        min_m: [v[0], v[2], v[4]],
        max_m: [v[1], v[3], v[5]],
    })
}

/// The candidates: from `--from`, or drawn in `--workspace`, the robot
/// file's `[workspace]`, or the frame below the anchors.
fn candidates(
    args: &PlanArgs,
    robot: &Robot,
    margins: &Margins,
) -> sagcal::Result<(CandidateSet, Option<Workspace>, String)> {
    if let Some(path) = &args.from {
        let data = read_measurements(
            path,
            &ReadOptions {
                reference_cable: robot.reference_cable,
                keep_rounded: false,
            },
        )?;
        let pool = pose_pool(robot, &data.poses, Source::Model)?;
        let set = filter_candidates(robot, pool.into_iter().map(|p| p.equilibrium).collect(), margins);
        return Ok((set, None, path.display().to_string()));
    }
    let (workspace, from) = match (args.workspace, robot.workspace) {
        (Some(w), _) => (w, "--workspace"),
        (None, Some(w)) => (w, "the robot file's [workspace]"),
        (None, None) => (
            frame_workspace(robot),
            "the frame below the anchors (10 % margin, z 5-75 % of the anchors' height)",
        ),
    };
    let bar = progress_bar(1, "{msg} {spinner} {elapsed}");
    bar.set_message(format!(
        "drawing {} candidate poses in {from}, seed {}",
        args.candidates, args.seed
    ));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let set = draw_candidates(robot, &workspace, args.candidates, margins, args.seed)?;
    bar.finish_and_clear();
    Ok((set, Some(workspace), format!("{} drawn in {from}", args.candidates)))
}

/// Plan, print the table (or JSON), write the CSV and the figure.
pub fn run(args: &PlanArgs) -> sagcal::Result<()> {
    let robot = Robot::from_file(&args.robot)?;
    let margins = Margins::for_robot(&robot);
    eprintln!(
        "sagcal plan: seed {}, {} poses, {:?}-optimal",
        args.seed, args.poses, args.criterion
    );
    let (set, workspace, from) = candidates(args, &robot, &margins)?;
    if set.equilibria.len() < args.poses {
        return Err(sagcal::Error::InvalidInput(format!(
            "{} poses requested but only {} candidates keep the margins and are stable ({} outside the margins, {} unstable)",
            args.poses,
            set.equilibria.len(),
            set.outside_margins,
            set.unstable
        )));
    }
    let mut options = CalibrationOptions::new(args.noise.sigmas(robot.platform_weight_n));
    options.orientation_prior = args.orientation_prior;
    let information = candidate_information(&robot, &set.equilibria, &options)?;
    let design = DesignOptions {
        criterion: args.criterion,
        ..DesignOptions::new(args.poses)
    };
    let start = start_point(&set.equilibria);
    let plan = plan_poses(&set.equilibria, &information, &design, &start, args.seed)?;
    let report = report(args, &robot, &set, workspace, from, margins, &plan);
    if let Some(path) = &args.out {
        write_plan_csv(path, &robot, &set.equilibria, &plan, args)?;
    }
    if let Some(path) = &args.plot {
        write_plot(path, &robot, &set.equilibria, &plan, workspace, args)?;
    }
    if args.json {
        return print_json(&report);
    }
    print_report(&report, &plan);
    Ok(())
}

/// Where the path starts: the candidate nearest the middle of the floor of
/// the candidates' region (an operator's usual home position).
fn start_point(candidates: &[Equilibrium]) -> Vector3<f64> {
    let n = candidates.len().max(1) as f64;
    let mut centre = candidates.iter().map(|e| e.pose.position_m).sum::<Vector3<f64>>() / n;
    centre.z = candidates
        .iter()
        .map(|e| e.pose.position_m.z)
        .fold(f64::INFINITY, f64::min);
    centre
}

fn report(
    args: &PlanArgs,
    robot: &Robot,
    set: &CandidateSet,
    workspace: Option<Workspace>,
    from: String,
    margins: Margins,
    plan: &Plan,
) -> Report {
    let poses = plan
        .order
        .iter()
        .enumerate()
        .map(|(visit, &k)| {
            let eq = &set.equilibria[k];
            let (r, p, y) = eq.pose.roll_pitch_yaw_deg();
            PlannedPose {
                visit: visit + 1,
                position_m: eq.pose.position_m.into(),
                roll_pitch_yaw_deg: [r, p, y],
                cable_lengths_m: eq.cable_lengths_m,
                min_horizontal_tension_n: eq.tensions.iter().map(|t| t.horizontal_n).fold(f64::INFINITY, f64::min),
            }
        })
        .collect();
    Report {
        robot: robot.name.clone(),
        seed: args.seed,
        noise: args.noise,
        criterion: args.criterion,
        orientation_prior: args.orientation_prior,
        workspace,
        candidates_from: from,
        candidates: set.clone(),
        margins,
        poses: plan.order.len(),
        anchor_bound_m: plan.bound.anchor_rms_m,
        offset_bound_m: plan.bound.offset_rms_m,
        random_anchor_bound_m: plan.random.anchor_rms_m,
        random_offset_bound_m: plan.random.offset_rms_m,
        random35_anchor_bound_m: plan.random35.as_ref().map(|r| r.anchor_rms_m),
        path_length_m: plan.path_length_m,
        ridge: plan.design.ridge,
        exchanges: plan.design.exchanges,
        plan: poses,
    }
}

/// The plan as a sagcal measurement CSV in visiting order: commanded
/// positions with the nominal model's orientation, lengths and tension.
fn write_plan_csv(
    path: &Path,
    robot: &Robot,
    candidates: &[Equilibrium],
    plan: &Plan,
    args: &PlanArgs,
) -> sagcal::Result<()> {
    let rows: Vec<_> = plan
        .order
        .iter()
        .map(|&k| noise_free_reading(robot, &candidates[k]))
        .collect();
    let comments = vec![
        format!(
            "sagcal plan: {} poses in visiting order ({:?}-optimal, seed {}, {} noise); path {:.1} m",
            plan.order.len(),
            args.criterion,
            args.seed,
            format!("{:?}", args.noise).to_lowercase(),
            plan.path_length_m
        ),
        format!(
            "bound (RMS per anchor): {:.3} m planned, {:.3} m for random sets of the same size",
            plan.bound.anchor_rms_m, plan.random.anchor_rms_m
        ),
        "orientation, lengths and tension: the nominal model's prediction at each commanded position".into(),
    ];
    write_measurements(path, &comments, &rows)
}

fn print_report(report: &Report, plan: &Plan) {
    println!(
        "{} candidates ({}; {} outside the margins, {} unstable left out), {} chosen, {:?}-optimal, seed {}",
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

/// The figure (see `sagcal::plot::plan`).
fn write_plot(
    path: &Path,
    robot: &Robot,
    candidates: &[Equilibrium],
    plan: &Plan,
    workspace: Option<Workspace>,
    args: &PlanArgs,
) -> sagcal::Result<()> {
    let plot = PlanPlot {
        title: format!(
            "sagcal plan: {} poses for robot {} ({:?}-optimal, {} noise)",
            plan.order.len(),
            robot.name,
            args.criterion,
            format!("{:?}", args.noise).to_lowercase()
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
    write_figure(path, &plan_plot_svg(&plot))
}

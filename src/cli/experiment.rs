//! `sagcal experiment table2`: the paper's calibration protocol; its flags
//! ([`Table2Args`]) and the run.

use sagcal::calib::{CableModel, OrientationPrior};
use sagcal::experiments::selection::{PlanSettings, Selection};
use sagcal::experiments::table2::{
    check_counts, pose_pool, run_selected_protocol, PoolPose, PoseCountResult, Protocol, Source,
};
use sagcal::io::measurements::{read_measurements, ReadOptions};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use serde::Serialize;

use sagcal::model::effect_kind::{EffectKind, EffectSet};

use super::output::{print_json, progress_bar, Table};
use super::robot_kind::{read_robot, AnyRobot};
pub(super) use super::table2_args::Table2Args;

/// The paper's Table II: (poses, anchor MAE m, offset MAE m) per robot.
const PAPER_LARGE: [(usize, f64, f64); 3] = [(9, 0.387, 0.380), (18, 0.226, 0.217), (35, 0.191, 0.173)];
const PAPER_SMALL: [(usize, f64, f64); 1] = [(8, 0.149, 0.115)];

#[derive(Serialize)]
struct Table2Report {
    robot: String,
    data: String,
    source: Source,
    noise: NoisePreset,
    model: CableModel,
    seed: u64,
    anchor_perturbation_m: f64,
    offset_perturbation_m: f64,
    basin_radius_m: f64,
    orientation_prior: sagcal::calib::OrientationPrior,
    pool_size: usize,
    /// `--select` when not random: the selection and the planner's anchor error, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    select: Option<(String, f64)>,
    results: Vec<PoseCountResult>,
}

/// The paper's (anchor, offset) MAE for this robot and pose count, if it gives one.
fn paper_numbers(robot: &Robot, poses: usize) -> Option<(f64, f64)> {
    let table: &[(usize, f64, f64)] = if robot.platform_weight_n < 100.0 {
        &PAPER_SMALL
    } else {
        &PAPER_LARGE
    };
    table.iter().find(|(n, _, _)| *n == poses).map(|(_, a, o)| (*a, *o))
}

/// Run the Table II protocol on the log's poses and print the table (or JSON).
/// Run the protocol on the robot of `--robot`: the four-cable Table II on
/// the log's poses, or for a robot of 3 to 8 cables
/// [`super::experiment_suspended::run`].
pub fn run(args: &Table2Args) -> sagcal::Result<()> {
    let truth = match read_robot(&args.robot)? {
        AnyRobot::Four(robot) => *robot,
        AnyRobot::Suspended(robot) => return super::experiment_suspended::run(args, &robot),
    };
    let data_path = args.data.as_ref().ok_or_else(|| {
        sagcal::Error::InvalidInput(format!(
            "--data is required: robot `{}` has four cables, whose Table II samples the poses of a log",
            truth.name
        ))
    })?;
    let data = read_measurements(
        data_path,
        &ReadOptions {
            reference_cable: truth.reference_cable,
            keep_rounded: false,
        },
    )?;
    let pool = pose_pool(&truth, &data.poses, args.source)?;
    check_counts(&args.poses, args.trials, pool.len())?;
    let protocol = protocol(args, &truth)?;
    let results = run_trials(args, &truth, &pool, &protocol)?;
    let report = Table2Report {
        robot: truth.name.clone(),
        data: data_path.display().to_string(),
        source: args.source,
        noise: args.noise,
        model: args.model,
        seed: args.seed,
        anchor_perturbation_m: protocol.anchor_perturbation_m,
        offset_perturbation_m: protocol.offset_perturbation_m,
        basin_radius_m: protocol.basin_radius_m,
        orientation_prior: args.orientation_prior,
        pool_size: pool.len(),
        select: (args.select != "random").then(|| (args.select.clone(), args.plan_anchor_error_m)),
        results,
    };
    if args.json {
        return print_json(&report);
    }
    print_table(args, &truth, &report);
    print_bound_verdicts(&truth, &report);
    Ok(())
}

/// The protocol of the arguments, with the robot's default perturbations
/// (10 m / 80 m off, 1 m / 10 m for a light robot) and basin radius.
fn protocol(args: &Table2Args, truth: &Robot) -> sagcal::Result<Protocol> {
    let light = truth.platform_weight_n < 100.0;
    let anchor_perturbation_m = args.anchor_perturbation_m.unwrap_or(if light { 1.0 } else { 10.0 });
    let offset_perturbation_m = args.offset_perturbation_m.unwrap_or(if light { 10.0 } else { 80.0 });
    let basin_radius_m = args.basin_radius_m.unwrap_or(match args.model {
        CableModel::Catenary => 0.3 * anchor_perturbation_m,
        CableModel::Rigid => f64::INFINITY,
    });
    for (flag, value) in [
        ("--anchor-perturbation-m", anchor_perturbation_m),
        ("--offset-perturbation-m", offset_perturbation_m),
        ("--plan-anchor-error-m", args.plan_anchor_error_m),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(sagcal::Error::InvalidInput(format!(
                "{flag} must be a finite distance >= 0 m, got {value}"
            )));
        }
    }
    if basin_radius_m.is_nan() || basin_radius_m < 0.0 {
        return Err(sagcal::Error::InvalidInput(format!(
            "--basin-radius-m must be >= 0 m, got {basin_radius_m}"
        )));
    }
    Ok(Protocol {
        noise: args.noise,
        model: args.model,
        anchor_perturbation_m,
        offset_perturbation_m,
        basin_radius_m,
        orientation_prior: args.orientation_prior,
        estimate: args.estimate.as_deref().map_or(Ok(EffectSet::NONE), parse_effect_set)?,
        apply_gross_errors: args.apply_gross_errors,
    })
}

/// The trials of every pose count, announced on stderr, with a progress bar.
fn run_trials(
    args: &Table2Args,
    truth: &Robot,
    pool: &[PoolPose],
    protocol: &Protocol,
) -> sagcal::Result<Vec<PoseCountResult>> {
    let total = (args.poses.len() * args.trials) as u64;
    eprintln!(
        "sagcal experiment table2: seed {}, {} trials x {} poses, {} noise, {} model, {} data ({} usable poses)",
        args.seed,
        args.trials,
        args.poses.iter().map(usize::to_string).collect::<Vec<_>>().join(","),
        args.noise,
        args.model,
        match args.source {
            Source::Log => "logged",
            Source::Model => "model-generated",
        },
        pool.len()
    );
    let selection = selection(args)?;
    if selection != Selection::Random {
        eprintln!(
            "poses chosen: {} ({}-optimal on the bound, planner's anchors {} m off the truth)",
            args.select, args.plan_criterion, args.plan_anchor_error_m
        );
    }
    // The bar after the lines above: a live bar would be written over.
    let bar = progress_bar(total, "{msg} [{bar:40}] {pos}/{len} trials, {elapsed} (eta {eta})");
    bar.set_message(format!("table2 seed {}", args.seed));
    let results = run_selected_protocol(
        truth,
        pool,
        &args.poses,
        args.trials,
        args.seed,
        protocol,
        &selection,
        &|| bar.inc(1),
    )?;
    bar.finish_and_clear();
    Ok(results)
}

/// `--select`: the plan's bound uses the orientation prior where the
/// calibration keeps it (`auto`: on model data, not on the RecurDyn log).
fn selection(args: &Table2Args) -> sagcal::Result<Selection> {
    if !(args.plan_anchor_error_m.is_finite() && args.plan_anchor_error_m >= 0.0) {
        return Err(sagcal::Error::InvalidInput(format!(
            "--plan-anchor-error-m must be a non-negative distance in metres, got {}",
            args.plan_anchor_error_m
        )));
    }
    let orientation_prior = match (args.orientation_prior, args.source) {
        (OrientationPrior::Auto, Source::Model) => OrientationPrior::On,
        (OrientationPrior::Auto, Source::Log) => OrientationPrior::Off,
        (other, _) => other,
    };
    let settings = PlanSettings {
        criterion: args.plan_criterion,
        orientation_prior,
        anchor_error_m: args.plan_anchor_error_m,
    };
    Ok(match args.select.as_str() {
        "planned" => Selection::Planned(settings),
        "sequential" => Selection::Sequential(settings),
        _ => Selection::Random,
    })
}

/// The readable Table II: the protocol's heading, then per pose count the
/// errors beside the bound and the paper, with the bound's legend.
fn print_table(args: &Table2Args, truth: &Robot, report: &Table2Report) {
    if args.select != "random" {
        println!(
            "poses: {} ({}-optimal; planner's anchors {} m off the truth)",
            args.select, args.plan_criterion, args.plan_anchor_error_m
        );
    }
    println!(
        "Table II protocol: robot `{}`, {} data, {} noise, {} cable model, orientation prior {}, seed {}, initial guess {} m / {} m off",
        report.robot,
        match args.source {
            Source::Log => "logged (RecurDyn)",
            Source::Model => "model-generated",
        },
        args.noise,
        args.model,
        args.orientation_prior,
        args.seed,
        report.anchor_perturbation_m,
        report.offset_perturbation_m
    );
    if let Some(estimate) = &args.estimate {
        println!("effects estimated with the anchors: {estimate}");
    }
    let mut table = Table::new([
        "poses",
        "converged",
        "anchor m (mean Eucl.)",
        "anchor m (per coord)",
        "offset m",
        "CRLB anchor m",
        "CRLB offset m",
        "paper anchor / offset m",
        "orientation prior kept",
        "readings flagged / inconsistent",
        "median ms",
    ]);
    for r in &report.results {
        let paper = paper_numbers(truth, r.poses);
        table.row([
            r.poses.to_string(),
            format!("{}/{}", r.converged, r.trials),
            format!("{:.3} +- {:.3}", r.anchor_mae_m, r.anchor_mae_standard_error_m),
            format!("{:.3}", r.anchor_coord_mae_m),
            format!("{:.3}", r.offset_mae_m),
            format!("{:.3}", r.anchor_crlb_m),
            format!("{:.3}", r.offset_crlb_m),
            paper.map_or("-".into(), |(a, o)| format!("{a:.3} / {o:.3}")),
            match args.orientation_prior {
                _ if args.model == CableModel::Rigid => "all (rigid model)".into(),
                OrientationPrior::Auto => format!("{}/{}", r.orientation_prior_kept, r.trials),
                OrientationPrior::On => "all".into(),
                OrientationPrior::Off => "none".into(),
            },
            format!("{} / {}", r.readings_left_out, r.inconsistent),
            format!("{:.0}", r.median_solve_ms),
        ]);
    }
    print!("{table}");
    println!("(CRLB: the error an unbiased estimator cannot beat on average, at the truth, for the same poses, noise and orientation prior;\n anchor errors are the mean Euclidean distance per anchor, as in the authors' program, +- the standard error of the mean over trials;\n readings flagged: by `calibrate`'s gross-error tests over all trials (left out only with --apply-gross-errors); inconsistent: trials whose fit fails them, which `calibrate` would refuse)");
}

/// Per pose count: whether the paper's anchor error is below the bound, and
/// the trials that did not converge.
fn print_bound_verdicts(truth: &Robot, report: &Table2Report) {
    for r in &report.results {
        if let Some((paper_anchor, _)) = paper_numbers(truth, r.poses) {
            let verdict = if paper_anchor < r.anchor_crlb_m {
                "below the bound: not reachable by an unbiased estimator under this noise reading"
            } else {
                "above the bound: reachable"
            };
            println!(
                "{} poses: the paper's {:.3} m is {} ({:.3} m)",
                r.poses, paper_anchor, verdict, r.anchor_crlb_m
            );
        }
        for t in &r.not_converged {
            println!(
                "  {} poses, trial {} did not converge: {}",
                r.poses,
                t.trial,
                t.failure.as_deref().unwrap_or("?")
            );
        }
    }
}

/// `--estimate`: effect names, comma separated.
fn parse_effect_set(list: &str) -> sagcal::Result<EffectSet> {
    list.split(',')
        .map(EffectKind::parse)
        .collect::<Result<EffectSet, _>>()
        .map_err(|e| sagcal::Error::InvalidInput(format!("--estimate: {e}")))
}

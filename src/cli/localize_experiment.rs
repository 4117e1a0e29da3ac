//! `sagcal experiment localize`: calibrate by the Table II protocol, then
//! localise the held-out poses (`experiments::localize_after_calibration`);
//! its flags ([`LocalizeExperimentArgs`]) and the run.

use std::path::PathBuf;

use serde::Serialize;

use sagcal::calib::{CableModel, OrientationPrior};
use sagcal::experiments::localize_after_calibration::{run, summarise, LocalizeSummary};
use sagcal::experiments::table2::{pose_pool, Protocol, Source};
use sagcal::io::measurements::{read_measurements, ReadOptions};
use sagcal::model::effect_kind::EffectSet;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;

use super::output::{print_json, progress_bar, Table};
use super::parse::{parse_noises, parse_sources};

#[derive(Debug, clap::Args)]
pub(super) struct LocalizeExperimentArgs {
    /// The robot the data were logged on (truth: its anchors, zero offsets).
    #[arg(long)]
    robot: PathBuf,
    /// A RecurDyn log or sagcal measurement file: the pool of poses.
    #[arg(long)]
    data: PathBuf,
    /// Calibration poses per trial; the rest of the pool is localised.
    #[arg(long, default_value_t = 35)]
    poses: usize,
    /// Trials per case.
    #[arg(long, default_value_t = 50)]
    trials: usize,
    /// Base random seed (printed; each trial's streams derive from it).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Noise: paper, authors, or both.
    #[arg(long, default_value = "both", value_parser = parse_noises)]
    noise: std::vec::Vec<sagcal::model::sensors::NoisePreset>,
    /// Data: log, model, or both (`model`: the closed-form equilibria at the logged poses).
    #[arg(long, default_value = "both", value_parser = parse_sources)]
    source: std::vec::Vec<sagcal::experiments::table2::Source>,
    /// Print JSON instead of the table.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct Case {
    source: Source,
    noise: NoisePreset,
    summary: LocalizeSummary,
}

#[derive(Debug, Serialize)]
struct Report {
    robot: String,
    data: String,
    seed: u64,
    poses: usize,
    pool_size: usize,
    cases: Vec<Case>,
}

/// The Table II protocol's defaults for `truth` (its perturbations of the
/// initial guess: 10 m / 80 m, 1 m / 10 m for a light robot).
fn table2_protocol(truth: &Robot, noise: NoisePreset) -> Protocol {
    let light = truth.platform_weight_n < 100.0;
    let anchor_perturbation_m = if light { 1.0 } else { 10.0 };
    Protocol {
        noise,
        model: CableModel::Catenary,
        anchor_perturbation_m,
        offset_perturbation_m: if light { 10.0 } else { 80.0 },
        basin_radius_m: 0.3 * anchor_perturbation_m,
        orientation_prior: OrientationPrior::Auto,
        estimate: EffectSet::NONE,
        apply_gross_errors: false,
    }
}

/// Run every (source, noise) case and print the table (or JSON).
pub fn run_experiment(args: &LocalizeExperimentArgs) -> sagcal::Result<()> {
    if args.poses < sagcal::calib::MIN_POSES {
        return Err(sagcal::Error::InvalidInput(format!(
            "--poses {}: at least {} calibration poses per trial are needed",
            args.poses,
            sagcal::calib::MIN_POSES
        )));
    }
    if args.trials == 0 {
        return Err(sagcal::Error::InvalidInput("--trials must be at least 1".into()));
    }
    let truth = Robot::from_file(&args.robot)?;
    let data = read_measurements(
        &args.data,
        &ReadOptions {
            reference_cable: truth.reference_cable,
            keep_rounded: false,
        },
    )?;
    if args.poses >= data.poses.len() {
        return Err(sagcal::Error::InvalidInput(format!(
            "--poses {} leaves no pose of the {} in {} to localise",
            args.poses,
            data.poses.len(),
            args.data.display()
        )));
    }
    eprintln!(
        "sagcal experiment localize: seed {}, {} trials, calibrate on {} poses, localise the other {}",
        args.seed,
        args.trials,
        args.poses,
        data.poses.len() - args.poses
    );
    let mut cases = Vec::new();
    for &source in &args.source {
        let pool = pose_pool(&truth, &data.poses, source)?;
        for &noise in &args.noise {
            let bar = progress_bar(args.trials as u64, "{msg} [{bar:40}] {pos}/{len} trials, {elapsed}");
            bar.set_message(format!("{source} data, {noise} noise"));
            let protocol = table2_protocol(&truth, noise);
            let trials = run(&truth, &pool, args.poses, args.trials, args.seed, &protocol, &|| {
                bar.inc(1)
            });
            bar.finish_and_clear();
            cases.push(Case {
                source,
                noise,
                summary: summarise(&trials)?,
            });
        }
    }
    let report = Report {
        robot: truth.name.clone(),
        data: args.data.display().to_string(),
        seed: args.seed,
        poses: args.poses,
        pool_size: data.poses.len(),
        cases,
    };
    if args.json {
        return print_json(&report);
    }
    print_report(&report);
    Ok(())
}

fn print_report(report: &Report) {
    println!(
        "localisation after calibration: robot {}, data {}, seed {}; calibrate on {} of {} poses (Table II protocol), localise the other {} from encoders and load cell (cold starts)\n",
        report.robot,
        report.data,
        report.seed,
        report.poses,
        report.pool_size,
        report.pool_size - report.poses
    );
    let mut table = Table::new([
        "data",
        "noise",
        "trials",
        "anchor err m",
        "RMS mm",
        "median trial RMS mm",
        "max mm",
        "predicted sigma mm",
        "within 95 %",
        "flagged",
        "truth RMS mm",
    ]);
    for case in &report.cases {
        let s = &case.summary;
        table.row(vec![
            case.source.to_string(),
            case.noise.to_string(),
            format!("{}/{}", s.calibrated, s.trials),
            format!("{:.3}", s.anchor_error_m),
            format!("{:.1}", s.position_rms_error_m * 1e3),
            format!("{:.1}", s.median_trial_rms_m * 1e3),
            format!("{:.1}", s.position_max_error_m * 1e3),
            format!("{:.1}", s.predicted_rms_sigma_m * 1e3),
            format!("{:.1} %", 100.0 * s.within_95_percent),
            format!("{:.1} %", 100.0 * s.flagged_share),
            format!("{:.1}", s.truth_rms_error_m * 1e3),
        ]);
    }
    print!("{table}");
    println!(
        "\nRMS/max: distance of each localised held-out pose to the pool's pose (log: RecurDyn's position; model: the closed-form equilibrium).\n\
         predicted sigma: RMS of the norm of the per-axis 1-sigma (reading noise + the calibration's recorded covariance).\n\
         within 95 %: share of rows inside their predicted 95 % sphere (chi-square, 3 dof); 95 % if the sigmas are right.\n\
         truth RMS: the same readings localised with the true anchors and offsets (the floor of noise and model error)."
    );
}

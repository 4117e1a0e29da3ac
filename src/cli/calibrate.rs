//! `sagcal calibrate`: anchors and offsets from a measurement file; its
//! flags ([`CalibrateArgs`]) and the run.

use std::path::PathBuf;

use sagcal::calib::gross_errors::Verdict;
use sagcal::calib::report::CalibrationReport;
use sagcal::calib::{
    calibrate_job_with_progress, CableModel, CalibrationOptions, CalibrationResult, CalibrationSettings,
    OrientationPrior, ParameterUncertainty,
};
use sagcal::error::FrontEnd;
use sagcal::io::measurements::{read_measurements, ReadOptions};
use sagcal::io::OutputSet;
use sagcal::model::Robot;
use sagcal::plot::{anchor_plot_svg, figure_bytes, AnchorPlot, AnchorPlotEntry};

use super::gross_errors;
use super::output::{print_json, progress_bar, Table};
use super::solver_args::SolverArgs;

#[derive(Debug, clap::Args)]
pub(super) struct CalibrateArgs {
    /// Nominal robot description (TOML): the initial guess of anchors and offsets.
    #[arg(long)]
    robot: PathBuf,
    /// Measurements: sagcal CSV (see docs/measurements.md), a RecurDyn log, or the authors' dataset folder
    /// (`pos_i_cpp_test.csv`, `R_i_cpp_test.csv`, `lc_meas_cpp_test.csv`, `forces_cpp_test.csv`).
    #[arg(long)]
    data: PathBuf,
    /// Write the calibrated robot (TOML) here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write a plot of nominal and calibrated anchors with error ellipses here (PNG if the name ends in `.png`, SVG otherwise).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Write the calibrated robot even when the fit fails its own consistency
    /// tests (the verdict is recorded in the file's header comment).
    #[arg(long)]
    accept_inconsistent: bool,
    /// False-alarm rate of the gross-error tests (per reading, over all
    /// readings; per sensor type, over the types).
    #[arg(long, default_value_t = 1e-3)]
    false_alarm: f64,
    #[command(flatten)]
    solver: SolverArgs,
}

pub fn run(args: &CalibrateArgs) -> sagcal::Result<()> {
    let nominal = Robot::from_file(&args.robot)?;
    let data = read_measurements(
        &args.data,
        &ReadOptions {
            reference_cable: nominal.reference_cable,
            keep_rounded: false,
        },
    )?;
    let settings = CalibrationSettings {
        solver: args.solver.settings(),
        false_alarm: args.false_alarm,
        accept_inconsistent: args.accept_inconsistent,
    };
    let source = args.data.display().to_string();
    let bar = progress_bar(1, "{msg} [{bar:30}] {pos}/{len} fits, {elapsed}");
    let job = calibrate_job_with_progress(
        &nominal,
        &data.poses,
        &source,
        &settings,
        FrontEnd::Cli,
        &mut |done, total, what| bar.report(done, total, what),
    );
    bar.finish_and_clear();
    let mut job = job?;
    if let Some(refusal) = job.refusal.take() {
        // Nothing is written: the report goes out (as text or JSON), then the error names the sensors.
        if args.json {
            print_json(&job.report)?;
        } else {
            print!("{}", render(&job.report.report, &job.options));
            print!("{}", gross_errors::render(&job.report.gross_errors));
        }
        return Err(refusal);
    }
    let result = &job.checked.result;
    // Files only after everything succeeded: all of them or none, none over an input.
    let mut outputs = OutputSet::new();
    outputs.input("--robot", &args.robot).input("--data", &args.data);
    if let Some(out) = &args.out {
        outputs.file("--out", out, robot_text(&result.robot, &job.checked.verdict)?);
    }
    if let Some(plot) = &args.plot {
        let positions: Vec<[f64; 3]> = data.poses.iter().map(|p| p.position_m).collect();
        let caption = format!("sagcal calibrate --data {}", args.data.display());
        let svg = plot_svg(&nominal, None, result, &positions, &caption);
        outputs.file("--plot", plot, figure_bytes(plot, &svg)?);
    }
    outputs.write()?;
    if args.json {
        print_json(&job.report)
    } else {
        print!("{}", render(&job.report.report, &job.options));
        print!("{}", gross_errors::render(&job.report.gross_errors));
        match &args.out {
            Some(out) => println!("calibrated robot written to {}", out.display()),
            None => println!("the calibrated robot was not saved: no --out given (--out calibrated.toml writes it)"),
        }
        if let Some(plot) = &args.plot {
            println!("plot written to {}", plot.display());
        }
        Ok(())
    }
}

/// A calibrated robot's TOML, with the consistency verdict in its header comment.
pub fn robot_text(robot: &Robot, verdict: &Verdict) -> sagcal::Result<String> {
    let text = robot.to_file_contents().to_toml()?;
    let mut header =
        "# Calibrated by sagcal: anchors and encoder length offsets estimated from measurements.\n".to_string();
    if let Verdict::Inconsistent { reason } = verdict {
        header +=
            &format!("# WARNING: written with --accept-inconsistent; the fit FAILS its consistency tests: {reason}\n");
    }
    Ok(format!("{header}{text}"))
}

/// The anchor plot of a calibration (SVG).
pub fn plot_svg(
    nominal: &Robot,
    truth: Option<&Robot>,
    result: &CalibrationResult,
    positions: &[[f64; 3]],
    caption: &str,
) -> String {
    let covariances = match &result.uncertainty {
        ParameterUncertainty::Full {
            anchor_covariance_m2, ..
        } => Some(anchor_covariance_m2.clone()),
        ParameterUncertainty::RankDeficient { .. } => None,
    };
    let plot = AnchorPlot {
        title: format!(
            "sagcal: calibrated anchors of `{}` ({} poses)",
            nominal.name,
            result.poses.len()
        ),
        caption: caption.to_string(),
        anchors: (0..4)
            .map(|i| AnchorPlotEntry {
                label: format!("anchor {}", i + 1),
                nominal_m: nominal.anchors_m[i].into(),
                initial_m: Some(nominal.anchors_m[i].into()),
                estimate_m: result.robot.anchors_m[i].into(),
                covariance_m2: covariances.as_ref().map(|c| c[i]),
                truth_m: truth.map(|t| t.anchors_m[i].into()),
            })
            .collect(),
        platform_positions_m: positions.to_vec(),
    };
    anchor_plot_svg(&plot)
}

fn sigma(value: Option<f64>) -> String {
    value.map_or_else(|| "n/a".to_string(), |s| format!("{s:.3}"))
}

/// How the orientation was handled, in words.
fn orientation_text(report: &CalibrationReport, options: &CalibrationOptions) -> String {
    let sigma = options.noise.orientation_sigma_rad;
    if options.model == CableModel::Rigid || options.orientation_prior == OrientationPrior::On {
        return format!("{sigma:.4} rad prior");
    }
    match report.orientation_check {
        None => "decided by the statics (no prior)".into(),
        Some(check) if check.prior_used => format!(
            "{sigma:.4} rad prior, kept: the localiser's orientations agree with the statics (chi-square {:.1} for {} components, 99.9 % limit {:.1}; mean angle {:.2} deg)",
            check.chi_square, check.components, check.limit, check.mean_angle_deg
        ),
        Some(check) => format!(
            "decided by the statics: the localiser's orientations disagree with them (chi-square {:.1} for {} components, 99.9 % limit {:.1}; mean angle {:.2} deg), so the {sigma:.4} rad prior was dropped",
            check.chi_square, check.components, check.limit, check.mean_angle_deg
        ),
    }
}

/// The human-readable calibration report.
pub fn render(report: &CalibrationReport, options: &CalibrationOptions) -> String {
    let mut out = String::new();
    let n = &options.noise;
    out += &format!(
        "sagcal calibrate: robot `{}`, {} cable model, {} poses\nnoise: encoders {:.4} m, load cell {:.2} N, position {:.4} m, orientation {}\n\n",
        report.robot,
        report.model,
        report.poses_used,
        n.encoder_sigma_m,
        n.load_cell_sigma_n,
        n.position_sigma_m,
        orientation_text(report, options)
    );
    let mut anchors = Table::new([
        "anchor",
        "x m",
        "y m",
        "z m",
        "1-sigma x,y,z m",
        "change from nominal m",
    ]);
    for (i, a) in report.anchors_m.iter().enumerate() {
        let s = report.anchor_sigma_m.as_ref().map(|s| s[i]);
        let d = report.anchor_change_m[i];
        anchors.row([
            format!("{}", i + 1),
            format!("{:.3}", a[0]),
            format!("{:.3}", a[1]),
            format!("{:.3}", a[2]),
            s.map_or("n/a".into(), |s| format!("{:.3} {:.3} {:.3}", s[0], s[1], s[2])),
            format!("{:+.3} {:+.3} {:+.3}", d[0], d[1], d[2]),
        ]);
    }
    out += &anchors.to_string();
    out += "\n";
    let mut offsets = Table::new(["cable", "length offset m", "1-sigma m"]);
    for (i, o) in report.length_offsets_m.iter().enumerate() {
        offsets.row([
            format!("{}", i + 1),
            format!("{o:.4}"),
            sigma(report.offset_sigma_m.as_ref().map(|s| s[i])),
        ]);
    }
    out += &offsets.to_string();
    if let ParameterUncertainty::RankDeficient { directions } = &report.uncertainty {
        out += "\nNOT OBSERVABLE from these poses (add poses spread over the workspace):\n";
        for d in directions {
            let parts: Vec<String> = d
                .components
                .iter()
                .take(6)
                .map(|(name, c, w)| format!("{w:+.2} {name}[{}]", ["x", "y", "z"].get(*c).unwrap_or(&"?")))
                .collect();
            out += &format!("  direction: {}\n", parts.join(" "));
        }
    }
    out += "\nnormalised residuals r/sigma per factor type (rms ~ 1 when the stated noise is right):\n";
    let mut stats = Table::new(["factor", "count", "rms", "max |r/sigma|"]);
    for s in &report.factor_statistics {
        stats.row([
            s.kind.clone(),
            s.factors.to_string(),
            format!("{:.3}", s.rms),
            format!("{:.2}", s.max_abs),
        ]);
    }
    out += &stats.to_string();
    out += "\nsolver:\n";
    let mut stages = Table::new(["stage", "iterations", "initial cost", "final cost", "termination"]);
    for s in &report.stages {
        stages.row([
            s.name.clone(),
            s.summary.iterations.to_string(),
            format!("{:.4e}", s.summary.initial_cost),
            format!("{:.4e}", s.summary.final_cost),
            s.summary.termination.to_string(),
        ]);
    }
    out += &stages.to_string();
    if !report.excluded_poses.is_empty() {
        let rows: Vec<String> = report.excluded_poses.iter().map(ToString::to_string).collect();
        out += &format!(
            "\nWARNING: {} poses left out (no positive-tension equilibrium near them): {}\n",
            report.excluded_poses.len(),
            rows.join(", ")
        );
    }
    if !report.converged {
        out += &format!("\nWARNING: the solver did not converge ({})\n", report.termination);
    }
    if let Some(e) = &report.error_against_truth {
        out += &format!(
            "\nerror against the truth: anchors {:.3} m mean Euclidean ({:.3} m per coordinate, max {:.3} m), offsets {:.3} m\n",
            e.anchor_mean_euclidean_m, e.anchor_coordinate_mae_m, e.anchor_max_euclidean_m, e.offset_mae_m
        );
    }
    out
}

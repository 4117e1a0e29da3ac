//! `sagcal calibrate`: anchors and offsets from a measurement file; its
//! flags ([`CalibrateArgs`]) and the run.

use sagcal::calib::gross_errors::Verdict;
use sagcal::calib::report::CalibrationReport;
use sagcal::calib::{
    calibrate_job_with_progress, CableModel, CalibrationOptions, CalibrationResult, CalibrationSettings,
    OrientationPrior,
};
use sagcal::error::FrontEnd;
use sagcal::io::measurements::{read_measurements, ReadOptions};
use sagcal::io::OutputSet;
use sagcal::model::Robot;
use sagcal::plot::figure_bytes;

pub(super) use super::calibrate_args::CalibrateArgs;
use super::calibration_tables::{calibrated_anchor_plot, fit_tables, parameter_tables};
use super::gross_errors;
use super::output::{print_json, progress_bar};
use super::robot_kind::{read_robot, AnyRobot};

/// Calibrate the robot of `--robot` from `--data`: the four-cable
/// pipeline with its gross-error tests, or for a robot of 3 to 8 cables
/// [`super::calibrate_suspended::run`].
pub fn run(args: &CalibrateArgs) -> sagcal::Result<()> {
    let nominal = match read_robot(&args.robot)? {
        AnyRobot::Four(robot) => *robot,
        AnyRobot::Suspended(robot) => return super::calibrate_suspended::run(args, &robot),
    };
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
    let title = format!(
        "sagcal: calibrated anchors of `{}` ({} poses)",
        nominal.name,
        result.poses.len()
    );
    let estimates: Vec<[f64; 3]> = result.robot.anchors_m.iter().map(|a| (*a).into()).collect();
    let nominal_m: Vec<[f64; 3]> = nominal.anchors_m.iter().map(|a| (*a).into()).collect();
    let truth_m: Option<Vec<[f64; 3]>> = truth.map(|t| t.anchors_m.iter().map(|a| (*a).into()).collect());
    calibrated_anchor_plot(
        title,
        caption,
        &nominal_m,
        &estimates,
        &result.uncertainty,
        truth_m.as_deref(),
        positions,
    )
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
    out += &parameter_tables(
        &report.anchors_m,
        report.anchor_sigma_m.as_deref(),
        &report.anchor_change_m,
        &report.length_offsets_m,
        report.offset_sigma_m.as_deref(),
    );
    out += &fit_tables(&report.uncertainty, &report.factor_statistics, &report.stages);
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

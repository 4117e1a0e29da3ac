//! `sagcal calibrate` on a robot of 3 to 8 cables
//! ([`sagcal::calib::suspended`]): the report, the calibrated robot file and
//! the anchor plot.

use sagcal::calib::gross_errors::GrossErrorOptions;
use sagcal::calib::suspended::{
    calibrate_suspended, suspended_options, SuspendedCalibration, SuspendedCalibrationReport, SuspendedReading,
};
use sagcal::calib::{check_false_alarm, refusal, CalibrationOptions, OrientationPrior, ParameterUncertainty};
use sagcal::error::FrontEnd;
use sagcal::io::suspended_measurements::read_suspended_measurements;
use sagcal::io::OutputSet;
use sagcal::model::suspended::SuspendedRobot;
use sagcal::plot::figure_bytes;

use super::calibrate_args::CalibrateArgs;
use super::calibration_tables::{calibrated_anchor_plot, fit_tables, parameter_tables};
use super::output::{print_json, progress_bar};

/// The stages of [`calibrate_suspended`], for the progress display.
const STAGES: u64 = 3;

/// Calibrate `nominal` from `args.data`, write what `args` ask for, report.
pub(super) fn run(args: &CalibrateArgs, nominal: &SuspendedRobot) -> sagcal::Result<()> {
    let options = options(args, nominal)?;
    let data = read_suspended_measurements(&args.data, nominal)?;
    let tests = GrossErrorOptions {
        false_alarm: check_false_alarm(args.false_alarm, "false_alarm", FrontEnd::Cli)?,
        ..GrossErrorOptions::default()
    };
    let bar = progress_bar(STAGES, "{msg} [{bar:30}] {pos}/{len} stages, {elapsed}");
    let mut done = 0;
    let result = calibrate_suspended(nominal, &data, &options, Some(&tests), &mut |stage| {
        // A reading left out adds a solve to the three stages.
        bar.report(done, (done + 1).max(STAGES as usize), stage);
        done += 1;
    });
    bar.finish_and_clear();
    let result = result?;
    let report = SuspendedCalibrationReport::new(nominal, &result);
    let text = render(&report, &options);
    if let Some(reason) = report.inconsistency().filter(|_| !args.accept_inconsistent) {
        // Nothing is written: the report goes out (as text or JSON), then the refusal.
        if args.json {
            print_json(&report)?;
        } else {
            print!("{text}");
        }
        return Err(refusal(&args.data.display().to_string(), &reason, FrontEnd::Cli));
    }
    // Files only after everything succeeded: all of them or none, none over an input.
    let mut outputs = OutputSet::new();
    outputs.input("--robot", &args.robot).input("--data", &args.data);
    if let Some(out) = &args.out {
        outputs.file("--out", out, robot_text(&result, &report)?);
    }
    if let Some(plot) = &args.plot {
        let positions: Vec<[f64; 3]> = data.iter().map(|m| m.position_m).collect();
        let caption = format!("sagcal calibrate --data {}", args.data.display());
        let svg = plot_svg(nominal, &result, &positions, &caption);
        outputs.file("--plot", plot, figure_bytes(plot, &svg)?);
    }
    outputs.write()?;
    if args.json {
        return print_json(&report);
    }
    print!("{text}");
    match &args.out {
        Some(out) => println!("calibrated robot written to {}", out.display()),
        None => println!("the calibrated robot was not saved: no --out given (--out calibrated.toml writes it)"),
    }
    if let Some(plot) = &args.plot {
        println!("plot written to {}", plot.display());
    }
    Ok(())
}

/// The options of `args` for `nominal`.
fn options(args: &CalibrateArgs, nominal: &SuspendedRobot) -> sagcal::Result<CalibrationOptions> {
    suspended_options(&args.solver.settings(), nominal, FrontEnd::Cli)
}

/// The human-readable report.
fn render(report: &SuspendedCalibrationReport, options: &CalibrationOptions) -> String {
    let n = &options.noise;
    let orientation = match options.orientation_prior {
        OrientationPrior::Off => "not used".to_string(),
        _ => format!("{:.4} rad prior", n.orientation_sigma_rad),
    };
    let mut out = format!(
        "sagcal calibrate: robot `{}`, {} cables (load cells on {}), {}, {} poses\nnoise: encoders {:.4} m, load cells {:.2} N, position {:.4} m, orientation {orientation}\n\n",
        report.robot,
        report.cables,
        cable_list(&report.load_cells),
        cable_model(&report.axial_stiffness_n),
        report.poses_used,
        n.encoder_sigma_m,
        n.load_cell_sigma_n,
        n.position_sigma_m,
    );
    out += &parameter_tables(
        &report.anchors_m,
        report.anchor_sigma_m.as_deref(),
        &report.anchor_change_m,
        &report.length_offsets_m,
        report.offset_sigma_m.as_deref(),
    );
    out += &fit_tables(&report.uncertainty, &report.factor_statistics, &report.stages);
    out += &format!(
        "\nchi-square {:.1} for {} degrees of freedom (99.9 % limit {:.1}): {}\n",
        report.chi_square,
        report.degrees_of_freedom,
        report.chi_square_limit,
        if report.consistent {
            "the model and the stated noise explain the readings"
        } else {
            "INCONSISTENT: the readings disagree with the model or the stated noise"
        }
    );
    for found in &report.readings_left_out {
        out += &format!(
            "left out as a gross error: {}, {}: residual {:+.4} (sigma {:.4}, redundancy {:.4}), |w| {:.1} > {:.2}\n",
            found.at,
            reading_name(found.reading),
            found.residual,
            found.sigma,
            found.redundancy,
            found.w.abs(),
            found.critical
        );
    }
    out += &undetermined_note(report);
    if !report.poses_without_start.is_empty() {
        out += &format!(
            "note: poses {} had no equilibrium at their measured position for the straight-cable anchors; they started from the measured pose\n",
            cable_list(&report.poses_without_start)
        );
    }
    if !report.converged {
        out += "WARNING: the solver did not converge\n";
    }
    out
}

/// What the readings leave undetermined of the forces, if anything.
fn undetermined_note(report: &SuspendedCalibrationReport) -> String {
    let undetermined = &report.undetermined_forces;
    if undetermined.is_empty() {
        return String::new();
    }
    let directions: usize = undetermined.iter().map(|u| u.directions).sum();
    let poses: Vec<usize> = undetermined.iter().map(|u| u.pose).collect();
    let most = undetermined.iter().map(|u| u.directions).max().unwrap_or(0);
    format!(
        "note: the readings do not determine the cable forces at {} of {} poses ({}): {directions} directions in all, \
         up to {most} at a pose, change no reading (the cables' sag cannot tell those forces apart, and {} load \
         cell{} read{} them). The anchors and offsets do not depend on them and their 1-sigma above holds; the \
         degrees of freedom count them out; the forces of those poses are one solution of many. A load cell on more \
         cables fixes them{}.\n",
        poses.len(),
        report.poses_used,
        if poses.len() == report.poses_used {
            "every pose".to_string()
        } else {
            format!("poses {}", cable_list(&poses))
        },
        report.load_cells.len(),
        if report.load_cells.len() == 1 { "" } else { "s" },
        if report.load_cells.len() == 1 { "s" } else { "" },
        if report.axial_stiffness_n.iter().all(Option::is_none) {
            ", and so does the cables' known stiffness (`axial_stiffness_n` in the robot file), through which each \
             encoder reads its cable's tension"
        } else {
            ""
        },
    )
}

/// `catenary model`, or with elastic cables `elastic catenary model (EA
/// 2.00e6 N)` (one value when every cable has it, else one per cable,
/// `inf` for an inextensible one).
fn cable_model(axial_stiffness_n: &[Option<f64>]) -> String {
    if axial_stiffness_n.iter().all(Option::is_none) {
        return "catenary model".into();
    }
    let text = |ea: &Option<f64>| ea.map_or("inf".to_string(), |ea| format!("{ea:.2e}"));
    let values = if axial_stiffness_n.iter().all(|ea| *ea == axial_stiffness_n[0]) {
        text(&axial_stiffness_n[0])
    } else {
        let each: Vec<String> = axial_stiffness_n.iter().map(text).collect();
        each.join(", ")
    };
    format!("elastic catenary model (EA {values} N)")
}

/// `1, 3 and 5`.
fn cable_list(items: &[usize]) -> String {
    let words: Vec<String> = items.iter().map(ToString::to_string).collect();
    match words.split_last() {
        None => "none".into(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
    }
}

/// The calibrated robot's file, its covariance as `[calibration]`, with the
/// consistency verdict in its header comment.
fn robot_text(result: &SuspendedCalibration, report: &SuspendedCalibrationReport) -> sagcal::Result<String> {
    let covariance = match &result.uncertainty {
        ParameterUncertainty::Full { covariance_m2, .. } => Some(covariance_m2.as_slice()),
        ParameterUncertainty::RankDeficient { .. } => None,
    };
    let mut header =
        "# Calibrated by sagcal: anchors and encoder length offsets estimated from measurements.\n".to_string();
    if let Some(reason) = report.inconsistency() {
        header +=
            &format!("# WARNING: written with --accept-inconsistent; the fit FAILS its consistency tests: {reason}\n");
    }
    Ok(format!("{header}{}", result.robot.to_toml(covariance)?))
}

/// The anchor plot of a calibration of `N` cables (SVG).
fn plot_svg(nominal: &SuspendedRobot, result: &SuspendedCalibration, positions: &[[f64; 3]], caption: &str) -> String {
    let title = format!(
        "sagcal: calibrated anchors of `{}` ({} cables, {} poses)",
        nominal.name,
        nominal.cable_count(),
        result.poses.len()
    );
    let estimates: Vec<[f64; 3]> = result.robot.anchors_m.iter().map(|a| (*a).into()).collect();
    let nominal_m: Vec<[f64; 3]> = nominal.anchors_m.iter().map(|a| (*a).into()).collect();
    calibrated_anchor_plot(
        title,
        caption,
        &nominal_m,
        &estimates,
        &result.uncertainty,
        None,
        positions,
    )
}

/// A reading in words: `encoder of cable 2`, `load cell on cable 5`, `localiser x`.
fn reading_name(reading: SuspendedReading) -> String {
    let axis = |a: usize| ["x", "y", "z"].get(a).copied().unwrap_or("?");
    match reading {
        SuspendedReading::Encoder(i) => format!("encoder of cable {}", i + 1),
        SuspendedReading::LoadCell(i) => format!("load cell on cable {}", i + 1),
        SuspendedReading::Position(a) => format!("localiser {}", axis(a)),
        SuspendedReading::Orientation(a) => format!("localiser orientation about {}", axis(a)),
    }
}

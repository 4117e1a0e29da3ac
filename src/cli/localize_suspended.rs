//! `sagcal localize` on a calibrated robot of 3 to 8 cables
//! ([`sagcal::localize::suspended`]): a table (or JSON, or CSV) of every
//! row's pose, forces' magnitudes, 1-sigma and tests; with `--plot` the
//! figure of the four-cable command (`sagcal::plot::localize`), an anchor
//! marker per cable.

use sagcal::io::suspended_measurements::read_suspended_measurements;
use sagcal::localize::{localize_suspended_rows, SuspendedLocalizationReport};
use sagcal::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use sagcal::plot::figure_bytes;
use sagcal::plot::localize::{localize_plot_svg, LocalizePlot, PlottedPose};

use super::localize_args::LocalizeArgs;
use super::output::{print_json, progress_bar, Table};
use super::robot_kind::refuse_four_cable_flags;

/// Localise every row of `args.data` on `robot`, write and report.
pub(super) fn run(args: &LocalizeArgs, robot: &SuspendedRobot) -> sagcal::Result<()> {
    refuse_four_cable_options(args, robot)?;
    let rows = read_suspended_measurements(&args.data, robot)?;
    let noise = args.noise.sigmas(robot.platform_weight_n);
    sagcal::calib::check_false_alarm(args.false_alarm, "false_alarm", sagcal::error::FrontEnd::Cli)?;
    let bar = progress_bar(rows.len() as u64, "{msg} [{bar:30}] {pos}/{len} rows, {elapsed}");
    let report = localize_suspended_rows(robot, &rows, &noise, args.false_alarm, &mut |done, total| {
        bar.report(done, total, "localize")
    });
    bar.finish_and_clear();
    let mut outputs = sagcal::io::OutputSet::new();
    outputs.input("--robot", &args.robot).input("--data", &args.data);
    if let Some(out) = &args.out {
        outputs.file("--out", out, render_csv(&report));
    }
    if let Some(path) = &args.plot {
        let svg = localize_plot_svg(&plot(&report, robot, &rows, &args.data.display().to_string()));
        outputs.file("--plot", path, figure_bytes(path, &svg)?);
    }
    outputs.write()?;
    if args.json {
        return print_json(&report);
    }
    print!("{}", render(&report, &args.data.display().to_string()));
    for path in args.out.iter().chain(&args.plot) {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The figure of `--plot`: every localised row's position and its 1-sigma
/// ellipse (the reading noise), joined to the file's localiser position.
fn plot(
    report: &SuspendedLocalizationReport,
    robot: &SuspendedRobot,
    rows: &[SuspendedMeasurement],
    data: &str,
) -> LocalizePlot {
    let poses = report
        .rows
        .iter()
        .zip(rows)
        .filter_map(|(r, logged)| {
            Some(PlottedPose {
                row: r.at.row,
                position_m: r.position_m?,
                covariance_m2: r.position_covariance_m2,
                reference_m: Some(logged.position_m),
                flagged: r.flag.is_some(),
            })
        })
        .collect();
    LocalizePlot {
        title: format!("sagcal localize: {} rows of {data}", report.rows.len()),
        caption: format!(
            "robot {} ({} cables); 1-sigma from the reading noise (the calibration's covariance is not carried into these)",
            report.robot, report.cables
        ),
        anchors_m: robot.anchors_m.iter().map(|a| [a.x, a.y, a.z]).collect(),
        sigma_source: "reading noise".into(),
        reference_label: "logged".into(),
        poses,
    }
}

/// The flags of the four-cable localiser that this one does not have.
fn refuse_four_cable_options(args: &LocalizeArgs, robot: &SuspendedRobot) -> sagcal::Result<()> {
    let given = [
        (args.pose_prior, "--pose-prior"),
        (args.fast, "--fast"),
        (args.no_calibration_uncertainty, "--no-calibration-uncertainty"),
    ];
    refuse_four_cable_flags(
        &given,
        robot,
        "its localisation reads the encoders and load cells alone, with the reading noise as its sigmas",
    )
}

/// The table.
fn render(report: &SuspendedLocalizationReport, data: &str) -> String {
    let mut out = format!(
        "sagcal localize: robot {} ({} cables), data {data}\nsigmas: the reading noise (the calibration's covariance is not carried into these)\n\n",
        report.robot, report.cables
    );
    let mut table = Table::new([
        "row",
        "line",
        "x m",
        "y m",
        "z m",
        "roll deg",
        "pitch deg",
        "yaw deg",
        "sx mm",
        "sy mm",
        "sz mm",
        "chi2/dof",
        "ok",
        "err mm",
    ]);
    for r in &report.rows {
        let (Some(p), Some(a), Some(s)) = (r.position_m, r.roll_pitch_yaw_deg, r.position_sigma_m) else {
            continue;
        };
        let mut cells = vec![r.at.row.to_string(), r.at.line.map_or("-".into(), |l| l.to_string())];
        cells.extend(p.iter().map(|v| format!("{v:.4}")));
        cells.extend(a.iter().map(|v| format!("{v:.3}")));
        cells.extend(s.iter().map(|v| format!("{:.2}", v * 1e3)));
        cells.push(format!(
            "{:.2}/{}",
            r.chi_square.unwrap_or(f64::NAN),
            r.degrees_of_freedom.unwrap_or(0)
        ));
        cells.push(if r.flag.is_none() { "yes" } else { "FLAG" }.into());
        cells.push(r.position_error_m.map_or("-".into(), |e| format!("{:.2}", e * 1e3)));
        table.row(cells);
    }
    out += &table.to_string();
    for r in report.rows.iter().filter(|r| r.flag.is_some()) {
        out += &format!("{}: {}\n", r.at, r.flag.as_deref().unwrap_or(""));
    }
    out += &format!(
        "\nrows localised: {}, flagged: {}\n",
        report.rows.len(),
        report.rows_flagged
    );
    if let (Some(rms), Some(max)) = (report.position_rms_error_m, report.position_max_error_m) {
        out += &format!(
            "position against the input's poses (unflagged rows): RMS {:.3} mm, max {:.3} mm\n",
            rms * 1e3,
            max * 1e3
        );
    }
    out
}

/// The poses as CSV, one line per input row (a row without a result: empty values).
fn render_csv(report: &SuspendedLocalizationReport) -> String {
    let forces: Vec<String> = (1..=report.cables)
        .flat_map(|i| [format!("fh{i}_n"), format!("fv{i}_n")])
        .collect();
    let mut out = format!(
        "row,line,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,{},sigma_x_m,sigma_y_m,sigma_z_m,chi_square,dof,consistent,stable,position_error_m,flag\n",
        forces.join(",")
    );
    let join = |v: Option<Vec<f64>>, n: usize| -> String {
        v.map_or_else(
            || vec![""; n].join(","),
            |v| v.iter().map(|x| format!("{x:e}")).collect::<Vec<_>>().join(","),
        )
    };
    for r in &report.rows {
        let flat_forces = r.forces_n.as_ref().map(|f| f.iter().flatten().copied().collect());
        out += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.at.row,
            r.at.line.map_or(String::new(), |l| l.to_string()),
            join(r.position_m.map(|v| v.to_vec()), 3),
            join(r.roll_pitch_yaw_deg.map(|v| v.to_vec()), 3),
            join(flat_forces, 2 * report.cables),
            join(r.position_sigma_m.map(|v| v.to_vec()), 3),
            r.chi_square.map_or(String::new(), |c| format!("{c:e}")),
            r.degrees_of_freedom.map_or(String::new(), |d| d.to_string()),
            r.consistent,
            r.stable.map_or(String::new(), |s| s.to_string()),
            r.position_error_m.map_or(String::new(), |e| format!("{e:e}")),
            r.flag
                .as_deref()
                .map_or(String::new(), |f| format!("\"{}\"", f.replace('"', "'"))),
        );
    }
    out
}

//! `sagcal localize`: the calibrated robot's pose and tensions from its cable readings;
//! its flags ([`LocalizeArgs`]) and the run.

use serde::Serialize;

use sagcal::error::FrontEnd;
use sagcal::io::readings::{read_readings, ReadingsFile, ReadingsFormat};
use sagcal::io::recurdyn::RejectedRow;
use sagcal::localize::{require_pose_priors, LocalizeSettings, Localized, Localizer, Readings};
use sagcal::model::pose::PlatformPose;
use sagcal::model::DataRow;
use sagcal::model::Robot;
use sagcal::plot::localize::{localize_plot_svg, LocalizePlot, PlottedPose};

pub(super) use super::localize_args::LocalizeArgs;
use super::output::{opt, print_json, progress_bar, Table};
use super::robot_kind::{read_robot, AnyRobot};

/// What the position sigmas hold, by whether the robot records its calibration's covariance.
fn covariance_note(robot: &Robot, used: bool) -> &'static str {
    match (robot.calibration_covariance_m2.is_some(), used) {
        (true, true) => "position_sigma_m combines the reading noise and the calibration's recorded anchor/offset covariance ([calibration] of the robot file)",
        (true, false) => "--no-calibration-uncertainty: position_sigma_m is from the reading noise only",
        (false, _) => "the robot file records no covariance of the calibrated anchors and offsets (no [calibration]; `calibrate --out` writes it): position_sigma_m is from the reading noise only",
    }
}

/// One row of the report.
#[derive(Debug, Clone, Serialize)]
struct RowReport {
    /// The row (from 1) and its line in the input (`null` without a file).
    #[serde(flatten)]
    at: DataRow,
    position_m: Option<[f64; 3]>,
    roll_pitch_yaw_deg: Option<[f64; 3]>,
    tensions_n: Option<[f64; 4]>,
    /// 1-sigma per axis from both sources (reading noise and calibration).
    position_sigma_m: Option<[f64; 3]>,
    /// 1-sigma per axis from the reading noise only.
    position_sigma_reading_m: Option<[f64; 3]>,
    /// 1-sigma per axis from the calibration's uncertainty only (`null`
    /// when the robot records no covariance).
    position_sigma_calibration_m: Option<[f64; 3]>,
    chi_square: Option<f64>,
    degrees_of_freedom: Option<usize>,
    consistent: bool,
    stable: Option<bool>,
    /// Distance from the input's localiser position, when it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    position_error_m: Option<f64>,
    /// Why the row has no (trusted) equilibrium; `null` for a good row.
    flag: Option<String>,
    /// Equilibria the multistart found (`null` with `--fast`).
    equilibria: Option<usize>,
    /// Of those, the stable ones.
    stable_equilibria: Option<usize>,
    /// Distance (position, metres) from the chosen pose to the farthest other
    /// stable equilibrium: the readings cannot tell them apart by more than
    /// their chi-square; `null` when the chosen one is the only stable one.
    ambiguity_m: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
struct Report {
    robot: String,
    data: String,
    format: ReadingsFormat,
    pose_prior: bool,
    covariance: &'static str,
    /// RMS over unflagged rows of the total position 1-sigma (norm of the three axes).
    #[serde(skip_serializing_if = "Option::is_none")]
    position_rms_sigma_m: Option<f64>,
    rows: Vec<RowReport>,
    /// What the figure draws per localised row.
    #[serde(skip)]
    plotted: Vec<PlottedPose>,
    rejected: Vec<RejectedRow>,
    rows_flagged: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    position_rms_error_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    position_max_error_m: Option<f64>,
}

/// Localise every row and print the table (or JSON); `--out` gets the CSV.
/// Localise every row of `--data` on the robot of `--robot`: the
/// four-cable localiser, or for a robot of 3 to 8 cables
/// [`super::localize_suspended::run`].
pub fn run(args: &LocalizeArgs) -> sagcal::Result<()> {
    let robot = match read_robot(&args.robot)? {
        AnyRobot::Four(robot) => *robot,
        AnyRobot::Suspended(robot) => return super::localize_suspended::run(args, &robot),
    };
    let file = read_readings(&args.data, robot.reference_cable)?;
    let localizer = LocalizeSettings {
        noise: args.noise,
        pose_prior: args.pose_prior,
        false_alarm: args.false_alarm,
        calibration_uncertainty: !args.no_calibration_uncertainty,
    }
    .localizer(&robot)?;
    let mut report = localize_file(
        &args.robot.display().to_string(),
        &file,
        &localizer,
        args.pose_prior,
        !args.fast,
    )?;
    report.covariance = covariance_note(&robot, !args.no_calibration_uncertainty);
    // All the files or none, none over an input.
    let mut outputs = sagcal::io::OutputSet::new();
    outputs.input("--robot", &args.robot).input("--data", &args.data);
    if let Some(out) = &args.out {
        outputs.file("--out", out, render_csv(&report));
    }
    if let Some(path) = &args.plot {
        let plot = LocalizePlot {
            title: format!("sagcal localize: {} rows of {}", report.rows.len(), report.data),
            caption: format!("robot {}; {}", report.robot, report.covariance),
            anchors_m: robot.anchors_m.map(Into::into).to_vec(),
            sigma_source: match robot.calibration_covariance_m2.is_some() && !args.no_calibration_uncertainty {
                true => "reading noise and calibration",
                false => "reading noise",
            }
            .into(),
            reference_label: if args.pose_prior { "prior" } else { "logged" }.into(),
            poses: report.plotted.clone(),
        };
        outputs.file(
            "--plot",
            path,
            sagcal::plot::figure_bytes(path, &localize_plot_svg(&plot))?,
        );
    }
    outputs.write()?;
    if args.json {
        print_json(&report)
    } else {
        print!("{}", render(&report));
        for path in args.out.iter().chain(&args.plot) {
            println!("wrote {}", path.display());
        }
        Ok(())
    }
}

fn localize_file(
    robot: &str,
    file: &ReadingsFile,
    localizer: &Localizer,
    pose_prior: bool,
    search: bool,
) -> sagcal::Result<Report> {
    if pose_prior {
        let rows = file.rows.iter().map(|r| (r.line, r.localiser_pose));
        require_pose_priors(&file.path, rows, FrontEnd::Cli)?;
    }
    let readings: Vec<Readings> = file
        .rows
        .iter()
        .map(|row| Readings {
            encoder_lengths_m: row.encoder_lengths_m,
            load_cell_n: row.load_cell_n,
            localiser_pose: row.localiser_pose,
        })
        .collect();
    let bar = progress_bar(1, "{msg} [{bar:30}] {pos}/{len} rows, {elapsed}");
    let solved =
        localizer.localize_sequence_with_progress(&readings, search, &mut || false, &mut |done, total, what| {
            bar.report(done, total, what)
        });
    bar.finish_and_clear();
    let solved = solved?;
    let mut rows = Vec::with_capacity(file.rows.len());
    let mut plotted = Vec::new();
    for (k, (row, solved)) in file.rows.iter().zip(solved).enumerate() {
        let at = DataRow::at(k, row.line);
        let report = match &solved.found {
            Ok(found) => {
                let mut report = row_report(at, found, solved.flag, row.localiser_pose.as_ref());
                if let Some(search) = solved.search {
                    report.equilibria = Some(search.equilibria);
                    report.stable_equilibria = Some(search.stable);
                    report.ambiguity_m = search.ambiguity_m;
                }
                let total = found.covariance + found.calibration_covariance.unwrap_or_default();
                plotted.push(PlottedPose {
                    row: at.row,
                    position_m: found.pose.position_m.into(),
                    covariance_m2: Some(std::array::from_fn(|r| std::array::from_fn(|c| total[(3 + r, 3 + c)]))),
                    reference_m: row.localiser_pose.map(|p| p.position_m.into()),
                    flagged: report.flag.is_some(),
                });
                report
            }
            Err(why) => flagged(at, why.to_string()),
        };
        rows.push(report);
    }
    let errors: Vec<f64> = rows
        .iter()
        .filter(|r| r.flag.is_none())
        .filter_map(|r| r.position_error_m)
        .collect();
    let rms = rms_of(errors.iter().copied());
    Ok(Report {
        robot: robot.to_string(),
        data: file.path.display().to_string(),
        format: file.format,
        pose_prior,
        covariance: "",
        position_rms_sigma_m: rms_of(rows.iter().filter(|r| r.flag.is_none()).filter_map(|r| {
            r.position_sigma_m
                .map(|s| (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt())
        })),
        rows_flagged: rows.iter().filter(|r| r.flag.is_some()).count(),
        rows,
        plotted,
        rejected: file.rejected.clone(),
        position_rms_error_m: rms,
        position_max_error_m: errors.iter().copied().reduce(f64::max),
    })
}

/// Root mean square, `None` when empty.
fn rms_of(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (n > 0).then(|| (sum / n as f64).sqrt())
}

fn row_report(at: DataRow, found: &Localized, flag: Option<String>, localiser: Option<&PlatformPose>) -> RowReport {
    let (roll, pitch, yaw) = found.pose.roll_pitch_yaw_deg();
    RowReport {
        at,
        position_m: Some(found.pose.position_m.into()),
        roll_pitch_yaw_deg: Some([roll, pitch, yaw]),
        tensions_n: Some(found.tension_magnitudes_n()),
        position_sigma_m: Some(found.position_sigma_m.into()),
        position_sigma_reading_m: Some(found.reading_position_sigma_m.into()),
        position_sigma_calibration_m: found
            .calibration_covariance
            .map(|c| std::array::from_fn(|a| c[(3 + a, 3 + a)].max(0.0).sqrt())),
        chi_square: Some(found.chi_square),
        degrees_of_freedom: Some(found.degrees_of_freedom),
        consistent: found.consistent,
        stable: Some(found.stable),
        position_error_m: localiser.map(|p| (p.position_m - found.pose.position_m).norm()),
        flag,
        equilibria: None,
        stable_equilibria: None,
        ambiguity_m: None,
    }
}

fn flagged(at: DataRow, reason: String) -> RowReport {
    RowReport {
        at,
        position_m: None,
        roll_pitch_yaw_deg: None,
        tensions_n: None,
        position_sigma_m: None,
        position_sigma_reading_m: None,
        position_sigma_calibration_m: None,
        chi_square: None,
        degrees_of_freedom: None,
        consistent: false,
        stable: None,
        position_error_m: None,
        flag: Some(reason),
        equilibria: None,
        stable_equilibria: None,
        ambiguity_m: None,
    }
}

fn render(report: &Report) -> String {
    let mut out = format!(
        "sagcal localize: robot {}, data {} ({}){}\nsigmas: {}\n\n",
        report.robot,
        report.data,
        report.format,
        if report.pose_prior {
            ", localiser pose as a prior"
        } else {
            ""
        },
        report.covariance
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
        "T1 N",
        "T2 N",
        "T3 N",
        "T4 N",
        "sx mm",
        "sy mm",
        "sz mm",
        "chi2/dof",
        "ok",
        "err mm",
        "stable eq",
        "other at m",
    ]);
    for r in &report.rows {
        let Some(p) = r.position_m else {
            continue;
        };
        let a = r.roll_pitch_yaw_deg.unwrap_or_default();
        let t = r.tensions_n.unwrap_or_default();
        let s = r.position_sigma_m.unwrap_or_default();
        let mut cells = vec![r.at.row.to_string(), r.at.line.map_or("-".into(), |l| l.to_string())];
        cells.extend(p.iter().map(|v| format!("{v:.4}")));
        cells.extend(a.iter().map(|v| format!("{v:.3}")));
        cells.extend(t.iter().map(|v| format!("{v:.2}")));
        cells.extend(s.iter().map(|v| format!("{:.2}", v * 1e3)));
        cells.push(format!(
            "{:.2}/{}",
            r.chi_square.unwrap_or(f64::NAN),
            r.degrees_of_freedom.unwrap_or(0)
        ));
        cells.push(if r.flag.is_none() { "yes" } else { "FLAG" }.into());
        cells.push(opt(r.position_error_m.map(|e| e * 1e3), 2));
        cells.push(r.stable_equilibria.map_or("-".into(), |n| n.to_string()));
        cells.push(opt(r.ambiguity_m, 3));
        table.row(cells);
    }
    out += &table.to_string();
    for r in report.rows.iter().filter(|r| r.flag.is_some()) {
        out += &format!("{}: {}\n", r.at, r.flag.as_deref().unwrap_or(""));
    }
    for r in &report.rejected {
        out += &format!("line {} left out by the loader: {}\n", r.line, r.reason);
    }
    out += &format!(
        "\nrows localised: {}, flagged: {}\n",
        report.rows.len(),
        report.rows_flagged
    );
    let ambiguous = report.rows.iter().filter(|r| r.ambiguity_m.is_some()).count();
    if ambiguous > 0 {
        out += &format!(
            "{ambiguous} row(s) have another stable equilibrium with the same readings (`other at m`): the chosen one is the stable solution nearest the previous row's pose (or the prior; the first row: the level start). Four lengths cannot tell them apart; a prior or a warm start along a trajectory can.\n"
        );
    }
    if let (Some(rms), Some(max)) = (report.position_rms_error_m, report.position_max_error_m) {
        out += &format!(
            "position against the input's poses (unflagged rows): RMS {:.3} mm, max {:.3} mm\n",
            rms * 1e3,
            max * 1e3
        );
    }
    out
}

/// The poses as CSV (one line per input row, named by its row and its
/// line in the input, empty without a file; a flagged row's values empty).
fn render_csv(report: &Report) -> String {
    let mut out = String::from(
        "row,line,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,t1_n,t2_n,t3_n,t4_n,sigma_x_m,sigma_y_m,sigma_z_m,chi_square,dof,consistent,stable,position_error_m,flag\n",
    );
    let join = |v: Option<&[f64]>, n: usize| -> String {
        v.map_or_else(
            || vec![""; n].join(","),
            |v| v.iter().map(|x| format!("{x:e}")).collect::<Vec<_>>().join(","),
        )
    };
    for r in &report.rows {
        out += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.at.row,
            r.at.line.map_or(String::new(), |l| l.to_string()),
            join(r.position_m.as_ref().map(|v| &v[..]), 3),
            join(r.roll_pitch_yaw_deg.as_ref().map(|v| &v[..]), 3),
            join(r.tensions_n.as_ref().map(|v| &v[..]), 4),
            join(r.position_sigma_m.as_ref().map(|v| &v[..]), 3),
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

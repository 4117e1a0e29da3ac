//! `sagcal verify`: the model against measured data (four cables; robots of
//! 3 to 8 cables in `verify_suspended.rs`).

use sagcal::diagnose::verify::{nothing_verified, verify, Closure, LengthKind, MeasuredData, VerifyReport};
use sagcal::io::measurements::{read_measurements, MeasurementFormat, ReadOptions};
use sagcal::io::recurdyn::{read_recurdyn, LoadOptions};
use sagcal::model::statics::StaticsOptions;
use sagcal::model::Robot;

use super::output::{opt, print_json, Table};
use super::robot_kind::{read_robot, AnyRobot};
use super::verify_args::{ClosureArg, VerifyArgs};

/// Verify the model against the data and print the report (or JSON).
pub fn run(args: &VerifyArgs) -> sagcal::Result<()> {
    let robot = match read_robot(&args.robot)? {
        AnyRobot::Four(robot) => *robot,
        AnyRobot::Suspended(robot) => return super::verify_suspended::run(args, &robot),
    };
    refuse_four_flags(args, &robot)?;
    let data = read_data(args, &robot)?;
    let closure = match args.close_with.unwrap_or(ClosureArg::ReferenceTension) {
        ClosureArg::ReferenceTension => Closure::ReferenceTension,
        ClosureArg::CableLengths => Closure::CableLengths,
    };
    let report = verify(&robot, &data, closure, &StaticsOptions::default());
    if let Some(error) = nothing_verified(&report) {
        // The rows' reasons go out first (not with --json), then the error.
        if !args.json {
            print!("{}", render(&report));
        }
        return Err(error);
    }
    if args.json {
        print_json(&report)
    } else {
        print!("{}", render(&report));
        Ok(())
    }
}

/// The flags only robots of 3 to 8 cables take, refused by name.
fn refuse_four_flags(args: &VerifyArgs, robot: &Robot) -> sagcal::Result<()> {
    let given = [
        (args.noise.is_some(), "--noise"),
        (args.false_alarm.is_some(), "--false-alarm"),
    ];
    match given.iter().find(|(on, _)| *on) {
        Some((_, flag)) => Err(sagcal::Error::InvalidInput(format!(
            "{flag}: robot `{}` has 4 cables, whose verification closes the model with one reading and reports \
             its errors in percent, unweighted (robots of 3 to 8 cables are verified by a weighted fit)",
            robot.name
        ))),
        None => Ok(()),
    }
}

/// The data: a RecurDyn log with every cable's tension, or a sagcal measurement file.
fn read_data(args: &VerifyArgs, robot: &Robot) -> sagcal::Result<MeasuredData> {
    let set = read_measurements(
        &args.data,
        &ReadOptions {
            reference_cable: robot.reference_cable,
            keep_rounded: args.keep_rounded,
        },
    )?;
    if set.format == MeasurementFormat::RecurDyn {
        let options = LoadOptions {
            keep_rounded: args.keep_rounded,
        };
        return Ok(MeasuredData::from_recurdyn(&read_recurdyn(&args.data, &options)?));
    }
    Ok(MeasuredData::from_measurements(&set, robot.reference_cable))
}

/// The readable verification: per row, then what was left out, the orientation and the summary.
fn render(report: &VerifyReport) -> String {
    let mut out = String::new();
    let closure = match report.closure {
        Closure::ReferenceTension => "position + reference-cable tension (load cell)",
        Closure::CableLengths => "position + the four cable lengths",
    };
    let lengths = match report.lengths {
        LengthKind::EncoderReadings => "encoder readings (cable length + the robot's length_offsets_m)",
        LengthKind::Absolute => "absolute cable lengths (no encoder offsets)",
    };
    out += &format!(
        "sagcal verify: robot `{}`, data {}\nmodel closed with: {closure}; orientation is predicted, never an input\nlengths compared as: {lengths}\n\n",
        report.robot, report.data
    );
    let mut table = Table::new([
        "row",
        "line",
        "x m",
        "y m",
        "z m",
        "dL1 %",
        "dL2 %",
        "dL3 %",
        "dL4 %",
        "F1 N",
        "F2 N",
        "F3 N",
        "F4 N",
        "dF2 %",
        "dF3 %",
        "dF4 %",
        "rot err deg",
    ]);
    for r in &report.rows {
        let mut cells = vec![
            r.at.row.to_string(),
            r.at.line.map_or("-".into(), |l| l.to_string()),
            format!("{:.3}", r.position_m[0]),
            format!("{:.3}", r.position_m[1]),
            format!("{:.3}", r.position_m[2]),
        ];
        cells.extend(r.length_error_pct.iter().map(|e| format!("{e:.5}")));
        cells.extend(r.predicted_tension_n.iter().map(|f| format!("{f:.1}")));
        cells.extend(r.tension_error_pct.iter().skip(1).map(|e| opt(*e, 3)));
        cells.push(format!("{:.2}", r.orientation_error_deg));
        table.row(cells);
    }
    out += &table.to_string();
    out += "(dL: cable-length error; F: predicted tension; dF: tension error where the log has one; rot err: angle between\n logged and predicted orientation)\n\n";
    out += &render_left_out(report);
    out += &render_orientation(report);
    out += &render_summary(report);
    out
}

/// Rows the loader rejected and rows without an equilibrium.
fn render_left_out(report: &VerifyReport) -> String {
    let mut out = String::new();
    if !report.rows_rejected.is_empty() {
        out += &format!(
            "rejected rows ({}, named by their line and not counted as rows):\n",
            report.rows_rejected.len()
        );
        for r in &report.rows_rejected {
            out += &format!("  line {:>3}: {}\n", r.line, r.reason);
        }
        out += "\n";
    }
    if !report.rows_unsolved.is_empty() {
        out += &format!(
            "rows without a positive-tension equilibrium ({}):\n",
            report.rows_unsolved.len()
        );
        for r in &report.rows_unsolved {
            out += &format!("  {}: {}\n", r.at, r.reason);
        }
        out += "\n";
    }
    out
}

/// How each reading of the angle columns matches the model's equilibria.
fn render_orientation(report: &VerifyReport) -> String {
    let mut out = "orientation: how each reading of the angle columns matches the model's equilibria\n".to_string();
    if report.orientation_conventions.is_empty() {
        return out + "  - (no row solved)\n\n";
    }
    let mut conventions = Table::new(["reading", "mean deg", "median deg"]);
    for c in &report.orientation_conventions {
        conventions.row([
            c.convention.clone(),
            format!("{:.3}", c.mean_error_deg),
            format!("{:.3}", c.median_error_deg),
        ]);
    }
    out += &conventions.to_string();
    if !report.suspect_orientation_rows.is_empty() {
        out += "rows whose angles fit far better with permuted columns:\n";
        for s in &report.suspect_orientation_rows {
            out += &format!(
                "  {}: {:.2} deg as documented, {:.2} deg as {}\n",
                s.at, s.documented_error_deg, s.best_error_deg, s.best_convention
            );
        }
    }
    out += "\n";
    out
}

/// MPE-L, MPE-F and the orientation error, beside the paper's Table I column
/// for the robot when it is one of the paper's; then why a value is missing.
fn render_summary(report: &VerifyReport) -> String {
    let paper = report.paper_table1.as_ref();
    let mut header = vec!["summary".to_string(), "sagcal".to_string()];
    header.extend(paper.map(|p| format!("paper Table I ({})", p.robot.name())));
    let mut summary = Table::new(header);
    let mut row = |cells: [String; 2], paper_cell: Option<String>| {
        summary.row(cells.into_iter().chain(paper.and(paper_cell)));
    };
    row(
        [
            format!("rows verified (kept {})", report.rows_kept),
            report.rows.len().to_string(),
        ],
        paper.map(|p| p.poses.to_string()),
    );
    row(
        ["MPE-L, cable length %".to_string(), opt(report.mpe_length_pct, 4)],
        paper.map(|p| format!("{:.4}", p.mpe_length_pct)),
    );
    row(
        [
            format!("MPE-F, tension % ({} comparisons)", report.force_comparisons),
            opt(report.mpe_force_pct, 4),
        ],
        paper.map(|p| format!("{:.4}", p.mpe_force_pct)),
    );
    row(
        [
            "orientation error deg (mean / max)".to_string(),
            format!(
                "{} / {}",
                opt(report.orientation_error_deg, 2),
                opt(report.max_orientation_error_deg, 2)
            ),
        ],
        Some("-".into()),
    );
    let mut out = summary.to_string();
    if let Some(reason) = &report.mpe_force_reason {
        out += &format!("MPE-F is -: {reason}\n");
    }
    if paper.is_none() {
        out += &format!(
            "no paper Table I column: robot `{}` is not one of the paper's robots (its file has no `paper_robot`)\n",
            report.robot
        );
    }
    out
}

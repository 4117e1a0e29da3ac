//! `sagcal verify`: the model against measured data.

use sagcal::diagnose::verify::{verify, Closure, MeasuredData, VerifyReport};
use sagcal::io::measurements::{read_measurements, MeasurementFormat, ReadOptions};
use sagcal::io::recurdyn::{read_recurdyn, LoadOptions};
use sagcal::model::statics::StaticsOptions;
use sagcal::model::Robot;

use super::output::{opt, print_json, Table};
use super::{ClosureArg, VerifyArgs};

/// Verify the model against the data and print the report (or JSON).
pub fn run(args: &VerifyArgs) -> sagcal::Result<()> {
    let robot = Robot::from_file(&args.robot)?;
    let data = read_data(args, &robot)?;
    let closure = match args.close_with {
        ClosureArg::ReferenceTension => Closure::ReferenceTension,
        ClosureArg::CableLengths => Closure::CableLengths,
    };
    let report = verify(&robot, &data, closure, &StaticsOptions::default());
    if args.json {
        print_json(&report)
    } else {
        print!("{}", render(&report));
        Ok(())
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
    out += &format!(
        "sagcal verify: robot `{}`, data {}\nmodel closed with: {closure}; orientation is predicted, never an input\n\n",
        report.robot, report.data
    );
    let mut table = Table::new([
        "row",
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
            r.line.to_string(),
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
        out += &format!("rejected rows ({}):\n", report.rows_rejected.len());
        for r in &report.rows_rejected {
            out += &format!("  row {:>3}: {}\n", r.line, r.reason);
        }
        out += "\n";
    }
    if !report.rows_unsolved.is_empty() {
        out += &format!(
            "rows without a positive-tension equilibrium ({}):\n",
            report.rows_unsolved.len()
        );
        for r in &report.rows_unsolved {
            out += &format!("  row {:>3}: {}\n", r.line, r.reason);
        }
        out += "\n";
    }
    out
}

/// How each reading of the angle columns matches the model's equilibria.
fn render_orientation(report: &VerifyReport) -> String {
    let mut out = "orientation: how each reading of the angle columns matches the model's equilibria\n".to_string();
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
                "  row {:>3}: {:.2} deg as documented, {:.2} deg as {}\n",
                s.line, s.documented_error_deg, s.best_error_deg, s.best_convention
            );
        }
    }
    out += "\n";
    out
}

/// MPE-L, MPE-F and the orientation error beside the paper's Table I.
fn render_summary(report: &VerifyReport) -> String {
    let mut summary = Table::new(["summary", "sagcal", "paper Table I"]);
    summary.row([
        format!("rows verified (kept {})", report.rows_kept),
        report.rows.len().to_string(),
        "5".into(),
    ]);
    summary.row([
        "MPE-L, cable length %".to_string(),
        format!("{:.4}", report.mpe_length_pct),
        format!("{:.4}", report.paper_table1_mpe_length_pct),
    ]);
    summary.row([
        format!("MPE-F, tension % ({} comparisons)", report.force_comparisons),
        format!("{:.4}", report.mpe_force_pct),
        format!("{:.4}", report.paper_table1_mpe_force_pct),
    ]);
    summary.row([
        "orientation error deg (mean / max)".to_string(),
        format!(
            "{:.2} / {:.2}",
            report.orientation_error_deg, report.max_orientation_error_deg
        ),
        "-".into(),
    ]);
    summary.to_string()
}

//! `sagcal verify` on a robot of 3 to 8 cables
//! ([`sagcal::diagnose::suspended::verify_suspended`]): each row's fit with
//! the robot held, the tests of the file, the rows and the readings.

use sagcal::calib::suspended::{suspended_options, SuspendedReading};
use sagcal::calib::SolverSettings;
use sagcal::diagnose::suspended::{verify_suspended, SuspendedVerifyReport, VerifiedReading};
use sagcal::error::FrontEnd;
use sagcal::io::suspended_measurements::read_suspended_measurements;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::suspended::SuspendedRobot;

use super::output::{print_json, wrapped, Table};
use super::robot_kind::refuse_four_cable_flags;
use super::verify_args::VerifyArgs;

/// The report's width, characters.
const WIDTH: usize = 100;

/// How many suspect readings the text lists (the JSON has all).
const SUSPECTS_SHOWN: usize = 10;

/// The false-alarm rate without `--false-alarm`.
const DEFAULT_FALSE_ALARM: f64 = 1e-3;

/// Verify `robot` against `args.data` and print the report (or JSON).
pub(super) fn run(args: &VerifyArgs, robot: &SuspendedRobot) -> sagcal::Result<()> {
    refuse_four_cable_flags(
        &[
            (args.close_with.is_some(), "--close-with"),
            (args.keep_rounded, "--keep-rounded"),
        ],
        robot,
        "every reading of a row closes its model at once (the four-cable closures leave N - 3 forces open)",
    )?;
    let noise = args.noise.unwrap_or(NoisePreset::Paper);
    let options = suspended_options(&SolverSettings::new(noise), robot, FrontEnd::Cli)?;
    let data = read_suspended_measurements(&args.data, robot)?;
    let false_alarm = args.false_alarm.unwrap_or(DEFAULT_FALSE_ALARM);
    let report = verify_suspended(robot, &args.data.display().to_string(), &data, &options, false_alarm).map_err(
        |e| match e {
            sagcal::Error::InvalidInput(m) if m.starts_with("false-alarm") => {
                sagcal::Error::InvalidInput(format!("--false-alarm: {m}"))
            }
            other => other,
        },
    )?;
    if args.json {
        return print_json(&report);
    }
    print!("{}", render(&report, noise));
    Ok(())
}

/// A reading's short name: `l3`, `f1`, `x`.
fn label(reading: SuspendedReading) -> String {
    match reading {
        SuspendedReading::Encoder(i) => format!("l{}", i + 1),
        SuspendedReading::LoadCell(i) => format!("f{}", i + 1),
        SuspendedReading::Position(a) => ["x", "y", "z"][a.min(2)].to_string(),
        SuspendedReading::Orientation(a) => ["roll", "pitch", "yaw"][a.min(2)].to_string(),
    }
}

/// A residual in the unit the table gives it: millimetres for lengths and
/// positions, newtons for load cells.
fn in_unit(reading: &VerifiedReading) -> String {
    match reading.reading {
        SuspendedReading::LoadCell(_) => format!("{:+.2}", reading.residual),
        SuspendedReading::Orientation(_) => format!("{:+.4}", reading.residual.to_degrees()),
        _ => format!("{:+.2}", reading.residual * 1e3),
    }
}

/// The unit [`in_unit`] writes.
fn unit(reading: SuspendedReading) -> &'static str {
    match reading {
        SuspendedReading::LoadCell(_) => "N",
        SuspendedReading::Orientation(_) => "deg",
        _ => "mm",
    }
}

/// The report as text.
fn render(report: &SuspendedVerifyReport, noise: NoisePreset) -> String {
    let cells: Vec<String> = report.load_cells.iter().map(|c| format!("cable {c}")).collect();
    let cells = cells.join(", ");
    let mut text = format!(
        "sagcal verify: robot `{}` ({} cables, load cells on {cells}), data {}, {} rows\n\
         each row's pose and cable forces fitted to its readings, weighed by the `{noise}` noise;\n\
         the robot held as its file gives it; the orientation predicted, never an input; residual = reading - model\n\n",
        report.robot,
        report.cables,
        report.data,
        report.rows.len(),
    );
    text += &rows_table(report);
    text += "(chi2: the row's chi-square, limit its 1 - a/rows quantile; rot: angle between the fitted and the \
             logged orientation; worst: the reading with the largest normalised residual w)\n\n";
    text += &summary_table(report);
    text += "\n";
    if report.suspect_readings.is_empty() {
        text += &format!("readings beyond |w| {:.2}: none\n", report.reading_limit);
    } else {
        text += &format!("readings beyond |w| {:.2}:\n", report.reading_limit);
        for s in report.suspect_readings.iter().take(SUSPECTS_SHOWN) {
            text += &format!(
                "  {}: {} residual {} {}, w {:+.2}\n",
                s.at,
                label(s.reading.reading),
                in_unit(&s.reading),
                unit(s.reading.reading),
                s.reading.w.unwrap_or(0.0)
            );
        }
        if report.suspect_readings.len() > SUSPECTS_SHOWN {
            text += &format!(
                "  ... and {} more (--json lists every one)\n",
                report.suspect_readings.len() - SUSPECTS_SHOWN
            );
        }
    }
    text += "\n";
    text += &wrapped(&report.conclusion, WIDTH).join("\n");
    text += "\n";
    text
}

/// Per row: position, chi-square and test, every encoder's and load cell's residual, the worst reading.
fn rows_table(report: &SuspendedVerifyReport) -> String {
    let mut header = vec!["row", "line", "x m", "y m", "z m", "chi2", "dof", "limit", ""]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
    header.pop();
    header.extend((1..=report.cables).map(|i| format!("dl{i} mm")));
    header.extend(report.load_cells.iter().map(|c| format!("df{c} N")));
    header.extend(["rot deg".to_string(), "worst".to_string(), "w".to_string()]);
    let mut table = Table::new(header);
    for row in &report.rows {
        let mut cells = vec![
            row.at.row.to_string(),
            row.at.line.map_or("-".into(), |l| l.to_string()),
            format!("{:.3}", row.position_m[0]),
            format!("{:.3}", row.position_m[1]),
            format!("{:.3}", row.position_m[2]),
            format!("{:.2}{}", row.chi_square, if row.passes { "" } else { " *" }),
            row.degrees_of_freedom.to_string(),
            format!("{:.1}", row.limit),
        ];
        let which = (0..report.cables)
            .map(SuspendedReading::Encoder)
            .chain(report.load_cells.iter().map(|c| SuspendedReading::LoadCell(c - 1)));
        cells.extend(which.map(|w| row.reading(w).map_or("-".into(), in_unit)));
        cells.push(format!("{:.3}", row.orientation_error_deg));
        match row.worst() {
            Some(worst) => {
                cells.push(label(worst.reading));
                cells.push(format!("{:+.2}", worst.w.unwrap_or(0.0)));
            }
            None => cells.extend([String::from("-"), String::from("-")]),
        }
        table.row(cells);
    }
    table.to_string()
}

/// Per encoder and load cell: the residuals' mean and RMS against the sigma, and how much the fit checks them.
fn summary_table(report: &SuspendedVerifyReport) -> String {
    let mut table = Table::new([
        "reading",
        "mean",
        "rms",
        "sigma",
        "unit",
        "mean redundancy",
        "found from (80 %)",
    ]);
    for s in &report.summaries {
        let scale = if matches!(s.reading, SuspendedReading::LoadCell(_)) {
            1.0
        } else {
            1e3
        };
        table.row([
            label(s.reading),
            format!("{:+.3}", s.mean * scale),
            format!("{:.3}", s.rms * scale),
            format!("{:.3}", s.sigma * scale),
            unit(s.reading).to_string(),
            format!("{:.4}", s.mean_redundancy),
            s.minimal_detectable.map_or("-".into(), |m| format!("{:.1}", m * scale)),
        ]);
    }
    table.to_string() + "(found from: the smallest single error in one reading that its w test finds with 80 % power)\n"
}

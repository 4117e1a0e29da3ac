//! `sagcal check`: what sagcal understood from a robot file and a data file,
//! before any fit; its flags ([`CheckArgs`]) and the text of the report
//! (`sagcal::check` makes it; `--json` prints the same struct); a robot of
//! 3 to 8 cables in `check_suspended.rs`.

use std::path::PathBuf;

use sagcal::check::{check_robot_and_data, check_suspended_robot_and_data, CheckReport, DataSummary, RobotSummary};

use super::check_tables::{data_tables, frame_lines, indent, point, short, warnings_text};
use super::output::{print_json, Table};
use super::robot_kind::{read_robot, AnyRobot};

#[derive(Debug, clap::Args)]
pub(super) struct CheckArgs {
    /// Robot description (TOML), e.g. one `sagcal init` wrote.
    #[arg(long)]
    robot: PathBuf,
    /// Data: sagcal CSV, readings-only CSV, RecurDyn log or the authors' dataset folder.
    #[arg(long)]
    data: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// Check the files and print what was understood (or JSON).
pub fn run(args: &CheckArgs) -> sagcal::Result<()> {
    let report = match read_robot(&args.robot)? {
        AnyRobot::Four(robot) => check_robot_and_data(&robot, &args.robot, args.data.as_deref())?,
        AnyRobot::Suspended(robot) => {
            let report = check_suspended_robot_and_data(&robot, &args.robot, args.data.as_deref())?;
            return super::check_suspended::print(&report, args.json);
        }
    };
    if args.json {
        return print_json(&report);
    }
    print!("{}", render(&report));
    Ok(())
}

/// The readable report: the robot, the data, the warnings.
fn render(report: &CheckReport) -> String {
    let mut out = render_robot(&report.robot);
    if let Some(data) = &report.data {
        out += "\n";
        out += &render_data(data);
    }
    out += "\n";
    out += &warnings_text(&report.warnings);
    out
}

fn render_robot(r: &RobotSummary) -> String {
    let mut out = format!(
        "robot {}: `{}`, {} cables, the load cell on cable {}\n",
        r.path, r.name, r.cables, r.reference_cable
    );
    out += &frame_lines(
        &r.anchor_span_m,
        [r.footprint_width_m, r.footprint_diameter_m],
        [r.platform_weight_n, r.platform_mass_kg],
        &r.com_offset_m,
        r.platform_reach_m,
    );
    out += &format!(
        "  cables: {} N/m ({:.2} g/m)\n",
        short(r.cable_weight_n_per_m),
        r.cable_mass_g_per_m
    );
    let mut table = Table::new(["cable", "anchor m (world)", "attachment m (platform)", "offset m"]);
    for i in 0..r.cables {
        table.row([
            (i + 1).to_string(),
            point(&r.anchors_m[i]),
            point(&r.attachments_m[i]),
            format!("{:.3}", r.length_offsets_m[i]),
        ]);
    }
    out += &indent(&table.to_string());
    let w = &r.workspace;
    out += &format!(
        "  workspace ({}): x {:.3} .. {:.3}, y {:.3} .. {:.3}, z {:.3} .. {:.3} m\n",
        w.source, w.min_m[0], w.max_m[0], w.min_m[1], w.max_m[1], w.min_m[2], w.max_m[2]
    );
    out += &format!(
        "  effects: {}\n",
        if r.effects.is_empty() {
            "none".to_string()
        } else {
            r.effects.join(" ")
        }
    );
    if r.calibration_covariance {
        out += "  calibrated: the file holds its calibration's covariance (localize uses it)\n";
    }
    if let Some(paper) = &r.paper_robot {
        out += &format!("  the paper's `{paper}` robot (verify prints its Table I column)\n");
    }
    out
}

fn render_data(d: &DataSummary) -> String {
    let mut out = format!(
        "data {}: {}, {} rows (lines {} .. {})\n",
        d.path, d.format_description, d.rows, d.lines.min, d.lines.max
    );
    if !d.rejected.is_empty() {
        out += &format!(
            "  {} rows left out by the reader (see the warnings)\n",
            d.rejected.len()
        );
    }
    let s = &d.sensors;
    let load_cell = match s.load_cell_cable {
        Some(cable) => format!("load cell on cable {cable} ({} of {} rows)", s.load_cell_rows, d.rows),
        None => "no load cell".to_string(),
    };
    out += &format!(
        "  sensors: {} encoders; {load_cell}; {}; localiser orientation {}{}\n",
        s.encoders,
        if s.localiser_position {
            "localiser position"
        } else {
            "no localiser position"
        },
        s.localiser_orientation,
        if s.all_cable_tension_rows > 0 {
            format!(
                "; every cable's tension on {} rows (verify compares them)",
                s.all_cable_tension_rows
            )
        } else {
            String::new()
        }
    );
    out += &format!("  closure: {}\n", s.closure);
    out += &format!("  usable by: {}\n", d.usable_by.join(", "));
    out += &data_tables(&d.columns, &d.samples, &d.geometry);
    out
}

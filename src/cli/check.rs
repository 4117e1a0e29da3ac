//! `sagcal check`: what sagcal understood from a robot file and a data file,
//! before any fit; its flags ([`CheckArgs`]) and the text of the report
//! (`sagcal::check` makes it; `--json` prints the same struct).

use std::path::PathBuf;

use sagcal::check::{check_files, row_label, CheckReport, DataSummary, RobotSummary};

use super::output::{print_json, Table};

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
    let report = check_files(&args.robot, args.data.as_deref())?;
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
    if report.warnings.is_empty() {
        out += "warnings: none\n";
    } else {
        out += &format!("warnings ({}):\n", report.warnings.len());
        for w in &report.warnings {
            out += &format!("  - {}\n", w.message);
        }
    }
    out
}

/// `v` to 6 significant digits, as short as it reads (333.54, 0.710070).
fn short(v: f64) -> String {
    format!("{v:.5e}")
        .parse::<f64>()
        .map_or_else(|_| v.to_string(), |r| r.to_string())
}

fn point(p: &[f64; 3]) -> String {
    format!("[{:.3}, {:.3}, {:.3}]", p[0], p[1], p[2])
}

fn render_robot(r: &RobotSummary) -> String {
    let [x, y, z] = r.anchor_span_m;
    let mut out = format!(
        "robot {}: `{}`, {} cables, the load cell on cable {}\n",
        r.path, r.name, r.cables, r.reference_cable
    );
    out += &format!(
        "  anchors (world frame): x {:.3} .. {:.3} m, y {:.3} .. {:.3} m, z {:.3} .. {:.3} m; footprint {:.3} m wide, \
         {:.3} m across\n",
        x.min, x.max, y.min, y.max, z.min, z.max, r.footprint_width_m, r.footprint_diameter_m
    );
    out += &format!(
        "  platform: {} N ({:.3} kg), centre of mass {} m (platform frame), attachments up to {:.3} m from its origin\n",
        short(r.platform_weight_n),
        r.platform_mass_kg,
        point(&r.com_offset_m),
        r.platform_reach_m
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

/// A value of a column, `-` for none (a column no row holds a value in).
fn value(v: f64) -> String {
    if v.is_nan() {
        "-".into()
    } else {
        format!("{v:.4}")
    }
}

fn indent(text: &str) -> String {
    text.lines().map(|l| format!("  {}\n", l.trim_end())).collect()
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
    // The quantity last and padded: the table right-aligns every column but the first.
    let width = d.columns.iter().map(|c| c.quantity.chars().count()).max().unwrap_or(0);
    let mut columns = Table::new([
        "column",
        "unit",
        "rows",
        "min",
        "max",
        &format!("{:<width$}", "quantity"),
    ]);
    for c in &d.columns {
        columns.row([
            c.column.clone(),
            c.unit.clone(),
            c.rows.to_string(),
            value(c.range.min),
            value(c.range.max),
            format!("{:<width$}", c.quantity),
        ]);
    }
    out += &indent(&columns.to_string());
    out += "  rows as read:\n";
    let mut samples = Table::new(std::iter::once("row".to_string()).chain(d.columns.iter().map(|c| c.column.clone())));
    for row in &d.samples {
        samples.row(
            std::iter::once(row_label(row.row, row.line)).chain(
                row.values
                    .iter()
                    .map(|v| v.map_or("-".to_string(), |v| format!("{v:.4}"))),
            ),
        );
    }
    out += &indent(&samples.to_string());
    if !d.geometry.is_empty() {
        out += "  encoders against the geometry (reading - distance from the anchor to the attachment at the logged \
                pose; slope of the readings on the distances):\n";
        let mut table = Table::new(["cable", "median m", "robot offset m", "slope", "correlation"]);
        for g in &d.geometry {
            table.row([
                g.cable.to_string(),
                format!("{:+.3}", g.median_reading_minus_distance_m),
                format!("{:.3}", g.robot_offset_m),
                g.slope.map_or("-".into(), |v| format!("{v:.4}")),
                g.correlation.map_or("-".into(), |v| format!("{v:.4}")),
            ]);
        }
        out += &indent(&table.to_string());
    }
    out
}

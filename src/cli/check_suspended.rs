//! `sagcal check` on a robot of 3 to 8 cables
//! ([`sagcal::check::check_suspended_files`]): the robot, the data, the
//! warnings; `--json` prints the same struct.

use sagcal::check::{SuspendedCheckReport, SuspendedDataSummary, SuspendedRobotSummary};

use super::check_tables::{data_tables, frame_lines, indent, point, short, warnings_text};
use super::output::{print_json, Table};

/// Print `report` (or its JSON).
pub(super) fn print(report: &SuspendedCheckReport, json: bool) -> sagcal::Result<()> {
    if json {
        return print_json(report);
    }
    let mut out = render_robot(&report.robot);
    if let Some(data) = &report.data {
        out += "\n";
        out += &render_data(data);
    }
    out += "\n";
    out += &warnings_text(&report.warnings);
    print!("{out}");
    Ok(())
}

fn render_robot(r: &SuspendedRobotSummary) -> String {
    let cells: Vec<String> = r.load_cells.iter().map(|c| format!("cable {c}")).collect();
    let mut out = format!(
        "robot {}: `{}`, {} cables, load cells on {}; the statics leave {} force components free at a pose\n",
        r.path,
        r.name,
        r.cables,
        cells.join(", "),
        r.free_force_components
    );
    out += &frame_lines(
        &r.anchor_span_m,
        [r.footprint_width_m, r.footprint_diameter_m],
        [r.platform_weight_n, r.platform_mass_kg],
        &r.com_offset_m,
        r.platform_reach_m,
    );
    let mut table = Table::new([
        "cable",
        "anchor m (world)",
        "attachment m (platform)",
        "weight N/m",
        "EA N",
        "offset m",
    ]);
    for i in 0..r.cables {
        table.row([
            (i + 1).to_string(),
            point(&r.anchors_m[i]),
            point(&r.attachments_m[i]),
            short(r.cable_weights_n_per_m[i]),
            r.axial_stiffness_n[i].map_or("inextensible".into(), short),
            format!("{:.3}", r.length_offsets_m[i]),
        ]);
    }
    out += &indent(&table.to_string());
    let w = &r.workspace;
    out += &format!(
        "  workspace ({}): x {:.3} .. {:.3}, y {:.3} .. {:.3}, z {:.3} .. {:.3} m\n",
        w.source, w.min_m[0], w.max_m[0], w.min_m[1], w.max_m[1], w.min_m[2], w.max_m[2]
    );
    out
}

fn render_data(d: &SuspendedDataSummary) -> String {
    let mut out = format!(
        "data {}: {}, {} rows (lines {} .. {})\n",
        d.path, d.format_description, d.rows, d.lines.min, d.lines.max
    );
    out += &format!("  usable by: {}\n", d.usable_by.join(", "));
    out += &data_tables(&d.columns, &d.samples, &d.geometry);
    out
}

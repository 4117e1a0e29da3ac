//! The text pieces `sagcal check` prints for robots of four cables and of
//! 3 to 8: numbers as short as they read, points, and the data's tables
//! (columns, rows as read, encoders against the geometry).

use sagcal::check::{row_label, CableAgainstGeometry, ColumnSummary, SampleRow, Span};

use super::output::Table;

/// `v` to 6 significant digits, as short as it reads (333.54, 0.710070).
pub(super) fn short(v: f64) -> String {
    format!("{v:.5e}")
        .parse::<f64>()
        .map_or_else(|_| v.to_string(), |r| r.to_string())
}

/// `[x, y, z]` to the millimetre.
pub(super) fn point(p: &[f64; 3]) -> String {
    format!("[{:.3}, {:.3}, {:.3}]", p[0], p[1], p[2])
}

/// The robot's frame and platform: the anchors' span and footprint
/// (`[width, diameter]` m), the platform's weight (`[N, kg]`), centre of
/// mass and reach.
pub(super) fn frame_lines(
    span: &[Span; 3],
    [width, diameter]: [f64; 2],
    [weight_n, mass_kg]: [f64; 2],
    com_m: &[f64; 3],
    reach_m: f64,
) -> String {
    let [x, y, z] = span;
    let mut out = format!(
        "  anchors (world frame): x {:.3} .. {:.3} m, y {:.3} .. {:.3} m, z {:.3} .. {:.3} m; footprint {width:.3} m wide, \
         {diameter:.3} m across\n",
        x.min, x.max, y.min, y.max, z.min, z.max
    );
    out += &format!(
        "  platform: {} N ({mass_kg:.3} kg), centre of mass {} m (platform frame), attachments up to {reach_m:.3} m from its origin\n",
        short(weight_n),
        point(com_m),
    );
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

/// `text` indented by two spaces, each line's trailing blanks removed.
pub(super) fn indent(text: &str) -> String {
    text.lines().map(|l| format!("  {}\n", l.trim_end())).collect()
}

/// The data's tables: each column's unit and range, the rows as read, and
/// (where there are poses) the encoders against the geometry.
pub(super) fn data_tables(
    columns: &[ColumnSummary],
    samples: &[SampleRow],
    geometry: &[CableAgainstGeometry],
) -> String {
    // The quantity last and padded: the table right-aligns every column but the first.
    let width = columns.iter().map(|c| c.quantity.chars().count()).max().unwrap_or(0);
    let mut table = Table::new([
        "column",
        "unit",
        "rows",
        "min",
        "max",
        &format!("{:<width$}", "quantity"),
    ]);
    for c in columns {
        table.row([
            c.column.clone(),
            c.unit.clone(),
            c.rows.to_string(),
            value(c.range.min),
            value(c.range.max),
            format!("{:<width$}", c.quantity),
        ]);
    }
    let mut out = indent(&table.to_string());
    out += "  rows as read:\n";
    let mut rows = Table::new(std::iter::once("row".to_string()).chain(columns.iter().map(|c| c.column.clone())));
    for row in samples {
        rows.row(
            std::iter::once(row_label(row.row, row.line)).chain(
                row.values
                    .iter()
                    .map(|v| v.map_or("-".to_string(), |v| format!("{v:.4}"))),
            ),
        );
    }
    out += &indent(&rows.to_string());
    if !geometry.is_empty() {
        out += "  encoders against the geometry (reading - distance from the anchor to the attachment at the logged \
                pose; slope of the readings on the distances):\n";
        let mut table = Table::new(["cable", "median m", "robot offset m", "slope", "correlation"]);
        for g in geometry {
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

/// The warnings, or `warnings: none`.
pub(super) fn warnings_text(warnings: &[sagcal::check::CheckWarning]) -> String {
    if warnings.is_empty() {
        return "warnings: none\n".into();
    }
    let mut out = format!("warnings ({}):\n", warnings.len());
    for w in warnings {
        out += &format!("  - {}\n", w.message);
    }
    out
}

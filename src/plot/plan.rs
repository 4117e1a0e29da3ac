//! The figure of `sagcal plan --plot`: the frame, the anchors, the candidate
//! region, the chosen poses in visiting order with the path, in a top (x-y)
//! and a side (x-z) view; below, per anchor, the 1-sigma error ellipses the
//! Cramer-Rao bound allows for the plan and for random pose sets of the same
//! size (the mean covariance of the random sets), top and side views at true
//! scale around the anchor.
//!
//! ```
//! use sagcal::plot::plan::{plan_plot_svg, PlanPlot};
//! let plot = PlanPlot {
//!     title: "plan: 3 poses".into(),
//!     caption: "sagcal plan --robot large --poses 3".into(),
//!     anchors_m: vec![[-125.0, -110.0, 48.0], [125.0, -110.0, 48.0], [125.0, 110.0, 48.0], [-125.0, 110.0, 48.0]],
//!     workspace_m: Some(([-30.0, -30.0, 1.0], [30.0, 30.0, 28.0])),
//!     candidates_m: vec![[0.0, 0.0, 10.0], [10.0, 5.0, 12.0], [-8.0, 4.0, 20.0], [5.0, -5.0, 5.0]],
//!     path_m: vec![[0.0, 0.0, 10.0], [10.0, 5.0, 12.0], [-8.0, 4.0, 20.0]],
//!     plan_covariance_m2: vec![[[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 4e-4]]; 4],
//!     random_covariance_m2: vec![[[4e-4, 0.0, 0.0], [0.0, 4e-4, 0.0], [0.0, 0.0, 1.6e-3]]; 4],
//! };
//! let svg = plan_plot_svg(&plot);
//! assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
//! assert!(svg.contains("plan: 3 poses"));
//! ```

use std::fmt::Write as _;

use super::svg::{esc, n2, C_FRAME, C_GRID, C_MUTED, C_TEXT, FONT};

/// Everything [`plan_plot_svg`] draws (plain numbers: the plot layer sees no model type).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlanPlot {
    /// Title at the top.
    pub title: String,
    /// Free text at the bottom (command, seed, numbers).
    pub caption: String,
    /// The anchors, metres.
    pub anchors_m: Vec<[f64; 3]>,
    /// The box candidates were drawn in, metres (`None` for candidates from a file).
    pub workspace_m: Option<([f64; 3], [f64; 3])>,
    /// Candidate positions, metres.
    pub candidates_m: Vec<[f64; 3]>,
    /// The chosen positions in visiting order, metres.
    pub path_m: Vec<[f64; 3]>,
    /// Per anchor, the plan's 3x3 covariance, m^2.
    pub plan_covariance_m2: Vec<[[f64; 3]; 3]>,
    /// Per anchor, the mean covariance of the random sets, m^2.
    pub random_covariance_m2: Vec<[[f64; 3]; 3]>,
}

const WIDTH: f64 = 1200.0;
const TOP_H: f64 = 430.0;
const CELL: f64 = 128.0;
/// Anchors whose two ellipse cells share a row.
const ANCHORS_PER_ROW: usize = 4;
/// From one row of ellipse cells to the next (a cell, its title and a gap).
const ROW_PITCH: f64 = CELL + 32.0;
const C_PLAN: &str = "#1f5fbf";
const C_RANDOM: &str = "#d9822b";
const C_CANDIDATE: &str = "#b8b8b8";
const C_ANCHOR: &str = "#222222";
const MAX_CANDIDATE_DOTS: usize = 4000;

/// A panel's mapping from metres (two axes) to pixels.
struct Frame {
    left: f64,
    top: f64,
    scale: f64,
    min: [f64; 2],
    height: f64,
}

impl Frame {
    /// Fit `[min, max]` into a `width x height` box (equal scale on both axes).
    fn fit(left: f64, top: f64, width: f64, height: f64, min: [f64; 2], max: [f64; 2]) -> Self {
        let span = [(max[0] - min[0]).max(1e-9), (max[1] - min[1]).max(1e-9)];
        let scale = (width / span[0]).min(height / span[1]);
        let pad = [(width - scale * span[0]) / 2.0, (height - scale * span[1]) / 2.0];
        Self {
            left: left + pad[0],
            top: top + pad[1],
            scale,
            min,
            height: scale * span[1],
        }
    }

    fn px(&self, p: [f64; 2]) -> (f64, f64) {
        (
            self.left + (p[0] - self.min[0]) * self.scale,
            self.top + self.height - (p[1] - self.min[1]) * self.scale,
        )
    }
}

fn bounds(points: impl Iterator<Item = [f64; 2]>) -> ([f64; 2], [f64; 2]) {
    points.fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), p| {
        ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])])
    })
}

fn rect(s: &mut String, f: &Frame, a: [f64; 2], b: [f64; 2], style: &str) {
    let (x0, y0) = f.px([a[0].min(b[0]), a[1].max(b[1])]);
    let (x1, y1) = f.px([a[0].max(b[0]), a[1].min(b[1])]);
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{}" height="{}" {style}/>"#,
        n2(x0),
        n2(y0),
        n2(x1 - x0),
        n2(y1 - y0)
    );
}

/// One overview panel: `axes` picks the two coordinates (0 = x, 1 = y, 2 = z).
fn overview(s: &mut String, plot: &PlanPlot, axes: [usize; 2], left: f64, top: f64, width: f64, name: &str) {
    let pick = |p: &[f64; 3]| [p[axes[0]], p[axes[1]]];
    let (mut lo, mut hi) = bounds(plot.anchors_m.iter().chain(&plot.candidates_m).map(pick));
    if axes[1] == 2 {
        lo[1] = lo[1].min(0.0);
    }
    let margin = 0.05 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    lo = [lo[0] - margin, lo[1] - margin];
    hi = [hi[0] + margin, hi[1] + margin];
    let f = Frame::fit(left + 40.0, top + 30.0, width - 60.0, TOP_H - 80.0, lo, hi);
    let axis = ["x", "y", "z"];
    plain_text(
        s,
        left + width / 2.0,
        top + 16.0,
        "middle",
        &format!("{name} ({} right, {} up), metres", axis[axes[0]], axis[axes[1]]),
    );
    // The frame: the anchors' box, down to the floor in the side view.
    let (flo, fhi) = bounds(plot.anchors_m.iter().map(pick));
    let flo = if axes[1] == 2 { [flo[0], 0.0] } else { flo };
    rect(
        s,
        &f,
        flo,
        fhi,
        &format!(r#"fill="none" stroke="{C_FRAME}" stroke-width="1.5""#),
    );
    if let Some((wmin, wmax)) = plot.workspace_m {
        rect(
            s,
            &f,
            pick(&wmin),
            pick(&wmax),
            &format!(r##"fill="#f4f8ff" stroke="{C_PLAN}" stroke-width="1" stroke-dasharray="5 4""##),
        );
    }
    let stride = (plot.candidates_m.len() / MAX_CANDIDATE_DOTS).max(1);
    for c in plot.candidates_m.iter().step_by(stride) {
        let (x, y) = f.px(pick(c));
        let _ = writeln!(
            s,
            r#"<circle cx="{}" cy="{}" r="1.3" fill="{C_CANDIDATE}"/>"#,
            n2(x),
            n2(y)
        );
    }
    let points: Vec<String> = plot
        .path_m
        .iter()
        .map(|p| {
            let (x, y) = f.px(pick(p));
            format!("{},{}", n2(x), n2(y))
        })
        .collect();
    let _ = writeln!(
        s,
        r#"<polyline points="{}" fill="none" stroke="{C_PLAN}" stroke-width="1.3" opacity="0.8"/>"#,
        points.join(" ")
    );
    for (k, p) in plot.path_m.iter().enumerate() {
        let (x, y) = f.px(pick(p));
        let fill = if k == 0 { "#0a8a3a" } else { C_PLAN };
        let _ = writeln!(s, r#"<circle cx="{}" cy="{}" r="3.2" fill="{fill}"/>"#, n2(x), n2(y));
        if plot.path_m.len() <= 40 {
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" font-size="9" fill="{C_MUTED}">{}</text>"#,
                n2(x + 4.0),
                n2(y - 3.0),
                k + 1
            );
        }
    }
    anchor_labels(s, plot, &f, axes, left + width);
}

/// The anchors' squares and labels in a view on `axes`: anchors that
/// project onto one point (the side view) or within a label's height of it
/// (pulleys in pairs on one post) share one label, which ends at its anchor
/// where it would pass `right`.
fn anchor_labels(s: &mut String, plot: &PlanPlot, f: &Frame, axes: [usize; 2], right: f64) {
    let pick = |p: &[f64; 3]| [p[axes[0]], p[axes[1]]];
    let mut labelled: Vec<((f64, f64), Vec<String>)> = Vec::new();
    for (i, a) in plot.anchors_m.iter().enumerate() {
        let (x, y) = f.px(pick(a));
        let _ = writeln!(
            s,
            r#"<rect x="{}" y="{}" width="8" height="8" fill="{C_ANCHOR}"/>"#,
            n2(x - 4.0),
            n2(y - 4.0)
        );
        match labelled
            .iter_mut()
            .find(|(p, _)| (p.0 - x).abs() < 16.0 && (p.1 - y).abs() < 16.0)
        {
            Some((_, names)) => names.push(format!("A{}", i + 1)),
            None => labelled.push(((x, y), vec![format!("A{}", i + 1)])),
        }
    }
    for ((x, y), names) in labelled {
        let text = names.join(", ");
        // About 7 px a character at 12 px: a label that would leave the view ends at its anchor.
        if x + 7.0 + 7.0 * text.len() as f64 > right {
            plain_text(s, x - 7.0, y - 6.0, "end", &text);
        } else {
            plain_text(s, x + 7.0, y - 6.0, "start", &text);
        }
    }
}

/// Text in the body colour (no halo: the labels sit on white).
fn plain_text(s: &mut String, x: f64, y: f64, anchor: &str, text: &str) {
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="{anchor}" fill="{C_TEXT}">{}</text>"#,
        n2(x),
        n2(y),
        esc(text)
    );
}

/// The 1-sigma ellipse of a 2x2 covariance: semi-axes and the angle of the first, radians.
fn ellipse(a: f64, b: f64, d: f64) -> Option<(f64, f64, f64)> {
    if !(a.is_finite() && b.is_finite() && d.is_finite() && a > 0.0 && d > 0.0 && a * d - b * b > 0.0) {
        return None;
    }
    let mean = 0.5 * (a + d);
    let radius = (0.25 * (a - d).powi(2) + b * b).sqrt();
    let (l1, l2) = (mean + radius, (mean - radius).max(0.0));
    let angle = 0.5 * (2.0 * b).atan2(a - d);
    Some((l1.sqrt(), l2.sqrt(), angle))
}

fn draw_ellipse(s: &mut String, f: &Frame, centre: [f64; 2], c: &[[f64; 3]; 3], axes: [usize; 2], color: &str) {
    let Some((r1, r2, angle)) = ellipse(c[axes[0]][axes[0]], c[axes[0]][axes[1]], c[axes[1]][axes[1]]) else {
        return;
    };
    let (x, y) = f.px(centre);
    // SVG's y points down: the angle turns the other way.
    let _ = writeln!(
        s,
        r#"<ellipse cx="{}" cy="{}" rx="{}" ry="{}" transform="rotate({} {} {})" fill="{color}" fill-opacity="0.12" stroke="{color}" stroke-width="1.6"/>"#,
        n2(x),
        n2(y),
        n2(r1 * f.scale),
        n2(r2 * f.scale),
        n2(-angle.to_degrees()),
        n2(x),
        n2(y)
    );
}

/// One anchor's zoomed panel: plan and random ellipses around the anchor, true scale.
fn anchor_cell(s: &mut String, plot: &PlanPlot, i: usize, axes: [usize; 2], left: f64, top: f64, half_m: f64) {
    let axis = ["x", "y", "z"];
    let f = Frame::fit(left, top + 18.0, CELL, CELL, [-half_m, -half_m], [half_m, half_m]);
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{CELL}" height="{CELL}" fill="white" stroke="{C_FRAME}"/>"#,
        n2(left),
        n2(top + 18.0)
    );
    let (cx, cy) = f.px([0.0, 0.0]);
    let _ = writeln!(
        s,
        r#"<path d="M{} {} H{} M{} {} V{}" stroke="{C_GRID}"/>"#,
        n2(left),
        n2(cy),
        n2(left + CELL),
        n2(cx),
        n2(top + 18.0),
        n2(top + 18.0 + CELL)
    );
    if let Some(c) = plot.random_covariance_m2.get(i) {
        draw_ellipse(s, &f, [0.0, 0.0], c, axes, C_RANDOM);
    }
    if let Some(c) = plot.plan_covariance_m2.get(i) {
        draw_ellipse(s, &f, [0.0, 0.0], c, axes, C_PLAN);
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="11" fill="{C_TEXT}">A{} {}-{} (+-{} m)</text>"#,
        n2(left),
        n2(top + 12.0),
        i + 1,
        axis[axes[0]],
        axis[axes[1]],
        fmt_half(half_m)
    );
}

fn fmt_half(x: f64) -> String {
    if x >= 1.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.2}")
    }
}

/// The largest 1-sigma extent over the ellipses, metres (the zoom of the anchor cells).
fn ellipse_extent(plot: &PlanPlot) -> f64 {
    plot.plan_covariance_m2
        .iter()
        .chain(&plot.random_covariance_m2)
        .flat_map(|c| (0..3).map(move |k| c[k][k]))
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold(0.0f64, f64::max)
        .sqrt()
}

/// The SVG text of the figure (module docs).
pub fn plan_plot_svg(plot: &PlanPlot) -> String {
    let cells_top = TOP_H + 40.0;
    // Four anchors a row (two cells each), as many rows as the robot needs.
    let rows = plot.anchors_m.len().div_ceil(ANCHORS_PER_ROW).max(1);
    let cells_bottom = cells_top + (rows - 1) as f64 * ROW_PITCH;
    let height = cells_bottom + CELL + 50.0 + 64.0 + 76.0 + 14.0 * plot.caption.lines().count() as f64;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{}" viewBox="0 0 {WIDTH} {}" font-family="{FONT}" font-size="12">"#,
        n2(height),
        n2(height)
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="20" y="26" font-size="16" font-weight="bold" fill="{C_TEXT}">{}</text>"#,
        esc(&plot.title)
    );
    overview(&mut s, plot, [0, 1], 20.0, 36.0, 580.0, "top view");
    overview(&mut s, plot, [0, 2], 600.0, 36.0, 580.0, "side view");
    let half = 1.15 * ellipse_extent(plot).max(1e-3);
    let _ = writeln!(
        s,
        r#"<text x="20" y="{}" fill="{C_TEXT}">Per-anchor 1-sigma error ellipses of the bound, true scale: <tspan fill="{C_PLAN}" font-weight="bold">plan</tspan> and <tspan fill="{C_RANDOM}" font-weight="bold">random sets of the same size</tspan> (mean covariance)</text>"#,
        n2(cells_top - 8.0)
    );
    for i in 0..plot.anchors_m.len() {
        let column = (i % ANCHORS_PER_ROW) as f64;
        let left = 20.0 + column * 2.0 * (CELL + 12.0) + column * 6.0;
        let top = cells_top + (i / ANCHORS_PER_ROW) as f64 * ROW_PITCH;
        anchor_cell(&mut s, plot, i, [0, 1], left, top, half);
        anchor_cell(&mut s, plot, i, [0, 2], left + CELL + 12.0, top, half);
    }
    let legend_y = cells_bottom + CELL + 50.0;
    let items = [
        (C_CANDIDATE, "candidate poses"),
        (C_PLAN, "chosen poses, numbered in visiting order, and the path"),
        ("#0a8a3a", "first pose"),
        (C_ANCHOR, "anchors; grey box: the frame; dashed: the candidate region"),
    ];
    for (k, (color, text)) in items.iter().enumerate() {
        let y = legend_y + 16.0 * k as f64;
        let _ = writeln!(s, r#"<circle cx="26" cy="{}" r="4" fill="{color}"/>"#, n2(y - 4.0));
        let _ = writeln!(s, r#"<text x="36" y="{}" fill="{C_TEXT}">{}</text>"#, n2(y), esc(text));
    }
    for (k, line) in plot.caption.lines().enumerate() {
        let _ = writeln!(
            s,
            r#"<text x="20" y="{}" font-size="11" fill="{C_MUTED}">{}</text>"#,
            n2(legend_y + 76.0 + 14.0 * k as f64),
            esc(line)
        );
    }
    s.push_str("</svg>\n");
    s
}

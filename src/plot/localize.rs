//! The localised poses of `sagcal localize --plot`: top (x-y) and side (x-z)
//! views of the frame with every localised position, its 1-sigma error
//! ellipse (the marginal of the pose covariance, reading noise and
//! calibration together) and, when the input has them, the logged or prior
//! positions joined to their localised pose by the error vector.
//!
//! Positions span metres while their uncertainty is millimetres, so the
//! ellipses are drawn magnified by a stated power of ten (the legend gives
//! it); the error vectors are drawn true to scale. Anchors outside a view
//! are drawn as labelled markers on its edge, in their direction. Flagged
//! rows are red. Non-finite values are left out, never drawn.
//!
//! Ellipses carry `data-row`, `data-semi-axes-m` (true size, metres) and
//! `data-view`, so tests can read the geometry back.
//!
//! ```
//! use sagcal::plot::localize::{localize_plot_svg, LocalizePlot, PlottedPose};
//! let plot = LocalizePlot {
//!     title: "Localised poses".into(),
//!     caption: "sagcal localize".into(),
//!     anchors_m: vec![[-5.0, -2.0, 20.0], [5.0, -2.0, 20.0], [5.0, 2.0, 20.0], [-5.0, 2.0, 20.0]],
//!     sigma_source: "reading noise".into(),
//!     reference_label: "logged".into(),
//!     poses: vec![PlottedPose {
//!         row: 2,
//!         position_m: [0.1, 0.2, 10.0],
//!         covariance_m2: Some([[1e-6, 0.0, 0.0], [0.0, 4e-6, 0.0], [0.0, 0.0, 1e-6]]),
//!         reference_m: Some([0.1, 0.21, 10.0]),
//!         flagged: false,
//!     }],
//! };
//! let svg = localize_plot_svg(&plot);
//! assert!(svg.contains("data-semi-axes-m"));
//! ```

use std::fmt::Write as _;

use super::anchors::{decimals_for, nice_step_below, sigma_ellipse, tick_label};
use super::svg::{esc, halo_text, n2, C_FRAME, C_GRID, C_MUTED, C_TEXT, FONT};

/// One localised row.
#[derive(Debug, Clone, PartialEq)]
pub struct PlottedPose {
    /// The row, counted from 1 in the input (`DataRow::row`).
    pub row: usize,
    /// Localised position, world frame, metres.
    pub position_m: [f64; 3],
    /// Its 3x3 covariance, m^2 (no ellipse when absent or not positive definite).
    pub covariance_m2: Option<[[f64; 3]; 3]>,
    /// The input's pose (logged or prior), metres.
    pub reference_m: Option<[f64; 3]>,
    /// Whether the row failed its consistency or stability check.
    pub flagged: bool,
}

/// Everything [`localize_plot_svg`] draws.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalizePlot {
    /// Title at the top.
    pub title: String,
    /// Free text at the bottom (command, robot, data).
    pub caption: String,
    /// The robot's anchors, world frame, metres, in cable order (any number).
    pub anchors_m: Vec<[f64; 3]>,
    /// What the ellipses' covariance holds, as the legend says it:
    /// `reading noise and calibration` or `reading noise`.
    pub sigma_source: String,
    /// What the references are: `logged` or `prior`.
    pub reference_label: String,
    /// The localised rows.
    pub poses: Vec<PlottedPose>,
}

const WIDTH: f64 = 1200.0;
const PANEL: f64 = 500.0;
const LEFT: [f64; 2] = [80.0, 680.0];
const TOP: f64 = 70.0;
const HEIGHT: f64 = 700.0;
const C_POSE: &str = "#1f5fbf";
const C_REFERENCE: &str = "#1a9a2a";
const C_FLAG: &str = "#d62728";
const C_ANCHOR: &str = "#7a4fa0";

/// One square panel: data axes `(a, b)` of the world (0 = x, 1 = y, 2 = z).
struct View {
    axes: [usize; 2],
    left: f64,
    centre: [f64; 2],
    half_extent_m: f64,
}

impl View {
    fn scale(&self) -> f64 {
        0.5 * PANEL / self.half_extent_m
    }
    fn px(&self, p: &[f64; 3]) -> [f64; 2] {
        let s = self.scale();
        [
            self.left + 0.5 * PANEL + (p[self.axes[0]] - self.centre[0]) * s,
            TOP + 0.5 * PANEL - (p[self.axes[1]] - self.centre[1]) * s,
        ]
    }
    fn inside(&self, q: [f64; 2]) -> bool {
        q[0] >= self.left && q[0] <= self.left + PANEL && q[1] >= TOP && q[1] <= TOP + PANEL
    }
}

/// Render `plot` as a standalone SVG document (1200 x 700 px).
pub fn localize_plot_svg(plot: &LocalizePlot) -> String {
    let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
    let points: Vec<[f64; 3]> = plot
        .poses
        .iter()
        .flat_map(|p| std::iter::once(p.position_m).chain(p.reference_m))
        .filter(finite)
        .collect();
    let views: Vec<View> = [[0, 1], [0, 2]]
        .iter()
        .enumerate()
        .map(|(k, axes)| view_over(&points, *axes, LEFT[k]))
        .collect();
    let magnification = ellipse_magnification(&plot.poses, &views);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="{FONT}" font-size="13">
<rect width="100%" height="100%" fill="white"/>"#
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="30" text-anchor="middle" fill="{C_TEXT}" font-size="17" font-weight="bold">{}</text>"#,
        n2(WIDTH / 2.0),
        esc(&plot.title)
    );
    for (k, (view, name)) in views.iter().zip(["top view (x-y)", "side view (x-z)"]).enumerate() {
        draw_panel(&mut s, view, name);
        let _ = writeln!(
            s,
            r#"<clipPath id="panel{k}"><rect x="{}" y="{TOP}" width="{PANEL}" height="{PANEL}"/></clipPath><g clip-path="url(#panel{k})">"#,
            n2(view.left)
        );
        draw_poses(&mut s, view, plot, magnification);
        s.push_str("</g>\n");
        draw_anchors(&mut s, view, &plot.anchors_m);
    }
    draw_legend(&mut s, plot, magnification);
    let _ = writeln!(
        s,
        r#"<text x="20" y="{}" fill="{C_MUTED}" font-size="11">{}</text>"#,
        n2(HEIGHT - 12.0),
        esc(&plot.caption)
    );
    s.push_str("</svg>\n");
    s
}

/// A square view over `points` with an 8 % margin (at least 0.5 m across).
fn view_over(points: &[[f64; 3]], axes: [usize; 2], left: f64) -> View {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[axes[k]]);
            hi[k] = hi[k].max(p[axes[k]]);
        }
    }
    if points.is_empty() {
        (lo, hi) = ([-1.0; 2], [1.0; 2]);
    }
    let half = (0..2).map(|k| 0.5 * (hi[k] - lo[k])).fold(0.25, f64::max) * 1.08;
    View {
        axes,
        left,
        centre: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
        half_extent_m: half,
    }
}

/// The magnification of the ellipses: the largest power of ten that keeps
/// the median major semi-axis (top view) at most 8 px and the largest one
/// (either view) at most 30 px; 1 when they are visible at true size.
fn ellipse_magnification(poses: &[PlottedPose], views: &[View]) -> f64 {
    let majors = |view: &View| -> Vec<f64> {
        let [a, b] = view.axes;
        let mut m: Vec<f64> = poses
            .iter()
            .filter_map(|p| p.covariance_m2)
            .filter_map(|c| sigma_ellipse(c[a][a], c[a][b], c[b][b]))
            .map(|e| e.major * view.scale())
            .collect();
        m.sort_by(f64::total_cmp);
        m
    };
    let top = majors(&views[0]);
    let largest = views
        .iter()
        .filter_map(|v| majors(v).last().copied())
        .fold(0.0, f64::max);
    let Some(&median) = top.get(top.len() / 2) else {
        return 1.0;
    };
    if median >= 4.0 || median.is_nan() || median <= 0.0 {
        return 1.0;
    }
    let limit = (8.0 / median).min(30.0 / largest);
    10f64.powf(limit.log10().floor()).clamp(1.0, 1e9)
}

fn draw_panel(s: &mut String, view: &View, name: &str) {
    let axis = ["x", "y", "z"];
    let _ = writeln!(
        s,
        r#"<g class="panel" data-view="{}{}"><rect x="{}" y="{TOP}" width="{PANEL}" height="{PANEL}" fill="white" stroke="{C_FRAME}"/>"#,
        axis[view.axes[0]],
        axis[view.axes[1]],
        n2(view.left)
    );
    let step = nice_step_below(2.0 * view.half_extent_m / 5.0);
    let decimals = decimals_for(step);
    for k in 0..2 {
        let lo = view.centre[k] - view.half_extent_m;
        let first = (lo / step).ceil() as i64;
        for i in first..=first + 12 {
            let v = i as f64 * step;
            if v > view.centre[k] + view.half_extent_m {
                break;
            }
            let mut p = [0.0; 3];
            p[view.axes[k]] = v;
            p[view.axes[1 - k]] = view.centre[1 - k];
            let q = view.px(&p);
            let label = tick_label(i, step, decimals);
            if k == 0 {
                let _ = writeln!(
                    s,
                    r#"<line x1="{0}" y1="{TOP}" x2="{0}" y2="{1}" stroke="{C_GRID}"/><text x="{0}" y="{2}" text-anchor="middle" fill="{C_MUTED}" font-size="11">{3}</text>"#,
                    n2(q[0]),
                    n2(TOP + PANEL),
                    n2(TOP + PANEL + 15.0),
                    label
                );
            } else {
                let _ = writeln!(
                    s,
                    r#"<line x1="{0}" y1="{1}" x2="{2}" y2="{1}" stroke="{C_GRID}"/><text x="{3}" y="{4}" text-anchor="end" fill="{C_MUTED}" font-size="11">{5}</text>"#,
                    n2(view.left),
                    n2(q[1]),
                    n2(view.left + PANEL),
                    n2(view.left - 5.0),
                    n2(q[1] + 4.0),
                    label
                );
            }
        }
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle" fill="{C_TEXT}">{name}: {} (m) across, {} (m) up</text></g>"#,
        n2(view.left + 0.5 * PANEL),
        n2(TOP - 10.0),
        axis[view.axes[0]],
        axis[view.axes[1]]
    );
}

/// Anchors inside the view as triangles; outside it, a marker on the edge
/// along the direction from the view's centre.
fn draw_anchors(s: &mut String, view: &View, anchors: &[[f64; 3]]) {
    let c = [view.left + 0.5 * PANEL, TOP + 0.5 * PANEL];
    // Markers that land within 12 px of each other (anchors one behind the
    // other in this view) share one marker and one label, e.g. "A1, A4".
    let mut markers: Vec<([f64; 2], bool, Vec<usize>)> = Vec::new();
    for (i, a) in anchors.iter().enumerate() {
        let q = view.px(a);
        if !(q[0].is_finite() && q[1].is_finite()) {
            continue;
        }
        let (d, inside) = ([q[0] - c[0], q[1] - c[1]], view.inside(q));
        let t = if inside {
            1.0
        } else {
            (0.5 * PANEL - 8.0) / d[0].abs().max(d[1].abs())
        };
        let m = [c[0] + t * d[0], c[1] + t * d[1]];
        match markers
            .iter_mut()
            .find(|(p, _, _)| (p[0] - m[0]).hypot(p[1] - m[1]) < 12.0)
        {
            Some(marker) => marker.2.push(i),
            None => markers.push((m, inside, vec![i])),
        }
    }
    for (m, inside, cables) in markers {
        let _ = writeln!(
            s,
            r#"<path d="M{} {}l-6 10h12z" fill="{}" stroke="{C_ANCHOR}"/>"#,
            n2(m[0]),
            n2(m[1] - 6.0),
            if inside { C_ANCHOR } else { "white" }
        );
        let label: Vec<String> = cables.iter().map(|i| format!("A{}", i + 1)).collect();
        let anchor = if m[0] > c[0] { "end" } else { "start" };
        let dx = if m[0] > c[0] { -9.0 } else { 9.0 };
        halo_text(s, m[0] + dx, m[1] + 4.0, anchor, C_ANCHOR, &label.join(", "));
    }
}

fn draw_poses(s: &mut String, view: &View, plot: &LocalizePlot, magnification: f64) {
    let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
    let [a, b] = view.axes;
    let path: Vec<String> = plot
        .poses
        .iter()
        .filter(|p| finite(&p.position_m))
        .map(|p| {
            let q = view.px(&p.position_m);
            format!("{} {}", n2(q[0]), n2(q[1]))
        })
        .collect();
    if path.len() > 1 {
        let _ = writeln!(
            s,
            r#"<path d="M{}" fill="none" stroke="{C_GRID}" stroke-width="1"/>"#,
            path.join(" L")
        );
    }
    for p in plot.poses.iter().filter(|p| finite(&p.position_m)) {
        let q = view.px(&p.position_m);
        if let Some(r) = p.reference_m.filter(finite) {
            let e = view.px(&r);
            let _ = writeln!(
                s,
                r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{C_REFERENCE}" stroke-width="1"/><path d="M{} {}m-4 -4l8 8m0 -8l-8 8" stroke="{C_REFERENCE}" stroke-width="1.5"/>"#,
                n2(q[0]),
                n2(q[1]),
                n2(e[0]),
                n2(e[1]),
                n2(e[0]),
                n2(e[1])
            );
        }
        let colour = if p.flagged { C_FLAG } else { C_POSE };
        if let Some(e) = p.covariance_m2.and_then(|c| sigma_ellipse(c[a][a], c[a][b], c[b][b])) {
            let k = magnification * view.scale();
            let _ = writeln!(
                s,
                r#"<ellipse class="sigma" data-row="{}" data-view="{}" data-semi-axes-m="{:e} {:e}" cx="{}" cy="{}" rx="{}" ry="{}" transform="rotate({} {} {})" fill="{colour}" fill-opacity="0.15" stroke="{colour}" stroke-width="1"/>"#,
                p.row,
                ["x", "y", "z"][a].to_owned() + ["x", "y", "z"][b],
                e.major,
                e.minor,
                n2(q[0]),
                n2(q[1]),
                n2(e.major * k),
                n2(e.minor * k),
                n2(-e.angle_deg),
                n2(q[0]),
                n2(q[1])
            );
        }
        let _ = writeln!(
            s,
            r#"<circle cx="{}" cy="{}" r="2.5" fill="{colour}"><title>row {}</title></circle>"#,
            n2(q[0]),
            n2(q[1]),
            p.row
        );
    }
}

fn draw_legend(s: &mut String, plot: &LocalizePlot, magnification: f64) {
    let y = TOP + PANEL + 50.0;
    let flagged = plot.poses.iter().filter(|p| p.flagged).count();
    let references = plot.poses.iter().filter(|p| p.reference_m.is_some()).count();
    let _ = writeln!(
        s,
        r#"<circle cx="90" cy="{0}" r="4" fill="{C_POSE}"/><text x="100" y="{1}" fill="{C_TEXT}">localised ({2} rows; {3} flagged, red)</text>"#,
        n2(y),
        n2(y + 4.0),
        plot.poses.len(),
        flagged
    );
    let magnified = if magnification > 1.0 {
        format!("1-sigma ellipses drawn x{magnification:.0} ({})", plot.sigma_source)
    } else {
        format!("1-sigma ellipses, true size ({})", plot.sigma_source)
    };
    let _ = writeln!(
        s,
        r#"<ellipse cx="390" cy="{0}" rx="10" ry="5" fill="{C_POSE}" fill-opacity="0.15" stroke="{C_POSE}"/><text x="405" y="{1}" fill="{C_TEXT}">{2}</text>"#,
        n2(y),
        n2(y + 4.0),
        esc(&magnified)
    );
    if references > 0 {
        let _ = writeln!(
            s,
            r#"<path d="M86 {0}m0 0l8 8m0 -8l-8 8" stroke="{C_REFERENCE}" stroke-width="1.5"/><text x="100" y="{1}" fill="{C_TEXT}">{2} position ({3} rows), joined to its localised pose, true scale</text>"#,
            n2(y + 16.0),
            n2(y + 24.0),
            esc(&plot.reference_label),
            references
        );
    }
    let _ = writeln!(
        s,
        r#"<path d="M86 {0}l-6 10h12z" fill="{C_ANCHOR}"/><text x="100" y="{1}" fill="{C_TEXT}">anchor (hollow on the panel edge: outside the view, in its direction)</text>"#,
        n2(y + 36.0),
        n2(y + 46.0)
    );
}

//! Dependency-free SVG plot of a calibration's anchor estimates.
//!
//! The anchors of a large cable robot are hundreds of metres apart while the
//! calibration errors are centimetres to metres, so one plot of the whole robot
//! would hide everything. [`anchor_plot_svg`] therefore draws
//!
//! * a small overview (top view, x-y) of the nominal anchors and of the
//!   measured platform positions, to orient the reader;
//! * per anchor, two zoomed panels, a top view (x-y) and a side view (x-z),
//!   centred on the truth (or on the estimate when there is no truth), each
//!   with its own metric scale, showing the initial guess (red star, or an arrow
//!   at the panel edge when it is off-panel), the estimate (blue dot) with its
//!   1-sigma and 3-sigma error ellipses and the truth (green cross);
//! * a title, a legend, a summary table and a caption line.
//!
//! Non-finite inputs and covariances that are not positive definite never
//! panic and never produce invalid SVG: the affected marker or ellipse is left
//! out and the text says `n/a`.
//!
//! The ellipse elements carry machine-readable attributes so that tests and
//! tools can read the geometry back: `data-semi-axes-m="major minor"` (metres),
//! `data-angle-deg` (angle of the major axis in the view's data frame,
//! counter-clockwise from the horizontal axis, in `(-90, 90]`) and
//! `data-sigma` (`1` or `3`). Each zoomed panel is a `<g class="panel">` with
//! `data-view` (`xy` or `xz`), `data-anchor` and `data-scale-px-per-m`.
//!
//! ```
//! use sagcal::plot::anchors::{anchor_plot_svg, AnchorPlot, AnchorPlotEntry};
//! let plot = AnchorPlot {
//!     title: "Anchor calibration".into(),
//!     caption: "sagcal calibrate --seed 1".into(),
//!     anchors: vec![AnchorPlotEntry {
//!         label: "A1".into(),
//!         nominal_m: [-125.0, -110.0, 48.0],
//!         initial_m: None,
//!         estimate_m: [-124.8, -110.1, 48.2],
//!         covariance_m2: Some([[0.04, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.02]]),
//!         truth_m: Some([-125.0, -110.0, 48.0]),
//!     }],
//!     platform_positions_m: vec![[0.0, 0.0, 10.0]],
//! };
//! let svg = anchor_plot_svg(&plot);
//! assert!(svg.starts_with("<?xml") && svg.trim_end().ends_with("</svg>"));
//! ```

use std::fmt::Write as _;

use super::svg::{caption_text, esc, halo_text, n2, shorten, text_w, wrap, C_FRAME, C_GRID, C_MUTED, C_TEXT, FONT};

/// One anchor (pulley) to draw: its nominal, initial, estimated and true position.
#[derive(Debug, Clone, PartialEq)]
pub struct AnchorPlotEntry {
    /// Name shown in the plot, e.g. `"A1"`.
    pub label: String,
    /// Nominal position from the robot description, metres; drawn in the overview,
    /// and in the zoomed panels when there is no `initial_m`.
    pub nominal_m: [f64; 3],
    /// Initial guess the calibration started from, metres, if different from the nominal.
    pub initial_m: Option<[f64; 3]>,
    /// Calibrated position, metres.
    pub estimate_m: [f64; 3],
    /// 3x3 covariance of the estimate [m^2]; the error ellipses are drawn from
    /// its 2x2 blocks. Ignored (`covariance n/a`) when not finite, symmetric
    /// positive definite.
    pub covariance_m2: Option<[[f64; 3]; 3]>,
    /// True position, metres, when known (simulation).
    pub truth_m: Option<[f64; 3]>,
}

/// Everything [`anchor_plot_svg`] draws.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AnchorPlot {
    /// Title at the top of the figure.
    pub title: String,
    /// Free text at the bottom, e.g. the command line and the seed.
    pub caption: String,
    /// The anchors, each drawn in its own pair of zoomed panels.
    pub anchors: Vec<AnchorPlotEntry>,
    /// Measured platform positions, metres, drawn as small dots in the overview.
    pub platform_positions_m: Vec<[f64; 3]>,
}

// ---------------------------------------------------------------------------
// Style and layout constants (pixels).

const WIDTH: f64 = 1200.0;
const MARGIN: f64 = 20.0;
const TITLE_H: f64 = 46.0;
const STRIP_MIN_H: f64 = 222.0;
const CELL_W: f64 = 570.0;
const CELL_GAP: f64 = 20.0;
const ROW_PITCH: f64 = 300.0;
const PANEL: f64 = 210.0;
const PANEL_LEFT: f64 = 62.0;
const PANEL_GAP: f64 = 88.0;
const PANEL_TOP: f64 = 46.0;
const CAPTION_H: f64 = 30.0;
const MAX_PLATFORM_DOTS: usize = 3000;
const LINE_H: f64 = 14.0;

const C_AXIS: &str = "#c4c4c4";
const C_INITIAL: &str = "#d62728";
const C_ESTIMATE: &str = "#1f5fbf";
const C_TRUTH: &str = "#1a9a2a";
const C_PLATFORM: &str = "#8c8c8c";

/// Render `plot` as a standalone SVG document (about 1200 x 900 px for four anchors).
///
/// Never panics: non-finite positions are left out, a covariance that is not
/// finite, symmetric positive definite gives no ellipses and the text
/// `covariance n/a`, and all text is escaped for XML.
pub fn anchor_plot_svg(plot: &AnchorPlot) -> String {
    let n = plot.anchors.len();
    let rows = n.div_ceil(2).max(1);
    let strip_h = STRIP_MIN_H.max(44.0 + 20.0 * n as f64);
    let cells_top = TITLE_H + strip_h + 8.0;
    // The caption wraps to the figure's width; the title is cut to one line.
    let caption = wrap(&plot.caption, WIDTH - 2.0 * MARGIN, 12.0);
    let title = shorten(&plot.title, ((WIDTH - 2.0 * MARGIN) / (0.62 * 20.0)) as usize);
    let caption_extra = 16.0 * (caption.len() - 1) as f64;
    let height = (cells_top + rows as f64 * ROW_PITCH + CAPTION_H + caption_extra).round();

    let mut s = String::with_capacity(64 * 1024);
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="{FONT}" font-size="12" fill="{C_TEXT}">"#,
        w = WIDTH,
        h = height
    );
    let _ = writeln!(s, "<title>{}</title>", esc(&plot.title));
    let _ = writeln!(
        s,
        r#"<rect x="0" y="0" width="{WIDTH}" height="{height}" fill="white" stroke="none"/>"#
    );

    // Title.
    let _ = writeln!(
        s,
        r#"<text class="title" x="{MARGIN}" y="30" font-size="20" font-weight="bold">{}</text>"#,
        esc(&title)
    );

    // Top strip: overview, legend, summary table.
    let strip_top = TITLE_H;
    render_overview(&mut s, plot, MARGIN, strip_top, 380.0, strip_h);
    render_legend(&mut s, 418.0, strip_top);
    render_table(&mut s, plot, 712.0, strip_top);

    // Zoomed panels.
    if plot.anchors.is_empty() {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" font-size="14" fill="{C_MUTED}">no anchors to show</text>"#,
            MARGIN,
            n2(cells_top + 30.0)
        );
    }
    for (i, entry) in plot.anchors.iter().enumerate() {
        let x = MARGIN + (i % 2) as f64 * (CELL_W + CELL_GAP);
        let y = cells_top + (i / 2) as f64 * ROW_PITCH;
        render_anchor_cell(&mut s, i, entry, x, y);
    }

    // Caption.
    caption_text(&mut s, MARGIN, height, &caption);
    s.push_str("</svg>\n");
    s
}

// ---------------------------------------------------------------------------
// Geometry helpers.

/// 1-sigma ellipse of a 2x2 covariance: semi-axes [m] and major-axis angle
/// [deg, counter-clockwise from the first axis, in (-90, 90]].
#[derive(Debug, Clone, Copy)]
pub(super) struct SigmaEllipse {
    pub(super) major: f64,
    pub(super) minor: f64,
    pub(super) angle_deg: f64,
}

/// Closed-form eigen-decomposition of the symmetric matrix [[a, b], [b, d]].
/// `None` unless finite and positive definite.
pub(super) fn sigma_ellipse(a: f64, b: f64, d: f64) -> Option<SigmaEllipse> {
    if !(a.is_finite() && b.is_finite() && d.is_finite()) {
        return None;
    }
    let mean = 0.5 * (a + d);
    let half_diff = (0.5 * (a - d)).hypot(b);
    let l1 = mean + half_diff;
    if !(l1 > 0.0 && l1.is_finite()) {
        return None;
    }
    let l2 = (a * d - b * b) / l1;
    if !(l2 > 0.0 && l2.is_finite()) {
        return None;
    }
    let angle_deg = 0.5 * (2.0 * b).atan2(a - d).to_degrees();
    Some(SigmaEllipse {
        major: l1.sqrt(),
        minor: l2.sqrt(),
        angle_deg,
    })
}

/// The covariance, symmetrised, if it is finite and positive definite (Cholesky test).
fn valid_covariance(c: &Option<[[f64; 3]; 3]>) -> Option<[[f64; 3]; 3]> {
    let c = (*c)?;
    if !c.iter().flatten().all(|v| v.is_finite()) {
        return None;
    }
    let mut m = c;
    for i in 0..3 {
        for j in (i + 1)..3 {
            let v = 0.5 * (c[i][j] + c[j][i]);
            m[i][j] = v;
            m[j][i] = v;
        }
    }
    let d0 = m[0][0];
    if !(d0 > 0.0 && d0.is_finite()) {
        return None;
    }
    let l10 = m[1][0] / d0.sqrt();
    let l20 = m[2][0] / d0.sqrt();
    let d1 = m[1][1] - l10 * l10;
    if !(d1 > 0.0 && d1.is_finite()) {
        return None;
    }
    let l21 = (m[2][1] - l20 * l10) / d1.sqrt();
    let d2 = m[2][2] - l20 * l20 - l21 * l21;
    if !(d2 > 0.0 && d2.is_finite()) {
        return None;
    }
    Some(m)
}

fn finite2(p: [f64; 2]) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

fn finite3(p: &[f64; 3]) -> bool {
    p.iter().all(|v| v.is_finite())
}

/// Largest of 1, 2, 5 x 10^k not above `raw` (or 1 for nonsense input).
pub(super) fn nice_step_below(raw: f64) -> f64 {
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let base = 10f64.powf(raw.log10().floor());
    let f = raw / base;
    let m = if f >= 5.0 {
        5.0
    } else if f >= 2.0 {
        2.0
    } else {
        1.0
    };
    m * base
}

/// Decimals needed to print multiples of `step`.
pub(super) fn decimals_for(step: f64) -> usize {
    if !(step.is_finite() && step > 0.0) {
        return 0;
    }
    (-(step.log10() + 1e-9).floor()).clamp(0.0, 9.0) as usize
}

/// Tick value `i * step` as text, with a typographic minus sign.
pub(super) fn tick_label(i: i64, step: f64, decimals: usize) -> String {
    if i == 0 {
        return "0".to_owned();
    }
    let v = i as f64 * step;
    let t = format!("{v:.decimals$}");
    match t.strip_prefix('-') {
        Some(rest) => format!("\u{2212}{rest}"),
        None => t,
    }
}

/// A length with three significant digits, or `n/a`.
fn fmt_len(x: f64) -> String {
    fmt_sig(x, 3)
}

/// `x` with `sig` significant digits (no exponent), or `n/a`.
fn fmt_sig(x: f64, sig: i32) -> String {
    if !x.is_finite() {
        return "n/a".to_owned();
    }
    let ax = x.abs();
    let dec = if ax == 0.0 {
        sig as usize
    } else {
        (f64::from(sig - 1) - ax.log10().floor()).clamp(0.0, 6.0) as usize
    };
    format!("{x:.dec$}")
}

// ---------------------------------------------------------------------------
// Markers.

fn star_points(cx: f64, cy: f64, r: f64) -> String {
    let mut pts = String::new();
    for k in 0..10 {
        let rr = if k % 2 == 0 { r } else { 0.45 * r };
        let a = (-90.0 + 36.0 * k as f64).to_radians();
        let _ = write!(pts, "{},{} ", n2(cx + rr * a.cos()), n2(cy + rr * a.sin()));
    }
    pts.trim_end().to_owned()
}

fn star(s: &mut String, cx: f64, cy: f64, r: f64) {
    let _ = writeln!(
        s,
        r#"<polygon class="initial" points="{}" fill="{C_INITIAL}" stroke="white" stroke-width="0.8"/>"#,
        star_points(cx, cy, r)
    );
}

fn cross(s: &mut String, cx: f64, cy: f64, r: f64) {
    let _ = writeln!(
        s,
        r#"<path class="truth" d="M{} {} L{} {} M{} {} L{} {}" stroke="{C_TRUTH}" stroke-width="2.2" stroke-linecap="round" fill="none"/>"#,
        n2(cx - r),
        n2(cy - r),
        n2(cx + r),
        n2(cy + r),
        n2(cx - r),
        n2(cy + r),
        n2(cx + r),
        n2(cy - r)
    );
}

fn dot(s: &mut String, cx: f64, cy: f64, r: f64) {
    let _ = writeln!(
        s,
        r#"<circle class="estimate" cx="{}" cy="{}" r="{}" fill="{C_ESTIMATE}" stroke="white" stroke-width="1"/>"#,
        n2(cx),
        n2(cy),
        n2(r)
    );
}

/// Arrow from `(x0, y0)` to the tip `(x1, y1)`.
fn arrow(s: &mut String, x0: f64, y0: f64, x1: f64, y1: f64, color: &str) {
    let (dx, dy) = (x1 - x0, y1 - y0);
    let len = dx.hypot(dy);
    if !(len > 1e-9 && len.is_finite()) {
        return;
    }
    let (ux, uy) = (dx / len, dy / len);
    let (nx, ny) = (-uy, ux);
    let (bx, by) = (x1 - 9.0 * ux, y1 - 9.0 * uy);
    let _ = writeln!(
        s,
        r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{color}" stroke-width="1.6"/>"#,
        n2(x0),
        n2(y0),
        n2(x1 - 6.0 * ux),
        n2(y1 - 6.0 * uy)
    );
    let _ = writeln!(
        s,
        r#"<polygon points="{},{} {},{} {},{}" fill="{color}" stroke="none"/>"#,
        n2(x1),
        n2(y1),
        n2(bx + 4.5 * nx),
        n2(by + 4.5 * ny),
        n2(bx - 4.5 * nx),
        n2(by - 4.5 * ny)
    );
}

// ---------------------------------------------------------------------------
// Overview, legend, table.

/// The overview's plot box and its metres-to-pixels map (top view).
#[derive(Debug, Clone, Copy)]
struct OverviewFrame {
    bx: f64,
    by: f64,
    bw: f64,
    bh: f64,
    scale: f64,
    /// Data centre, metres.
    cxm: f64,
    cym: f64,
    /// Half the data range shown, metres.
    half_w: f64,
    half_h: f64,
}

impl OverviewFrame {
    /// The pixel column of `x`, metres.
    fn px(&self, x: f64) -> f64 {
        self.bx + 0.5 * self.bw + (x - self.cxm) * self.scale
    }

    /// The pixel row of `y`, metres.
    fn py(&self, y: f64) -> f64 {
        self.by + 0.5 * self.bh - (y - self.cym) * self.scale
    }
}

fn render_overview(s: &mut String, plot: &AnchorPlot, left: f64, top: f64, width: f64, height: f64) {
    let _ = writeln!(s, r#"<g class="overview">"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="13" font-weight="bold">Overview: top view (x-y)</text>"#,
        n2(left),
        n2(top + 14.0)
    );
    let anchors: Vec<[f64; 2]> = plot
        .anchors
        .iter()
        .map(|a| [a.nominal_m[0], a.nominal_m[1]])
        .filter(|p| finite2(*p))
        .collect();
    let stride = plot.platform_positions_m.len().div_ceil(MAX_PLATFORM_DOTS).max(1);
    let platform: Vec<[f64; 2]> = plot
        .platform_positions_m
        .iter()
        .step_by(stride)
        .map(|p| [p[0], p[1]])
        .filter(|p| finite2(*p))
        .collect();
    // Plot box.
    let boxed = (left + 50.0, top + 26.0, width - 60.0, height - 26.0 - 40.0);
    let Some(f) = overview_frame(boxed, &anchors, &platform) else {
        let _ = writeln!(s, "</g>");
        return;
    };
    overview_grid(s, &f);
    overview_points(s, &f, &anchors, &platform);
    overview_anchors(s, &f, plot, &anchors);
    let _ = writeln!(s, "</g>");
}

/// The box `(x, y, width, height)` fitted to the points with a 10 % margin,
/// at least 1 m across; `None` if no finite scale results.
fn overview_frame(
    (bx, by, bw, bh): (f64, f64, f64, f64),
    anchors: &[[f64; 2]],
    platform: &[[f64; 2]],
) -> Option<OverviewFrame> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in anchors.iter().chain(platform.iter()) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !(lo[0].is_finite() && hi[0].is_finite() && lo[1].is_finite() && hi[1].is_finite()) {
        lo = [-1.0, -1.0];
        hi = [1.0, 1.0];
    }
    // At least 1 m (or a relative 1e-6 of the coordinates) so that ticks stay readable.
    let magnitude = lo[0].abs().max(hi[0].abs()).max(lo[1].abs()).max(hi[1].abs());
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0).max(1e-6 * magnitude);
    let pad = 0.1 * span;
    let (x0, x1) = (lo[0] - pad, hi[0] + pad);
    let (y0, y1) = (lo[1] - pad, hi[1] + pad);
    let scale = (bw / (x1 - x0)).min(bh / (y1 - y0));
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    // Centre the data in the box.
    Some(OverviewFrame {
        bx,
        by,
        bw,
        bh,
        scale,
        cxm: 0.5 * (x0 + x1),
        cym: 0.5 * (y0 + y1),
        half_w: 0.5 * bw / scale,
        half_h: 0.5 * bh / scale,
    })
}

/// The overview's box, grid, ticks (absolute metres) and axis names.
fn overview_grid(s: &mut String, f: &OverviewFrame) {
    let (bx, by, bw, bh, scale) = (f.bx, f.by, f.bw, f.bh, f.scale);
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="white" stroke="{C_FRAME}" stroke-width="1"/>"#,
        n2(bx),
        n2(by),
        n2(bw),
        n2(bh)
    );
    let step = nice_step_below(f.half_w.max(f.half_h) / 2.0);
    let dec = decimals_for(step);
    let label_every = (40.0 / (step * scale)).ceil().max(1.0) as i64;
    let mut grid = String::new();
    let mut labels = String::new();
    let ix0 = ((f.cxm - f.half_w) / step).ceil() as i64;
    let ix1 = ((f.cxm + f.half_w) / step).floor() as i64;
    for i in ix0..=ix1.min(ix0 + 200) {
        let x = f.px(i as f64 * step);
        let _ = write!(grid, "M{} {} V{} ", n2(x), n2(by), n2(by + bh));
        if i % label_every == 0 {
            let _ = writeln!(
                labels,
                r#"<text x="{}" y="{}" text-anchor="middle" fill="{C_MUTED}">{}</text>"#,
                n2(x),
                n2(by + bh + 14.0),
                tick_label(i, step, dec)
            );
        }
    }
    let iy0 = ((f.cym - f.half_h) / step).ceil() as i64;
    let iy1 = ((f.cym + f.half_h) / step).floor() as i64;
    let label_every_y = (20.0 / (step * scale)).ceil().max(1.0) as i64;
    for i in iy0..=iy1.min(iy0 + 200) {
        let y = f.py(i as f64 * step);
        let _ = write!(grid, "M{} {} H{} ", n2(bx), n2(y), n2(bx + bw));
        if i % label_every_y == 0 {
            let _ = writeln!(
                labels,
                r#"<text x="{}" y="{}" text-anchor="end" fill="{C_MUTED}">{}</text>"#,
                n2(bx - 5.0),
                n2(y + 4.0),
                tick_label(i, step, dec)
            );
        }
    }
    let _ = writeln!(
        s,
        r#"<path d="{}" stroke="{C_GRID}" stroke-width="1" fill="none"/>"#,
        grid.trim_end()
    );
    s.push_str(&labels);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle" fill="{C_MUTED}">x [m]</text>"#,
        n2(bx + 0.5 * bw),
        n2(by + bh + 30.0)
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle" fill="{C_MUTED}" transform="rotate(-90 {} {})">y [m]</text>"#,
        n2(bx - 40.0),
        n2(by + 0.5 * bh),
        n2(bx - 40.0),
        n2(by + 0.5 * bh)
    );
}

/// The frame outline through the anchors (in the given order) and the platform positions.
fn overview_points(s: &mut String, f: &OverviewFrame, anchors: &[[f64; 2]], platform: &[[f64; 2]]) {
    if anchors.len() >= 3 {
        let mut d = String::new();
        for (k, p) in anchors.iter().enumerate() {
            let _ = write!(
                d,
                "{}{} {} ",
                if k == 0 { "M" } else { "L" },
                n2(f.px(p[0])),
                n2(f.py(p[1]))
            );
        }
        d.push('Z');
        let _ = writeln!(
            s,
            r#"<path d="{d}" fill="none" stroke="{C_AXIS}" stroke-width="1" stroke-dasharray="4 3"/>"#
        );
    }
    if !platform.is_empty() {
        let _ = writeln!(s, r#"<g class="platform" fill="{C_PLATFORM}" stroke="none">"#);
        for p in platform {
            let _ = writeln!(
                s,
                r#"<circle cx="{}" cy="{}" r="1.6"/>"#,
                n2(f.px(p[0])),
                n2(f.py(p[1]))
            );
        }
        let _ = writeln!(s, "</g>");
    }
}

/// The anchors as stars with labels pushed away from their centroid.
fn overview_anchors(s: &mut String, f: &OverviewFrame, plot: &AnchorPlot, anchors: &[[f64; 2]]) {
    let (mut gx, mut gy, mut cnt) = (0.0, 0.0, 0.0);
    for p in anchors {
        gx += p[0];
        gy += p[1];
        cnt += 1.0;
    }
    if cnt > 0.0 {
        gx /= cnt;
        gy /= cnt;
    }
    for a in &plot.anchors {
        let p = [a.nominal_m[0], a.nominal_m[1]];
        if !finite2(p) {
            continue;
        }
        let (x, y) = (f.px(p[0]), f.py(p[1]));
        star(s, x, y, 6.0);
        let right = p[0] >= gx;
        let up = p[1] >= gy;
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="{}" font-weight="bold">{}</text>"#,
            n2(if right { x + 8.0 } else { x - 8.0 }),
            n2(if up { y - 6.0 } else { y + 15.0 }),
            if right { "start" } else { "end" },
            esc(&shorten(&a.label, 12))
        );
    }
}

fn render_legend(s: &mut String, left: f64, top: f64) {
    let _ = writeln!(s, r#"<g class="legend">"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="13" font-weight="bold">Legend</text>"#,
        n2(left),
        n2(top + 14.0)
    );
    let sx = left + 12.0;
    let tx = left + 32.0;
    let mut y = top + 36.0;
    let line = |s: &mut String, y: f64, text: &str| {
        let _ = writeln!(s, r#"<text x="{}" y="{}">{}</text>"#, n2(tx), n2(y + 4.0), esc(text));
    };
    star(s, sx, y, 6.5);
    line(s, y, "nominal / initial guess");
    y += 20.0;
    arrow(s, sx - 10.0, y, sx + 10.0, y, C_INITIAL);
    line(s, y, "initial guess off-panel");
    y += 20.0;
    dot(s, sx, y, 4.0);
    line(s, y, "estimate");
    y += 20.0;
    let _ = writeln!(
        s,
        r#"<ellipse cx="{}" cy="{}" rx="11" ry="6" fill="{C_ESTIMATE}" fill-opacity="0.14" stroke="{C_ESTIMATE}" stroke-width="1.4"/>"#,
        n2(sx),
        n2(y)
    );
    line(s, y, "1\u{3c3} error ellipse");
    y += 20.0;
    let _ = writeln!(
        s,
        r#"<ellipse cx="{}" cy="{}" rx="11" ry="6" fill="none" stroke="{C_ESTIMATE}" stroke-width="1" stroke-dasharray="4 3"/>"#,
        n2(sx),
        n2(y)
    );
    line(s, y, "3\u{3c3} error ellipse");
    y += 20.0;
    cross(s, sx, y, 5.0);
    line(s, y, "truth");
    y += 20.0;
    let _ = writeln!(
        s,
        r#"<circle cx="{}" cy="{}" r="1.8" fill="{C_PLATFORM}"/>"#,
        n2(sx),
        n2(y)
    );
    line(s, y, "platform positions (overview)");
    y += 24.0;
    for note in [
        "Zoomed panels: centred on the truth (or",
        "estimate), ticks in m from the centre;",
        "arrow labels: distance in the view plane.",
    ] {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" fill="{C_MUTED}">{}</text>"#,
            n2(left),
            n2(y),
            esc(note)
        );
        y += 15.0;
    }
    let _ = writeln!(s, "</g>");
}

fn render_table(s: &mut String, plot: &AnchorPlot, left: f64, top: f64) {
    let _ = writeln!(s, r#"<g class="summary">"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="13" font-weight="bold">Summary (1&#963; from the covariance)</text>"#,
        n2(left),
        n2(top + 14.0)
    );
    // Column right edges (numbers right-aligned), first column left-aligned.
    let cols: [(f64, &str); 6] = [
        (0.0, "anchor"),
        (150.0, "|est \u{2212} truth|"),
        (218.0, "\u{3c3}x"),
        (286.0, "\u{3c3}y"),
        (354.0, "\u{3c3}z"),
        (466.0, "|init \u{2212} est|"),
    ];
    let hy = top + 36.0;
    for (k, (x, name)) in cols.iter().enumerate() {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="{}" font-weight="bold" fill="{C_MUTED}">{}</text>"#,
            n2(left + x),
            n2(hy),
            if k == 0 { "start" } else { "end" },
            esc(name)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="end" fill="{C_MUTED}">all in m</text>"#,
        n2(left + 466.0),
        n2(top + 14.0)
    );
    let _ = writeln!(
        s,
        r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{C_AXIS}" stroke-width="1"/>"#,
        n2(left),
        n2(hy + 6.0),
        n2(left + 466.0),
        n2(hy + 6.0)
    );
    for (i, a) in plot.anchors.iter().enumerate() {
        let y = hy + 22.0 + 20.0 * i as f64;
        let err = error_m(a).map(fmt_len).unwrap_or_else(|| "\u{2013}".to_owned());
        let sig = sigmas(a);
        let init = a.initial_m.unwrap_or(a.nominal_m);
        let off = dist3(&init, &a.estimate_m)
            .map(fmt_len)
            .unwrap_or_else(|| "n/a".to_owned());
        let cells = [
            shorten(&a.label, 16),
            err,
            sig.map(|v| fmt_len(v[0])).unwrap_or_else(|| "n/a".into()),
            sig.map(|v| fmt_len(v[1])).unwrap_or_else(|| "n/a".into()),
            sig.map(|v| fmt_len(v[2])).unwrap_or_else(|| "n/a".into()),
            off,
        ];
        for (k, ((x, _), text)) in cols.iter().zip(cells.iter()).enumerate() {
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" text-anchor="{}"{}>{}</text>"#,
                n2(left + x),
                n2(y),
                if k == 0 { "start" } else { "end" },
                if k == 0 { r#" font-weight="bold""# } else { "" },
                esc(text)
            );
        }
    }
    let _ = writeln!(s, "</g>");
}

fn dist3(a: &[f64; 3], b: &[f64; 3]) -> Option<f64> {
    if !(finite3(a) && finite3(b)) {
        return None;
    }
    let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
    d.is_finite().then_some(d)
}

fn error_m(a: &AnchorPlotEntry) -> Option<f64> {
    dist3(&a.estimate_m, a.truth_m.as_ref()?)
}

fn sigmas(a: &AnchorPlotEntry) -> Option<[f64; 3]> {
    let c = valid_covariance(&a.covariance_m2)?;
    Some([c[0][0].sqrt(), c[1][1].sqrt(), c[2][2].sqrt()])
}

// ---------------------------------------------------------------------------
// Zoomed panels.

#[derive(Debug, Clone, Copy)]
enum View {
    TopXy,
    SideXz,
}

impl View {
    fn axes(self) -> (usize, usize) {
        match self {
            View::TopXy => (0, 1),
            View::SideXz => (0, 2),
        }
    }
    fn id(self) -> &'static str {
        match self {
            View::TopXy => "xy",
            View::SideXz => "xz",
        }
    }
    fn title(self) -> &'static str {
        match self {
            View::TopXy => "top (x-y)",
            View::SideXz => "side (x-z)",
        }
    }
    fn axis_names(self) -> (&'static str, &'static str) {
        match self {
            View::TopXy => ("x", "y"),
            View::SideXz => ("x", "z"),
        }
    }
}

fn render_anchor_cell(s: &mut String, index: usize, a: &AnchorPlotEntry, x: f64, y: f64) {
    let _ = writeln!(s, r#"<g class="anchor" data-anchor="{}">"#, esc(&a.label));
    // Header line: label, error, sigmas.
    let err = match (&a.truth_m, error_m(a)) {
        (None, _) => "truth unknown".to_owned(),
        (Some(_), Some(e)) => format!("error |est \u{2212} truth| = {} m", fmt_len(e)),
        (Some(_), None) => "error n/a".to_owned(),
    };
    let sig = match sigmas(a) {
        Some(v) => format!(
            "1\u{3c3} (x, y, z) = {}, {}, {} m",
            fmt_len(v[0]),
            fmt_len(v[1]),
            fmt_len(v[2])
        ),
        None => "covariance n/a".to_owned(),
    };
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="13"><tspan font-size="15" font-weight="bold">{}</tspan><tspan dx="12">{}</tspan><tspan dx="14" fill="{C_MUTED}">{}</tspan></text>"#,
        n2(x),
        n2(y + 16.0),
        esc(&shorten(&a.label, 20)),
        esc(&err),
        esc(&sig)
    );
    let cov = valid_covariance(&a.covariance_m2);
    for (k, view) in [View::TopXy, View::SideXz].into_iter().enumerate() {
        let left = x + PANEL_LEFT + k as f64 * (PANEL + PANEL_GAP);
        render_panel(s, index, a, cov.as_ref(), view, (left, y + PANEL_TOP, PANEL));
    }
    let _ = writeln!(s, "</g>");
}

/// Where a zoomed panel sits and how it maps metres to pixels.
#[derive(Debug, Clone, Copy)]
struct PanelFrame {
    left: f64,
    top: f64,
    size: f64,
    /// Pixels per metre.
    scale: f64,
    /// The data point at the panel's centre (truth, else estimate), metres.
    centre: [f64; 2],
}

impl PanelFrame {
    /// Half the panel's side, pixels.
    fn half_px(&self) -> f64 {
        0.5 * self.size
    }

    /// The pixel column of the horizontal data coordinate `u`.
    fn px(&self, u: f64) -> f64 {
        self.left + self.half_px() + (u - self.centre[0]) * self.scale
    }

    /// The pixel row of the vertical data coordinate `v`.
    fn py(&self, v: f64) -> f64 {
        self.top + self.half_px() - (v - self.centre[1]) * self.scale
    }
}

/// One zoomed panel of an anchor: what it shows, in the view's plane.
struct PanelContent<'a> {
    index: usize,
    anchor: &'a AnchorPlotEntry,
    cov: Option<&'a [[f64; 3]; 3]>,
    view: View,
    est: [f64; 2],
    est_ok: bool,
    truth: Option<[f64; 2]>,
    ellipse: Option<SigmaEllipse>,
}

/// Grid spacing of a panel: step (m), label decimals, labels every so many steps.
#[derive(Debug, Clone, Copy)]
struct PanelTicks {
    step: f64,
    dec: usize,
    label_every: i64,
}

fn render_panel(
    s: &mut String,
    index: usize,
    a: &AnchorPlotEntry,
    cov: Option<&[[f64; 3]; 3]>,
    view: View,
    (left, top, size): (f64, f64, f64),
) {
    let (iu, iv) = view.axes();
    let proj = |p: &[f64; 3]| [p[iu], p[iv]];
    let est = proj(&a.estimate_m);
    let est_ok = finite2(est);
    let content = PanelContent {
        index,
        anchor: a,
        cov,
        view,
        est,
        est_ok,
        truth: a.truth_m.as_ref().map(proj).filter(|p| finite2(*p)),
        ellipse: cov.and_then(|c| sigma_ellipse(c[iu][iu], c[iu][iv], c[iv][iv])),
    };
    let centre = content.truth.or(if est_ok { Some(est) } else { None });
    let (half_m, scale) = panel_zoom(&content, centre, 0.5 * size);
    let clip_id = panel_header(s, &content, (left, top, size), scale, half_m);
    let Some(c) = centre else {
        frame(s, left, top, size);
        halo_text(
            s,
            left + 0.5 * size,
            top + 0.5 * size + 4.0,
            "middle",
            C_MUTED,
            "no finite position",
        );
        let _ = writeln!(s, "</g>");
        return;
    };
    let f = PanelFrame {
        left,
        top,
        size,
        scale,
        centre: c,
    };
    let ticks = panel_grid(s, &f, half_m);
    let off_panel = panel_data(s, &f, &content, &clip_id);
    frame(s, left, top, size);
    if let Some((dx, dy, dist, init_name)) = off_panel {
        off_panel_arrow(s, &f, (dx, dy), dist, init_name);
    }
    panel_axes(s, &f, view, ticks);
    let _ = writeln!(s, "</g>");
}

/// Zoom: estimate, truth and the 3-sigma ellipse with a margin, at least
/// +-0.05 m: the half range (m) and the scale (px per m).
fn panel_zoom(content: &PanelContent<'_>, centre: Option<[f64; 2]>, half_px: f64) -> (f64, f64) {
    let (iu, iv) = content.view.axes();
    let est = content.est;
    match centre {
        Some(c) => {
            let mut need: f64 = 0.0;
            for p in [Some(est).filter(|p| finite2(*p)), content.truth].into_iter().flatten() {
                need = need.max((p[0] - c[0]).abs()).max((p[1] - c[1]).abs());
            }
            if let (Some(_), Some(cv), true) = (content.ellipse, content.cov, content.est_ok) {
                need = need
                    .max((est[0] - c[0]).abs() + 3.0 * cv[iu][iu].sqrt())
                    .max((est[1] - c[1]).abs() + 3.0 * cv[iv][iv].sqrt());
            }
            let half = (need * 1.18).max(0.05);
            let scale = half_px / half;
            if half.is_finite() && scale.is_finite() && scale > 0.0 {
                (half, scale)
            } else {
                (0.05, half_px / 0.05)
            }
        }
        None => (0.05, half_px / 0.05),
    }
}

/// The panel's group, title, in-plane 1-sigma text, clip path and
/// background; returns the clip path's id.
fn panel_header(
    s: &mut String,
    content: &PanelContent<'_>,
    (left, top, size): (f64, f64, f64),
    scale: f64,
    half_m: f64,
) -> String {
    let view = content.view;
    let _ = writeln!(
        s,
        r#"<g class="panel" data-anchor="{}" data-view="{}" data-scale-px-per-m="{:.6}" data-half-range-m="{:.6}">"#,
        esc(&content.anchor.label),
        view.id(),
        scale,
        half_m
    );
    // Panel title and in-plane 1-sigma axes.
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="13" font-weight="bold">{}</text>"#,
        n2(left),
        n2(top - 7.0),
        view.title()
    );
    let right_text = match (&content.ellipse, &content.cov) {
        (Some(e), _) if e.major < 0.01 => format!(
            "1\u{3c3} {} \u{d7} {} mm",
            fmt_sig(1e3 * e.major, 2),
            fmt_sig(1e3 * e.minor, 2)
        ),
        (Some(e), _) => format!("1\u{3c3} {} \u{d7} {} m", fmt_sig(e.major, 2), fmt_sig(e.minor, 2)),
        (None, Some(_)) => "ellipse n/a".to_owned(),
        (None, None) => "covariance n/a".to_owned(),
    };
    // Only when it fits next to the title (the anchor's header repeats the sigmas).
    if text_w(view.title(), 13.0) + text_w(&right_text, 12.0) + 6.0 <= size {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="end" fill="{C_MUTED}">{}</text>"#,
            n2(left + size),
            n2(top - 7.0),
            esc(&right_text)
        );
    }
    let clip_id = format!("clip-{}-{}", content.index, view.id());
    let _ = writeln!(
        s,
        r#"<defs><clipPath id="{clip_id}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
        n2(left),
        n2(top),
        n2(size),
        n2(size)
    );
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="white" stroke="none"/>"#,
        n2(left),
        n2(top),
        n2(size),
        n2(size)
    );
    clip_id
}

/// Grid, ticks and labels (metres relative to the centre), and the axes through it.
fn panel_grid(s: &mut String, f: &PanelFrame, half_m: f64) -> PanelTicks {
    let (left, top, size, scale) = (f.left, f.top, f.size, f.scale);
    let half_px = f.half_px();
    let step = nice_step_below(half_m / 2.0);
    let dec = decimals_for(step);
    let label_every = (44.0 / (step * scale)).ceil().max(1.0) as i64;
    let nt = ((half_m / step) + 1e-9).floor().min(100.0) as i64;
    let mut grid = String::new();
    let mut labels = String::new();
    for i in -nt..=nt {
        if i == 0 {
            continue;
        }
        let off = i as f64 * step * scale;
        let _ = write!(
            grid,
            "M{} {} V{} M{} {} H{} ",
            n2(left + half_px + off),
            n2(top),
            n2(top + size),
            n2(left),
            n2(top + half_px - off),
            n2(left + size)
        );
    }
    for i in -nt..=nt {
        if i % label_every != 0 {
            continue;
        }
        let off = i as f64 * step * scale;
        let text = tick_label(i, step, dec);
        let _ = writeln!(
            labels,
            r#"<text x="{}" y="{}" text-anchor="middle" fill="{C_MUTED}">{}</text>"#,
            n2(left + half_px + off),
            n2(top + size + 14.0),
            text
        );
        let _ = writeln!(
            labels,
            r#"<text x="{}" y="{}" text-anchor="end" fill="{C_MUTED}">{}</text>"#,
            n2(left - 5.0),
            n2(top + half_px - off + 4.0),
            text
        );
    }
    if !grid.is_empty() {
        let _ = writeln!(
            s,
            r#"<path d="{}" stroke="{C_GRID}" stroke-width="1" fill="none"/>"#,
            grid.trim_end()
        );
    }
    let _ = writeln!(
        s,
        r#"<path d="M{} {} V{} M{} {} H{}" stroke="{C_AXIS}" stroke-width="1" fill="none"/>"#,
        n2(left + half_px),
        n2(top),
        n2(top + size),
        n2(left),
        n2(top + half_px),
        n2(left + size)
    );
    s.push_str(&labels);
    PanelTicks { step, dec, label_every }
}

/// The clipped data layer: the error ellipses, truth, estimate and the
/// initial guess (a star when inside). Returns the initial guess's offset
/// (px), distance (m) and name when it lies off the panel.
fn panel_data(
    s: &mut String,
    f: &PanelFrame,
    content: &PanelContent<'_>,
    clip_id: &str,
) -> Option<(f64, f64, f64, &'static str)> {
    let (left, top, scale, c) = (f.left, f.top, f.scale, f.centre);
    let half_px = f.half_px();
    let est = content.est;
    let _ = writeln!(s, r#"<g clip-path="url(#{clip_id})">"#);
    if let (Some(e), true) = (content.ellipse, content.est_ok) {
        let (ex, ey) = (f.px(est[0]), f.py(est[1]));
        for k in [3.0, 1.0] {
            let style = if k == 3.0 {
                format!(r#"fill="none" stroke="{C_ESTIMATE}" stroke-width="1.1" stroke-dasharray="5 3""#)
            } else {
                format!(r#"fill="{C_ESTIMATE}" fill-opacity="0.14" stroke="{C_ESTIMATE}" stroke-width="1.5""#)
            };
            let _ = writeln!(
                s,
                r#"<ellipse class="sigma{k}" data-sigma="{k}" data-semi-axes-m="{:.6} {:.6}" data-angle-deg="{:.6}" cx="{}" cy="{}" rx="{:.4}" ry="{:.4}" transform="rotate({:.4} {} {})" {style}/>"#,
                k * e.major,
                k * e.minor,
                e.angle_deg,
                n2(ex),
                n2(ey),
                k * e.major * scale,
                k * e.minor * scale,
                -e.angle_deg + 0.0,
                n2(ex),
                n2(ey)
            );
        }
    }
    if let Some(t) = content.truth {
        cross(s, f.px(t[0]), f.py(t[1]), 5.5);
    }
    if content.est_ok {
        dot(s, f.px(est[0]), f.py(est[1]), 4.0);
    }
    // Initial guess (or nominal): star if inside, arrow at the edge otherwise.
    let a = content.anchor;
    let (init3, init_name) = match &a.initial_m {
        Some(p) => (p, "initial"),
        None => (&a.nominal_m, "nominal"),
    };
    let (iu, iv) = content.view.axes();
    let init = [init3[iu], init3[iv]];
    let mut off_panel = None;
    if finite2(init) {
        let dx = (init[0] - c[0]) * scale;
        let dy = -(init[1] - c[1]) * scale;
        if dx.abs() <= half_px - 7.0 && dy.abs() <= half_px - 7.0 {
            star(s, left + half_px + dx, top + half_px + dy, 7.0);
        } else if dx.is_finite() && dy.is_finite() {
            off_panel = Some((dx, dy, (init[0] - c[0]).hypot(init[1] - c[1]), init_name));
        }
    }
    let _ = writeln!(s, "</g>");
    off_panel
}

/// An initial guess off the panel: an arrow at the edge towards it and a
/// label with its distance, kept inside the panel.
fn off_panel_arrow(s: &mut String, f: &PanelFrame, (dx, dy): (f64, f64), dist: f64, init_name: &str) {
    let (left, top, size) = (f.left, f.top, f.size);
    let half_px = f.half_px();
    let len = dx.hypot(dy);
    let (ux, uy) = (dx / len, dy / len);
    let inset = half_px - 4.0;
    let tx = if ux.abs() > 1e-12 {
        inset / ux.abs()
    } else {
        f64::INFINITY
    };
    let ty = if uy.abs() > 1e-12 {
        inset / uy.abs()
    } else {
        f64::INFINITY
    };
    let t = tx.min(ty);
    let (cx, cy) = (left + half_px, top + half_px);
    let (tipx, tipy) = (cx + ux * t, cy + uy * t);
    let (tailx, taily) = (tipx - 26.0 * ux, tipy - 26.0 * uy);
    arrow(s, tailx, taily, tipx, tipy, C_INITIAL);
    let dist_text = format!("{} m", fmt_len(dist));
    let (lx, ly, anchor, lines);
    if tx <= ty {
        // Left or right edge: a narrow two-line label beside the edge, above
        // or below the arrow, preferring the side away from the centre.
        lines = vec![init_name.to_owned(), dist_text];
        let right = ux > 0.0;
        lx = if right { left + size - 4.0 } else { left + 4.0 };
        anchor = if right { "end" } else { "start" };
        let above_y = tipy.min(taily) - 8.0 - LINE_H;
        let below_y = tipy.max(taily) + 16.0;
        let fits = |y: f64| y >= top + 14.0 && y + LINE_H <= top + size - 5.0;
        ly = if tipy < cy {
            if fits(above_y) {
                above_y
            } else {
                below_y
            }
        } else if fits(below_y) {
            below_y
        } else {
            above_y
        };
    } else {
        // Top or bottom edge: one line to the side of the arrow, preferring
        // the side away from the centre if the text fits there.
        lines = vec![format!("{init_name} {dist_text}")];
        let w = text_w(&lines[0], 12.0);
        ly = 0.5 * (tipy + taily) + 4.0;
        let left_x = tipx.min(tailx) - 8.0;
        let right_x = tipx.max(tailx) + 8.0;
        let fits_left = left_x - w >= left + 4.0;
        let fits_right = right_x + w <= left + size - 4.0;
        let go_left = if tipx < cx {
            fits_left || !fits_right
        } else {
            !fits_right && fits_left
        };
        if go_left {
            lx = left_x;
            anchor = "end";
        } else {
            lx = right_x;
            anchor = "start";
        }
    }
    off_panel_label(s, f, (lx, ly), anchor, &lines, dist);
}

/// The off-panel label's lines at `(lx, ly)`, clamped inside the panel.
fn off_panel_label(s: &mut String, f: &PanelFrame, (lx, ly): (f64, f64), anchor: &str, lines: &[String], dist: f64) {
    let (left, top, size) = (f.left, f.top, f.size);
    let w = lines.iter().map(|l| text_w(l, 12.0)).fold(0.0, f64::max);
    let (lo_x, hi_x) = match anchor {
        "end" => (left + 4.0 + w, left + size - 4.0),
        _ => (left + 4.0, left + size - 4.0 - w),
    };
    let lx = if lo_x <= hi_x { lx.clamp(lo_x, hi_x) } else { lx };
    let block = LINE_H * (lines.len() as f64 - 1.0);
    let ly = ly.clamp(top + 14.0, (top + size - 5.0 - block).max(top + 14.0));
    let mut body = String::new();
    for (k, l) in lines.iter().enumerate() {
        let _ = write!(
            body,
            r#"<tspan x="{}" dy="{}">{}</tspan>"#,
            n2(lx),
            if k == 0 { 0.0 } else { LINE_H },
            esc(l)
        );
    }
    let _ = writeln!(
        s,
        r#"<text class="off-panel" data-distance-m="{dist:.6}" x="{}" y="{}" text-anchor="{anchor}" fill="{C_INITIAL}" stroke="white" stroke-width="3" stroke-linejoin="round" paint-order="stroke">{body}</text>"#,
        n2(lx),
        n2(ly)
    );
}

/// Axis names and the scale bar below the panel.
fn panel_axes(s: &mut String, f: &PanelFrame, view: View, ticks: PanelTicks) {
    let (left, top, size, scale) = (f.left, f.top, f.size, f.scale);
    let (un, vn) = view.axis_names();
    let bar_m = ticks.step * ticks.label_every as f64;
    let bar_px = bar_m * scale;
    let by = top + size + 31.0;
    if bar_px.is_finite() && bar_px > 0.0 && bar_px < size {
        let _ = writeln!(
            s,
            r#"<path class="scale-bar" d="M{x0} {y0} V{y1} M{x0} {ym} H{x1} M{x1} {y0} V{y1}" stroke="{C_TEXT}" stroke-width="1.5" fill="none"/>"#,
            x0 = n2(left),
            x1 = n2(left + bar_px),
            y0 = n2(by - 9.0),
            y1 = n2(by - 1.0),
            ym = n2(by - 5.0)
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}">{} m</text>"#,
            n2(left + bar_px + 6.0),
            n2(by),
            tick_label(ticks.label_every, ticks.step, ticks.dec)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="end" fill="{C_MUTED}">&#916;{un} [m]</text>"#,
        n2(left + size),
        n2(by)
    );
    let _ = writeln!(
        s,
        r#"<text x="{x}" y="{y}" text-anchor="middle" fill="{C_MUTED}" transform="rotate(-90 {x} {y})">&#916;{vn} [m]</text>"#,
        x = n2(left - 46.0),
        y = n2(top + f.half_px())
    );
}

fn frame(s: &mut String, left: f64, top: f64, size: f64) {
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="{C_FRAME}" stroke-width="1"/>"#,
        n2(left),
        n2(top),
        n2(size),
        n2(size)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ellipse_closed_form() {
        let e = sigma_ellipse(4.0, 0.0, 1.0).unwrap();
        assert!((e.major - 2.0).abs() < 1e-12 && (e.minor - 1.0).abs() < 1e-12);
        assert!(e.angle_deg.abs() < 1e-12);
        let e = sigma_ellipse(1.0, 0.0, 4.0).unwrap();
        assert!((e.angle_deg - 90.0).abs() < 1e-12);
        let e = sigma_ellipse(2.0, 1.0, 2.0).unwrap();
        assert!((e.major - 3f64.sqrt()).abs() < 1e-12 && (e.minor - 1.0).abs() < 1e-12);
        assert!((e.angle_deg - 45.0).abs() < 1e-9);
        assert!(sigma_ellipse(1.0, 2.0, 1.0).is_none());
        assert!(sigma_ellipse(f64::NAN, 0.0, 1.0).is_none());
    }

    #[test]
    fn nice_steps_and_labels() {
        assert_eq!(nice_step_below(0.07), 0.05);
        assert_eq!(nice_step_below(0.3), 0.2);
        assert_eq!(nice_step_below(1.0), 1.0);
        assert_eq!(decimals_for(0.05), 2);
        assert_eq!(decimals_for(0.1), 1);
        assert_eq!(decimals_for(50.0), 0);
        assert_eq!(tick_label(-2, 0.05, 2), "\u{2212}0.10");
        assert_eq!(fmt_len(0.4123), "0.412");
        assert_eq!(fmt_len(10.0), "10.0");
        assert_eq!(esc("a<b>&\"'\u{1}"), "a&lt;b&gt;&amp;&quot;&apos; ");
    }
}

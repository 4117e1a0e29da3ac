//! Dependency-free SVG scatter plot of normalised residuals against a
//! physical driver, before and after a model extension.
//!
//! `sagcal diagnose` uses it to show whether a residual is explained by
//! some physical quantity (the *driver*, e.g. cable tension times length):
//! if the model misses an effect, the residuals of the baseline fit line up
//! along the driver (a clear slope, structure in the binned means), and once
//! the model is extended with the effect they should scatter flat around
//! zero. [`residual_plot_svg`] therefore draws
//!
//! * one panel for the `before` series (red circles) and, when there is an
//!   `after` series, a second panel to its right (blue circles); both panels
//!   share the same axes, so the two can be compared directly;
//! * in each panel: axes with 4 to 6 "nice" ticks (1, 2 or 5 x 10^k), a zero
//!   line, the points, the least-squares straight line through them (dashed)
//!   with its slope printed in the panel, and the *binned mean* curve: the
//!   finite points sorted by driver and split into 10 equal-count bins, each
//!   drawn at (mean driver, mean residual). It shows structure that a dense
//!   scatter hides and is drawn when the series has at least 10 finite points;
//! * a title, a legend and a caption, both wrapped to the figure's width.
//!
//! Points with a non-finite coordinate are skipped and counted in a note in
//! the panel; a series without finite points shows `no data`; when all driver
//! values are equal the axis is widened around them and the slope is `n/a`.
//! Rendering never panics and all text is escaped for XML.
//!
//! For tests and tools, every point is a `<circle class="before">` or
//! `<circle class="after">` (no other element carries these classes), and each
//! panel is a `<g class="panel" data-series="before|after" data-slope="..."
//! data-n="..." data-skipped="...">`. `data-slope` is the least-squares slope
//! (residual per unit of driver) printed with full precision, or `NaN` when it
//! is undefined (fewer than two finite points, or all driver values equal).
//!
//! ```
//! use sagcal::plot::residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};
//! let before: Vec<(f64, f64)> = (0..50).map(|i| (i as f64, 0.1 * i as f64 - 2.5)).collect();
//! let after: Vec<(f64, f64)> = (0..50).map(|i| (i as f64, 0.0)).collect();
//! let plot = ResidualPlot {
//!     title: "Encoder residuals vs cable load".into(),
//!     driver_label: "cable tension x length (kN m)".into(),
//!     residual_label: "encoder residual / sigma".into(),
//!     before: ResidualSeries { label: "baseline model".into(), points: before },
//!     after: Some(ResidualSeries { label: "with cable elasticity".into(), points: after }),
//!     caption: "fitted compliance 1.2e-4 m/kN, chi2 gain 35 %".into(),
//! };
//! let svg = residual_plot_svg(&plot);
//! assert!(svg.starts_with("<?xml") && svg.trim_end().ends_with("</svg>"));
//! assert_eq!(svg.matches(r#"class="before""#).count(), 50);
//! assert_eq!(svg.matches(r#"class="after""#).count(), 50);
//! ```

use super::svg::{
    caption_text, esc, halo_text, n2, shorten, text_lines, text_w, wrap, C_FRAME, C_GRID, C_MUTED, C_TEXT, FONT,
};
use std::fmt::Write as _;

/// One series of points: `(driver value, residual)` pairs and a name.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ResidualSeries {
    /// Name of the series shown above its panel, e.g. `"baseline model"`.
    pub label: String,
    /// The points as `(driver value, residual)`; points with a non-finite
    /// coordinate are skipped (and counted in a note).
    pub points: Vec<(f64, f64)>,
}

/// Everything [`residual_plot_svg`] draws.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ResidualPlot {
    /// Title at the top of the figure.
    pub title: String,
    /// Label of the horizontal (driver) axis, e.g. `"cable tension x length (kN m)"`.
    pub driver_label: String,
    /// Label of the vertical (residual) axis, e.g. `"encoder residual / sigma"`.
    pub residual_label: String,
    /// Residuals of the original model, drawn as red circles in the left panel.
    pub before: ResidualSeries,
    /// Residuals of the extended model, drawn as blue circles in a second panel
    /// to the right; `None` draws only the `before` panel.
    pub after: Option<ResidualSeries>,
    /// One line of free text under the plot, e.g. the fitted effect and its gain.
    pub caption: String,
}

// ---------------------------------------------------------------------------
// Style and layout constants (pixels), after `crate::plot`.

const MARGIN: f64 = 20.0;
const LEGEND_Y: f64 = 60.0;
const PANEL_TOP: f64 = 112.0;
const PANEL_LEFT: f64 = 74.0;
const PANEL_W: f64 = 440.0;
const PANEL_H: f64 = 300.0;
const CELL_W: f64 = PANEL_LEFT + PANEL_W + 26.0;
const BELOW_PANEL: f64 = 50.0;
const CAPTION_H: f64 = 30.0;
const BINS: usize = 10;

const C_ZERO: &str = "#8c8c8c";
const C_BEFORE: &str = "#d62728";
const C_BEFORE_DARK: &str = "#8e1616";
const C_AFTER: &str = "#1f5fbf";
const C_AFTER_DARK: &str = "#0c326e";

/// Render `plot` as a complete standalone SVG document.
///
/// Two panels side by side (before | after) sharing the same axes, or a single
/// panel when `plot.after` is `None`. Never panics: non-finite points are
/// skipped and counted, empty series show `no data`, degenerate ranges are
/// widened, and all text is escaped for XML.
pub fn residual_plot_svg(plot: &ResidualPlot) -> String {
    let mut series = vec![Prepared::new("before", &plot.before)];
    if let Some(after) = &plot.after {
        series.push(Prepared::new("after", after));
    }

    // Shared axes over all finite points; the residual axis always shows zero.
    let (mut xlo, mut xhi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut ylo, mut yhi) = (0.0_f64, 0.0_f64);
    for p in series.iter().flat_map(|s| s.points.iter()) {
        xlo = xlo.min(p.0);
        xhi = xhi.max(p.0);
        ylo = ylo.min(p.1);
        yhi = yhi.max(p.1);
    }
    if xlo > xhi {
        (xlo, xhi) = (0.0, 1.0);
    }
    let xaxis = Axis::nice(xlo, xhi);
    let yaxis = Axis::nice(ylo, yhi);

    let width = 2.0 * MARGIN + series.len() as f64 * CELL_W;
    // Title and caption wrap to the figure's width; the body moves down by the title's extra lines.
    let title = wrap(&plot.title, width - 2.0 * MARGIN, 20.0);
    let caption = wrap(&plot.caption, width - 2.0 * MARGIN, 12.0);
    let title_extra = 24.0 * (title.len() - 1) as f64;
    let caption_extra = 16.0 * (caption.len() - 1) as f64;
    let height = PANEL_TOP + PANEL_H + BELOW_PANEL + CAPTION_H + title_extra + caption_extra;

    let mut s = String::with_capacity(16 * 1024 + 160 * series.iter().map(|p| p.points.len()).sum::<usize>());
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="{FONT}" font-size="12" fill="{C_TEXT}">"#,
        w = width,
        h = height
    );
    let _ = writeln!(s, "<title>{}</title>", esc(&plot.title));
    let _ = writeln!(
        s,
        r#"<rect x="0" y="0" width="{width}" height="{height}" fill="white" stroke="none"/>"#
    );
    text_lines(
        &mut s,
        MARGIN,
        30.0,
        24.0,
        r#"class="title" font-size="20" font-weight="bold""#,
        &title,
    );
    let _ = writeln!(s, r#"<g transform="translate(0 {})">"#, n2(title_extra));
    render_legend(&mut s, &series, MARGIN, width - MARGIN, LEGEND_Y);

    for (i, p) in series.iter().enumerate() {
        let left = MARGIN + i as f64 * CELL_W + PANEL_LEFT;
        render_panel(&mut s, plot, p, &xaxis, &yaxis, left, PANEL_TOP);
    }
    let _ = writeln!(s, "</g>");

    caption_text(&mut s, MARGIN, height, &caption);
    s.push_str("</svg>\n");
    s
}

// ---------------------------------------------------------------------------
// Statistics.

/// A series reduced to what is drawn.
struct Prepared<'a> {
    /// `"before"` or `"after"`: the CSS class of its points.
    name: &'static str,
    label: &'a str,
    /// The finite points, in input order.
    points: Vec<(f64, f64)>,
    /// Number of points left out because a coordinate is not finite.
    skipped: usize,
    fit: Option<Fit>,
    /// (mean driver, mean residual) of each equal-count bin, by increasing driver.
    bins: Vec<(f64, f64)>,
}

impl<'a> Prepared<'a> {
    fn new(name: &'static str, series: &'a ResidualSeries) -> Self {
        let points: Vec<(f64, f64)> = series
            .points
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        let skipped = series.points.len() - points.len();
        let fit = least_squares(&points);
        let bins = binned_means(&points, BINS);
        Prepared {
            name,
            label: &series.label,
            points,
            skipped,
            fit,
            bins,
        }
    }

    fn colours(&self) -> (&'static str, &'static str) {
        if self.name == "after" {
            (C_AFTER, C_AFTER_DARK)
        } else {
            (C_BEFORE, C_BEFORE_DARK)
        }
    }
}

/// Least-squares line `y = mean_y + slope * (x - mean_x)`.
#[derive(Debug, Clone, Copy)]
struct Fit {
    slope: f64,
    mean_x: f64,
    mean_y: f64,
}

/// Least-squares straight line through finite points (two-pass, centred sums).
/// `None` for fewer than two points, all `x` equal, or overflow.
fn least_squares(points: &[(f64, f64)]) -> Option<Fit> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let mean_x = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for &(x, y) in points {
        let dx = x - mean_x;
        sxx += dx * dx;
        sxy += dx * (y - mean_y);
    }
    let slope = sxy / sxx;
    (sxx > 0.0 && slope.is_finite() && mean_x.is_finite() && mean_y.is_finite()).then_some(Fit {
        slope,
        mean_x,
        mean_y,
    })
}

/// Sort by driver, split into `bins` equal-count bins (sizes differ by at most
/// one) and return each bin's (mean driver, mean residual). Empty when there
/// are fewer points than bins.
fn binned_means(points: &[(f64, f64)], bins: usize) -> Vec<(f64, f64)> {
    let n = points.len();
    if bins == 0 || n < bins {
        return Vec::new();
    }
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    (0..bins)
        .map(|k| {
            let bin = &sorted[k * n / bins..(k + 1) * n / bins];
            let m = bin.len() as f64;
            (
                bin.iter().map(|p| p.0).sum::<f64>() / m,
                bin.iter().map(|p| p.1).sum::<f64>() / m,
            )
        })
        .collect()
}

// ---------------------------------------------------------------------------
// Axes.

/// An axis from `lo` to `hi`, both multiples of the tick step `m x 10^k`
/// (`m` in {1, 2, 5}); ticks at `i x step` for `i` in `first..=last`.
#[derive(Debug, Clone, Copy)]
struct Axis {
    lo: f64,
    hi: f64,
    m: f64,
    k: i32,
    first: f64,
    last: f64,
}

impl Axis {
    /// Nice axis around the data range `[lo, hi]` with 4 to 6 ticks.
    fn nice(lo: f64, hi: f64) -> Axis {
        let (mut lo, mut hi) = if lo.is_finite() && hi.is_finite() && lo <= hi && (hi - lo).is_finite() {
            (lo, hi)
        } else {
            (-1.0, 1.0)
        };
        let mag = lo.abs().max(hi.abs());
        if hi - lo <= 1e-9 * mag {
            // Degenerate range: widen around the value.
            let c = 0.5 * lo + 0.5 * hi;
            let half = if c.abs() > 1e-100 && c.abs() < 1e300 {
                0.05 * c.abs()
            } else {
                1.0
            };
            let c = if c.abs() < 1e300 { c } else { 0.0 };
            (lo, hi) = (c - half, c + half);
        }
        // Smallest 1-2-5 step giving at most 5 intervals. Starting at or below a
        // tenth of the span, the previous step gave at least 6 intervals, so
        // this one gives at least 2 (the steps grow by at most 2.5x).
        let (mut m, mut k) = nice_step_below((hi - lo) / 10.0);
        let (mut a, mut b) = (0.0, 1.0);
        for _ in 0..40 {
            let step = m * 10f64.powi(k);
            a = (lo / step).floor();
            b = (hi / step).ceil();
            // Guard against rounding in the division: the ticks must cover the data.
            if a * step > lo {
                a -= 1.0;
            }
            if b * step < hi {
                b += 1.0;
            }
            if b - a <= 5.0 {
                break;
            }
            (m, k) = next_step(m, k);
        }
        // At least 3 intervals (4 ticks): add a step on the tighter side.
        let step = m * 10f64.powi(k);
        for _ in 0..3 {
            if b - a >= 3.0 {
                break;
            }
            if lo - a * step < b * step - hi {
                a -= 1.0;
            } else {
                b += 1.0;
            }
        }
        let (alo, ahi) = (a * step, b * step);
        if alo.is_finite() && ahi.is_finite() && ahi > alo {
            Axis {
                lo: alo,
                hi: ahi,
                m,
                k,
                first: a,
                last: b,
            }
        } else {
            Axis {
                lo: -1.0,
                hi: 1.0,
                m: 5.0,
                k: -1,
                first: -2.0,
                last: 2.0,
            }
        }
    }

    fn step(&self) -> f64 {
        self.m * 10f64.powi(self.k)
    }

    /// Tick indices (at most 11, whatever happened to the arithmetic).
    fn ticks(&self) -> impl Iterator<Item = f64> + '_ {
        let n = (self.last - self.first).clamp(0.0, 10.0) as usize;
        (0..=n).map(move |j| self.first + j as f64)
    }

    /// Fraction of the way from `lo` to `hi`.
    fn frac(&self, v: f64) -> f64 {
        (v - self.lo) / (self.hi - self.lo)
    }

    /// Tick `i x step` as text, exactly, with a typographic minus sign.
    fn label(&self, i: f64) -> String {
        if i == 0.0 {
            return "0".to_owned();
        }
        let t = if (-4..=5).contains(&self.k) {
            let dec = (-self.k).max(0) as usize;
            format!("{:.dec$}", i * self.step())
        } else {
            let (mut mant, mut k) = (i * self.m, self.k);
            for _ in 0..20 {
                if mant % 10.0 != 0.0 {
                    break;
                }
                mant /= 10.0;
                k += 1;
            }
            format!("{mant:.0}e{k}")
        };
        match t.strip_prefix('-') {
            Some(rest) => format!("\u{2212}{rest}"),
            None => t,
        }
    }
}

/// Largest of 1, 2, 5 x 10^k not above `raw`, as `(m, k)` (or `(1, 0)` for nonsense input).
fn nice_step_below(raw: f64) -> (f64, i32) {
    if !(raw.is_finite() && raw > 0.0) {
        return (1.0, 0);
    }
    let k = raw.log10().floor() as i32;
    let f = raw / 10f64.powi(k);
    let m = if f >= 5.0 {
        5.0
    } else if f >= 2.0 {
        2.0
    } else {
        1.0
    };
    (m, k)
}

/// The 1-2-5 step after `m x 10^k`.
fn next_step(m: f64, k: i32) -> (f64, i32) {
    if m < 1.5 {
        (2.0, k)
    } else if m < 3.5 {
        (5.0, k)
    } else {
        (1.0, k.saturating_add(1))
    }
}

// ---------------------------------------------------------------------------
// Rendering.

/// Legend items left to right from `left`, wrapping to a second row (16 px
/// lower) when an item would pass `right`.
fn render_legend(s: &mut String, series: &[Prepared<'_>], left: f64, right: f64, y: f64) {
    /// Marker of a legend item.
    enum Key {
        Dot(&'static str),
        Dashed,
        Thick,
    }
    let mut items: Vec<(Key, String)> = series
        .iter()
        .map(|p| {
            let text = if p.label.is_empty() {
                p.name.to_owned()
            } else {
                format!("{}: {}", p.name, p.label)
            };
            (Key::Dot(p.colours().0), shorten(&text, 48))
        })
        .collect();
    items.push((Key::Dashed, "least-squares line".to_owned()));
    items.push((Key::Thick, format!("mean of {BINS} equal-count bins")));

    let _ = writeln!(s, r#"<g class="legend">"#);
    let (mut x, mut y) = (left, y);
    for (key, text) in &items {
        let key_w = if matches!(key, Key::Dot(_)) { 13.0 } else { 32.0 };
        let w = key_w + text_w(text, 12.0);
        if x > left && x + w > right {
            x = left;
            y += 16.0;
        }
        match key {
            Key::Dot(c) => {
                let _ = writeln!(
                    s,
                    r#"<circle cx="{}" cy="{}" r="3.5" fill="{c}" fill-opacity="0.55" stroke="{c}" stroke-width="0.8"/>"#,
                    n2(x + 4.0),
                    n2(y - 4.0)
                );
            }
            Key::Dashed | Key::Thick => {
                let style = if matches!(key, Key::Dashed) {
                    r#"stroke-width="1.6" stroke-dasharray="6 4""#
                } else {
                    r#"stroke-width="2.6""#
                };
                let _ = writeln!(
                    s,
                    r#"<path d="M{} {} H{}" stroke="{C_TEXT}" {style} fill="none"/>"#,
                    n2(x),
                    n2(y - 4.0),
                    n2(x + 26.0)
                );
            }
        }
        let _ = writeln!(s, r#"<text x="{}" y="{}">{}</text>"#, n2(x + key_w), n2(y), esc(text));
        x += w + 22.0;
    }
    let _ = writeln!(s, "</g>");
}

/// A residual panel's place and axes.
struct PanelPlace<'a> {
    left: f64,
    top: f64,
    xa: &'a Axis,
    ya: &'a Axis,
}

impl PanelPlace<'_> {
    /// The pixel column of driver value `x`.
    fn px(&self, x: f64) -> f64 {
        self.left + self.xa.frac(x) * PANEL_W
    }

    /// The pixel row of residual `y`.
    fn py(&self, y: f64) -> f64 {
        self.top + PANEL_H - self.ya.frac(y) * PANEL_H
    }
}

fn render_panel(s: &mut String, plot: &ResidualPlot, p: &Prepared<'_>, xa: &Axis, ya: &Axis, left: f64, top: f64) {
    let slope_attr = p.fit.map_or_else(|| "NaN".to_owned(), |f| format!("{}", f.slope));
    let _ = writeln!(
        s,
        r#"<g class="panel" data-series="{}" data-slope="{}" data-n="{}" data-skipped="{}">"#,
        p.name,
        slope_attr,
        p.points.len(),
        p.skipped
    );
    let place = PanelPlace { left, top, xa, ya };
    // Panel title.
    let heading = if p.name == "after" { "After" } else { "Before" };
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" font-size="13"><tspan font-weight="bold">{heading}</tspan><tspan dx="8" fill="{C_MUTED}">{}</tspan></text>"#,
        n2(left),
        n2(top - 8.0),
        esc(&shorten(p.label, 60))
    );
    let clip_id = format!("residual-clip-{}", p.name);
    let _ = writeln!(
        s,
        r#"<defs><clipPath id="{clip_id}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
        n2(left),
        n2(top),
        n2(PANEL_W),
        n2(PANEL_H)
    );
    panel_grid(s, &place);
    panel_points(s, &place, p, &clip_id);
    let _ = writeln!(
        s,
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="{C_FRAME}" stroke-width="1"/>"#,
        n2(left),
        n2(top),
        n2(PANEL_W),
        n2(PANEL_H)
    );
    panel_notes(s, &place, p);
    // Axis labels.
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        n2(left + 0.5 * PANEL_W),
        n2(top + PANEL_H + 36.0),
        esc(&plot.driver_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="{x}" y="{y}" text-anchor="middle" transform="rotate(-90 {x} {y})">{}</text>"#,
        esc(&plot.residual_label),
        x = n2(left - 56.0),
        y = n2(top + 0.5 * PANEL_H)
    );
    let _ = writeln!(s, "</g>");
}

/// Grid, zero line and tick labels.
fn panel_grid(s: &mut String, place: &PanelPlace<'_>) {
    let (left, top, xa, ya) = (place.left, place.top, place.xa, place.ya);
    let mut grid = String::new();
    for i in xa.ticks() {
        let x = place.px(i * xa.step());
        let _ = write!(grid, "M{} {} V{} ", n2(x), n2(top), n2(top + PANEL_H));
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle" fill="{C_MUTED}">{}</text>"#,
            n2(x),
            n2(top + PANEL_H + 16.0),
            esc(&xa.label(i))
        );
    }
    for i in ya.ticks() {
        let y = place.py(i * ya.step());
        let _ = write!(grid, "M{} {} H{} ", n2(left), n2(y), n2(left + PANEL_W));
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="end" fill="{C_MUTED}">{}</text>"#,
            n2(left - 6.0),
            n2(y + 4.0),
            esc(&ya.label(i))
        );
    }
    let _ = writeln!(
        s,
        r#"<path class="grid" d="{}" stroke="{C_GRID}" stroke-width="1" fill="none"/>"#,
        grid.trim_end()
    );
    if ya.lo <= 0.0 && ya.hi >= 0.0 {
        let _ = writeln!(
            s,
            r#"<path class="zero" d="M{} {} H{}" stroke="{C_ZERO}" stroke-width="1.2" fill="none"/>"#,
            n2(left),
            n2(place.py(0.0)),
            n2(left + PANEL_W)
        );
    }
}

/// Points and binned means (inside the axes by construction), then the
/// least-squares line clipped to the panel.
fn panel_points(s: &mut String, place: &PanelPlace<'_>, p: &Prepared<'_>, clip_id: &str) {
    let (colour, dark) = p.colours();
    for &(x, y) in &p.points {
        let _ = writeln!(
            s,
            r#"<circle class="{}" cx="{}" cy="{}" r="2.6" fill="{colour}" fill-opacity="0.45" stroke="{colour}" stroke-width="0.6"/>"#,
            p.name,
            n2(place.px(x)),
            n2(place.py(y))
        );
    }
    if p.bins.len() >= 2 {
        let pts: Vec<String> = p
            .bins
            .iter()
            .map(|b| format!("{},{}", n2(place.px(b.0)), n2(place.py(b.1))))
            .collect();
        let _ = writeln!(
            s,
            r#"<polyline class="binned-mean" points="{}" stroke="{dark}" stroke-width="2.6" stroke-linejoin="round" fill="none"/>"#,
            pts.join(" ")
        );
        for b in &p.bins {
            let _ = writeln!(
                s,
                r#"<rect class="bin-mean" x="{}" y="{}" width="6" height="6" fill="{dark}" stroke="white" stroke-width="1"/>"#,
                n2(place.px(b.0) - 3.0),
                n2(place.py(b.1) - 3.0)
            );
        }
    }
    if let Some(f) = p.fit {
        let xa = place.xa;
        let _ = writeln!(s, r#"<g clip-path="url(#{clip_id})">"#);
        let line_y = |x: f64| f.mean_y + f.slope * (x - f.mean_x);
        let _ = writeln!(
            s,
            r#"<path class="fit" d="M{} {} L{} {}" stroke="{dark}" stroke-width="1.6" stroke-dasharray="6 4" fill="none"/>"#,
            n2(place.px(xa.lo)),
            n2(place.py(line_y(xa.lo))),
            n2(place.px(xa.hi)),
            n2(place.py(line_y(xa.hi)))
        );
        let _ = writeln!(s, "</g>");
    }
}

/// The slope, and notes for an empty series or skipped points.
fn panel_notes(s: &mut String, place: &PanelPlace<'_>, p: &Prepared<'_>) {
    let (left, top) = (place.left, place.top);
    let (_, dark) = p.colours();
    let slope_text = match p.fit {
        Some(f) => format!("slope {} per unit (n = {})", fmt_sig(f.slope, 3), p.points.len()),
        None => format!("slope n/a (n = {})", p.points.len()),
    };
    halo_text(s, left + 8.0, top + 18.0, "start", dark, &slope_text);
    if p.points.is_empty() {
        halo_text(
            s,
            left + 0.5 * PANEL_W,
            top + 0.5 * PANEL_H + 5.0,
            "middle",
            C_MUTED,
            "no data",
        );
    }
    if p.skipped > 0 {
        let note = format!(
            "{} non-finite point{} skipped",
            p.skipped,
            if p.skipped == 1 { "" } else { "s" }
        );
        halo_text(s, left + 8.0, top + PANEL_H - 8.0, "start", C_MUTED, &note);
    }
}

// ---------------------------------------------------------------------------
// Text helpers.

/// `x` with `sig` significant digits (no exponent for moderate values), or `n/a`.
fn fmt_sig(x: f64, sig: i32) -> String {
    if !x.is_finite() {
        return "n/a".to_owned();
    }
    let ax = x.abs();
    if ax != 0.0 && !(1e-4..1e6).contains(&ax) {
        return format!("{:.*e}", (sig - 1).max(0) as usize, x);
    }
    let dec = if ax == 0.0 {
        (sig - 1).max(0) as usize
    } else {
        (f64::from(sig - 1) - ax.log10().floor()).clamp(0.0, 9.0) as usize
    };
    format!("{:.dec$}", x + 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(label: &str, points: Vec<(f64, f64)>) -> ResidualSeries {
        ResidualSeries {
            label: label.into(),
            points,
        }
    }

    fn plot(before: Vec<(f64, f64)>, after: Option<Vec<(f64, f64)>>) -> ResidualPlot {
        ResidualPlot {
            title: "Residuals & drivers <test>".into(),
            driver_label: "tension x length (kN m) > 0".into(),
            residual_label: "residual / sigma".into(),
            before: series("baseline & co", before),
            after: after.map(|p| series("extended <model>", p)),
            caption: "gain 35 % & slope < 1".into(),
        }
    }

    /// `data-slope` of the panel of `name`, parsed.
    fn data_slope(svg: &str, name: &str) -> f64 {
        let key = format!(r#"data-series="{name}" data-slope=""#);
        let start = svg.find(&key).expect("panel present") + key.len();
        let end = start + svg[start..].find('"').unwrap();
        svg[start..end].parse().unwrap()
    }

    /// Minimal well-formedness check: tags balanced and properly nested,
    /// quotes balanced inside tags, every `&` starts an entity, no raw `<`/`>`
    /// in text.
    fn assert_xmlish(svg: &str) {
        assert_eq!(svg.matches("<svg").count(), 1);
        assert_eq!(svg.matches("</svg>").count(), 1);
        assert!(svg.trim_end().ends_with("</svg>"));
        let mut rest = svg;
        while let Some(i) = rest.find('&') {
            rest = &rest[i + 1..];
            let end = rest.find(';').expect("entity terminated");
            let name = &rest[..end];
            let ok = matches!(name, "amp" | "lt" | "gt" | "quot" | "apos")
                || (name.starts_with('#') && name[1..].chars().all(|c| c.is_ascii_digit()) && name.len() > 1);
            assert!(ok, "bad entity &{name};");
        }
        let mut stack: Vec<String> = Vec::new();
        let mut rest = svg;
        while let Some(i) = rest.find('<') {
            assert!(!rest[..i].contains('>'), "raw > in text");
            let end = rest[i..].find('>').expect("tag closed") + i;
            let tag = &rest[i + 1..end];
            assert!(!tag.contains('<'), "raw < inside tag");
            assert_eq!(tag.matches('"').count() % 2, 0, "unbalanced quotes in <{tag}>");
            if tag.starts_with('?') {
                assert!(tag.ends_with('?'));
            } else if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched </{name}>");
            } else if !tag.ends_with('/') {
                let name = tag.split_whitespace().next().unwrap().to_owned();
                stack.push(name);
            }
            rest = &rest[end + 1..];
        }
        assert!(stack.is_empty(), "unclosed: {stack:?}");
    }

    /// y = 2x + 1 plus a small deterministic perturbation.
    fn known_points(n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let x = 0.37 * i as f64 - 3.0;
                (x, 2.0 * x + 1.0 + 0.05 * ((i * 7919) % 13) as f64 - 0.3)
            })
            .collect()
    }

    /// Closed-form least-squares slope from raw sums.
    fn closed_form_slope(p: &[(f64, f64)]) -> f64 {
        let n = p.len() as f64;
        let sx: f64 = p.iter().map(|q| q.0).sum();
        let sy: f64 = p.iter().map(|q| q.1).sum();
        let sxx: f64 = p.iter().map(|q| q.0 * q.0).sum();
        let sxy: f64 = p.iter().map(|q| q.0 * q.1).sum();
        (n * sxy - sx * sy) / (n * sxx - sx * sx)
    }

    #[test]
    fn circles_match_finite_points_and_panels() {
        let before = known_points(57);
        let after: Vec<(f64, f64)> = before.iter().map(|p| (p.0, 0.1 * p.1)).collect();
        let svg = residual_plot_svg(&plot(before, Some(after)));
        assert_xmlish(&svg);
        assert_eq!(svg.matches(r#"<circle class="before""#).count(), 57);
        assert_eq!(svg.matches(r#"<circle class="after""#).count(), 57);
        assert_eq!(svg.matches(r#"class="before""#).count(), 57);
        assert_eq!(svg.matches(r#"class="after""#).count(), 57);
        assert_eq!(svg.matches(r#"<g class="panel""#).count(), 2);
        assert_eq!(svg.matches(r#"class="binned-mean""#).count(), 2);
        assert_eq!(svg.matches(r#"class="bin-mean""#).count(), 2 * BINS);
        assert!(svg.contains("slope "));
        assert!(!svg.contains("no data"));
    }

    #[test]
    fn slope_matches_closed_form() {
        let pts = known_points(40);
        let expected = closed_form_slope(&pts);
        assert!((expected - 2.0).abs() < 0.1, "{expected}");
        let after: Vec<(f64, f64)> = pts.iter().map(|p| (p.0, p.1 - 2.0 * p.0 - 1.0)).collect();
        let expected_after = closed_form_slope(&after);
        let svg = residual_plot_svg(&plot(pts, Some(after)));
        assert!((data_slope(&svg, "before") - expected).abs() < 1e-9);
        assert!((data_slope(&svg, "after") - expected_after).abs() < 1e-9);
    }

    #[test]
    fn nan_points_are_skipped() {
        let mut pts = known_points(30);
        pts.push((f64::NAN, 1.0));
        pts.push((1.0, f64::INFINITY));
        pts.push((f64::NEG_INFINITY, f64::NAN));
        let expected = closed_form_slope(&pts[..30]);
        let svg = residual_plot_svg(&plot(pts, None));
        assert_xmlish(&svg);
        assert_eq!(svg.matches(r#"class="before""#).count(), 30);
        assert_eq!(svg.matches(r#"class="after""#).count(), 0);
        assert_eq!(svg.matches(r#"<g class="panel""#).count(), 1);
        assert!(svg.contains(r#"data-n="30" data-skipped="3""#));
        assert!(svg.contains("3 non-finite points skipped"));
        assert!((data_slope(&svg, "before") - expected).abs() < 1e-9);
        assert!(!svg.contains("inf"));
    }

    #[test]
    fn empty_and_degenerate_series_render() {
        // Empty before, all-NaN after.
        let svg = residual_plot_svg(&plot(vec![], Some(vec![(f64::NAN, f64::NAN)])));
        assert_xmlish(&svg);
        assert_eq!(svg.matches("no data").count(), 2);
        assert!(svg.contains("1 non-finite point skipped"));
        assert!(data_slope(&svg, "before").is_nan());
        assert!(data_slope(&svg, "after").is_nan());

        // All driver values equal: renders, slope undefined, every point drawn.
        let pts: Vec<(f64, f64)> = (0..25).map(|i| (3.5, 0.1 * i as f64 - 1.0)).collect();
        let svg = residual_plot_svg(&plot(pts, None));
        assert_xmlish(&svg);
        assert_eq!(svg.matches(r#"class="before""#).count(), 25);
        assert!(data_slope(&svg, "before").is_nan());
        assert!(svg.contains("slope n/a"));

        // A single point at zero, and huge values.
        for pts in [
            vec![(0.0, 0.0)],
            vec![(1e300, -1e300), (-1e300, 1e300)],
            vec![(f64::MAX, 0.0), (f64::MIN, 1.0)],
        ] {
            let n = pts.len();
            let svg = residual_plot_svg(&plot(pts, None));
            assert_xmlish(&svg);
            assert_eq!(svg.matches(r#"class="before""#).count(), n);
            assert!(!svg.contains("inf"));
        }
    }

    #[test]
    fn text_is_escaped() {
        let svg = residual_plot_svg(&plot(known_points(12), None));
        assert_xmlish(&svg);
        assert!(svg.contains("Residuals &amp; drivers &lt;test&gt;"));
        assert!(svg.contains("gain 35 % &amp; slope &lt; 1"));
        assert!(svg.contains("(kN m) &gt; 0"));
    }

    #[test]
    fn least_squares_and_bins() {
        let pts: Vec<(f64, f64)> = (0..20).map(|i| (i as f64, 3.0 * i as f64 - 4.0)).collect();
        let f = least_squares(&pts).unwrap();
        assert!((f.slope - 3.0).abs() < 1e-12);
        assert!(least_squares(&pts[..1]).is_none());
        assert!(least_squares(&[(1.0, 0.0), (1.0, 2.0)]).is_none());
        // 20 points in 10 bins of 2, input order irrelevant.
        let mut rev = pts.clone();
        rev.reverse();
        let bins = binned_means(&rev, 10);
        assert_eq!(bins.len(), 10);
        assert!((bins[0].0 - 0.5).abs() < 1e-12 && (bins[0].1 - (-2.5)).abs() < 1e-12);
        assert!((bins[9].0 - 18.5).abs() < 1e-12);
        // Unequal split: 23 points -> sizes 2 or 3, all points used.
        let bins = binned_means(&pts.iter().chain(&pts[..3]).copied().collect::<Vec<_>>(), 10);
        assert_eq!(bins.len(), 10);
        assert!(binned_means(&pts[..9], 10).is_empty());
    }

    #[test]
    fn axes_have_four_to_six_nice_ticks() {
        let mut cases = vec![
            (0.0, 1.0),
            (-2.5, 2.5),
            (0.0, 0.0),
            (5.0, 5.0),
            (-1e-7, 3e-7),
            (1e6, 1e6 + 3.0),
        ];
        for i in 0..400 {
            let lo = -50.0 + 0.37 * i as f64;
            let span = 10f64.powf(-3.0 + 0.0173 * i as f64);
            cases.push((lo, lo + span));
            cases.push((-span * 0.3, span));
        }
        for (lo, hi) in cases {
            let a = Axis::nice(lo, hi);
            let n = a.ticks().count();
            assert!((4..=6).contains(&n), "{lo}..{hi}: {n} ticks {a:?}");
            assert!(a.lo <= lo && a.hi >= hi, "{lo}..{hi} not covered by {a:?}");
            assert!([1.0, 2.0, 5.0].contains(&a.m));
            let labels: Vec<String> = a.ticks().map(|i| a.label(i)).collect();
            let mut uniq = labels.clone();
            uniq.dedup();
            assert_eq!(uniq, labels, "{lo}..{hi}");
        }
        let a = Axis::nice(0.0, 0.95);
        assert_eq!(
            a.ticks().map(|i| a.label(i)).collect::<Vec<_>>(),
            ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]
        );
        let a = Axis::nice(-3e-7, 4e-7);
        assert!(
            a.ticks().any(|i| a.label(i) == "\u{2212}2e-7"),
            "{:?}",
            a.ticks().map(|i| a.label(i)).collect::<Vec<_>>()
        );
    }
}

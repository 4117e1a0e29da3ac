//! Figures: SVG drawn by hand, one file per figure, written as SVG or PNG
//! by [`write_figure`] (PNG when the file name ends in `.png`).
//!
//! - [`anchors`]: a calibration's anchor estimates with their error ellipses
//!   (`sagcal calibrate --plot`, the demo);
//! - [`residuals`]: normalised residuals against a physical driver, before and
//!   after a model extension (`sagcal diagnose --plots`);
//! - `svg`: the drawing helpers both share (escaping, coordinates, labels,
//!   the font and colours);
//! - `png`: [`write_figure`] and [`svg_to_png`], the SVG rendered with `resvg`
//!   and a bundled font (DejaVu Sans), so PNG needs no system fonts.

pub mod anchors;
mod png;
pub mod residuals;
mod svg;

pub use anchors::{anchor_plot_svg, AnchorPlot, AnchorPlotEntry};
pub use png::{is_png_path, svg_to_png, write_figure, PNG_SCALE};
pub use residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};

//! Figures: dependency-free SVG drawn by hand, one file per figure.
//!
//! - [`anchors`]: a calibration's anchor estimates with their error ellipses
//!   (`sagcal calibrate --plot`, the demo);
//! - [`residuals`]: normalised residuals against a physical driver, before and
//!   after a model extension (`sagcal diagnose --plots`);
//! - [`localize`]: localised poses with their error ellipses (`sagcal localize --plot`);
//! - `svg`: the drawing helpers both share (escaping, coordinates, labels,
//!   the font and colours) and [`write_svg`].

pub mod anchors;
pub mod localize;
pub mod plan;
pub mod residuals;
mod svg;

pub use anchors::{anchor_plot_svg, AnchorPlot, AnchorPlotEntry};
pub use residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};
pub use svg::write_svg;

//! Figures: SVG drawn by hand, one file per figure, written as SVG or PNG
//! by [`write_figure`] (PNG when the file name ends in `.png`).
//!
//! - [`anchors`]: a calibration's anchor estimates with their error ellipses
//!   (`sagcal calibrate --plot`, the demo);
//! - [`residuals`]: normalised residuals against a physical driver, before and
//!   after a model extension (`sagcal diagnose --plots`);
//! - [`localize`]: localised poses with their error ellipses (`sagcal localize --plot`);
//! - [`plan`]: a planned pose set (`sagcal plan --plot`);
//! - `svg`: the drawing helpers they share (escaping, coordinates, labels,
//!   the font and colours);
//! - `png`: [`write_figure`] (and [`figure_bytes`], its bytes) and
//!   [`svg_to_png`], the SVG rendered with `resvg` and a bundled font
//!   (DejaVu Sans), so PNG needs no system fonts.
//!
//! ```
//! use sagcal::plot::residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};
//! use sagcal::plot::write_figure;
//! let plot = ResidualPlot {
//!     title: "encoder residual vs cable length".into(),
//!     driver_label: "cable length (m)".into(),
//!     residual_label: "encoder residual / sigma".into(),
//!     before: ResidualSeries {
//!         label: "baseline model".into(),
//!         points: (0..30).map(|i| (140.0 + 2.0 * i as f64, 0.1 * i as f64 - 1.5)).collect(),
//!     },
//!     after: None,
//!     caption: "simulated".into(),
//! };
//! let svg = residual_plot_svg(&plot);
//! let dir = std::env::temp_dir();
//! let png = dir.join(format!("sagcal-plot-doc-{}.png", std::process::id()));
//! write_figure(&png, &svg)?; // PNG: the name ends in .png
//! assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
//! # std::fs::remove_file(&png).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

pub mod anchors;
pub mod localize;
pub mod plan;
mod png;
pub mod residuals;
mod svg;

pub use anchors::{anchor_plot_svg, AnchorPlot, AnchorPlotEntry};
pub use png::{figure_bytes, is_png_path, svg_to_png, write_figure, PNG_SCALE};
pub use residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};

//! Why a figure could not be rendered to PNG ([`crate::plot::svg_to_png`]).
//!
//! ```
//! let failed = sagcal::plot::svg_to_png("<svg", 2.0, "residual plot").unwrap_err();
//! assert!(matches!(failed, sagcal::Error::Png(sagcal::error::PngError::Svg { .. })));
//! assert!(failed.to_string().starts_with("residual plot: the figure's SVG does not parse: "));
//! ```

/// Why a figure could not be rendered to PNG.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PngError {
    /// The figure's SVG does not parse.
    #[error("{what}: the figure's SVG does not parse: {message}")]
    Svg {
        /// The figure.
        what: String,
        /// The parser's message.
        message: String,
    },
    /// The figure has no area.
    #[error("{what}: the figure has no area")]
    NoArea {
        /// The figure.
        what: String,
    },
    /// The image would be too large to allocate.
    #[error("{what}: a {width} x {height} px image is too large")]
    TooLarge {
        /// The figure.
        what: String,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// The PNG encoder failed.
    #[error("{what}: PNG encoding failed: {message}")]
    Encode {
        /// The figure.
        what: String,
        /// The encoder's message.
        message: String,
    },
}

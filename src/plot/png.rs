//! PNG figures: the hand-written SVG of every figure rendered with `resvg`,
//! with the font bundled so that rendering needs nothing from the machine.
//!
//! The figures are drawn once, as SVG ([`super::anchors`],
//! [`super::residuals`]); a PNG is that SVG rasterised at [`PNG_SCALE`] times
//! its pixel size, so both formats show exactly the same content. The SVG
//! asks for `DejaVu Sans` first; DejaVu Sans and DejaVu Sans Bold (Bitstream
//! Vera licence, `assets/fonts/LICENSE`) are embedded in the binary and are
//! the only fonts the renderer knows, so a machine without system fonts gives
//! the same picture as any other.

use std::path::Path;
use std::sync::{Arc, OnceLock};

use resvg::{tiny_skia, usvg};

use crate::error::{PngError, Result};

/// DejaVu Sans 2.37, regular.
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
/// DejaVu Sans 2.37, bold (titles and table headers).
static DEJAVU_SANS_BOLD: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-Bold.ttf");

/// Device pixels per SVG pixel of a PNG: 2, sharp in slides and printed reports.
pub const PNG_SCALE: f32 = 2.0;

/// The bundled fonts, loaded once.
fn fonts() -> Arc<usvg::fontdb::Database> {
    static FONTS: OnceLock<Arc<usvg::fontdb::Database>> = OnceLock::new();
    FONTS
        .get_or_init(|| {
            let mut db = usvg::fontdb::Database::new();
            db.load_font_data(DEJAVU_SANS.to_vec());
            db.load_font_data(DEJAVU_SANS_BOLD.to_vec());
            // Helvetica, Arial and the generic families of the font stack resolve to DejaVu too.
            db.set_sans_serif_family("DejaVu Sans");
            db.set_serif_family("DejaVu Sans");
            db.set_monospace_family("DejaVu Sans");
            Arc::new(db)
        })
        .clone()
}

/// Render `svg` to PNG bytes at `scale` device pixels per SVG pixel, on white.
///
/// Errors are [`PngError`]s (`what` names the figure) when the SVG does not
/// parse, the image would be empty or too large, or the encoder fails.
///
/// ```
/// let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20">
///   <rect x="0" y="0" width="20" height="20" fill="#ff0000"/>
///   <text x="22" y="15" font-family="DejaVu Sans" font-size="12">a</text></svg>"##;
/// let png = sagcal::plot::svg_to_png(svg, 2.0, "example").unwrap();
/// assert_eq!(&png[1..4], b"PNG");
/// ```
pub fn svg_to_png(svg: &str, scale: f32, what: &str) -> Result<Vec<u8>> {
    let options = usvg::Options {
        fontdb: fonts(),
        font_family: "DejaVu Sans".into(),
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_str(svg, &options).map_err(|e| PngError::Svg {
        what: what.to_string(),
        message: e.to_string(),
    })?;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(scale)
        .ok_or_else(|| PngError::NoArea { what: what.to_string() })?;
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).ok_or_else(|| PngError::TooLarge {
        what: what.to_string(),
        width: size.width(),
        height: size.height(),
    })?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap.encode_png().map_err(|e| PngError::Encode {
        what: what.to_string(),
        message: e.to_string(),
    })?)
}

/// Whether `path` names a PNG file (extension `.png`, any case).
pub fn is_png_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// Write a figure: PNG (rendered at [`PNG_SCALE`]) when `path` ends in
/// `.png`, the SVG text otherwise. The file is written atomically
/// ([`crate::io::write_atomically`]): on any error `path` is left as it was.
pub fn write_figure(path: &Path, svg: &str) -> Result<()> {
    crate::io::write_atomically(path, &figure_bytes(path, svg)?)
}

/// The bytes [`write_figure`] writes to `path`: the PNG rendered at
/// [`PNG_SCALE`] when `path` ends in `.png`, the SVG text otherwise. For a
/// figure written with other files ([`crate::io::OutputSet`]).
///
/// ```
/// let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="4" height="2"/>"##;
/// let png = sagcal::plot::figure_bytes(std::path::Path::new("f.PNG"), svg).unwrap();
/// assert_eq!(&png[1..4], b"PNG");
/// assert_eq!(sagcal::plot::figure_bytes(std::path::Path::new("f.svg"), svg).unwrap(), svg.as_bytes());
/// ```
pub fn figure_bytes(path: &Path, svg: &str) -> Result<Vec<u8>> {
    if is_png_path(path) {
        svg_to_png(svg, PNG_SCALE, &path.display().to_string())
    } else {
        Ok(svg.as_bytes().to_vec())
    }
}

//! Drawing helpers shared by every figure: text escaping, pixel coordinates,
//! haloed labels, the font and the common colours, and atomic file writing.

use std::fmt::Write as _;

/// Font stack of every figure.
pub(crate) const FONT: &str = "DejaVu Sans, Helvetica, Arial, sans-serif";
/// Body text.
pub(crate) const C_TEXT: &str = "#222222";
/// Secondary text.
pub(crate) const C_MUTED: &str = "#666666";
/// Grid lines.
pub(crate) const C_GRID: &str = "#e6e6e6";
/// Panel frames.
pub(crate) const C_FRAME: &str = "#9a9a9a";

/// Write `svg` to `path` atomically: the text goes to a temporary file in the
/// same directory, which is then renamed over `path`.
///
/// Errors are [`crate::Error::Io`] naming `path`; on error no file is left behind.
pub fn write_svg(path: &std::path::Path, svg: &str) -> crate::Result<()> {
    crate::io::write_atomically(path, svg.as_bytes())
}

/// A pixel coordinate for an attribute (always a finite number).
pub(crate) fn n2(x: f64) -> String {
    if x.is_finite() {
        format!("{:.2}", x + 0.0)
    } else {
        "0".to_owned()
    }
}

/// Escape text for XML content and attribute values; control characters become spaces.
pub(crate) fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 || c == '\u{7f}' => out.push(' '),
            '\u{FFFE}' | '\u{FFFF}' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

/// `s` cut to at most `max` characters (with an ellipsis).
pub(crate) fn shorten(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        s.to_owned()
    } else {
        let mut t: String = s.chars().take(max.saturating_sub(1)).collect();
        t.push('\u{2026}');
        t
    }
}

/// Rough width of `s` in pixels at `font` px (sans-serif average).
pub(crate) fn text_w(s: &str, font: f64) -> f64 {
    s.chars().count() as f64 * font * 0.6
}

/// Text with a white halo so it stays readable over grid and ellipses.
pub(crate) fn halo_text(s: &mut String, x: f64, y: f64, anchor: &str, fill: &str, text: &str) {
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="{anchor}" fill="{fill}" stroke="white" stroke-width="3" stroke-linejoin="round" paint-order="stroke">{}</text>"#,
        n2(x),
        n2(y),
        esc(text)
    );
}

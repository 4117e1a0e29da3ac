//! Drawing helpers shared by every figure: text escaping, pixel coordinates,
//! haloed labels, the font and the common colours.

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

/// `text` broken at spaces into lines that fit `max_w` pixels at `font` px
/// (a rough width of 0.62 em per character, bold included); a word longer
/// than a line is shortened with an ellipsis. Always at least one line.
pub(crate) fn wrap(text: &str, max_w: f64, font: f64) -> Vec<String> {
    let max_chars = ((max_w / (0.62 * font)).floor() as usize).max(8);
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let word = shorten(word, max_chars);
        let used = line.chars().count();
        if used > 0 && used + 1 + word.chars().count() > max_chars {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(&word);
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// One `<text>` of several lines (`<tspan>`s `line_h` apart), the first on baseline `y`.
pub(crate) fn text_lines(s: &mut String, x: f64, y: f64, line_h: f64, attrs: &str, lines: &[String]) {
    let _ = write!(s, r#"<text x="{}" y="{}" {attrs}>"#, n2(x), n2(y));
    for (i, line) in lines.iter().enumerate() {
        let dy = if i == 0 { 0.0 } else { line_h };
        let _ = write!(s, r#"<tspan x="{}" dy="{}">{}</tspan>"#, n2(x), n2(dy), esc(line));
    }
    let _ = writeln!(s, "</text>");
}

/// A figure's caption: `lines` (12 px, muted), the last one 12 px above `bottom`.
pub(crate) fn caption_text(s: &mut String, x: f64, bottom: f64, lines: &[String]) {
    let first = bottom - 12.0 - 16.0 * lines.len().saturating_sub(1) as f64;
    let attrs = format!(r#"class="caption" font-size="12" fill="{C_MUTED}""#);
    text_lines(s, x, first, 16.0, &attrs, lines);
}

#[cfg(test)]
mod tests {
    use super::wrap;

    #[test]
    fn wrap_keeps_every_word_within_the_width() {
        let text = "sagcal diagnose `large`: load_cell residual vs mid-span sag (m) (verdict: none)";
        let lines = wrap(text, 300.0, 20.0);
        // 300 px / (0.62 * 20 px) = 24 characters per line.
        assert!(lines.iter().all(|l| l.chars().count() <= 24), "{lines:?}");
        assert_eq!(lines.join(" "), text);
        assert_eq!(wrap("", 100.0, 12.0), vec![String::new()]);
        assert_eq!(
            wrap("abcdefghijklmnop", 62.0, 10.0),
            vec!["abcdefghi\u{2026}".to_string()],
            "10 characters with the ellipsis"
        );
    }
}

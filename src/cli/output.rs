//! Plain-text tables, JSON output and progress displays shared by the commands.

use std::io::IsTerminal;
use std::ops::Deref;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle, TermLike};
use serde::Serialize;

/// `n` things in words: `1 reading`, `2 readings` (`plural` for every count but one).
pub fn counted(n: usize, singular: &str, plural: &str) -> String {
    format!("{n} {}", if n == 1 { singular } else { plural })
}

/// A left-aligned first column, right-aligned others, columns sized to fit;
/// optionally a last column of free text, left-aligned and wrapped.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
    /// The last column's width in characters, its cells wrapped onto lines
    /// of their own (the other cells blank) at `, ` or at a space.
    wrap_last: Option<usize>,
}

impl Table {
    /// A table with these column titles.
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Self {
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
            wrap_last: None,
        }
    }

    /// Append a row (as many cells as the header).
    pub fn row<S: Into<String>>(&mut self, cells: impl IntoIterator<Item = S>) {
        self.rows.push(cells.into_iter().map(Into::into).collect());
    }

    /// Left-align the last column and wrap its cells at `width` characters,
    /// so that a list of parameters does not run the table off the screen.
    pub fn wrap_last(mut self, width: usize) -> Self {
        self.wrap_last = Some(width.max(1));
        self
    }

    /// The rows as printed: a wrapped last cell spread over several lines.
    fn lines(&self) -> Vec<Vec<String>> {
        let Some(width) = self.wrap_last else {
            return self.rows.clone();
        };
        let last = self.header.len().saturating_sub(1);
        let mut lines = Vec::new();
        for row in &self.rows {
            let cell = row.get(last).map(String::as_str).unwrap_or("");
            for (k, piece) in wrapped(cell, width).into_iter().enumerate() {
                let mut line: Vec<String> = if k == 0 {
                    row.iter().take(last).cloned().collect()
                } else {
                    vec![String::new(); last]
                };
                line.push(piece);
                lines.push(line);
            }
        }
        lines
    }
}

/// `text` in lines of at most `width` characters, broken after `, ` where it
/// can be and at a space otherwise (a word longer than `width` stays whole).
pub(super) fn wrapped(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in text.split(' ') {
        let fits = current.is_empty() || current.chars().count() + 1 + word.chars().count() <= width;
        if !fits {
            // Break after a list item: at the line's end when it ends one,
            // else after the last `, ` on it when it has one.
            match current.rfind(", ") {
                _ if current.ends_with(',') => lines.push(std::mem::take(&mut current)),
                Some(at) if at > 0 => {
                    let rest = current[at + 2..].to_string();
                    current.truncate(at + 1);
                    lines.push(std::mem::take(&mut current));
                    current = rest;
                }
                _ => lines.push(std::mem::take(&mut current)),
            }
        }
        if !current.is_empty() {
            current.push(' ');
        }
        current.push_str(word);
    }
    lines.push(current);
    lines
}

impl std::fmt::Display for Table {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let columns = self.header.len();
        let rows = self.lines();
        let widths: Vec<usize> = (0..columns)
            .map(|c| {
                std::iter::once(&self.header)
                    .chain(&rows)
                    .filter_map(|r| r.get(c))
                    .map(|s| s.chars().count())
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let line = |f: &mut std::fmt::Formatter<'_>, cells: &[String]| -> std::fmt::Result {
            for (c, width) in widths.iter().enumerate() {
                let cell = cells.get(c).map(String::as_str).unwrap_or("");
                if c == 0 {
                    write!(f, "{cell:<width$}")?;
                } else if self.wrap_last.is_some() && c + 1 == columns {
                    write!(f, "  {}", cell.trim_end())?;
                } else {
                    write!(f, "  {cell:>width$}")?;
                }
            }
            writeln!(f)
        };
        line(f, &self.header)?;
        let total: usize = widths.iter().sum::<usize>() + 2 * columns.saturating_sub(1);
        writeln!(f, "{}", "-".repeat(total))?;
        for row in &rows {
            line(f, row)?;
        }
        Ok(())
    }
}

/// `value` with `decimals` decimals, or `-` when there is none.
pub fn opt(value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.decimals$}"))
}

/// Where stderr is not a terminal (a pipe, a log file, `TERM=dumb`), where
/// indicatif would draw nothing, a progress display is written as a plain
/// line at most this often, and its final state once more at its end if it
/// wrote any: a run shorter than this adds nothing to a log.
pub const LOG_INTERVAL: Duration = Duration::from_secs(10);

/// A progress display on stderr ([`progress_bar`]): an indicatif bar (its
/// methods through `Deref`) redrawn in place on a terminal, written as lines
/// elsewhere.
pub struct Progress {
    bar: ProgressBar,
    /// The lines of a display that is not on a terminal.
    log: Option<Arc<LogLines>>,
}

impl Deref for Progress {
    type Target = ProgressBar;

    fn deref(&self) -> &ProgressBar {
        &self.bar
    }
}

impl Progress {
    /// Show `done` of `total` steps of `what` (a job's `(done, total, what)` report).
    pub fn report(&self, done: usize, total: usize, what: &str) {
        self.bar.set_message(what.to_string());
        self.bar.update(|state| {
            state.set_len(total as u64);
            state.set_pos(done as u64);
        });
    }

    /// End the display: cleared from a terminal; on a log, its final state
    /// written as a line if it wrote any before.
    pub fn finish_and_clear(&self) {
        match &self.log {
            None => self.bar.finish_and_clear(),
            Some(log) => {
                log.lock().finishing = true;
                self.bar.finish();
            }
        }
    }
}

/// A progress bar of `len` steps drawn with `template` (indicatif's syntax),
/// filled with `=>`, on stderr, ticking every second (so that its elapsed
/// time and estimate move while a step runs); not on a terminal, written as
/// lines ([`LOG_INTERVAL`]). Progress is never written to stdout.
pub fn progress_bar(len: u64, template: &str) -> Progress {
    let dumb = match std::env::var("TERM") {
        Ok(term) => term == "dumb",
        Err(_) => !cfg!(windows),
    };
    let log = (!std::io::stderr().is_terminal() || dumb).then(|| Arc::new(LogLines::default()));
    let target = match &log {
        None => ProgressDrawTarget::stderr(),
        Some(log) => ProgressDrawTarget::term_like_with_hz(Box::new(LogTarget(log.clone())), 1),
    };
    let bar = ProgressBar::with_draw_target(Some(len), target);
    bar.set_style(
        ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.enable_steady_tick(Duration::from_secs(1));
    Progress { bar, log }
}

/// What a display off the terminal has drawn, and when it last wrote a line.
#[derive(Debug)]
struct LogState {
    /// The text of the draw under way.
    drawn: String,
    /// When the last line was written (or the display began).
    last: Instant,
    /// Whether any line was written.
    wrote: bool,
    /// The next draw is the display's final state.
    finishing: bool,
}

/// The lines of a display off the terminal (see [`LOG_INTERVAL`]).
#[derive(Debug)]
struct LogLines(Mutex<LogState>);

impl Default for LogLines {
    fn default() -> Self {
        LogLines(Mutex::new(LogState {
            drawn: String::new(),
            last: Instant::now(),
            wrote: false,
            finishing: false,
        }))
    }
}

impl LogLines {
    fn lock(&self) -> MutexGuard<'_, LogState> {
        self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// indicatif's terminal for a display off the terminal: each draw collected,
/// then written as one line when it is due.
#[derive(Debug)]
struct LogTarget(Arc<LogLines>);

impl TermLike for LogTarget {
    fn width(&self) -> u16 {
        1000
    }

    fn move_cursor_up(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }

    fn move_cursor_down(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }

    fn move_cursor_right(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }

    fn move_cursor_left(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }

    fn write_line(&self, s: &str) -> std::io::Result<()> {
        self.write_str(s)
    }

    fn write_str(&self, s: &str) -> std::io::Result<()> {
        self.0.lock().drawn.push_str(s);
        Ok(())
    }

    fn clear_line(&self) -> std::io::Result<()> {
        self.0.lock().drawn.clear();
        Ok(())
    }

    fn flush(&self) -> std::io::Result<()> {
        let mut state = self.0.lock();
        let line = std::mem::take(&mut state.drawn);
        let line = line.trim_end();
        let due = if state.finishing {
            state.wrote
        } else {
            state.last.elapsed() >= LOG_INTERVAL
        };
        if !line.is_empty() && due {
            eprintln!("{line}");
            state.last = Instant::now();
            state.wrote = true;
        }
        Ok(())
    }
}

/// Serialise `value` as pretty JSON to stdout.
pub fn print_json<T: Serialize>(value: &T) -> sagcal::Result<()> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| sagcal::Error::InvalidInput(format!("cannot serialise the report as JSON: {e}")))?;
    println!("{text}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Off the terminal a draw becomes a line only when one is due: after
    /// [`LOG_INTERVAL`], or at the end of a display that wrote one.
    #[test]
    fn a_log_gets_a_line_when_one_is_due() {
        let lines = Arc::new(LogLines::default());
        let target = LogTarget(lines.clone());
        let draw = |text: &str| {
            target.clear_line().unwrap();
            target.write_str(text).unwrap();
            target.write_str("   ").unwrap();
            target.flush().unwrap();
        };
        draw("step [=>  ] 1/4, 0s");
        assert!(!lines.lock().wrote, "a line before it is due");
        lines.lock().last = Instant::now() - LOG_INTERVAL;
        draw("step [==> ] 2/4, 10s");
        let written = lines.lock().last;
        assert!(lines.lock().wrote && written.elapsed() < LOG_INTERVAL);
        assert!(lines.lock().drawn.is_empty(), "each draw starts afresh");
        lines.lock().finishing = true;
        draw("step [====] 4/4, 12s");
        assert!(lines.lock().last >= written, "the end is written");
    }

    /// A wrapped last column breaks after `, `, keeps every word, and leaves
    /// the other cells of its continuation lines blank.
    #[test]
    fn a_wrapped_last_column_breaks_after_commas() {
        let text = "alpha 1.0e0 (1e-1), beta 2.0e0 (2e-1), gamma 3.0e0 (3e-1)";
        let lines = wrapped(text, 40);
        assert_eq!(lines, ["alpha 1.0e0 (1e-1), beta 2.0e0 (2e-1),", "gamma 3.0e0 (3e-1)"]);
        // A line that ends an item breaks there; one that does not, after its last item.
        assert_eq!(wrapped("a 1, b 2, c 3", 9), ["a 1, b 2,", "c 3"]);
        assert_eq!(wrapped("a 1, b 2, c 3", 8), ["a 1,", "b 2, c 3"]);
        assert_eq!(wrapped("a 1, b 2 [why not]", 12), ["a 1,", "b 2 [why", "not]"]);
        assert_eq!(wrapped("a-very-long-single-word", 5), ["a-very-long-single-word"]);
        let mut table = Table::new(["step", "parameters"]).wrap_last(40);
        table.row(["1", text]);
        let printed = table.to_string();
        let rows: Vec<&str> = printed.lines().collect();
        assert_eq!(rows.len(), 4, "{printed}");
        assert_eq!(rows[2], "1     alpha 1.0e0 (1e-1), beta 2.0e0 (2e-1),");
        assert_eq!(rows[3], "      gamma 3.0e0 (3e-1)");
        assert!(printed.lines().all(|l| l.chars().count() <= 46), "{printed}");
    }
}

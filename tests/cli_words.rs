//! What the commands print speaks the robot's language: no Rust debug names
//! (`(Sagcal)`, `[Paper, Authors]`, `Catenary`), no internal function names,
//! no doubled error prefixes, and `1 reading`, not `1 readings`. Every
//! `--help` of every command is read, and the output of the jobs that run
//! in seconds.

use std::path::Path;

#[path = "common/cli.rs"]
mod cli;
use cli::{robot, sagcal};

/// Words a person should never read, with why.
const FORBIDDEN: &[(&str, &str)] = &[
    ("(Sagcal)", "a Rust debug name of a format"),
    ("(ReadingsOnly)", "a Rust debug name of a format"),
    ("(RecurDyn)", "a Rust debug name of a format"),
    ("(Authors)", "a Rust debug name of a format"),
    ("recur-dyn", "a serde name, not the tool's"),
    ("[Paper", "a Rust debug list of noise readings"),
    ("[Authors", "a Rust debug list of noise readings"),
    ("none noise", "no noise, in words"),
    ("Catenary cable", "a Rust debug name of the cable model"),
    ("Rigid cable", "a Rust debug name of the cable model"),
    ("Catenary model", "a Rust debug name of the cable model"),
    ("cramer_rao_bound", "a library function's name"),
    ("Some(", "a Rust Option"),
    ("None)", "a Rust Option"),
    (" 1 poses", "a singular"),
    (" 1 readings", "a singular"),
    (" 1 rows", "a singular"),
];

/// Why `text` (what `what` printed) is not for a person, or `None`.
fn unreadable(what: &str, text: &str) -> Option<String> {
    for line in text.lines() {
        let padded = format!(" {line}");
        if let Some((word, why)) = FORBIDDEN.iter().find(|(word, _)| padded.contains(word)) {
            return Some(format!("{what}: `{word}` ({why}) in: {line}"));
        }
        if line.matches("invalid input: ").count() > 1 {
            return Some(format!("{what}: a doubled `invalid input:` in: {line}"));
        }
        let lower = line.to_lowercase();
        let internal = [
            "issue 1", "issue 2", "issue 3", "issue 4", "issue 5", "issue 6", "issue 7",
        ];
        if let Some(word) = internal.iter().find(|w| lower.contains(*w)) {
            return Some(format!("{what}: `{word}` (the project's tracker) in: {line}"));
        }
    }
    None
}

/// The widest table diagnose may print, in columns (its parameter lists wrap).
const DIAGNOSE_TABLE_COLUMNS: usize = 150;

/// Why `text` has a table wider than `columns`, or `None`: a table's rule
/// (a line of dashes) spans the table.
fn too_wide(what: &str, text: &str, columns: usize) -> Option<String> {
    text.lines()
        .map(|l| l.chars().count())
        .zip(text.lines())
        .find(|(n, l)| *n > columns && l.chars().all(|c| c == '-'))
        .map(|(n, _)| format!("{what}: a table {n} columns wide, over {columns}"))
}

/// stdout and stderr of `sagcal ARGS` run in `dir`.
fn printed(dir: &Path, args: &[&str]) -> String {
    let out = sagcal(dir, args);
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The subcommands a `--help` lists under `Commands:` (without `help`).
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|line| !line.starts_with("Commands:"))
        .skip(1)
        .take_while(|line| line.starts_with("  "))
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

#[test]
fn the_self_check_finds_what_it_forbids() {
    assert!(unreadable("t", "sagcal localize: data d.csv (Sagcal)").is_some());
    assert!(unreadable("t", "x [Paper, Authors] noise").is_some());
    assert!(unreadable("t", "error: invalid input: a: invalid input: b").is_some());
    assert!(unreadable("t", "1 readings left out").is_some());
    assert!(unreadable("t", "as in issue 4's sweep").is_some());
    assert!(unreadable("t", "11 readings left out, 1 reading flagged").is_none());
    assert!(too_wide("t", &format!("a  b\n{}\n", "-".repeat(151)), 150).is_some());
    assert!(too_wide("t", &format!("a  b\n{}\n{}\n", "-".repeat(150), "x".repeat(200)), 150).is_none());
    let help = "Usage: x\n\nCommands:\n  plan  Plan\n  help  Print\n\nOptions:\n  -h\n";
    assert_eq!(subcommands(help), ["plan"]);
}

#[test]
fn every_help_text_is_free_of_internal_names() {
    let dir = tempfile::tempdir().unwrap();
    let mut pending: Vec<Vec<String>> = vec![vec![]];
    let mut read = 0;
    while let Some(command) = pending.pop() {
        for flag in ["--help", "-h"] {
            let mut args: Vec<&str> = command.iter().map(String::as_str).collect();
            args.push(flag);
            let help = printed(dir.path(), &args);
            assert!(help.contains("Usage:"), "{args:?}: {help}");
            if let Some(why) = unreadable(&args.join(" "), &help) {
                panic!("{why}");
            }
            read += 1;
            if flag == "--help" {
                for sub in subcommands(&help) {
                    let mut next = command.clone();
                    next.push(sub);
                    pending.push(next);
                }
            }
        }
    }
    assert!(read >= 20, "only {read} help texts read");
}

#[test]
fn the_quick_jobs_print_no_internal_names() {
    let dir = tempfile::tempdir().unwrap();
    let large = robot("large");
    let runs: Vec<Vec<&str>> = vec![
        vec!["demo", "--out-dir", "D"],
        vec![
            "simulate", "--robot", &large, "--poses", "1", "--noise", "none", "--seed", "4", "--out", "one.csv",
        ],
        vec!["calibrate", "--robot", "D/guess.toml", "--data", "D/data.csv"],
        vec!["localize", "--robot", "D/calibrated.toml", "--data", "D/data.csv"],
        vec!["verify", "--robot", "D/calibrated.toml", "--data", "D/data.csv"],
        vec![
            "calibrate",
            "--robot",
            "D/guess.toml",
            "--data",
            "D/data.csv",
            "--noise",
            "loud",
        ],
        vec!["calibrate", "--robot", "D/guess.toml", "--data", "no-such.csv"],
    ];
    for args in runs {
        let text = printed(dir.path(), &args);
        if let Some(why) = unreadable(&args.join(" "), &text) {
            panic!("{why}");
        }
    }
    // diagnose's tables (candidates with their parameters, sensors, drivers)
    // fit a wide terminal: a table's rule is as wide as the table.
    let diagnosis = printed(
        dir.path(),
        &["diagnose", "--robot", "D/guess.toml", "--data", "D/data.csv"],
    );
    assert!(diagnosis.contains("parameters (1-sigma)"), "{diagnosis}");
    if let Some(why) = too_wide("diagnose", &diagnosis, DIAGNOSE_TABLE_COLUMNS) {
        panic!("{why}");
    }
    let one = printed(
        dir.path(),
        &[
            "simulate", "--robot", &large, "--poses", "1", "--noise", "none", "--out", "two.csv",
        ],
    );
    assert!(one.contains("1 pose of robot `large` without noise"), "{one}");
}

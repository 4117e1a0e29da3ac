//! `docs/your-robot.md`, run as a user would: every `sh` block in order in
//! one empty folder, each line of the `text` block after a command found in
//! what the command printed, and `sh exit 1` blocks exiting 1.

use std::process::Command;

#[path = "common/doc_pages.rs"]
#[allow(dead_code)] // the recipe uses only the blocks
mod doc_pages;
use doc_pages::{blocks, page};

/// The words of a command line as a page prints it (no quoting needed: the
/// page's commands have no spaces inside an argument).
fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

#[test]
fn the_recipe_runs_as_the_page_says() {
    let text = page("your-robot.md");
    let all = blocks(&text);
    let dir = tempfile::tempdir().unwrap();
    let mut last: Option<(String, String)> = None;
    let (mut commands, mut checked) = (0, 0);
    for block in &all {
        match block.info.first().map(String::as_str) {
            Some("sh") => {
                let line = block.text.trim();
                assert_eq!(block.text.lines().count(), 1, "one command per block: {line}");
                let args = words(line);
                assert_eq!(args[0], "sagcal", "{line}");
                let out = Command::new(env!("CARGO_BIN_EXE_sagcal"))
                    .args(&args[1..])
                    .current_dir(dir.path())
                    .output()
                    .unwrap();
                let expected = if block.info.get(1..) == Some(&["exit".to_string(), "1".to_string()][..]) {
                    1
                } else {
                    0
                };
                let printed = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
                assert_eq!(out.status.code(), Some(expected), "{line}:\n{printed}");
                last = Some((line.to_string(), printed));
                commands += 1;
            }
            Some("text") => {
                let (line, printed) = last.take().expect("a text block follows a command");
                let printed_lines: Vec<&str> = printed.lines().map(str::trim_end).collect();
                for wanted in block.text.lines() {
                    assert!(
                        printed_lines.contains(&wanted.trim_end()),
                        "docs/your-robot.md: `{line}` does not print\n{wanted}\nit prints:\n{printed}"
                    );
                    checked += 1;
                }
            }
            other => panic!("docs/your-robot.md: a block of `{other:?}`: only sh and text are run"),
        }
    }
    assert!(commands >= 7 && checked >= 10, "{commands} commands, {checked} lines");
    // What the recipe leaves: a calibrated robot with the rope's stiffness, and the poses.
    let extended = sagcal::model::Robot::from_file(&dir.path().join("yard-extended.toml")).unwrap();
    let stiffness = extended
        .effects
        .axial_stiffness_n
        .expect("the stiffness is in the robot file");
    assert!((stiffness - 1.5e6).abs() < 0.15 * 1.5e6, "{stiffness}");
    assert!(dir.path().join("poses.csv").exists());
    assert!(
        !dir.path().join("yard-calibrated.toml").exists(),
        "a refused calibration writes nothing"
    );
}

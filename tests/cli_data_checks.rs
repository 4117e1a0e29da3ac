//! `sagcal calibrate` on damaged data made from `sagcal demo`'s folder: every
//! case exits non-zero naming the row, line and field (or the option), and
//! writes nothing; quoted numbers are read as numbers.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// Run `sagcal ARGS` in `dir`.
fn sagcal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

/// The folder `sagcal demo` writes, made once for every test of this file.
fn demo() -> &'static Path {
    static DEMO: OnceLock<tempfile::TempDir> = OnceLock::new();
    DEMO.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let out = sagcal(dir.path(), &["demo"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        dir
    })
    .path()
}

/// `D/data.csv`'s lines.
fn data_lines() -> Vec<String> {
    std::fs::read_to_string(demo().join("sagcal-demo/data.csv"))
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// The index in [`data_lines`] of data row `row` (1-based).
fn line_of_row(lines: &[String], row: usize) -> usize {
    let header = lines.iter().position(|l| l.starts_with("x_m,")).unwrap();
    header + row
}

/// `D/data.csv` with field `column` (0-based) of data row `row` (1-based) set to `value`, in `dir`.
fn with_field(dir: &Path, name: &str, row: usize, column: usize, value: &str) -> PathBuf {
    let mut lines = data_lines();
    let i = line_of_row(&lines, row);
    let mut fields: Vec<String> = lines[i].split(',').map(str::to_string).collect();
    fields[column] = value.to_string();
    lines[i] = fields.join(",");
    write(dir, name, &lines)
}

fn write(dir: &Path, name: &str, lines: &[String]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

/// `sagcal calibrate --robot D/guess.toml --data DATA EXTRA...` in `dir`.
fn calibrate(dir: &Path, data: &Path, extra: &[&str]) -> Output {
    let guess = demo().join("sagcal-demo/guess.toml");
    let mut args = vec![
        "calibrate",
        "--robot",
        guess.to_str().unwrap(),
        "--data",
        data.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    sagcal(dir, &args)
}

/// Assert a refusal (non-zero exit, no `--out` file) whose message holds every one of `needles`.
fn assert_refused(out: &Output, dir: &Path, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        !out.status.success(),
        "exit 0: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    for needle in needles {
        assert!(stderr.contains(needle), "`{needle}` not in: {stderr}");
    }
    assert!(!dir.join("o.toml").exists(), "a robot file was written");
    stderr
}

#[test]
fn every_row_written_twice_is_refused_naming_both_rows() {
    let dir = tempfile::tempdir().unwrap();
    let lines = data_lines();
    let header = line_of_row(&lines, 0);
    let mut twice = lines.clone();
    twice.extend_from_slice(&lines[header + 1..]);
    let data = write(dir.path(), "twice.csv", &twice);
    let out = calibrate(dir.path(), &data, &["--out", "o.toml"]);
    assert_refused(
        &out,
        dir.path(),
        &[
            "rows 1 and 36 (lines 3 and 38) hold the same readings",
            "35 such pairs in all",
            "delete one of them",
        ],
    );
}

#[test]
fn a_row_repeated_at_printed_precision_is_a_duplicate() {
    // Row 4 again as row 36, printed with 5 decimals (angles 4, tension 3):
    // the same pose, readings identical to the printed precision.
    let dir = tempfile::tempdir().unwrap();
    let mut lines = data_lines();
    let row = &lines[line_of_row(&lines, 4)];
    let rounded: Vec<String> = row
        .split(',')
        .enumerate()
        .map(|(c, v)| {
            let v: f64 = v.parse().unwrap();
            match c {
                3..=5 => format!("{v:.4}"),
                10 => format!("{v:.3}"),
                _ => format!("{v:.5}"),
            }
        })
        .collect();
    lines.push(rounded.join(","));
    let data = write(dir.path(), "again.csv", &lines);
    let out = calibrate(dir.path(), &data, &["--out", "o.toml"]);
    assert_refused(
        &out,
        dir.path(),
        &["rows 4 and 36 (lines 6 and 38) hold the same readings"],
    );
}

#[test]
fn sigmas_the_data_cannot_beat_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let data = demo().join("sagcal-demo/data.csv");
    let huge = [
        "--encoder-sigma-m",
        "1e300",
        "--position-sigma-m",
        "1e300",
        "--load-cell-sigma-n",
        "1e300",
        "--out",
        "o.toml",
    ];
    let stderr = assert_refused(
        &calibrate(dir.path(), &data, &huge),
        dir.path(),
        &["the encoder sigma 1e300 m is larger than the robot's size (341.2063 m)"],
    );
    assert!(stderr.len() < 600, "a number printed in full: {stderr}");
    // Within the options' range, but still too uncertain for these 35 poses:
    // the fit itself finds that the data did not determine the anchors.
    let wide = [
        "--encoder-sigma-m",
        "300",
        "--position-sigma-m",
        "300",
        "--load-cell-sigma-n",
        "300",
        "--out",
        "o.toml",
    ];
    assert_refused(
        &calibrate(dir.path(), &data, &wide),
        dir.path(),
        &[
            "fails its own consistency tests",
            "the data do not determine the anchors",
        ],
    );
    assert_refused(
        &calibrate(dir.path(), &data, &["--encoder-sigma-m", "1e-300", "--out", "o.toml"]),
        dir.path(),
        &["the encoder sigma 1e-300 m is below 1e-6 m"],
    );
}

#[test]
fn an_absurd_encoder_reading_is_named_in_any_row() {
    let dir = tempfile::tempdir().unwrap();
    for row in [1, 4, 5, 19, 35] {
        let data = with_field(dir.path(), &format!("l1_{row}.csv"), row, 6, "1e6");
        let out = calibrate(dir.path(), &data, &["--out", "o.toml"]);
        let named = format!("row {row} (line {}), field `l1_m`: 1e6 m", row + 2);
        assert_refused(&out, dir.path(), &[&named, "impossible for this robot"]);
    }
}

#[test]
fn an_absurd_load_cell_reading_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let data = with_field(dir.path(), "f.csv", 7, 10, "1e300");
    assert_refused(
        &calibrate(dir.path(), &data, &["--out", "o.toml"]),
        dir.path(),
        &["row 7 (line 9), field `f_ref_n`: 1e300 N"],
    );
}

#[test]
fn a_roll_of_400_degrees_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let data = with_field(dir.path(), "roll.csv", 12, 3, "400");
    assert_refused(
        &calibrate(dir.path(), &data, &["--out", "o.toml"]),
        dir.path(),
        &["row 12 (line 14), field `roll_deg`: 400 deg is outside -180..180"],
    );
}

#[test]
fn data_in_millimetres_say_why_every_row_was_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let lines: Vec<String> = data_lines()
        .into_iter()
        .map(|l| {
            if l.starts_with('#') || l.starts_with("x_m") {
                return l;
            }
            l.split(',')
                .enumerate()
                .map(|(c, v)| {
                    let v: f64 = v.parse().unwrap();
                    if matches!(c, 0..=2 | 6..=9) {
                        format!("{}", v * 1000.0)
                    } else {
                        format!("{v}")
                    }
                })
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    let data = write(dir.path(), "mm.csv", &lines);
    assert_refused(
        &calibrate(dir.path(), &data, &["--out", "o.toml"]),
        dir.path(),
        &[
            "35 of 35 rows are left out because the localiser's position is outside the robot's frame",
            "row 1 (line 3)",
            "the positions look like mm, not m",
        ],
    );
}

#[test]
fn quoted_numbers_read_as_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let lines: Vec<String> = data_lines()
        .into_iter()
        .map(|l| {
            if l.starts_with('#') || l.starts_with("x_m") {
                return l;
            }
            l.split(',').map(|v| format!("\"{v}\"")).collect::<Vec<_>>().join(",")
        })
        .collect();
    let quoted = write(dir.path(), "quoted.csv", &lines);
    let plain = demo().join("sagcal-demo/data.csv");
    let a = calibrate(dir.path(), &plain, &["--json"]);
    let b = calibrate(dir.path(), &quoted, &["--json"]);
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn a_search_that_gives_up_does_not_contradict_itself() {
    // The encoders stated 2.5 times more precise than they are: the search
    // leaves readings out, then gives up and reports the fit with all of them.
    let dir = tempfile::tempdir().unwrap();
    let data = demo().join("sagcal-demo/data.csv");
    let out = calibrate(dir.path(), &data, &["--encoder-sigma-m", "0.004", "--out", "o.toml"]);
    assert_refused(&out, dir.path(), &["fails its own consistency tests"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("set aside: row "), "{stdout}");
    assert!(!stdout.contains("no reading left out\n"), "{stdout}");
    assert!(
        stdout.contains(
            "gave up after leaving out 2 readings, so the fit reported leaves none out (they are listed as set aside)"
        ),
        "{stdout}"
    );
}

#[test]
fn one_mistyped_roll_in_range_is_that_rows_blunder() {
    // Roll 40 degrees in row 12 (the others within about 3): the orientation
    // prior stays for every pose and the row's reading is the one left out.
    let dir = tempfile::tempdir().unwrap();
    let data = with_field(dir.path(), "roll40.csv", 12, 3, "40");
    let out = calibrate(dir.path(), &data, &["--out", "o.toml"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}{stdout}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("rad prior, kept"), "{stdout}");
    assert!(
        stdout.contains("1 reading left out as gross errors:\n  row 12 (line 14), localiser orientation about x"),
        "{stdout}"
    );
}

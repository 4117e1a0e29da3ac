//! Property-based tests of the three loaders: the sagcal measurement CSV
//! (`io::measurements`), the RecurDyn log (`io::recurdyn`) and the robot TOML
//! (`io::robot_file`). Random bytes, rows with valid headers and random or
//! mutated fields (empty, huge, NaN, inf, negative, text, missing and extra
//! columns) and random numbers are written to a temporary file and loaded:
//! no loader panics, every error names the file, and whatever loads holds
//! what the loader promises (finite values, positive tensions and lengths).
//!
//! Few cases per property (`CASES`) so that the file runs in seconds.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use sagcal::io::measurements::{read_measurements, ReadOptions, MEASUREMENT_HEADER};
use sagcal::io::recurdyn::{read_recurdyn, LoadOptions};
use sagcal::model::Robot;

/// Cases per property.
const CASES: u32 = 64;

/// The RecurDyn header (22 named columns and the empty marker column).
const RECURDYN_HEADER: &str = "x,y,z,pitch,roll,yaw,L1,L2,L3,L4,fc1,fz1,fh1,fc2,fz2,fh2,fc3,fz3,fh3,fc4,fz4,fh4,";

/// Fields of a RecurDyn row: 22 data columns and the marker.
const RECURDYN_FIELDS: usize = 23;

/// The large robot's file, the seed of the mutated robot files.
const LARGE_TOML: &str = include_str!("../robots/large.toml");

/// A temporary directory holding `bytes` as `name`.
fn temp_file(name: &str, bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).expect("the temporary file is written");
    (dir, path)
}

/// An error must name the file it is about.
fn names_file(error: &sagcal::Error, path: &Path) -> Result<(), TestCaseError> {
    let message = error.to_string();
    prop_assert!(
        message.contains(&path.display().to_string()),
        "the error does not name {}: {message}",
        path.display()
    );
    Ok(())
}

/// Load `bytes` as a measurement file with a few options: an error names the
/// file, measurements are finite with a positive reference tension. The errors, if any.
fn check_measurements(bytes: &[u8]) -> Result<Vec<sagcal::Error>, TestCaseError> {
    let (_dir, path) = temp_file("fuzzed measurements.csv", bytes);
    let mut errors = Vec::new();
    for (reference_cable, keep_rounded) in [(0, false), (1, true), (3, false)] {
        let options = ReadOptions {
            reference_cable,
            keep_rounded,
        };
        match read_measurements(&path, &options) {
            Ok(set) => {
                prop_assert_eq!(&set.path, &path);
                prop_assert!(!set.poses.is_empty());
                for pose in &set.poses {
                    let values = pose.position_m.iter().chain(&pose.encoder_lengths_m).chain([
                        &pose.roll_deg,
                        &pose.pitch_deg,
                        &pose.yaw_deg,
                        &pose.reference_tension_n,
                    ]);
                    for value in values {
                        prop_assert!(value.is_finite(), "line {}: {value}", pose.line);
                    }
                    prop_assert!(pose.reference_tension_n > 0.0, "line {}", pose.line);
                }
            }
            Err(error) => {
                names_file(&error, &path)?;
                errors.push(error);
            }
        }
    }
    Ok(errors)
}

/// Load `bytes` as a RecurDyn log: an error names the file, kept rows are
/// finite with positive lengths and the reference cable's tension. The errors, if any.
fn check_recurdyn(bytes: &[u8]) -> Result<Vec<sagcal::Error>, TestCaseError> {
    let (_dir, path) = temp_file("fuzzed recurdyn.csv", bytes);
    let mut errors = Vec::new();
    for keep_rounded in [false, true] {
        match read_recurdyn(&path, &LoadOptions { keep_rounded }) {
            Ok(log) => {
                prop_assert!(!(log.rows.is_empty() && log.rejected.is_empty()));
                for row in &log.rows {
                    let angles = [row.roll_deg, row.pitch_deg, row.yaw_deg];
                    for value in row.position_m.iter().chain(&angles) {
                        prop_assert!(value.is_finite(), "line {}: {value}", row.line);
                    }
                    for length in row.cable_lengths_m {
                        prop_assert!(length.is_finite() && length > 0.0, "line {}: {length}", row.line);
                    }
                    prop_assert!(row.tensions[0].is_some(), "line {}", row.line);
                    for tension in row.tensions.iter().flatten() {
                        prop_assert!(tension.total_n.is_finite() && tension.total_n > 0.0);
                        prop_assert!(tension.vertical_n.is_finite());
                        prop_assert!(tension.horizontal_n.is_none_or(|h| h.is_finite() && h >= 0.0));
                    }
                }
            }
            Err(error) => {
                names_file(&error, &path)?;
                errors.push(error);
            }
        }
    }
    Ok(errors)
}

/// A row error must point at line `line`, and at column `field` when given.
fn points_at(errors: &[sagcal::Error], line: usize, field: Option<&str>) -> Result<(), TestCaseError> {
    for error in errors {
        if let sagcal::Error::Field {
            line: at, field: named, ..
        } = error
        {
            prop_assert_eq!(*at, Some(line), "{}", error);
            if let Some(field) = field {
                prop_assert_eq!(named, field, "{}", error);
            }
        }
    }
    Ok(())
}

/// `lines` with each `(at, blank)` inserted before line `at` (wrapping).
fn with_blank_lines(mut lines: Vec<String>, blanks: &[(usize, &str)]) -> Vec<String> {
    for (at, blank) in blanks {
        lines.insert(at % (lines.len() + 1), (*blank).to_string());
    }
    lines
}

/// Blank lines: empty or whitespace only.
fn blank_lines() -> impl Strategy<Value = Vec<(usize, &'static str)>> {
    proptest::collection::vec(
        (
            any::<usize>(),
            proptest::sample::select(vec!["", " ", "\t", "  \t ", "\r"]),
        ),
        0..4,
    )
}

/// Load `text` as a robot file: an error names the file, a robot is finite
/// with a reference cable that exists.
fn check_robot(text: &[u8]) -> Result<(), TestCaseError> {
    let (_dir, path) = temp_file("fuzzed robot.toml", text);
    match Robot::from_file(&path) {
        Ok(robot) => {
            prop_assert!(robot.reference_cable < 4);
            let points = robot.anchors_m.iter().chain(&robot.attachments_m);
            for point in points.chain([&robot.com_offset_m]) {
                prop_assert!(point.iter().all(|x| x.is_finite()), "{point:?}");
            }
            prop_assert!(robot.platform_weight_n.is_finite() && robot.platform_weight_n > 0.0);
            prop_assert!(robot.cable_weight_n_per_m.is_finite() && robot.cable_weight_n_per_m >= 0.0);
            prop_assert!(robot.length_offsets_m.iter().all(|x| x.is_finite()));
        }
        Err(error) => names_file(&error, &path)?,
    }
    Ok(())
}

/// Tokens a hand-edited or corrupted file may hold where a number belongs.
const ODD_FIELDS: &[&str] = &[
    "",
    "  ",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "+infinity",
    "1e400",
    "-1e400",
    "1e-400",
    "0",
    "-0",
    "-1",
    "-5e3",
    "1e308",
    "-1.7976931348623157e308",
    "0e99999999999",
    "0e400",
    "1e-99999999999",
    "5e-324",
    "abc",
    "1,5",
    "\"1\"",
    "\"",
    "0x10",
    "1.2.3",
    "--1",
    "1e",
    "e5",
    ".",
    "#",
    "\u{feff}1",
    "é",
    "\r",
    "\t7\t",
];

/// One field of a CSV row: mostly a plausible number, often something odd.
fn field() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-500.0..500.0f64).prop_map(|v| v.to_string()),
        2 => proptest::sample::select(ODD_FIELDS).prop_map(String::from),
        1 => any::<f64>().prop_map(|v| format!("{v:e}")),
        1 => "[0-9]{1,400}(\\.[0-9]{0,400})?",
        1 => "[ -~]{0,12}",
        1 => "\\PC{0,6}",
    ]
}

/// A row of `n - 2 ..= n + 2` random fields (missing and extra columns too).
fn random_row(n: usize) -> impl Strategy<Value = String> {
    proptest::collection::vec(field(), n.saturating_sub(2)..=n + 2).prop_map(|fields| fields.join(","))
}

/// A file of `header` and `rows`, with `\n` or `\r\n` line endings.
fn file_of(header: &str, rows: &[String], crlf: bool) -> Vec<u8> {
    let end = if crlf { "\r\n" } else { "\n" };
    let mut text = format!("{header}{end}");
    for row in rows {
        text += row;
        text += end;
    }
    text.into_bytes()
}

/// A valid sagcal measurement row (the reference tension positive).
fn sagcal_row() -> impl Strategy<Value = Vec<String>> {
    (proptest::collection::vec(-200.0..200.0f64, 10), 1e-3..2000.0f64)
        .prop_map(|(values, tension)| values.iter().chain([&tension]).map(|v| v.to_string()).collect())
}

/// A valid RecurDyn row: positive lengths, consistent tensions on cable 1
/// and on some of cables 2..4 (`fh` sometimes left out), a marker sometimes.
fn recurdyn_row() -> impl Strategy<Value = Vec<String>> {
    let tension = (0.0..1000.0f64, 0.0..1000.0f64, 0..3u8);
    (
        proptest::collection::vec(-50.0..50.0f64, 6),
        proptest::collection::vec(0.5..300.0f64, 4),
        proptest::collection::vec(tension, 4),
        proptest::sample::select(vec!["", "", "marker", "x"]),
    )
        .prop_map(|(pose, lengths, tensions, marker)| {
            let mut fields: Vec<String> = pose.iter().chain(&lengths).map(|v| v.to_string()).collect();
            for (c, (fz, fh, shape)) in tensions.into_iter().enumerate() {
                let fc = fz.hypot(fh).max(1e-3);
                let given = match (c, shape) {
                    (0, _) | (_, 2) => [Some(fc), Some(fz), Some(fh)],
                    (_, 1) => [Some(fc), Some(fz), None],
                    _ => [None; 3],
                };
                fields.extend(given.map(|v| v.map(|v| v.to_string()).unwrap_or_default()));
            }
            fields.push(marker.to_string());
            fields
        })
}

/// `rows` with field `index` of row `which` replaced by `value` (indices wrap).
fn mutate(mut rows: Vec<Vec<String>>, which: usize, index: usize, value: String) -> Vec<String> {
    let n = rows.len();
    let row = &mut rows[which % n];
    let i = index % row.len();
    row[i] = value;
    rows.into_iter().map(|r| r.join(",")).collect()
}

/// A number as a CSV field, in one of Rust's spellings (`NaN`, `inf` included).
fn number_field() -> impl Strategy<Value = String> {
    (any::<f64>(), 0..3u8).prop_map(|(v, style)| match style {
        0 => format!("{v}"),
        1 => format!("{v:e}"),
        _ => format!("{v:?}"),
    })
}

/// A TOML float in any spelling TOML has (`nan`, `inf`, `-inf` included).
fn toml_float(v: f64) -> String {
    match v {
        v if v.is_nan() => "nan".to_string(),
        v if v.is_infinite() => if v > 0.0 { "inf" } else { "-inf" }.to_string(),
        v => format!("{v:?}"),
    }
}

/// A TOML array of floats.
fn toml_floats(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|v| toml_float(*v)).collect();
    format!("[{}]", items.join(", "))
}

/// A float for robot files: small, huge, zero, negative, NaN, infinite.
fn robot_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -200.0..200.0f64,
        1 => any::<f64>(),
        1 => proptest::sample::select(vec![0.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e308, -1e-300]),
    ]
}

/// A robot TOML with random numbers: 0..6 cables, any reference cable, and
/// optional offsets, workspace, effects and paper robot.
fn robot_toml() -> impl Strategy<Value = String> {
    let cable = proptest::collection::vec(robot_number(), 6);
    (
        (any::<i64>(), 0..6i64, any::<bool>()),
        proptest::collection::vec(robot_number(), 5),
        proptest::collection::vec(cable, 0..6),
        proptest::option::of(proptest::collection::vec(robot_number(), 0..6)),
        proptest::option::of(proptest::collection::vec(robot_number(), 6)),
        proptest::option::of(proptest::collection::vec(robot_number(), 9)),
        proptest::sample::select(vec!["", "large", "small", "medium", "LARGE"]),
    )
        .prop_map(
            |((any_ref, small_ref, pick), scalars, cables, offsets, workspace, effects, paper)| {
                let reference = if pick { small_ref } else { any_ref };
                let mut text = format!(
                "name = \"fuzzed\"\nreference_cable = {reference}\nplatform_weight_n = {}\ncable_weight_n_per_m = {}\n\
                 com_offset_m = {}\n",
                toml_float(scalars[0]),
                toml_float(scalars[1]),
                toml_floats(&scalars[2..5]),
            );
                if !paper.is_empty() {
                    text += &format!("paper_robot = \"{paper}\"\n");
                }
                if let Some(offsets) = offsets {
                    text += &format!("length_offsets_m = {}\n", toml_floats(&offsets));
                }
                for c in &cables {
                    text += &format!(
                        "\n[[cables]]\nanchor_m = {}\nattachment_m = {}\n",
                        toml_floats(&c[..3]),
                        toml_floats(&c[3..])
                    );
                }
                if let Some(w) = workspace {
                    text += &format!(
                        "\n[workspace]\nmin_m = {}\nmax_m = {}\n",
                        toml_floats(&w[..3]),
                        toml_floats(&w[3..])
                    );
                }
                if let Some(e) = effects {
                    text += &format!(
                        "\n[effects]\naxial_stiffness_n = {}\npulley_radius_m = {}\nencoder_gain = {}\n\
                     load_cell_bias_n = {}\nload_cell_gain = {}\ncable_segments = {}\n",
                        toml_float(e[0]),
                        toml_float(e[1]),
                        toml_floats(&e[2..6]),
                        toml_float(e[6]),
                        toml_float(e[7]),
                        toml_float(e[8]),
                    );
                }
                text
            },
        )
}

/// Values that may replace the value of a `key = value` line of a robot file.
fn toml_value() -> impl Strategy<Value = String> {
    prop_oneof![
        2 => robot_number().prop_map(toml_float),
        1 => any::<i64>().prop_map(|v| v.to_string()),
        1 => proptest::collection::vec(robot_number(), 0..6).prop_map(|v| toml_floats(&v)),
        1 => proptest::sample::select(vec![
            "", "\"large\"", "\"text\"", "true", "[]", "{}", "[1, \"a\"]", "1979-05-27", "99999999999999999999", "-1",
            "0", "nan", "+inf", "[[", "\"\\u0000\"",
        ])
        .prop_map(String::from),
        1 => "[ -~]{0,12}",
    ]
}

/// One edit of a robot file's lines.
#[derive(Debug, Clone)]
enum Edit {
    /// Replace the value of line `n` (when it is `key = value`).
    Value(usize, String),
    /// Delete line `n`.
    Delete(usize),
    /// Repeat line `n`.
    Repeat(usize),
    /// Insert a line before line `n`.
    Insert(usize, String),
}

/// Apply `edits` to the large robot's file (line indices wrap).
fn edited_large(edits: &[Edit]) -> String {
    let mut lines: Vec<String> = LARGE_TOML.lines().map(String::from).collect();
    for edit in edits {
        let n = lines.len().max(1);
        match edit {
            Edit::Value(i, value) => {
                if let Some(line) = lines.get_mut(i % n) {
                    if let Some((key, _)) = line.split_once('=') {
                        *line = format!("{key}= {value}");
                    }
                }
            }
            Edit::Delete(i) if !lines.is_empty() => {
                lines.remove(i % n);
            }
            Edit::Repeat(i) if !lines.is_empty() => {
                let line = lines[i % n].clone();
                lines.insert(i % n, line);
            }
            Edit::Insert(i, line) => lines.insert(i % n, line.clone()),
            _ => {}
        }
    }
    lines.join("\n")
}

/// Random edits of a robot file.
fn edits() -> impl Strategy<Value = Vec<Edit>> {
    let edit = prop_oneof![
        4 => (any::<usize>(), toml_value()).prop_map(|(i, v)| Edit::Value(i, v)),
        1 => any::<usize>().prop_map(Edit::Delete),
        1 => any::<usize>().prop_map(Edit::Repeat),
        1 => (any::<usize>(), proptest::sample::select(vec![
            "extra = 1", "[cables]", "[[cables]]", "[effects]", "[workspace]", "paper_robot = \"small\"",
            "anchor_m = [1.0, 2.0, 3.0]", "name = \"again\"", "[unknown]",
        ]))
            .prop_map(|(i, line)| Edit::Insert(i, line.to_string())),
    ];
    proptest::collection::vec(edit, 1..5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        check_measurements(&bytes)?;
        check_recurdyn(&bytes)?;
        check_robot(&bytes)?;
    }

    #[test]
    fn random_bytes_after_a_valid_header_never_panic(
        bytes in proptest::collection::vec(any::<u8>(), 0..600),
        sagcal_header in any::<bool>(),
    ) {
        let header = if sagcal_header { MEASUREMENT_HEADER.join(",") } else { RECURDYN_HEADER.to_string() };
        let file = [format!("{header}\n").into_bytes(), bytes].concat();
        check_measurements(&file)?;
        check_recurdyn(&file)?;
    }

    #[test]
    fn random_sagcal_rows_never_panic(
        rows in proptest::collection::vec(random_row(MEASUREMENT_HEADER.len()), 0..5),
        crlf in any::<bool>(),
    ) {
        check_measurements(&file_of(&MEASUREMENT_HEADER.join(","), &rows, crlf))?;
    }

    #[test]
    fn random_recurdyn_rows_never_panic(
        rows in proptest::collection::vec(random_row(RECURDYN_FIELDS), 0..5),
        crlf in any::<bool>(),
    ) {
        let file = file_of(RECURDYN_HEADER, &rows, crlf);
        check_measurements(&file)?;
        check_recurdyn(&file)?;
    }

    #[test]
    fn one_mutated_field_of_valid_rows_loads_or_is_an_error_at_its_row(
        sagcal in proptest::collection::vec(sagcal_row(), 1..4),
        recurdyn in proptest::collection::vec(recurdyn_row(), 1..4),
        (which, index, value) in (any::<usize>(), any::<usize>(), field()),
        crlf in any::<bool>(),
    ) {
        // Header on line 1, row k (0-based) on line k + 2: errors point at the mutated row.
        let line = 2 + which % sagcal.len();
        let field = (!value.contains(',')).then_some(MEASUREMENT_HEADER[index % MEASUREMENT_HEADER.len()]);
        let file = file_of(&MEASUREMENT_HEADER.join(","), &mutate(sagcal, which, index, value.clone()), crlf);
        points_at(&check_measurements(&file)?, line, field)?;
        let line = 2 + which % recurdyn.len();
        let file = file_of(RECURDYN_HEADER, &mutate(recurdyn, which, index, value.clone()), crlf);
        let mut errors = check_measurements(&file)?;
        errors.extend(check_recurdyn(&file)?);
        // A quote opens a quoted CSV field that may run over the following rows.
        if !value.contains('"') {
            points_at(&errors, line, None)?;
        }
    }

    #[test]
    fn blank_lines_are_ignored_by_both_formats(
        sagcal in proptest::collection::vec(sagcal_row(), 1..4),
        recurdyn in proptest::collection::vec(recurdyn_row(), 1..4),
        blanks in blank_lines(),
    ) {
        let header = MEASUREMENT_HEADER.join(",");
        let lines: Vec<String> = std::iter::once(header).chain(sagcal.iter().map(|r| r.join(","))).collect();
        let (_dir, clean) = temp_file("clean.csv", lines.join("\n").as_bytes());
        let (_dir, blank) = temp_file("blank.csv", with_blank_lines(lines, &blanks).join("\n").as_bytes());
        // The poses but their line numbers; `None` when every row is rejected (a RecurDyn log).
        let values = |path: &Path| {
            let set = read_measurements(path, &ReadOptions::default()).ok()?;
            let unnumbered = |p: &sagcal::model::PoseMeasurement| sagcal::model::PoseMeasurement { line: 0, ..*p };
            Some(set.poses.iter().map(|p| format!("{:?}", unnumbered(p))).collect::<Vec<_>>())
        };
        prop_assert!(values(&clean).is_some());
        prop_assert_eq!(values(&clean), values(&blank));

        let lines: Vec<String> =
            std::iter::once(RECURDYN_HEADER.to_string()).chain(recurdyn.iter().map(|r| r.join(","))).collect();
        let (_dir, clean) = temp_file("clean.csv", lines.join("\n").as_bytes());
        let (_dir, blank) = temp_file("blank.csv", with_blank_lines(lines, &blanks).join("\n").as_bytes());
        prop_assert_eq!(values(&clean), values(&blank));
        let rows = |path: &Path| -> Result<(Vec<String>, usize), TestCaseError> {
            let log = read_recurdyn(path, &LoadOptions::default()).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let rows = log.rows.iter().map(|r| format!("{:?}", sagcal::io::recurdyn::RecurDynRow { line: 0, ..*r }));
            Ok((rows.collect(), log.rejected.len()))
        };
        prop_assert_eq!(rows(&clean)?, rows(&blank)?);
    }

    #[test]
    fn valid_rows_load(
        sagcal in proptest::collection::vec(sagcal_row(), 1..4),
        recurdyn in proptest::collection::vec(recurdyn_row(), 1..4),
    ) {
        let sagcal: Vec<String> = sagcal.iter().map(|r| r.join(",")).collect();
        let (_dir, path) = temp_file("valid.csv", &file_of(&MEASUREMENT_HEADER.join(","), &sagcal, false));
        let set = read_measurements(&path, &ReadOptions::default());
        prop_assert!(set.is_ok_and(|s| s.poses.len() == sagcal.len()));
        let recurdyn: Vec<String> = recurdyn.iter().map(|r| r.join(",")).collect();
        let (_dir, path) = temp_file("valid.csv", &file_of(RECURDYN_HEADER, &recurdyn, false));
        let log = read_recurdyn(&path, &LoadOptions::default()).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(log.rows.len() + log.rejected.len(), recurdyn.len(), "{:?}", log.rejected);
    }

    #[test]
    fn random_numbers_never_panic(
        sagcal in proptest::collection::vec(proptest::collection::vec(number_field(), MEASUREMENT_HEADER.len()), 1..4),
        recurdyn in proptest::collection::vec(proptest::collection::vec(number_field(), RECURDYN_FIELDS), 1..4),
    ) {
        let sagcal: Vec<String> = sagcal.iter().map(|r| r.join(",")).collect();
        check_measurements(&file_of(&MEASUREMENT_HEADER.join(","), &sagcal, false))?;
        let recurdyn: Vec<String> = recurdyn.iter().map(|r| r.join(",")).collect();
        let file = file_of(RECURDYN_HEADER, &recurdyn, false);
        check_measurements(&file)?;
        check_recurdyn(&file)?;
    }

    #[test]
    fn robot_files_with_random_numbers_never_panic(text in robot_toml()) {
        check_robot(text.as_bytes())?;
    }

    #[test]
    fn edited_robot_files_never_panic(edits in edits()) {
        check_robot(edited_large(&edits).as_bytes())?;
    }
}

#[test]
fn the_large_robot_file_loads_unedited() {
    let (_dir, path) = temp_file("large.toml", edited_large(&[]).as_bytes());
    assert!(Robot::from_file(&path).is_ok());
}

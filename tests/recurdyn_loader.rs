//! Tests of the RecurDyn log loader: the shared data file and malformed inputs.

use std::io::Write;
use std::path::{Path, PathBuf};

use sagcal::io::recurdyn::{
    looks_like_recurdyn, read_recurdyn, CableTensionReading, LoadOptions, RecurDynLog, RejectedRow,
};
use sagcal::Error;

const SHARED: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../shared/data/recurdyn-large/recurdyn_large.csv"
);

const HEADER: &str = "x,y,z,pitch,roll,yaw,L1,L2,L3,L4,fc1,fz1,fh1,fc2,fz2,fh2,fc3,fz3,fh3,fc4,fz4,fh4,";

/// Line 16 of the shared file (cable 1 only, empty marker).
const ROW_A: &str = "12.1078075634081,-5.95279927691681,14.5078874719318,-0.362744235071052,-0.266067830356039,\
                     -0.333769430569064,175.275461874535,156.968901792313,165.14219807337,182.631366033682,\
                     690.22064842419,110.901988556817,681.252737569,781.138331866916,141.194446412258,,\
                     710.047807252735,121.048489357446,,674.564345262271,107.040151869113,,";

/// Line 20 of the shared file.
const ROW_B: &str = "-5.337186007,-1.442254863,7.791544838,0.8150187947,-0.2856225884,-0.238467354,166.4326455,\
                     174.3233171,176.1500236,168.3449953,618.3138844,133.9847964,603.6225095,,,,,,,,,,";

/// The shared file, or `None` (with a message) when it is not there.
fn shared() -> Option<&'static Path> {
    let path = Path::new(SHARED);
    if path.exists() {
        Some(path)
    } else {
        eprintln!("skipped: shared RecurDyn log {SHARED} not found");
        None
    }
}

/// Write `text` to a temporary file; keep the returned handle alive while reading.
fn temp_log(text: &str) -> tempfile::NamedTempFile {
    let mut file = tempfile::Builder::new()
        .suffix(".csv")
        .tempfile()
        .expect("create temp file");
    file.write_all(text.as_bytes()).expect("write temp file");
    file.flush().expect("flush temp file");
    file
}

/// A log made of the header and `rows`.
fn log_text(rows: &[&str]) -> String {
    let mut text = format!("{HEADER}\n");
    for row in rows {
        text.push_str(row);
        text.push('\n');
    }
    text
}

/// Replace field `index` (0-based) of a CSV row.
fn with_field(row: &str, index: usize, value: &str) -> String {
    let mut fields: Vec<&str> = row.split(',').collect();
    fields[index] = value;
    fields.join(",")
}

fn load(text: &str) -> (tempfile::NamedTempFile, sagcal::Result<RecurDynLog>) {
    let file = temp_log(text);
    let result = read_recurdyn(file.path(), &LoadOptions::default());
    (file, result)
}

fn reason(log: &RecurDynLog, line: usize) -> &str {
    log.rejected
        .iter()
        .find(|r| r.line == line)
        .map(|r| r.reason.as_str())
        .unwrap_or_else(|| panic!("line {line} is not rejected; rejected: {:?}", log.rejected))
}

/// Assert a field error at `line`, column `field`, whose message names the file too.
fn assert_field_error(result: sagcal::Result<RecurDynLog>, path: &Path, line: usize, field: &str, contains: &str) {
    let err = result.expect_err("malformed input must be an error");
    let text = err.to_string();
    match &err {
        Error::Field {
            path: p,
            line: at,
            field: f,
            message,
            ..
        } => {
            assert_eq!(p, path, "{text}");
            assert_eq!(*at, Some(line), "{text}");
            assert_eq!(f, field, "{text}");
            assert!(message.contains(contains), "message `{message}` lacks `{contains}`");
        }
        other => panic!("expected Error::Field, got {other:?}"),
    }
    assert!(text.contains(&path.display().to_string()), "{text}");
    assert!(text.contains(&format!(" (line {line}), field")), "{text}");
    assert!(text.contains(&format!("`{field}`")), "{text}");
}

#[test]
fn shared_file_counts() {
    let Some(path) = shared() else { return };
    let log = read_recurdyn(path, &LoadOptions::default()).expect("shared log loads");
    assert_eq!(log.path, PathBuf::from(path));
    assert_eq!(log.rows.len(), 57);
    assert_eq!(log.rejected.len(), 35);
    let duplicates = log
        .rejected
        .iter()
        .filter(|r| r.reason.starts_with("duplicate of row"))
        .count();
    assert_eq!(duplicates, 32, "31 plain duplicates and line 71 (duplicate of 34)");
    assert!(log.rows.iter().all(|r| r.tensions[0].is_some()));
    // Every line 2..=93 is either kept or rejected, once, in file order.
    let mut lines: Vec<usize> = log
        .rows
        .iter()
        .map(|r| r.line)
        .chain(log.rejected.iter().map(|r| r.line))
        .collect();
    lines.sort_unstable();
    assert_eq!(lines, (2..=93).collect::<Vec<_>>());
    assert!(log.rows.windows(2).all(|w| w[0].line < w[1].line));

    let keep = read_recurdyn(path, &LoadOptions { keep_rounded: true }).expect("shared log loads");
    assert_eq!(keep.rows.len(), 59);
    assert_eq!(keep.rejected.len(), 33);
    assert_eq!(keep.rows[0].line, 2);
    assert_eq!(keep.rows[1].line, 3);
    assert_eq!(keep.rows[0].position_m, [9.93, 9.92, 10.91]);
}

#[test]
fn shared_file_reasons() {
    let Some(path) = shared() else { return };
    let log = read_recurdyn(path, &LoadOptions::default()).expect("shared log loads");
    let expected_rounded = "rounded: position given to 0.01 m (2 decimals), orientation to 0.01 deg (2 decimals)";
    let r2 = reason(&log, 2);
    assert!(r2.starts_with(expected_rounded), "{r2}");
    assert!(r2.contains("tensions to 3 to 6 decimals"), "{r2}");
    assert!(r2.contains("cable lengths to 12 decimals"), "{r2}");
    assert!(r2.contains("hand transcription"), "{r2}");
    let r3 = reason(&log, 3);
    assert!(r3.starts_with(expected_rounded), "{r3}");
    assert!(r3.contains("tensions to 3 to 4 decimals"), "{r3}");

    let r18 = reason(&log, 18);
    assert!(
        r18.starts_with("cable 1: fc1 = 578.648 N but sqrt(fz1^2 + fh1^2) = 684.583 N (difference 105.935 N"),
        "{r18}"
    );
    // The first is named by its row among the rows kept and its line.
    assert_eq!(reason(&log, 71), "duplicate of row 29 (line 34)");
    assert_eq!(reason(&log, 33), "duplicate of row 14 (line 17)");
    assert_eq!(reason(&log, 61), "duplicate of row 14 (line 17)");
    assert_eq!(reason(&log, 93), "duplicate of row 25 (line 29)");

    // Line 34 has line 18's pose with corrected tensions: kept, since 18 was rejected.
    let row34 = log.rows.iter().find(|r| r.line == 34).expect("line 34 kept");
    assert_eq!(row34.tensions[0].and_then(|t| t.horizontal_n), Some(569.870611754));
    assert!(log.rows.iter().all(|r| r.line != 18));
}

#[test]
fn shared_file_row_values() {
    let Some(path) = shared() else { return };
    let log = read_recurdyn(path, &LoadOptions::default()).expect("shared log loads");
    // Line 4: all four cables with all three forces.
    let row = log.rows.iter().find(|r| r.line == 4).expect("line 4 kept");
    assert_eq!(row.position_m, [9.94283158474076, 9.93145571155357, 15.9060269359906]);
    assert_eq!(row.pitch_deg, -0.19122393512445);
    assert_eq!(row.roll_deg, -1.06322173025346);
    assert_eq!(row.yaw_deg, 0.971850603803798);
    assert_eq!(
        row.cable_lengths_m,
        [183.324069126233, 169.162981532604, 155.642263929178, 170.927219368362]
    );
    assert_eq!(
        row.tensions[0],
        Some(CableTensionReading {
            total_n: 698.722056942942,
            vertical_n: 105.732855715641,
            horizontal_n: Some(690.675811131),
        })
    );
    assert_eq!(
        row.tensions[3],
        Some(CableTensionReading {
            total_n: 736.491974752971,
            vertical_n: 114.481987560832,
            horizontal_n: Some(727.53989815),
        })
    );
    // Line 5: cables 2..4 without fh.
    let row = log.rows.iter().find(|r| r.line == 5).expect("line 5 kept");
    assert_eq!(
        row.tensions[1],
        Some(CableTensionReading {
            total_n: 578.811635084674,
            vertical_n: 126.572667665785,
            horizontal_n: None,
        })
    );
    // Line 17: cable 1 only.
    let row = log.rows.iter().find(|r| r.line == 17).expect("line 17 kept");
    assert_eq!(row.tensions[1..], [None, None, None]);
    assert_eq!(row.tensions[0].map(|t| t.total_n), Some(684.5826046));
}

#[test]
fn header_detection() {
    let fields: Vec<&str> = HEADER.split(',').collect();
    assert_eq!(fields.len(), 23);
    assert!(looks_like_recurdyn(&fields));
    assert!(looks_like_recurdyn(&fields[..22]));
    assert!(!looks_like_recurdyn(&fields[..21]));
    let mut renamed = fields.clone();
    renamed[6] = "l1";
    assert!(!looks_like_recurdyn(&renamed));
    let mut marker = fields.clone();
    marker[22] = "marker";
    assert!(!looks_like_recurdyn(&marker));
    assert!(!looks_like_recurdyn(&[]));
}

#[test]
fn small_log_parses() {
    let (_file, result) = load(&log_text(&[ROW_A, ROW_B]));
    let log = result.expect("valid log");
    assert_eq!(log.rows.len(), 2);
    assert!(log.rejected.is_empty());
    assert_eq!(log.rows[0].line, 2);
    assert_eq!(log.rows[1].line, 3);
    assert_eq!(
        log.rows[1].cable_lengths_m,
        [166.4326455, 174.3233171, 176.1500236, 168.3449953]
    );
    // CRLF line endings and a byte-order mark are accepted.
    let crlf = format!("\u{feff}{}", log_text(&[ROW_A, ROW_B]).replace('\n', "\r\n"));
    let (_file, result) = load(&crlf);
    assert_eq!(result.expect("CRLF log").rows, log.rows);
    // Blank lines are skipped but still counted.
    let blank = format!("{HEADER}\n\n{ROW_A}\r\n\r\n{ROW_B}\n\n");
    let (_file, result) = load(&blank);
    let lines: Vec<usize> = result
        .expect("log with blank lines")
        .rows
        .iter()
        .map(|r| r.line)
        .collect();
    assert_eq!(lines, vec![3, 5]);
    // So are lines of spaces and tabs, before the header too (as the measurement loader skips them).
    let spaces = format!(" \n{HEADER}\n\t\n{ROW_A}\r\n  \r\n{ROW_B}\n \t \n");
    let (_file, result) = load(&spaces);
    let lines: Vec<usize> = result
        .expect("log with lines of spaces")
        .rows
        .iter()
        .map(|r| r.line)
        .collect();
    assert_eq!(lines, vec![4, 6]);
}

#[test]
fn quality_rejections() {
    // |fz| > fc without fh.
    let fz_too_big = with_field(ROW_A, 14, "900.5");
    // Same pose as ROW_B, other tension.
    let same_pose = with_field(&with_field(ROW_B, 12, ""), 11, "133.0");
    // Inconsistent cable 1.
    let inconsistent = with_field(ROW_B, 10, "620.0");
    let (_file, result) = load(&log_text(&[
        ROW_A,
        ROW_B,
        &fz_too_big,
        &same_pose,
        ROW_B,
        &inconsistent,
    ]));
    let log = result.expect("valid log");
    assert_eq!(log.rows.iter().map(|r| r.line).collect::<Vec<_>>(), vec![2, 3]);
    assert_eq!(
        log.rejected,
        vec![
            RejectedRow {
                line: 4,
                reason: "cable 2: |fz2| = 900.500 N exceeds fc2 = 781.138 N (a component cannot exceed the total)"
                    .to_string(),
            },
            RejectedRow {
                line: 5,
                reason: "same pose as row 2 (line 3) with different tensions".to_string(),
            },
            RejectedRow {
                line: 6,
                reason: "duplicate of row 2 (line 3)".to_string(),
            },
            RejectedRow {
                line: 7,
                reason: log.rejected[3].reason.clone(),
            },
        ]
    );
    assert!(
        log.rejected[3]
            .reason
            .starts_with("cable 1: fc1 = 620.000 N but sqrt(fz1^2 + fh1^2) = 618.314 N"),
        "{}",
        log.rejected[3].reason
    );
}

#[test]
fn error_missing_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("no_such_log.csv");
    let err = read_recurdyn(&path, &LoadOptions::default()).expect_err("missing file");
    assert!(matches!(err, Error::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("no_such_log.csv"), "{err}");
}

#[test]
fn error_unknown_header() {
    let text = format!("a,b,c\n{ROW_A}\n");
    let (file, result) = load(&text);
    let err = result.expect_err("unknown header");
    match &err {
        Error::Format { path, message } => {
            assert_eq!(path, file.path());
            assert!(
                message.contains("expected the columns `x,y,z,pitch,roll,yaw,L1"),
                "{message}"
            );
            assert!(message.contains("found `a,b,c`"), "{message}");
            assert!(message.contains("column 1 is `a`, expected `x`"), "{message}");
        }
        other => panic!("expected Error::Format, got {other:?}"),
    }
    assert!(err.to_string().contains(&file.path().display().to_string()));
}

#[test]
fn error_wrong_field_count() {
    let short: Vec<&str> = ROW_B.split(',').take(20).collect();
    let (file, result) = load(&log_text(&[ROW_A, &short.join(",")]));
    assert_field_error(result, file.path(), 3, "fz4", "row has 20 fields, the header 23");
    let long = format!("{ROW_B},extra");
    let (file, result) = load(&log_text(&[&long]));
    assert_field_error(result, file.path(), 2, "column 24", "row has 24 fields, the header 23");
}

#[test]
fn error_column_of_text() {
    let text = with_field(ROW_B, 7, "abc");
    let (file, result) = load(&log_text(&[ROW_A, ROW_B, &text]));
    assert_field_error(result, file.path(), 4, "L2", "not a number: `abc`");
}

#[test]
fn error_nan() {
    let text = with_field(ROW_B, 3, "NaN");
    let (file, result) = load(&log_text(&[&text]));
    assert_field_error(result, file.path(), 2, "pitch", "not a finite number: `NaN`");
}

#[test]
fn error_inf() {
    let text = with_field(ROW_A, 17, "-inf");
    let (file, result) = load(&log_text(&[&text]));
    assert_field_error(result, file.path(), 2, "fz3", "not a finite number: `-inf`");
}

#[test]
fn error_empty_required_field() {
    let text = with_field(ROW_B, 11, "");
    let (file, result) = load(&log_text(&[ROW_A, &text]));
    assert_field_error(result, file.path(), 3, "fz1", "required value is empty");
    let text = with_field(ROW_B, 2, " ");
    let (file, result) = load(&log_text(&[&text]));
    assert_field_error(result, file.path(), 2, "z", "required value is empty");
}

#[test]
fn error_negative_tension_and_length() {
    let text = with_field(ROW_A, 19, "-674.5");
    let (file, result) = load(&log_text(&[&text]));
    assert_field_error(result, file.path(), 2, "fc4", "total tension must be positive");
    let text = with_field(ROW_B, 9, "0");
    let (file, result) = load(&log_text(&[&text]));
    assert_field_error(result, file.path(), 2, "L4", "cable length must be positive");
}

#[test]
fn error_incomplete_cable_forces() {
    // fh2 without fc2 / fz2.
    let text = with_field(ROW_B, 15, "600.0");
    let (file, result) = load(&log_text(&[&text]));
    assert_field_error(result, file.path(), 2, "fh2", "fh2 is given but fc2 and fz2");
    // fc3 without fz3.
    let text = with_field(ROW_A, 17, "");
    let (file, result) = load(&log_text(&[&text]));
    assert_field_error(result, file.path(), 2, "fz3", "fc3 is given but fz3 is empty");
}

#[test]
fn error_header_only_and_empty() {
    for text in [format!("{HEADER}\n"), String::new()] {
        let (file, result) = load(&text);
        let err = result.expect_err("no data");
        match &err {
            Error::Format { path, message } => {
                assert_eq!(path, file.path());
                assert!(message.contains("header"), "{message}");
            }
            other => panic!("expected Error::Format, got {other:?}"),
        }
    }
}

#[test]
fn garbage_does_not_panic() {
    let inputs: Vec<Vec<u8>> = vec![
        b"\xff\xfe\x00garbage".to_vec(),
        [HEADER.as_bytes(), b"\n\xc3", ROW_B.as_bytes()].concat(),
        format!("{HEADER}\n\"unterminated,{ROW_B}").into_bytes(),
        format!("{HEADER}\n,,,,,,,,,,,,,,,,,,,,,,\n").into_bytes(),
        format!("{HEADER}\n1e999{}\n", &ROW_B[ROW_B.find(',').unwrap_or(0)..]).into_bytes(),
        b"x\n\n\n".to_vec(),
    ];
    for bytes in inputs {
        let mut file = tempfile::NamedTempFile::new().expect("temp file");
        file.write_all(&bytes).expect("write");
        file.flush().expect("flush");
        let result = read_recurdyn(file.path(), &LoadOptions::default());
        assert!(result.is_err(), "{bytes:?} -> {result:?}");
    }
}

//! Tests of sagcal's measurement file: round trip, RecurDyn conversion, errors.

use std::io::Write;
use std::path::{Path, PathBuf};

use sagcal::io::measurements::{
    read_measurements, write_measurements, MeasurementFormat, MeasurementSet, PoseMeasurement, ReadOptions,
    MEASUREMENT_HEADER,
};
use sagcal::model::measurement::ReadingOrder;
use sagcal::Error;

const SHARED: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../shared/data/recurdyn-large/recurdyn_large.csv"
);

const HEADER: &str = "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n";

/// A valid data row.
const ROW: &str = "1.5,-2.25,10,0.5,-0.25,3,180.125,-0.5,0,171.75,600.5";

/// The shared RecurDyn file, or `None` (with a message) when it is not there.
fn shared() -> Option<&'static Path> {
    let path = Path::new(SHARED);
    if path.exists() {
        Some(path)
    } else {
        eprintln!("skipped: shared RecurDyn log {SHARED} not found");
        None
    }
}

/// Write `text` to a temporary `.csv` file; keep the handle alive while reading.
fn temp_file(text: &[u8]) -> tempfile::NamedTempFile {
    let mut file = tempfile::Builder::new()
        .suffix(".csv")
        .tempfile()
        .expect("create temp file");
    file.write_all(text).expect("write temp file");
    file.flush().expect("flush temp file");
    file
}

/// Read `text` as a measurement file with default options.
fn read_text(text: &str) -> (tempfile::NamedTempFile, sagcal::Result<MeasurementSet>) {
    let file = temp_file(text.as_bytes());
    let result = read_measurements(file.path(), &ReadOptions::default());
    (file, result)
}

/// Replace field `index` (0-based) of a CSV row.
fn with_field(row: &str, index: usize, value: &str) -> String {
    let mut fields: Vec<&str> = row.split(',').collect();
    fields[index] = value;
    fields.join(",")
}

/// Assert an [`Error::Field`] at `line`, column `field`, whose message contains
/// `contains` and whose text names the file, the row and the field.
fn assert_field_error(result: sagcal::Result<MeasurementSet>, path: &Path, line: usize, field: &str, contains: &str) {
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

/// Assert an [`Error::Format`] for `path` whose message contains every one of `parts`.
fn assert_format_error(result: sagcal::Result<MeasurementSet>, path: &Path, parts: &[&str]) {
    let err = result.expect_err("malformed input must be an error");
    let text = err.to_string();
    match &err {
        Error::Format { path: p, message } => {
            assert_eq!(p, path, "{text}");
            for part in parts {
                assert!(message.contains(part), "message `{message}` lacks `{part}`");
            }
        }
        other => panic!("expected Error::Format, got {other:?}"),
    }
    assert!(text.contains(&path.display().to_string()), "{text}");
}

/// Names of the entries of `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("list dir")
        .map(|e| e.expect("dir entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Bit patterns of every value of a pose, for exact comparison (`-0.0` != `0.0`).
fn bits(pose: &PoseMeasurement) -> Vec<u64> {
    let mut values: Vec<f64> = pose.position_m.to_vec();
    values.extend([pose.roll_deg, pose.pitch_deg, pose.yaw_deg]);
    values.extend(pose.encoder_lengths_m);
    values.push(pose.reference_tension_n);
    values.iter().map(|v| v.to_bits()).collect()
}

/// Poses with values that are hard to round-trip.
fn tricky_poses() -> Vec<PoseMeasurement> {
    vec![
        PoseMeasurement {
            line: 0,
            position_m: [0.1 + 0.2, -0.0, 1.0 / 3.0],
            roll_deg: -1.06322173025346,
            pitch_deg: f64::MIN_POSITIVE,
            yaw_deg: 5e-324,
            encoder_lengths_m: [183.324069126233, -12.5, 0.0, 1e300],
            reference_tension_n: 698.722056942942,
            excluded: Default::default(),
            order: None,
        },
        PoseMeasurement {
            line: 17,
            position_m: [f64::MAX, -f64::MAX, 2.0f64.sqrt()],
            roll_deg: std::f64::consts::PI,
            pitch_deg: -1e-300,
            yaw_deg: 123456789.12345679,
            encoder_lengths_m: [1e-7, -1e-7, 171.686733095484, 9007199254740991.0],
            reference_tension_n: f64::MIN_POSITIVE,
            excluded: Default::default(),
            order: None,
        },
        PoseMeasurement {
            line: 0,
            position_m: [-9.92414615236591, -9.90879763138036, 11.0432049462401],
            roll_deg: 1.08382713920521,
            pitch_deg: -0.087901686672993,
            yaw_deg: -2.3271554167164,
            encoder_lengths_m: [156.778902665505, 171.962857387867, 184.290054861894, 170.209354387472],
            reference_tension_n: 722.490692830791,
            excluded: Default::default(),
            order: None,
        },
    ]
}

#[test]
fn header_constant_matches_documented_header() {
    assert_eq!(MEASUREMENT_HEADER.join(","), HEADER);
    assert_eq!(
        ReadOptions::default(),
        ReadOptions {
            reference_cable: 0,
            keep_rounded: false
        }
    );
}

#[test]
fn round_trip_is_bit_identical_with_line_numbers() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("poses.csv");
    let poses = tricky_poses();
    let comments = vec![
        "simulated by sagcal, seed 7".to_string(),
        "noise: 10 mm\non lengths".to_string(),
        String::new(),
    ];
    write_measurements(&path, &comments, &poses).expect("write");
    assert_eq!(
        entries(dir.path()),
        vec!["poses.csv".to_string()],
        "no temporary file left"
    );

    let text = std::fs::read_to_string(&path).expect("read back text");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "# simulated by sagcal, seed 7");
    assert_eq!(lines[1], "# noise: 10 mm");
    assert_eq!(lines[2], "# on lengths");
    assert_eq!(lines[3], "#");
    assert_eq!(lines[4], HEADER);
    assert_eq!(lines.len(), 5 + poses.len());
    assert!(text.ends_with('\n'));

    let set = read_measurements(&path, &ReadOptions::default()).expect("read back");
    assert_eq!(set.path, path);
    assert_eq!(set.format, MeasurementFormat::Sagcal);
    assert!(set.rejected.is_empty());
    assert_eq!(set.poses.len(), poses.len());
    for (i, (read, written)) in set.poses.iter().zip(&poses).enumerate() {
        assert_eq!(read.line, 6 + i, "4 comment lines, header on line 5");
        assert_eq!(bits(read), bits(written), "pose {i}");
    }
    // -0.0 survives as -0.0, not 0.0.
    assert!(set.poses[0].position_m[1].is_sign_negative());

    // Writing again replaces the file, and a second round trip is identical.
    write_measurements(&path, &[], &set.poses).expect("rewrite");
    let again = read_measurements(&path, &ReadOptions::default()).expect("read again");
    assert_eq!(again.poses[0].line, 2, "no comments: header on line 1");
    for (a, b) in again.poses.iter().zip(&set.poses) {
        assert_eq!(bits(a), bits(b));
    }
    assert_eq!(entries(dir.path()), vec!["poses.csv".to_string()]);
}

#[test]
fn reads_comments_blank_lines_crlf_bom_and_spaces() {
    let text = format!(
        "\u{feff}# simulated by sagcal, seed 7\r\n\r\n  # indented comment\r\n{HEADER}\r\n{ROW}\r\n\r\n# between \
         rows\r\n 2 , 3 ,4,-5,6e-1,7.,-1e2,1E1,+3,.5,1e-3\r\n   \r\n"
    );
    let (file, result) = read_text(&text);
    let set = result.expect("valid file");
    assert_eq!(set.path, file.path());
    assert_eq!(set.format, MeasurementFormat::Sagcal);
    assert_eq!(set.poses.len(), 2);
    assert_eq!(
        set.poses[0],
        PoseMeasurement {
            line: 5,
            position_m: [1.5, -2.25, 10.0],
            roll_deg: 0.5,
            pitch_deg: -0.25,
            yaw_deg: 3.0,
            encoder_lengths_m: [180.125, -0.5, 0.0, 171.75],
            reference_tension_n: 600.5,
            excluded: Default::default(),
            // A sagcal file's rows are in the order taken: the first has no
            // direction of last motion.
            order: Some(ReadingOrder {
                row: 1,
                direction: [0; 4]
            }),
        }
    );
    assert_eq!(
        set.poses[1],
        PoseMeasurement {
            line: 8,
            position_m: [2.0, 3.0, 4.0],
            roll_deg: -5.0,
            pitch_deg: 0.6,
            yaw_deg: 7.0,
            encoder_lengths_m: [-100.0, 10.0, 3.0, 0.5],
            reference_tension_n: 1e-3,
            excluded: Default::default(),
            // Each cable's direction: the sign of its reading's change since row 1.
            order: Some(ReadingOrder {
                row: 2,
                direction: [-1, 1, 1, -1]
            }),
        }
    );
}

#[test]
fn shared_recurdyn_log() {
    let Some(path) = shared() else { return };
    let set = read_measurements(path, &ReadOptions::default()).expect("shared log loads");
    assert_eq!(set.path, PathBuf::from(path));
    // A RecurDyn log's rows are not the order a robot took its poses in.
    assert!(set.poses.iter().all(|p| p.order.is_none()));
    assert_eq!(set.format, MeasurementFormat::RecurDyn);
    assert_eq!(set.poses.len(), 57);
    assert_eq!(set.rejected.len(), 35);
    assert_eq!(set.rejected[0].line, 2);
    assert!(
        set.rejected[0].reason.starts_with("rounded"),
        "{}",
        set.rejected[0].reason
    );
    assert!(set.rejected.windows(2).all(|w| w[0].line < w[1].line));
    assert!(set.poses.windows(2).all(|w| w[0].line < w[1].line));
    assert_eq!(
        set.poses[0],
        PoseMeasurement {
            line: 4,
            position_m: [9.94283158474076, 9.93145571155357, 15.9060269359906],
            roll_deg: -1.06322173025346,
            pitch_deg: -0.19122393512445,
            yaw_deg: 0.971850603803798,
            encoder_lengths_m: [183.324069126233, 169.162981532604, 155.642263929178, 170.927219368362],
            reference_tension_n: 698.722056942942,
            excluded: Default::default(),
            order: None,
        }
    );
    let line5 = set.poses.iter().find(|p| p.line == 5).expect("line 5 kept");
    assert_eq!(line5.reference_tension_n, 576.70539843293);

    // Rounded rows kept on request.
    let keep = read_measurements(
        path,
        &ReadOptions {
            reference_cable: 0,
            keep_rounded: true,
        },
    )
    .expect("shared log loads");
    assert_eq!(keep.poses.len(), 59);
    assert_eq!(keep.rejected.len(), 33);
    assert_eq!(keep.poses[0].line, 2);
    assert_eq!(keep.poses[0].position_m, [9.93, 9.92, 10.91]);
    assert_eq!(keep.poses[0].reference_tension_n, 628.101603);
}

#[test]
fn shared_recurdyn_log_other_reference_cable() {
    let Some(path) = shared() else { return };
    let options = ReadOptions {
        reference_cable: 1,
        keep_rounded: false,
    };
    let set = read_measurements(path, &options).expect("shared log loads");
    assert_eq!(set.format, MeasurementFormat::RecurDyn);
    // Line 4 has all cables: cable 2's total tension is the reference.
    assert_eq!(set.poses[0].line, 4);
    assert_eq!(set.poses[0].reference_tension_n, 712.530469558956);
    let line5 = set.poses.iter().find(|p| p.line == 5).expect("line 5 kept");
    assert_eq!(line5.reference_tension_n, 578.811635084674);
    // Kept rows without cable-2 tensions move to `rejected`, with a reason.
    let missing: Vec<_> = set
        .rejected
        .iter()
        .filter(|r| r.reason.contains("no tension logged for the reference cable 2"))
        .collect();
    assert_eq!(set.poses.len() + missing.len(), 57);
    assert_eq!(set.rejected.len(), 35 + missing.len());
    // Lines 4..=16 are the only rows of the file with cable-2 forces, and all are kept.
    let pose_lines: Vec<usize> = set.poses.iter().map(|p| p.line).collect();
    assert_eq!(pose_lines, (4..=16).collect::<Vec<_>>());
    assert_eq!(missing.len(), 44);
    assert!(set.rejected.windows(2).all(|w| w[0].line < w[1].line));
    // Every line 2..=93 is a pose or a rejection, once.
    let mut lines: Vec<usize> = set
        .poses
        .iter()
        .map(|p| p.line)
        .chain(set.rejected.iter().map(|r| r.line))
        .collect();
    lines.sort_unstable();
    assert_eq!(lines, (2..=93).collect::<Vec<_>>());
}

#[test]
fn missing_file_is_an_io_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("absent.csv");
    let err = read_measurements(&path, &ReadOptions::default()).expect_err("missing file");
    assert!(matches!(&err, Error::Io { path: p, .. } if *p == path), "{err:?}");
    assert!(err.to_string().contains("absent.csv"), "{err}");
}

#[test]
fn unknown_header_lists_both_formats() {
    let (file, result) = read_text(&format!("# comment\nx,y,z,roll,pitch,yaw,l1,l2,l3,l4,f\n{ROW}\n"));
    assert_format_error(
        result,
        file.path(),
        &[
            "line 2",
            HEADER,
            "RecurDyn logs",
            "accepted too",
            "column 1 is `x`, expected `x_m`",
        ],
    );

    let (file, result) = read_text(&format!("{HEADER},extra\n{ROW}\n"));
    assert_format_error(result, file.path(), &[HEADER, "12 columns, expected 11"]);

    let (file, result) = read_text("x_m,y_m,z_m\n1,2,3\n");
    assert_format_error(result, file.path(), &["column 4 `roll_deg` is missing"]);

    let (file, result) = read_text("");
    assert_format_error(result, file.path(), &["empty file", HEADER]);

    let (file, result) = read_text("# only a comment\n\n");
    assert_format_error(result, file.path(), &["empty file", HEADER]);
}

#[test]
fn header_without_rows_is_no_measurements() {
    let (file, result) = read_text(&format!("# c\n{HEADER}\n\n# nothing here\n"));
    assert_format_error(result, file.path(), &["no measurements", "line 2"]);
    let (file, result) = read_text(HEADER);
    assert_format_error(result, file.path(), &["no measurements"]);
}

#[test]
fn wrong_field_count() {
    let short = ROW.rsplit_once(',').expect("comma").0;
    let (file, result) = read_text(&format!("# c\n{HEADER}\n{ROW}\n{short}\n"));
    assert_field_error(result, file.path(), 4, "f_ref_n", "expected 11, found 10");

    let (file, result) = read_text(&format!("{HEADER}\n{ROW},\n"));
    assert_field_error(result, file.path(), 2, "column 12", "expected 11, found 12");

    let (file, result) = read_text(&format!("{HEADER}\n1\n"));
    assert_field_error(result, file.path(), 2, "y_m", "expected 11, found 1");
}

#[test]
fn values_that_are_not_finite_numbers() {
    let cases = [
        (1, "abc", "y_m", "not a number: `abc`"),
        (7, "NaN", "l2_m", "not a finite number"),
        (0, "inf", "x_m", "not a finite number"),
        (5, "-infinity", "yaw_deg", "not a finite number"),
        (9, "1e400", "l4_m", "not a finite number"),
        (3, "", "roll_deg", "empty"),
        (4, "  ", "pitch_deg", "empty"),
        // Quotes are read around a number (`"600"`), not around anything else.
        (10, "\"six\"", "f_ref_n", "not a number: `six`"),
        (10, "\"600", "f_ref_n", "not a number"),
        (2, "1,5", "", ""),
    ];
    for (index, value, field, contains) in cases {
        if field.is_empty() {
            // A decimal comma splits the field: a field-count error.
            let (file, result) = read_text(&format!("{HEADER}\n{}\n", with_field(ROW, index, value)));
            assert_field_error(result, file.path(), 2, "column 12", "expected 11, found 12");
            continue;
        }
        let text = format!("# c\n\n{HEADER}\n{ROW}\n{}\n", with_field(ROW, index, value));
        let (file, result) = read_text(&text);
        assert_field_error(result, file.path(), 5, field, contains);
    }
}

#[test]
fn invalid_utf8_is_an_error_not_a_panic() {
    let mut text = format!("{HEADER}\n").into_bytes();
    text.extend_from_slice(b"1,2,3,4,5,6,7,\xff\xfe,9,10,11\n");
    let file = temp_file(&text);
    let result = read_measurements(file.path(), &ReadOptions::default());
    assert_field_error(result, file.path(), 2, "l2_m", "UTF-8");

    let file = temp_file(b"\xff\xfe\x00x\x00\n\x00\x01");
    let result = read_measurements(file.path(), &ReadOptions::default());
    assert_format_error(result, file.path(), &["not a measurement file header"]);
}

#[test]
fn reference_tension_must_be_positive() {
    let cases = [
        ("-3.5", "negative tension"),
        ("0", "zero tension"),
        ("-0", "zero tension"),
        ("0e5", "zero tension"),
    ];
    for (value, contains) in cases {
        let (file, result) = read_text(&format!("{HEADER}\n{ROW}\n{ROW}\n{}\n", with_field(ROW, 10, value)));
        assert_field_error(result, file.path(), 4, "f_ref_n", contains);
    }
    // Encoder readings carry an offset: negative and zero ones are fine.
    let row = with_field(&with_field(ROW, 6, "-200"), 8, "0");
    let (_file, result) = read_text(&format!("{HEADER}\n{row}\n"));
    let set = result.expect("negative encoder reading is valid");
    assert_eq!(set.poses[0].encoder_lengths_m, [-200.0, -0.5, 0.0, 171.75]);
}

#[test]
fn recurdyn_header_after_comments_is_rejected() {
    let recurdyn = "x,y,z,pitch,roll,yaw,L1,L2,L3,L4,fc1,fz1,fh1,fc2,fz2,fh2,fc3,fz3,fh3,fc4,fz4,fh4,";
    let (file, result) = read_text(&format!("# a comment\n{recurdyn}\n"));
    assert_format_error(result, file.path(), &["line 2", "RecurDyn", "line 1"]);
}

#[test]
fn recurdyn_log_with_every_row_rejected() {
    let recurdyn = "x,y,z,pitch,roll,yaw,L1,L2,L3,L4,fc1,fz1,fh1,fc2,fz2,fh2,fc3,fz3,fh3,fc4,fz4,fh4,";
    // A rounded hand transcription (line 2 of the shared file).
    let row = "9.93,9.92,10.91,-1.31,0.68,-0.04,184.290054861894,170.209354387472,156.778902665505,\
               171.962857387867,628.101603,68.629,624.341,,,,,,,,,,in";
    let (file, result) = read_text(&format!("{recurdyn}\n{row}\n"));
    assert_format_error(
        result,
        file.path(),
        &["no measurements", "every row", "1 rejected", "line 2: rounded"],
    );

    // Kept by the RecurDyn loader, but cable 3 has no tension.
    let file = temp_file(format!("{recurdyn}\n{row}\n").as_bytes());
    let options = ReadOptions {
        reference_cable: 2,
        keep_rounded: true,
    };
    let result = read_measurements(file.path(), &options);
    assert_format_error(
        result,
        file.path(),
        &["no measurements", "line 2: no tension logged for the reference cable 3"],
    );

    // Malformed RecurDyn rows are errors from the RecurDyn loader, unchanged.
    let bad = row.replacen("9.93", "oops", 1);
    let (file, result) = read_text(&format!("{recurdyn}\n{bad}\n"));
    assert_field_error(result, file.path(), 2, "x", "not a number");
}

#[test]
fn reference_cable_out_of_range() {
    let file = temp_file(format!("{HEADER}\n{ROW}\n").as_bytes());
    let options = ReadOptions {
        reference_cable: 4,
        keep_rounded: false,
    };
    let err = read_measurements(file.path(), &options).expect_err("cable 4 does not exist");
    assert!(matches!(err, Error::InvalidInput(_)), "{err:?}");
    assert!(err.to_string().contains("reference cable index 4"), "{err}");
}

/// Assert that writing `poses` is refused with a message naming the file,
/// `row` and `field`, and that the directory is left as it was.
fn assert_write_refused(poses: &[PoseMeasurement], row: usize, field: &str, contains: &str) {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("out.csv");
    let err = write_measurements(&path, &["c".to_string()], poses).expect_err("invalid data must be refused");
    let text = err.to_string();
    assert!(matches!(err, Error::InvalidInput(_)), "{err:?}");
    assert!(text.contains(&path.display().to_string()), "{text}");
    assert!(text.contains(&format!("row {row} ")), "{text}");
    assert!(text.contains(&format!("`{field}`")), "{text}");
    assert!(text.contains(contains), "{text}");
    assert!(!path.exists(), "nothing written at {}", path.display());
    assert!(entries(dir.path()).is_empty(), "left behind: {:?}", entries(dir.path()));
}

#[test]
fn write_refuses_invalid_data_and_leaves_nothing() {
    let good = tricky_poses();

    let mut poses = good.clone();
    poses[1].position_m[2] = f64::NAN;
    assert_write_refused(&poses, 2, "z_m", "not a finite number");

    let mut poses = good.clone();
    poses[2].encoder_lengths_m[2] = f64::INFINITY;
    assert_write_refused(&poses, 3, "l3_m", "not a finite number");

    let mut poses = good.clone();
    poses[0].yaw_deg = f64::NEG_INFINITY;
    assert_write_refused(&poses, 1, "yaw_deg", "not a finite number");

    let mut poses = good.clone();
    poses[2].reference_tension_n = 0.0;
    assert_write_refused(&poses, 3, "f_ref_n", "zero tension");

    let mut poses = good.clone();
    poses[0].reference_tension_n = -0.0;
    assert_write_refused(&poses, 1, "f_ref_n", "zero tension");

    let mut poses = good.clone();
    poses[1].reference_tension_n = -12.0;
    assert_write_refused(&poses, 2, "f_ref_n", "negative tension");

    let mut poses = good.clone();
    poses[1].reference_tension_n = f64::NAN;
    assert_write_refused(&poses, 2, "f_ref_n", "not a finite number");

    // No poses: a file that could not be read back.
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("out.csv");
    let err = write_measurements(&path, &[], &[]).expect_err("empty set refused");
    assert!(err.to_string().contains("no measurements"), "{err}");
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn refused_write_keeps_the_existing_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("poses.csv");
    let good = tricky_poses();
    write_measurements(&path, &[], &good).expect("write");
    let before = std::fs::read(&path).expect("read");

    let mut bad = good.clone();
    bad[0].roll_deg = f64::NAN;
    write_measurements(&path, &["new".to_string()], &bad).expect_err("refused");
    assert_eq!(std::fs::read(&path).expect("read"), before);
    assert_eq!(entries(dir.path()), vec!["poses.csv".to_string()]);
}

#[test]
fn write_failures_leave_nothing_behind() {
    let dir = tempfile::tempdir().expect("temp dir");
    let poses = tricky_poses();

    // Directory that does not exist.
    let path = dir.path().join("missing").join("out.csv");
    let err = write_measurements(&path, &[], &poses).expect_err("no such directory");
    assert!(matches!(&err, Error::Io { path: p, .. } if *p == path), "{err:?}");
    assert!(entries(dir.path()).is_empty());

    // Target is an existing directory: the rename fails, the temp file is removed.
    let target = dir.path().join("a_directory");
    std::fs::create_dir(&target).expect("mkdir");
    let err = write_measurements(&target, &[], &poses).expect_err("cannot replace a directory");
    assert!(matches!(&err, Error::Io { path: p, .. } if *p == target), "{err:?}");
    assert_eq!(entries(dir.path()), vec!["a_directory".to_string()]);
    assert!(entries(&target).is_empty());
}

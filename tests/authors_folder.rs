//! The authors' dataset folder (`pos_i_cpp_test.csv`, `R_i_cpp_test.csv`,
//! `lc_meas_cpp_test.csv`, `forces_cpp_test.csv`): `sagcal calibrate --data
//! <folder>` gives the same result as the same data in sagcal's CSV; the
//! mapping agrees with the RecurDyn log the published files were cut from;
//! every file's errors name the file, the row and the field.

use std::fmt::Write as _;
use std::path::Path;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::io::authors::{read_authors_folder, FORCES_FILE, LENGTHS_FILE, ORIENTATION_FILE, POSITION_FILE};
use sagcal::io::measurements::{read_measurements, write_measurements, MeasurementFormat, ReadOptions};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
use sagcal::Error;

const SHARED: &str = "../shared/data/recurdyn-large/recurdyn_large.csv";

#[path = "common/cli.rs"]
mod cli;
use cli::{robot, sagcal};

/// A valid one-row folder; `edit` replaces one file's text.
fn folder(dir: &Path, edit: Option<(&str, &str)>) {
    std::fs::create_dir_all(dir).unwrap();
    for (file, text) in [
        (POSITION_FILE, "9.93,9.92,10.91\n4.93,-4.91,-3.61\n"),
        (ORIENTATION_FILE, "-1.31,0.68,-0.04\n-0.13,-0.35,-0.03\n"),
        (
            LENGTHS_FILE,
            "184.29,170.21,156.78,171.96\n175.03,167.75,174.17,181.20\n",
        ),
        (FORCES_FILE, "624.341,68.629\n454.885,79.1454\n"),
    ] {
        let text = match edit {
            Some((f, t)) if f == file => t,
            _ => text,
        };
        std::fs::write(dir.join(file), text).unwrap();
    }
}

#[test]
fn calibrate_on_the_folder_equals_calibrate_on_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let truth = Robot::builtin("large").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 20, &mut rng).unwrap();
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let simulated = measure(&truth, &equilibria, &noise, &mut rng);

    // The folder, written here by hand in the published layout: pitch before
    // roll, the reference force split into a horizontal and a vertical part
    // (the vertical sign alternates: only the norm is a reading), trailing
    // commas in one file and CRLF line ends in another, as the authors' reader allows.
    let authors = dir.path().join("dataset");
    std::fs::create_dir(&authors).unwrap();
    let (mut pos, mut rot, mut len, mut force) = (String::new(), String::new(), String::new(), String::new());
    let mut poses = simulated.clone();
    for (k, p) in poses.iter_mut().enumerate() {
        let [x, y, z] = p.position_m;
        let [l1, l2, l3, l4] = p.encoder_lengths_m;
        let slope = 0.05 + 0.01 * k as f64;
        let f_h = p.reference_tension_n * slope.cos();
        let f_v = p.reference_tension_n * slope.sin() * if k % 2 == 0 { 1.0 } else { -1.0 };
        writeln!(pos, "{x},{y},{z},").unwrap();
        write!(rot, "{},{},{}\r\n", p.pitch_deg, p.roll_deg, p.yaw_deg).unwrap();
        writeln!(len, "{l1},{l2},{l3},{l4}").unwrap();
        writeln!(force, "{f_h},{f_v}").unwrap();
        // The same reading in sagcal's CSV: the load cell is the norm.
        p.reference_tension_n = f_h.hypot(f_v);
    }
    for (file, text) in [
        (POSITION_FILE, pos),
        (ORIENTATION_FILE, rot),
        (LENGTHS_FILE, len),
        (FORCES_FILE, force),
    ] {
        std::fs::write(authors.join(file), text).unwrap();
    }
    write_measurements(&dir.path().join("same.csv"), &[], &poses).unwrap();

    let set = read_measurements(&authors, &ReadOptions::default()).unwrap();
    assert_eq!(set.format, MeasurementFormat::Authors);
    assert_eq!(set.poses.len(), 20);
    assert_eq!(set.poses[3].line, 4, "line k of every file is pose k");
    for (a, b) in set.poses.iter().zip(&poses) {
        assert_eq!(
            (a.position_m, a.roll_deg, a.pitch_deg, a.yaw_deg),
            (b.position_m, b.roll_deg, b.pitch_deg, b.yaw_deg)
        );
        assert_eq!(a.encoder_lengths_m, b.encoder_lengths_m);
        assert_eq!(a.reference_tension_n, b.reference_tension_n);
    }

    let nominal = std::fs::read_to_string(robot("large"))
        .unwrap()
        .replace("anchor_m = [125.0, -110.0, 48.0]", "anchor_m = [128.0, -106.0, 48.0]");
    std::fs::write(dir.path().join("nominal.toml"), nominal).unwrap();
    let calibrate = |data: &str| {
        let out = sagcal(
            dir.path(),
            &["calibrate", "--robot", "nominal.toml", "--data", data, "--json"],
        );
        assert!(out.status.success(), "{data}: {}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let mut from_folder = calibrate("dataset");
    let from_csv = calibrate("same.csv");
    // Line numbers name the row in its own file: line k of the folder's files
    // is line k + 1 of the CSV, below its header.
    let largest = |r: &serde_json::Value| r["gross_errors"]["tests"]["largest"]["line"].clone();
    assert_eq!(
        largest(&from_csv).as_u64().unwrap(),
        largest(&from_folder).as_u64().unwrap() + 1
    );
    from_folder["gross_errors"]["tests"]["largest"]["line"] = largest(&from_csv);
    // Otherwise the whole report, every number to the last digit (the JSON names no file).
    assert_eq!(from_folder, from_csv);
    assert_eq!(from_folder["converged"], true);
    // The anchor moved 5 m in the nominal is found again.
    let estimate = serde_json::from_value::<[[f64; 3]; 4]>(from_folder["anchors_m"].clone()).unwrap()[1];
    let error = (nalgebra::Vector3::from(estimate) - truth.anchors_m[1]).norm();
    assert!(error < 0.5, "anchor 2 is {error} m off");
}

/// The published files were cut from the RecurDyn log: `x,y,z`, `pitch,roll,yaw`,
/// `L1..L4` and `fh1,fz1`. A folder cut the same way from the shared log reads
/// as the log itself: the norm of `(fh1, fz1)` is the logged total `fc1`.
#[test]
fn a_folder_cut_from_the_recurdyn_log_reads_as_the_log() {
    let path = Path::new(SHARED);
    if !path.exists() {
        eprintln!("skipped: shared RecurDyn log {SHARED} not found");
        return;
    }
    let log = read_measurements(path, &ReadOptions::default()).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    let rows: Vec<Vec<&str>> = text.lines().map(|l| l.split(',').collect()).collect();
    let dir = tempfile::tempdir().unwrap();
    let mut files = [String::new(), String::new(), String::new(), String::new()];
    let mut lines = Vec::new();
    for (i, row) in rows.iter().enumerate().skip(1) {
        // Rows the log loader kept, with the horizontal force logged.
        if !log.poses.iter().any(|p| p.line == i + 1) || row[12].trim().is_empty() {
            continue;
        }
        lines.push(i + 1);
        for (file, columns) in files
            .iter_mut()
            .zip([&[0, 1, 2][..], &[3, 4, 5], &[6, 7, 8, 9], &[12, 11]])
        {
            let values: Vec<&str> = columns.iter().map(|&c| row[c]).collect();
            writeln!(file, "{}", values.join(",")).unwrap();
        }
    }
    assert!(lines.len() > 40, "{} rows with fh1", lines.len());
    for (name, text) in [POSITION_FILE, ORIENTATION_FILE, LENGTHS_FILE, FORCES_FILE]
        .iter()
        .zip(&files)
    {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let folder = read_authors_folder(dir.path()).unwrap();
    assert_eq!(folder.len(), lines.len());
    for (pose, line) in folder.iter().zip(&lines) {
        let logged = log.poses.iter().find(|p| p.line == *line).unwrap();
        assert_eq!(pose.position_m, logged.position_m, "line {line}");
        assert_eq!(
            (pose.roll_deg, pose.pitch_deg, pose.yaw_deg),
            (logged.roll_deg, logged.pitch_deg, logged.yaw_deg),
            "line {line}"
        );
        assert_eq!(pose.encoder_lengths_m, logged.encoder_lengths_m, "line {line}");
        let relative = (pose.reference_tension_n - logged.reference_tension_n).abs() / logged.reference_tension_n;
        assert!(
            relative < 2e-6,
            "line {line}: |(fh1, fz1)| = {} N, fc1 = {} N",
            pose.reference_tension_n,
            logged.reference_tension_n
        );
    }
}

fn field_error(dir: &Path, edit: (&str, &str)) -> (String, usize, String, String) {
    folder(dir, Some(edit));
    match read_authors_folder(dir) {
        Err(Error::Field {
            path,
            row,
            line,
            field,
            message,
        }) if line == Some(row) => (
            path.file_name().unwrap().to_string_lossy().into_owned(),
            row,
            field,
            message,
        ),
        other => panic!("{edit:?}: expected a field error, got {other:?}"),
    }
}

#[test]
fn each_file_names_its_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (file, row, field, message) = field_error(d, (POSITION_FILE, "9.93,9.92,10.91\nx,y,z\n"));
    assert_eq!((file.as_str(), row, field.as_str()), (POSITION_FILE, 2, "x_m"));
    assert!(message.contains("no header"), "{message}");

    let (file, row, field, message) = field_error(d, (ORIENTATION_FILE, "-1.31,0.68\n-0.13,-0.35,-0.03\n"));
    assert_eq!((file.as_str(), row, field.as_str()), (ORIENTATION_FILE, 1, "yaw_deg"));
    assert!(message.contains("expected 3 values"), "{message}");

    let (file, row, field, message) = field_error(
        d,
        (LENGTHS_FILE, "184.29,170.21,156.78,171.96\n175.03,NaN,174.17,181.20\n"),
    );
    assert_eq!((file.as_str(), row, field.as_str()), (LENGTHS_FILE, 2, "l2_m"));
    assert!(message.contains("finite"), "{message}");

    let (file, row, field, message) = field_error(d, (FORCES_FILE, "624.341,68.629\n0,-0\n"));
    assert_eq!((file.as_str(), row, field.as_str()), (FORCES_FILE, 2, "f_h_n"));
    assert!(message.contains("must be positive"), "{message}");

    let (file, row, field, _) = field_error(d, (FORCES_FILE, "624.341,68.629,1\n454.885,79.1454\n"));
    assert_eq!((file.as_str(), row, field.as_str()), (FORCES_FILE, 1, "f_v_n"));
}

#[test]
fn folder_level_errors_name_the_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Row counts that disagree name both files.
    folder(d, Some((FORCES_FILE, "624.341,68.629\n")));
    let message = read_authors_folder(d).unwrap_err().to_string();
    assert!(
        message.contains(POSITION_FILE) && message.contains(FORCES_FILE) && message.contains("2 rows"),
        "{message}"
    );
    // A blank line inside a file would shift the pairing.
    folder(
        d,
        Some((
            LENGTHS_FILE,
            "184.29,170.21,156.78,171.96\n\n175.03,167.75,174.17,181.20\n",
        )),
    );
    let message = read_authors_folder(d).unwrap_err().to_string();
    assert!(
        message.contains(LENGTHS_FILE) && message.contains("line 2 is blank"),
        "{message}"
    );
    // An empty file.
    folder(d, Some((ORIENTATION_FILE, "\n")));
    let message = read_authors_folder(d).unwrap_err().to_string();
    assert!(
        message.contains(ORIENTATION_FILE) && message.contains("no rows"),
        "{message}"
    );
    // A folder without the files lists the missing ones.
    std::fs::remove_file(d.join(FORCES_FILE)).unwrap();
    std::fs::remove_file(d.join(POSITION_FILE)).unwrap();
    let message = read_authors_folder(d).unwrap_err().to_string();
    assert!(
        message.contains(&format!("{POSITION_FILE}, {FORCES_FILE} are missing")),
        "{message}"
    );

    // Through the CLI: exit code 1, the message, no robot file written.
    folder(d, Some((POSITION_FILE, "9.93,9.92,10.91\n4.93,-4.91\n")));
    let out = sagcal(
        d,
        &[
            "calibrate",
            "--robot",
            &robot("large"),
            "--data",
            ".",
            "--out",
            "cal.toml",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!("{POSITION_FILE}: row 2 (line 2), field `z_m`")),
        "{stderr}"
    );
    assert!(!d.join("cal.toml").exists());
}

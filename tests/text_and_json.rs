//! Every command prints its text and its JSON from one report: the figures
//! of the text equal the JSON's, and both name rows and cables alike (a row
//! counted from 1 with its file line, `row 10 (line 12)` in text and
//! `"row": 10, "line": 12` in JSON; a cable counted from 1).
//!
//! The commands run on `sagcal demo`'s data, damaged where a test needs a
//! gross error, and on the shared RecurDyn log where it is beside the checkout.

#[path = "common/cli.rs"]
mod cli;
#[path = "common/shared_data.rs"]
mod shared_data;

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

use cli::{robot, sagcal};
use serde_json::Value;

/// The folder `sagcal demo` writes (truth, guess, data), made once.
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

fn demo_file(name: &str) -> String {
    demo().join("sagcal-demo").join(name).display().to_string()
}

/// The demo's data with a comment and a blank line more before the header,
/// so that a row's line is its row + 4, and `edit(row, fields)` applied to
/// each data row (1-based).
fn demo_data(dir: &Path, name: &str, edit: impl Fn(usize, &mut Vec<String>)) -> PathBuf {
    let text = std::fs::read_to_string(demo_file("data.csv")).unwrap();
    let mut lines = vec!["# edited for a test".to_string(), String::new()];
    let mut row = 0;
    for line in text.lines() {
        if line.starts_with('#') || line.starts_with("x_m") {
            lines.push(line.to_string());
            continue;
        }
        row += 1;
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        edit(row, &mut fields);
        lines.push(fields.join(","));
    }
    let path = dir.join(name);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

fn run(dir: &Path, args: &[&str]) -> (String, String, Output) {
    let out = sagcal(dir, args);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (stdout, stderr, out)
}

/// `args` with and without `--json`: the text and the parsed JSON (both must succeed).
fn text_and_json(dir: &Path, args: &[&str]) -> (String, Value) {
    let (text, stderr, out) = run(dir, args);
    assert!(out.status.success(), "{args:?}: {stderr}");
    let mut with_json = args.to_vec();
    with_json.push("--json");
    let (json, stderr, out) = run(dir, &with_json);
    assert!(out.status.success(), "{args:?} --json: {stderr}");
    (text, serde_json::from_str(&json).unwrap())
}

/// `row 10 (line 12)` from a JSON object's `row` and `line`.
fn row_name(v: &Value) -> String {
    let row = v["row"].as_u64().unwrap_or_else(|| panic!("no row in {v}"));
    match v["line"].as_u64() {
        Some(line) => format!("row {row} (line {line})"),
        None => {
            assert!(v["line"].is_null(), "{v}");
            format!("row {row}")
        }
    }
}

/// A reading's name from its JSON: `row 10 (line 12), encoder of cable 1`.
fn reading_name(test: &Value) -> String {
    let sensor = match test["sensor"].as_str().unwrap() {
        "encoder" => format!("encoder of cable {}", test["cable"].as_u64().unwrap()),
        "load_cell" => "load cell".to_string(),
        "position" => format!("localiser {}", test["axis"].as_str().unwrap()),
        "orientation" => format!("localiser orientation about {}", test["axis"].as_str().unwrap()),
        other => panic!("unknown sensor {other}"),
    };
    if test["sensor"] != "encoder" {
        assert!(test["cable"].is_null(), "{test}");
    }
    format!("{}, {sensor}: ", row_name(test))
}

/// The text's table whose header line starts with `first_column`: its rows
/// (the lines below the rule with as many cells as the header), split on
/// runs of two or more spaces.
fn table(text: &str, first_column: &str) -> Vec<Vec<String>> {
    let cells = |line: &str| -> Vec<String> {
        line.split("  ")
            .map(str::trim)
            .filter(|c| !c.is_empty())
            .map(str::to_string)
            .collect()
    };
    let lines: Vec<&str> = text.lines().collect();
    let start = lines
        .iter()
        .position(|l| l.starts_with(first_column) && l.contains("  "))
        .unwrap_or_else(|| panic!("no table `{first_column}` in:\n{text}"));
    let columns = cells(lines[start]).len();
    assert!(lines[start + 1].starts_with("---"), "{}", lines[start + 1]);
    lines[start + 2..]
        .iter()
        .map(|l| cells(l))
        .take_while(|row| row.len() == columns)
        .collect()
}

/// `sagcal calibrate`'s text against its JSON: anchors, offsets, the
/// gross-error table, the largest `|w|`, every reading left out or set aside,
/// the mistakes and the verdict, each figure as the text rounds it.
fn assert_calibrate_agrees(text: &str, json: &Value) {
    let anchors = table(text, "anchor ");
    for (i, row) in anchors.iter().enumerate() {
        let a = &json["anchors_m"][i];
        let expected: Vec<String> = (0..3).map(|c| format!("{:.3}", a[c].as_f64().unwrap())).collect();
        assert_eq!(row[0], (i + 1).to_string());
        assert_eq!(&row[1..4], &expected[..], "anchor {}", i + 1);
    }
    for (i, row) in table(text, "cable ").iter().enumerate() {
        assert_eq!(row[1], format!("{:.4}", json["length_offsets_m"][i].as_f64().unwrap()));
    }
    let gross = &json["gross_errors"];
    let tests = &gross["tests"];
    let sensors = table(text, "sensor ");
    let types = tests["sensor_types"].as_array().unwrap();
    assert_eq!(sensors.len(), types.len(), "{text}");
    for (row, t) in sensors.iter().zip(types) {
        let f = |key: &str| t[key].as_f64().unwrap();
        let expected = [
            t["sensor"].as_str().unwrap().to_string(),
            t["readings"].to_string(),
            format!("{:.1}", f("chi_square")),
            format!("{:.1}", f("redundancy")),
            format!("{:.2e}", f("p_value")),
            if t["consistent"] == true { "yes" } else { "NO" }.to_string(),
        ];
        assert_eq!(row[..], expected[..], "{text}");
    }
    if let Some(largest) = tests["largest"].as_object() {
        let largest = Value::Object(largest.clone());
        let line = text
            .lines()
            .find(|l| l.starts_with("largest |w|: "))
            .expect("largest |w| printed");
        let name = reading_name(&largest);
        assert!(line.starts_with(&format!("largest |w|: {name}")), "{line} / {name}");
        assert!(
            line.ends_with(&format!("w = {:.1}", largest["w"].as_f64().unwrap())),
            "{line}"
        );
    }
    for (key, prefix) in [("excluded_readings", "  "), ("set_aside_readings", "  set aside: ")] {
        for x in gross[key].as_array().into_iter().flatten() {
            let name = format!("{prefix}{}", reading_name(&x["test"]));
            assert!(text.lines().any(|l| l.starts_with(&name)), "`{name}` not in:\n{text}");
        }
    }
    for m in gross["mistakes"].as_array().unwrap() {
        let message = m["message"].as_str().unwrap();
        assert!(text.contains(&format!("MISTAKE: {message}\n")), "{message}");
        for row in m["rows"].as_array().unwrap() {
            assert!(message.contains(&row_name(row)) || m["kind"] == "rehoming", "{m}");
        }
    }
    let verdict = text.lines().find(|l| l.starts_with("verdict: ")).expect("a verdict");
    match gross["verdict"]["verdict"].as_str().unwrap() {
        "consistent" => assert_eq!(verdict, "verdict: consistent with the stated noise"),
        _ => {
            let reason = gross["verdict"]["reason"].as_str().unwrap();
            assert_eq!(verdict, format!("verdict: INCONSISTENT: {reason}"));
            assert_verdict_quotes_the_table(reason, &sensors);
        }
    }
}

/// Every `the X readings fail their chi-square test: A against an expected B`
/// of a verdict quotes the table's row of X: the verdict is the fit's that is
/// reported.
fn assert_verdict_quotes_the_table(reason: &str, sensors: &[Vec<String>]) {
    let mut quoted = 0;
    for part in reason.split("the ").skip(1) {
        let Some((sensor, rest)) = part.split_once(" readings fail their chi-square test: ") else {
            continue;
        };
        let row = sensors
            .iter()
            .find(|r| r[0] == sensor)
            .unwrap_or_else(|| panic!("the verdict names `{sensor}`, the table does not: {sensors:?}"));
        assert!(
            rest.starts_with(&format!("{} against an expected {} ", row[2], row[3])),
            "the verdict says `{sensor} {rest}`, the table {row:?}"
        );
        assert_eq!(row[5], "NO", "{row:?}");
        quoted += 1;
    }
    let failing = sensors.iter().filter(|r| r[5] == "NO").count();
    assert_eq!(quoted, failing, "{reason}");
}

#[test]
fn calibrate_prints_one_report_as_text_and_as_json() {
    let dir = tempfile::tempdir().unwrap();
    let guess = demo_file("guess.toml");
    // Clean data, and cable 1's encoder of row 10 read 5 m long (left out).
    let clean = demo_data(dir.path(), "clean.csv", |_, _| {});
    let blunder = demo_data(dir.path(), "blunder.csv", |row, fields| {
        if row == 10 {
            fields[6] = format!("{}", fields[6].parse::<f64>().unwrap() + 5.0);
        }
    });
    for data in [&clean, &blunder] {
        let (text, json) = text_and_json(
            dir.path(),
            &["calibrate", "--robot", &guess, "--data", data.to_str().unwrap()],
        );
        assert_calibrate_agrees(&text, &json);
        assert!(
            text.ends_with("the calibrated robot was not saved: no --out given (--out calibrated.toml writes it)\n"),
            "{text}"
        );
    }
    let (text, json) = text_and_json(
        dir.path(),
        &["calibrate", "--robot", &guess, "--data", blunder.to_str().unwrap()],
    );
    let left_out = &json["gross_errors"]["excluded_readings"][0]["test"];
    assert_eq!(
        (
            &left_out["row"],
            &left_out["line"],
            &left_out["sensor"],
            &left_out["cable"]
        ),
        (
            &Value::from(10),
            &Value::from(14),
            &Value::from("encoder"),
            &Value::from(1)
        )
    );
    assert!(text.contains("\n  row 10 (line 14), encoder of cable 1: +"), "{text}");
    // With --out, where the robot went.
    let (text, _, out) = run(
        dir.path(),
        &[
            "calibrate",
            "--robot",
            &guess,
            "--data",
            clean.to_str().unwrap(),
            "--out",
            "c.toml",
        ],
    );
    assert!(out.status.success());
    assert!(text.ends_with("calibrated robot written to c.toml\n"), "{text}");
}

#[test]
fn an_inconsistent_calibration_prints_the_reported_fit_in_its_verdict_and_refusal() {
    // The encoders stated 2.5 times more precise than they are: the search
    // for gross errors leaves readings out, gives up, and reports the fit
    // with every reading.
    let dir = tempfile::tempdir().unwrap();
    let guess = demo_file("guess.toml");
    let data = demo_file("data.csv");
    let args = [
        "calibrate",
        "--robot",
        &guess,
        "--data",
        &data,
        "--encoder-sigma-m",
        "0.004",
    ];
    let (refused, stderr, out) = run(dir.path(), &args);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let mut accepted = args.to_vec();
    accepted.push("--accept-inconsistent");
    let (text, json) = text_and_json(dir.path(), &accepted);
    assert!(!json["gross_errors"]["set_aside_readings"]
        .as_array()
        .unwrap()
        .is_empty());
    assert_calibrate_agrees(&text, &json);
    // The refused run printed the same report, as text and as JSON, and its
    // error the same reason.
    assert!(text.starts_with(&refused), "{refused}\n---\n{text}");
    let mut refused_json = args.to_vec();
    refused_json.push("--json");
    let (printed, _, out) = run(dir.path(), &refused_json);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(serde_json::from_str::<Value>(&printed).unwrap(), json);
    let reason = json["gross_errors"]["verdict"]["reason"].as_str().unwrap();
    assert!(stderr.trim_end().ends_with(reason), "{stderr}");
    assert!(
        stderr.starts_with(&format!(
            "error: {data}: the calibration fails its own consistency tests"
        )),
        "{stderr}"
    );
}

#[test]
fn the_recurdyn_calibration_verdict_quotes_the_table_it_is_printed_under() {
    let Some(log) = shared_data::recurdyn_log() else { return };
    let dir = tempfile::tempdir().unwrap();
    let large = robot("large");
    let args = [
        "calibrate",
        "--robot",
        &large,
        "--data",
        log.to_str().unwrap(),
        "--noise",
        "authors",
    ];
    let (refused, stderr, out) = run(dir.path(), &args);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    // The gross-error table and the verdict printed under it are the same fit's.
    let sensors = table(&refused, "sensor ");
    let verdict = refused
        .lines()
        .find(|l| l.starts_with("verdict: INCONSISTENT: "))
        .expect("refused");
    assert_verdict_quotes_the_table(verdict, &sensors);
    for sensor in ["encoder", "localiser position"] {
        let row = sensors.iter().find(|r| r[0] == sensor).unwrap();
        let quoted = format!(
            "the {sensor} readings fail their chi-square test: {} against an expected {}",
            row[2], row[3]
        );
        assert!(verdict.contains(&quoted), "{verdict}");
        assert!(stderr.contains(&quoted), "{stderr}");
    }
    // A refusal, not an input error.
    assert!(!stderr.contains("invalid input"), "{stderr}");
    let mut accepted = args.to_vec();
    accepted.push("--accept-inconsistent");
    let (text, json) = text_and_json(dir.path(), &accepted);
    assert_calibrate_agrees(&text, &json);
    assert_eq!(json["gross_errors"]["excluded_readings"], Value::Array(Vec::new()));
}

#[test]
fn a_parse_error_and_a_report_name_a_row_alike() {
    let dir = tempfile::tempdir().unwrap();
    let guess = demo_file("guess.toml");
    // Row 3's f_ref_n not a number: the error names the row and its line ...
    let bad = demo_data(dir.path(), "bad.csv", |row, fields| {
        if row == 3 {
            fields[10] = "NaN".into();
        }
    });
    let (_, stderr, out) = run(
        dir.path(),
        &["calibrate", "--robot", &guess, "--data", bad.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: {}: row 3 (line 7), field `f_ref_n`: not a finite number: `NaN`",
            bad.display()
        )
    );
    // ... as the calibration's report names a blunder there.
    let blunder = demo_data(dir.path(), "blunder.csv", |row, fields| {
        if row == 3 {
            fields[9] = format!("{}", fields[9].parse::<f64>().unwrap() - 3.0);
        }
    });
    let (text, json) = text_and_json(
        dir.path(),
        &["calibrate", "--robot", &guess, "--data", blunder.to_str().unwrap()],
    );
    assert!(text.contains("\n  row 3 (line 7), encoder of cable 4: -"), "{text}");
    let test = &json["gross_errors"]["excluded_readings"][0]["test"];
    assert_eq!(reading_name(test), "row 3 (line 7), encoder of cable 4: ");
}

#[test]
fn localize_names_rows_alike_in_its_table_its_csv_and_its_json() {
    let dir = tempfile::tempdir().unwrap();
    let data = demo_data(dir.path(), "m.csv", |_, _| {});
    let truth = demo_file("truth.toml");
    let args = [
        "localize",
        "--robot",
        &truth,
        "--data",
        data.to_str().unwrap(),
        "--fast",
        "--out",
        "poses.csv",
    ];
    let (text, json) = text_and_json(dir.path(), &args);
    let rows = json["rows"].as_array().unwrap();
    let table = table(&text, "row ");
    assert_eq!(table.len(), rows.len());
    for (k, (cells, row)) in table.iter().zip(rows).enumerate() {
        // Row k + 1, on line k + 5 (two comments, a blank line and the header above).
        assert_eq!(
            (row["row"].as_u64(), row["line"].as_u64()),
            (Some(k as u64 + 1), Some(k as u64 + 5))
        );
        assert_eq!(cells[..2], [row["row"].to_string(), row["line"].to_string()]);
        let p = &row["position_m"];
        assert_eq!(cells[2], format!("{:.4}", p[0].as_f64().unwrap()));
    }
    let csv = std::fs::read_to_string(dir.path().join("poses.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(lines.next().unwrap().starts_with("row,line,x_m,"));
    for (line, row) in lines.zip(rows) {
        assert!(line.starts_with(&format!("{},{},", row["row"], row["line"])), "{line}");
    }
    // The RecurDyn log: rows counted among those kept, rejected ones named by their line.
    let Some(log) = shared_data::recurdyn_log() else { return };
    let large = robot("large");
    let (text, json) = text_and_json(
        dir.path(),
        &["localize", "--robot", &large, "--data", log.to_str().unwrap(), "--fast"],
    );
    let rows = json["rows"].as_array().unwrap();
    for (k, (cells, row)) in crate::table(&text, "row ").iter().zip(rows).enumerate() {
        assert_eq!(row["row"].as_u64(), Some(k as u64 + 1));
        assert_eq!(cells[..2], [row["row"].to_string(), row["line"].to_string()]);
    }
    for r in json["rejected"].as_array().unwrap() {
        assert!(r.get("row").is_none(), "{r}");
        let line = format!(
            "line {} left out by the loader: {}\n",
            r["line"],
            r["reason"].as_str().unwrap()
        );
        assert!(text.contains(&line), "{line}");
    }
}

#[test]
fn verify_names_rows_alike_in_its_table_and_its_json() {
    let dir = tempfile::tempdir().unwrap();
    let data = demo_data(dir.path(), "m.csv", |_, _| {});
    let truth = demo_file("truth.toml");
    let (text, json) = text_and_json(
        dir.path(),
        &["verify", "--robot", &truth, "--data", data.to_str().unwrap()],
    );
    let rows = json["rows"].as_array().unwrap();
    let table = table(&text, "row ");
    assert_eq!(table.len(), rows.len());
    for (k, (cells, row)) in table.iter().zip(rows).enumerate() {
        assert_eq!(
            (row["row"].as_u64(), row["line"].as_u64()),
            (Some(k as u64 + 1), Some(k as u64 + 5))
        );
        assert_eq!(cells[..2], [row["row"].to_string(), row["line"].to_string()]);
        assert_eq!(cells[2], format!("{:.3}", row["position_m"][0].as_f64().unwrap()));
        // dL4 %, after row, line, x, y, z, dL1 .. dL3.
        assert_eq!(cells[8], format!("{:.5}", row["length_error_pct"][3].as_f64().unwrap()));
    }
    let Some(log) = shared_data::recurdyn_log() else { return };
    let large = robot("large");
    let (text, json) = text_and_json(
        dir.path(),
        &["verify", "--robot", &large, "--data", log.to_str().unwrap()],
    );
    for (k, (cells, row)) in crate::table(&text, "row ")
        .iter()
        .zip(json["rows"].as_array().unwrap())
        .enumerate()
    {
        assert_eq!(row["row"].as_u64(), Some(k as u64 + 1));
        assert_eq!(cells[..2], [row["row"].to_string(), row["line"].to_string()]);
    }
    for r in json["rows_rejected"].as_array().unwrap() {
        let line = format!(
            "  line {:>3}: {}\n",
            r["line"].as_u64().unwrap(),
            r["reason"].as_str().unwrap()
        );
        assert!(text.contains(&line), "{line}");
    }
}

#[test]
fn diagnose_names_the_readings_it_left_out_alike_in_text_and_json() {
    let dir = tempfile::tempdir().unwrap();
    // Cables 1 and 2 swapped in row 10 (a mistake named), cable 4 of row 20 4 m long.
    let data = demo_data(dir.path(), "m.csv", |row, fields| match row {
        10 => fields.swap(6, 7),
        20 => fields[9] = format!("{}", fields[9].parse::<f64>().unwrap() + 4.0),
        _ => {}
    });
    let guess = demo_file("guess.toml");
    let args = [
        "diagnose",
        "--robot",
        &guess,
        "--data",
        data.to_str().unwrap(),
        "--candidates",
        "encoder-gain",
        "--folds",
        "2",
    ];
    let (text, json) = text_and_json(dir.path(), &args);
    let excluded = json["excluded_readings"].as_array().unwrap();
    assert_eq!(excluded.len(), 3, "{text}");
    for x in excluded {
        let name = format!("   {}", reading_name(&x["test"]));
        assert!(text.lines().any(|l| l.starts_with(&name)), "`{name}` not in:\n{text}");
    }
    let names: Vec<String> = excluded.iter().map(|x| reading_name(&x["test"])).collect();
    assert!(
        names.contains(&"row 20 (line 24), encoder of cable 4: ".to_string()),
        "{names:?}"
    );
    let mistakes = json["mistakes"].as_array().unwrap();
    for m in mistakes {
        let message = m["message"].as_str().unwrap();
        assert!(text.contains(&format!("   MISTAKE: {message}\n")), "{message}");
    }
    let swap = mistakes
        .iter()
        .find(|m| m["kind"] == "swapped_cables")
        .expect("the swap named");
    assert_eq!(swap["rows"], serde_json::json!([{"row": 10, "line": 14}]), "{swap}");
    let message = swap["message"].as_str().unwrap();
    assert!(
        message.starts_with("row 10 (line 14): the readings of cables 1 and 2 are swapped"),
        "{message}"
    );
    let first = text.lines().find(|l| l.starts_with("1. baseline model")).unwrap();
    let chi_square = format!(
        "chi-square {:.1} for {} degrees",
        json["baseline_chi_square"].as_f64().unwrap(),
        json["baseline_dof"]
    );
    assert!(first.contains(&chi_square), "{first} / {chi_square}");
}

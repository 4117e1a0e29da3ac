//! `sagcal init` and `sagcal check`, run as a user runs them: a new robot
//! file that loads and reads back to the same robot, a refusal that names
//! the flag, and what `check` says of the demo's data, the shared RecurDyn
//! log, readings alone and files in the wrong unit. The expected numbers are
//! computed here from the inputs and the files, not taken from sagcal.

#[path = "common/cli.rs"]
mod cli;
#[path = "common/shared_data.rs"]
mod shared_data;

use std::path::Path;
use std::process::Output;

use cli::sagcal;
use sagcal::model::Robot;
use serde_json::Value;

const ANCHORS: [[f64; 3]; 4] = [
    [-6.25, -2.25, 28.5],
    [6.25, -2.25, 28.5],
    [6.25, 2.25, 28.5],
    [-6.25, 2.25, 28.5],
];
const ATTACHMENTS: [[f64; 3]; 4] = [
    [-0.21, -0.21, -0.011],
    [0.21, -0.21, -0.011],
    [0.21, 0.21, -0.011],
    [-0.21, 0.21, -0.011],
];

fn triple(p: &[f64; 3]) -> String {
    format!("{},{},{}", p[0], p[1], p[2])
}

/// The flags of a lab robot: `--anchor=x,y,z` (the `=` lets a value start
/// with `-`), each `(flag, value)` of `replaced` in place of the lab's.
fn lab_flags_with(attachment_scale: f64, replaced: &[(&str, &str)]) -> Vec<String> {
    let mut flags = Vec::new();
    for a in &ANCHORS {
        flags.push(format!("--anchor={}", triple(a)));
    }
    for b in &ATTACHMENTS {
        flags.push(format!("--attachment={}", triple(&b.map(|v| v * attachment_scale))));
    }
    flags.extend(
        [
            "--platform-mass-kg",
            "4.4",
            "--cable-mass-per-m-kg",
            "0.0102",
            "--com-offset-m=0,0,-0.3",
            "--axial-stiffness-n",
            "2e4",
            "--reference-cable",
            "2",
            "--workspace=-2,2,-0.8,0.8,3,18",
        ]
        .map(String::from),
    );
    for (flag, value) in replaced {
        let at = flags.iter().position(|f| f == flag).unwrap();
        flags[at + 1] = value.to_string();
    }
    flags
}

fn lab_flags(attachment_scale: f64) -> Vec<String> {
    lab_flags_with(attachment_scale, &[])
}

fn run(dir: &Path, args: &[String]) -> Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    sagcal(dir, &args)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The JSON of `sagcal check --robot R --data D --json`.
fn check_json(dir: &Path, robot: &Path, data: &Path) -> Value {
    let out = sagcal(
        dir,
        &[
            "check",
            "--robot",
            robot.to_str().unwrap(),
            "--data",
            data.to_str().unwrap(),
            "--json",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    serde_json::from_str(&stdout(&out)).unwrap()
}

#[test]
fn init_writes_a_commented_file_that_loads_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = vec!["init".to_string()];
    args.extend(lab_flags(1.0));
    args.extend(["--out".into(), "lab.toml".into()]);
    let out = run(dir.path(), &args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let path = dir.path().join("lab.toml");
    let robot = Robot::from_file(&path).unwrap();
    assert_eq!(robot.name, "lab", "named after the file");
    for i in 0..4 {
        assert_eq!(<[f64; 3]>::from(robot.anchors_m[i]), ANCHORS[i]);
        assert_eq!(<[f64; 3]>::from(robot.attachments_m[i]), ATTACHMENTS[i]);
    }
    // 4.4 kg and 10.2 g/m at 9.81 m/s^2.
    assert!(
        (robot.platform_weight_n - 43.164).abs() < 1e-12,
        "{}",
        robot.platform_weight_n
    );
    assert!((robot.cable_weight_n_per_m - 0.100062).abs() < 1e-15);
    assert_eq!(robot.reference_cable, 1, "cable 2, 0-based");
    assert_eq!(robot.effects.axial_stiffness_n, Some(2e4));
    assert_eq!(<[f64; 3]>::from(robot.com_offset_m), [0.0, 0.0, -0.3]);
    let workspace = robot.workspace.unwrap();
    assert_eq!(
        (workspace.min_m, workspace.max_m),
        ([-2.0, -0.8, 3.0], [2.0, 0.8, 18.0])
    );
    // Written by the library and read back: the same robot, to the last bit.
    let again = dir.path().join("again.toml");
    std::fs::write(&again, robot.to_file_contents().to_toml().unwrap()).unwrap();
    assert_eq!(Robot::from_file(&again).unwrap(), robot);
    // Every key has a comment line right above it.
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    for (k, line) in lines.iter().enumerate() {
        if line.contains(" = ") && !line.starts_with('#') {
            assert!(
                k > 0 && lines[k - 1].starts_with('#'),
                "no comment above `{line}`:\n{text}"
            );
        }
    }
    // Without --out the same text goes to stdout.
    let printed = run(
        dir.path(),
        &[args[..args.len() - 2].to_vec(), vec!["--name".into(), "lab".into()]].concat(),
    );
    assert_eq!(stdout(&printed), text);
}

#[test]
fn init_refuses_to_overwrite_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("robot.toml");
    std::fs::write(&path, "keep me\n").unwrap();
    let out = sagcal(dir.path(), &["init", "--from-template", "small", "--out", "robot.toml"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--force"), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "keep me\n");
    let out = sagcal(
        dir.path(),
        &["init", "--from-template", "small", "--out", "robot.toml", "--force"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // The small template's values, under the file's name and without the paper's mark.
    let small = Robot::builtin("small").unwrap();
    let robot = Robot::from_file(&path).unwrap();
    assert_eq!(robot.name, "robot");
    assert_eq!(robot.paper_robot, None);
    assert_eq!(
        (robot.anchors_m, robot.platform_weight_n, robot.workspace),
        (small.anchors_m, small.platform_weight_n, small.workspace)
    );
}

#[test]
fn implausible_input_is_refused_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(Vec<String>, &str); 4] = [
        // Attachment points typed in millimetres: a platform 594 m across.
        (lab_flags(1e3), "--attachment"),
        (
            lab_flags_with(1.0, &[("--platform-mass-kg", "1e-7")]),
            "--platform-mass-kg 1e-7",
        ),
        // 10.2 kg/m (grams typed as kilograms) on a 4.4 kg platform.
        (
            lab_flags_with(1.0, &[("--cable-mass-per-m-kg", "10.2")]),
            "--cable-mass-per-m-kg 10.2",
        ),
        // EA in kN.
        (
            lab_flags_with(1.0, &[("--axial-stiffness-n", "20")]),
            "--axial-stiffness-n 20",
        ),
    ];
    for (flags, named) in cases {
        let mut args = vec!["init".to_string()];
        args.extend(flags);
        args.extend(["--out".into(), "bad.toml".into()]);
        let out = run(dir.path(), &args);
        let message = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{message}");
        assert!(message.contains(named), "expected `{named}` in: {message}");
        assert!(!message.contains("panicked"), "{message}");
        assert!(!dir.path().join("bad.toml").exists(), "nothing is written");
    }
}

/// The demo's files in `dir/demo`.
fn demo(dir: &Path) -> std::path::PathBuf {
    let out = sagcal(dir, &["demo", "--poses", "12", "--out-dir", "demo", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    dir.join("demo")
}

/// The data lines of a CSV (not blank, not a comment), with their 1-based line numbers, header first.
fn data_lines(path: &Path) -> Vec<(usize, String)> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|(i, l)| (i + 1, l.to_string()))
        .collect()
}

/// Equal to the last bits serde_json's float parsing keeps (it may be one
/// unit in the last place off the shortest form sagcal writes).
fn assert_close(found: &[f64], expected: &[f64]) {
    assert_eq!(found.len(), expected.len(), "{found:?} against {expected:?}");
    for (f, e) in found.iter().zip(expected) {
        assert!(
            (f - e).abs() <= 4.0 * f64::EPSILON * e.abs(),
            "{found:?} against {expected:?}"
        );
    }
}

fn numbers(line: &str) -> Vec<f64> {
    line.split(',')
        .filter(|f| !f.trim().is_empty())
        .filter_map(|f| f.trim().parse().ok())
        .collect()
}

#[test]
fn check_reads_the_demo_data_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let demo = demo(dir.path());
    let data = demo.join("data.csv");
    let lines = data_lines(&data);
    let report = check_json(dir.path(), &demo.join("guess.toml"), &data);
    let read = &report["data"];
    assert_eq!(read["format"], "sagcal-csv");
    assert_eq!(read["rows"], lines.len() - 1);
    // Row 1 is the first line after the header, its values as written.
    let (line, text) = &lines[1];
    assert_eq!(read["samples"][0]["row"], 1);
    assert_eq!(read["samples"][0]["line"], *line);
    let values: Vec<f64> = read["samples"][0]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_close(&values, &numbers(text));
    // x_m's range is the column's.
    let xs: Vec<f64> = lines[1..].iter().map(|(_, l)| numbers(l)[0]).collect();
    let x = &read["columns"][0];
    assert_eq!((x["column"].as_str(), x["unit"].as_str()), (Some("x_m"), Some("m")));
    assert_close(
        &[x["range"]["min"].as_f64().unwrap(), x["range"]["max"].as_f64().unwrap()],
        &[
            xs.iter().cloned().fold(f64::INFINITY, f64::min),
            xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        ],
    );
    assert_eq!(read["sensors"]["load_cell_cable"], 1);
    assert_eq!(read["sensors"]["localiser_orientation"], "measured");
    assert_eq!(report["warnings"].as_array().unwrap().len(), 0, "{report:#}");
    // The text says the same.
    let out = sagcal(
        dir.path(),
        &[
            "check",
            "--robot",
            demo.join("guess.toml").to_str().unwrap(),
            "--data",
            data.to_str().unwrap(),
        ],
    );
    let text = stdout(&out);
    assert!(text.contains(&format!("{} rows", lines.len() - 1)), "{text}");
    assert!(text.contains(&format!("row 1 (line {line})")), "{text}");
    assert!(text.contains("warnings: none"), "{text}");
}

/// The demo's data with `edit` applied to every data row's numbers.
fn edited(demo: &Path, name: &str, edit: impl Fn(&mut Vec<f64>)) -> std::path::PathBuf {
    let lines = data_lines(&demo.join("data.csv"));
    let mut text = lines[0].1.clone() + "\n";
    for (_, line) in &lines[1..] {
        let mut values = numbers(line);
        edit(&mut values);
        text += &(values.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(",") + "\n");
    }
    let path = demo.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn warnings(report: &Value) -> Vec<(String, String)> {
    report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| {
            (
                w["kind"].as_str().unwrap().to_string(),
                w["message"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn a_file_in_millimetres_is_flagged() {
    let dir = tempfile::tempdir().unwrap();
    let demo = demo(dir.path());
    let robot = demo.join("guess.toml");
    // The encoders in mm.
    let encoders = edited(&demo, "encoders-mm.csv", |v| {
        v[6..10].iter_mut().for_each(|l| *l *= 1e3)
    });
    let found = warnings(&check_json(dir.path(), &robot, &encoders));
    for cable in 1..=4 {
        assert!(
            found.iter().any(|(kind, m)| kind == "unit"
                && m.contains(&format!("encoder of cable {cable} "))
                && m.contains("mm")),
            "cable {cable}: {found:#?}"
        );
    }
    // The whole file in mm: positions and encoders.
    let all = edited(&demo, "all-mm.csv", |v| {
        for k in [0, 1, 2, 6, 7, 8, 9] {
            v[k] *= 1e3;
        }
    });
    let found = warnings(&check_json(dir.path(), &robot, &all));
    assert!(
        found.iter().any(|(_, m)| m.contains("positions look like mm")),
        "{found:#?}"
    );
    // The load cell in kN.
    let kn = edited(&demo, "kn.csv", |v| v[10] /= 1e3);
    let found = warnings(&check_json(dir.path(), &robot, &kn));
    assert!(
        found.iter().any(|(kind, m)| kind == "unit" && m.contains("kN")),
        "{found:#?}"
    );
    // Readings alone, in mm: no poses, the spread against the frame tells.
    let lines = data_lines(&demo.join("data.csv"));
    let mut text = "l1_m,l2_m,l3_m,l4_m\n".to_string();
    for (_, line) in &lines[1..] {
        let v = numbers(line);
        text += &(v[6..10]
            .iter()
            .map(|l| format!("{:?}", l * 1e3))
            .collect::<Vec<_>>()
            .join(",")
            + "\n");
    }
    let readings = demo.join("readings-mm.csv");
    std::fs::write(&readings, text).unwrap();
    let report = check_json(dir.path(), &robot, &readings);
    assert_eq!(report["data"]["format"], "readings-only-csv");
    assert_eq!(report["data"]["rows"], lines.len() - 1);
    assert_eq!(report["data"]["sensors"]["load_cell_rows"], 0);
    let found = warnings(&report);
    assert_eq!(found.iter().filter(|(kind, _)| kind == "unit").count(), 4, "{found:#?}");
}

#[test]
fn check_reads_the_recurdyn_log() {
    let Some(log) = shared_data::recurdyn_log() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let report = check_json(dir.path(), Path::new(&cli::robot("large")), &log);
    let read = &report["data"];
    assert_eq!(read["format"], "recurdyn-log");
    // Every data line is a row read or a row left out with its reason.
    let lines = data_lines(&log);
    let rows = read["rows"].as_u64().unwrap() as usize;
    let rejected = read["rejected"].as_array().unwrap().len();
    assert_eq!(rows + rejected, lines.len() - 1, "{read:#}");
    assert!(rows >= 35, "the paper calibrates on 35 of its rows: {rows}");
    // Row 1 is the first line not left out, as the file has it (the RecurDyn
    // columns pitch, roll are read as roll, pitch).
    let left_out: Vec<u64> = read["rejected"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["line"].as_u64().unwrap())
        .collect();
    let (line, text) = lines[1..]
        .iter()
        .find(|(l, _)| !left_out.contains(&(*l as u64)))
        .unwrap();
    assert_eq!(read["samples"][0]["line"], *line);
    let v = numbers(text);
    let expected = [v[0], v[1], v[2], v[4], v[3], v[5], v[6], v[7], v[8], v[9], v[10]];
    let values: Vec<f64> = read["samples"][0]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_close(&values, &expected);
    assert_eq!(read["columns"][6]["column"], "L1");
    let kinds: Vec<String> = warnings(&report).into_iter().map(|(k, _)| k).collect();
    assert_eq!(kinds, ["rejected"], "the log is of this robot, in its units");
}

#[test]
fn unreadable_files_are_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = sagcal(
        dir.path(),
        &["check", "--robot", &cli::robot("large"), "--data", "missing.csv"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("missing.csv"), "{}", stderr(&out));
    std::fs::write(dir.path().join("junk.csv"), "a,b\n1,2\n").unwrap();
    let out = sagcal(
        dir.path(),
        &["check", "--robot", &cli::robot("large"), "--data", "junk.csv"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("junk.csv: line 1"), "{}", stderr(&out));
    let out = sagcal(dir.path(), &["check", "--robot", "junk.csv"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("junk.csv"), "{}", stderr(&out));
}

/// `sagcal check` on robots of six and eight cables and their simulated
/// files: the load cells, the free force components (`2N - 6`), every
/// column, the encoders following the geometry (slope about 1); then the
/// same file with one encoder in mm, the load cell in kN, the positions in
/// mm, each named; a reading shorter than its chord named with its row.
#[test]
fn check_reads_robots_of_six_and_eight_cables_and_names_their_mistakes() {
    let dir = tempfile::tempdir().unwrap();
    for (name, cells, free) in [("six", vec![1], 6), ("eight", vec![1, 5], 10)] {
        let robot = cli::robot(name);
        let data = dir.path().join(format!("{name}.csv"));
        let simulate = [
            "simulate",
            "--robot",
            &robot,
            "--poses",
            "12",
            "--seed",
            "5",
            "--out",
            data.to_str().unwrap(),
        ];
        assert!(sagcal(dir.path(), &simulate).status.success());
        let report = check_json(dir.path(), Path::new(&robot), &data);
        let cables = if name == "six" { 6 } else { 8 };
        assert_eq!(report["robot"]["cables"], cables);
        assert_eq!(report["robot"]["free_force_components"], free);
        let read: Vec<u64> = report["robot"]["load_cells"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap())
            .collect();
        assert_eq!(read, cells);
        assert_eq!(report["data"]["rows"], 12);
        assert_eq!(
            report["data"]["columns"].as_array().unwrap().len(),
            6 + cables + cells.len()
        );
        assert!(warnings(&report).is_empty(), "{:?}", warnings(&report));
        for g in report["data"]["geometry"].as_array().unwrap() {
            let slope = g["slope"].as_f64().unwrap();
            assert!((0.9..1.1).contains(&slope), "{name}: {g}");
        }
    }
    let text = sagcal(
        dir.path(),
        &["check", "--robot", &cli::robot("six"), "--data", "six.csv"],
    );
    let printed = stdout(&text);
    assert!(
        printed.contains("load cells on cable 1;") && printed.contains("warnings: none"),
        "{printed}"
    );
    // The six-cable file, damaged one way at a time: (column index, scale, words expected).
    let original = std::fs::read_to_string(dir.path().join("six.csv")).unwrap();
    let cases = [
        (8, 1e3, "column l3_m", "look like mm"),
        (12, 1e-3, "column f1_n", "look like kN"),
        (0, 1e3, "the positions", "look like mm"),
    ];
    for (column, scale, what, words) in cases {
        let damaged: String = original
            .lines()
            .map(|line| {
                if line.starts_with('#') || line.starts_with('x') {
                    return format!("{line}\n");
                }
                let mut values: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
                let columns = if column == 0 { 0..3 } else { column..column + 1 };
                values[columns].iter_mut().for_each(|v| *v *= scale);
                values.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(",") + "\n"
            })
            .collect();
        let path = dir.path().join("damaged.csv");
        std::fs::write(&path, damaged).unwrap();
        let report = check_json(dir.path(), Path::new(&cli::robot("six")), &path);
        let found = warnings(&report);
        assert!(
            found
                .iter()
                .any(|(kind, message)| kind == "unit" && message.contains(what) && message.contains(words)),
            "{what}: {found:?}"
        );
    }
    // Row 4's encoder 2 half a metre short: shorter than the straight line.
    let mut row = 0;
    let short: String = original
        .lines()
        .map(|line| {
            if line.starts_with('#') || line.starts_with('x') {
                return format!("{line}\n");
            }
            row += 1;
            let mut values: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
            if row == 4 {
                values[7] -= 0.5;
            }
            values.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(",") + "\n"
        })
        .collect();
    let path = dir.path().join("short.csv");
    std::fs::write(&path, short).unwrap();
    let found = warnings(&check_json(dir.path(), Path::new(&cli::robot("six")), &path));
    assert!(
        found
            .iter()
            .any(|(kind, m)| kind == "geometry" && m.starts_with("cable 2:") && m.contains("row 4 (line")),
        "{found:?}"
    );
}

//! Answers the commands must check before they print them: `verify` with the
//! robot's encoder offsets, `localize` rows outside the robot's frame, the
//! massless cable, and the experiments' options checked up front.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn sagcal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

/// The folder `sagcal demo` writes (truth.toml with random encoder offsets,
/// calibrated.toml, data.csv), made once per test process.
fn demo() -> &'static Path {
    static DEMO: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &DEMO
        .get_or_init(|| {
            let dir = tempfile::tempdir().unwrap();
            let out = sagcal(dir.path(), &["demo"]);
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
            let path = dir.path().join("sagcal-demo");
            (dir, path)
        })
        .1
}

fn ok_json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn verify_adds_the_robots_length_offsets_to_its_predicted_encoder_readings() {
    let d = demo();
    let dir = tempfile::tempdir().unwrap();
    let truth = d.join("truth.toml");
    let truth = truth.to_str().unwrap();
    let text = std::fs::read_to_string(truth).unwrap();
    assert!(
        !text.contains("length_offsets_m = [0.0, 0.0, 0.0, 0.0]"),
        "the demo truth has offsets"
    );
    let out = sagcal(
        dir.path(),
        &[
            "simulate", "--robot", truth, "--poses", "10", "--noise", "none", "--out", "nn.csv",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // Noise-free data of the same robot: every reading predicted to 1e-6 %.
    let report = ok_json(&sagcal(
        dir.path(),
        &["verify", "--robot", truth, "--data", "nn.csv", "--json"],
    ));
    assert_eq!(report["lengths"], "encoder-readings");
    assert_eq!(report["rows"].as_array().unwrap().len(), 10);
    let mpe = report["mpe_length_pct"].as_f64().unwrap();
    assert!(
        mpe < 1e-6,
        "MPE-L {mpe} % on noise-free data of the same robot (1.33 % without the offsets)"
    );
    // The cable-lengths closure reads the same readings as lengths plus offsets.
    let report = ok_json(&sagcal(
        dir.path(),
        &[
            "verify",
            "--robot",
            truth,
            "--data",
            "nn.csv",
            "--close-with",
            "cable-lengths",
            "--json",
        ],
    ));
    let (mpe_l, mpe_f) = (
        report["mpe_length_pct"].as_f64().unwrap(),
        report["mpe_force_pct"].as_f64().unwrap(),
    );
    assert!(mpe_l < 1e-6 && mpe_f < 1e-4, "MPE-L {mpe_l} %, MPE-F {mpe_f} %");
    let text = String::from_utf8_lossy(&sagcal(dir.path(), &["verify", "--robot", truth, "--data", "nn.csv"]).stdout)
        .into_owned();
    assert!(text.contains("lengths compared as: encoder readings"), "{text}");
}

#[test]
fn localize_flags_a_pose_below_the_floor() {
    let d = demo();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("r.csv"), "l1_m,l2_m,l3_m,l4_m\n1000,1000,1000,1000\n").unwrap();
    let robot = d.join("calibrated.toml");
    let robot = robot.to_str().unwrap();
    let report = ok_json(&sagcal(
        dir.path(),
        &["localize", "--robot", robot, "--data", "r.csv", "--json"],
    ));
    assert_eq!(report["rows_flagged"], 1);
    let row = &report["rows"][0];
    let z = row["position_m"][2].as_f64().unwrap();
    assert!(z < -900.0, "{row}");
    let flag = row["flag"].as_str().unwrap();
    assert!(
        flag.contains("outside the frame") && flag.contains("below the floor"),
        "{flag}"
    );
    let out = sagcal(dir.path(), &["localize", "--robot", robot, "--data", "r.csv"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("FLAG") && text.contains("below the floor"), "{text}");
    assert!(text.contains("flagged: 1"), "{text}");
    // The demo's own data: every row inside the frame, none flagged.
    let data = d.join("data.csv");
    let report = ok_json(&sagcal(
        dir.path(),
        &[
            "localize",
            "--robot",
            d.join("truth.toml").to_str().unwrap(),
            "--data",
            data.to_str().unwrap(),
            "--fast",
            "--json",
        ],
    ));
    assert_eq!(report["rows_flagged"], 0, "{report}");
}

#[test]
fn localize_a_massless_cable_finds_the_stable_equilibria() {
    let d = demo();
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(d.join("truth.toml")).unwrap();
    for weight in ["0.0", "1e-9", "1e-3"] {
        let robot: String = text
            .lines()
            .map(|l| {
                if l.starts_with("cable_weight_n_per_m") {
                    format!("cable_weight_n_per_m = {weight}\n")
                } else {
                    format!("{l}\n")
                }
            })
            .collect();
        let path = dir.path().join(format!("m{weight}.toml"));
        std::fs::write(&path, robot).unwrap();
        let path = path.to_str().unwrap();
        let data = format!("m{weight}.csv");
        let out = sagcal(
            dir.path(),
            &["simulate", "--robot", path, "--poses", "20", "--out", &data],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let report = ok_json(&sagcal(
            dir.path(),
            &["localize", "--robot", path, "--data", &data, "--fast", "--json"],
        ));
        let rows = report["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 20);
        assert_eq!(report["rows_flagged"], 0, "g_c = {weight}: {report}");
        assert!(rows.iter().all(|r| r["stable"] == true), "g_c = {weight}");
        // Within the paper noise's reach of the simulated poses.
        let rms = report["position_rms_error_m"].as_f64().unwrap();
        assert!(rms < 0.1, "g_c = {weight}: RMS {rms} m");
        // The noise-free data of the massless robot verify exactly.
        let out = sagcal(
            dir.path(),
            &[
                "simulate", "--robot", path, "--poses", "5", "--noise", "none", "--out", "nn.csv",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let report = ok_json(&sagcal(
            dir.path(),
            &["verify", "--robot", path, "--data", "nn.csv", "--json"],
        ));
        assert!(
            report["mpe_length_pct"].as_f64().unwrap() < 1e-6,
            "g_c = {weight}: {report}"
        );
    }
}

#[test]
fn experiments_check_their_options_before_running() {
    let d = demo();
    let dir = tempfile::tempdir().unwrap();
    let (truth, data) = (d.join("truth.toml"), d.join("data.csv"));
    let (truth, data) = (truth.to_str().unwrap(), data.to_str().unwrap());
    let cases: [(&[&str], &str); 9] = [
        (
            &["hidden-effects", "--seeds", "1", "--poses", "0", "--robots", "small"],
            "--poses",
        ),
        (
            &["hidden-effects", "--seeds", "1", "--poses", "9", "--robots", "small"],
            "at least 10 poses",
        ),
        (&["hidden-effects", "--seeds", "1", "--segments", "0"], "--segments"),
        (&["hidden-effects", "--seeds", "0"], "--seeds"),
        (&["hidden-effects", "--robots", "small,small"], "--robots"),
        (
            &[
                "table2", "--robot", truth, "--data", data, "--poses", "0", "--trials", "1",
            ],
            "--poses 0",
        ),
        (
            &[
                "table2", "--robot", truth, "--data", data, "--poses", "9", "--trials", "0",
            ],
            "--trials",
        ),
        (
            &[
                "table2", "--robot", truth, "--data", data, "--poses", "99", "--trials", "1",
            ],
            "--poses 99: more poses than the data's 35 usable poses",
        ),
        (
            &[
                "localize", "--robot", truth, "--data", data, "--poses", "0", "--trials", "1",
            ],
            "--poses 0",
        ),
    ];
    for (args, expected) in cases {
        let mut all = vec!["experiment"];
        all.extend_from_slice(args);
        let out = sagcal(dir.path(), &all);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        let message = stderr(&out);
        assert!(message.contains(expected), "{args:?}: {message}");
        assert!(!message.contains("NaN"), "{args:?}: {message}");
    }
    let out = sagcal(
        dir.path(),
        &[
            "experiment",
            "localize",
            "--robot",
            truth,
            "--data",
            data,
            "--poses",
            "9",
            "--trials",
            "0",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("--trials"), "{}", stderr(&out));
}

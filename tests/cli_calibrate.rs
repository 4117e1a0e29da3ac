//! `sagcal simulate`, `calibrate` and `demo` end to end.

use std::path::Path;
use std::process::{Command, Output};

fn sagcal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

fn robot(name: &str) -> String {
    format!("{}/robots/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn simulate_then_calibrate_recovers_the_robot() {
    let dir = tempfile::tempdir().unwrap();
    let out = sagcal(
        dir.path(),
        &[
            "simulate",
            "--robot",
            &robot("large"),
            "--poses",
            "20",
            "--seed",
            "4",
            "--out",
            "m.csv",
            "--truth",
            "t.toml",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("seed 4"));
    // Same seed, same file.
    let again = sagcal(
        dir.path(),
        &[
            "simulate",
            "--robot",
            &robot("large"),
            "--poses",
            "20",
            "--seed",
            "4",
            "--out",
            "m2.csv",
        ],
    );
    assert!(again.status.success());
    assert_eq!(
        std::fs::read(dir.path().join("m.csv")).unwrap(),
        std::fs::read(dir.path().join("m2.csv")).unwrap()
    );
    // Calibrate from a nominal robot whose anchor 2 is 5 m off.
    let nominal = std::fs::read_to_string(robot("large"))
        .unwrap()
        .replace("anchor_m = [125.0, -110.0, 48.0]", "anchor_m = [128.0, -106.0, 48.0]");
    std::fs::write(dir.path().join("nominal.toml"), nominal).unwrap();
    let out = sagcal(
        dir.path(),
        &[
            "calibrate",
            "--robot",
            "nominal.toml",
            "--data",
            "m.csv",
            "--out",
            "cal.toml",
            "--plot",
            "a.svg",
            "--json",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["converged"], true);
    let anchors = report["anchors_m"].as_array().unwrap();
    let a2: Vec<f64> = anchors[1]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let error = ((a2[0] - 125.0).powi(2) + (a2[1] + 110.0).powi(2) + (a2[2] - 48.0).powi(2)).sqrt();
    let sigma: f64 = report["anchor_sigma_m"][1]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap().powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(error < 4.0 * sigma, "anchor 2 error {error} vs sigma {sigma}");
    for key in [
        "anchor_sigma_m",
        "length_offsets_m",
        "offset_sigma_m",
        "final_cost",
        "iterations",
        "termination",
    ] {
        assert!(!report[key].is_null(), "{key}");
    }
    let calibrated = std::fs::read_to_string(dir.path().join("cal.toml")).unwrap();
    assert!(calibrated.contains("length_offsets_m"));
    assert!(std::fs::read_to_string(dir.path().join("a.svg"))
        .unwrap()
        .contains("</svg>"));
}

fn expect_failure(dir: &Path, args: &[&str], needles: &[&str], must_not_exist: &[&str]) {
    let out = sagcal(dir, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "`{n}` missing from: {stderr}");
    }
    for f in must_not_exist {
        assert!(!dir.join(f).exists(), "{f} was written although the command failed");
    }
}

#[test]
fn bad_calibration_input_is_a_clear_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let header = "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m,l2_m,l3_m,l4_m,f_ref_n\n";
    let row = |x: f64| format!("{x},1,10,0,0,0,170,171,172,173,600\n");
    std::fs::write(
        p.join("three.csv"),
        format!("{header}{}{}{}", row(1.0), row(2.0), row(3.0)),
    )
    .unwrap();
    expect_failure(
        p,
        &[
            "calibrate",
            "--robot",
            &robot("large"),
            "--data",
            "three.csv",
            "--out",
            "c.toml",
        ],
        &["3 poses", "at least 4"],
        &["c.toml"],
    );
    std::fs::write(p.join("same.csv"), format!("{header}{}", row(1.0).repeat(6))).unwrap();
    expect_failure(
        p,
        &[
            "calibrate",
            "--robot",
            &robot("large"),
            "--data",
            "same.csv",
            "--out",
            "c.toml",
        ],
        &["same position"],
        &["c.toml"],
    );
    std::fs::write(p.join("cols.csv"), format!("{header}1,2,3\n")).unwrap();
    expect_failure(
        p,
        &[
            "calibrate",
            "--robot",
            &robot("large"),
            "--data",
            "cols.csv",
            "--out",
            "c.toml",
        ],
        &["cols.csv", "row 1 (line 2)", "expected 11"],
        &["c.toml"],
    );
    std::fs::write(
        p.join("neg.csv"),
        format!("{header}{}", row(1.0).replace(",600", ",-600")),
    )
    .unwrap();
    expect_failure(
        p,
        &[
            "calibrate",
            "--robot",
            &robot("large"),
            "--data",
            "neg.csv",
            "--out",
            "c.toml",
        ],
        &["neg.csv", "row 1 (line 2)", "f_ref_n", "negative tension"],
        &["c.toml"],
    );
    let bad_ref = std::fs::read_to_string(robot("large"))
        .unwrap()
        .replace("reference_cable = 1", "reference_cable = 5");
    std::fs::write(p.join("badref.toml"), bad_ref).unwrap();
    std::fs::write(
        p.join("ok.csv"),
        format!("{header}{}{}{}{}", row(1.0), row(2.0), row(3.0), row(4.0)),
    )
    .unwrap();
    expect_failure(
        p,
        &[
            "calibrate",
            "--robot",
            "badref.toml",
            "--data",
            "ok.csv",
            "--out",
            "c.toml",
        ],
        &["badref.toml", "reference_cable", "cable 5 does not exist"],
        &["c.toml"],
    );
    expect_failure(
        p,
        &["simulate", "--robot", "badref.toml", "--poses", "5", "--out", "s.csv"],
        &["badref.toml"],
        &["s.csv"],
    );
    expect_failure(
        p,
        &[
            "calibrate",
            "--robot",
            &robot("large"),
            "--data",
            "ok.csv",
            "--encoder-sigma-m=-1",
        ],
        &["--encoder-sigma-m"],
        &[],
    );
}

#[test]
fn demo_runs_with_a_seed_and_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = sagcal(dir.path(), &["demo", "--seed", "3", "--poses", "12", "--out-dir", "d"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains("seed 3") && stdout.contains("Cramer-Rao bound"),
        "{stdout}"
    );
    for f in ["data.csv", "truth.toml", "guess.toml", "calibrated.toml", "anchors.svg"] {
        assert!(dir.path().join("d").join(f).exists(), "{f}");
    }
    // Each robot file's header says what it is: only the calibrated one was estimated from measurements.
    let first_line = |f: &str| {
        let text = std::fs::read_to_string(dir.path().join("d").join(f)).unwrap();
        text.lines().next().unwrap_or_default().to_string()
    };
    for (f, header) in [
        (
            "truth.toml",
            "# The truth of sagcal demo (seed 3, 12 poses): the simulated robot's true parameters",
        ),
        (
            "guess.toml",
            "# The initial guess of sagcal demo (seed 3): the nominal robot the calibration starts from",
        ),
        (
            "calibrated.toml",
            "# Calibrated by sagcal: anchors and encoder length offsets estimated from measurements.",
        ),
    ] {
        assert!(first_line(f).starts_with(header), "{f}: {}", first_line(f));
    }
}

//! The files every command writes: all of them or none, and never one over a
//! file the command reads, however the path is spelled (`sagcal::io::OutputSet`).

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

#[path = "common/cli.rs"]
#[allow(dead_code)] // `robot`: these tests use the demo's robots
mod cli;
use cli::sagcal;

/// The folder `sagcal demo` writes (truth, guess, calibrated robot, data),
/// made once per run of these tests and only read.
fn demo() -> &'static Path {
    static DEMO: OnceLock<PathBuf> = OnceLock::new();
    DEMO.get_or_init(|| {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_outputs");
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(&root).unwrap();
        let out = sagcal(&root, &["demo", "--out-dir", "D"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        root.join("D")
    })
}

/// A fresh folder holding the demo's `guess.toml`, `truth.toml`,
/// `calibrated.toml` and its data as `d.csv`.
fn workspace() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (from, to) in [
        ("guess.toml", "guess.toml"),
        ("truth.toml", "truth.toml"),
        ("calibrated.toml", "calibrated.toml"),
        ("data.csv", "d.csv"),
    ] {
        std::fs::copy(demo().join(from), dir.path().join(to)).unwrap();
    }
    dir
}

/// The command failed with exit code 1 and an error holding every needle.
fn assert_refused(out: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "`{needle}` not in: {stderr}");
    }
}

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `d.csv` written again under other names: the same path spelled otherwise,
/// and on Unix a symbolic and a hard link.
fn spellings_of_the_data(dir: &Path) -> Vec<&'static str> {
    std::fs::create_dir(dir.join("sub")).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("d.csv", dir.join("link.csv")).unwrap();
        std::fs::hard_link(dir.join("d.csv"), dir.join("hard.csv")).unwrap();
        vec!["d.csv", "./d.csv", "sub/../d.csv", "link.csv", "hard.csv"]
    }
    #[cfg(not(unix))]
    vec!["d.csv", "./d.csv", "sub/../d.csv"]
}

#[test]
fn calibrate_never_writes_over_its_data_or_robot() {
    let dir = workspace();
    let d = dir.path();
    let data = std::fs::read(d.join("d.csv")).unwrap();
    let robot = std::fs::read(d.join("guess.toml")).unwrap();
    for out in spellings_of_the_data(d) {
        let run = sagcal(
            d,
            &["calibrate", "--robot", "guess.toml", "--data", "d.csv", "--out", out],
        );
        assert_refused(
            &run,
            &[&format!("--out {out} is the --data file d.csv"), "nothing was written"],
        );
        assert_eq!(std::fs::read(d.join("d.csv")).unwrap(), data, "--out {out}");
    }
    // Over the robot file, and the figure over the data.
    let run = sagcal(
        d,
        &[
            "calibrate",
            "--robot",
            "guess.toml",
            "--data",
            "d.csv",
            "--out",
            "./guess.toml",
        ],
    );
    assert_refused(&run, &["--out ./guess.toml is the --robot file guess.toml"]);
    let run = sagcal(
        d,
        &[
            "calibrate",
            "--robot",
            "guess.toml",
            "--data",
            "d.csv",
            "--out",
            "o.toml",
            "--plot",
            "d.csv",
        ],
    );
    assert_refused(&run, &["--plot d.csv is the --data file d.csv"]);
    assert!(!d.join("o.toml").exists());
    assert_eq!(std::fs::read(d.join("d.csv")).unwrap(), data);
    assert_eq!(std::fs::read(d.join("guess.toml")).unwrap(), robot);
}

#[test]
fn diagnose_never_writes_over_its_data_or_truth() {
    let dir = workspace();
    let d = dir.path();
    let data = std::fs::read(d.join("d.csv")).unwrap();
    let truth = std::fs::read(d.join("truth.toml")).unwrap();
    let quick = ["--candidates", "elastic", "--folds", "2"];
    let mut args = vec!["diagnose", "--robot", "guess.toml", "--data", "d.csv", "--plots", "P"];
    args.extend(quick);
    args.extend(["--out", "./d.csv"]);
    assert_refused(&sagcal(d, &args), &["--out ./d.csv is the --data file d.csv"]);
    assert_eq!(std::fs::read(d.join("d.csv")).unwrap(), data);
    assert!(!d.join("P").exists(), "the --plots folder was created");

    let mut args = vec![
        "diagnose",
        "--robot",
        "guess.toml",
        "--data",
        "d.csv",
        "--truth",
        "truth.toml",
    ];
    args.extend(quick);
    args.extend(["--out", "truth.toml"]);
    assert_refused(&sagcal(d, &args), &["--out truth.toml is the --truth file truth.toml"]);
    assert_eq!(std::fs::read(d.join("truth.toml")).unwrap(), truth);
}

#[test]
fn simulate_refuses_one_file_for_two_outputs_or_over_its_robot() {
    let dir = workspace();
    let d = dir.path();
    let run = sagcal(
        d,
        &[
            "simulate",
            "--robot",
            "truth.toml",
            "--poses",
            "3",
            "--out",
            "s.csv",
            "--truth",
            "./s.csv",
        ],
    );
    assert_refused(&run, &["--out s.csv and --truth ./s.csv name the same file"]);
    assert!(!d.join("s.csv").exists());
    let robot = std::fs::read(d.join("truth.toml")).unwrap();
    let run = sagcal(
        d,
        &[
            "simulate",
            "--robot",
            "truth.toml",
            "--poses",
            "3",
            "--out",
            "s.csv",
            "--truth",
            "truth.toml",
        ],
    );
    assert_refused(&run, &["--truth truth.toml is the --robot file truth.toml"]);
    assert!(!d.join("s.csv").exists());
    assert_eq!(std::fs::read(d.join("truth.toml")).unwrap(), robot);
}

#[test]
fn plan_never_writes_over_its_candidates() {
    let dir = workspace();
    let d = dir.path();
    let data = std::fs::read(d.join("d.csv")).unwrap();
    let run = sagcal(
        d,
        &[
            "plan",
            "--robot",
            "guess.toml",
            "--poses",
            "4",
            "--from",
            "d.csv",
            "--out",
            "./d.csv",
        ],
    );
    assert_refused(&run, &["--out ./d.csv is the --from file d.csv"]);
    assert_eq!(std::fs::read(d.join("d.csv")).unwrap(), data);
}

#[test]
fn demo_writes_all_its_files_or_none() {
    let dir = tempfile::tempdir().unwrap();
    // anchors.svg cannot be written (a folder is there): no other file appears.
    std::fs::create_dir_all(dir.path().join("E").join("anchors.svg")).unwrap();
    let run = sagcal(dir.path(), &["demo", "--out-dir", "E"]);
    assert_refused(&run, &["--out-dir", "anchors.svg", "is a folder"]);
    assert_eq!(listing(&dir.path().join("E")), ["anchors.svg"]);
}

/// `--out` (and for diagnose `--plots`) must not exist after `args` fail on
/// an unwritable figure, and an existing `--out` must be left as it was.
#[cfg(target_os = "linux")]
fn assert_nothing_written(dir: &Path, args: &[&str], out: &str, figure: &str) {
    let run = sagcal(dir, args);
    assert_refused(&run, &[figure, "nothing was written"]);
    assert!(!dir.join(out).exists(), "{out} was written: {args:?}");
    std::fs::write(dir.join(out), "before").unwrap();
    let run = sagcal(dir, args);
    assert_refused(&run, &[figure, "nothing was written"]);
    assert_eq!(std::fs::read_to_string(dir.join(out)).unwrap(), "before", "{args:?}");
    std::fs::remove_file(dir.join(out)).unwrap();
}

#[cfg(target_os = "linux")]
#[test]
fn calibrate_with_an_unwritable_plot_writes_no_robot() {
    let dir = workspace();
    let d = dir.path();
    let args = [
        "calibrate",
        "--robot",
        "guess.toml",
        "--data",
        "d.csv",
        "--out",
        "o.toml",
        "--plot",
        "/proc/x.svg",
    ];
    assert_nothing_written(d, &args, "o.toml", "/proc/x.svg: --plot: cannot write");
    // The same command with a writable figure writes both.
    let mut ok = args;
    ok[8] = "x.svg";
    let run = sagcal(d, &ok);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(std::fs::read_to_string(d.join("o.toml")).unwrap().contains("anchor_m"));
    assert!(std::fs::read_to_string(d.join("x.svg")).unwrap().contains("<svg"));
}

#[cfg(target_os = "linux")]
#[test]
fn localize_with_an_unwritable_plot_writes_no_poses() {
    let dir = workspace();
    let args = [
        "localize",
        "--robot",
        "calibrated.toml",
        "--data",
        "d.csv",
        "--fast",
        "--out",
        "lo.csv",
        "--plot",
        "/proc/x.svg",
    ];
    assert_nothing_written(dir.path(), &args, "lo.csv", "/proc/x.svg: --plot: cannot write");
}

#[cfg(target_os = "linux")]
#[test]
fn plan_with_an_unwritable_plot_writes_no_plan() {
    let dir = workspace();
    let args = [
        "plan",
        "--robot",
        "guess.toml",
        "--poses",
        "4",
        "--from",
        "d.csv",
        "--out",
        "pl.csv",
        "--plot",
        "/proc/x.png",
    ];
    assert_nothing_written(dir.path(), &args, "pl.csv", "/proc/x.png: --plot: cannot write");
}

#[cfg(target_os = "linux")]
#[test]
fn diagnose_with_an_unwritable_robot_creates_no_plots() {
    let dir = workspace();
    let d = dir.path();
    let args = [
        "diagnose",
        "--robot",
        "guess.toml",
        "--data",
        "d.csv",
        "--candidates",
        "elastic",
        "--folds",
        "2",
        "--plots",
        "P",
        "--out",
        "/proc/x.toml",
    ];
    let run = sagcal(d, &args);
    assert_refused(&run, &["/proc/x.toml: --out: cannot write", "nothing was written"]);
    assert!(!d.join("P").exists(), "the --plots folder was left behind");
}

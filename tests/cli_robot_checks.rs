//! A robot that cannot be a suspended robot, or of implausible magnitudes,
//! is named when its file is read; a box the robot cannot hang its platform
//! in is named before any pose is drawn; drawing is bounded (issue 30,
//! faults 6, 8, 9, 13, 16 and 18). Every case exits 1 with the reason, never
//! panics (exit 101) and writes nothing.

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

/// The large robot's file with each `anchor_m` line replaced by `anchor(i)`.
fn large_with_anchors(anchor: impl Fn(usize, &str) -> String) -> String {
    let text = std::fs::read_to_string(robot("large")).unwrap();
    let mut i = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            if line.starts_with("anchor_m") {
                i += 1;
                anchor(i - 1, line)
            } else {
                line.to_string()
            }
        })
        .collect();
    lines.join("\n") + "\n"
}

/// Anchors on the line y = 0 (fault 6).
fn collinear() -> String {
    large_with_anchors(|i, _| format!("anchor_m = [{}, 0.0, 48.0]", [-125.0, -40.0, 40.0, 125.0][i]))
}

/// The issue's `sed 's/^\(anchor_m = \[[^,]*,[^,]*,\).*/\1 -48.0]/'` (fault 8).
fn below() -> String {
    large_with_anchors(|_, line| {
        let cut = line.match_indices(',').nth(1).unwrap().0;
        format!("{}, -48.0]", &line[..cut])
    })
}

/// A clean failure: exit 1, the message in stderr, no panic.
fn fails_with(out: &Output, expected: &str) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains(expected), "expected `{expected}` in: {stderr}");
    stderr
}

/// A few poses of the large robot to verify and calibrate against.
fn data(dir: &Path) -> String {
    let out = sagcal(
        dir,
        &[
            "simulate",
            "--robot",
            &robot("large"),
            "--poses",
            "4",
            "--out",
            "data.csv",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    "data.csv".into()
}

#[test]
fn collinear_anchors_are_refused_by_verify_calibrate_and_plan() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("col.toml"), collinear()).unwrap();
    let data = data(dir.path());
    let verify = sagcal(dir.path(), &["verify", "--robot", "col.toml", "--data", &data]);
    let message = fails_with(
        &verify,
        "robot col.toml: anchors: their horizontal projections are collinear",
    );
    assert!(message.contains("0.000 m wide across 250.000 m"), "{message}");
    assert!(String::from_utf8_lossy(&verify.stdout).is_empty(), "no report at all");
    let calibrate = sagcal(
        dir.path(),
        &["calibrate", "--robot", "col.toml", "--data", &data, "--out", "o.toml"],
    );
    let message = fails_with(&calibrate, "are collinear");
    assert!(!message.contains("0 poses cannot determine"), "{message}");
    assert!(!dir.path().join("o.toml").exists());
    let plan = sagcal(
        dir.path(),
        &["plan", "--robot", "col.toml", "--poses", "4", "--candidates", "10"],
    );
    fails_with(&plan, "are collinear");
}

#[test]
fn anchors_below_the_platform_are_refused_without_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("b.toml"), below()).unwrap();
    let expected = "robot b.toml: cable 1: its anchor at z = -48 m is not above the platform";
    let simulate = sagcal(
        dir.path(),
        &["simulate", "--robot", "b.toml", "--poses", "5", "--out", "x.csv"],
    );
    fails_with(&simulate, expected);
    assert!(!dir.path().join("x.csv").exists());
    fails_with(
        &sagcal(dir.path(), &["plan", "--robot", "b.toml", "--poses", "4"]),
        expected,
    );
    let data = data(dir.path());
    let calibrate = sagcal(
        dir.path(),
        &["calibrate", "--robot", "b.toml", "--data", &data, "--out", "o.toml"],
    );
    fails_with(&calibrate, expected);
    assert!(!dir.path().join("o.toml").exists());
    // The same anchors with a box of positions below them are a robot (a frame with its origin up high).
    let hung = below() + "\n[workspace]\nmin_m = [-10.0, -10.0, -90.0]\nmax_m = [10.0, 10.0, -50.0]\n";
    std::fs::write(dir.path().join("hung.toml"), hung).unwrap();
    let out = sagcal(
        dir.path(),
        &["simulate", "--robot", "hung.toml", "--poses", "2", "--out", "h.csv"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_box_the_robot_cannot_reach_is_named_before_drawing() {
    let dir = tempfile::tempdir().unwrap();
    let plan = |workspace: &str| {
        sagcal(
            dir.path(),
            &[
                "plan",
                "--robot",
                &robot("small"),
                "--poses",
                "4",
                "--candidates",
                "4",
                "--workspace",
                workspace,
            ],
        )
    };
    let above = fails_with(
        &plan("-2,2,-0.8,0.8,30,40"),
        "--workspace [-2, -0.8, 30] .. [2, 0.8, 40] m cannot give candidate poses for robot `small`",
    );
    assert!(
        above.contains("the box's top z = 40 m is not below the anchor of cable 1 (z = 28.5 m)"),
        "{above}"
    );
    let beside = fails_with(&plan("100,110,100,110,3,18"), "cannot give candidate poses");
    assert!(
        beside.contains("lies 97.750 m outside the anchors' horizontal footprint"),
        "{beside}"
    );
}

#[test]
fn a_hopeless_box_under_the_anchors_fails_on_its_first_candidate() {
    // Under the anchors, but so low that every cable sags below the 0.5 m clearance:
    // candidate 1 of 1000 draws its 50 poses, all outside the margins, and the drawing stops.
    let dir = tempfile::tempdir().unwrap();
    let out = sagcal(
        dir.path(),
        &[
            "plan",
            "--robot",
            &robot("small"),
            "--poses",
            "4",
            "--workspace",
            "-2,2,-0.8,0.8,0.05,0.3",
        ],
    );
    let message = fails_with(
        &out,
        "candidate 1 of 1000 found none (its 50 poses drawn all failed: 50 outside the margins",
    );
    assert!(message.contains("below the 0.50 m clearance"), "{message}");
}

#[test]
fn identical_logged_poses_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let data = data(dir.path());
    let text = std::fs::read_to_string(dir.path().join(&data)).unwrap();
    let mut rows = text.lines().filter(|l| !l.starts_with('#'));
    let header = rows.next().unwrap();
    let row = rows.next().unwrap();
    std::fs::write(
        dir.path().join("five.csv"),
        format!("{header}\n{}", format!("{row}\n").repeat(5)),
    )
    .unwrap();
    let plan = sagcal(
        dir.path(),
        &["plan", "--robot", &robot("large"), "--from", "five.csv", "--poses", "5"],
    );
    let message = fails_with(
        &plan,
        "five.csv: the 5 logged poses are only 1 distinct pose (lines 2, 3, 4, 5, 6 are the same pose)",
    );
    assert!(message.contains("at least 4 distinct poses"), "{message}");
    assert!(!message.contains("choose at least 4"), "{message}");
}

#[test]
fn implausible_masses_and_pulleys_are_refused_when_read() {
    let dir = tempfile::tempdir().unwrap();
    let large = std::fs::read_to_string(robot("large")).unwrap();
    let with = |key: &str, value: &str| {
        large
            .lines()
            .map(|l| {
                if l.starts_with(key) {
                    format!("{key} = {value}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
            + "\n"
    };
    let cases = [
        (
            with("cable_weight_n_per_m", "1e6"),
            "field `cable_weight_n_per_m`: 1e6 N/m is above 2419 N/m",
        ),
        (
            with("platform_weight_n", "1e-300"),
            "field `platform_weight_n`: 1e-300 N is outside the plausible",
        ),
        (
            large.clone() + "\n[effects]\npulley_radius_m = 1e6\n",
            "table `effects`: field `pulley_radius_m`: 1000000 m is over a tenth of the 220.000 m",
        ),
    ];
    for (k, (text, expected)) in cases.iter().enumerate() {
        let name = format!("r{k}.toml");
        std::fs::write(dir.path().join(&name), text).unwrap();
        let out = sagcal(
            dir.path(),
            &["simulate", "--robot", &name, "--poses", "5", "--out", "x.csv"],
        );
        fails_with(&out, expected);
        assert!(!dir.path().join("x.csv").exists());
    }
    // The same pulley given on the command line.
    let out = sagcal(
        dir.path(),
        &[
            "simulate",
            "--robot",
            &robot("large"),
            "--poses",
            "2",
            "--effect",
            "pulley:radius_m=1e6",
            "--out",
            "x.csv",
        ],
    );
    fails_with(
        &out,
        "effects on robot `large`: field `pulley_radius_m`: 1000000 m is over a tenth",
    );
    assert!(!dir.path().join("x.csv").exists());
}

/// The work count of a run (`SAGCAL_REPORT_STEPS`): a bound on its time that no clock decides.
fn steps(out: &Output) -> u64 {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .find_map(|l| l.strip_prefix("sagcal steps: "))
        .and_then(|s| s.trim().parse().ok())
        .expect("the step count is printed")
}

/// A plan of 0 poses, or of more poses than candidates, is refused before a
/// single candidate is drawn (found by tests/prop_commands.rs: 26 million
/// steps of drawing, then "cannot choose 0 poses from 6 candidates").
#[test]
fn impossible_plan_counts_are_refused_before_drawing() {
    let dir = tempfile::tempdir().unwrap();
    for (poses, candidates, expected) in [
        ("0", "6", "poses = 0: a plan chooses at least 1 pose"),
        ("5", "3", "5 poses requested but only 3 candidates to draw"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_sagcal"))
            .args([
                "plan",
                "--robot",
                &robot("large"),
                "--poses",
                poses,
                "--candidates",
                candidates,
                "--out",
                "p.csv",
            ])
            .current_dir(dir.path())
            .env("SAGCAL_REPORT_STEPS", "1")
            .output()
            .unwrap();
        fails_with(&out, expected);
        assert_eq!(steps(&out), 0, "no statics evaluated before the refusal");
        assert!(!dir.path().join("p.csv").exists());
    }
}

/// A robot that solves none of the data's rows verifies nothing: exit 1 with
/// the first row's reason, not exit 0 with "rows verified 0" (found by
/// tests/prop_commands.rs with random robots against the large robot's data).
#[test]
fn a_verification_that_solves_no_row_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let data = data(dir.path());
    // A plausible robot 10 m across, whose frame none of the large robot's poses are in.
    let small = std::fs::read_to_string(robot("small")).unwrap();
    std::fs::write(dir.path().join("small.toml"), small).unwrap();
    let out = sagcal(dir.path(), &["verify", "--robot", "small.toml", "--data", &data]);
    let stderr = fails_with(&out, "nothing verified for robot `small`");
    assert!(stderr.contains("none of its 4 kept rows"), "{stderr}");
    let out = sagcal(
        dir.path(),
        &["verify", "--robot", "small.toml", "--data", &data, "--json"],
    );
    fails_with(&out, "nothing verified");
    assert!(out.stdout.is_empty(), "no report printed as if verified");
}

/// `simulate` on robots of three, six and eight cables writes what the
/// library draws for the same seed (the CLI adds nothing), in a file with a
/// column per cable and per load cell; `verify` takes the file, `diagnose`
/// refuses its four-cable flags by name.
#[test]
fn simulate_takes_three_to_eight_cables() {
    use rand::SeedableRng;
    use sagcal::io::suspended_measurements::read_suspended_measurements;
    use sagcal::model::sensors::NoisePreset;
    use sagcal::model::suspended::SuspendedRobot;
    use sagcal::sim::closed_form::Closure;
    use sagcal::sim::suspended::{measure_suspended, sample_suspended};

    let dir = tempfile::tempdir().unwrap();
    for (name, header_end) in [
        ("three", "l3_m,f1_n"),
        ("six", "l6_m,f1_n"),
        ("eight", "l8_m,f1_n,f5_n"),
    ] {
        let out = sagcal(
            dir.path(),
            &[
                "simulate",
                "--robot",
                &robot(name),
                "--poses",
                "7",
                "--seed",
                "5",
                "--out",
                "d.csv",
            ],
        );
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let path = dir.path().join("d.csv");
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(&format!("{header_end}\n")), "{name}: {text}");
        let suspended = SuspendedRobot::from_file(Path::new(&robot(name))).unwrap();
        let rows = read_suspended_measurements(&path, &suspended).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let poses = sample_suspended(&suspended, &suspended.workspace.unwrap(), 7, Closure::Level, &mut rng).unwrap();
        let expected = measure_suspended(
            &suspended,
            &poses,
            &NoisePreset::Paper.sigmas(suspended.platform_weight_n),
            &mut rng,
        )
        .unwrap();
        assert_eq!(rows.len(), 7);
        for (row, want) in rows.iter().zip(&expected) {
            assert_eq!(row.encoder_lengths_m, want.encoder_lengths_m, "{name}");
            assert_eq!(row.load_cell_tensions_n, want.load_cell_tensions_n, "{name}");
            assert_eq!(row.position_m, want.position_m, "{name}");
        }
        // `verify` takes the robot: the file it simulated is its own model.
        let verified = sagcal(
            dir.path(),
            &["verify", "--robot", &robot(name), "--data", "d.csv", "--json"],
        );
        let message = String::from_utf8_lossy(&verified.stderr);
        assert!(verified.status.success(), "{name}: {message}");
        let report: serde_json::Value = serde_json::from_slice(&verified.stdout).unwrap();
        assert_eq!(report["rows"].as_array().map(Vec::len), Some(7), "{name}");
        // `diagnose` takes the robot, and refuses the four-cable flag by name, writing nothing.
        let refused = sagcal(
            dir.path(),
            &["diagnose", "--robot", &robot(name), "--data", "d.csv", "--plots", "c"],
        );
        let message = String::from_utf8_lossy(&refused.stderr);
        assert_eq!(refused.status.code(), Some(1), "{name}: {message}");
        assert!(message.contains(&format!("--plots: robot `{name}` has")), "{message}");
        assert!(!dir.path().join("c").exists());
    }
}

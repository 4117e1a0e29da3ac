//! Calibration and localisation of robots of 3 to 8 cables: round trips
//! from simulated, noiseless readings, starting away from the truth; noisy
//! calibrations from 10 m off; the command and its refusals.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::calib::suspended::calibrate_suspended;
use sagcal::calib::CalibrationOptions;
use sagcal::localize::suspended::localize_suspended;
use sagcal::model::sensors::{NoisePreset, SensorNoise};
use sagcal::model::suspended::{SuspendedEquilibrium, SuspendedMeasurement, SuspendedRobot};
use sagcal::sim::closed_form::{Closure, Workspace};
use sagcal::sim::suspended::{measure_suspended, sample_suspended};

/// `count` noiseless readings of `truth` (seed `seed`), and the equilibria they were read at.
fn readings(truth: &SuspendedRobot, count: usize, seed: u64) -> (Vec<SuspendedMeasurement>, Vec<SuspendedEquilibrium>) {
    let workspace = truth
        .workspace
        .unwrap_or_else(|| Workspace::around_anchor_points(&truth.anchors_m));
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let closure = if truth.cable_count() > 3 {
        Closure::Yaw { max_yaw_deg: 5.0 }
    } else {
        Closure::Level
    };
    let equilibria = sample_suspended(truth, &workspace, count, closure, &mut rng).unwrap();
    let silent = NoisePreset::None.sigmas(truth.platform_weight_n);
    (
        measure_suspended(truth, &equilibria, &silent, &mut rng).unwrap(),
        equilibria,
    )
}

/// `truth` with offsets of a few decimetres, and a guess of it with every
/// anchor `guess_m` away along a fixed direction per cable.
fn truth_and_guess(name: &str, guess_m: f64) -> (SuspendedRobot, SuspendedRobot) {
    let mut truth = robot(name);
    truth.length_offsets_m = (0..truth.cable_count()).map(|i| 0.1 + 0.07 * i as f64).collect();
    let mut guess = truth.clone();
    for (i, anchor) in guess.anchors_m.iter_mut().enumerate() {
        let angle = 1.3 * i as f64;
        *anchor += guess_m * Vector3::new(angle.cos(), angle.sin(), 0.5).normalize();
    }
    guess.length_offsets_m = vec![0.0; truth.cable_count()];
    (truth, guess)
}

/// A built-in robot, or `five` / `seven`: the six- and eight-cable robots
/// without their last cable.
fn robot(name: &str) -> SuspendedRobot {
    match name {
        "five" => SuspendedRobot::builtin("six")
            .unwrap()
            .without_last_cable(name)
            .unwrap(),
        "seven" => SuspendedRobot::builtin("eight")
            .unwrap()
            .without_last_cable(name)
            .unwrap(),
        other => SuspendedRobot::builtin(other).unwrap(),
    }
}

fn paper_options(robot: &SuspendedRobot) -> CalibrationOptions {
    let noise: SensorNoise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
    CalibrationOptions::new(noise)
}

#[test]
fn noiseless_round_trips_recover_every_robot() {
    for name in ["three", "large", "five", "six", "seven", "eight"] {
        let (truth, guess) = truth_and_guess(name, 0.5);
        let (measurements, equilibria) = readings(&truth, 24, 11);
        let mut stages = Vec::new();
        // Noiseless data: stop on the step alone, not on a relative cost decrease.
        let mut options = paper_options(&truth);
        options.lm.relative_cost_tolerance = 0.0;
        options.lm.relative_step_tolerance = 1e-14;
        let result = calibrate_suspended(&guess, &measurements, &options, None, &mut |s| {
            stages.push(s.to_string())
        })
        .unwrap();
        let anchor_error = truth
            .anchors_m
            .iter()
            .zip(&result.robot.anchors_m)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        let offset_error = truth
            .length_offsets_m
            .iter()
            .zip(&result.robot.length_offsets_m)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{name}: {} cables, anchors {anchor_error:.2e} m, offsets {offset_error:.2e} m, stages {:?}, fell back {:?}",
            truth.cable_count(),
            result
                .stages
                .iter()
                .map(|s| (s.summary.iterations, s.summary.termination))
                .collect::<Vec<_>>(),
            result.fell_back
        );
        assert!(anchor_error < 1e-9 && offset_error < 1e-9, "{name}");
        // The calibrated robot localised from the same readings: every pose found again.
        let sigmas = NoisePreset::Paper.sigmas(truth.platform_weight_n);
        let mut worst: f64 = 0.0;
        for (row, eq) in measurements.iter().zip(&equilibria) {
            let found = localize_suspended(&result.robot, row, &sigmas, 1e-3).unwrap();
            assert!(found.consistent && found.stable, "{name}: {found:?}");
            worst = worst.max((found.pose.position_m - eq.pose.position_m).norm());
        }
        println!("{name}: localised positions {worst:.2e} m from the truth");
        assert!(worst < 1e-9, "{name}: {worst}");
    }
}

/// The four-cable robot calibrated by the graph of `N` cables (every
/// cable's forces its own variables) and by the four-cable graph (the other
/// forces from the reference cable's, eq. 11) from the same noisy readings:
/// the same model, so the same minimum, up to the finite sigmas of the
/// equilibrium and height constraints.
#[test]
fn four_cables_agree_with_the_four_cable_graph() {
    use sagcal::calib::{calibrate, OrientationPrior};
    use sagcal::model::measurement::PoseMeasurement;
    use sagcal::model::Robot;
    let four = Robot::builtin("large").unwrap();
    let truth = SuspendedRobot::from_robot(&four);
    let workspace = Workspace::default_for(&four);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let equilibria = sample_suspended(&truth, &workspace, 20, Closure::Yaw { max_yaw_deg: 5.0 }, &mut rng).unwrap();
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let measurements = measure_suspended(&truth, &equilibria, &noise, &mut rng).unwrap();
    let rows: Vec<PoseMeasurement> = measurements
        .iter()
        .map(|m| PoseMeasurement {
            position_m: m.position_m,
            roll_deg: m.roll_deg,
            pitch_deg: m.pitch_deg,
            yaw_deg: m.yaw_deg,
            encoder_lengths_m: m.encoder_lengths_m.clone().try_into().unwrap(),
            reference_tension_n: m.load_cell_tensions_n[0],
            line: 0,
            excluded: Default::default(),
            order: None,
        })
        .collect();
    let mut options = paper_options(&truth);
    options.orientation_prior = OrientationPrior::On;
    let by_four = calibrate(&four, &rows, &options).unwrap();
    let by_n = calibrate_suspended(&truth, &measurements, &options, None, &mut |_| {}).unwrap();
    let mut largest_difference: f64 = 0.0;
    let mut largest_error: f64 = 0.0;
    for i in 0..4 {
        largest_difference = largest_difference.max((by_four.robot.anchors_m[i] - by_n.robot.anchors_m[i]).norm());
        largest_error = largest_error.max((by_four.robot.anchors_m[i] - truth.anchors_m[i]).norm());
    }
    println!("anchors: graphs differ by {largest_difference:.2e} m; the four-cable graph is {largest_error:.2e} m from the truth");
    assert!(
        largest_difference < 1e-3 * largest_error.max(1e-3),
        "{largest_difference} vs {largest_error}"
    );
}

/// From a guess with every anchor 10 m off (the paper's Table II start),
/// noisy readings: the calibration ends where it ends from the truth.
#[test]
fn ten_metre_guesses_reach_the_minimum_of_the_truth() {
    for name in ["three", "large", "five", "six", "seven", "eight"] {
        let (truth, guess) = truth_and_guess(name, 10.0);
        let workspace = truth
            .workspace
            .unwrap_or_else(|| Workspace::around_anchor_points(&truth.anchors_m));
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let closure = if truth.cable_count() > 3 {
            Closure::Yaw { max_yaw_deg: 5.0 }
        } else {
            Closure::Level
        };
        let equilibria = sample_suspended(&truth, &workspace, 30, closure, &mut rng).unwrap();
        let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
        let measurements = measure_suspended(&truth, &equilibria, &noise, &mut rng).unwrap();
        let options = paper_options(&truth);
        let from_guess = calibrate_suspended(&guess, &measurements, &options, None, &mut |_| {}).unwrap();
        let from_truth = calibrate_suspended(&truth, &measurements, &options, None, &mut |_| {}).unwrap();
        let apart = from_guess
            .robot
            .anchors_m
            .iter()
            .zip(&from_truth.robot.anchors_m)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        let error = from_truth
            .robot
            .anchors_m
            .iter()
            .zip(&truth.anchors_m)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        println!(
            "{name}: from 10 m {apart:.2e} m from the truth's minimum (costs {:.3} / {:.3}), which is {error:.3} m from the truth; fell back {:?}",
            from_guess.final_cost, from_truth.final_cost, from_guess.fell_back
        );
        assert!(apart < 1e-6, "{name}: {apart}");
    }
}

fn sagcal(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

fn robot_path(name: &str) -> String {
    format!("{}/robots/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

/// `sagcal calibrate` on simulated readings of the six- and eight-cable
/// robots: the JSON report's anchors lie within 4 sigma of the truth (the
/// robot file simulated from), the fit passes its chi-square test, and the
/// written robot reads back with the reported anchors and offsets;
/// `sagcal localize` with that robot finds every row.
#[test]
fn the_command_calibrates_six_and_eight_cables() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["six", "eight"] {
        let truth = SuspendedRobot::builtin(name).unwrap();
        let data = format!("{name}.csv");
        let out = sagcal(
            dir.path(),
            &[
                "simulate",
                "--robot",
                &robot_path(name),
                "--poses",
                "30",
                "--seed",
                "7",
                "--out",
                &data,
            ],
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let written = format!("{name}-calibrated.toml");
        let out = sagcal(
            dir.path(),
            &[
                "calibrate",
                "--robot",
                &robot_path(name),
                "--data",
                &data,
                "--out",
                &written,
                "--json",
            ],
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["cables"], truth.cable_count());
        assert_eq!(report["consistent"], true, "{}", report["chi_square"]);
        let calibrated = SuspendedRobot::from_file(&dir.path().join(&written)).unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..truth.cable_count() {
            for k in 0..3 {
                let estimate = report["anchors_m"][i][k].as_f64().unwrap();
                let sigma = report["anchor_sigma_m"][i][k].as_f64().unwrap();
                assert!((calibrated.anchors_m[i][k] - estimate).abs() < 1e-12);
                worst = worst.max((estimate - truth.anchors_m[i][k]).abs() / sigma);
            }
            let offset = report["length_offsets_m"][i].as_f64().unwrap();
            assert!((calibrated.length_offsets_m[i] - offset).abs() < 1e-12);
        }
        println!("{name}: worst anchor coordinate {worst:.2} sigma from the truth");
        assert!(worst < 4.0, "{name}: {worst}");
        // The calibrated robot localises the same rows: none flagged, each
        // position within 5 of its 1-sigma (the reading noise's and the
        // localiser's 5 mm) of the localiser's.
        let out = sagcal(
            dir.path(),
            &[
                "localize",
                "--robot",
                &written,
                "--data",
                &data,
                "--json",
                "--out",
                "poses.csv",
            ],
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["rows_flagged"], 0, "{name}");
        for row in report["rows"].as_array().unwrap() {
            let sigma = row["position_sigma_m"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_f64().unwrap());
            let combined = sigma.map(|s| s * s + 0.005 * 0.005).sum::<f64>().sqrt();
            let error = row["position_error_m"].as_f64().unwrap();
            assert!(error < 5.0 * combined, "{name}: {error} m against {combined} m");
        }
        let csv = std::fs::read_to_string(dir.path().join("poses.csv")).unwrap();
        assert_eq!(csv.lines().count(), 31);
        assert!(csv.starts_with("row,line,x_m"));
    }
}

/// A blunder in a well-formed file (one encoder reading 0.5 m long) is
/// found by the tests for single gross errors, named and left out, and the
/// fit without it passes; a robot file whose platform is 30 % too heavy
/// (a model error, not a blunder) leaves the tests finding one after
/// another: the fit is refused, nothing is written, the command exits 1.
#[test]
fn a_blunder_is_left_out_and_a_wrong_model_refused() {
    let dir = tempfile::tempdir().unwrap();
    let six = robot_path("six");
    let out = sagcal(
        dir.path(),
        &[
            "simulate", "--robot", &six, "--poses", "30", "--seed", "7", "--out", "six.csv",
        ],
    );
    assert!(out.status.success());
    let text = std::fs::read_to_string(dir.path().join("six.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let header = lines.iter().position(|l| l.starts_with("x_m")).unwrap();
    let column = lines[header].split(',').position(|c| c == "l2_m").unwrap();
    let mut cells: Vec<String> = lines[header + 5].split(',').map(String::from).collect();
    cells[column] = format!("{}", cells[column].parse::<f64>().unwrap() + 0.5);
    lines[header + 5] = cells.join(",");
    std::fs::write(dir.path().join("blunder.csv"), lines.join("\n") + "\n").unwrap();
    let out = sagcal(
        dir.path(),
        &[
            "calibrate",
            "--robot",
            &six,
            "--data",
            "blunder.csv",
            "--out",
            "cal.toml",
            "--json",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let left_out = report["readings_left_out"].as_array().unwrap();
    assert_eq!(left_out.len(), 1, "{left_out:?}");
    assert_eq!(left_out[0]["row"], 5);
    assert_eq!(left_out[0]["reading"]["encoder"], 1, "cable 2, 0-based");
    assert_eq!(report["consistent"], true);
    let text =
        String::from_utf8_lossy(&sagcal(dir.path(), &["calibrate", "--robot", &six, "--data", "blunder.csv"]).stdout)
            .into_owned();
    assert!(text.contains("left out as a gross error: row 5 (line "), "{text}");
    assert!(text.contains(", encoder of cable 2: residual "), "{text}");
    // The platform 30 % heavier than the one the data were simulated with.
    let heavy = std::fs::read_to_string(&six)
        .unwrap()
        .replace("platform_weight_n = 2943.0", "platform_weight_n = 3825.9");
    std::fs::write(dir.path().join("heavy.toml"), heavy).unwrap();
    let out = sagcal(
        dir.path(),
        &[
            "calibrate",
            "--robot",
            "heavy.toml",
            "--data",
            "six.csv",
            "--out",
            "heavy-cal.toml",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("fails its own consistency tests"), "{stderr}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("INCONSISTENT"));
    assert!(!dir.path().join("heavy-cal.toml").exists());
    let out = sagcal(
        dir.path(),
        &["calibrate", "--robot", &six, "--data", "six.csv", "--model", "rigid"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--model rigid: robot `six` has 6 cables"), "{stderr}");
}

/// `sagcal experiment table2` on a robot of N cables draws its own poses:
/// few trials here (the guide has 100), every one converged and the error
/// of the size of the Cramer-Rao bound; the four-cable protocol's options
/// are refused by name, and the four-cable robot still needs its log.
#[test]
fn the_table2_experiment_runs_on_n_cables() {
    let dir = tempfile::tempdir().unwrap();
    let (six, large) = (robot_path("six"), robot_path("large"));
    let out = sagcal(
        dir.path(),
        &[
            "experiment",
            "table2",
            "--robot",
            &six,
            "--poses",
            "12",
            "--trials",
            "4",
            "--json",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summaries: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let summary = &summaries[0];
    assert_eq!(summary["converged"], 4, "{summary}");
    let ratio = summary["anchor_rms_error_m"].as_f64().unwrap() / summary["anchor_rms_bound_m"].as_f64().unwrap();
    assert!(ratio > 0.3 && ratio < 2.0, "{ratio}");
    for (args, expected) in [
        (
            vec!["--robot", &six, "--data", "x.csv"],
            "--data: robot `six` has 6 cables",
        ),
        (
            vec!["--robot", &six, "--select", "planned"],
            "--select: robot `six` has 6 cables",
        ),
        (
            vec!["--robot", &large],
            "--data is required: robot `large` has four cables",
        ),
    ] {
        let mut command = vec!["experiment", "table2", "--trials", "1"];
        command.extend(args.iter().copied());
        let out = sagcal(dir.path(), &command);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
    }
}

/// A guess 10 m off that leads the joint straight-cable fit of nine poses
/// into another minimum (eight cables, paper noise, trial 47 of seed 1:
/// chi-square 7897.3 for 40 degrees of freedom without a second start,
/// 2873.7 with the catenary stages restarted from the guess's anchors): the
/// second start from each cable's trilateration reaches the minimum that
/// passes. A fit that passes at once never tries it (its stages as before).
#[test]
fn a_failed_minimum_is_left_for_the_second_start_from_trilateration() {
    use sagcal::experiments::suspended_trials::{suspended_trials, SuspendedTrialsOptions};
    let eight = SuspendedRobot::builtin("eight").unwrap();
    let options = SuspendedTrialsOptions {
        poses: 9,
        trials: 1,
        noise: NoisePreset::Paper,
        guess_m: 10.0,
        seed: 1 + 47,
    };
    let summary = suspended_trials(&eight, &options, &mut |_, _| {}).unwrap();
    assert_eq!(summary.converged, 1, "{:?}", summary.failures);
    let (truth, guess) = truth_and_guess("six", 10.0);
    let (data, _) = readings(&truth, 12, 3);
    let result = calibrate_suspended(&guess, &data, &paper_options(&truth), None, &mut |_| {}).unwrap();
    let names: Vec<&str> = result.stages.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["straight cables", "catenary (anchors held)", "catenary"]);
}

/// Data from the discretised simulator (chains over pulleys, not the
/// catenary the calibration fits): 100-element chains, whose lengths depart
/// from the catenary's by `O(1/n^2)`, calibrate to a consistent fit with
/// every anchor coordinate within the two-sided Bonferroni 99.9 % bound of
/// its 1-sigma (4.03 for 18 coordinates); a platform 15 % heavier than its
/// file says is refused (exit 1, nothing written). The sweep command runs
/// its ten effects and names each case's seed, and a run mixing four-cable
/// and six-cable robots is refused.
#[test]
fn discretised_data_calibrate_and_the_sweep_scores_them() {
    let dir = tempfile::tempdir().unwrap();
    let six = robot_path("six");
    for (effect, noise, consistent) in [
        ("segments:n=100", "authors", true),
        ("platform-weight:scale=1.15", "paper", false),
    ] {
        let simulate = [
            "simulate", "--robot", &six, "--poses", "30", "--seed", "7", "--noise", noise, "--effect", effect, "--out",
            "d.csv",
        ];
        let out = sagcal(dir.path(), &simulate);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stdout).contains("discretised simulator, 100 segments per cable"));
        let calibrate = [
            "calibrate",
            "--robot",
            &six,
            "--data",
            "d.csv",
            "--noise",
            noise,
            "--json",
            "--out",
            "c.toml",
        ];
        let out = sagcal(dir.path(), &calibrate);
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["consistent"], consistent, "{effect}: {}", report["chi_square"]);
        assert_eq!(out.status.success(), consistent, "{effect}");
        assert_eq!(dir.path().join("c.toml").exists(), consistent, "{effect}");
        if consistent {
            let truth = SuspendedRobot::builtin("six").unwrap();
            for i in 0..6 {
                for k in 0..3 {
                    let error = report["anchors_m"][i][k].as_f64().unwrap() - truth.anchors_m[i][k];
                    let sigma = report["anchor_sigma_m"][i][k].as_f64().unwrap();
                    assert!(
                        error.abs() < 4.03 * sigma,
                        "{effect}: cable {} axis {k}: {error} m, sigma {sigma}",
                        i + 1
                    );
                }
            }
            std::fs::remove_file(dir.path().join("c.toml")).unwrap();
        }
    }
    let sweep = [
        "experiment",
        "hidden-effects",
        "--robots",
        "six",
        "--seeds",
        "1",
        "--seed",
        "5",
        "--poses",
        "20",
        "--noise",
        "authors",
        "--segments",
        "20",
        "--json",
    ];
    let out = sagcal(dir.path(), &sweep);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let sweeps: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let cases = sweeps[0]["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 10);
    for (e, case) in cases.iter().enumerate() {
        assert_eq!(case["seed"], 5 + 1000 * e as u64, "{case}");
    }
    let mixed = ["experiment", "hidden-effects", "--robots", "large,six", "--seeds", "1"];
    let out = sagcal(dir.path(), &mixed);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("`six` has 6 cables: sweep robots of 3 to 8 cables in a run of their own"),
        "{stderr}"
    );
}

/// Weightless cables (no sag ties a cable's force to its length) on the
/// eight-cable robot: per pose 16 force components, 8 fixed by the heights
/// (each force along its chord), 6 by the equilibrium and one by each load
/// cell, so one load cell leaves exactly one force direction per pose that
/// no reading sees, and two load cells none. The report says so, counts it
/// out of the degrees of freedom (both fits have the same: a load cell adds
/// a row and fixes a direction) and still gives the anchors' 1-sigma,
/// which holds: every coordinate within the Bonferroni 99.9 % bound (4.10
/// for 24 coordinates) of the truth.
#[test]
fn undetermined_forces_are_counted_and_the_anchors_still_bounded() {
    use sagcal::calib::suspended::SuspendedCalibrationReport;
    let mut dof = Vec::new();
    for load_cells in [vec![0], vec![0, 4]] {
        let mut truth = SuspendedRobot::builtin("eight").unwrap();
        truth.cable_weights_n_per_m = vec![0.0; 8];
        truth.load_cells = load_cells.clone();
        let workspace = truth.workspace.unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let equilibria = sample_suspended(&truth, &workspace, 30, Closure::Level, &mut rng).unwrap();
        let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
        let data = measure_suspended(&truth, &equilibria, &noise, &mut rng).unwrap();
        let result = calibrate_suspended(&truth, &data, &paper_options(&truth), None, &mut |_| {}).unwrap();
        let report = SuspendedCalibrationReport::new(&truth, &result);
        let expected: Vec<(usize, usize)> = if load_cells.len() == 1 {
            (0..30).map(|k| (k, 1)).collect()
        } else {
            Vec::new()
        };
        assert_eq!(result.undetermined_forces, expected, "load cells {load_cells:?}");
        assert!(
            report.consistent,
            "{} for {}",
            report.chi_square, report.degrees_of_freedom
        );
        let sigma = report.anchor_sigma_m.as_ref().expect("the anchors' 1-sigma");
        for (i, cable_sigma) in sigma.iter().enumerate() {
            for (k, s) in cable_sigma.iter().enumerate() {
                let error = result.robot.anchors_m[i][k] - truth.anchors_m[i][k];
                assert!(error.abs() < 4.10 * s, "cable {} axis {k}: {error} m, sigma {s}", i + 1);
            }
        }
        dof.push(report.degrees_of_freedom);
    }
    assert_eq!(dof[0], dof[1], "{dof:?}");
}

/// The elastic catenary closes what the readings leave open: the same
/// weightless eight-cable robot with one load cell whose forces are
/// undetermined in one direction per pose when its cables are inextensible
/// has every force determined once they stretch (EA = 2 MN, 8 mm steel
/// wire rope), because each encoder then reads `l (1 - T / EA)`: the
/// tensions enter the lengths. The data come from the discretised
/// simulator (the chains stretch exactly, not to first order); the fit
/// passes its chi-square test and its anchors lie within their bounds.
#[test]
fn elastic_cables_determine_the_forces_one_load_cell_leaves_open() {
    use sagcal::calib::suspended::SuspendedCalibrationReport;
    use sagcal::model::effects::Effects;
    use sagcal::sim::suspended_effects::simulate_readings;
    let mut truth = SuspendedRobot::builtin("eight").unwrap();
    truth.cable_weights_n_per_m = vec![0.0; 8];
    truth.load_cells = vec![0];
    truth.axial_stiffness_n = vec![2e6; 8];
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let equilibria = sample_suspended(&truth, &truth.workspace.unwrap(), 30, Closure::Level, &mut rng).unwrap();
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let data = simulate_readings(&truth, &Effects::default(), &equilibria, &noise, 50, &mut rng).unwrap();
    // The cables stretch by millimetres (a third of the encoders' 1 cm sigma
    // at one pose; thirty poses and eight cables are what determine them).
    let paid_out = equilibria[0].paid_out_lengths_m(&truth);
    let stretch_m = (0..8)
        .map(|i| equilibria[0].cable_lengths_m[i] - paid_out[i])
        .fold(0.0, f64::max);
    assert!(stretch_m > 2e-3, "stretch {stretch_m} m");
    let result = calibrate_suspended(&truth, &data, &paper_options(&truth), None, &mut |_| {}).unwrap();
    let report = SuspendedCalibrationReport::new(&truth, &result);
    assert_eq!(result.undetermined_forces, Vec::<(usize, usize)>::new());
    assert!(
        report.consistent,
        "{} for {}",
        report.chi_square, report.degrees_of_freedom
    );
    let sigma = report.anchor_sigma_m.as_ref().expect("the anchors' 1-sigma");
    let mut worst: f64 = 0.0;
    for (i, cable_sigma) in sigma.iter().enumerate() {
        for (k, s) in cable_sigma.iter().enumerate() {
            let error = result.robot.anchors_m[i][k] - truth.anchors_m[i][k];
            assert!(error.abs() < 4.10 * s, "cable {} axis {k}: {error} m, sigma {s}", i + 1);
            worst = worst.max(error.abs() / s);
        }
    }
    println!(
        "elastic model of the elastic robot: no undetermined force, chi-square {:.1} for {}, worst anchor {worst:.2} sigma",
        report.chi_square, report.degrees_of_freedom
    );
    // The same readings under an inextensible model: the forces fall open again.
    let mut rigid = truth.clone();
    rigid.axial_stiffness_n = vec![f64::INFINITY; 8];
    let result = calibrate_suspended(&rigid, &data, &paper_options(&rigid), None, &mut |_| {}).unwrap();
    println!(
        "inextensible model of the elastic robot: {} poses with undetermined forces, chi-square {:.1} for {}",
        result.undetermined_forces.len(),
        SuspendedCalibrationReport::new(&rigid, &result).chi_square,
        result.degrees_of_freedom
    );
    assert_eq!(result.undetermined_forces.len(), 30);
}

/// A robot file that gives its cables' stiffness: `sagcal simulate` draws
/// its data with the discretised simulator (the chains stretch), `sagcal
/// calibrate` fits the elastic catenary and says so, its anchors lie within
/// 4 sigma of the truth, the written robot keeps the stiffness, and
/// `sagcal localize` with it flags no row. The inextensible model of the
/// same readings is printed beside it.
#[test]
fn the_command_calibrates_an_elastic_robot() {
    let dir = tempfile::tempdir().unwrap();
    // 10 mm steel wire rope: 45 mm^2 of steel at a rope modulus of 100 GPa.
    let six = std::fs::read_to_string(robot_path("six")).unwrap();
    let elastic = six.replacen("com_offset_m", "axial_stiffness_n = 4.5e6\ncom_offset_m", 1);
    std::fs::write(dir.path().join("elastic.toml"), &elastic).unwrap();
    let truth = SuspendedRobot::from_file(&dir.path().join("elastic.toml")).unwrap();
    let simulate = [
        "simulate",
        "--robot",
        "elastic.toml",
        "--poses",
        "30",
        "--seed",
        "7",
        "--segments",
        "20",
        "--out",
        "d.csv",
    ];
    let out = sagcal(dir.path(), &simulate);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("elastic cables"));
    let calibrate = [
        "calibrate",
        "--robot",
        "elastic.toml",
        "--data",
        "d.csv",
        "--out",
        "c.toml",
    ];
    let out = sagcal(dir.path(), &calibrate);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("elastic catenary model (EA 4.50e6 N)"), "{text}");
    let out = sagcal(dir.path(), &[&calibrate[..5], &["--json"]].concat());
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["consistent"], true, "{}", report["chi_square"]);
    assert_eq!(report["axial_stiffness_n"][5], 4.5e6);
    let worst = worst_sigma(&report, &truth);
    assert!(worst < 4.0, "{worst}");
    let calibrated = SuspendedRobot::from_file(&dir.path().join("c.toml")).unwrap();
    assert_eq!(calibrated.axial_stiffness_n, vec![4.5e6; 6]);
    let out = sagcal(
        dir.path(),
        &["localize", "--robot", "c.toml", "--data", "d.csv", "--json"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let localized: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(localized["rows_flagged"], 0);
    let out = sagcal(
        dir.path(),
        &["calibrate", "--robot", &robot_path("six"), "--data", "d.csv", "--json"],
    );
    let rigid: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    println!(
        "elastic model: chi-square {:.1} for {}, worst anchor {worst:.2} sigma; the inextensible model of the same \
         readings: chi-square {:.1} for {}, worst anchor {:.2} sigma",
        report["chi_square"].as_f64().unwrap(),
        report["degrees_of_freedom"],
        rigid["chi_square"].as_f64().unwrap(),
        rigid["degrees_of_freedom"],
        worst_sigma(&rigid, &truth)
    );
}

/// The largest distance of a reported anchor coordinate from the truth's, in its reported sigmas.
fn worst_sigma(report: &serde_json::Value, truth: &SuspendedRobot) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..truth.cable_count() {
        for k in 0..3 {
            let estimate = report["anchors_m"][i][k].as_f64().unwrap();
            let sigma = report["anchor_sigma_m"][i][k].as_f64().unwrap();
            worst = worst.max((estimate - truth.anchors_m[i][k]).abs() / sigma);
        }
    }
    worst
}

/// `sagcal plan` on robots of 3 to 8 cables: the plan's bound (summed from
/// each candidate's Schur-complement information) is the marginal
/// covariance of the calibration graph of the chosen poses at the truth,
/// computed independently by the sparse solver; chosen for it, the plan
/// beats random sets of as many candidates.
#[test]
fn the_plan_of_n_cables_is_the_bound_of_its_calibration_graph() {
    use sagcal::calib::suspended::{build_suspended_graph, Exclusions, PoseStart, SuspendedStage};
    use sagcal::calib::{anchor_and_offset_uncertainty, ParameterUncertainty};
    use sagcal::experiments::suspended_plan::{plan_suspended, SuspendedPlanSettings};
    use sagcal::plan::suspended_information::noise_free_suspended_reading;
    for (name, poses) in [("three", 8), ("six", 10), ("eight", 12)] {
        let robot = SuspendedRobot::builtin(name).unwrap();
        let settings = SuspendedPlanSettings {
            candidates: 80,
            ..SuspendedPlanSettings::new(poses)
        };
        let planned = plan_suspended(&robot, &settings, &mut |_| {}).unwrap();
        let report = &planned.report;
        assert_eq!((report.cables, report.plan.len()), (robot.cable_count(), poses));
        let chosen: Vec<&SuspendedEquilibrium> = planned.plan.order.iter().map(|&k| &planned.candidates[k]).collect();
        let readings: Vec<_> = chosen
            .iter()
            .map(|eq| noise_free_suspended_reading(&robot, eq))
            .collect();
        let starts: Vec<PoseStart> = chosen
            .iter()
            .map(|eq| PoseStart {
                pose: eq.pose,
                forces: eq.tensions.clone(),
            })
            .collect();
        let built = build_suspended_graph(
            &robot,
            &readings,
            &starts,
            SuspendedStage::Catenary,
            &paper_options(&robot),
            false,
            &Exclusions::new(),
        );
        let ParameterUncertainty::Full {
            anchor_sigma_m,
            offset_sigma_m,
            ..
        } = anchor_and_offset_uncertainty(&built.graph, &built.anchors, &built.length_offsets).unwrap()
        else {
            panic!("{name}: the chosen poses leave the anchors undetermined");
        };
        let n = robot.cable_count() as f64;
        let anchor_rms = (anchor_sigma_m.iter().flatten().map(|s| s * s).sum::<f64>() / n).sqrt();
        let offset_rms = (offset_sigma_m.iter().map(|s| s * s).sum::<f64>() / n).sqrt();
        println!(
            "{name}: plan of {poses} bounds the anchors to {:.4} m RMS (graph {anchor_rms:.4} m), random sets to {:.4} m",
            report.anchor_bound_m, report.random_anchor_bound_m
        );
        assert!((report.anchor_bound_m / anchor_rms - 1.0).abs() < 1e-6, "{name}");
        assert!((report.offset_bound_m / offset_rms - 1.0).abs() < 1e-6, "{name}");
        assert!(report.anchor_bound_m < report.random_anchor_bound_m, "{name}");
    }
}

/// `sagcal plan --robot six.toml`: the JSON report, the plan as a
/// measurement file of six cables (noise-free: calibrating it from the
/// nominal robot moves no anchor), the figure, and a plan among logged
/// poses (`--from`): each planned pose is one of them.
#[test]
fn the_plan_command_plans_six_cables() {
    let dir = tempfile::tempdir().unwrap();
    let six = robot_path("six");
    let args = [
        "plan",
        "--robot",
        &six,
        "--poses",
        "10",
        "--candidates",
        "60",
        "--out",
        "plan.csv",
        "--plot",
        "plan.svg",
        "--json",
    ];
    let out = sagcal(dir.path(), &args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (report["cables"].as_u64(), report["poses"].as_u64()),
        (Some(6), Some(10))
    );
    assert_eq!(report["plan"][0]["cable_lengths_m"].as_array().unwrap().len(), 6);
    let svg = std::fs::read_to_string(dir.path().join("plan.svg")).unwrap();
    assert!(svg.contains("A6 x-z"), "an ellipse cell per anchor");
    let csv = std::fs::read_to_string(dir.path().join("plan.csv")).unwrap();
    assert!(csv.contains("l6_m,f1_n"));
    let calibrate = sagcal(
        dir.path(),
        &["calibrate", "--robot", &six, "--data", "plan.csv", "--json"],
    );
    assert!(
        calibrate.status.success(),
        "{}",
        String::from_utf8_lossy(&calibrate.stderr)
    );
    let fit: serde_json::Value = serde_json::from_slice(&calibrate.stdout).unwrap();
    let moved = fit["anchor_change_m"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|a| a.as_array().unwrap().clone());
    let moved = moved.map(|v| v.as_f64().unwrap().abs()).fold(0.0, f64::max);
    assert!(moved < 1e-6, "noise-free readings of the nominal robot: {moved} m");
    let simulate = [
        "simulate",
        "--robot",
        &six,
        "--poses",
        "40",
        "--seed",
        "8",
        "--out",
        "logged.csv",
    ];
    assert!(sagcal(dir.path(), &simulate).status.success());
    let from = sagcal(
        dir.path(),
        &[
            "plan",
            "--robot",
            &six,
            "--poses",
            "8",
            "--from",
            "logged.csv",
            "--json",
        ],
    );
    assert!(from.status.success(), "{}", String::from_utf8_lossy(&from.stderr));
    let report: serde_json::Value = serde_json::from_slice(&from.stdout).unwrap();
    let words = report["candidates_from"].as_str().unwrap();
    assert!(words.starts_with("40 logged poses of logged.csv"), "{words}");
    let logged = sagcal::io::suspended_measurements::read_suspended_measurements(
        &dir.path().join("logged.csv"),
        &SuspendedRobot::builtin("six").unwrap(),
    )
    .unwrap();
    for pose in report["plan"].as_array().unwrap() {
        let p: Vec<f64> = pose["position_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let nearest = logged
            .iter()
            .map(|m| (0..3).map(|a| (m.position_m[a] - p[a]).abs()).fold(0.0, f64::max))
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-12, "planned {p:?} is {nearest} m from every logged pose");
    }
    // A box beyond the anchors' footprint is refused under the flag's name, once.
    let outside = sagcal(
        dir.path(),
        &[
            "plan",
            "--robot",
            &six,
            "--poses",
            "10",
            "--workspace=-50,50,-50,50,5,20",
        ],
    );
    let message = String::from_utf8_lossy(&outside.stderr);
    assert!(!outside.status.success(), "{message}");
    assert!(
        message.contains(
            "--workspace: [-50, -50, 5] .. [50, 50, 20] m for robot `six`: the box's corner (-50, -50) m lies outside"
        ),
        "{message}"
    );
    assert_eq!(message.matches("robot `six`").count(), 1, "{message}");
}

//! `sagcal plan`'s library: the per-pose information against the calibration's
//! own Cramer-Rao bound, the rank-k update against a from-scratch bound, and
//! planned against random pose sets on both robots.

use sagcal::calib::{cramer_rao_bound, CalibrationOptions, OrientationPrior, ParameterUncertainty};
use sagcal::experiments::plan_candidates::draw_candidates;
use sagcal::model::robot::Workspace;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::statics::Equilibrium;
use sagcal::model::Robot;
use sagcal::plan::bound::{bound_from_covariance, covariance_of, information_sum};
use sagcal::plan::design::{search_ridge, updated_values};
use sagcal::plan::{
    candidate_information, choose_poses, plan_bound, random_bounds, Criterion, DesignOptions, Margins, PoseInformation,
};

fn candidates(robot: &Robot, count: usize, seed: u64) -> Vec<Equilibrium> {
    let workspace = Workspace::default_for(robot);
    draw_candidates(robot, &workspace, count, &Margins::for_robot(robot), seed)
        .unwrap()
        .equilibria
}

fn options(robot: &Robot, prior: OrientationPrior) -> CalibrationOptions {
    let mut options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
    options.orientation_prior = prior;
    options
}

fn relative_difference(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs())
}

/// The sum of the per-pose Schur complements inverts to the marginal
/// covariance the calibration's sparse graph gives (`cramer_rao_bound`), with
/// and without the orientation prior. To 1e-5 relative: the graph factors
/// `H = J^T J`, whose per-pose blocks have condition ~1e11 (the local
/// Jacobian's is ~4e5, from the 0.1 mm height sigma), so its inverse carries
/// ~1e-7 relative rounding (4e-7 measured); the QR elimination here does not
/// square the condition number. The exact identity is checked at 1e-9 below.
#[test]
fn per_pose_information_sums_to_the_calibration_bound() {
    let robot = Robot::builtin("large").unwrap();
    let poses = candidates(&robot, 12, 3);
    for prior in [OrientationPrior::On, OrientationPrior::Off] {
        let options = options(&robot, prior);
        let information = candidate_information(&robot, &poses, &options).unwrap();
        let rank = information[0].rank();
        assert_eq!(rank, if prior == OrientationPrior::On { 7 } else { 4 }, "{prior}");
        let all: Vec<usize> = (0..poses.len()).collect();
        let ours = plan_bound(&information, &all).unwrap();
        let ParameterUncertainty::Full {
            anchor_covariance_m2,
            offset_sigma_m,
            ..
        } = cramer_rao_bound(&robot, &poses, &options).unwrap()
        else {
            panic!("the bound of 12 poses is full rank");
        };
        for (i, (mine, graph)) in ours.anchor_covariance_m2.iter().zip(&anchor_covariance_m2).enumerate() {
            for r in 0..3 {
                for c in 0..3 {
                    let d = relative_difference(mine[r][c], graph[r][c]);
                    let scale = (graph[r][r] * graph[c][c]).sqrt();
                    assert!(
                        (mine[r][c] - graph[r][c]).abs() < 1e-5 * scale,
                        "{prior}: anchor {i} ({r},{c}) differs by {d:e}"
                    );
                }
            }
        }
        let offset_rms = (offset_sigma_m.iter().map(|s| s * s).sum::<f64>() / 4.0).sqrt();
        assert!(relative_difference(ours.offset_rms_m, offset_rms) < 1e-5);
    }
}

/// The criterion after adding a candidate by Sherman-Morrison-Woodbury equals
/// the one of the information rebuilt from scratch, for A and D.
#[test]
fn rank_k_update_equals_the_bound_from_scratch() {
    let robot = Robot::builtin("small").unwrap();
    let poses = candidates(&robot, 30, 5);
    let information = candidate_information(&robot, &poses, &options(&robot, OrientationPrior::On)).unwrap();
    let chosen = [0, 1, 2, 3, 4];
    let a = updated_values(&information, &chosen, 0.0, Criterion::A).unwrap();
    let d = updated_values(&information, &chosen, 0.0, Criterion::D).unwrap();
    for k in 5..30 {
        let with_k: Vec<usize> = chosen.iter().copied().chain([k]).collect();
        let m = information_sum(&information, &with_k, 0.0);
        let scratch = bound_from_covariance(&covariance_of(&m).unwrap(), 4);
        let scratch_a = 4.0 * scratch.anchor_rms_m.powi(2);
        assert!(
            relative_difference(a[k], scratch_a) < 1e-9,
            "A, candidate {k}: {} vs {scratch_a}",
            a[k]
        );
        let logdet = 2.0 * m.cholesky().unwrap().l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
        assert!(
            (d[k] + logdet).abs() < 1e-9 * logdet.abs(),
            "D, candidate {k}: {} vs {}",
            d[k],
            -logdet
        );
    }
    // ... and the A value is the trace the calibration's own bound gives for
    // those poses (to the graph's rounding, see the test above).
    let with_5: Vec<Equilibrium> = [0, 1, 2, 3, 4, 5].iter().map(|&k| poses[k].clone()).collect();
    let crb = cramer_rao_bound(&robot, &with_5, &options(&robot, OrientationPrior::On)).unwrap();
    let rms = sagcal::calib::anchor_rms_bound_m(&crb).unwrap();
    let trace: f64 = rms.iter().map(|r| r * r).sum();
    assert!(relative_difference(a[5], trace) < 1e-5, "{} vs {trace}", a[5]);
    assert!(search_ridge(&information) > 0.0);
}

/// A planned 9-pose set has a lower bound than the mean of 100 random 9-pose
/// sets from the same candidates, on both robots and for both criteria; the
/// plan's poses keep the tension margin.
#[test]
fn planned_nine_beat_random_nine_on_both_robots() {
    for name in ["large", "small"] {
        let robot = Robot::builtin(name).unwrap();
        let poses = candidates(&robot, 150, 11);
        let information: Vec<PoseInformation> =
            candidate_information(&robot, &poses, &options(&robot, OrientationPrior::Off)).unwrap();
        let random = random_bounds(&information, 9, 100, 1);
        for criterion in [Criterion::A, Criterion::D] {
            let design = choose_poses(
                &information,
                &DesignOptions {
                    criterion,
                    ..DesignOptions::new(9)
                },
            )
            .unwrap();
            let planned = plan_bound(&information, &design.chosen).unwrap();
            eprintln!(
                "{name} {criterion:?}: planned 9 {:.3} m, random 9 {:.3} m (mean of 100), exchanges {}",
                planned.anchor_rms_m, random.anchor_rms_m, design.exchanges
            );
            assert!(planned.anchor_rms_m < random.anchor_rms_m, "{name} {criterion:?}");
            let margins = Margins::for_robot(&robot);
            for &k in &design.chosen {
                assert!(poses[k]
                    .tensions
                    .iter()
                    .all(|t| t.horizontal_n >= margins.min_horizontal_tension_n));
                assert!(margins.violation(&robot, &poses[k]).is_none());
            }
        }
    }
}

/// `sagcal plan` end to end on the small robot: the JSON has the issue's
/// keys, the CSV reads back in visiting order with the plan's positions, and
/// bad input fails with a message and writes nothing.
#[test]
fn plan_command_writes_the_plan_and_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan.csv");
    let sagcal = env!("CARGO_BIN_EXE_sagcal");
    let ok = std::process::Command::new(sagcal)
        .args([
            "plan",
            "--robot",
            "robots/small.toml",
            "--poses",
            "5",
            "--candidates",
            "40",
            "--seed",
            "2",
        ])
        .arg("--out")
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let json: serde_json::Value = serde_json::from_slice(&ok.stdout).unwrap();
    for key in [
        "poses",
        "anchor_bound_m",
        "offset_bound_m",
        "random_anchor_bound_m",
        "random35_anchor_bound_m",
        "path_length_m",
        "plan",
    ] {
        assert!(json.get(key).is_some(), "JSON lacks {key}");
    }
    assert!(json["anchor_bound_m"].as_f64().unwrap() < json["random_anchor_bound_m"].as_f64().unwrap());
    let read = sagcal::io::measurements::read_measurements(
        &out,
        &sagcal::io::measurements::ReadOptions {
            reference_cable: 0,
            keep_rounded: true,
        },
    )
    .unwrap();
    assert_eq!(read.poses.len(), 5);
    let plan = json["plan"].as_array().unwrap();
    let mut path = 0.0;
    for (k, row) in read.poses.iter().enumerate() {
        let p: Vec<f64> = plan[k]["position_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        // serde_json's default float parsing may differ in the last bit.
        let gap = (0..3).map(|i| (row.position_m[i] - p[i]).abs()).fold(0.0, f64::max);
        assert!(gap < 1e-12, "row {k} is visit {}: {:?} vs {p:?}", k + 1, row.position_m);
        if k > 0 {
            let q = read.poses[k - 1].position_m;
            path += (0..3).map(|i| (row.position_m[i] - q[i]).powi(2)).sum::<f64>().sqrt();
        }
    }
    assert!((path - json["path_length_m"].as_f64().unwrap()).abs() < 1e-9);
    // More poses than candidates: an error naming both counts, no file.
    let refused = dir.path().join("refused.csv");
    let bad = std::process::Command::new(sagcal)
        .args([
            "plan",
            "--robot",
            "robots/small.toml",
            "--poses",
            "50",
            "--candidates",
            "10",
        ])
        .arg("--out")
        .arg(&refused)
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("50 poses requested but only 10 candidates"));
    assert!(!refused.exists());
    let box_error = std::process::Command::new(sagcal)
        .args([
            "plan",
            "--robot",
            "robots/small.toml",
            "--poses",
            "5",
            "--workspace",
            "1,2,3",
        ])
        .output()
        .unwrap();
    assert_eq!(box_error.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&box_error.stderr).contains("x0,x1,y0,y1,z0,z1"));
}

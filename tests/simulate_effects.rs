//! `sagcal simulate --effect`: the effect parser, the robot file's `[effects]`,
//! and data generated through the discretised simulator against the
//! closed-form data and hand estimates of each effect.

use std::path::Path;
use std::process::{Command, Output};

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::io::measurements::PoseMeasurement;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::statics::{self, Equilibrium, StaticsOptions};
use sagcal::model::{Effects, Robot};
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
use sagcal::sim::effects::{measure_with_effects, solve_with_effects};

fn sagcal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

fn robot_path(name: &str) -> String {
    format!("{}/robots/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

fn effects(specs: &[&str]) -> Effects {
    let mut e = Effects::default();
    for spec in specs {
        e.apply_spec(spec).unwrap();
    }
    e
}

/// A few closed-form equilibria of the large robot, with length offsets so the encoders' offsets are exercised.
fn setup(count: usize) -> (Robot, Vec<Equilibrium>) {
    let mut robot = Robot::builtin("large").unwrap();
    robot.length_offsets_m = [3.0, -2.0, 40.0, 0.5];
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), count, &mut rng).unwrap();
    (robot, equilibria)
}

fn noiseless(robot: &Robot, e: &Effects, equilibria: &[Equilibrium], segments: usize) -> Vec<PoseMeasurement> {
    let noise = NoisePreset::None.sigmas(robot.platform_weight_n);
    measure_with_effects(
        robot,
        e,
        equilibria,
        &noise,
        segments,
        &mut ChaCha8Rng::seed_from_u64(1),
    )
    .unwrap()
}

#[test]
fn parser_errors_name_the_effect_and_parameter() {
    for (spec, needle) in [
        ("gravity:g=9.81", "unknown effect `gravity`"),
        ("elastic:stiffness=1", "unknown parameter `stiffness`"),
        ("pulley:radius_m", "`radius_m` has no `=VALUE`"),
        ("loadcell:gain=inf", "`gain` must be finite"),
        ("elastic:ea_n=0", "must be > 0"),
        ("pulley:radius_m=-1", "must be >= 0"),
        ("encoder-scale:gain2=-1", "must be > 0"),
    ] {
        let message = Effects::default().apply_spec(spec).unwrap_err().to_string();
        assert!(message.contains(needle), "{spec}: {message}");
    }
}

#[test]
fn cli_writes_effect_data_and_truth_and_rejects_bad_effects() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "simulate",
        "--robot",
        &robot_path("large"),
        "--poses",
        "2",
        "--seed",
        "5",
        "--segments",
        "30",
        "--out",
        "m.csv",
        "--truth",
        "t.toml",
        "--effect",
        "elastic:ea_n=3e6",
    ];
    let out = sagcal(dir.path(), &args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        // The older spelling is read; the output names the robot file's key.
        stdout.contains("elastic:axial_stiffness_n=3e6") && stdout.contains("seed 5"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(dir.path().join("m.csv")).unwrap();
    assert!(csv.contains("# effects elastic:axial_stiffness_n=3e6"), "{csv}");
    let data = sagcal::io::measurements::read_measurements(&dir.path().join("m.csv"), &Default::default()).unwrap();
    assert_eq!(data.poses.len(), 2);
    let truth = Robot::from_file(&dir.path().join("t.toml")).unwrap();
    assert_eq!(truth.effects, effects(&["elastic:ea_n=3e6"]));
    assert!(std::fs::read_to_string(dir.path().join("t.toml"))
        .unwrap()
        .contains("[effects]"));

    // Without --effect: no [effects] table, no effects comment.
    let plain = sagcal(
        dir.path(),
        &[
            "simulate",
            "--robot",
            &robot_path("large"),
            "--poses",
            "2",
            "--out",
            "p.csv",
            "--truth",
            "p.toml",
        ],
    );
    assert!(plain.status.success());
    assert!(!std::fs::read_to_string(dir.path().join("p.toml"))
        .unwrap()
        .contains("effects"));
    assert!(!std::fs::read_to_string(dir.path().join("p.csv"))
        .unwrap()
        .contains("effects"));

    // A bad effect: non-zero exit, a message naming it, nothing written.
    let mut bad = args.to_vec();
    bad[10] = "bad.csv";
    bad[12] = "bad.toml";
    bad[14] = "elastic:ea_n=-3e6";
    let out = sagcal(dir.path(), &bad);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("--effect `elastic:ea_n=-3e6`") && stderr.contains("`ea_n`"),
        "{stderr}"
    );
    assert!(!dir.path().join("bad.csv").exists() && !dir.path().join("bad.toml").exists());
}

#[test]
fn robot_files_without_effects_load_and_effects_round_trip() {
    let robot = Robot::builtin("small").unwrap();
    assert!(robot.effects.is_none());
    assert!(robot.to_file_contents().effects.is_none());
    let mut with = robot.clone();
    with.effects = effects(&["pulley:radius_m=0.15", "encoder-scale:gain3=1.002", "com:dy_m=0.01"]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.toml");
    std::fs::write(&path, with.to_file_contents().to_toml().unwrap()).unwrap();
    assert_eq!(Robot::from_file(&path).unwrap(), with);
    // An invalid value in the file is an error naming the table.
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("pulley_radius_m = 0.15", "pulley_radius_m = -0.15");
    std::fs::write(&path, text).unwrap();
    let message = Robot::from_file(&path).unwrap_err().to_string();
    assert!(
        message.contains("effects") && message.contains("pulley_radius_m"),
        "{message}"
    );
}

/// No effect, 200 segments: the discretised data agree with the closed-form data.
/// Encoders read the commanded lengths exactly (1e-9 m); the position agrees to 0.1 mm
/// (seen: 26 um), the angles to 0.001 degree (seen: 2e-5), the reference tension to
/// 0.1 % (seen: 1.1e-5 relative).
#[test]
fn no_effect_agrees_with_the_closed_form_data() {
    let (robot, equilibria) = setup(3);
    let discretised = noiseless(&robot, &Effects::default(), &equilibria, 200);
    let closed = measure(
        &robot,
        &equilibria,
        &NoisePreset::None.sigmas(robot.platform_weight_n),
        &mut ChaCha8Rng::seed_from_u64(1),
    );
    for (d, c) in discretised.iter().zip(&closed) {
        for i in 0..4 {
            assert!((d.encoder_lengths_m[i] - c.encoder_lengths_m[i]).abs() < 1e-9);
        }
        let dp = (Vector3::from(d.position_m) - Vector3::from(c.position_m)).norm();
        assert!(dp < 1e-4, "position differs by {dp} m");
        for (a, b) in [
            (d.roll_deg, c.roll_deg),
            (d.pitch_deg, c.pitch_deg),
            (d.yaw_deg, c.yaw_deg),
        ] {
            assert!((a - b).abs() < 1e-3, "angle {a} vs {b} deg");
        }
        let rel = (d.reference_tension_n / c.reference_tension_n - 1.0).abs();
        eprintln!("no effect vs closed form: position {dp:.2e} m, reference tension {rel:.2e} relative");
        assert!(rel < 1e-3, "reference tension differs by {rel}");
    }
}

/// Encoder scale and load cell act on the readings exactly; the pose is untouched.
#[test]
fn sensor_effects_are_exact() {
    let (robot, equilibria) = setup(2);
    let none = noiseless(&robot, &Effects::default(), &equilibria, 20);
    let e = effects(&[
        "encoder-scale:gain=1.002",
        "encoder-scale:gain4=0.997",
        "loadcell:bias_n=3,gain=1.01",
    ]);
    let with = noiseless(&robot, &e, &equilibria, 20);
    for (w, n) in with.iter().zip(&none) {
        assert_eq!(w.position_m, n.position_m);
        for i in 0..4 {
            let gain = if i == 3 { 0.997 } else { 1.002 };
            let expected = gain * (n.encoder_lengths_m[i] - robot.length_offsets_m[i]) + robot.length_offsets_m[i];
            assert!((w.encoder_lengths_m[i] - expected).abs() < 1e-9);
        }
        assert!((w.reference_tension_n - (3.0 + 1.01 * n.reference_tension_n)).abs() < 1e-9);
    }
}

/// Elastic cables stretch by about `L T_mean / EA`: the platform sits where the
/// inextensible closed-form robot would with cables that much longer, i.e. lower
/// (EA = 3e6 N on the large robot: about 0.175 m lower; estimate within 5 %, seen 1 %).
#[test]
fn elastic_cables_lower_the_platform_by_the_stretch() {
    let (robot, equilibria) = setup(2);
    let ea = 3e6;
    let segments = 40;
    let none = solve_with_effects(&robot, &Effects::default(), &equilibria, segments).unwrap();
    let elastic = solve_with_effects(&robot, &effects(&["elastic:ea_n=3e6"]), &equilibria, segments).unwrap();
    for ((eq, n), e) in equilibria.iter().zip(&none).zip(&elastic) {
        // Hand estimate: the mean of the platform and pulley tensions of the closed-form catenary.
        let stretched: [f64; 4] = std::array::from_fn(|i| {
            let t = eq.tensions[i];
            let top = t
                .horizontal_n
                .hypot(t.vertical_n + robot.cable_weight_n_per_m * eq.cable_lengths_m[i]);
            let mean = 0.5 * (t.magnitude_n() + top);
            eq.cable_lengths_m[i] * (1.0 + mean / ea)
        });
        let expected = statics::solve_forward(&robot, &stretched, Some(eq.pose), &StaticsOptions::default()).unwrap();
        let predicted = expected.pose.position_m - eq.pose.position_m;
        let simulated = e.pose.position_m - n.pose.position_m;
        assert!(simulated.z < -0.01, "elastic platform not lower: {simulated:?}");
        let error = (simulated - predicted).norm();
        eprintln!(
            "EA = 3e6 N: platform {:.3} m lower (hand estimate {:.3} m, difference {:.1} %)",
            -simulated.z,
            -predicted.z,
            100.0 * error / predicted.norm()
        );
        assert!(
            error < 0.05 * predicted.norm(),
            "simulated shift {simulated:?} m vs hand estimate {predicted:?} m"
        );
    }
}

/// A load-cell bias larger than the small robot's lightest reference tension
/// makes a reading negative: `simulate` refuses, names the row and field, and
/// writes neither the data nor the truth file.
#[test]
fn a_refused_data_file_leaves_no_truth_file_behind() {
    let dir = tempfile::tempdir().unwrap();
    let robot = robot_path("small");
    let out = sagcal(
        dir.path(),
        &[
            "simulate",
            "--robot",
            &robot,
            "--poses",
            "30",
            "--seed",
            "11",
            "--noise",
            "paper",
            "--effect",
            "loadcell:bias_n=-20,gain=1.0",
            "--out",
            "d.csv",
            "--truth",
            "t.toml",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("refusing to write d.csv") && stderr.contains("field `f_ref_n`"),
        "{stderr}"
    );
    assert!(!dir.path().join("d.csv").exists());
    assert!(
        !dir.path().join("t.toml").exists(),
        "the truth was written beside a refused data file"
    );
}

//! `diagnose`'s forward selection (issue 14), fast subset: data from the
//! discretised simulator with the true anchors off the nominal ones, each
//! case seeded and printed. A 5 cm centre-of-mass shift under the paper's
//! noise is named (its evidence is the platform's tilt, which the
//! localiser's orientation carries); two effects at once are named as a
//! pair; `none` stays `none` under both noise readings; an extension from
//! the selected model predicts poses it was not fitted on better than the
//! baseline.

#[path = "common/truth.rs"]
mod truth;

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::calib::{calibrate, predict_with_effects, CalibrationOptions, OrientationPrior};
use sagcal::diagnose::{diagnose, DiagnoseOptions, Diagnosis};
use sagcal::model::effects::Effects;
use sagcal::model::measurement::PoseMeasurement;
use sagcal::model::sensors::{NoisePreset, SensorNoise};
use sagcal::model::statics::{self, StaticsOptions};
use sagcal::model::{Robot, CABLE_COUNT};
use sagcal::sim::closed_form::{sample_equilibria, Workspace};
use sagcal::sim::effects::measure_with_effects;
use truth::truth_off_nominal;

/// Segments per cable of the discretised truth (fewer than the sweep's 50, for speed).
const SEGMENTS: usize = 40;

/// A truth 0.3 m off the nominal large robot per anchor coordinate with
/// offsets of metres, `effects` acting, and `poses` measured with `noise`;
/// returns the truth, the measurements and the nominal robot as the guess.
fn case(effects: &[&str], noise: NoisePreset, poses: usize, seed: u64) -> (Robot, Vec<PoseMeasurement>, Robot) {
    let (nominal, mut truth, equilibria, mut rng) = truth_off_nominal("large", seed, poses, |_| {});
    let e = Effects::from_specs(effects).unwrap();
    let sigmas = noise.sigmas(truth.platform_weight_n);
    let measurements = measure_with_effects(&truth, &e, &equilibria, &sigmas, SEGMENTS, &mut rng).unwrap();
    truth.effects = e;
    (truth, measurements, nominal)
}

fn run(effects: &[&str], noise: NoisePreset, seed: u64) -> (Robot, Vec<PoseMeasurement>, Diagnosis) {
    let (truth, measurements, guess) = case(effects, noise, 30, seed);
    let mut options = DiagnoseOptions::new(CalibrationOptions::new(noise.sigmas(truth.platform_weight_n)));
    options.folds = 4;
    let d = diagnose(&guess, &measurements, Some(&truth), &options, &mut |_, _, _| {}).unwrap();
    println!(
        "seed {seed}, {effects:?}, {noise:?} noise: verdict {}, {}; anchor MAE {:?} -> {:?} m",
        d.verdict, d.reason, d.gain.anchor_mae_before_m, d.gain.anchor_mae_after_m
    );
    (truth, measurements, d)
}

fn named(d: &Diagnosis) -> Vec<String> {
    let mut names: Vec<String> = d.verdict.split('+').map(String::from).collect();
    names.sort();
    names
}

#[test]
fn a_five_centimetre_com_shift_under_the_paper_noise_is_named() {
    let (_, _, d) = run(&["com:dx_m=0.03,dy_m=-0.04"], NoisePreset::Paper, 21);
    assert_eq!(d.verdict, "com");
    let shift = &d.effects[0].params;
    assert!(
        (shift[0].value - 0.03).abs() < 4.0 * shift[0].sigma + 0.005,
        "{shift:?}"
    );
    assert!(
        (shift[1].value + 0.04).abs() < 4.0 * shift[1].sigma + 0.005,
        "{shift:?}"
    );
    // Under the paper's noise the anchors' own noise (about 0.3 m, the
    // Cramer-Rao bound of `experiment table2`) hides what a 5 cm shift does to
    // them, so no anchor gain is asserted here; the held-out residual shows it.
    assert!(d.gain.residual_rms_after < d.gain.residual_rms_before);
}

#[test]
fn two_effects_at_once_are_named_as_a_pair() {
    let (_, _, d) = run(&["com:dx_m=0.08", "elastic:ea_n=3e6"], NoisePreset::Authors, 22);
    assert_eq!(named(&d), ["com", "elastic"]);
    assert_eq!(d.effects.len(), 2);
    let (_, _, d) = run(
        &[
            "encoder-scale:gain1=1.002,gain2=0.998,gain3=1.001,gain4=0.999",
            "loadcell:bias_n=40",
        ],
        NoisePreset::Authors,
        23,
    );
    assert_eq!(named(&d), ["encoder-scale", "loadcell"]);
}

/// A structured localiser fault: one mounting rotation for every pose (3
/// parameters) is named and measured, not absorbed by freeing 3 orientation
/// components per pose or by a centre-of-mass shift that tilts the platform;
/// with a shift as well, the pair is named.
#[test]
fn a_localiser_mount_is_named_alone_and_beside_a_com_shift() {
    let (truth, _, d) = run(
        &["localiser-mount:rx_deg=1.2,ry_deg=-0.6,rz_deg=0.9"],
        NoisePreset::Paper,
        28,
    );
    assert_eq!(d.verdict, "localiser-mount", "{}", d.reason);
    let mount = &d.effects[0].params;
    for (k, p) in mount.iter().enumerate() {
        let true_deg = truth.effects.localiser_mount_deg[k];
        assert!((p.value - true_deg).abs() < 4.0 * p.sigma + 0.05, "{mount:?}");
    }
    let (_, _, d) = run(
        &["com:dx_m=-0.06,dy_m=0.05", "localiser-mount:rx_deg=-0.8,rz_deg=1.5"],
        NoisePreset::Authors,
        29,
    );
    // Both are named as causes. The final model's load-cell chi-square
    // (61.0 for a redundancy of 26.5, p = 2e-4 below the 3.3e-4 of each sensor
    // test) adds `unexplained` to this verdict: the overall fit is right
    // (190.4 for 189 degrees of freedom), so either a false alarm of the
    // per-sensor test or a model error of the truth at the load cell alone.
    let mut causes = d.explanation.causes.clone();
    causes.sort();
    assert_eq!(causes, ["com", "localiser-mount"], "{}", d.reason);
}

/// The platform 3 % heavier, or cables 5 % lighter, than the robot file
/// says (the weak end of each range) are named under both noise readings,
/// each with its estimate within 4 sigma of the truth; the report gives the
/// fit it cannot be told from (both weights scaled, seen as a load-cell gain).
#[test]
fn a_wrong_platform_or_cable_weight_at_the_weak_end_is_named() {
    for noise in [NoisePreset::Paper, NoisePreset::Authors] {
        for (spec, name, truth_scale) in [
            ("platform-weight:scale=1.03", "platform-weight", 1.03),
            ("cable-weight:scale=0.95", "cable-weight", 0.95),
        ] {
            let (_, _, d) = run(&[spec], noise, 41);
            assert_eq!(d.verdict, name, "{spec}, {noise:?}: {}", d.reason);
            let scale = &d.effects[0].params[0];
            assert!(
                (scale.value - truth_scale).abs() < 4.0 * scale.sigma,
                "{spec}, {noise:?}: {scale:?}"
            );
            assert_eq!(d.equivalent_fits.len(), 1, "{:?}", d.equivalent_fits);
            assert!(d.gain.anchor_mae_after_m < d.gain.anchor_mae_before_m);
        }
    }
}

/// Data with the authors' noise (1 mm encoders) diagnosed with the paper's
/// stated noise (10 mm encoders, the load cell's 5 N as stated): one
/// variance factor for all sensors left the load cell looking far too noisy
/// against the rest, and `none` came out `loadcell|platform-weight` or
/// `unexplained` (seed 4 here: `platform-weight`; 1 of 16 seeds of this
/// truth, 2 of 2 `simulate` runs of the nominal robots); with each sensor's
/// noise as its data show it the verdict is `none` (16 of 16), and a hidden
/// effect is still named.
#[test]
fn overstated_noise_does_not_reject_none() {
    let stated = |truth: &Robot| {
        let mut options = DiagnoseOptions::new(CalibrationOptions::new(
            NoisePreset::Paper.sigmas(truth.platform_weight_n),
        ));
        options.folds = 4;
        options
    };
    for seed in [4, 11, 12] {
        let (truth, measurements, guess) = case(&[], NoisePreset::Authors, 30, seed);
        let d = diagnose(&guess, &measurements, Some(&truth), &stated(&truth), &mut |_, _, _| {}).unwrap();
        println!(
            "seed {seed}, none: verdict {}; noise shown {:?}",
            d.verdict, d.noise_shown
        );
        assert_eq!(d.verdict, "none", "seed {seed}: {}", d.reason);
        let shown = d
            .noise_shown
            .expect("the sensors differ from the stated noise by different factors");
        assert!(shown.encoder_sigma_m < 0.5 * NoisePreset::Paper.sigmas(truth.platform_weight_n).encoder_sigma_m);
    }
    let (truth, measurements, guess) = case(&["cable-weight:scale=0.92"], NoisePreset::Authors, 30, 11);
    let d = diagnose(&guess, &measurements, Some(&truth), &stated(&truth), &mut |_, _, _| {}).unwrap();
    assert_eq!(d.verdict, "cable-weight", "{}", d.reason);
}

#[test]
fn none_stays_none_under_both_noise_readings() {
    for (noise, seed) in [(NoisePreset::Paper, 24), (NoisePreset::Authors, 25)] {
        let (_, _, d) = run(&[], noise, seed);
        assert_eq!(d.verdict, "none", "{noise:?}: {}", d.reason);
        assert!(d.steps.is_empty());
        // The first step tests every hypothesis at alpha / m: none reaches it.
        assert!(d.candidates.iter().all(|c| !c.significant));
    }
}

#[test]
fn the_selected_extension_predicts_unseen_poses_better() {
    let (truth, measurements, d) = run(&["elastic:ea_n=2.5e6"], NoisePreset::Authors, 26);
    assert_eq!(d.verdict, "elastic");
    // Poses no fit saw, from the same truth, without noise.
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let mut plain = truth.clone();
    plain.effects = Effects::default();
    let equilibria = sample_equilibria(&plain, &Workspace::default_for(&plain), 12, &mut rng).unwrap();
    let exact = SensorNoise {
        encoder_sigma_m: 0.0,
        load_cell_sigma_n: 0.0,
        position_sigma_m: 0.0,
        orientation_sigma_rad: 0.0,
    };
    let unseen = measure_with_effects(&plain, &truth.effects, &equilibria, &exact, SEGMENTS, &mut rng).unwrap();
    assert_eq!(measurements.len(), 30);
    let baseline_options = CalibrationOptions {
        orientation_prior: OrientationPrior::On,
        ..CalibrationOptions::new(NoisePreset::Authors.sigmas(truth.platform_weight_n))
    };
    let baseline = calibrate(&Robot::builtin("large").unwrap(), &measurements, &baseline_options).unwrap();
    let rms = |robot: &Robot| {
        let mut sum = 0.0;
        for m in &unseen {
            let start = statics::solve_with_reference_tension(
                robot,
                Vector3::from(m.position_m),
                m.reference_tension_n,
                None,
                &StaticsOptions::default(),
            )
            .unwrap();
            let predicted = predict_with_effects(robot, &start, m.reference_tension_n).unwrap();
            for i in 0..CABLE_COUNT {
                sum += (predicted.cable_lengths_m[i] - m.encoder_lengths_m[i]).powi(2);
            }
        }
        (sum / (CABLE_COUNT * unseen.len()) as f64).sqrt()
    };
    let (before, after) = (rms(&baseline.robot), rms(&d.robot_after));
    println!("unseen poses: length RMS baseline {before:.4} m, selected model {after:.4} m");
    assert!(after < 0.5 * before, "{before} -> {after}");
}

#[test]
fn calibrate_keeps_orientations_that_the_robot_files_effects_explain() {
    let (truth, measurements, _) = case(&["com:dx_m=0.15"], NoisePreset::Paper, 30, 27);
    let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(truth.platform_weight_n));
    // Without the shift the orientations contradict the statics and are dropped ...
    let plain = calibrate(&Robot::builtin("large").unwrap(), &measurements, &options).unwrap();
    assert!(!plain.orientation_check.unwrap().prior_used);
    // ... with the shift as a known effect they agree and are kept.
    let mut known = Robot::builtin("large").unwrap();
    known.effects = truth.effects;
    let result = calibrate(&known, &measurements, &options).unwrap();
    let check = result.orientation_check.unwrap();
    println!(
        "seed 27: orientation chi-square {:.1} (limit {:.1})",
        check.chi_square, check.limit
    );
    assert!(check.prior_used);
    // The same for a localiser mounted 2 degrees off: dropped without it, kept with it.
    let (truth, measurements, _) = case(&["localiser-mount:rx_deg=1.5,ry_deg=1.3"], NoisePreset::Paper, 30, 30);
    let plain = calibrate(&Robot::builtin("large").unwrap(), &measurements, &options).unwrap();
    assert!(!plain.orientation_check.unwrap().prior_used);
    let mut known = Robot::builtin("large").unwrap();
    known.effects = truth.effects;
    let check = calibrate(&known, &measurements, &options)
        .unwrap()
        .orientation_check
        .unwrap();
    println!(
        "seed 30: orientation chi-square with the mount known {:.1} (limit {:.1})",
        check.chi_square, check.limit
    );
    assert!(check.prior_used);
}

fn sagcal(dir: &std::path::Path, args: &[&str]) -> serde_json::Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null)
}

#[test]
fn an_extension_written_by_diagnose_improves_verify_on_unseen_poses() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let large = format!("{}/robots/large.toml", env!("CARGO_MANIFEST_DIR"));
    // The unseen poses without sensor noise: `verify` then measures the model's
    // own error (with the authors' noise, MPE-L is 0.0037 % even for the truth,
    // which would mask it: baseline 0.0075 %, extension 0.0037 %).
    for (seed, out, noise) in [("31", "fit.csv", "authors"), ("32", "unseen.csv", "none")] {
        sagcal(
            d,
            &[
                "simulate",
                "--robot",
                &large,
                "--poses",
                "30",
                "--seed",
                seed,
                "--noise",
                noise,
                "--effect",
                "elastic:ea_n=2.5e6",
                "--segments",
                "40",
                "--out",
                out,
            ],
        );
    }
    // The baseline misses the stretch: `calibrate` refuses it (exit 1, nothing
    // written) and names the failing sensors ...
    let refused = std::process::Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args([
            "calibrate",
            "--robot",
            &large,
            "--data",
            "fit.csv",
            "--noise",
            "authors",
            "--out",
            "baseline.toml",
        ])
        .current_dir(d)
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("sagcal diagnose"));
    assert!(!d.join("baseline.toml").exists());
    // ... and writes it only when told to, for this comparison.
    sagcal(
        d,
        &[
            "calibrate",
            "--robot",
            &large,
            "--data",
            "fit.csv",
            "--noise",
            "authors",
            "--out",
            "baseline.toml",
            "--accept-inconsistent",
            "--json",
        ],
    );
    let diagnosis = sagcal(
        d,
        &[
            "diagnose",
            "--robot",
            &large,
            "--data",
            "fit.csv",
            "--noise",
            "authors",
            "--folds",
            "4",
            "--out",
            "extended.toml",
            "--json",
        ],
    );
    assert_eq!(diagnosis["verdict"], "elastic");
    let written = std::fs::read_to_string(d.join("extended.toml")).unwrap();
    assert!(written.contains("axial_stiffness_n") && written.starts_with("# Calibrated by sagcal diagnose"));
    let mpe = |robot: &str| {
        let report = sagcal(d, &["verify", "--robot", robot, "--data", "unseen.csv", "--json"]);
        assert_eq!(report["rows_unsolved"].as_array().unwrap().len(), 0, "{robot}");
        report["mpe_length_pct"].as_f64().unwrap()
    };
    let (before, after) = (mpe("baseline.toml"), mpe("extended.toml"));
    println!("unseen poses (seed 32): MPE-L baseline {before:.5} %, extension {after:.5} %");
    assert!(after < 0.5 * before, "{before} -> {after}");
}

//! `diagnose` on robots of 3 to 8 cables: the profile fit of one extension
//! against readings with a known gain hidden in them, its 1-sigma against
//! the chi-squares it comes from, the verdicts on clean and on gained
//! readings, and the command; `verify` of a robot file against readings.

#[path = "common/cli.rs"]
mod cli;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::calib::suspended::SuspendedReading;
use sagcal::calib::CalibrationOptions;
use sagcal::diagnose::suspended::{
    calibrated_chi_square, diagnose_suspended, errors_against_truth, fit_profile, residual_structure,
    suspended_catalogue, verify_suspended, SuspendedDiagnoseSettings, SuspendedExtension, SuspendedVerdict,
    SUSPENDED_EXTENSIONS,
};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use sagcal::sim::closed_form::Closure;
use sagcal::sim::suspended::{measure_suspended, sample_suspended};

/// `count` readings of the six-cable robot (offsets of a few decimetres)
/// with `noise`, seed `seed`, every encoder reading times `gain`; and the robot file.
fn six_cable_readings(
    count: usize,
    seed: u64,
    noise: NoisePreset,
    gain: f64,
) -> (SuspendedRobot, Vec<SuspendedMeasurement>) {
    let nominal = SuspendedRobot::builtin("six").unwrap();
    let mut truth = nominal.clone();
    truth.length_offsets_m = (0..truth.cable_count()).map(|i| 0.1 + 0.07 * i as f64).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let workspace = truth.workspace.unwrap();
    let equilibria = sample_suspended(&truth, &workspace, count, Closure::Yaw { max_yaw_deg: 5.0 }, &mut rng).unwrap();
    let sigmas = noise.sigmas(truth.platform_weight_n);
    let mut readings = measure_suspended(&truth, &equilibria, &sigmas, &mut rng).unwrap();
    for reading in &mut readings {
        reading.encoder_lengths_m.iter_mut().for_each(|l| *l *= gain);
    }
    (nominal, readings)
}

fn paper_options(robot: &SuspendedRobot) -> CalibrationOptions {
    CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n))
}

/// Noiseless readings through encoders 0.2 % long: the profile's minimum
/// is the gain, to the solver's tolerance, and leaves no misfit, where the
/// baseline's is above the likelihood-ratio limit (14.2 at 1e-3 over six
/// extensions: 20 poses see the gain though the anchors take up most of
/// it); the elastic extension's minimum leaves a misfit.
#[test]
fn noiseless_readings_give_back_the_encoder_gain_hidden_in_them() {
    let (robot, readings) = six_cable_readings(20, 3, NoisePreset::None, 1.002);
    let options = paper_options(&robot);
    let fit = fit_profile(&robot, &readings, SuspendedExtension::EncoderScale, &options).unwrap();
    println!(
        "gain {:.9} +- {:.2e}, chi-square {:.3e} (null {:.3e})",
        fit.value, fit.sigma, fit.chi_square, fit.null_chi_square
    );
    assert!((fit.value - 1.002).abs() < 1e-6, "{fit:?}");
    assert!(fit.chi_square < 1e-6, "{fit:?}");
    assert!(fit.null_chi_square > 14.2, "{fit:?}");
    let elastic = fit_profile(&robot, &readings, SuspendedExtension::Elastic, &options).unwrap();
    println!("elastic: {elastic:?}");
    assert!(elastic.chi_square > 1.0, "{elastic:?}");
}

/// The 1-sigma from the profile's curvature is the distance at which the
/// chi-square, computed again by independent calibrations, rises by one.
#[test]
fn the_profile_sigma_is_where_the_chi_square_rises_by_one() {
    let (robot, readings) = six_cable_readings(25, 5, NoisePreset::Paper, 1.0);
    let options = paper_options(&robot);
    for extension in [SuspendedExtension::EncoderScale, SuspendedExtension::CableWeight] {
        let fit = fit_profile(&robot, &readings, extension, &options).unwrap();
        for side in [-1.0, 1.0] {
            let at =
                calibrated_chi_square(&robot, &readings, extension, fit.value + side * fit.sigma, &options).unwrap();
            let rise = at - fit.chi_square;
            println!(
                "{}: {:.6} +- {:.2e}, rise {rise:.3} at {side:+} sigma",
                extension.name(),
                fit.value,
                fit.sigma
            );
            assert!((rise - 1.0).abs() < 0.15, "{extension:?} {fit:?} rise {rise}");
        }
    }
}

fn settings() -> SuspendedDiagnoseSettings {
    SuspendedDiagnoseSettings {
        extensions: SUSPENDED_EXTENSIONS.to_vec(),
        folds: 5,
        false_alarm: 1e-3,
    }
}

/// Clean readings with the paper's noise: no cause named. The same poses
/// read through encoders 0.2 % long: the encoder gain is named, within
/// three of its 1-sigma of the truth.
#[test]
fn the_encoder_gain_is_named_and_clean_readings_name_nothing() {
    let (robot, clean) = six_cable_readings(30, 7, NoisePreset::Paper, 1.0);
    let options = paper_options(&robot);
    let diagnosis = diagnose_suspended(&robot, &clean, &settings(), &options, &|_, _| {}).unwrap();
    println!("clean: {}", diagnosis.conclusion);
    assert_eq!(diagnosis.verdict, SuspendedVerdict::Consistent, "{diagnosis:#?}");
    let (_, gained) = six_cable_readings(30, 7, NoisePreset::Paper, 1.002);
    let diagnosis = diagnose_suspended(&robot, &gained, &settings(), &options, &|_, _| {}).unwrap();
    println!("gained: {}", diagnosis.conclusion);
    assert_eq!(
        diagnosis.verdict,
        SuspendedVerdict::Named {
            extension: SuspendedExtension::EncoderScale
        },
        "{diagnosis:#?}"
    );
    let fit = &diagnosis.extensions[3];
    assert_eq!(fit.extension, SuspendedExtension::EncoderScale);
    assert!((fit.value - 1.002).abs() < 3.0 * fit.sigma, "{fit:?}");
}

/// The same poses read through cable 3's encoder alone 0.5 % long, with
/// the common gain, one cable's weight and two other drums' gains as
/// rivals: drum 3's gain is named, within three of its 1-sigma of the
/// truth, and the common gain is not a candidate the readings confuse it
/// with.
#[test]
fn one_drum_s_gain_is_named_as_that_drum_s() {
    let (robot, mut readings) = six_cable_readings(30, 7, NoisePreset::Paper, 1.0);
    readings.iter_mut().for_each(|r| r.encoder_lengths_m[2] *= 1.005);
    let options = paper_options(&robot);
    let settings = SuspendedDiagnoseSettings {
        extensions: vec![
            SuspendedExtension::EncoderScale,
            SuspendedExtension::DrumGain(1),
            SuspendedExtension::DrumGain(2),
            SuspendedExtension::DrumGain(3),
            SuspendedExtension::OneCableWeight(2),
        ],
        ..settings()
    };
    let diagnosis = diagnose_suspended(&robot, &readings, &settings, &options, &|_, _| {}).unwrap();
    println!("drum 3: {}", diagnosis.conclusion);
    let drum = SuspendedExtension::DrumGain(2);
    assert_eq!(
        diagnosis.verdict,
        SuspendedVerdict::Named { extension: drum },
        "{diagnosis:#?}"
    );
    let fit = &diagnosis.extensions[2];
    assert_eq!(fit.extension, drum);
    assert!((fit.value - 1.005).abs() < 3.0 * fit.sigma, "{fit:?}");
    assert!(fit.sigma < 1e-3, "{fit:?}");
}

/// The score tests of the baseline's residuals: on clean readings no term
/// is beyond the limit; with drum 3 reading its cable 0.5 % long, the
/// strongest term is encoder 3 against its own reading, its coefficient
/// (metres per metre, the model's parameters re-fitted with it) the gain
/// less one within three of its 1-sigma.
#[test]
fn the_residual_tests_see_a_drum_s_gain_the_model_lacks() {
    let (robot, mut readings) = six_cable_readings(30, 7, NoisePreset::Paper, 1.0);
    let options = paper_options(&robot);
    let baseline = SuspendedExtension::Elastic;
    let clean = residual_structure(&robot, &readings, (baseline, 0.0), &options, 1e-3, &[]).unwrap();
    println!(
        "clean: {:?} of {} (limit {:.2})",
        clean.strongest, clean.tested, clean.limit
    );
    assert!(clean.clean(), "{clean:#?}");
    assert_eq!(clean.tested, 6 * 3 + 3 + 3 + 3, "{clean:#?}");
    readings.iter_mut().for_each(|r| r.encoder_lengths_m[2] *= 1.005);
    let gained = residual_structure(&robot, &readings, (baseline, 0.0), &options, 1e-3, &[]).unwrap();
    let strongest = gained.strongest.clone().unwrap();
    println!(
        "drum 3: {strongest:?}, {} beyond {:.2}",
        gained.beyond.len(),
        gained.limit
    );
    assert_eq!(strongest.reading, "encoder 3", "{gained:#?}");
    assert_eq!(strongest.driver, "its reading (m)", "{gained:#?}");
    assert!(
        (strongest.coefficient - 0.005).abs() < 3.0 * strongest.sigma,
        "{strongest:?}"
    );
    assert!(!gained.clean(), "{gained:#?}");
}

/// Drum 3's gain with cable 3's weight the only extension tried (the gain
/// outside the catalogue): the baseline's residuals show encoder 3 against
/// its own reading, the weight takes up part of it (significant, better on
/// held-out poses, plausible, passing), but what the term still takes off
/// the extended model is beyond its limit, so the weight is not named.
/// Seed 2 is one where the weight would be named without that check; over
/// seeds 1 to 13 the weight is `partial` in 3 (2, 5, 12), a stand-in in 2,
/// `unexplained` in 7 and still named in 1 (13: the term left in it below
/// its limit), which docs/diagnose.md reports.
#[test]
fn a_drum_s_gain_outside_the_catalogue_is_not_named_as_its_cable_s_weight() {
    let (robot, mut readings) = six_cable_readings(30, 2, NoisePreset::Paper, 1.0);
    readings.iter_mut().for_each(|r| r.encoder_lengths_m[2] *= 1.005);
    let options = paper_options(&robot);
    let weight = SuspendedExtension::OneCableWeight(2);
    let settings = SuspendedDiagnoseSettings {
        extensions: vec![weight],
        ..settings()
    };
    let diagnosis = diagnose_suspended(&robot, &readings, &settings, &options, &|_, _| {}).unwrap();
    println!("{}", diagnosis.conclusion);
    let lacked = &diagnosis.baseline_structure.describing;
    println!(
        "baseline lacked {lacked:?}; named model {:?}",
        diagnosis.named_structure
    );
    assert_eq!(lacked[0].reading, "encoder 3", "{diagnosis:#?}");
    assert_eq!(lacked[0].driver, "its reading (m)", "{diagnosis:#?}");
    assert_eq!(
        diagnosis.verdict,
        SuspendedVerdict::Partial { extension: weight },
        "{diagnosis:#?}"
    );
    let named = diagnosis.named_structure.as_ref().unwrap();
    assert!(
        diagnosis.extensions[0].passes && diagnosis.extensions[0].plausible,
        "{diagnosis:#?}"
    );
    assert!(named.given_drop > named.given_limit, "{named:#?}");
}

/// Each model against the truth: the baseline's anchor error is that of
/// an independent calibration of the same readings, and where noiseless
/// encoders read 0.2 % long, the encoder gain's model lands its anchors
/// and offsets on the truth (to 0.1 mm) where the baseline's are
/// centimetres off (the gain, measured).
#[test]
fn the_encoder_gain_s_model_lands_on_the_truth() {
    let (robot, readings) = six_cable_readings(20, 3, NoisePreset::None, 1.002);
    let mut truth = robot.clone();
    truth.length_offsets_m = (0..truth.cable_count()).map(|i| 0.1 + 0.07 * i as f64).collect();
    let options = paper_options(&robot);
    let gain = fit_profile(&robot, &readings, SuspendedExtension::EncoderScale, &options).unwrap();
    let models = [
        (SuspendedExtension::Elastic, 0.0),
        (SuspendedExtension::EncoderScale, gain.value),
    ];
    let errors = errors_against_truth(&robot, &readings, &models, &truth, &options).unwrap();
    println!("{errors:#?}");
    let alone = sagcal::calib::suspended::calibrate_suspended(&robot, &readings, &options, None, &mut |_| {}).unwrap();
    let mae: f64 = (0..6)
        .map(|i| (alone.robot.anchors_m[i] - truth.anchors_m[i]).abs().sum())
        .sum::<f64>()
        / 18.0;
    assert_eq!(errors[0].model, "baseline");
    assert!(
        (errors[0].anchor_mae_m - mae).abs() < 1e-12,
        "{} against {mae}",
        errors[0].anchor_mae_m
    );
    assert_eq!(errors[1].model, "encoder-scale");
    assert!(errors[1].anchor_max_distance_m < 1e-4, "{errors:#?}");
    assert!(errors[1].offset_mae_m < 1e-4, "{errors:#?}");
    assert!(errors[0].anchor_mae_m > 1e-2, "{errors:#?}");
}

/// `sagcal diagnose --robot robots/six.toml --data six.csv ARGS` in `dir`.
fn diagnose_six(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    let robot = cli::robot("six");
    let mut all = vec!["diagnose", "--robot", robot.as_str(), "--data", "six.csv"];
    all.extend_from_slice(args);
    cli::sagcal(dir, &all)
}

/// `sagcal diagnose` on simulated readings of the six-cable robot: the
/// JSON's verdict and extensions; a four-cable flag and an unknown
/// extension refused by name, with a non-zero exit.
#[test]
fn the_diagnose_command_diagnoses_six_cables() {
    let dir = tempfile::tempdir().unwrap();
    let robot = cli::robot("six");
    let simulated = cli::sagcal(
        dir.path(),
        &[
            "simulate", "--robot", &robot, "--poses", "20", "--seed", "4", "--out", "six.csv",
        ],
    );
    assert!(
        simulated.status.success(),
        "{}",
        String::from_utf8_lossy(&simulated.stderr)
    );
    let out = diagnose_six(
        dir.path(),
        &["--json", "--candidates", "elastic,encoder-scale,drum-gain"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["cables"], 6);
    let names: Vec<&str> = json["extensions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["extension"].as_str().unwrap())
        .collect();
    let drums = [
        "drum-gain-1",
        "drum-gain-2",
        "drum-gain-3",
        "drum-gain-4",
        "drum-gain-5",
        "drum-gain-6",
    ];
    assert_eq!(names[..2], ["elastic", "encoder-scale"]);
    assert_eq!(names[2..], drums);
    assert_eq!(json["verdict"]["kind"], "consistent", "{json:#}");
    let text = diagnose_six(
        dir.path(),
        &["--candidates", "elastic,encoder-scale", "--truth", &robot],
    );
    let stdout = String::from_utf8_lossy(&text.stdout);
    assert!(
        stdout.contains("baseline: chi-square") && stdout.contains("encoder-scale"),
        "{stdout}"
    );
    // Against the truth: the baseline's and each extension's anchors.
    let against: Vec<&str> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("against the truth"))
        .skip(2)
        .take(3)
        .map(|l| l.split_whitespace().next().unwrap_or_default())
        .collect();
    assert_eq!(against, ["baseline", "elastic", "encoder-scale"], "{stdout}");
    assert!(
        !stdout.lines().any(|line| line.starts_with("loadcell-gain")),
        "{stdout}"
    );
    let three = cli::robot("three");
    let truth = diagnose_six(dir.path(), &["--candidates", "elastic", "--truth", &three]);
    let message = String::from_utf8_lossy(&truth.stderr);
    assert!(
        !truth.status.success() && message.contains("the truth `three` has 3 cables"),
        "{message}"
    );
    let plots = diagnose_six(dir.path(), &["--plots", "figures"]);
    let message = String::from_utf8_lossy(&plots.stderr);
    assert!(
        !plots.status.success() && message.contains("--plots: robot `six` has 6 cables"),
        "{message}"
    );
    let unknown = diagnose_six(dir.path(), &["--candidates", "pulley"]);
    let message = String::from_utf8_lossy(&unknown.stderr);
    assert!(
        !unknown.status.success() && message.contains("`pulley` is not an extension"),
        "{message}"
    );
    let lacking = diagnose_six(dir.path(), &["--candidates", "cable-weight-7"]);
    let message = String::from_utf8_lossy(&lacking.stderr);
    assert!(
        !lacking.status.success() && message.contains("`cable-weight-7` names a cable the robot lacks"),
        "{message}"
    );
}

/// `text` with every run of white space as one space.
fn flat(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The example of docs/diagnose.md (and its number in the README) is what
/// the commands printed beside it print: the table's rows and the verdict.
#[test]
fn the_documented_example_prints_what_the_pages_show() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let page = flat(&std::fs::read_to_string(root.join("docs/diagnose.md")).unwrap());
    let readme = flat(&std::fs::read_to_string(root.join("README.md")).unwrap());
    let dir = tempfile::tempdir().unwrap();
    let robot = cli::robot("six");
    let simulate = [
        "simulate",
        "--robot",
        &robot,
        "--poses",
        "30",
        "--seed",
        "2",
        "--effect",
        "encoder-scale:gain=1.002",
        "--out",
        "six-gain.csv",
    ];
    assert!(page.contains(
        "sagcal simulate --robot robots/six.toml --poses 30 --seed 2 --effect encoder-scale:gain=1.002 --out six-gain.csv"
    ));
    let simulated = cli::sagcal(dir.path(), &simulate);
    assert!(
        simulated.status.success(),
        "{}",
        String::from_utf8_lossy(&simulated.stderr)
    );
    let out = cli::sagcal(dir.path(), &["diagnose", "--robot", &robot, "--data", "six-gain.csv"]);
    let printed = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // Every extension of the catalogue has its row, and the page shows it.
    let catalogue = suspended_catalogue(&SuspendedRobot::builtin("six").unwrap());
    let rows: Vec<&str> = printed
        .lines()
        .filter(|l| catalogue.iter().any(|e| l.starts_with(&format!("{} ", e.name()))))
        .collect();
    assert_eq!(rows.len(), catalogue.len(), "{printed}");
    for row in &rows {
        assert!(page.contains(&flat(row)), "docs/diagnose.md does not show `{row}`");
    }
    let verdict = &printed[printed.find("named cause").expect("a named cause")..];
    let verdict = flat(&verdict[..verdict.find("not in the model").unwrap()]);
    assert!(page.contains(&verdict), "docs/diagnose.md does not say `{verdict}`");
    // The encoder gain's row: its fitted value and 1-sigma as quoted.
    let gain: Vec<&str> = rows[3].split_whitespace().collect();
    assert_eq!(gain[0], "encoder-scale");
    let quoted = format!("{} +- {}", gain[1], gain[2]);
    assert!(readme.contains(&quoted), "README.md does not say `{quoted}`");
    assert!(
        page.contains(&format!("found at {quoted}")),
        "docs/diagnose.md does not say `{quoted}`"
    );
}

/// `count` readings of the built-in robot `name` with `noise`, seed `seed`:
/// the robot (its offsets as the readings have them) and the readings.
fn readings_of(name: &str, count: usize, seed: u64, noise: NoisePreset) -> (SuspendedRobot, Vec<SuspendedMeasurement>) {
    let mut truth = SuspendedRobot::builtin(name).unwrap();
    truth.length_offsets_m = (0..truth.cable_count()).map(|i| 0.1 + 0.07 * i as f64).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let workspace = truth.workspace.unwrap();
    let closure = match truth.cable_count() {
        3 => Closure::Level,
        _ => Closure::Yaw { max_yaw_deg: 5.0 },
    };
    let equilibria = sample_suspended(&truth, &workspace, count, closure, &mut rng).unwrap();
    let readings = measure_suspended(&truth, &equilibria, &noise.sigmas(truth.platform_weight_n), &mut rng).unwrap();
    (truth, readings)
}

/// Readings the model made itself leave nothing, and each row has the
/// degrees of freedom its readings less its unknowns give: 3 positions, N
/// encoders and K load cells against the pose's 6 coordinates and N free
/// forces (2N less the N attachment heights), so 3 + K.
#[test]
fn verify_leaves_nothing_of_noiseless_readings_with_three_plus_k_dof_a_row() {
    for name in ["three", "six", "eight"] {
        let (robot, readings) = readings_of(name, 8, 21, NoisePreset::None);
        let report = verify_suspended(&robot, name, &readings, &paper_options(&robot), 1e-3).unwrap();
        let k = robot.load_cells.len();
        println!(
            "{name}: chi-square {:.2e}, dof {}",
            report.chi_square, report.degrees_of_freedom
        );
        assert!(report.chi_square < 1e-9, "{name}: {}", report.chi_square);
        assert!(report.rows.iter().all(|r| r.degrees_of_freedom == 3 + k), "{name}");
        assert!(report.passes && report.suspect_readings.is_empty(), "{name}");
        // The summed redundancy numbers are that count before rounding, less
        // the little the statics' tight constraints (sigma 1e-5 of the
        // platform's weight, not exact) take up: below 1e-3.
        for row in &report.rows {
            let sum: f64 = row.readings.iter().map(|r| r.redundancy).sum();
            assert!((sum - (3 + k) as f64).abs() < 1e-3, "{name} {}: {sum}", row.at);
        }
    }
}

/// The minimal detectable error of encoder 1, put into encoder 1 of every
/// row, is found in about 80 % of the rows (Baarda's power, 30 independent
/// rows: 19 to 28 is the binomial's 99 % range), half of it in few (a 3 %
/// power: at most 5); clean readings pass; the nominal robot (offsets 0)
/// against readings whose encoders have offsets of 0.1 to 0.45 m fails.
#[test]
fn verify_finds_an_encoder_error_of_its_minimal_detectable_size_four_times_in_five() {
    let (robot, clean) = readings_of("six", 30, 11, NoisePreset::Paper);
    let options = paper_options(&robot);
    let report = verify_suspended(&robot, "clean", &clean, &options, 1e-3).unwrap();
    assert!(report.passes, "{}", report.conclusion);
    let detectable = report.summaries[0].minimal_detectable.unwrap();
    println!(
        "encoder 1: found from {detectable:.4} m (mean r {:.3})",
        report.summaries[0].mean_redundancy
    );
    let found = |size: f64| {
        let mut damaged = clean.clone();
        damaged.iter_mut().for_each(|m| m.encoder_lengths_m[0] += size);
        let report = verify_suspended(&robot, "damaged", &damaged, &options, 1e-3).unwrap();
        report
            .suspect_readings
            .iter()
            .filter(|s| s.reading.reading == SuspendedReading::Encoder(0))
            .count()
    };
    let (full, half) = (found(detectable), found(detectable / 2.0));
    println!("found in {full} of 30 rows at full size, {half} at half");
    assert!((19..=28).contains(&full), "{full}");
    assert!(half <= 5, "{half}");
    let nominal = SuspendedRobot::builtin("six").unwrap();
    let wrong = verify_suspended(&nominal, "offsets", &clean, &options, 1e-3).unwrap();
    assert!(!wrong.passes, "{}", wrong.conclusion);
}

/// `sagcal verify` on a six-cable file: text and JSON; the four-cable
/// closures refused by name for six cables, the weighted fit's flags for four.
#[test]
fn the_verify_command_verifies_six_cables() {
    let dir = tempfile::tempdir().unwrap();
    let six = cli::robot("six");
    let simulate = [
        "simulate", "--robot", &six, "--poses", "12", "--seed", "4", "--out", "six.csv",
    ];
    assert!(cli::sagcal(dir.path(), &simulate).status.success());
    let verify = ["verify", "--robot", &six, "--data", "six.csv"];
    let out = cli::sagcal(dir.path(), &[&verify[..], &["--json"]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (json["cables"].as_u64(), json["degrees_of_freedom"].as_u64()),
        (Some(6), Some(48))
    );
    assert_eq!(json["passes"], true, "{json:#}");
    let text = cli::sagcal(dir.path(), &verify);
    let stdout = String::from_utf8_lossy(&text.stdout);
    assert!(
        stdout.contains("dl6 mm") && stdout.contains("found from (80 %)"),
        "{stdout}"
    );
    let closed = cli::sagcal(dir.path(), &[&verify[..], &["--close-with", "cable-lengths"]].concat());
    let message = String::from_utf8_lossy(&closed.stderr);
    assert!(
        !closed.status.success() && message.contains("--close-with: robot `six` has 6 cables"),
        "{message}"
    );
    let large = cli::robot("large");
    let simulate = [
        "simulate",
        "--robot",
        &large,
        "--poses",
        "3",
        "--seed",
        "4",
        "--out",
        "large.csv",
    ];
    assert!(cli::sagcal(dir.path(), &simulate).status.success());
    let four = ["verify", "--robot", &large, "--data", "large.csv", "--noise", "authors"];
    let refused = cli::sagcal(dir.path(), &four);
    let message = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && message.contains("--noise: robot `large` has 4 cables"),
        "{message}"
    );
    assert!(refused.stdout.is_empty());
}

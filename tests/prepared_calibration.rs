//! `PreparedCalibration` (the rigid stage and warm-ups made once for a
//! series of calibrations of the same data, as `diagnose` refits its
//! hypotheses) gives what `calibrate` gives, bit for bit.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::calib::{calibrate, CalibrationOptions, CalibrationResult, OrientationPrior, PreparedCalibration};
use sagcal::graph::RobustKernel;
use sagcal::model::effect_kind::{EffectKind, EffectSet};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

/// Every number a caller reads off a calibration, as bits.
fn fingerprint(result: &CalibrationResult) -> Vec<u64> {
    let mut bits: Vec<f64> = result.robot.anchors_m.iter().flat_map(|a| a.iter().copied()).collect();
    bits.extend(result.robot.length_offsets_m);
    bits.extend(result.stages.iter().map(|s| s.summary.final_cost));
    bits.extend(result.poses.iter().flat_map(|p| p.position_m.iter().copied()));
    bits.extend(result.effect_estimates.iter().flat_map(|e| e.values.iter().copied()));
    if let Some(check) = result.orientation_check {
        bits.push(check.chi_square);
        bits.push(if check.prior_used { 1.0 } else { 0.0 });
    }
    bits.push(result.excluded_poses.len() as f64);
    bits.into_iter().map(f64::to_bits).collect()
}

#[test]
fn prepared_calibrations_equal_calibrate_bit_for_bit() {
    let truth = Robot::builtin("large").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 14, &mut rng).unwrap();
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let mut data = measure(&truth, &equilibria, &noise, &mut rng);
    // The localiser's roll 2 degrees off: Auto drops the prior (two calibrations and a refit).
    for m in &mut data {
        m.roll_deg += 2.0;
    }
    let mut guess = truth.clone();
    guess.anchors_m[0] += Vector3::new(2.0, -1.5, 1.0);
    guess.length_offsets_m = [3.0, -2.0, 1.0, -4.0];
    let options = CalibrationOptions::new(noise);
    let prepared = PreparedCalibration::new(&guess, &data, &options);
    let robust = {
        let mut robust = options;
        robust.robust.encoder = RobustKernel::parse("huber").unwrap();
        robust
    };
    let variants = [
        options,
        CalibrationOptions {
            orientation_prior: OrientationPrior::On,
            ..options
        },
        CalibrationOptions {
            orientation_prior: OrientationPrior::Off,
            ..options
        },
        CalibrationOptions {
            orientation_prior: OrientationPrior::On,
            free_effects: EffectSet::NONE.with(EffectKind::Elastic),
            ..options
        },
        // Other kernels change the rigid stage: calibrated from the start.
        robust,
    ];
    for variant in &variants {
        let direct = calibrate(&guess, &data, variant).unwrap();
        let shared = prepared.calibrate(variant).unwrap();
        assert_eq!(
            fingerprint(&direct),
            fingerprint(&shared),
            "{:?} / {:?}",
            variant.orientation_prior,
            variant.free_effects
        );
    }
    let auto = prepared.calibrate(&options).unwrap();
    assert!(
        !auto.orientation_check.unwrap().prior_used,
        "the biased roll should fail the test"
    );
}

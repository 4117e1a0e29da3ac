//! `diagnose` in an open world: causes the catalogue does not hold. Each
//! case's data come from a truth off the nominal large robot (anchors within
//! +-0.3 m, offsets of metres) under the authors' noise, 35 poses, seeded
//! and printed. What must hold: a cause outside the catalogue is reported as
//! `unexplained` (or beside the causes that explain part of it), a fitted
//! value no real robot could have is called a stand-in and not named, and
//! an effect that does not predict held-out poses is taken out. The same
//! data with the hidden effect in the catalogue are named and explained, so
//! each test can tell the two apart.

#[path = "common/truth.rs"]
mod truth;

use sagcal::calib::CalibrationOptions;
use sagcal::diagnose::{diagnose, DiagnoseOptions, Diagnosis};
use sagcal::model::effect_kind::EffectKind;
use sagcal::model::effects::Effects;
use sagcal::model::measurement::PoseMeasurement;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::measure;
use sagcal::sim::effects::measure_with_effects;
use truth::truth_off_nominal;

const POSES: usize = 35;

/// A truth off the nominal large robot (the guess), changed by `change`,
/// measured at `POSES` poses with the authors' noise, `effects` acting (the
/// discretised simulator, 100 elements per cable) or none (the closed form).
fn case(seed: u64, change: impl Fn(&mut Robot), effects: &[&str]) -> (Robot, Vec<PoseMeasurement>, Robot) {
    let (nominal, mut truth, equilibria, mut rng) = truth_off_nominal("large", seed, POSES, change);
    let sigmas = NoisePreset::Authors.sigmas(truth.platform_weight_n);
    let measurements = if effects.is_empty() {
        measure(&truth, &equilibria, &sigmas, &mut rng)
    } else {
        let mut e = Effects::default();
        for spec in effects {
            e.apply_spec(spec).unwrap();
        }
        truth.effects = e;
        measure_with_effects(&truth, &e, &equilibria, &sigmas, 100, &mut rng).unwrap()
    };
    (truth, measurements, nominal)
}

/// Diagnose `measurements` with `candidates` (every effect but those left out).
fn run(
    label: &str,
    seed: u64,
    (truth, measurements, guess): &(Robot, Vec<PoseMeasurement>, Robot),
    left_out: &[EffectKind],
) -> Diagnosis {
    let sigmas = NoisePreset::Authors.sigmas(truth.platform_weight_n);
    let mut options = DiagnoseOptions::new(CalibrationOptions::new(sigmas));
    options.candidates.retain(|k| !left_out.contains(k));
    let d = diagnose(guess, measurements, Some(truth), &options, &mut |_, _, _| {}).unwrap();
    println!(
        "{label}, seed {seed}: verdict {} (selected {}, final model {}, explained {}); {}",
        d.verdict, d.selected, d.explanation.final_model, d.explanation.explained, d.reason
    );
    d
}

/// A platform 11 % heavier than the robot file says (an unmodelled payload)
/// was named `segments+loadcell`: a chain of 2.9 elements. The platform's
/// weight is now a hypothesis and is named, at its value; with it left out
/// of the catalogue the chain is a stand-in, never a cause: the verdict says
/// that something is left, or names the platform weight's exact equivalent
/// (the cables' weight and the load cell's gain, whose family of equal fits
/// the report prints).
#[test]
fn an_unmodelled_payload_is_not_named_as_a_chain_of_three_elements() {
    let seed = 31;
    let data = case(seed, |t| t.platform_weight_n *= 1.11, &[]);
    let named = run("payload +11 %", seed, &data, &[]);
    assert_eq!(named.verdict, "platform-weight");
    let scale = &named.effects[0].params[0];
    assert!((scale.value - 1.11).abs() < 4.0 * scale.sigma, "{scale:?}");
    let d = run(
        "payload +11 %, platform-weight left out",
        seed,
        &data,
        &[EffectKind::PlatformWeight],
    );
    if d.explanation.explained {
        // The exact equivalent of the platform's weight: the cables' weight
        // read through a load cell's gain, one family of equal fits that
        // holds a platform 11 % heavier with the cables and the gain as the
        // file says.
        assert_eq!(d.verdict, "loadcell+cable-weight");
        let platform_alone = d
            .equivalent_fits
            .iter()
            .find(|f| f.contains("cable weight x 1.0000"))
            .expect("the fit with the cables as the file says");
        let scale: f64 = platform_alone["the same fit: platform weight x ".len()..]
            .split(',')
            .next()
            .and_then(|v| v.trim().parse().ok())
            .unwrap();
        assert!((scale - 1.11).abs() < 0.01, "{platform_alone}");
    } else {
        assert!(d.verdict.ends_with("unexplained"), "{}", d.verdict);
    }
    assert!(
        !d.explanation.causes.iter().any(|c| c == "segments"),
        "{:?}",
        d.explanation.causes
    );
    if d.explanation.final_model.contains("segments") {
        let chain = d
            .explanation
            .stand_ins
            .iter()
            .find(|s| s.hypothesis == "segments")
            .unwrap();
        assert!(chain
            .sentence()
            .contains("stands in for something that changes the cables' sag"));
    }
}

/// Encoders creeping by 1 mm per row were named `encoder-scale+elastic`
/// although the held-out residual got worse. The drift is now a hypothesis
/// of the catalogue (`encoder-drift`) and is named at its value; left out of
/// the catalogue, those effects are taken out and the verdict is
/// `unexplained`.
#[test]
fn an_encoder_drift_is_named_or_unexplained_not_two_effects() {
    let seed = 32;
    let (truth, mut measurements, guess) = case(seed, |_| {}, &[]);
    for (row, m) in measurements.iter_mut().enumerate() {
        for l in &mut m.encoder_lengths_m {
            *l += 1e-3 * (row + 1) as f64;
        }
    }
    let data = (truth, measurements, guess);
    let named = run("encoder drift 1 mm per row", seed, &data, &[]);
    assert_eq!(named.verdict, "encoder-drift", "{}", named.reason);
    assert!(named.explanation.explained);
    for p in &named.effects[0].params {
        assert!((p.value - 1.0).abs() < 4.0 * p.sigma, "{p:?}");
    }
    let d = run(
        "encoder drift 1 mm per row, encoder-drift left out",
        seed,
        &data,
        &[EffectKind::EncoderDrift],
    );
    assert_eq!(d.verdict, "unexplained", "{}", d.reason);
    assert!(d.explanation.causes.is_empty());
    let failing: Vec<&str> = d
        .explanation
        .final_tests
        .iter()
        .filter(|t| !t.consistent)
        .map(|t| t.kind.as_str())
        .collect();
    assert!(failing.contains(&"catenary_length"), "{failing:?}");
    // Whatever the selection added, it did not predict held-out poses.
    for x in &d.not_predictive {
        assert!(
            x.cv_rms_with >= x.cv_rms_without || x.anchor_mse_with_m2 > x.anchor_mse_without_m2,
            "{x:?}"
        );
    }
    assert!(d.gain.residual_rms_after <= d.gain.residual_rms_before);
    // The rows are the order the poses were taken: the drift shows against the row.
    let strongest = &d.drivers[0];
    assert_eq!(
        (strongest.residual.as_str(), strongest.driver.as_str()),
        ("encoder", "row (order taken)")
    );
    assert!(strongest.t_statistic.abs() > 10.0, "{strongest:?}");
    assert!(d
        .explanation
        .structure_left
        .iter()
        .any(|s| s.starts_with("encoder vs row")));
    // The term that explains it, by the score test: the encoders against the
    // row, proposed or named alike (the localiser's z drifting the other
    // way is the same disagreement), within 5 sigma of 1 mm per row.
    let e = &d.explanation;
    let drift = e
        .missing_terms
        .iter()
        .find(|t| t.residual == "encoder" && t.driver == "row (order taken)")
        .expect("the encoder drift is a missing term");
    assert!((drift.coefficient - 1e-3).abs() < 5.0 * drift.sigma + 1e-4, "{drift:?}");
    let first = &e.proposed_terms[0];
    assert!(
        (first.residual.as_str(), first.driver.as_str()) == ("encoder", "row (order taken)")
            || first.alike.iter().any(|a| a == "encoder vs row (order taken)"),
        "{first:?}"
    );
    // Taken out of time order (a RecurDyn log), the row is no driver.
    let (truth, measurements, guess) = case(seed, |_| {}, &[]);
    let sigmas = NoisePreset::Authors.sigmas(truth.platform_weight_n);
    let mut options = DiagnoseOptions::new(CalibrationOptions::new(sigmas));
    options.rows_in_time_order = false;
    let d = diagnose(&guess, &measurements, Some(&truth), &options, &mut |_, _, _| {}).unwrap();
    assert!(!d
        .drivers
        .iter()
        .any(|t| t.driver.starts_with("row") || t.driver.starts_with("direction")));
}

/// Leave one out: an effect of the catalogue hidden in the data (`spec`,
/// seed `seed`) and removed from the diagnosis' catalogue (`left_out`) must
/// not be replaced by a wrong cause; with it in the catalogue it is named
/// (`kind`) and the data are explained.
fn left_out_is_unexplained_not_a_wrong_cause(seed: u64, spec: &str, kind: EffectKind, left_out: &[EffectKind]) {
    let data = case(seed, |_| {}, &[spec]);
    let full = run(&format!("{spec}, full catalogue"), seed, &data, &[]);
    assert_eq!(full.verdict, kind.name(), "{}", full.reason);
    assert!(full.explanation.explained);
    let blind = run(&format!("{spec}, {left_out:?} left out"), seed, &data, left_out);
    assert!(
        blind.explanation.causes.is_empty() && blind.verdict == "unexplained",
        "{spec}: {} ({})",
        blind.verdict,
        blind.reason
    );
    // The load cell's gain error shows as a term: its reading grows by
    // 0.04 N per newton of the tension it reads.
    if kind == EffectKind::LoadCell {
        let gain = blind
            .explanation
            .missing_terms
            .iter()
            .find(|t| t.residual == "load_cell" && t.driver == "tension at the pulley (N)")
            .expect("the gain is a missing term");
        println!("{}", gain.formula());
        assert!((gain.coefficient - 0.04).abs() < 5.0 * gain.sigma, "{gain:?}");
    }
}

#[test]
fn a_hidden_load_cell_left_out_of_the_catalogue_is_unexplained_not_a_wrong_cause() {
    left_out_is_unexplained_not_a_wrong_cause(
        33,
        "loadcell:gain=1.04,bias_n=-30",
        EffectKind::LoadCell,
        &[EffectKind::LoadCell],
    );
}

#[test]
fn a_hidden_elastic_cable_left_out_of_the_catalogue_is_unexplained_not_a_wrong_cause() {
    left_out_is_unexplained_not_a_wrong_cause(34, "elastic:ea_n=3e6", EffectKind::Elastic, &[EffectKind::Elastic]);
}

#[test]
fn a_hidden_drum_gain_left_out_of_the_catalogue_is_unexplained_not_a_wrong_cause() {
    // The per-drum gains contain the common one: both go.
    left_out_is_unexplained_not_a_wrong_cause(
        35,
        "encoder-scale:gain=1.002",
        EffectKind::CommonGain,
        &[EffectKind::CommonGain, EffectKind::EncoderScale],
    );
}

/// The structure test of the final model states its false-alarm rate: on
/// data the baseline describes (the closed form, truth off the nominal
/// robot, authors' noise), with the rate raised to 0.2 so that it can be
/// measured, a term is found missing in at most 20 % of the cases (the
/// Bonferroni limit makes it fewer). 40 cases: more than 14 would have
/// probability below 0.01 at the stated rate. (The measured tension, which
/// holds the load cell's own noise, was once a driver; it failed here.)
#[test]
fn the_structure_test_keeps_its_false_alarm_rate() {
    let cases = 40;
    let mut alarms = Vec::new();
    for seed in 0..cases {
        let seed = 4000 + seed;
        let (truth, measurements, guess) = case(seed, |_| {}, &[]);
        let sigmas = NoisePreset::Authors.sigmas(truth.platform_weight_n);
        let mut options = DiagnoseOptions::new(CalibrationOptions::new(sigmas));
        options.candidates.clear();
        options.orientation_hypothesis = false;
        options.folds = 2;
        options.false_alarm = 0.2;
        let d = diagnose(&guess, &measurements, Some(&truth), &options, &mut |_, _, _| {}).unwrap();
        if let Some(term) = d.explanation.missing_terms.first() {
            alarms.push(format!("seed {seed}: {}", term.formula()));
        }
    }
    println!("{} of {cases} alarms: {alarms:#?}", alarms.len());
    assert!(alarms.len() <= 14, "{alarms:#?}");
}

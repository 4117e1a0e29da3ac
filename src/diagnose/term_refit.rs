//! The proposed missing terms as empirical corrections of the readings, and
//! a model refitted with them.
//!
//! A term `reading - model = c (x - mean x)` ([`super::missing_terms`]) is
//! added to a model by correcting each reading it touches by `-c (x - mean x)`
//! (every factor's residual is prediction minus reading; a localiser
//! orientation `R` becomes `R Exp(-c (x - mean x) e_a)`, the rotation error's
//! axis `a`), with `x` the driver's value in the baseline's samples, held
//! fixed: the term is a regressor of the data, not of the fit. The model's
//! own parameters and the coefficients `c` are then fitted together by
//! variable projection: each round re-fits the model to the corrected
//! readings and takes the Gauss-Newton step of the coefficients with the
//! model's parameters profiled out, `dc = M^-1 b` of Rao's score system at
//! that fit ([`crate::solver::ScoreSystem`]), until the step is below
//! [`STEP_TOLERANCE_SIGMAS`] of each coefficient's sigma.
//!
//! The chi-square of a model with the terms is what the causes of a model
//! that does not explain the data are judged by: the likelihood ratio of the
//! causes given the terms is the baseline's chi-square with the terms less
//! the model's with the terms, both refitted, not the first-order gains of
//! the terms at each fit (which, far from the data, are not a refit's).

use nalgebra::{UnitQuaternion, Vector3};

use super::drivers::PoseSample;
use super::fitted_graph::rebuild;
use super::missing_terms::{direction_of, factor_of, factor_poses};
use super::residual_tests::total_chi_square;
use crate::calib::{refine_with_effects, CalibrationGraph, CalibrationOptions, CalibrationResult};
use crate::error::{Error, Result};
use crate::model::effects::Effects;
use crate::model::measurement::{PoseMeasurement, Sensor};
use crate::solver::{score_system, Direction};

/// The refits stop when every coefficient's last step is below this many of its sigmas.
pub const STEP_TOLERANCE_SIGMAS: f64 = 1e-3;

/// The most refits of the model (a step that does not shrink by then leaves the fit unconverged).
pub const MOST_REFITS: usize = 12;

/// A model fitted with the proposed terms as corrections of its readings.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FitWithTerms {
    /// Its chi-square over all factors (to second order in the last step).
    pub chi_square: f64,
    /// The terms' coefficients, in the readings' units per unit of their drivers.
    pub coefficients: Vec<f64>,
    /// Whether the last step was below [`STEP_TOLERANCE_SIGMAS`].
    pub converged: bool,
}

/// A term's direction over the graph's factors, with the pose and the
/// sensor of each of its rows.
struct TermRows {
    /// The whitened direction (the centred driver over each row's sigma).
    direction: Direction,
    /// Per factor, its pose (index into the poses used).
    poses: Vec<Option<usize>>,
}

/// The model of `options` fitted from `start` (its fit, with the robot's
/// known `[effects]` in `known_effects`) to `measurements` (every pose the
/// calibration was given; its excluded poses stay out) with the terms `keys`
/// (`(reading, driver)` of [`super::missing_terms`]) as corrections, their
/// drivers from `samples` (the baseline's, one per pose used).
pub(super) fn fit_with_terms(
    (start, options, known_effects): (&CalibrationResult, &CalibrationOptions, &Effects),
    measurements: &[PoseMeasurement],
    samples: &[PoseSample],
    keys: &[(&'static str, &'static str)],
) -> Result<FitWithTerms> {
    let used_index: Vec<usize> = (0..measurements.len())
        .filter(|k| !start.excluded_poses.contains(k))
        .collect();
    let used: Vec<PoseMeasurement> = used_index.iter().map(|&k| measurements[k]).collect();
    let graph = rebuild(start, &used, options);
    let terms: Vec<TermRows> = keys
        .iter()
        .map(|(residual, driver)| {
            let (kind, sensors) = factor_of(residual);
            TermRows {
                direction: direction_of(&graph, &used, samples, residual, driver).0,
                poses: factor_poses(&graph, &used, kind, &sensors),
            }
        })
        .collect();
    let directions: Vec<Direction> = terms.iter().map(|t| t.direction.clone()).collect();
    let step_at = |graph: &CalibrationGraph| -> Result<(Vec<f64>, f64, f64)> {
        let system = score_system(&graph.graph, &directions)?;
        let (step, gain) = system
            .joint_fit()
            .ok_or_else(|| Error::InvalidInput("the proposed terms' information is singular".into()))?;
        let largest = (0..step.len())
            .map(|j| step[j].abs() * system.information[(j, j)].sqrt())
            .fold(0.0, f64::max);
        Ok((step.iter().copied().collect(), gain, largest))
    };
    let (mut coefficients, mut gain, mut largest) = step_at(&graph)?;
    let mut chi_square = total_chi_square(&graph.graph) - gain;
    let mut current = start.clone();
    for _ in 0..MOST_REFITS {
        if largest < STEP_TOLERANCE_SIGMAS {
            break;
        }
        let mut corrected = measurements.to_vec();
        for (term, c) in terms.iter().zip(&coefficients) {
            correct(&mut corrected, &used_index, &graph, term, *c);
        }
        current.robot.effects = *known_effects;
        current = refine_with_effects(&current, &corrected, options)?;
        let corrected_used: Vec<PoseMeasurement> = used_index.iter().map(|&k| corrected[k]).collect();
        let fitted = rebuild(&current, &corrected_used, options);
        let step;
        (step, gain, largest) = step_at(&fitted)?;
        chi_square = total_chi_square(&fitted.graph) - gain;
        for (c, dc) in coefficients.iter_mut().zip(step) {
            *c += dc;
        }
    }
    Ok(FitWithTerms {
        chi_square,
        coefficients,
        converged: largest < STEP_TOLERANCE_SIGMAS,
    })
}

/// Correct `measurements` by the term `term` with coefficient `c` (module
/// docs): each of its rows' readings by `-c (x - mean x)`, recovered from
/// the whitened direction and the row's sigma.
fn correct(
    measurements: &mut [PoseMeasurement],
    used_index: &[usize],
    graph: &CalibrationGraph,
    term: &TermRows,
    c: f64,
) {
    for ((weights, pose), factor) in term.direction.iter().zip(&term.poses).zip(&graph.graph.factors) {
        let (Some(weights), Some(pose)) = (weights, pose) else {
            continue;
        };
        let rows = factor.residual_dim();
        let m = &mut measurements[used_index[*pose]];
        for (row, (w, sigma)) in weights.iter().zip(factor.sigmas()).enumerate() {
            if *w == 0.0 {
                continue;
            }
            let amount = c * w * sigma;
            match sensor_of(factor.kind(), row, rows) {
                Some(Sensor::Encoder(i)) => m.encoder_lengths_m[i] -= amount,
                Some(Sensor::LoadCell) => m.reference_tension_n -= amount,
                Some(Sensor::Position(a)) => m.position_m[a] -= amount,
                Some(Sensor::Orientation(a)) => turn(m, a, -amount),
                None => {}
            }
        }
    }
}

/// The reading of row `row` of a factor of `kind` with `rows` rows.
fn sensor_of(kind: &str, row: usize, rows: usize) -> Option<Sensor> {
    match kind {
        "catenary_length" => Some(Sensor::Encoder(row)),
        "reference_tension" => Some(Sensor::LoadCell),
        // Orientation rows first, where the prior has them; position last.
        "pose_prior" if rows == 6 && row < 3 => Some(Sensor::Orientation(row)),
        "pose_prior" => Some(Sensor::Position(row + 3 - rows)),
        _ => None,
    }
}

/// The localiser's orientation `R` of `m` turned to `R Exp(angle e_axis)`.
fn turn(m: &mut PoseMeasurement, axis: usize, angle_rad: f64) {
    let mut rotation_vector = Vector3::zeros();
    rotation_vector[axis] = angle_rad;
    let turned = m.localiser_pose().rotation * UnitQuaternion::from_scaled_axis(rotation_vector);
    let (roll, pitch, yaw) = turned.euler_angles();
    m.roll_deg = roll.to_degrees();
    m.pitch_deg = pitch.to_degrees();
    m.yaw_deg = yaw.to_degrees();
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;

    use super::*;
    use crate::calib::{OrientationPrior, PreparedCalibration};
    use crate::diagnose::drivers::{samples, DRIVERS};
    use crate::diagnose::missing_terms::CONSTANT_DRIVER;
    use crate::model::effect_kind::{EffectKind, EffectSet};
    use crate::model::sensors::NoisePreset;
    use crate::model::statics::{solve_level, StaticsOptions};
    use crate::model::Robot;

    /// Closed-form data of the large robot under the paper's noise at 20
    /// level equilibria on a grid over its workspace (the statics of
    /// `crate::model::statics`), changed by `change`.
    fn data(seed: u64, change: impl Fn(&mut PoseMeasurement, &[f64; 4])) -> (Robot, Vec<PoseMeasurement>) {
        let robot = Robot::builtin("large").unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
        let normal = |sigma: f64, rng: &mut rand_chacha::ChaCha8Rng| rng.sample::<f64, _>(StandardNormal) * sigma;
        let mut measured = Vec::new();
        for (k, (x, y)) in [-25.0, -12.0, 0.0, 12.0, 25.0]
            .into_iter()
            .flat_map(|x| [-24.0, -8.0, 8.0, 24.0].map(|y| (x, y)))
            .enumerate()
        {
            let z = 5.0 + 6.0 * (k % 4) as f64;
            let eq = solve_level(&robot, Vector3::new(x, y, z), &StaticsOptions::default()).unwrap();
            let rotation = eq.pose.rotation
                * UnitQuaternion::from_scaled_axis(Vector3::from_fn(|_, _| {
                    normal(noise.orientation_sigma_rad, &mut rng)
                }));
            let (roll, pitch, yaw) = rotation.euler_angles();
            let mut m = PoseMeasurement {
                line: 0,
                position_m: (eq.pose.position_m + Vector3::from_fn(|_, _| normal(noise.position_sigma_m, &mut rng)))
                    .into(),
                roll_deg: roll.to_degrees(),
                pitch_deg: pitch.to_degrees(),
                yaw_deg: yaw.to_degrees(),
                encoder_lengths_m: std::array::from_fn(|i| {
                    eq.cable_lengths_m[i] + robot.length_offsets_m[i] + normal(noise.encoder_sigma_m, &mut rng)
                }),
                reference_tension_n: eq.tensions[robot.reference_cable].magnitude_n()
                    + normal(noise.load_cell_sigma_n, &mut rng),
                excluded: Default::default(),
                order: None,
            };
            change(&mut m, &eq.cable_lengths_m);
            measured.push(m);
        }
        (robot, measured)
    }

    /// The baseline fit of `diagnose` (the orientation as a prior), its
    /// options as used and its samples.
    fn baseline(
        robot: &Robot,
        measured: &[PoseMeasurement],
    ) -> (CalibrationResult, CalibrationOptions, Vec<PoseSample>) {
        let mut options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
        options.orientation_prior = OrientationPrior::On;
        let result = PreparedCalibration::new(robot, measured, &options)
            .calibrate(&options)
            .unwrap();
        let options = options.as_used_by(&result);
        let used: Vec<PoseMeasurement> = (0..measured.len())
            .filter(|k| !result.excluded_poses.contains(k))
            .map(|k| measured[k])
            .collect();
        let samples = samples(&result, &used, &options).unwrap();
        (result, options, samples)
    }

    fn chi_square_of(result: &CalibrationResult, measured: &[PoseMeasurement], options: &CalibrationOptions) -> f64 {
        let used: Vec<PoseMeasurement> = (0..measured.len())
            .filter(|k| !result.excluded_poses.contains(k))
            .map(|k| measured[k])
            .collect();
        total_chi_square(&rebuild(result, &used, options).graph)
    }

    #[test]
    fn a_constant_orientation_term_is_a_turned_localiser() {
        // Every orientation read turned by 0.05 rad about the platform's x
        // (`R Rx(d)`: roll + d in `Rz Ry Rx`). With the constant term the
        // baseline fits as well as on the unturned readings.
        let turn = 0.05f64;
        let (robot, clean) = data(3, |_, _| {});
        let (_, turned) = data(3, |m, _| m.roll_deg += turn.to_degrees());
        let (fit, options, samples) = baseline(&robot, &clean);
        let clean_chi_square = chi_square_of(&fit, &clean, &options);
        let (fit, options, samples_turned) = baseline(&robot, &turned);
        let turned_chi_square = chi_square_of(&fit, &turned, &options);
        assert_eq!(samples.len(), samples_turned.len());
        let with_term = fit_with_terms(
            (&fit, &options, &robot.effects),
            &turned,
            &samples_turned,
            &[("orientation_x", CONSTANT_DRIVER)],
        )
        .unwrap();
        eprintln!(
            "turned: baseline {turned_chi_square:.1}, with the term {:.1}, unturned {clean_chi_square:.1}, c {:?}",
            with_term.chi_square, with_term.coefficients
        );
        assert!(with_term.converged);
        assert!(
            turned_chi_square > clean_chi_square + 200.0,
            "{turned_chi_square} vs {clean_chi_square}"
        );
        // The constant takes one degree of freedom of the noise besides the turn.
        assert!(
            (with_term.chi_square - clean_chi_square).abs() < 10.0,
            "{} vs {clean_chi_square}",
            with_term.chi_square
        );
        // reading - model = +turn about x.
        let c = with_term.coefficients[0];
        assert!((c - turn).abs() < 0.01, "coefficient {c}");
    }

    #[test]
    fn an_encoder_term_in_the_cable_length_is_a_common_gain() {
        // Encoders that read 1 % long: a term in the cable length fitted with
        // the model re-fitted matches the common-gain effect's fit.
        let (robot, measured) = data(5, |m, lengths| {
            for (reading, length) in m.encoder_lengths_m.iter_mut().zip(lengths) {
                *reading += 0.01 * length;
            }
        });
        let (fit, options, samples) = baseline(&robot, &measured);
        let base_chi_square = chi_square_of(&fit, &measured, &options);
        let with_term = fit_with_terms(
            (&fit, &options, &robot.effects),
            &measured,
            &samples,
            &[("encoder", DRIVERS[2])],
        )
        .unwrap();
        let gain_options = CalibrationOptions {
            free_effects: EffectSet::of(EffectKind::CommonGain),
            ..options
        };
        let gain = refine_with_effects(&fit, &measured, &gain_options).unwrap();
        let gain_chi_square = chi_square_of(&gain, &measured, &gain_options);
        eprintln!(
            "gain: baseline {base_chi_square:.1}, with the term {:.1}, with the gain {gain_chi_square:.1}, c {:?}",
            with_term.chi_square, with_term.coefficients
        );
        assert!(with_term.converged);
        assert!(
            base_chi_square > gain_chi_square + 100.0,
            "{base_chi_square} vs {gain_chi_square}"
        );
        let gap = (with_term.chi_square - gain_chi_square).abs();
        assert!(
            gap < 0.01 * (base_chi_square - gain_chi_square),
            "with the term {} against the gain's {gain_chi_square} (baseline {base_chi_square})",
            with_term.chi_square
        );
        assert!(
            (with_term.coefficients[0] - 0.01).abs() < 1e-3,
            "{:?}",
            with_term.coefficients
        );
    }
}

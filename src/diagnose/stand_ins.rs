//! Step 4a: stand-ins. A selected hypothesis whose estimate no real robot
//! could have (beyond its plausible limit, [`crate::model::effect_limits`])
//! fits the data only as a proxy for something else: a chain of 2.9 elements
//! that makes the lengths right is not a cable, it says that something
//! changes the sag. Freeing every pose's orientation is a stand-in too: it
//! says that the localiser's orientations disagree with the statics, not why.
//! The verdict names neither as a cause.
//!
//! An effect whose own sensor (the readings it changes directly: the
//! encoders for the cable and drum effects, the load cell for its bias and
//! gain, the localiser for the mount and the centre of mass's tilt) still
//! fails its chi-square test in the final model is a stand-in as well: it
//! lowers that sensor's misfit without explaining it, so it stands in for
//! part of something the catalogue lacks.
//!
//! Two of the platform's weight, the cables' weight and the load cell's gain
//! fitted together are judged as one: every `(s p, s c, g / s)` predicts
//! the same readings ([`super::candidates::WEIGHT_SCALING`]), so neither
//! value means anything alone, only the family does. Their values are a
//! stand-in only when no member of the family is within every limit
//! ([`weight_family_plausible`]); a family with a plausible member is that
//! member's fit (the report prints it beside the verdict).
//!
//! The test: an estimate is beyond its limit when its magnitude (the norm of
//! the limited parameters, in the effect variable's units) exceeds the limit
//! by more than 3 standard deviations of that magnitude (its covariance
//! projected on the estimate's direction): a one-sided test at p = 0.00135
//! that the data put the effect outside what a real robot can have.

use serde::Serialize;

use super::candidates::WEIGHT_SCALING;
use super::residual_tests::FactorTest;
use crate::calib::EffectEstimate;
use crate::model::effect_kind::EffectKind;
use crate::model::effect_limits::{plausible_limits, PlausibleLimit};
use crate::model::robot::Robot;

/// How many standard deviations beyond its limit an estimate must be to be a stand-in.
pub const STAND_IN_SIGMAS: f64 = 3.0;

/// A selected hypothesis that fits the data as a proxy, not as a cause.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StandIn {
    /// The hypothesis (`segments`, ..., or `orientation`).
    pub hypothesis: String,
    /// What was estimated, in the robot's words ("a chain of 2.9 elements").
    pub estimate: String,
    /// The plausible limit it is beyond ("at least 10 elements"), empty for `orientation`.
    pub limit: String,
    /// Why no real robot goes beyond the limit, empty for `orientation`.
    pub why: String,
    /// What it stands in for ("something changes the cables' sag or length").
    pub stands_for: String,
}

impl StandIn {
    /// The report's sentence for it.
    pub fn sentence(&self) -> String {
        if self.limit.is_empty() {
            return format!("{}: {}: {}", self.hypothesis, self.estimate, self.stands_for);
        }
        format!(
            "{}: {}, which no real robot has ({}: {}); it stands in for {}",
            self.hypothesis, self.estimate, self.limit, self.why, self.stands_for
        )
    }
}

/// The stand-in that freed orientations are.
pub(super) fn orientation_stand_in() -> StandIn {
    StandIn {
        hypothesis: "orientation".into(),
        estimate: "every pose's orientation is freed from the localiser's reading".into(),
        limit: String::new(),
        why: String::new(),
        stands_for: "the localiser's orientations disagree with the statics, and no effect tested says why \
                     (something the catalogue lacks tilts the platform or turns the localiser)"
            .into(),
    }
}

/// The stand-in `estimate` is, if it is beyond a plausible limit for `robot` (module docs).
pub(super) fn stand_in(estimate: &EffectEstimate, robot: &Robot, mean_reference_tension_n: f64) -> Option<StandIn> {
    let kind = estimate.effect;
    plausible_limits(kind, robot, mean_reference_tension_n)
        .into_iter()
        .find(|limit| beyond(estimate, limit))
        .map(|limit| StandIn {
            hypothesis: kind.name().into(),
            estimate: describe(estimate, &limit),
            limit: limit.limit.clone(),
            why: limit.why.clone(),
            stands_for: stands_for(kind).into(),
        })
}

/// Whether `estimates` hold two of [`WEIGHT_SCALING`] whose family of equal
/// fits (module docs) has a member within every plausible limit of the
/// three: the platform's and the cables' weight scales `s p` and `s c`, and
/// the load cell's gain `g / s` beside its bias (a bias does not scale).
/// The family is searched over `s` from 1/4 to 4 on a grid of ratio 1.0007.
pub(super) fn weight_family_plausible(
    estimates: &[EffectEstimate],
    robot: &Robot,
    mean_reference_tension_n: f64,
) -> bool {
    let find = |kind: EffectKind| estimates.iter().find(|e| e.effect == kind);
    if WEIGHT_SCALING.iter().filter(|k| find(**k).is_some()).count() < 2 {
        return false;
    }
    // Each member as an estimate, scaled by `s` (a member the model lacks: 1 exactly).
    let member = |kind: EffectKind, s: f64| -> EffectEstimate {
        let names: Vec<String> = kind.parameter_names().iter().map(|n| n.to_string()).collect();
        let n = names.len();
        let (mut values, mut sigmas, mut covariance) = match find(kind) {
            Some(e) => (e.values.clone(), e.sigmas.clone(), e.covariance.clone()),
            None => (vec![0.0; n], vec![0.0; n], vec![vec![0.0; n]; n]),
        };
        // The scale is the last parameter (the load cell's gain after its bias).
        let scale = n - 1;
        if find(kind).is_none() {
            values[scale] = 1.0;
        }
        let factor = if kind == EffectKind::LoadCell { 1.0 / s } else { s };
        values[scale] *= factor;
        sigmas[scale] *= factor;
        for row in covariance.iter_mut() {
            row[scale] *= factor;
        }
        for value in covariance[scale].iter_mut() {
            *value *= factor;
        }
        EffectEstimate {
            effect: kind,
            names,
            covariance,
            values,
            sigmas,
        }
    };
    let steps = 4000;
    (0..=steps)
        .map(|k| 0.25 * 16f64.powf(k as f64 / steps as f64))
        .any(|s| {
            WEIGHT_SCALING
                .iter()
                .all(|kind| stand_in(&member(*kind, s), robot, mean_reference_tension_n).is_none())
        })
}

/// The measurement factor kind of the sensor `kind` changes directly
/// (`catenary_length`, `reference_tension` or `pose_prior`).
pub(super) fn own_sensor(kind: EffectKind) -> &'static str {
    match kind {
        EffectKind::Elastic
        | EffectKind::Pulley
        | EffectKind::EncoderScale
        | EffectKind::CommonGain
        | EffectKind::Segments => "catenary_length",
        EffectKind::LoadCell => "reference_tension",
        EffectKind::Com | EffectKind::LocaliserMount | EffectKind::Attachments => "pose_prior",
        // A heavier platform pulls every cable harder: the sag, and so the
        // lengths, change with it; heavier cables sag more.
        EffectKind::PlatformWeight | EffectKind::CableWeight => "catenary_length",
        EffectKind::EncoderDrift | EffectKind::EncoderBacklash => "catenary_length",
        EffectKind::LoadCellDrift | EffectKind::LoadCellFriction => "reference_tension",
    }
}

/// The stand-in an effect is when its own sensor still fails its test in
/// the final model (module docs).
pub(super) fn partial_stand_in(estimate: &EffectEstimate, sensor_test: &FactorTest) -> StandIn {
    let kind = estimate.effect;
    StandIn {
        hypothesis: kind.name().into(),
        estimate: estimate
            .names
            .iter()
            .zip(&estimate.values)
            .zip(&estimate.sigmas)
            .map(|((n, v), s)| format!("{n} {v:.5} +- {s:.1e}"))
            .collect::<Vec<_>>()
            .join(", "),
        limit: String::new(),
        why: String::new(),
        stands_for: format!(
            "it lowers the misfit of its own sensor but leaves it inconsistent ({} chi-square {:.1} above its limit {:.1}): \
             it stands in for part of something the catalogue lacks",
            sensor_test.kind, sensor_test.chi_square, sensor_test.limit
        ),
    }
}

/// A parameter in the effect variable's units (gains as errors).
fn variable_value(kind: EffectKind, index: usize, value: f64) -> f64 {
    if kind.is_scale(index) {
        value - 1.0
    } else {
        value
    }
}

/// The magnitude of the limited parameters and its standard deviation.
fn magnitude(estimate: &EffectEstimate, limit: &PlausibleLimit) -> (f64, f64) {
    let theta: Vec<f64> = limit
        .parameters
        .iter()
        .map(|&i| variable_value(estimate.effect, i, estimate.values[i]))
        .collect();
    let norm = theta.iter().map(|t| t * t).sum::<f64>().sqrt();
    if norm == 0.0 {
        return (0.0, f64::NAN);
    }
    let mut variance = 0.0;
    for (a, &i) in limit.parameters.iter().enumerate() {
        for (b, &j) in limit.parameters.iter().enumerate() {
            variance += theta[a] * theta[b] * estimate.covariance[i][j];
        }
    }
    // A NaN covariance (an unidentified estimate) gives a NaN sigma: never beyond.
    let sigma = if variance.is_nan() {
        f64::NAN
    } else {
        variance.max(0.0).sqrt() / norm
    };
    (norm, sigma)
}

/// Whether the estimate is beyond `limit` by more than [`STAND_IN_SIGMAS`].
fn beyond(estimate: &EffectEstimate, limit: &PlausibleLimit) -> bool {
    let (norm, sigma) = magnitude(estimate, limit);
    sigma.is_finite() && norm - STAND_IN_SIGMAS * sigma > limit.largest
}

/// The estimate in the robot's words, for the parameters of `limit`.
fn describe(estimate: &EffectEstimate, limit: &PlausibleLimit) -> String {
    let (norm, sigma) = magnitude(estimate, limit);
    let first = limit.parameters[0];
    let (value, value_sigma) = (estimate.values[first], estimate.sigmas[first]);
    match estimate.effect {
        EffectKind::Elastic => format!(
            "cables of EA {:.3e} N (compliance {value:.4} +- {value_sigma:.1e} per MN)",
            1e6 / value
        ),
        EffectKind::Pulley => format!("a pulley of radius {value:.3} +- {value_sigma:.3} m"),
        EffectKind::EncoderScale => format!("drum {} read with a gain of {value:.5} +- {value_sigma:.1e}", first + 1),
        EffectKind::CommonGain => format!("every drum read with a gain of {value:.5} +- {value_sigma:.1e}"),
        EffectKind::LoadCell if first == 0 => format!("a load cell off by {value:.2} +- {value_sigma:.2} N"),
        EffectKind::LoadCell => format!("a load cell with a gain of {value:.4} +- {value_sigma:.1e}"),
        EffectKind::Com => format!(
            "a centre-of-mass shift of {:.1} +- {:.1} cm",
            norm * 100.0,
            sigma * 100.0
        ),
        EffectKind::Segments => format!(
            "cables as chains of {:.1} elements (1/n^2 = {value:.4} +- {value_sigma:.1e})",
            1.0 / value.sqrt()
        ),
        EffectKind::LocaliserMount => format!("a localiser turned by {norm:.2} +- {sigma:.2} deg"),
        EffectKind::PlatformWeight => {
            format!("a platform {value:.3} +- {value_sigma:.3} times as heavy as its file says")
        }
        EffectKind::CableWeight => {
            format!("cables {value:.3} +- {value_sigma:.3} times as heavy per metre as the file says")
        }
        EffectKind::EncoderDrift => {
            format!("drum {} creeping {value:.3} +- {value_sigma:.3} mm per row", first + 1)
        }
        EffectKind::EncoderBacklash => {
            format!(
                "drum {} with a backlash of {value:.2} +- {value_sigma:.2} mm",
                first + 1
            )
        }
        EffectKind::LoadCellDrift => format!("a load cell creeping {value:.3} +- {value_sigma:.3} N per row"),
        EffectKind::LoadCellFriction => format!("a pulley friction mu theta of {value:.4} +- {value_sigma:.1e}"),
        EffectKind::Attachments => format!(
            "cable {}'s attachment moved by {:.1} +- {:.1} cm",
            first / 2 + 1,
            norm * 100.0,
            sigma * 100.0
        ),
    }
}

/// What an estimate beyond its limit stands in for.
fn stands_for(kind: EffectKind) -> &'static str {
    match kind {
        EffectKind::Elastic => "something that lengthens the cables with their tension",
        EffectKind::Pulley => "something that changes the cable lengths with the cables' direction at the anchors",
        EffectKind::EncoderScale | EffectKind::CommonGain => {
            "something that changes the encoder readings in proportion to the cable lengths"
        }
        EffectKind::LoadCell => {
            "something that changes the tension the load cell sees (the platform's or the cables' weight, friction)"
        }
        EffectKind::Com => "something that tilts the platform or moves its load between the cables",
        EffectKind::Segments => "something that changes the cables' sag or length",
        EffectKind::LocaliserMount => "something that turns the localiser's orientations",
        EffectKind::PlatformWeight => {
            "something that changes every tension in proportion (a load cell's gain, the cables' weight)"
        }
        EffectKind::CableWeight => "something that changes the cables' sag",
        EffectKind::EncoderDrift => "something that moves the encoder readings over time",
        EffectKind::EncoderBacklash => "something that moves the encoder readings with the direction of motion",
        EffectKind::LoadCellDrift => "something that moves the load cell's reading over time",
        EffectKind::LoadCellFriction => {
            "something that changes the tension the load cell sees with the direction of motion"
        }
        EffectKind::Attachments => "something that moves the cables' ends or the platform's balance",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(effect: EffectKind, values: Vec<f64>, sigma: f64) -> EffectEstimate {
        let k = values.len();
        EffectEstimate {
            effect,
            names: effect.parameter_names().iter().map(|s| s.to_string()).collect(),
            values,
            sigmas: vec![sigma; k],
            covariance: (0..k)
                .map(|r| (0..k).map(|c| if r == c { sigma * sigma } else { 0.0 }).collect())
                .collect(),
        }
    }

    #[test]
    fn two_weight_scalings_are_judged_by_their_family() {
        let robot = Robot::builtin("large").unwrap();
        let pair = |gain: f64, platform: f64| {
            vec![
                estimate(EffectKind::LoadCell, vec![-4.0, gain], 5e-3),
                estimate(EffectKind::PlatformWeight, vec![platform], 1e-3),
            ]
        };
        // A gain of 1.163 is beyond 10 % alone, but with a platform x 0.865 it
        // is cables x 1.157 read by a gain of 1.005 (s = 1.157).
        let fitted = pair(1.163, 0.865);
        assert!(stand_in(&fitted[0], &robot, 500.0).is_some());
        assert!(weight_family_plausible(&fitted, &robot, 500.0));
        // Gain 2 with a platform x 0.3: the platform needs s >= 1.67, the
        // cables s <= 1.5: no member of the family is plausible.
        assert!(!weight_family_plausible(&pair(2.0, 0.3), &robot, 500.0));
        // A bias beyond its limit does not scale away.
        let mut biased = pair(1.163, 0.865);
        biased[0].values[0] = 0.5 * 500.0;
        assert!(!weight_family_plausible(&biased, &robot, 500.0));
        // One scaling alone is judged by its own value.
        assert!(!weight_family_plausible(&fitted[..1], &robot, 500.0));
    }

    #[test]
    fn a_chain_of_three_elements_is_a_stand_in_and_one_of_forty_is_not() {
        let robot = Robot::builtin("large").unwrap();
        let coarse = stand_in(
            &estimate(EffectKind::Segments, vec![1.0 / 2.9f64.powi(2)], 1.6e-3),
            &robot,
            500.0,
        )
        .expect("2.9 elements is no cable");
        assert!(
            coarse.estimate.contains("chains of 2.9 elements"),
            "{}",
            coarse.estimate
        );
        assert!(coarse
            .sentence()
            .contains("stands in for something that changes the cables' sag"));
        assert!(stand_in(&estimate(EffectKind::Segments, vec![1.0 / 1600.0], 1e-4), &robot, 500.0).is_none());
        // 1/n^2 = 0.0105 +- 0.001: beyond 0.01, but not by 3 sigma.
        assert!(stand_in(&estimate(EffectKind::Segments, vec![0.0105], 1e-3), &robot, 500.0).is_none());
    }

    #[test]
    fn gains_are_tested_as_errors_and_a_shift_by_its_length() {
        let robot = Robot::builtin("large").unwrap();
        let gains = |g: f64| estimate(EffectKind::EncoderScale, vec![1.0, 1.0, g, 1.0], 1e-4);
        assert!(stand_in(&gains(1.003), &robot, 500.0).is_none());
        let drum = stand_in(&gains(0.93), &robot, 500.0).expect("a 7 % drum error");
        assert!(
            drum.estimate.starts_with("drum 3 read with a gain of 0.93000"),
            "{}",
            drum.estimate
        );
        // A 40 cm shift (0.3 m, 0.265 m) is off the 0.297 m platform; a 22.6 cm one is on it.
        assert!(stand_in(&estimate(EffectKind::Com, vec![0.3, 0.265], 0.01), &robot, 500.0).is_some());
        assert!(stand_in(&estimate(EffectKind::Com, vec![0.16, 0.16], 0.01), &robot, 500.0).is_none());
        // The load cell: a 1.066 gain is within 10 %, a 120 N bias on 500 N is not within 15 %.
        assert!(stand_in(
            &estimate(EffectKind::LoadCell, vec![-2.7, 1.066], 3.7e-3),
            &robot,
            500.0
        )
        .is_none());
        let bias = stand_in(&estimate(EffectKind::LoadCell, vec![120.0, 1.0], 3.0), &robot, 500.0).unwrap();
        assert!(bias.estimate.contains("off by 120.00"), "{}", bias.estimate);
    }

    #[test]
    fn an_unidentified_estimate_is_not_called_a_stand_in() {
        let robot = Robot::builtin("large").unwrap();
        assert!(stand_in(&estimate(EffectKind::Pulley, vec![3.5], f64::NAN), &robot, 500.0).is_none());
        assert!(stand_in(&estimate(EffectKind::Pulley, vec![3.5], 0.08), &robot, 500.0).is_some());
    }
}

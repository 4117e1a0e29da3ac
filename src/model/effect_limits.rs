//! The edge of what a real robot can have: per effect of the catalogue, the
//! largest magnitude any robot like this one could show, with the reason.
//!
//! [`crate::model::effect_ranges`] gives the magnitudes a robot typically
//! has (the ranges the hidden-effect experiment draws from); these limits are
//! wider: beyond them no real cable, drum, pulley, load cell or platform of
//! this robot could be. `sagcal diagnose` calls an estimate beyond its limit
//! (by more than 3 standard deviations) a **stand-in**: the effect fits the
//! data, but as a proxy for something else, and is not named as the cause.
//!
//! | effect | largest plausible | why |
//! |---|---|---|
//! | `elastic` | compliance `1e6 / EA` with `EA = A E_min` | no rope of this weight per metre is softer (the rope's cross-section `A` from its weight, the softest modulus of its fibre) |
//! | `pulley` | the largest pulley radius for the robot's scale | winch pulleys are sized to the cable (0.3 m for the large robot's 8 mm rope, 0.05 m for a small robot's braid) |
//! | `encoder-scale`, `encoder-gain` | gain 1 +- 0.05 per drum | ignoring the rope's thickness on a drum of 20 rope diameters (the smallest ratio ropes are wound at) is 5 % |
//! | `loadcell` | bias +- 15 % of the mean reference tension, gain 1 +- 0.10 | the zero error (5 % of a full scale of 3 x the mean tension) and rated-output tolerance (+- 5 % for the cell and again for its amplifier) of an uncalibrated load cell |
//! | `com` | a horizontal shift up to the platform's attachment radius | a centre of mass outside the platform's footprint would tip a real payload off it |
//! | `segments` | `1/n^2 = 0.01` (10 elements) | a real cable is continuous (`1/n^2 = 0`); finite-element cable models use at least 10 elements |
//! | `localiser-mount` | 10 degrees | a localiser bolted on with its axes further off would be seen by eye |
//! | `platform-weight` | weight 1 +- 0.5 x the file's | a platform half again as heavy, or half as heavy, as its file says would be noticed when it is lifted or its motors sized |
//! | `cable-weight` | weight per metre 1 +- 0.5 x the file's | a rope off by half its weight per metre is off by a fifth or more of its diameter, two or three size steps: another rope, not a datasheet error |
//! | `encoder-drift` | 5 x the typical range's top per drum (5 mm per row large, 1 mm small) | a drum losing more per pose would be decimetres off within a session, which an operator sees |
//! | `encoder-backlash` | 5 x the typical range's top per drum (25 mm large, 5 mm small) | a dead band that wide is a broken gearbox, felt by hand |
//! | `loadcell-drift` | 1 % of the mean reference tension per row | a gauge whose zero moves that fast is faulty and fails its own zero check |
//! | `loadcell-friction` | `mu theta` 0.2 | a pulley that holds a fifth of the tension is seized (a plain bush's mu 0.15 over more than a quarter turn) |
//! | `attachments` | a quarter of the platform's attachment radius per attachment | a point that far off its drawing would be seen on the platform |
//!
//! ```
//! use sagcal::model::effect_limits::plausible_limits;
//! use sagcal::model::effect_kind::EffectKind;
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! // A chain of 3 elements is no real cable: 1/9 is beyond the limit 1/100.
//! let segments = &plausible_limits(EffectKind::Segments, &robot, 500.0)[0];
//! assert_eq!(segments.largest, 0.01);
//! assert!(1.0 / 9.0 > segments.largest);
//! // The large robot's platform: attachments 0.297 m from its centre.
//! let com = &plausible_limits(EffectKind::Com, &robot, 500.0)[0];
//! assert_eq!(com.parameters, vec![0, 1]);
//! assert!((com.largest - 0.21 * 2f64.sqrt()).abs() < 1e-12);
//! # Ok::<(), sagcal::Error>(())
//! ```

use crate::model::effect_kind::EffectKind;
use crate::model::effect_ranges::{
    axial_stiffness_range_n, encoder_backlash_range_mm, encoder_drift_range_mm_per_row, pulley_radius_range_m,
    SEGMENTS_LOW,
};
use crate::model::robot::{Robot, CABLE_COUNT};

/// The largest plausible encoder gain error (dimensionless, module docs).
pub const ENCODER_GAIN_LIMIT: f64 = 0.05;
/// The largest plausible load-cell bias as a share of the mean reference tension.
pub const LOAD_CELL_BIAS_LIMIT: f64 = 0.15;
/// The largest plausible load-cell gain error (dimensionless).
pub const LOAD_CELL_GAIN_LIMIT: f64 = 0.10;
/// The largest plausible platform-weight error, as a share of the file's weight.
pub const PLATFORM_WEIGHT_LIMIT: f64 = 0.5;
/// The largest plausible cable-weight error, as a share of the file's weight per metre.
pub const CABLE_WEIGHT_LIMIT: f64 = 0.5;
/// The largest plausible localiser mounting rotation, degrees.
pub const LOCALISER_MOUNT_LIMIT_DEG: f64 = 10.0;
/// The largest plausible encoder creep and backlash, as a multiple of the top of their typical range.
pub const ENCODER_TIME_LIMIT_FACTOR: f64 = 5.0;
/// The largest plausible load-cell creep per row, as a share of the mean reference tension.
pub const LOAD_CELL_DRIFT_LIMIT: f64 = 0.01;
/// The largest plausible pulley friction `mu theta` before a load cell.
pub const LOAD_CELL_FRICTION_LIMIT: f64 = 0.2;

/// The largest plausible magnitude of a group of an effect's parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct PlausibleLimit {
    /// The parameters (indices into [`EffectKind::parameter_names`]) whose
    /// joint magnitude (Euclidean norm, in the effect variable's units: gains
    /// as errors) is limited; one index for a scalar.
    pub parameters: Vec<usize>,
    /// The largest plausible magnitude, variable units.
    pub largest: f64,
    /// The limit in the robot's words ("at least 10 elements").
    pub limit: String,
    /// Why no real robot goes beyond it.
    pub why: String,
}

/// The limits of `kind` for `robot` (module docs); `mean_reference_tension_n`
/// scales the load cell's bias.
pub fn plausible_limits(kind: EffectKind, robot: &Robot, mean_reference_tension_n: f64) -> Vec<PlausibleLimit> {
    match kind {
        EffectKind::Elastic => {
            let softest_n = axial_stiffness_range_n(robot).0;
            vec![one(
                0,
                1e6 / softest_n,
                format!("EA at least {softest_n:.3e} N"),
                "no rope of this weight per metre is softer",
            )]
        }
        EffectKind::Pulley => {
            let largest_m = pulley_radius_range_m(robot).1;
            vec![one(
                0,
                largest_m,
                format!("a radius of at most {largest_m} m"),
                "winch pulleys are sized to the cable and the robot",
            )]
        }
        EffectKind::EncoderScale | EffectKind::CommonGain => (0..kind.parameter_count())
            .map(|i| {
                one(
                    i,
                    ENCODER_GAIN_LIMIT,
                    format!("a gain within 1 +- {ENCODER_GAIN_LIMIT}"),
                    "ignoring the rope's thickness on a drum of 20 rope diameters is a 5 % error",
                )
            })
            .collect(),
        EffectKind::LoadCell => vec![
            one(
                0,
                LOAD_CELL_BIAS_LIMIT * mean_reference_tension_n,
                format!(
                    "a bias within +- {:.1} N ({:.0} % of the mean reference tension)",
                    LOAD_CELL_BIAS_LIMIT * mean_reference_tension_n,
                    LOAD_CELL_BIAS_LIMIT * 100.0
                ),
                "an uncalibrated load cell's zero is off by 5 % of a full scale of 3 x the mean tension",
            ),
            one(
                1,
                LOAD_CELL_GAIN_LIMIT,
                format!("a gain within 1 +- {LOAD_CELL_GAIN_LIMIT}"),
                "an uncalibrated load cell's rated output and its amplifier are each within 5 %",
            ),
        ],
        EffectKind::Com => {
            let radius_m = attachment_radius_m(robot);
            vec![PlausibleLimit {
                parameters: vec![0, 1],
                largest: radius_m,
                limit: format!(
                    "a shift of at most {:.1} cm (the platform's attachment radius)",
                    radius_m * 100.0
                ),
                why: "a centre of mass outside the platform's footprint would tip a real payload off it".into(),
            }]
        }
        EffectKind::Segments => vec![one(
            0,
            1.0 / (SEGMENTS_LOW * SEGMENTS_LOW),
            format!("at least {SEGMENTS_LOW} elements"),
            "a real cable is continuous (1/n^2 = 0) and finite-element cable models use at least 10 elements",
        )],
        EffectKind::LocaliserMount => vec![PlausibleLimit {
            parameters: vec![0, 1, 2],
            largest: LOCALISER_MOUNT_LIMIT_DEG,
            limit: format!("a rotation of at most {LOCALISER_MOUNT_LIMIT_DEG} deg"),
            why: "a localiser bolted on with its axes further off would be seen by eye".into(),
        }],
        EffectKind::PlatformWeight => vec![one(
            0,
            PLATFORM_WEIGHT_LIMIT,
            format!("a weight within 1 +- {PLATFORM_WEIGHT_LIMIT} x the robot file's"),
            "a platform that much heavier or lighter than its file says would be noticed when it is lifted",
        )],
        EffectKind::CableWeight => vec![one(
            0,
            CABLE_WEIGHT_LIMIT,
            format!("a weight per metre within 1 +- {CABLE_WEIGHT_LIMIT} x the robot file's"),
            "a rope off by half its weight per metre is another rope, two or three diameter steps away",
        )],
        _ => time_and_motion_limits(kind, robot, mean_reference_tension_n),
    }
}

/// The limits of the effects of time and motion (drift, backlash, friction).
fn time_and_motion_limits(kind: EffectKind, robot: &Robot, mean_reference_tension_n: f64) -> Vec<PlausibleLimit> {
    match kind {
        EffectKind::EncoderDrift => {
            let largest = ENCODER_TIME_LIMIT_FACTOR * encoder_drift_range_mm_per_row(robot).1;
            (0..CABLE_COUNT)
                .map(|i| {
                    one(
                        i,
                        largest,
                        format!("a creep of at most {largest} mm per row"),
                        "a drum losing more per pose would be decimetres off within a session",
                    )
                })
                .collect()
        }
        EffectKind::EncoderBacklash => {
            let largest = ENCODER_TIME_LIMIT_FACTOR * encoder_backlash_range_mm(robot).1;
            (0..CABLE_COUNT)
                .map(|i| {
                    one(
                        i,
                        largest,
                        format!("a backlash of at most {largest} mm"),
                        "a dead band that wide is a broken gearbox",
                    )
                })
                .collect()
        }
        EffectKind::LoadCellDrift => vec![one(
            0,
            LOAD_CELL_DRIFT_LIMIT * mean_reference_tension_n,
            format!(
                "a creep of at most {:.2} N per row ({} % of the mean reference tension)",
                LOAD_CELL_DRIFT_LIMIT * mean_reference_tension_n,
                LOAD_CELL_DRIFT_LIMIT * 100.0
            ),
            "a gauge whose zero moves that fast is faulty",
        )],
        EffectKind::LoadCellFriction => vec![one(
            0,
            LOAD_CELL_FRICTION_LIMIT,
            format!("a friction mu theta of at most {LOAD_CELL_FRICTION_LIMIT}"),
            "a pulley that holds a fifth of the tension is seized",
        )],
        EffectKind::Attachments => {
            let largest = 0.25 * attachment_radius_m(robot);
            (0..CABLE_COUNT)
                .map(|i| PlausibleLimit {
                    parameters: vec![2 * i, 2 * i + 1],
                    largest,
                    limit: format!("a move of at most {:.1} cm", largest * 100.0),
                    why: "an attachment that far off its drawing would be seen on the platform".into(),
                })
                .collect()
        }
        _ => Vec::new(),
    }
}

/// The limit `largest` of parameter `index` alone.
fn one(index: usize, largest: f64, limit: String, why: &str) -> PlausibleLimit {
    PlausibleLimit {
        parameters: vec![index],
        largest,
        limit,
        why: why.to_string(),
    }
}

/// The largest horizontal distance of an attachment point from the
/// platform's origin, metres.
fn attachment_radius_m(robot: &Robot) -> f64 {
    robot.attachments_m.iter().map(|a| a.x.hypot(a.y)).fold(0.0, f64::max)
}

//! Physically plausible magnitudes of each effect for a robot, derived from
//! its own data (rope cross-section from the cable weight, platform size):
//! the ranges the hidden-effect experiment draws from and the magnitudes at
//! which `diagnose` states the power of its tests.
//!
//! ```
//! use sagcal::model::effect_ranges::{axial_stiffness_range_n, effect_ranges};
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! // The rope's cross-section from its weight per metre is that of a 4 mm radius rope,
//! // and EA = A E with E = 30 .. 160 GPa for aramid.
//! let area_m2 = std::f64::consts::PI * 0.004f64.powi(2);
//! let (low, high) = axial_stiffness_range_n(&robot);
//! assert!((low / (area_m2 * 30e9) - 1.0).abs() < 1e-9 && (high / (area_m2 * 160e9) - 1.0).abs() < 1e-9);
//! let ranges = effect_ranges(&robot);
//! assert!(ranges.iter().any(|r| r.effect == "elastic" && r.justification.contains("50.27 mm^2")));
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::Serialize;

use crate::model::effect_kind::EffectKind;
use crate::model::plausibility::STANDARD_GRAVITY_M_S2 as GRAVITY;
use crate::model::robot::Robot;

/// Density of the synthetic-fibre (aramid) cables, kg/m^3.
pub const CABLE_DENSITY_KG_M3: f64 = 1440.0;

/// The range an effect's magnitude is drawn from, for one robot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectRange {
    /// The effect.
    pub effect: String,
    /// The range, in words with units.
    pub range: String,
    /// Why it is plausible.
    pub justification: String,
}

/// The magnitude ranges of every effect for `robot` (module docs).
pub fn effect_ranges(robot: &Robot) -> Vec<EffectRange> {
    let (ea_low, ea_high) = axial_stiffness_range_n(robot);
    let (r_low, r_high) = pulley_radius_range_m(robot);
    let mut ranges = vec![
        EffectRange {
            effect: "elastic".into(),
            range: format!("EA {ea_low:.3e} .. {ea_high:.3e} N (log-uniform)"),
            justification: format!(
                "{}: A = g_c / (rho g) = {:.2} mm^2 from {:.1} g/m at {CABLE_DENSITY_KG_M3} kg/m^3, rope modulus {:.0}-{:.0} GPa",
                if is_large(robot) { "aramid rope" } else { "nylon braid" },
                cross_section_m2(robot) * 1e6,
                robot.cable_weight_n_per_m / GRAVITY * 1e3,
                rope_modulus_pa(robot).0 / 1e9,
                rope_modulus_pa(robot).1 / 1e9
            ),
        },
        EffectRange {
            effect: "pulley".into(),
            range: format!("radius {r_low:.3} .. {r_high:.3} m"),
            justification: "pulley sizes of winches for this cable and robot scale".into(),
        },
        EffectRange {
            effect: "encoder-scale".into(),
            range: "gain 1 +- (0.001 .. 0.003) per cable".into(),
            justification: "effective drum radius uncertain by a fraction of the rope diameter".into(),
        },
        EffectRange {
            effect: "loadcell".into(),
            range: "bias +-(5 .. 12) % of the mean reference tension, gain 1 +- (0.02 .. 0.05)".into(),
            justification: "zero and span errors of an uncalibrated load cell of 2-3 x the mean tension full scale".into(),
        },
        EffectRange {
            effect: "com".into(),
            range: format!(
                "horizontal shift {:.2} .. {:.2} m, random direction",
                com_shift_range_m(robot).0,
                com_shift_range_m(robot).1
            ),
            justification: "payload mounted off the centre of the 0.42 m platform".into(),
        },
        EffectRange {
            effect: "encoder-gain".into(),
            range: format!("gain 1 +- ({COMMON_GAIN_LOW} .. {COMMON_GAIN_HIGH}), the same on every drum"),
            justification: "one drum radius or counts-per-metre figure used for all four winches".into(),
        },
        EffectRange {
            effect: "localiser-mount".into(),
            range: format!("rotation {LOCALISER_MOUNT_LOW_DEG} .. {LOCALISER_MOUNT_HIGH_DEG} deg about a random axis"),
            justification: "a localiser (IMU, camera, marker body) bolted to the platform with its axes off by a few degrees".into(),
        },
        EffectRange {
            effect: "segments".into(),
            range: format!("{SEGMENTS_LOW} .. {SEGMENTS_HIGH} straight elements per cable"),
            justification: "finite-element cable models (lumped-mass chains) of tens of elements".into(),
        },
        EffectRange {
            effect: "platform-weight".into(),
            range: format!(
                "weight 1 +- ({PLATFORM_WEIGHT_LOW} .. {PLATFORM_WEIGHT_HIGH}) x the robot file's {:.1} N",
                robot.platform_weight_n
            ),
            justification: "a payload, tool or cabling left out of the platform's weight (or one taken off)".into(),
        },
        EffectRange {
            effect: "cable-weight".into(),
            range: format!(
                "weight per metre 1 +- ({CABLE_WEIGHT_LOW} .. {CABLE_WEIGHT_HIGH}) x the robot file's {:.3} N/m",
                robot.cable_weight_n_per_m
            ),
            justification: "a rope of the next diameter (weight ~ d^2: 10-20 % per size step) or with a coating the datasheet leaves out".into(),
        },
    ];
    ranges.extend(time_and_motion_ranges(robot));
    ranges
}

/// The ranges of the effects of time and motion (drift, backlash, friction).
fn time_and_motion_ranges(robot: &Robot) -> Vec<EffectRange> {
    vec![
        EffectRange {
            effect: "encoder-drift".into(),
            range: {
                let (low, high) = encoder_drift_range_mm_per_row(robot);
                format!("{low} .. {high} mm per row per drum, random signs")
            },
            justification: "rope creep and slip on the drum, or a counter losing counts: a fraction of a millimetre per pose, more on long heavy ropes".into(),
        },
        EffectRange {
            effect: "encoder-backlash".into(),
            range: {
                let (low, high) = encoder_backlash_range_mm(robot);
                format!("half dead band {low} .. {high} mm per drum, random signs")
            },
            justification: "gearbox backlash of a few arc-minutes between a motor-side encoder and the drum, times the drum radius".into(),
        },
        EffectRange {
            effect: "loadcell-drift".into(),
            range: format!(
                "{} .. {} % of the mean reference tension per row, random sign",
                LOAD_CELL_DRIFT_LOW * 100.0,
                LOAD_CELL_DRIFT_HIGH * 100.0
            ),
            justification: "zero drift of a strain-gauge cell with temperature and creep over a session".into(),
        },
        EffectRange {
            effect: "attachments".into(),
            range: {
                let (low, high) = attachment_shift_range_m(robot);
                format!("{:.1} .. {:.1} cm per attachment, random direction", low * 100.0, high * 100.0)
            },
            justification: "an eyelet drilled or a shackle hung off the platform's drawing".into(),
        },
        EffectRange {
            effect: "loadcell-friction".into(),
            range: format!("k = mu theta {LOAD_CELL_FRICTION_LOW} .. {LOAD_CELL_FRICTION_HIGH}"),
            justification: "a rolling-bearing pulley (mu 0.01-0.03 at the rope) with a wrap of a quarter to half a turn before a drum-side load cell".into(),
        },
    ]
}

/// The localiser's mounting rotation angle: smallest plausible, degrees.
pub const LOCALISER_MOUNT_LOW_DEG: f64 = 0.5;
/// The localiser's mounting rotation angle: largest plausible, degrees.
pub const LOCALISER_MOUNT_HIGH_DEG: f64 = 3.0;
/// A common encoder gain error's range (dimensionless).
pub const COMMON_GAIN_LOW: f64 = 0.001;
/// See [`COMMON_GAIN_LOW`].
pub const COMMON_GAIN_HIGH: f64 = 0.003;
/// The platform's weight error: smallest plausible share of its weight.
pub const PLATFORM_WEIGHT_LOW: f64 = 0.03;
/// The platform's weight error: largest typical share of its weight.
pub const PLATFORM_WEIGHT_HIGH: f64 = 0.15;
/// The cables' weight-per-metre error: smallest plausible share.
pub const CABLE_WEIGHT_LOW: f64 = 0.05;
/// The cables' weight-per-metre error: largest typical share.
pub const CABLE_WEIGHT_HIGH: f64 = 0.20;
/// The number of elements of a finite-element cable: fewest plausible.
pub const SEGMENTS_LOW: f64 = 10.0;
/// The number of elements of a finite-element cable: most plausible.
pub const SEGMENTS_HIGH: f64 = 100.0;
/// The load cell's creep per row: smallest plausible share of the mean reference tension.
pub const LOAD_CELL_DRIFT_LOW: f64 = 0.0005;
/// The load cell's creep per row: largest typical share of the mean reference tension.
pub const LOAD_CELL_DRIFT_HIGH: f64 = 0.002;
/// Friction `mu theta` of a pulley before a drum-side load cell: smallest plausible.
pub const LOAD_CELL_FRICTION_LOW: f64 = 0.01;
/// See [`LOAD_CELL_FRICTION_LOW`]: largest typical.
pub const LOAD_CELL_FRICTION_HIGH: f64 = 0.05;

/// The smallest plausible magnitude of `kind` for `robot` as the effect
/// variable's values (gains as errors, elastic as the compliance in 1/MN,
/// segments as `1/n^2`), for the power of a test: the stiffest rope, the
/// smallest pulley, gains off by 0.1 % with alternating signs, a load cell
/// off by 5 % of `mean_reference_tension_n` and 2 % in gain, a 5 cm
/// centre-of-mass shift along the diagonal, the finest plausible chain, a
/// localiser turned by 0.5 degrees about the diagonal of its axes, a platform
/// 3 % and cables 5 % heavier than the robot file says, the slowest encoder
/// creep and smallest backlash with alternating signs, the slowest load-cell
/// creep and the least pulley friction, and each attachment moved outward
/// by the least misplacement.
pub fn smallest_plausible(kind: EffectKind, robot: &Robot, mean_reference_tension_n: f64) -> Vec<f64> {
    match kind {
        EffectKind::Elastic => vec![1e6 / axial_stiffness_range_n(robot).1],
        EffectKind::Pulley => vec![pulley_radius_range_m(robot).0],
        EffectKind::EncoderScale => vec![0.001, -0.001, 0.001, -0.001],
        EffectKind::LoadCell => vec![0.05 * mean_reference_tension_n, 0.02],
        EffectKind::Com => {
            let low = com_shift_range_m(robot).0;
            vec![low / 2f64.sqrt(), low / 2f64.sqrt()]
        }
        EffectKind::CommonGain => vec![COMMON_GAIN_LOW],
        EffectKind::Segments => vec![1.0 / (SEGMENTS_HIGH * SEGMENTS_HIGH)],
        EffectKind::LocaliserMount => vec![LOCALISER_MOUNT_LOW_DEG / 3f64.sqrt(); 3],
        EffectKind::PlatformWeight => vec![PLATFORM_WEIGHT_LOW],
        EffectKind::CableWeight => vec![CABLE_WEIGHT_LOW],
        EffectKind::EncoderDrift => {
            let low = encoder_drift_range_mm_per_row(robot).0;
            vec![low, -low, low, -low]
        }
        EffectKind::EncoderBacklash => {
            let low = encoder_backlash_range_mm(robot).0;
            vec![low, -low, low, -low]
        }
        EffectKind::LoadCellDrift => vec![LOAD_CELL_DRIFT_LOW * mean_reference_tension_n],
        EffectKind::LoadCellFriction => vec![LOAD_CELL_FRICTION_LOW],
        EffectKind::Attachments => {
            // Outward from the platform's centre: a change of the pattern's
            // size, which neither a centre-of-mass shift (a common move) nor
            // a localiser's turn (a common turn) can fit.
            let low = attachment_shift_range_m(robot).0;
            robot
                .attachments_m
                .iter()
                .flat_map(|b| {
                    let radius = b.x.hypot(b.y).max(f64::MIN_POSITIVE);
                    [low * b.x / radius, low * b.y / radius]
                })
                .collect()
        }
    }
}

fn cross_section_m2(robot: &Robot) -> f64 {
    robot.cable_weight_n_per_m / (CABLE_DENSITY_KG_M3 * GRAVITY)
}

/// The large robot (tens of kilograms, cables over 100 m) or a light one.
fn is_large(robot: &Robot) -> bool {
    robot.platform_weight_n > 100.0
}

/// Young's modulus range of the rope, pascals (module docs).
fn rope_modulus_pa(robot: &Robot) -> (f64, f64) {
    if is_large(robot) {
        (30e9, 160e9)
    } else {
        (1e9, 3e9)
    }
}

/// The axial stiffness range `EA` of the robot's rope, newtons (low, high).
pub fn axial_stiffness_range_n(robot: &Robot) -> (f64, f64) {
    let area = cross_section_m2(robot);
    let (low, high) = rope_modulus_pa(robot);
    (area * low, area * high)
}

/// The horizontal centre-of-mass shift range, metres (low, high).
pub fn com_shift_range_m(robot: &Robot) -> (f64, f64) {
    if is_large(robot) {
        (0.05, 0.25)
    } else {
        (0.05, 0.20)
    }
}

/// Each attachment point's horizontal misplacement, metres (low, high): a
/// drilled eyelet or a hung shackle off its drawing, in proportion to the
/// platform's size.
pub fn attachment_shift_range_m(robot: &Robot) -> (f64, f64) {
    if is_large(robot) {
        (0.005, 0.02)
    } else {
        (0.002, 0.01)
    }
}

/// Each drum's encoder creep, millimetres per row (low, high): long heavy
/// ropes creep and slip more.
pub fn encoder_drift_range_mm_per_row(robot: &Robot) -> (f64, f64) {
    if is_large(robot) {
        (0.2, 1.0)
    } else {
        (0.05, 0.2)
    }
}

/// Each drum's backlash (half the dead band), millimetres (low, high): a few
/// arc-minutes of gear play times the drum's radius.
pub fn encoder_backlash_range_mm(robot: &Robot) -> (f64, f64) {
    if is_large(robot) {
        (1.0, 5.0)
    } else {
        (0.2, 1.0)
    }
}

/// The pulley radius range, metres (low, high).
pub fn pulley_radius_range_m(robot: &Robot) -> (f64, f64) {
    if is_large(robot) {
        (0.1, 0.3)
    } else {
        (0.02, 0.05)
    }
}

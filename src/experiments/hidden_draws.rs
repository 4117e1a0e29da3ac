//! The magnitudes each hidden effect is drawn with: uniformly from its
//! physically justified range for the robot ([`crate::model::effect_ranges`]),
//! and the smallest and mid-range magnitudes the report checks against.

use rand::Rng;

use crate::model::effect_kind::EffectKind;
use crate::model::effect_ranges::{
    attachment_shift_range_m, axial_stiffness_range_n, com_shift_range_m, encoder_backlash_range_mm,
    encoder_drift_range_mm_per_row, pulley_radius_range_m, CABLE_WEIGHT_HIGH, CABLE_WEIGHT_LOW, COMMON_GAIN_HIGH,
    COMMON_GAIN_LOW, LOAD_CELL_DRIFT_HIGH, LOAD_CELL_DRIFT_LOW, LOAD_CELL_FRICTION_HIGH, LOAD_CELL_FRICTION_LOW,
    LOCALISER_MOUNT_HIGH_DEG, LOCALISER_MOUNT_LOW_DEG, PLATFORM_WEIGHT_HIGH, PLATFORM_WEIGHT_LOW, SEGMENTS_HIGH,
    SEGMENTS_LOW,
};
use crate::model::effects::Effects;
use crate::model::robot::{Robot, CABLE_COUNT};

/// The smallest magnitude of every scored effect's range (encoder gains with
/// alternating signs), to check that it moves the anchors by more than their 1-sigma.
pub fn smallest_effects(robot: &Robot, mean_reference_tension_n: f64) -> Vec<(EffectKind, Effects)> {
    let (_, ea_high) = axial_stiffness_range_n(robot);
    let (com_low, _) = com_shift_range_m(robot);
    vec![
        (
            EffectKind::Elastic,
            Effects {
                axial_stiffness_n: Some(ea_high),
                ..Effects::default()
            },
        ),
        (
            EffectKind::EncoderScale,
            Effects {
                encoder_gain: [1.001, 0.999, 1.001, 0.999],
                ..Effects::default()
            },
        ),
        (
            EffectKind::LoadCell,
            Effects {
                load_cell_bias_n: 0.05 * mean_reference_tension_n,
                load_cell_gain: 1.02,
                ..Effects::default()
            },
        ),
        (
            EffectKind::Com,
            Effects {
                com_shift_m: [com_low / 2f64.sqrt(), com_low / 2f64.sqrt(), 0.0],
                ..Effects::default()
            },
        ),
    ]
}

/// Mid-range magnitudes of the effects that are candidates for exclusion from
/// the detection score: the pulley radius and the load-cell bias.
pub fn mid_range_effects(robot: &Robot, mean_reference_tension_n: f64) -> Vec<(EffectKind, Effects)> {
    let (low, high) = pulley_radius_range_m(robot);
    vec![
        (
            EffectKind::Pulley,
            Effects {
                pulley_radius_m: 0.5 * (low + high),
                ..Effects::default()
            },
        ),
        (
            EffectKind::LoadCell,
            Effects {
                load_cell_bias_n: 0.085 * mean_reference_tension_n,
                ..Effects::default()
            },
        ),
    ]
}

fn signed(rng: &mut impl Rng, low: f64, high: f64) -> f64 {
    let magnitude = rng.random_range(low..high);
    if rng.random_bool(0.5) {
        magnitude
    } else {
        -magnitude
    }
}

/// Draw the magnitudes of `hidden` for `robot` (empty: no effect), each
/// from its range ([`crate::model::effect_ranges`]).
pub fn draw_effects(
    robot: &Robot,
    hidden: &[EffectKind],
    mean_reference_tension_n: f64,
    rng: &mut impl Rng,
) -> Effects {
    let mut e = Effects::default();
    for kind in hidden {
        draw_effect(robot, *kind, mean_reference_tension_n, rng, &mut e);
    }
    e
}

/// Draw `effect`'s magnitude into `e`.
fn draw_effect(robot: &Robot, effect: EffectKind, mean_reference_tension_n: f64, rng: &mut impl Rng, e: &mut Effects) {
    match effect {
        EffectKind::Elastic => {
            let (low, high) = axial_stiffness_range_n(robot);
            e.axial_stiffness_n = Some((rng.random_range(low.ln()..high.ln())).exp());
        }
        EffectKind::Pulley => {
            let (low, high) = pulley_radius_range_m(robot);
            e.pulley_radius_m = rng.random_range(low..high);
        }
        EffectKind::EncoderScale => {
            e.encoder_gain = std::array::from_fn(|_| 1.0 + signed(rng, 0.001, 0.003));
        }
        EffectKind::LoadCell => {
            e.load_cell_bias_n = signed(rng, 0.05, 0.12) * mean_reference_tension_n;
            e.load_cell_gain = 1.0 + signed(rng, 0.02, 0.05);
        }
        EffectKind::Com => {
            let (low, high) = com_shift_range_m(robot);
            let magnitude = rng.random_range(low..high);
            let angle = rng.random_range(0.0..std::f64::consts::TAU);
            e.com_shift_m = [magnitude * angle.cos(), magnitude * angle.sin(), 0.0];
        }
        EffectKind::CommonGain => {
            e.encoder_gain = [1.0 + signed(rng, COMMON_GAIN_LOW, COMMON_GAIN_HIGH); CABLE_COUNT];
        }
        EffectKind::Segments => {
            e.cable_segments = Some(rng.random_range(SEGMENTS_LOW..SEGMENTS_HIGH).round());
        }
        EffectKind::LocaliserMount => {
            let angle = rng.random_range(LOCALISER_MOUNT_LOW_DEG..LOCALISER_MOUNT_HIGH_DEG);
            // A uniform direction on the sphere: z uniform in [-1, 1], azimuth uniform.
            let z: f64 = rng.random_range(-1.0..1.0);
            let azimuth = rng.random_range(0.0..std::f64::consts::TAU);
            let r = (1.0 - z * z).sqrt();
            e.localiser_mount_deg = [angle * r * azimuth.cos(), angle * r * azimuth.sin(), angle * z];
        }
        EffectKind::PlatformWeight => {
            e.platform_weight_scale = 1.0 + signed(rng, PLATFORM_WEIGHT_LOW, PLATFORM_WEIGHT_HIGH);
        }
        EffectKind::CableWeight => {
            e.cable_weight_scale = 1.0 + signed(rng, CABLE_WEIGHT_LOW, CABLE_WEIGHT_HIGH);
        }
        EffectKind::EncoderDrift => {
            let (low, high) = encoder_drift_range_mm_per_row(robot);
            e.encoder_drift_m_per_row = std::array::from_fn(|_| 1e-3 * signed(rng, low, high));
        }
        EffectKind::EncoderBacklash => {
            let (low, high) = encoder_backlash_range_mm(robot);
            e.encoder_backlash_m = std::array::from_fn(|_| 1e-3 * signed(rng, low, high));
        }
        EffectKind::LoadCellDrift => {
            e.load_cell_drift_n_per_row =
                signed(rng, LOAD_CELL_DRIFT_LOW, LOAD_CELL_DRIFT_HIGH) * mean_reference_tension_n;
        }
        EffectKind::LoadCellFriction => {
            e.load_cell_friction = rng.random_range(LOAD_CELL_FRICTION_LOW..LOAD_CELL_FRICTION_HIGH);
        }
        EffectKind::Attachments => {
            let (low, high) = attachment_shift_range_m(robot);
            e.attachment_shift_m = std::array::from_fn(|_| {
                let magnitude = rng.random_range(low..high);
                let angle = rng.random_range(0.0..std::f64::consts::TAU);
                [magnitude * angle.cos(), magnitude * angle.sin()]
            });
        }
    }
}

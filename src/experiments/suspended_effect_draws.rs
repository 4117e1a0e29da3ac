//! The effects hidden in the N-cable sweep ([`super::suspended_sweep`]) and
//! the ranges their magnitudes are drawn from, for robots on steel wire
//! rope (the built-in three-, six- and eight-cable robots).
//!
//! - `elastic`: `EA = A E` with the rope's metallic area `A = m / rho`
//!   (its mass per metre over steel's 7850 kg/m^3) and a stranded rope's
//!   modulus `E` of 60 .. 120 GPa (Feyrer, *Wire Ropes*, 2nd ed., 2015,
//!   ch. 1.4: the rope modulus of stranded ropes), log-uniform;
//! - `pulley`: radius 10 .. 20 rope diameters (a sheave of `D/d` = 20 .. 40,
//!   the range of running-rope sheaves in ISO 4308-1 and Feyrer ch. 3), the
//!   diameter `d` from the metallic area at a fill factor of 0.55;
//! - `com`: a horizontal shift of 5 .. 20 % of the platform's radius (its
//!   farthest attachment from the origin), random direction;
//! - `platform-weight`, `cable-weight`, `encoder-scale` (one gain on every
//!   drum), `localiser-mount` and `segments`: the four-cable catalogue's
//!   ranges ([`crate::model::effect_ranges`]), random signs;
//! - `loadcell`: a bias of 5 .. 12 % of the load-cell cables' mean tension
//!   and a gain error of 2 .. 5 %, random signs, as for four cables.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::experiments::suspended_effect_draws::{draw_suspended_effect, suspended_effect_ranges};
//! use sagcal::model::suspended::SuspendedRobot;
//! let robot = SuspendedRobot::builtin("six")?;
//! // The 0.4 kg/m steel rope: 51 mm^2 of steel, EA from 3.1 to 6.1 MN.
//! let elastic = suspended_effect_ranges(&robot).into_iter().find(|r| r.effect == "elastic").unwrap();
//! assert!(elastic.range.starts_with("EA 3.057e6 .. 6.115e6 N"), "{}", elastic.range);
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let spec = draw_suspended_effect("elastic", &robot, 1000.0, &mut rng).unwrap();
//! assert!(spec.starts_with("elastic:ea_n="));
//! assert_eq!(draw_suspended_effect("none", &robot, 1000.0, &mut rng), None);
//! # Ok::<(), sagcal::Error>(())
//! ```

use rand::Rng;
use serde::Serialize;

use crate::model::effect_ranges::{
    CABLE_WEIGHT_HIGH, CABLE_WEIGHT_LOW, COMMON_GAIN_HIGH, COMMON_GAIN_LOW, LOCALISER_MOUNT_HIGH_DEG,
    LOCALISER_MOUNT_LOW_DEG, PLATFORM_WEIGHT_HIGH, PLATFORM_WEIGHT_LOW, SEGMENTS_HIGH, SEGMENTS_LOW,
};
use crate::model::plausibility::STANDARD_GRAVITY_M_S2 as GRAVITY;
use crate::model::suspended::SuspendedRobot;

/// Density of steel wire, kg/m^3.
const STEEL_DENSITY_KG_M3: f64 = 7850.0;
/// A stranded rope's modulus, pascals (low, high).
const ROPE_MODULUS_PA: (f64, f64) = (60e9, 120e9);
/// Metallic area over the rope's circle.
const FILL_FACTOR: f64 = 0.55;
/// Pulley radius in rope diameters (low, high).
const PULLEY_RADIUS_DIAMETERS: (f64, f64) = (10.0, 20.0);
/// Centre-of-mass shift over the platform's radius (low, high).
const COM_SHIFT_FRACTION: (f64, f64) = (0.05, 0.20);

/// The effects of the sweep, in its order (`none`: the false-alarm cases).
pub const SUSPENDED_EFFECTS: [&str; 10] = [
    "none",
    "elastic",
    "pulley",
    "segments",
    "com",
    "platform-weight",
    "cable-weight",
    "encoder-scale",
    "loadcell",
    "localiser-mount",
];

/// One effect's range for a robot, in words with units.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedEffectRange {
    /// The effect.
    pub effect: String,
    /// The range.
    pub range: String,
}

/// The rope's metallic area, m^2, from the heaviest cable's weight per metre.
fn metallic_area_m2(robot: &SuspendedRobot) -> f64 {
    let heaviest = robot.cable_weights_n_per_m.iter().copied().fold(0.0, f64::max);
    heaviest / GRAVITY / STEEL_DENSITY_KG_M3
}

/// The rope's diameter, metres.
fn rope_diameter_m(robot: &SuspendedRobot) -> f64 {
    (4.0 * metallic_area_m2(robot) / (FILL_FACTOR * std::f64::consts::PI)).sqrt()
}

/// The platform's radius: its farthest attachment from the origin, horizontally, metres.
fn platform_radius_m(robot: &SuspendedRobot) -> f64 {
    robot.attachments_m.iter().map(|b| b.xy().norm()).fold(0.0, f64::max)
}

/// Every effect's range for `robot` (module docs).
pub fn suspended_effect_ranges(robot: &SuspendedRobot) -> Vec<SuspendedEffectRange> {
    let area = metallic_area_m2(robot);
    let d = rope_diameter_m(robot);
    let radius = platform_radius_m(robot);
    let range = |effect: &str, range: String| SuspendedEffectRange {
        effect: effect.into(),
        range,
    };
    vec![
        range(
            "none",
            "no effect: the chains of the discretised simulator alone".into(),
        ),
        range(
            "elastic",
            format!(
                "EA {:.3e} .. {:.3e} N (log-uniform; steel area {:.1} mm^2, E 60 .. 120 GPa)",
                area * ROPE_MODULUS_PA.0,
                area * ROPE_MODULUS_PA.1,
                area * 1e6
            ),
        ),
        range(
            "pulley",
            format!(
                "radius {:.3} .. {:.3} m (10 .. 20 rope diameters of {:.1} mm)",
                10.0 * d,
                20.0 * d,
                d * 1e3
            ),
        ),
        range(
            "segments",
            format!("{SEGMENTS_LOW} .. {SEGMENTS_HIGH} straight elements per cable"),
        ),
        range(
            "com",
            format!(
                "horizontal shift {:.3} .. {:.3} m, random direction",
                COM_SHIFT_FRACTION.0 * radius,
                COM_SHIFT_FRACTION.1 * radius
            ),
        ),
        range(
            "platform-weight",
            format!("scale 1 +- ({PLATFORM_WEIGHT_LOW} .. {PLATFORM_WEIGHT_HIGH})"),
        ),
        range(
            "cable-weight",
            format!("scale 1 +- ({CABLE_WEIGHT_LOW} .. {CABLE_WEIGHT_HIGH})"),
        ),
        range(
            "encoder-scale",
            format!("gain 1 +- ({COMMON_GAIN_LOW} .. {COMMON_GAIN_HIGH}) on every drum"),
        ),
        range(
            "loadcell",
            "bias +-(5 .. 12) % of the mean load-cell tension, gain 1 +- (0.02 .. 0.05)".into(),
        ),
        range(
            "localiser-mount",
            format!("{LOCALISER_MOUNT_LOW_DEG} .. {LOCALISER_MOUNT_HIGH_DEG} deg about a random axis"),
        ),
    ]
}

/// A random sign.
fn sign(rng: &mut impl Rng) -> f64 {
    if rng.random_bool(0.5) {
        1.0
    } else {
        -1.0
    }
}

/// The spec (`NAME:PARAM=VALUE,...`, as `sagcal simulate --effect` takes it)
/// of `effect` at a magnitude drawn from its range for `robot`;
/// `mean_load_cell_tension_n` scales the load cell's bias. `None` for `none`.
pub fn draw_suspended_effect(
    effect: &str,
    robot: &SuspendedRobot,
    mean_load_cell_tension_n: f64,
    rng: &mut impl Rng,
) -> Option<String> {
    let area = metallic_area_m2(robot);
    let d = rope_diameter_m(robot);
    let spec = match effect {
        "elastic" => {
            let (low, high) = (area * ROPE_MODULUS_PA.0, area * ROPE_MODULUS_PA.1);
            let ea = (low.ln() + rng.random::<f64>() * (high / low).ln()).exp();
            format!("elastic:ea_n={ea:.4e}")
        }
        "pulley" => format!(
            "pulley:radius_m={:.4}",
            d * rng.random_range(PULLEY_RADIUS_DIAMETERS.0..=PULLEY_RADIUS_DIAMETERS.1)
        ),
        "segments" => format!("segments:n={:.0}", rng.random_range(SEGMENTS_LOW..=SEGMENTS_HIGH)),
        "com" => {
            let shift = platform_radius_m(robot) * rng.random_range(COM_SHIFT_FRACTION.0..=COM_SHIFT_FRACTION.1);
            let angle = rng.random_range(0.0..std::f64::consts::TAU);
            format!("com:dx_m={:.4},dy_m={:.4}", shift * angle.cos(), shift * angle.sin())
        }
        "platform-weight" => format!(
            "platform-weight:scale={:.4}",
            1.0 + sign(rng) * rng.random_range(PLATFORM_WEIGHT_LOW..=PLATFORM_WEIGHT_HIGH)
        ),
        "cable-weight" => format!(
            "cable-weight:scale={:.4}",
            1.0 + sign(rng) * rng.random_range(CABLE_WEIGHT_LOW..=CABLE_WEIGHT_HIGH)
        ),
        "encoder-scale" => format!(
            "encoder-scale:gain={:.5}",
            1.0 + sign(rng) * rng.random_range(COMMON_GAIN_LOW..=COMMON_GAIN_HIGH)
        ),
        "loadcell" => format!(
            "loadcell:bias_n={:.3},gain={:.4}",
            sign(rng) * rng.random_range(0.05..=0.12) * mean_load_cell_tension_n,
            1.0 + sign(rng) * rng.random_range(0.02..=0.05)
        ),
        "localiser-mount" => {
            let angle = rng.random_range(LOCALISER_MOUNT_LOW_DEG..=LOCALISER_MOUNT_HIGH_DEG);
            let axis = nalgebra::Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0)).normalize() * angle;
            format!(
                "localiser-mount:rx_deg={:.4},ry_deg={:.4},rz_deg={:.4}",
                axis.x, axis.y, axis.z
            )
        }
        _ => return None,
    };
    Some(spec)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::effects::Effects;
    use rand::SeedableRng;

    /// The six-cable robot's 0.4 kg/m rope is 51 mm^2 of steel, a 10.9 mm
    /// rope: EA 3.1 .. 6.1 MN, pulleys of 0.11 .. 0.22 m; every drawn spec
    /// parses and lies in its range.
    #[test]
    fn six_cable_ranges_follow_from_its_rope() {
        let robot = SuspendedRobot::builtin("six").unwrap();
        let area = metallic_area_m2(&robot);
        assert!((area * 1e6 - 50.96).abs() < 0.01, "{}", area * 1e6);
        assert!((rope_diameter_m(&robot) * 1e3 - 10.86).abs() < 0.01);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..20 {
            for effect in SUSPENDED_EFFECTS {
                let Some(spec) = draw_suspended_effect(effect, &robot, 1000.0, &mut rng) else {
                    assert_eq!(effect, "none");
                    continue;
                };
                let mut effects = Effects::default();
                effects.apply_spec(&spec).unwrap();
                effects.validate().unwrap();
                if let Some(ea) = effects.axial_stiffness_n {
                    assert!((3.05e6..6.12e6).contains(&ea), "{spec}");
                }
                if effect == "pulley" {
                    assert!((0.108..0.218).contains(&effects.pulley_radius_m), "{spec}");
                }
            }
        }
    }
}

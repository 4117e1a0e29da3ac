//! Magnitudes no real suspended robot falls outside, checked when a robot
//! file is read ([`check_masses`], [`check_effects`]) so that a mistyped
//! number (a weight in the wrong unit, a radius in millimetres) is named at
//! once instead of sending the solvers into minutes of hopeless work. Each
//! range has a physical reason, stated in its constant's docs and in the
//! message:
//!
//! | quantity | plausible | why |
//! |---|---|---|
//! | platform weight | 1 g .. 1000 t | lighter cannot carry four cable attachments; 1000 t is over 30 times the heaviest platform hung from cables |
//! | cable weight per metre | 0 .. a solid steel bar 200 mm thick | no rope is heavier per metre (0: the massless limit) |
//! | four cables across the anchors' spread | at most 100 platforms | heavier, the cables hang in their own weight's shape and no robot is built so |
//! | pulley radius | at most a tenth of the closest anchors' distance | the cable leaves up to two radii from its anchor; larger pulleys near-touch their neighbours |
//!
//! ```
//! use sagcal::model::plausibility::{check_effects, check_masses};
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! assert!(check_masses(&robot).is_ok() && check_effects(&robot, &robot.effects).is_ok());
//! // A platform lighter than a gram: refused, with the range and why.
//! let mut light = robot.clone();
//! light.platform_weight_n = 1e-300;
//! assert!(check_masses(&light).unwrap_err().contains("1 g .. 1000 t"));
//! // A pulley of a kilometre on anchors 220 m apart.
//! let mut effects = robot.effects;
//! effects.pulley_radius_m = 1e3;
//! assert!(check_effects(&robot, &effects).unwrap_err().contains("a tenth of the 220.000 m between anchors 1 and 4"));
//! # Ok::<(), sagcal::Error>(())
//! ```

use crate::model::effects::Effects;
use crate::model::robot::Robot;

/// Standard gravity, m/s^2: a mass `m` weighs `m g` newtons, the `g` of the
/// built-in robot files, of `sagcal init` and of every range here.
pub const STANDARD_GRAVITY_M_S2: f64 = 9.81;
const GRAVITY: f64 = STANDARD_GRAVITY_M_S2;

/// The lightest plausible platform, newtons: 1 g, lighter than any that can
/// carry four cable attachment points.
pub const MIN_PLATFORM_WEIGHT_N: f64 = 1e-3 * GRAVITY;

/// The heaviest plausible platform, newtons: 1000 t, over 30 times the
/// heaviest platform hung from cables (the 30 t feed cabin of the FAST radio
/// telescope).
pub const MAX_PLATFORM_WEIGHT_N: f64 = 1e6 * GRAVITY;

/// The heaviest plausible cable, newtons per metre: a solid steel bar 200 mm
/// thick (`pi (0.1 m)^2 7850 kg/m^3 g`, 2.42 kN/m); a wire rope of that
/// diameter, about the thickest made, is lighter, since it is not solid.
pub const MAX_CABLE_WEIGHT_N_PER_M: f64 = std::f64::consts::PI * 0.1 * 0.1 * 7850.0 * GRAVITY;

/// At most this many platforms' weight in four cables each as long as the
/// anchors' spread (the largest distance between two anchors): heavier, the
/// cables hang in the shape of their own weight, the platform hardly
/// shapes them, and no suspended robot is built so (the paper's large robot
/// is at 2.8, its small one at 0.12).
pub const MAX_CABLE_TO_PLATFORM_WEIGHT: f64 = 100.0;

/// A pulley's radius is at most this fraction of the distance between the
/// two closest anchors: the cable leaves the pulley up to two radii from its
/// anchor, so at a tenth the exit points stay a fifth of the way to the
/// neighbour's and the point-anchor model stays a perturbation of the truth.
pub const MAX_PULLEY_FRACTION: f64 = 0.1;

/// The largest and the smallest distance between two anchors, metres, with
/// the closest pair (0-based).
fn anchor_distances(robot: &Robot) -> (f64, f64, (usize, usize)) {
    let a = &robot.anchors_m;
    let mut largest = 0.0f64;
    let mut smallest = (f64::INFINITY, (0, 1));
    for i in 0..a.len() {
        for j in i + 1..a.len() {
            let d = (a[i] - a[j]).norm();
            largest = largest.max(d);
            if d < smallest.0 {
                smallest = (d, (i, j));
            }
        }
    }
    (largest, smallest.0, smallest.1)
}

/// Check the platform's and the cables' weights against the plausible
/// ranges (module docs). The error names the field, the value, the range and why.
pub fn check_masses(robot: &Robot) -> Result<(), String> {
    let w = robot.platform_weight_n;
    if !(MIN_PLATFORM_WEIGHT_N..=MAX_PLATFORM_WEIGHT_N).contains(&w) {
        return Err(format!(
            "field `platform_weight_n`: {w:e} N is outside the plausible {MIN_PLATFORM_WEIGHT_N:.3e} .. {MAX_PLATFORM_WEIGHT_N:.3e} N \
             (1 g .. 1000 t): a lighter platform cannot carry four cable attachments, and 1000 t is over 30 times the \
             heaviest platform hung from cables (the 30 t feed cabin of the FAST telescope); the weight is m g in newtons"
        ));
    }
    let g_c = robot.cable_weight_n_per_m;
    if g_c > MAX_CABLE_WEIGHT_N_PER_M {
        return Err(format!(
            "field `cable_weight_n_per_m`: {g_c:e} N/m is above {MAX_CABLE_WEIGHT_N_PER_M:.0} N/m, the weight of a solid \
             steel bar 200 mm thick: no rope weighs more per metre; the weight is rho_c g in newtons per metre"
        ));
    }
    let (spread, _, _) = anchor_distances(robot);
    let cables_n = 4.0 * g_c * spread;
    if cables_n > MAX_CABLE_TO_PLATFORM_WEIGHT * w {
        return Err(format!(
            "fields `cable_weight_n_per_m` and `platform_weight_n`: four cables of {g_c} N/m as long as the anchors' \
             {spread:.3} m spread weigh {cables_n:.4e} N, {:.3e} times the platform's {w} N (at most {MAX_CABLE_TO_PLATFORM_WEIGHT}): \
             such cables hang in the shape of their own weight, the platform hardly shapes them, and no suspended \
             robot is built so (the paper's large robot: 2.8)",
            cables_n / w
        ));
    }
    Ok(())
}

/// Check `effects` against `robot`'s size (module docs): the pulley radius
/// at most [`MAX_PULLEY_FRACTION`] of the closest anchors' distance, and no
/// attachment moved by more than the platform's attachment radius.
pub fn check_effects(robot: &Robot, effects: &Effects) -> Result<(), String> {
    let (_, closest, (i, j)) = anchor_distances(robot);
    let r = effects.pulley_radius_m;
    if r > MAX_PULLEY_FRACTION * closest {
        return Err(format!(
            "field `pulley_radius_m`: {r} m is over a tenth of the {closest:.3} m between anchors {} and {} (the \
             closest): the cable leaves a pulley up to two radii from its anchor, so pulleys that large near-touch \
             their neighbours and no longer act as the anchor points the model has",
            i + 1,
            j + 1
        ));
    }
    let platform_radius_m = robot.attachments_m.iter().map(|b| b.x.hypot(b.y)).fold(0.0, f64::max);
    if let Some((k, [dx, dy])) = effects
        .attachment_shift_m
        .iter()
        .enumerate()
        .find(|(_, [dx, dy])| dx.hypot(*dy) > platform_radius_m)
    {
        return Err(format!(
            "field `attachment_shift_m`: attachment {} moved by {:.3} m, more than the platform's attachment \
             radius of {platform_radius_m:.3} m: the point would no longer be on the platform",
            k + 1,
            dx.hypot(*dy)
        ));
    }
    check_masses(&crate::model::robot::with_true_weights(robot, effects)).map_err(|e| {
        format!(
            "with `platform_weight_scale` {} and `cable_weight_scale` {} the robot's true weights: {e}",
            effects.platform_weight_scale, effects.cable_weight_scale
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::effect_ranges::pulley_radius_range_m;

    #[test]
    fn the_ranges_are_what_their_docs_say() {
        assert!((MIN_PLATFORM_WEIGHT_N - 0.00981).abs() < 1e-15);
        assert!((MAX_PLATFORM_WEIGHT_N - 9.81e6).abs() < 1e-6);
        // 7850 kg/m^3 x 0.0314 m^2 = 246.6 kg/m.
        assert!((MAX_CABLE_WEIGHT_N_PER_M / GRAVITY - 246.615).abs() < 1e-3);
    }

    #[test]
    fn the_shipped_robots_and_their_simulated_effects_are_plausible() {
        for name in ["large", "small"] {
            let robot = Robot::builtin(name).unwrap();
            check_masses(&robot).unwrap();
            let (spread, closest, _) = anchor_distances(&robot);
            let ratio = 4.0 * robot.cable_weight_n_per_m * spread / robot.platform_weight_n;
            assert!(ratio < 3.0, "{name}: {ratio}");
            // The hidden-effect experiment's largest pulley stays under the limit with room.
            let (_, largest) = pulley_radius_range_m(&robot);
            let mut effects = robot.effects;
            effects.pulley_radius_m = largest;
            check_effects(&robot, &effects).unwrap();
            // A true weight beyond the plausible range is refused, naming the scale.
            effects.cable_weight_scale = 1e6;
            let message = check_effects(&robot, &effects).unwrap_err();
            assert!(
                message.contains("cable_weight_scale") && message.contains("cable_weight_n_per_m"),
                "{message}"
            );
            assert!(
                largest < 0.2 * MAX_PULLEY_FRACTION * closest,
                "{name}: {largest} m against {closest} m"
            );
        }
    }

    #[test]
    fn the_issues_values_are_refused_with_the_range() {
        let robot = Robot::builtin("large").unwrap();
        let mut heavy = robot.clone();
        heavy.cable_weight_n_per_m = 1e6;
        assert!(check_masses(&heavy).unwrap_err().contains("above 2419 N/m"));
        // Within the absolute range but 32 kN of cable on a 333.54 N platform: 96 x.
        heavy.cable_weight_n_per_m = 24.0;
        assert!(check_masses(&heavy).is_ok());
        heavy.cable_weight_n_per_m = 26.0;
        let message = check_masses(&heavy).unwrap_err();
        assert!(message.contains("1.038e2 times the platform's 333.54 N"), "{message}");
        let mut light = robot.clone();
        light.platform_weight_n = 1e-300;
        assert!(check_masses(&light)
            .unwrap_err()
            .starts_with("field `platform_weight_n`: 1e-300 N is outside"));
        light.platform_weight_n = 9e6;
        assert!(check_masses(&light).is_ok());
        light.platform_weight_n = 1e7;
        assert!(check_masses(&light).is_err());
        // Massless cables are the straight-line limit, always plausible.
        light.platform_weight_n = MIN_PLATFORM_WEIGHT_N;
        light.cable_weight_n_per_m = 0.0;
        assert!(check_masses(&light).is_ok());
    }

    #[test]
    fn a_pulley_is_checked_against_the_closest_anchors() {
        let robot = Robot::builtin("small").unwrap();
        let mut effects = robot.effects;
        effects.pulley_radius_m = 0.45;
        assert!(check_effects(&robot, &effects).is_ok(), "4.5 m apart: up to 0.45 m");
        effects.pulley_radius_m = 0.46;
        let message = check_effects(&robot, &effects).unwrap_err();
        assert!(message.contains("the 4.500 m between anchors 1 and 4"), "{message}");
    }

    #[test]
    fn an_attachment_stays_on_the_platform() {
        let robot = Robot::builtin("large").unwrap();
        let radius = 0.21 * 2f64.sqrt();
        let mut effects = robot.effects;
        effects.attachment_shift_m[2] = [0.99 * radius, 0.0];
        assert!(check_effects(&robot, &effects).is_ok());
        effects.attachment_shift_m[2] = [0.0, -1.01 * radius];
        let message = check_effects(&robot, &effects).unwrap_err();
        assert!(message.contains("attachment 3 moved by 0.300 m"), "{message}");
    }
}

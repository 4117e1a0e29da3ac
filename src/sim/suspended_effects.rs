//! Simulated data of a robot of 3 to 8 cables with physical effects the
//! closed-form model lacks, through the discretised simulator
//! ([`super::discretised_suspended`]), as [`super::effects`] does for four
//! cables.
//!
//! The robot is commanded to each closed-form equilibrium's cable lengths:
//! the drums pay them out (less each elastic cable's stretch where the
//! robot file gives its stiffness, [`SuspendedEquilibrium::paid_out_lengths_m`]:
//! the controller knows the cables it was given). The discretised robot (elastic cables, pulley
//! wrap, finite elements, a shifted centre of mass, another platform or
//! cable weight than its file says) settles where it settles under those
//! lengths; that pose is the truth the localiser sees (through its
//! mounting). Each encoder reads its paid-out length through its gain plus
//! its offset, each load cell its cable's force at the platform through the
//! load cell's bias and gain.
//!
//! The effects of the catalogue ([`Effects`], the `--effect` specs) that act
//! on every cable alike are simulated; those written per drum of the
//! four-cable robot (encoder drift and backlash, a load cell's drift or
//! friction, moved attachments, per-drum encoder gains) are refused with
//! the reason, not dropped.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::model::effects::Effects;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! use sagcal::sim::closed_form::Closure;
//! use sagcal::sim::suspended::sample_suspended;
//! use sagcal::sim::suspended_effects::measure_suspended_with_effects;
//! let robot = SuspendedRobot::builtin("six")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
//! let poses = sample_suspended(&robot, &robot.workspace.unwrap(), 2, Closure::Level, &mut rng)?;
//! let mut effects = Effects::default();
//! effects.apply_spec("encoder-scale:gain=1.002")?;
//! let noise = NoisePreset::None.sigmas(robot.platform_weight_n);
//! let rows = measure_suspended_with_effects(&robot, &effects, &poses, &noise, 50, &mut rng)?;
//! // The drums pay out the commanded lengths; the encoders read them 0.2 % long.
//! for (reading, length) in rows[0].encoder_lengths_m.iter().zip(&poses[0].cable_lengths_m) {
//!     assert!((reading - 1.002 * length).abs() < 1e-9);
//! }
//! // A drum-by-drum effect of the four-cable catalogue is refused, not dropped.
//! effects.apply_spec("encoder-backlash:b_m=0.002")?;
//! let refused = measure_suspended_with_effects(&robot, &effects, &poses, &noise, 50, &mut rng).unwrap_err();
//! assert!(refused.to_string().contains("encoder-backlash"), "{refused}");
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;
use rand::Rng;

use super::closed_form::SensorSampler;
use super::discretised::MAX_SEGMENTS;
use super::discretised_suspended::{
    closed_form_forces, solve_forward_suspended, SuspendedDiscretisedEquilibrium, SuspendedDiscretisedOptions,
};
use super::effects::localiser_reading;
use super::suspended::read_suspended_row;
use crate::error::{Error, FrontEnd, Result};
use crate::model::effects::Effects;
use crate::model::sensors::SensorNoise;
use crate::model::suspended::{SuspendedEquilibrium, SuspendedMeasurement, SuspendedRobot};

/// The effect specs whose parameters are written per drum of the
/// four-cable robot, and why a robot of `N` cables refuses them; `None`
/// when every effect in `effects` can be simulated on `N` cables.
pub fn unsupported_effect(effects: &Effects) -> Option<&'static str> {
    let default = Effects::default();
    let gains = &effects.encoder_gain;
    if gains.iter().any(|g| *g != gains[0]) {
        return Some("encoder-scale with gain1 .. gain4 (one gain per drum of four): give `gain` for every cable");
    }
    let per_drum = [
        (
            effects.encoder_drift_m_per_row != default.encoder_drift_m_per_row,
            "encoder-drift (written per drum of four cables)",
        ),
        (
            effects.encoder_backlash_m != default.encoder_backlash_m,
            "encoder-backlash (written per drum of four cables)",
        ),
        (
            effects.load_cell_drift_n_per_row != default.load_cell_drift_n_per_row,
            "loadcell-drift (the reference cable's load cell of four cables)",
        ),
        (
            effects.load_cell_friction != default.load_cell_friction,
            "loadcell-friction (the reference cable's load cell of four cables)",
        ),
        (
            effects.attachment_shift_m != default.attachment_shift_m,
            "attachments (written per attachment of four cables)",
        ),
    ];
    per_drum.into_iter().find(|(set, _)| *set).map(|(_, name)| name)
}

/// The robot as it truly is under `effects`: the platform's weight and
/// every cable's weight per metre scaled (`platform-weight`, `cable-weight`).
pub fn weighed_suspended(robot: &SuspendedRobot, effects: &Effects) -> SuspendedRobot {
    SuspendedRobot {
        platform_weight_n: robot.platform_weight_n * effects.platform_weight_scale,
        cable_weights_n_per_m: robot
            .cable_weights_n_per_m
            .iter()
            .map(|w| w * effects.cable_weight_scale)
            .collect(),
        ..robot.clone()
    }
}

/// The discretised model's settings for `effects` on `robot`, `segments`
/// segments per cable (or a finite-element cable's own count,
/// `effects.cable_segments`, rounded): every cable with the effects' `EA`
/// (else its own from the robot file) and pulley radius, the centre of
/// mass shifted.
pub fn suspended_discretised_options(
    robot: &SuspendedRobot,
    effects: &Effects,
    segments: usize,
) -> SuspendedDiscretisedOptions {
    let cables = robot.cable_count();
    SuspendedDiscretisedOptions {
        segments: effects.cable_segments.map_or(segments, |n| n.round().max(1.0) as usize),
        axial_stiffness_n: robot
            .axial_stiffness_n
            .iter()
            .map(|own| effects.axial_stiffness_n.unwrap_or(*own))
            .collect(),
        pulley_radius_m: vec![effects.pulley_radius_m; cables],
        com_offset_m: Some(robot.com_offset_m + Vector3::from(effects.com_shift_m)),
        ..SuspendedDiscretisedOptions::inextensible(cables, segments)
    }
}

/// The discretised robot's equilibrium under each closed-form equilibrium's
/// paid-out lengths ([`SuspendedEquilibrium::paid_out_lengths_m`]); a pose whose solve fails is an error
/// naming the pose (1-based) and its commanded position.
pub fn solve_suspended_with_effects(
    robot: &SuspendedRobot,
    effects: &Effects,
    equilibria: &[SuspendedEquilibrium],
    segments: usize,
) -> Result<Vec<SuspendedDiscretisedEquilibrium>> {
    let context = |message: String| Error::InvalidInput(format!("robot `{}`: {message}", robot.name));
    effects.validate().map_err(|e| context(format!("effects: {e}")))?;
    if let Some(refused) = unsupported_effect(effects) {
        return Err(context(format!(
            "{} cables: the effect {refused} is not simulated on robots of 3 to 8 cables",
            robot.cable_count()
        )));
    }
    if !(1..=MAX_SEGMENTS).contains(&segments) {
        return Err(context(format!(
            "segments must be between 1 and {MAX_SEGMENTS}, got {segments}"
        )));
    }
    let options = suspended_discretised_options(robot, effects, segments);
    let truth = weighed_suspended(robot, effects);
    equilibria
        .iter()
        .enumerate()
        .map(|(k, eq)| {
            let guess = closed_form_forces(robot, eq);
            let commanded = eq.paid_out_lengths_m(robot);
            solve_forward_suspended(&truth, &options, &commanded, &eq.pose, Some(&guess)).map_err(|e| {
                let p = eq.pose.position_m;
                context(format!(
                    "pose {} (commanded position [{:.3}, {:.3}, {:.3}] m): the discretised robot with effects \
                     `{effects}` ({} segments) has no equilibrium: {e}",
                    k + 1,
                    p.x,
                    p.y,
                    p.z,
                    options.segments
                ))
            })
        })
        .collect()
}

/// The effects of `specs` (`NAME:PARAM=VALUE[,PARAM=VALUE...]`,
/// [`Effects::apply_spec`]) applied in order to no effect; a bad spec is
/// named as `front_end` spells the option (the command's repeatable
/// `--effect`, Python's list `effects`).
pub fn effects_from_specs(specs: &[String], front_end: FrontEnd) -> Result<Effects> {
    let option = match front_end {
        FrontEnd::Cli => "--effect",
        FrontEnd::Python => "effects",
    };
    let mut effects = Effects::default();
    for spec in specs {
        effects
            .apply_spec(spec)
            .map_err(|e| Error::InvalidInput(format!("{option} `{spec}`: {e}")))?;
    }
    Ok(effects)
}

/// The readings of a simulation of `robot` at `equilibria`: the
/// closed-form model's ([`super::suspended::measure_suspended`]) without
/// effects on inextensible cables, the discretised robot's
/// ([`measure_suspended_with_effects`]) with effects or elastic cables
/// (whose drums pay out the closed-form lengths and which stretch under
/// them).
pub fn simulate_readings(
    robot: &SuspendedRobot,
    effects: &Effects,
    equilibria: &[SuspendedEquilibrium],
    noise: &SensorNoise,
    segments: usize,
    rng: &mut impl Rng,
) -> Result<Vec<SuspendedMeasurement>> {
    if effects.is_none() && !robot.is_elastic() {
        return super::suspended::measure_suspended(robot, equilibria, noise, rng);
    }
    measure_suspended_with_effects(robot, effects, equilibria, noise, segments, rng)
}

/// What the robot's sensors read with `effects` acting, the robot commanded
/// to the cable lengths of `equilibria` (module docs), the noise drawn in
/// the order of [`super::suspended::measure_suspended`] (so with no effect
/// the same seed gives the same noise). Every pose is solved before any
/// noise is drawn.
pub fn measure_suspended_with_effects(
    robot: &SuspendedRobot,
    effects: &Effects,
    equilibria: &[SuspendedEquilibrium],
    noise: &SensorNoise,
    segments: usize,
    rng: &mut impl Rng,
) -> Result<Vec<SuspendedMeasurement>> {
    let solved = solve_suspended_with_effects(robot, effects, equilibria, segments)?;
    let sensors = SensorSampler::new(noise);
    let gain = effects.encoder_gain[0];
    Ok(solved
        .iter()
        .map(|eq| {
            let lengths = eq
                .paid_out_lengths_m
                .iter()
                .zip(&robot.length_offsets_m)
                .map(|(paid_out, offset)| gain * paid_out + offset);
            let tensions = robot.load_cells.iter().map(|&cable| {
                effects.load_cell_bias_n + effects.load_cell_gain * eq.cables[cable].platform_force_n.norm()
            });
            read_suspended_row(&sensors, &localiser_reading(&eq.pose, effects), lengths, tensions, rng)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::sensors::NoisePreset;
    use crate::sim::closed_form::Closure;
    use crate::sim::suspended::sample_suspended;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn poses(robot: &SuspendedRobot, count: usize, seed: u64) -> Vec<SuspendedEquilibrium> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        sample_suspended(robot, &robot.workspace.unwrap(), count, Closure::Level, &mut rng).unwrap()
    }

    /// An elastic robot commanded to its paid-out lengths (the catenary's
    /// less Irvine's first-order stretch) settles where the closed-form
    /// model drew it: within the second-order stretch `l (T / EA)^2` on
    /// weightless cables, within the height the first order leaves
    /// (`g_c l^2 / 2EA` and the chain's `1/n^2`) on heavy ones; commanded the
    /// inextensible lengths, it hangs millimetres lower.
    #[test]
    fn an_elastic_robot_settles_at_the_pose_its_paid_out_lengths_hold() {
        for (name, weightless, bound_m) in [("three", true, 2e-5), ("eight", true, 2e-5), ("eight", false, 2e-4)] {
            let mut robot = SuspendedRobot::builtin(name).unwrap();
            if weightless {
                robot.cable_weights_n_per_m = vec![0.0; robot.cable_count()];
            }
            robot.axial_stiffness_n = vec![2e6; robot.cable_count()];
            let equilibria = poses(&robot, 5, 8);
            let settled = solve_suspended_with_effects(&robot, &Effects::default(), &equilibria, 40).unwrap();
            let mut worst: f64 = 0.0;
            for (eq, truth) in equilibria.iter().zip(&settled) {
                worst = worst.max((truth.pose.position_m - eq.pose.position_m).norm());
                let paid_out = eq.paid_out_lengths_m(&robot);
                assert_eq!(truth.paid_out_lengths_m, paid_out);
                assert!(eq.cable_lengths_m.iter().zip(&paid_out).all(|(l, p)| l - p > 1e-4));
            }
            assert!(worst < bound_m, "{name}, weightless {weightless}: {worst} m");
            // The same chains paid out the inextensible lengths sag further.
            let options = suspended_discretised_options(&robot, &Effects::default(), 40);
            let eq = &equilibria[0];
            let guess = closed_form_forces(&robot, eq);
            let sagged =
                solve_forward_suspended(&robot, &options, &eq.cable_lengths_m, &eq.pose, Some(&guess)).unwrap();
            let drop_m = eq.pose.position_m.z - sagged.pose.position_m.z;
            println!("{name}, weightless {weightless}: settled within {worst:.1e} m; {drop_m:.1e} m lower on the inextensible lengths");
            assert!(drop_m > 10.0 * worst, "{name}: {drop_m} m");
        }
    }

    /// With no effect the chains' readings approach the closed-form
    /// readings as the segments grow (`O(1/n^2)`), and the noise is the
    /// closed-form simulation's draw for draw.
    #[test]
    fn no_effect_is_the_closed_form_data_in_the_limit() {
        let robot = SuspendedRobot::builtin("eight").unwrap();
        let equilibria = poses(&robot, 3, 4);
        let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
        let closed =
            crate::sim::suspended::measure_suspended(&robot, &equilibria, &noise, &mut ChaCha8Rng::seed_from_u64(9))
                .unwrap();
        let gap = |segments: usize| {
            let rows = measure_suspended_with_effects(
                &robot,
                &Effects::default(),
                &equilibria,
                &noise,
                segments,
                &mut ChaCha8Rng::seed_from_u64(9),
            )
            .unwrap();
            let mut worst: f64 = 0.0;
            for (a, b) in rows.iter().zip(&closed) {
                assert_eq!(
                    a.encoder_lengths_m, b.encoder_lengths_m,
                    "the encoders read the commanded lengths"
                );
                worst = worst.max((Vector3::from(a.position_m) - Vector3::from(b.position_m)).norm());
            }
            worst
        };
        let (coarse, fine) = (gap(20), gap(40));
        assert!((3.5..4.5).contains(&(coarse / fine)), "{coarse} -> {fine}");
    }

    /// Sensor effects read as their specs say: every load cell through
    /// the bias and gain, a shifted centre of mass tilts the platform.
    #[test]
    fn sensor_and_platform_effects_act_on_every_cable() {
        let mut robot = SuspendedRobot::builtin("six").unwrap();
        robot.load_cells = vec![0, 3];
        let equilibria = poses(&robot, 2, 6);
        let none = NoisePreset::None.sigmas(robot.platform_weight_n);
        let mut effects = Effects::default();
        effects.apply_spec("loadcell:bias_n=15,gain=1.02").unwrap();
        effects.apply_spec("com:dx_m=0.1").unwrap();
        let solved = solve_suspended_with_effects(&robot, &effects, &equilibria, 30).unwrap();
        let rows = measure_suspended_with_effects(
            &robot,
            &effects,
            &equilibria,
            &none,
            30,
            &mut ChaCha8Rng::seed_from_u64(1),
        )
        .unwrap();
        for (row, eq) in rows.iter().zip(&solved) {
            for (reading, &cable) in row.load_cell_tensions_n.iter().zip(&robot.load_cells) {
                let force = eq.cables[cable].platform_force_n.norm();
                assert!((reading - (15.0 + 1.02 * force)).abs() < 1e-9 * force);
            }
            let (roll, pitch, _) = eq.pose.roll_pitch_yaw_deg();
            assert!(
                roll.abs().max(pitch.abs()) > 0.01,
                "a 10 cm shift tilts the platform: {roll}, {pitch}"
            );
        }
    }
}

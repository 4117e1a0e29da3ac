//! Simulated calibration data with physical effects the closed-form model
//! lacks ([`Effects`]), generated through the discretised simulator
//! ([`crate::sim::discretised`]).
//!
//! The robot is commanded to each closed-form equilibrium's cable lengths: the
//! drums pay out `eq.cable_lengths_m`. The discretised robot (elastic cables,
//! pulley wrap, shifted centre of mass) settles where it settles under those
//! paid-out lengths; that pose is the truth the localiser sees. The encoders
//! read the paid-out lengths through their gains, the load cell the reference
//! cable's force at the platform through its bias and gain.
//!
//! With no effect the discretised robot converges to the closed-form one as
//! `O(1/n^2)` in the segment count `n`, and so do the data.

use nalgebra::{UnitQuaternion, Vector3};
use rand::Rng;

use crate::error::{Error, Result};
use crate::model::effects::Effects;
use crate::model::measurement::PoseMeasurement;
use crate::model::pose::PlatformPose;
use crate::model::robot::Robot;
use crate::model::sensors::SensorNoise;
use crate::model::statics::Equilibrium;
use crate::sim::closed_form::SensorSampler;
use crate::sim::discretised::{solve_forward, DiscretisedEquilibrium, DiscretisedOptions, InitialGuess};

/// The discretised model's settings for `effects` with `segments` segments
/// per cable, or, for a finite-element cable (`effects.cable_segments`), its
/// own number of elements rounded to a whole number.
pub fn discretised_options(robot: &Robot, effects: &Effects, segments: usize) -> DiscretisedOptions {
    DiscretisedOptions {
        segments: effects.cable_segments.map_or(segments, |n| n.round().max(1.0) as usize),
        axial_stiffness_n: effects.axial_stiffness_n.unwrap_or(f64::INFINITY),
        pulley_radius_m: effects.pulley_radius_m,
        com_offset_m: Some(robot.com_offset_m + Vector3::from(effects.com_shift_m)),
        ..DiscretisedOptions::default()
    }
}

/// The discretised robot's equilibrium under each closed-form equilibrium's
/// cable lengths as paid-out lengths. A pose whose solve fails is an error
/// naming the pose (1-based) and its commanded position.
pub fn solve_with_effects(
    robot: &Robot,
    effects: &Effects,
    equilibria: &[Equilibrium],
    segments: usize,
) -> Result<Vec<DiscretisedEquilibrium>> {
    effects
        .validate()
        .map_err(|e| Error::InvalidInput(format!("effects: {e}")))?;
    let options = discretised_options(robot, effects, segments);
    equilibria
        .iter()
        .enumerate()
        .map(|(k, eq)| {
            solve_forward(
                robot,
                &options,
                &eq.cable_lengths_m,
                &InitialGuess::from_closed_form(robot, eq),
            )
            .map_err(|e| {
                let p = eq.pose.position_m;
                Error::InvalidInput(format!(
                    "pose {} (commanded position [{:.3}, {:.3}, {:.3}] m, cable lengths {:?} m): \
                     the discretised robot with effects `{effects}` ({segments} segments) has no equilibrium: {e}",
                    k + 1,
                    p.x,
                    p.y,
                    p.z,
                    eq.cable_lengths_m
                ))
            })
        })
        .collect()
}

/// What the robot's sensors read with `effects` acting, the robot commanded
/// to the cable lengths of `equilibria` (module docs): localiser pose = the
/// discretised equilibrium's pose perturbed on its tangent space; encoder
/// `i` = `encoder_gain[i] * paid_out_i + length_offsets_m[i]` + noise; load
/// cell = `load_cell_bias_n + load_cell_gain * |F_ref|` + noise with `F_ref`
/// (a mounted localiser reads `R Exp(m)`, [`localiser_reading`])
/// the reference cable's force on the platform. The random numbers are drawn
/// in the order of [`crate::sim::closed_form::measure`], so with no effect the
/// same seed gives the same noise. Every pose is solved before any noise is
/// drawn; a pose without an equilibrium is an error naming it (nothing is skipped).
pub fn measure_with_effects(
    robot: &Robot,
    effects: &Effects,
    equilibria: &[Equilibrium],
    noise: &SensorNoise,
    segments: usize,
    rng: &mut impl Rng,
) -> Result<Vec<PoseMeasurement>> {
    let solved = solve_with_effects(robot, effects, equilibria, segments)?;
    let sensors = SensorSampler::new(noise);
    Ok(solved
        .iter()
        .map(|eq| {
            let lengths =
                std::array::from_fn(|i| effects.encoder_gain[i] * eq.paid_out_lengths_m[i] + robot.length_offsets_m[i]);
            let force = eq.cables[robot.reference_cable].platform_force_n.norm();
            let tension = effects.load_cell_bias_n + effects.load_cell_gain * force;
            sensors.read(&localiser_reading(&eq.pose, effects), lengths, tension, rng)
        })
        .collect())
}

/// The pose a localiser mounted with `effects.localiser_mount_deg` reports at
/// `pose` before its noise: its own body's orientation `R Exp(m)` (`m` the
/// mount's rotation vector in the platform frame) at the platform origin.
pub fn localiser_reading(pose: &PlatformPose, effects: &Effects) -> PlatformPose {
    let mount = Vector3::from(effects.localiser_mount_deg.map(f64::to_radians));
    PlatformPose {
        rotation: pose.rotation * UnitQuaternion::from_scaled_axis(mount),
        ..*pose
    }
}

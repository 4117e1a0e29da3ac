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
//!
//! ```
//! use nalgebra::Vector3;
//! use rand::SeedableRng;
//! use sagcal::model::effects::Effects;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::statics::{solve_level, StaticsOptions};
//! use sagcal::model::Robot;
//! use sagcal::sim::effects::{localiser_reading, measure_with_effects};
//! let robot = Robot::builtin("large")?;
//! let commanded = solve_level(&robot, Vector3::new(4.0, -2.0, 15.0), &StaticsOptions::default())?;
//! let mut effects = Effects::default();
//! effects.apply_spec("encoder-scale:gain=1.002")?;
//! effects.apply_spec("loadcell:bias_n=12")?;
//! let noise = NoisePreset::None.sigmas(robot.platform_weight_n);
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
//! let read = measure_with_effects(&robot, &effects, &[commanded.clone()], &noise, 20, &mut rng)?;
//! // The drums pay out the commanded lengths; the encoders read them 0.2 % long.
//! for i in 0..4 {
//!     assert!((read[0].encoder_lengths_m[i] - 1.002 * commanded.cable_lengths_m[i]).abs() < 1e-9);
//! }
//! // The load cell reads the 20-element chain's force (within 0.1 % of the catenary's) plus its bias.
//! let tension = commanded.tensions[robot.reference_cable].magnitude_n();
//! assert!((read[0].reference_tension_n - 12.0 - tension).abs() < 1e-3 * tension);
//! // A localiser mounted turned by m reports R Exp(m): |m| away from the platform.
//! effects.apply_spec("localiser-mount:rx_deg=3,ry_deg=4")?;
//! assert!((localiser_reading(&commanded.pose, &effects).angle_to_deg(&commanded.pose) - 5.0).abs() < 1e-9);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{UnitQuaternion, Vector3};
use rand::Rng;

use crate::error::{Error, FrontEnd, Result};
use crate::model::effects::Effects;
use crate::model::measurement::{mark_time_order, PoseMeasurement, ReadingOrder};
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::model::statics::Equilibrium;
use crate::sim::closed_form::SensorSampler;
use crate::sim::discretised::{solve_forward, DiscretisedEquilibrium, DiscretisedOptions, InitialGuess, MAX_SEGMENTS};

/// The true robot of a simulation of `poses` poses: `robot` with each of
/// `specs` (`NAME:PARAM=VALUE[,PARAM=VALUE...]`, [`Effects::apply_spec`])
/// applied in order, checked as `sagcal simulate` checks its flags: at least
/// 1 pose, every spec valid and, with effects (the robot's or the specs'),
/// 1 to [`MAX_SEGMENTS`] segments per cable. A message names the option as
/// `front_end` spells it (the command's repeatable `--effect`, Python's list `effects`).
///
/// ```
/// use sagcal::error::FrontEnd;
/// use sagcal::model::Robot;
/// use sagcal::sim::effects::simulation_truth;
/// let robot = Robot::builtin("large")?;
/// let truth = simulation_truth(&robot, 5, &["elastic:ea_n=3e6".into()], 50, FrontEnd::Cli)?;
/// assert_eq!(truth.effects.axial_stiffness_n, Some(3e6));
/// let message = simulation_truth(&robot, 0, &[], 50, FrontEnd::Python).unwrap_err().to_string();
/// assert_eq!(message, "invalid input: poses must be at least 1");
/// # Ok::<(), sagcal::Error>(())
/// ```
pub fn simulation_truth(
    robot: &Robot,
    poses: usize,
    specs: &[String],
    segments: usize,
    front_end: FrontEnd,
) -> Result<Robot> {
    if poses == 0 {
        return Err(Error::InvalidInput(format!(
            "{} must be at least 1",
            front_end.option("poses")
        )));
    }
    let mut truth = robot.clone();
    let effect = match front_end {
        FrontEnd::Cli => "--effect",
        FrontEnd::Python => "effects",
    };
    for spec in specs {
        truth
            .effects
            .apply_spec(spec)
            .map_err(|e| Error::InvalidInput(format!("{effect} `{spec}`: {e}")))?;
    }
    if !truth.effects.is_none() && !(1..=MAX_SEGMENTS).contains(&segments) {
        return Err(Error::InvalidInput(format!(
            "{} must be between 1 and {MAX_SEGMENTS}, got {segments}",
            front_end.option("segments")
        )));
    }
    Ok(truth)
}

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

/// The robot as it truly is under `effects`' errors of the robot file: the
/// platform's weight and the cables' weight per metre scaled
/// (`platform-weight`, `cable-weight`), the attachment points moved
/// (`attachments`); the commanded cable lengths still come from the robot
/// file, as a controller's would.
pub fn weighed(robot: &Robot, effects: &Effects) -> Robot {
    crate::model::robot::with_true_attachments(&crate::model::robot::with_true_weights(robot, effects), effects)
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
    crate::model::plausibility::check_effects(robot, effects)
        .map_err(|e| Error::InvalidInput(format!("effects on robot `{}`: {e}", robot.name)))?;
    let options = discretised_options(robot, effects, segments);
    let true_robot = weighed(robot, effects);
    equilibria
        .iter()
        .enumerate()
        .map(|(k, eq)| {
            solve_forward(
                &true_robot,
                &options,
                &eq.cable_lengths_m,
                &InitialGuess::from_closed_form(&true_robot, eq),
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
///
/// The robot visits the equilibria in their order, so the effects of time
/// and motion ([`Effects::time_and_motion`]) act with the row and each
/// cable's true direction of last motion: the sign of its paid-out length's
/// change since the previous pose, and for the first pose since the middle
/// of the poses' lengths (where the robot starts). The rows come back marked
/// as a reader marks a measurement file's ([`mark_time_order`]: directions
/// from the readings, none for the first row).
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
    let orders = true_orders(&solved);
    let mut rows: Vec<PoseMeasurement> = solved
        .iter()
        .zip(&orders)
        .map(|(eq, order)| {
            let now = effects.time_and_motion(order, robot.reference_cable);
            let lengths = std::array::from_fn(|i| {
                effects.encoder_gain[i] * eq.paid_out_lengths_m[i] + robot.length_offsets_m[i] + now.encoder_shift_m[i]
            });
            let force = eq.cables[robot.reference_cable].platform_force_n.norm();
            let tension = effects.load_cell_bias_n
                + effects.load_cell_gain * now.load_cell_factor * force
                + now.load_cell_shift_n;
            sensors.read(&localiser_reading(&eq.pose, effects), lengths, tension, rng)
        })
        .collect();
    mark_time_order(&mut rows);
    Ok(rows)
}

/// Each pose's row and each cable's true direction of last motion (module
/// docs of [`measure_with_effects`]): the paid-out length's change since the
/// previous pose, the first pose's since the mean over the poses.
fn true_orders(solved: &[DiscretisedEquilibrium]) -> Vec<ReadingOrder> {
    let count = solved.len().max(1) as f64;
    let start: [f64; CABLE_COUNT] =
        std::array::from_fn(|i| solved.iter().map(|eq| eq.paid_out_lengths_m[i]).sum::<f64>() / count);
    let mut previous = start;
    solved
        .iter()
        .enumerate()
        .map(|(k, eq)| {
            let direction = std::array::from_fn(|i| {
                let change = eq.paid_out_lengths_m[i] - previous[i];
                if change > 0.0 {
                    1
                } else if change < 0.0 {
                    -1
                } else {
                    0
                }
            });
            previous = eq.paid_out_lengths_m;
            ReadingOrder { row: k + 1, direction }
        })
        .collect()
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

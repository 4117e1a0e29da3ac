//! Simulated calibration data from the closed-form kineto-static model.
//!
//! Poses are drawn uniformly in a workspace box; at each position the robot's
//! static equilibrium is one member of the one-parameter family (see
//! [`crate::model::statics`]): sagcal takes the most level one
//! ([`statics::solve_level`]) with its reference tension scaled by a random
//! factor in `[0.98, 1.02]`, which keeps the platform within a few degrees of
//! level and the tensions as even as in the RecurDyn log. Positions without a
//! positive-tension equilibrium are redrawn.

use nalgebra::{Vector3, Vector6};
use rand::Rng;
use rand_distr::{Distribution, Normal};

use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::model::statics::{self, Equilibrium, StaticsOptions};

pub use crate::model::robot::Workspace;

impl Workspace {
    /// The robot file's `[workspace]` if it has one, else [`Workspace::around_anchors`].
    pub fn default_for(robot: &Robot) -> Self {
        robot.workspace.unwrap_or_else(|| Self::around_anchors(robot))
    }

    /// The default box for a robot: the RecurDyn log's range on the large
    /// robot scaled to the anchors' footprint: x, y within 24 % / 27 % of the
    /// anchors' half-extent around their centre, z from 2 % to 58 % of the
    /// anchors' height.
    pub fn around_anchors(robot: &Robot) -> Self {
        let min = robot
            .anchors_m
            .iter()
            .fold(Vector3::repeat(f64::INFINITY), |m, a| m.inf(a));
        let max = robot
            .anchors_m
            .iter()
            .fold(Vector3::repeat(f64::NEG_INFINITY), |m, a| m.sup(a));
        let centre = (min + max) / 2.0;
        let half = (max - min) / 2.0;
        let top = min.z;
        Self {
            min_m: [centre.x - 0.24 * half.x, centre.y - 0.27 * half.y, 0.02 * top],
            max_m: [centre.x + 0.24 * half.x, centre.y + 0.27 * half.y, 0.58 * top],
        }
    }
}

/// Draw `count` static equilibria spread over `workspace`.
pub fn sample_equilibria(
    robot: &Robot,
    workspace: &Workspace,
    count: usize,
    rng: &mut impl Rng,
) -> Result<Vec<Equilibrium>> {
    let options = StaticsOptions::default();
    let mut poses = Vec::with_capacity(count);
    let mut attempts = 0;
    while poses.len() < count {
        attempts += 1;
        if attempts > 100 * count + 1000 {
            return Err(Error::InvalidInput(format!(
                "only {} of {count} reachable static poses found in the workspace {workspace:?}",
                poses.len()
            )));
        }
        let position = Vector3::from_fn(|i, _| rng.random_range(workspace.min_m[i]..=workspace.max_m[i]));
        let Ok(level) = statics::solve_level(robot, position, &options) else {
            continue;
        };
        let magnitude = level.tensions[robot.reference_cable].magnitude_n() * rng.random_range(0.98..=1.02);
        if let Ok(eq) =
            statics::solve_with_reference_tension(robot, position, magnitude, Some(level.pose.rotation), &options)
        {
            poses.push(eq);
        }
    }
    Ok(poses)
}

fn normal(sigma: f64) -> Normal<f64> {
    // sigma = 0 is a valid "no noise" setting; Normal::new only rejects negative or NaN.
    Normal::new(0.0, sigma.max(0.0)).unwrap_or_else(|_| Normal::new(0.0, 0.0).expect("zero sigma is valid"))
}

/// The sensors' noise, ready to draw: what a noise-free reading becomes.
pub struct SensorSampler {
    encoder: Normal<f64>,
    load_cell: Normal<f64>,
    position: Normal<f64>,
    orientation: Normal<f64>,
}

impl SensorSampler {
    /// Samplers for these sigmas (zero sigmas give exact readings).
    pub fn new(noise: &SensorNoise) -> Self {
        Self {
            encoder: normal(noise.encoder_sigma_m),
            load_cell: normal(noise.load_cell_sigma_n),
            position: normal(noise.position_sigma_m),
            orientation: normal(noise.orientation_sigma_rad),
        }
    }

    /// One pose's readings: the localiser's pose is `true_pose` perturbed on its
    /// tangent space, the encoders and load cell get additive noise. Draws in a
    /// fixed order (orientation, position, encoders, load cell).
    pub fn read(
        &self,
        true_pose: &PlatformPose,
        encoder_lengths_m: [f64; CABLE_COUNT],
        reference_tension_n: f64,
        rng: &mut impl Rng,
    ) -> PoseMeasurement {
        let xi = Vector6::new(
            self.orientation.sample(rng),
            self.orientation.sample(rng),
            self.orientation.sample(rng),
            self.position.sample(rng),
            self.position.sample(rng),
            self.position.sample(rng),
        );
        let pose = true_pose.retract(&xi);
        let (roll_deg, pitch_deg, yaw_deg) = pose.roll_pitch_yaw_deg();
        let encoder_lengths_m = encoder_lengths_m.map(|l| l + self.encoder.sample(rng));
        PoseMeasurement {
            line: 0,
            position_m: pose.position_m.into(),
            roll_deg,
            pitch_deg,
            yaw_deg,
            encoder_lengths_m,
            reference_tension_n: reference_tension_n + self.load_cell.sample(rng),
            excluded: Default::default(),
        }
    }
}

/// What the robot's sensors read at these equilibria: encoder = catenary
/// length + the robot's length offset + noise; load cell = reference tension
/// + noise; localiser pose = true pose perturbed on its tangent space.
pub fn measure(
    robot: &Robot,
    equilibria: &[Equilibrium],
    noise: &SensorNoise,
    rng: &mut impl Rng,
) -> Vec<PoseMeasurement> {
    let sensors = SensorSampler::new(noise);
    equilibria
        .iter()
        .map(|eq| {
            let lengths = std::array::from_fn(|i| eq.cable_lengths_m[i] + robot.length_offsets_m[i]);
            sensors.read(&eq.pose, lengths, eq.tensions[robot.reference_cable].magnitude_n(), rng)
        })
        .collect()
}

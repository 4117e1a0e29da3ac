//! Simulated calibration data from the closed-form kineto-static model.
//!
//! Poses are drawn uniformly in a workspace box; at each position the robot's
//! static equilibrium is one member of the one-parameter family (see
//! [`crate::model::statics`]): sagcal takes the most level one
//! ([`statics::solve_level`]) with its reference tension scaled by a random
//! factor in `[0.98, 1.02]`, which keeps the platform within a few degrees of
//! level and the tensions as even as in the RecurDyn log. Positions without a
//! positive-tension equilibrium are redrawn. [`sample_equilibria_with`] can
//! close the family by a random yaw instead ([`Closure`]), for some or all poses.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{sample_equilibria_with, Closure, Workspace};
//! let robot = Robot::builtin("large")?;
//! // The default box around anchors at x = +-125 m, z = 48 m: x within 24 % of 125 m, z up to 58 % of 48 m.
//! let workspace = Workspace::around_anchors(&robot);
//! assert!((workspace.max_m[0] - 30.0).abs() < 1e-12 && (workspace.max_m[2] - 27.84).abs() < 1e-12);
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
//! let closure = Closure::parse("yaw")?;
//! let poses = sample_equilibria_with(&robot, &workspace, 4, closure, &mut rng)?;
//! for eq in &poses {
//!     let p = eq.pose.position_m;
//!     assert!((0..3).all(|i| workspace.min_m[i] <= p[i] && p[i] <= workspace.max_m[i]));
//!     assert!(eq.pose.yaw_rad().to_degrees().abs() <= 1.0 + 1e-6); // the closure's +-1 degree
//!     assert!(eq.tensions.iter().all(|t| t.is_taut()) && eq.max_height_residual_m() < 1e-9);
//! }
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{Vector3, Vector6};
use rand::Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::error::{Error, ParseError, Result};
use crate::model::geometry;
use crate::model::measurement::{mark_time_order, PoseMeasurement};
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
        Self::around_anchor_points(&robot.anchors_m)
    }

    /// [`Workspace::around_anchors`] for any number of anchors.
    pub fn around_anchor_points(anchors_m: &[Vector3<f64>]) -> Self {
        let min = anchors_m.iter().fold(Vector3::repeat(f64::INFINITY), |m, a| m.inf(a));
        let max = anchors_m
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

/// Draw `count` static equilibria spread over `workspace`, each the most level
/// member of its family ([`Closure::Level`]).
pub fn sample_equilibria(
    robot: &Robot,
    workspace: &Workspace,
    count: usize,
    rng: &mut impl Rng,
) -> Result<Vec<Equilibrium>> {
    sample_equilibria_with(robot, workspace, count, Closure::Level, rng)
}

/// The yaw bound of [`Closure::Yaw`] and [`Closure::Mixed`] by default,
/// degrees: reachable at most positions of both built-in robots (the large
/// robot's family spans only about -1.5 .. +2 degrees of yaw, the small
/// robot's about -20 .. +10).
pub const DEFAULT_MAX_YAW_DEG: f64 = 1.0;

/// How a sampled pose closes the one-parameter family of equilibria at its
/// position (module docs of [`crate::model::statics`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Closure {
    /// The most level member, its reference tension scaled by a random factor
    /// in `[0.98, 1.02]` ([`statics::solve_level`]): a robot commanded to a
    /// level, unrotated platform.
    Level,
    /// The member of a yaw drawn uniformly in `+-max_yaw_deg`
    /// ([`statics::solve_with_yaw`]): a platform settled wherever its statics put it.
    Yaw {
        /// The bound of the yaw drawn, degrees.
        max_yaw_deg: f64,
    },
    /// Each pose by the yaw closure with probability `yaw_fraction`, else level.
    Mixed {
        /// The probability of the yaw closure per pose, 0 .. 1.
        yaw_fraction: f64,
        /// The bound of the yaw drawn, degrees.
        max_yaw_deg: f64,
    },
}

impl Closure {
    /// `level`, `yaw` or `mixed` (half the poses by yaw), with [`DEFAULT_MAX_YAW_DEG`].
    pub fn parse(text: &str) -> std::result::Result<Self, ParseError> {
        match text {
            "level" => Ok(Self::Level),
            "yaw" => Ok(Self::Yaw {
                max_yaw_deg: DEFAULT_MAX_YAW_DEG,
            }),
            "mixed" => Ok(Self::Mixed {
                yaw_fraction: 0.5,
                max_yaw_deg: DEFAULT_MAX_YAW_DEG,
            }),
            other => Err(ParseError::UnknownChoice {
                what: "closure",
                given: other.to_string(),
                choices: ": level, yaw or mixed".to_string(),
            }),
        }
    }

    /// `level`, `yaw` or `mixed`: what [`Closure::parse`] reads.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Level => "level",
            Self::Yaw { .. } => "yaw",
            Self::Mixed { .. } => "mixed",
        }
    }

    pub(super) fn validate(&self) -> Result<()> {
        let (fraction, max_yaw_deg) = match *self {
            Self::Level => return Ok(()),
            Self::Yaw { max_yaw_deg } => (1.0, max_yaw_deg),
            Self::Mixed {
                yaw_fraction,
                max_yaw_deg,
            } => (yaw_fraction, max_yaw_deg),
        };
        if !((0.0..=1.0).contains(&fraction) && max_yaw_deg.is_finite() && max_yaw_deg >= 0.0) {
            return Err(Error::InvalidInput(format!(
                "closure {self}: the yaw fraction must be in 0 .. 1 and the yaw bound a non-negative number of degrees"
            )));
        }
        Ok(())
    }

    /// The next pose's yaw bound, degrees, or `None` for the level closure
    /// (draws one number for [`Closure::Mixed`], none otherwise).
    pub(super) fn draw(&self, rng: &mut impl Rng) -> Option<f64> {
        match *self {
            Self::Level => None,
            Self::Yaw { max_yaw_deg } => Some(max_yaw_deg),
            Self::Mixed {
                yaw_fraction,
                max_yaw_deg,
            } => rng.random_bool(yaw_fraction).then_some(max_yaw_deg),
        }
    }
}

impl std::fmt::Display for Closure {
    /// `level`, `yaw (+-1 deg)`, `mixed (50 % yaw, +-1 deg)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Level => write!(f, "level"),
            Self::Yaw { max_yaw_deg } => write!(f, "yaw (+-{max_yaw_deg} deg)"),
            Self::Mixed {
                yaw_fraction,
                max_yaw_deg,
            } => write!(f, "mixed ({} % yaw, +-{max_yaw_deg} deg)", 100.0 * yaw_fraction),
        }
    }
}

/// Draws [`sample_equilibria_with`] makes before it gives up when none of
/// them had an equilibrium: at a success rate of 1 % the chance of 1000
/// failures in a row is 4e-5 (a box that fails this is not where the robot
/// can hang its platform).
pub const FIRST_DRAWS: usize = 1000;

/// Draw `count` static equilibria spread over `workspace`, each closed by
/// `closure`. A pose's closure is chosen first (a [`Closure::Mixed`] draw),
/// then positions (and yaws) are drawn until one has that equilibrium: a
/// position without it, or where the family does not reach the drawn yaw, is
/// redrawn. [`Closure::Level`] draws exactly what [`sample_equilibria`] always did.
///
/// The box is checked against the robot first ([`geometry::check_workspace`]:
/// below every anchor, under their footprint); the draws are bounded: an
/// error after [`FIRST_DRAWS`] draws without any equilibrium, or after
/// `100 count + 1000` draws in all, says how many draws failed.
pub fn sample_equilibria_with(
    robot: &Robot,
    workspace: &Workspace,
    count: usize,
    closure: Closure,
    rng: &mut impl Rng,
) -> Result<Vec<Equilibrium>> {
    sample_equilibria_counted(robot, workspace, count, closure, FIRST_DRAWS, rng).map(|(poses, _)| poses)
}

/// [`sample_equilibria_with`] giving up after `first_draws` draws without
/// any equilibrium (instead of [`FIRST_DRAWS`]), with the number of draws it made.
pub fn sample_equilibria_counted(
    robot: &Robot,
    workspace: &Workspace,
    count: usize,
    closure: Closure,
    first_draws: usize,
    rng: &mut impl Rng,
) -> Result<(Vec<Equilibrium>, usize)> {
    closure.validate()?;
    geometry::check_workspace(robot, workspace)
        .map_err(|e| Error::InvalidInput(format!("robot `{}`: no pose can be drawn: {e}", robot.name)))?;
    let options = StaticsOptions::default();
    let failure = "no equilibrium with every cable taut";
    draw_poses(
        &robot.name,
        workspace,
        count,
        closure,
        first_draws,
        failure,
        rng,
        |position, max_yaw_deg, rng| match max_yaw_deg {
            None => level_pose(robot, position, &options, rng),
            Some(max) => {
                let yaw_rad = rng.random_range(-max..=max).to_radians();
                statics::solve_with_yaw(robot, position, yaw_rad, &options).ok()
            }
        },
    )
}

/// The draws of the samplers (four cables here, `N` in `sim::suspended`):
/// per pose its closure's yaw bound (`None`: level), then positions drawn
/// uniformly in `workspace` until `try_pose` finds that pose there; an
/// error (naming `robot_name` and what the failed positions lacked,
/// `failure`) after `first_draws` draws without any pose or
/// `100 count + 1000` in all. Returns the poses and the number of draws.
#[allow(clippy::too_many_arguments)]
pub(super) fn draw_poses<T, R: Rng>(
    robot_name: &str,
    workspace: &Workspace,
    count: usize,
    closure: Closure,
    first_draws: usize,
    failure: &str,
    rng: &mut R,
    mut try_pose: impl FnMut(Vector3<f64>, Option<f64>, &mut R) -> Option<T>,
) -> Result<(Vec<T>, usize)> {
    let mut poses = Vec::with_capacity(count);
    let mut attempts = 0;
    let limit = 100 * count + 1000;
    while poses.len() < count {
        let max_yaw_deg = closure.draw(rng);
        loop {
            crate::cancel::check()?;
            attempts += 1;
            if attempts > limit || (poses.is_empty() && attempts > first_draws) {
                let drawn = attempts - 1;
                return Err(Error::InvalidInput(format!(
                    "robot `{robot_name}`: only {} of {count} reachable static poses ({closure} closure) found in the box {workspace} \
                     after {drawn} draws: {:.1} % of the positions drawn had {failure}",
                    poses.len(),
                    100.0 * (drawn - poses.len()) as f64 / drawn as f64
                )));
            }
            let position = Vector3::from_fn(|i, _| rng.random_range(workspace.min_m[i]..=workspace.max_m[i]));
            if let Some(pose) = try_pose(position, max_yaw_deg, rng) {
                poses.push(pose);
                break;
            }
        }
    }
    Ok((poses, attempts))
}

/// The most level equilibrium at `position`, its reference tension scaled by
/// a random factor in `[0.98, 1.02]` (drawn only where the level member exists).
fn level_pose(
    robot: &Robot,
    position: Vector3<f64>,
    options: &StaticsOptions,
    rng: &mut impl Rng,
) -> Option<Equilibrium> {
    let level = statics::solve_level(robot, position, options).ok()?;
    let magnitude = level.tensions[robot.reference_cable].magnitude_n() * rng.random_range(0.98..=1.02);
    statics::solve_with_reference_tension(robot, position, magnitude, Some(level.pose.rotation), options).ok()
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

    /// What the localiser reads at `true_pose`: the pose perturbed on its
    /// tangent space (three rotation draws, then three position draws).
    pub fn localiser(&self, true_pose: &PlatformPose, rng: &mut impl Rng) -> PlatformPose {
        let xi = Vector6::new(
            self.orientation.sample(rng),
            self.orientation.sample(rng),
            self.orientation.sample(rng),
            self.position.sample(rng),
            self.position.sample(rng),
            self.position.sample(rng),
        );
        true_pose.retract(&xi)
    }

    /// What an encoder reads for a cable of `length_m` (offset included).
    pub fn encoder(&self, length_m: f64, rng: &mut impl Rng) -> f64 {
        length_m + self.encoder.sample(rng)
    }

    /// What a load cell reads for a tension of `tension_n`.
    pub fn load_cell(&self, tension_n: f64, rng: &mut impl Rng) -> f64 {
        tension_n + self.load_cell.sample(rng)
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
        let pose = self.localiser(true_pose, rng);
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
            order: None,
        }
    }
}

/// What the robot's sensors read at these equilibria: encoder = catenary
/// length + the robot's length offset + noise; load cell = reference
/// tension + noise; localiser pose = true pose perturbed on its tangent
/// space. The robot visits the equilibria in their order: the rows are
/// marked so ([`mark_time_order`]).
pub fn measure(
    robot: &Robot,
    equilibria: &[Equilibrium],
    noise: &SensorNoise,
    rng: &mut impl Rng,
) -> Vec<PoseMeasurement> {
    let sensors = SensorSampler::new(noise);
    let mut rows: Vec<PoseMeasurement> = equilibria
        .iter()
        .map(|eq| {
            let lengths = std::array::from_fn(|i| eq.cable_lengths_m[i] + robot.length_offsets_m[i]);
            sensors.read(&eq.pose, lengths, eq.tensions[robot.reference_cable].magnitude_n(), rng)
        })
        .collect();
    mark_time_order(&mut rows);
    rows
}

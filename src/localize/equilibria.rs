//! Every equilibrium of one row, not just the one a start converges to.
//!
//! Four cable lengths leave the 6-DoF platform two directions the statics
//! must fix, and the forward problem can have several solutions: a platform
//! tilted the other way, turned about the vertical, or hanging upside down
//! with the same lengths. [`Localizer::equilibria`] searches the orientation
//! space by a deterministic multistart: the trilaterated position with every
//! orientation of a grid (roll and pitch every 30 degrees over the full
//! circle, yaw every 45 degrees: 12 x 12 x 8 = 1152 starts) plus the
//! regular starts, each converged by the same constrained Gauss-Newton as
//! [`Localizer::localize`], and the converged poses merged when they agree
//! to 1e-6 (metres plus radians). This is a search, not a proof: an
//! equilibrium whose basin misses every start of the grid is not found. The
//! test suite checks that it finds the simulated equilibrium on both robots.

use nalgebra::{UnitQuaternion, Vector3};

use super::localizer::{pose_distance, ColdStart, Localized, Localizer, Readings};
use crate::error::Result;
use crate::model::pose::PlatformPose;

/// Grid of the multistart: roll and pitch step, yaw step, degrees.
const TILT_STEP_DEG: f64 = 30.0;
const YAW_STEP_DEG: f64 = 45.0;

impl Localizer {
    /// Every equilibrium the multistart finds for `readings` (module docs),
    /// stable or not, sorted with the stable ones first and, among them, by
    /// distance to `reference` (the previous pose or the prior; else by
    /// chi-square). Empty when no start converges: no pose with taut cables
    /// reproduces the readings.
    ///
    /// Errors: a reading that is not a finite number, as [`Localizer::localize`].
    pub fn equilibria(&self, readings: &Readings, reference: Option<&PlatformPose>) -> Result<Vec<Localized>> {
        let observation = self.observation(readings)?;
        let level = self.level_start(readings);
        let mut starts: Vec<(PlatformPose, Option<nalgebra::Vector2<f64>>)> = Vec::new();
        for kind in [ColdStart::Prior, ColdStart::Level, ColdStart::Statics] {
            if let Some(start) = self.cold_start(kind, &observation, &level) {
                starts.push(start);
            }
        }
        let steps = |step: f64| (0..(360.0 / step) as usize).map(move |k| (k as f64 * step - 180.0).to_radians());
        for roll in steps(TILT_STEP_DEG) {
            for pitch in steps(TILT_STEP_DEG) {
                for yaw in steps(YAW_STEP_DEG) {
                    let rotation = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
                    starts.push((PlatformPose::new(level.position_m, rotation), None));
                }
            }
        }
        let mut found: Vec<Localized> = Vec::new();
        let mut iterations = 0;
        for (pose, tension) in starts {
            let Some(solution) = self.try_start(&observation, pose, tension, &mut iterations) else {
                continue;
            };
            // With the encoders alone the system is square: a local minimum
            // that leaves a residual is not a solution of the equations.
            let exact = solution.degrees_of_freedom > 0 || solution.chi_square <= 1e-6;
            if !(exact && solution.pose.position_m.iter().all(|v| v.is_finite())) {
                continue;
            }
            if found.iter().all(|f| pose_distance(&f.pose, &solution.pose) > 1e-6) {
                found.push(solution);
            }
        }
        let key = |l: &Localized| reference.map_or(l.chi_square, |r| pose_distance(&l.pose, r));
        found.sort_by(|a, b| b.stable.cmp(&a.stable).then(key(a).total_cmp(&key(b))));
        Ok(found)
    }
}

/// The platform's tilt from level, degrees (angle of its z axis from the world's).
pub fn tilt_deg(pose: &PlatformPose) -> f64 {
    (pose.rotation * Vector3::z()).z.clamp(-1.0, 1.0).acos().to_degrees()
}

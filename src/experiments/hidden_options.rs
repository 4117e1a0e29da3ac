//! The settings of `sagcal experiment hidden-effects` ([`HiddenEffectOptions`])
//! and their checks, before any case is drawn.

use super::leave_one_out::Catalogue;
use crate::error::{Error, Result};
use crate::model::sensors::NoisePreset;
use crate::sim::closed_form::{Closure, DEFAULT_MAX_YAW_DEG};

/// Settings of the experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct HiddenEffectOptions {
    /// Static poses per case.
    pub poses: usize,
    /// Sensor noise of the simulated data and of the calibration.
    pub noise: NoisePreset,
    /// Segments per cable of the discretised simulator.
    pub segments: usize,
    /// Folds of the diagnosis' cross-validation.
    pub folds: usize,
    /// How each pose closes its family of equilibria: the most level member
    /// or one of a random yaw ([`Closure`]).
    pub closure: Closure,
    /// The diagnosis' catalogue: every effect, or also each hidden effect left out.
    pub catalogue: Catalogue,
}

impl Default for HiddenEffectOptions {
    /// 35 poses, the authors' noise, 50 segments, 5 folds, about half the
    /// poses closed by a yaw within [`DEFAULT_MAX_YAW_DEG`] (the rest level).
    fn default() -> Self {
        Self {
            poses: 35,
            noise: NoisePreset::Authors,
            segments: 50,
            folds: 5,
            closure: Closure::Mixed {
                yaw_fraction: 0.5,
                max_yaw_deg: DEFAULT_MAX_YAW_DEG,
            },
            catalogue: Catalogue::Full,
        }
    }
}

impl HiddenEffectOptions {
    /// The fewest poses a case can have: the diagnosis' cross-validation
    /// needs two poses per fold (`diagnose`), and a calibration
    /// [`crate::calib::MIN_POSES`].
    pub fn min_poses(&self) -> usize {
        (2 * self.folds).max(crate::calib::MIN_POSES)
    }

    /// Check the options before any case is drawn, naming the option (and
    /// its flag of `sagcal experiment hidden-effects`): too few poses would
    /// leave the mean reference tension, and so the effects drawn from it,
    /// undefined.
    pub fn validate(&self) -> Result<()> {
        if self.folds < 2 {
            return Err(Error::InvalidInput(format!(
                "folds: the diagnosis' cross-validation needs at least 2 folds, got {}",
                self.folds
            )));
        }
        if self.poses < self.min_poses() {
            return Err(Error::InvalidInput(format!(
                "poses (--poses): at least {} poses per case are needed (two per fold of the diagnosis' {}-fold cross-validation, and {} for a calibration), got {}",
                self.min_poses(),
                self.folds,
                crate::calib::MIN_POSES,
                self.poses
            )));
        }
        if self.segments < 1 {
            return Err(Error::InvalidInput(
                "segments (--segments): the discretised simulator needs at least 1 segment per cable, got 0".into(),
            ));
        }
        Ok(())
    }
}

//! The checks of [`HiddenEffectOptions`], before any case is drawn.

use super::hidden_effects::HiddenEffectOptions;
use crate::error::{Error, Result};

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

//! What a user asks of a localisation, as `sagcal localize`'s flags and
//! `sagcal.localize`'s keywords give it: the [`Localizer`] it builds, and the
//! check that a localiser pose used as a prior is on every row, worded for
//! the caller ([`FrontEnd`]).

use std::path::Path;

use super::localizer::{LocalizeOptions, Localizer};
use crate::error::{Error, FrontEnd, Result};
use crate::model::pose::PlatformPose;
use crate::model::sensors::NoisePreset;
use crate::model::Robot;

/// The settings of `sagcal localize` (and `sagcal.localize`).
///
/// ```
/// use sagcal::localize::LocalizeSettings;
/// use sagcal::model::sensors::NoisePreset;
/// use sagcal::model::Robot;
/// let robot = Robot::builtin("large")?;
/// let localizer = LocalizeSettings::new(NoisePreset::Paper).localizer(&robot)?;
/// assert!(!localizer.options().pose_prior);
/// # Ok::<(), sagcal::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalizeSettings {
    /// The sensor noise of the readings.
    pub noise: NoisePreset,
    /// Use the localiser pose as a prior ([`LocalizeOptions::pose_prior`]).
    pub pose_prior: bool,
    /// False-alarm rate of each row's chi-square test.
    pub false_alarm: f64,
    /// Propagate the robot's recorded calibration covariance
    /// ([`LocalizeOptions::calibration_uncertainty`]).
    pub calibration_uncertainty: bool,
}

impl LocalizeSettings {
    /// The command's defaults with `noise`: no prior, false-alarm rate 1e-3,
    /// the calibration's uncertainty propagated.
    pub fn new(noise: NoisePreset) -> Self {
        let defaults = LocalizeOptions::default();
        Self {
            noise,
            pose_prior: defaults.pose_prior,
            false_alarm: defaults.false_alarm,
            calibration_uncertainty: defaults.calibration_uncertainty,
        }
    }

    /// The localiser of `robot` with these settings (checked by [`Localizer::with_options`]).
    pub fn localizer(&self, robot: &Robot) -> Result<Localizer> {
        let options = LocalizeOptions {
            pose_prior: self.pose_prior,
            false_alarm: self.false_alarm,
            calibration_uncertainty: self.calibration_uncertainty,
            ..LocalizeOptions::default()
        };
        Localizer::with_options(robot, &self.noise.sigmas(robot.platform_weight_n), options)
    }
}

/// With the localiser pose as a prior every row needs one: the error naming
/// the first of `rows` (each its line in `path`, 0 for data not read from a
/// file, and its localiser pose) without, and the option `pose_prior` as
/// `front_end` spells it.
///
/// ```
/// use std::path::Path;
/// use sagcal::error::FrontEnd;
/// use sagcal::localize::require_pose_priors;
/// let rows = [(2, None)];
/// let message = require_pose_priors(Path::new("r.csv"), rows, FrontEnd::Python).unwrap_err().to_string();
/// assert_eq!(
///     message,
///     "r.csv: row 1 (line 2), field `x_m`: pose_prior=True needs a localiser pose on every row; this file has none"
/// );
/// ```
pub fn require_pose_priors(
    path: &Path,
    rows: impl IntoIterator<Item = (usize, Option<PlatformPose>)>,
    front_end: FrontEnd,
) -> Result<()> {
    match rows.into_iter().enumerate().find(|(_, (_, pose))| pose.is_none()) {
        Some((k, (line, _))) => Err(Error::Field {
            path: path.to_path_buf(),
            row: k + 1,
            line: (line > 0).then_some(line),
            field: "x_m".into(),
            message: format!(
                "{} needs a localiser pose on every row; this file has none",
                front_end.switch("pose_prior")
            ),
        }),
        None => Ok(()),
    }
}

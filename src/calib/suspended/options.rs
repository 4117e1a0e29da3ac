//! The calibration options of a robot of `N` cables from the solver
//! settings the command's flags and the Python keywords name.

use crate::calib::options::{CableModel, CalibrationOptions};
use crate::calib::settings::SolverSettings;
use crate::error::{Error, FrontEnd, Result};
use crate::model::suspended::SuspendedRobot;

/// The options of `settings` for `robot` (sigmas for its platform's
/// weight); a rigid model, which only the four-cable pipeline solves as a
/// model of its own, is refused naming `model` as `front_end` spells it.
///
/// ```
/// use sagcal::calib::suspended::suspended_options;
/// use sagcal::calib::{CableModel, SolverSettings};
/// use sagcal::error::FrontEnd;
/// use sagcal::model::sensors::NoisePreset;
/// use sagcal::model::suspended::SuspendedRobot;
/// let six = SuspendedRobot::builtin("six")?;
/// let mut settings = SolverSettings::new(NoisePreset::Paper);
/// assert_eq!(suspended_options(&settings, &six, FrontEnd::Cli)?.noise.load_cell_sigma_n, 5.0);
/// settings.model = CableModel::Rigid;
/// let message = suspended_options(&settings, &six, FrontEnd::Python).unwrap_err().to_string();
/// assert!(message.contains("model rigid: robot `six` has 6 cables"), "{message}");
/// # Ok::<(), sagcal::Error>(())
/// ```
pub fn suspended_options(
    settings: &SolverSettings,
    robot: &SuspendedRobot,
    front_end: FrontEnd,
) -> Result<CalibrationOptions> {
    if settings.model == CableModel::Rigid {
        return Err(Error::InvalidInput(format!(
            "{} rigid: robot `{}` has {} cables, which sagcal calibrates with catenaries (straight cables are its first stage)",
            front_end.option("model"),
            robot.name,
            robot.cable_count()
        )));
    }
    settings.options_for_weight(robot.platform_weight_n, front_end)
}

//! What a user asks of a calibration, as the command's flags and the Python
//! package's keywords give it, checked into [`CalibrationOptions`] and
//! [`GrossErrorOptions`]: the one place the noise overrides and the
//! false-alarm rate are validated, with messages naming the input as the
//! caller spells it ([`FrontEnd`]).

use super::options::{CableModel, CalibrationOptions, GrossErrorOptions, OrientationPrior, RobustKernels};
use crate::error::{Error, FrontEnd, Result};
use crate::model::sensors::NoisePreset;
use crate::model::Robot;

/// The calibration solver's settings shared by `calibrate` and `diagnose`
/// (the flags `--model`, `--noise`, `--encoder-sigma-m`, ... and the Python
/// keywords of the same names).
///
/// ```
/// use sagcal::calib::{CalibrationOptions, SolverSettings};
/// use sagcal::error::FrontEnd;
/// use sagcal::model::sensors::NoisePreset;
/// use sagcal::model::Robot;
/// let robot = Robot::builtin("large")?;
/// let mut settings = SolverSettings::new(NoisePreset::Paper);
/// settings.encoder_sigma_m = Some(0.02);
/// let options = settings.options(&robot, FrontEnd::Cli)?;
/// assert_eq!(options.noise.encoder_sigma_m, 0.02);
/// // A bad override is named as the caller wrote it.
/// settings.encoder_sigma_m = Some(-1.0);
/// let message = settings.options(&robot, FrontEnd::Python).unwrap_err().to_string();
/// assert_eq!(message, "invalid input: encoder_sigma_m must be a positive number, got -1");
/// # Ok::<(), sagcal::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// The cable model (default catenary).
    pub model: CableModel,
    /// The sensor noise used as factor weights (`none` is refused: the factors need sigmas).
    pub noise: NoisePreset,
    /// Override of the encoder sigma, metres.
    pub encoder_sigma_m: Option<f64>,
    /// Override of the load-cell sigma, newtons.
    pub load_cell_sigma_n: Option<f64>,
    /// Override of the localiser position sigma, metres.
    pub position_sigma_m: Option<f64>,
    /// The localiser's orientation as a prior (default `auto`).
    pub orientation_prior: OrientationPrior,
    /// Robust kernels per factor type (default none).
    pub robust: RobustKernels,
}

impl SolverSettings {
    /// The command's defaults with `noise`: catenary model, no override,
    /// automatic orientation prior, no robust kernel.
    pub fn new(noise: NoisePreset) -> Self {
        Self {
            model: CableModel::Catenary,
            noise,
            encoder_sigma_m: None,
            load_cell_sigma_n: None,
            position_sigma_m: None,
            orientation_prior: OrientationPrior::Auto,
            robust: RobustKernels::default(),
        }
    }

    /// The calibration options for `robot`: the preset's sigmas with the
    /// overrides (each a positive number, named as `front_end` spells it),
    /// every sigma positive.
    pub fn options(&self, robot: &Robot, front_end: FrontEnd) -> Result<CalibrationOptions> {
        self.options_for_weight(robot.platform_weight_n, front_end)
    }

    /// [`SolverSettings::options`] for a robot whose platform weighs
    /// `platform_weight_n` (the noise preset's load-cell sigma depends on it).
    pub fn options_for_weight(&self, platform_weight_n: f64, front_end: FrontEnd) -> Result<CalibrationOptions> {
        let mut noise = self.noise.sigmas(platform_weight_n);
        for (value, target, keyword) in [
            (self.encoder_sigma_m, &mut noise.encoder_sigma_m, "encoder_sigma_m"),
            (
                self.load_cell_sigma_n,
                &mut noise.load_cell_sigma_n,
                "load_cell_sigma_n",
            ),
            (self.position_sigma_m, &mut noise.position_sigma_m, "position_sigma_m"),
        ] {
            if let Some(v) = value {
                if !(v.is_finite() && v > 0.0) {
                    return Err(Error::InvalidInput(format!(
                        "{} must be a positive number, got {v}",
                        front_end.option(keyword)
                    )));
                }
                *target = v;
            }
        }
        if [noise.encoder_sigma_m, noise.load_cell_sigma_n, noise.position_sigma_m]
            .iter()
            .any(|s| *s <= 0.0)
        {
            return Err(Error::InvalidInput(
                "sensor sigmas must be positive to weight the factors".into(),
            ));
        }
        let mut options = CalibrationOptions::new(noise);
        options.model = self.model;
        options.orientation_prior = self.orientation_prior;
        options.robust = self.robust;
        Ok(options)
    }
}

/// `value` if it is a false-alarm rate, strictly between 0 and 1; else the
/// error naming the option `keyword` as `front_end` spells it.
///
/// ```
/// use sagcal::calib::check_false_alarm;
/// use sagcal::error::FrontEnd;
/// assert_eq!(check_false_alarm(1e-3, "false_alarm", FrontEnd::Cli)?, 1e-3);
/// let message = check_false_alarm(2.0, "false_alarm", FrontEnd::Cli).unwrap_err().to_string();
/// assert_eq!(message, "invalid input: --false-alarm must be between 0 and 1, got 2");
/// # Ok::<(), sagcal::Error>(())
/// ```
pub fn check_false_alarm(value: f64, keyword: &str, front_end: FrontEnd) -> Result<f64> {
    if value > 0.0 && value < 1.0 {
        Ok(value)
    } else {
        Err(Error::InvalidInput(format!(
            "{} must be between 0 and 1, got {value}",
            front_end.option(keyword)
        )))
    }
}

/// What `sagcal calibrate` (and `sagcal.calibrate`) is asked for: the
/// solver's settings, the gross-error tests' false-alarm rate, and whether an
/// inconsistent fit is accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibrationSettings {
    /// The solver's settings.
    pub solver: SolverSettings,
    /// False-alarm rate of the gross-error tests (default 1e-3).
    pub false_alarm: f64,
    /// Keep a fit that fails its own consistency tests instead of refusing it.
    pub accept_inconsistent: bool,
}

impl CalibrationSettings {
    /// The command's defaults with `noise` (see [`SolverSettings::new`]):
    /// false-alarm rate 1e-3, an inconsistent fit refused.
    pub fn new(noise: NoisePreset) -> Self {
        Self {
            solver: SolverSettings::new(noise),
            false_alarm: GrossErrorOptions::default().false_alarm,
            accept_inconsistent: false,
        }
    }

    /// The checked options of the solver ([`SolverSettings::options`]) and of
    /// the gross-error tests, in that order.
    pub fn options(&self, robot: &Robot, front_end: FrontEnd) -> Result<(CalibrationOptions, GrossErrorOptions)> {
        let options = self.solver.options(robot, front_end)?;
        let check = GrossErrorOptions {
            false_alarm: check_false_alarm(self.false_alarm, "false_alarm", front_end)?,
            ..GrossErrorOptions::default()
        };
        Ok((options, check))
    }
}

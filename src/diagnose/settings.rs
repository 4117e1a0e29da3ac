//! What a user asks of a diagnosis, as `sagcal diagnose`'s flags and
//! `sagcal.diagnose`'s keywords give it, checked into [`DiagnoseOptions`]
//! with messages naming the input as the caller spells it ([`FrontEnd`]).

use super::DiagnoseOptions;
use crate::calib::SolverSettings;
use crate::error::{Error, FrontEnd, Result};
use crate::model::effect_kind::EffectKind;
use crate::model::sensors::NoisePreset;
use crate::model::Robot;

/// The settings of `sagcal diagnose` (and `sagcal.diagnose`).
///
/// ```
/// use sagcal::diagnose::DiagnoseSettings;
/// use sagcal::error::FrontEnd;
/// use sagcal::model::sensors::NoisePreset;
/// use sagcal::model::Robot;
/// let robot = Robot::builtin("large")?;
/// let mut settings = DiagnoseSettings::new(NoisePreset::Paper);
/// settings.candidates = Some(vec!["elastic".into(), "loadcell".into()]);
/// assert_eq!(settings.options(&robot, FrontEnd::Cli)?.candidates.len(), 2);
/// settings.candidates = Some(vec!["magic".into()]);
/// let message = settings.options(&robot, FrontEnd::Cli).unwrap_err().to_string();
/// assert!(message.starts_with("invalid input: --candidates: "), "{message}");
/// # Ok::<(), sagcal::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseSettings {
    /// The baseline calibration's solver settings.
    pub solver: SolverSettings,
    /// The candidate effects by name (`elastic`, `encoder-gain`, ...);
    /// `None`: the whole catalogue.
    pub candidates: Option<Vec<String>>,
    /// Whether "the localiser's orientations are unreliable" is a hypothesis too.
    pub orientation_hypothesis: bool,
    /// Folds of the cross-validation over poses.
    pub folds: usize,
    /// The false-alarm rate of the whole search.
    pub false_alarm: f64,
    /// Whether the rows are in the order the poses were taken
    /// ([`DiagnoseOptions::rows_in_time_order`]).
    pub rows_in_time_order: bool,
}

impl DiagnoseSettings {
    /// The command's defaults with `noise`: the solver's
    /// ([`SolverSettings::new`]) and those of [`DiagnoseOptions::new`] (the
    /// whole catalogue and the orientation hypothesis, 5 folds, a false-alarm
    /// rate of 0.1 %, rows in time order).
    pub fn new(noise: NoisePreset) -> Self {
        Self {
            solver: SolverSettings::new(noise),
            candidates: None,
            orientation_hypothesis: true,
            folds: 5,
            false_alarm: 1e-3,
            rows_in_time_order: true,
        }
    }

    /// The diagnosis options for `robot`: the solver's checked options
    /// ([`SolverSettings::options`]) and every candidate a known effect (an
    /// unknown one named under the option `candidates` as `front_end` spells
    /// it). The folds and the false-alarm rate are checked by
    /// [`super::diagnose`].
    pub fn options(&self, robot: &Robot, front_end: FrontEnd) -> Result<DiagnoseOptions> {
        let mut options = DiagnoseOptions::new(self.solver.options(robot, front_end)?);
        options.folds = self.folds;
        options.false_alarm = self.false_alarm;
        options.orientation_hypothesis = self.orientation_hypothesis;
        options.rows_in_time_order = self.rows_in_time_order;
        if let Some(names) = &self.candidates {
            options.candidates = names
                .iter()
                .map(|name| EffectKind::parse(name))
                .collect::<std::result::Result<_, _>>()
                .map_err(|e| Error::InvalidInput(format!("{}: {e}", front_end.option("candidates"))))?;
        }
        Ok(options)
    }
}

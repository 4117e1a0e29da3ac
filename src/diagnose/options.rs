//! The diagnosis' options ([`DiagnoseOptions`]), their own checks, and
//! what the order of the rows allows.

use crate::calib::CalibrationOptions;
use crate::error::{Error, Result};
use crate::model::effect_kind::EffectKind;
use crate::model::measurement::PoseMeasurement;

/// How to diagnose.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// The baseline calibration's options (their `free_effects` are ignored;
    /// the orientation prior is used unless it is `off`).
    pub calibration: CalibrationOptions,
    /// The candidate effects of the search.
    pub candidates: Vec<EffectKind>,
    /// Whether "the localiser's orientations are unreliable" is a hypothesis too.
    pub orientation_hypothesis: bool,
    /// Folds of the cross-validation over poses (>= 2).
    pub folds: usize,
    /// The false-alarm rate of the whole search: the probability of
    /// declaring an effect on data the baseline describes (module docs).
    pub false_alarm: f64,
    /// Whether the rows are in the order the poses were taken (a sagcal
    /// measurement file): only then are the row (a drift over time) and each
    /// cable's direction of last motion drivers of step 2. A RecurDyn log or
    /// an authors' folder holds poses whose order is not the order a robot
    /// took them in.
    pub rows_in_time_order: bool,
}

impl DiagnoseOptions {
    /// Every candidate of the catalogue and the orientation hypothesis, 5
    /// folds, a false-alarm rate of 0.1 %.
    pub fn new(calibration: CalibrationOptions) -> Self {
        Self {
            calibration,
            candidates: EffectKind::ALL.to_vec(),
            orientation_hypothesis: true,
            folds: 5,
            false_alarm: 1e-3,
            rows_in_time_order: true,
        }
    }
}

/// `options` for `measurements`: the row and the direction of last motion
/// are drivers, and the effects of time and motion
/// ([`EffectKind::needs_time_order`]) candidates, only where the rows are
/// in the order the robot took them and every pose carries that order
/// ([`PoseMeasurement::order`]); elsewhere they are off.
pub(super) fn time_order_resolved(options: &DiagnoseOptions, measurements: &[PoseMeasurement]) -> DiagnoseOptions {
    let ordered = options.rows_in_time_order && measurements.iter().all(|m| m.order.is_some());
    DiagnoseOptions {
        rows_in_time_order: ordered,
        candidates: options
            .candidates
            .iter()
            .copied()
            .filter(|k| ordered || !k.needs_time_order())
            .collect(),
        ..options.clone()
    }
}

/// The options' own checks: at least 2 folds, a false-alarm rate in (0, 1).
pub(super) fn check_options(options: &DiagnoseOptions) -> Result<()> {
    if options.folds < 2 {
        return Err(Error::InvalidInput(format!(
            "diagnose: at least 2 cross-validation folds are needed, got {}",
            options.folds
        )));
    }
    if !(options.false_alarm > 0.0 && options.false_alarm < 1.0) {
        return Err(Error::InvalidInput(format!(
            "diagnose: the false-alarm rate must be in (0, 1), got {}",
            options.false_alarm
        )));
    }
    Ok(())
}

//! The graph of a fitted calibration at its values: what every comparison
//! of the diagnosis re-evaluates (residuals, chi-squares, folds).

use crate::calib::gross_errors::graph_at_solution;
use crate::calib::{CableModel, CalibrationGraph, CalibrationOptions, CalibrationResult};
use crate::model::measurement::PoseMeasurement;

/// The graph of a fitted calibration (values at the fit), with the effect
/// variables set from the estimates (the robot file's effects cannot hold a
/// negative compliance): [`graph_at_solution`] with the catenary model.
pub(super) fn rebuild(
    result: &CalibrationResult,
    used: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> CalibrationGraph {
    let catenary = CalibrationOptions {
        model: CableModel::Catenary,
        ..*options
    };
    graph_at_solution(result, used, &catenary)
}

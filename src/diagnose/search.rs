//! What the search for the model's missing effects works on: the baseline,
//! the measurements, the truth where known, and the options.

use super::baseline::Baseline;
use super::options::DiagnoseOptions;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::Robot;

/// What the search works on.
pub(super) struct Search<'a> {
    /// The baseline fit.
    pub base: &'a Baseline,
    /// All measurements (the baseline's excluded poses stay out).
    pub measurements: &'a [PoseMeasurement],
    /// The truth, if known (for the report only).
    pub truth: Option<&'a Robot>,
    /// The options.
    pub options: &'a DiagnoseOptions,
}

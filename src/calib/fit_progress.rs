//! The progress of a checked calibration
//! ([`super::gross_errors::calibrate_checked_with_progress`]):
//! `report(done, total, what)` before each stage of each fit, the form of
//! the diagnosis' progress. `done` counts the fits made, `total` the fits
//! expected so far (one for data that pass; during the search for gross
//! errors, one more per reading still flagged), `what` names the fit and its
//! stage (`gross-error search, 2 readings left out: catenary`); the last
//! report is `(fits, fits, "done")`.

use super::entry::calibrate_with_stages;
use super::options::CalibrationOptions;
use super::result::CalibrationResult;
use crate::error::Result;
use crate::model::measurement::PoseMeasurement;
use crate::model::Robot;

/// The fits of a checked calibration, counted and reported.
pub(super) struct FitProgress<'a> {
    done: usize,
    total: usize,
    report: &'a mut dyn FnMut(usize, usize, &str),
}

impl<'a> FitProgress<'a> {
    /// No fit made, one expected.
    pub(super) fn new(report: &'a mut dyn FnMut(usize, usize, &str)) -> Self {
        Self {
            done: 0,
            total: 1,
            report,
        }
    }

    /// [`super::calibrate`] as the next fit, named `what`: each of its
    /// stages reported as `what: stage`.
    pub(super) fn fit(
        &mut self,
        what: &str,
        initial: &Robot,
        measurements: &[PoseMeasurement],
        options: &CalibrationOptions,
    ) -> Result<CalibrationResult> {
        self.total = self.total.max(self.done + 1);
        let (done, total, report) = (self.done, self.total, &mut *self.report);
        let result = calibrate_with_stages(initial, measurements, options, &mut |stage| {
            report(done, total, &format!("{what}: {stage}"))
        });
        self.done += 1;
        result
    }

    /// `more` fits expected after those made.
    pub(super) fn expect(&mut self, more: usize) {
        self.total = self.done + more;
    }

    /// The end: `(fits, fits, "done")`.
    pub(super) fn finish(&mut self) {
        (self.report)(self.done, self.done, "done");
    }
}

/// The fit of the search for gross errors with `left_out` readings left out, in words.
pub(super) fn search_fit(left_out: usize) -> String {
    match left_out {
        1 => "gross-error search, 1 reading left out".to_string(),
        n => format!("gross-error search, {n} readings left out"),
    }
}

//! The progress of a diagnosis, reported before each fit.

/// The progress of a diagnosis: `report(done, total, what)` before each fit.
pub(super) struct Progress<'a> {
    pub(super) done: usize,
    pub(super) total: usize,
    pub(super) report: &'a mut dyn FnMut(usize, usize, &str),
}

impl<'a> Progress<'a> {
    /// A progress of `total` steps, reported to `report`.
    pub(super) fn new(total: usize, report: &'a mut dyn FnMut(usize, usize, &str)) -> Self {
        Self { done: 0, total, report }
    }

    /// Report `what` as the next step.
    pub(super) fn step(&mut self, what: &str) {
        (self.report)(self.done, self.total, what);
        self.done += 1;
    }

    /// Count `steps` steps as done without a report of their own (fits run
    /// in parallel under one report).
    pub(super) fn advance(&mut self, steps: usize) {
        self.done += steps;
    }

    /// `steps` more steps than planned.
    pub(super) fn grow(&mut self, steps: usize) {
        self.total += steps;
    }

    /// Report the end.
    pub(super) fn finish(&mut self) {
        (self.report)(self.total, self.total, "done");
    }
}

//! The `progress` keyword of the long jobs (`calibrate`, `diagnose`,
//! `localize`, `plan`): a Python callable called with `(done, total, what)`
//! as the library reports while the job runs without the GIL. The first
//! exception it raises is re-raised after the run (an error of the job
//! itself comes first); it never changes what the job computes.

use std::sync::Mutex;

use pyo3::prelude::*;

/// A job's progress callback (or none).
pub(crate) struct Progress {
    callback: Option<Py<PyAny>>,
    /// The first exception the callback raised, re-raised after the run.
    error: Mutex<Option<PyErr>>,
    /// The stage and whole percent of the last report passed on.
    last: Mutex<Option<(String, usize)>>,
}

impl Progress {
    /// The keyword's value (`None`: no calls).
    pub(crate) fn new(callback: Option<Py<PyAny>>) -> Self {
        Self {
            callback,
            error: Mutex::new(None),
            last: Mutex::new(None),
        }
    }

    /// Pass `(done, total, what)` on to the callback when `what` changes,
    /// at each whole percent of `total`, and at the end (`done == total`):
    /// a job of many small steps (the rows of `localize`) calls it about a
    /// hundred times, not once per step.
    pub(crate) fn report(&self, done: usize, total: usize, what: &str) {
        let Some(callback) = &self.callback else {
            return;
        };
        let percent = done.saturating_mul(100) / total.max(1);
        {
            let mut last = self.last.lock().expect("not poisoned");
            let same = last.as_ref().is_some_and(|(w, p)| w == what && *p == percent);
            if same && done < total {
                return;
            }
            *last = Some((what.to_string(), percent));
        }
        Python::attach(|py| {
            if let Err(e) = callback.call1(py, (done, total, what)) {
                self.error.lock().expect("not poisoned").get_or_insert(e);
            }
        });
    }

    /// The run is over: the first exception the callback raised, if any.
    pub(crate) fn finish(self) -> PyResult<()> {
        match self.error.into_inner().expect("not poisoned") {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

//! Cooperative cancellation of long jobs: a process-wide flag the long loops
//! check (the pose sampler of `simulate` and `plan`, the solver's
//! iterations of `calibrate` and `diagnose`, the rows of the Python
//! `localize`). A front end that catches an interrupt (the Python package on
//! Ctrl-C) calls [`request`]; the job then returns [`Error::Cancelled`] at its
//! next check, and the front end calls [`reset`] before its next job.
//!
//! ```
//! sagcal::cancel::reset();
//! assert!(sagcal::cancel::check().is_ok());
//! sagcal::cancel::request();
//! assert!(matches!(sagcal::cancel::check(), Err(sagcal::Error::Cancelled)));
//! sagcal::cancel::reset();
//! assert!(!sagcal::cancel::requested());
//! ```

use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::{Error, Result};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Ask every running job to stop at its next check.
pub fn request() {
    REQUESTED.store(true, Ordering::Relaxed);
}

/// Clear a request (before starting a new job).
pub fn reset() {
    REQUESTED.store(false, Ordering::Relaxed);
}

/// Whether a stop was requested.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// [`Error::Cancelled`] when a stop was requested.
pub fn check() -> Result<()> {
    if requested() {
        Err(Error::Cancelled)
    } else {
        Ok(())
    }
}

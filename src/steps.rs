//! A count of the work a process has done, in steps, so that a test can bound
//! a command's running time by a count instead of a clock (a shared, noisy
//! machine makes wall-clock limits flaky; a count is the same on every run).
//!
//! A step is one bounded unit of the expensive loops: one evaluation of the
//! statics' cable tensions (paper eq. 11, the innermost call of every
//! equilibrium search and of the simulators' pose draws), one
//! Levenberg-Marquardt iteration, one Newton iteration of the localisation or
//! of the discretised simulator. Each of them takes at most milliseconds, so a
//! command whose count is bounded by a formula of its inputs cannot hang.
//!
//! Counting is per thread and flushed to the process total every
//! [`FLUSH_EVERY`] steps and when a thread ends, so that rayon's workers do not
//! share one cache line on every step; [`total`] may therefore miss fewer than
//! [`FLUSH_EVERY`] steps per live worker thread. The count changes no result.
//! The `sagcal` binary prints it to stderr when the environment variable
//! `SAGCAL_REPORT_STEPS` is set.
//!
//! ```
//! let before = sagcal::steps::total();
//! for _ in 0..3 * sagcal::steps::FLUSH_EVERY {
//!     sagcal::steps::tick();
//! }
//! // The calling thread's steps are in the total (other threads may add theirs).
//! assert!(sagcal::steps::total() >= before + 3 * sagcal::steps::FLUSH_EVERY);
//! ```

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Steps a thread counts on its own before it adds them to the process total.
pub const FLUSH_EVERY: u64 = 1024;

/// Steps flushed by every thread so far.
static TOTAL: AtomicU64 = AtomicU64::new(0);

/// A thread's steps not yet flushed; flushed when the thread ends.
struct Pending(Cell<u64>);

impl Drop for Pending {
    fn drop(&mut self) {
        TOTAL.fetch_add(self.0.get(), Ordering::Relaxed);
    }
}

thread_local! {
    static PENDING: Pending = const { Pending(Cell::new(0)) };
}

/// Count one step.
#[inline]
pub fn tick() {
    add(1);
}

/// Count `steps` steps.
#[inline]
pub fn add(steps: u64) {
    // A thread being torn down has no pending counter: its step goes straight to the total.
    let flushed = PENDING.try_with(|p| {
        let pending = p.0.get() + steps;
        if pending >= FLUSH_EVERY {
            TOTAL.fetch_add(pending, Ordering::Relaxed);
            p.0.set(0);
        } else {
            p.0.set(pending);
        }
    });
    if flushed.is_err() {
        TOTAL.fetch_add(steps, Ordering::Relaxed);
    }
}

/// The steps of the whole process so far: every flushed step and the calling
/// thread's pending ones.
pub fn total() -> u64 {
    TOTAL.load(Ordering::Relaxed) + PENDING.try_with(|p| p.0.get()).unwrap_or(0)
}

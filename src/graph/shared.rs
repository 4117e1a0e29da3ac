//! One evaluation read by several factors: the last result of an expensive
//! call, kept with the inputs it was computed at.
//!
//! The length and height factors of a pose (paper eq. 14 and 15) and its
//! tension guard read different rows of one generated call
//! (`generated::catenary_cable_residuals`). Each factor is still its own
//! [`super::Factor`] (its own sigmas, robust kernel, masked rows and
//! per-type statistics); the first one evaluated at a point makes the call,
//! the others find its result here. Solvers evaluate a pose's factors one
//! after the other, so one remembered result per graph is enough.
//!
//! ```
//! use std::cell::Cell;
//! use sagcal::graph::SharedEvaluation;
//! // Two factors read one expensive call (here: both roots of x^2 - s); the call runs once per input.
//! let calls = Cell::new(0);
//! let roots = SharedEvaluation::<1, [f64; 2]>::default();
//! let evaluate = |out: &mut [f64; 2], _jacobians: bool| {
//!     calls.set(calls.get() + 1);
//!     *out = [2f64.sqrt(), -2f64.sqrt()];
//! };
//! let plus = roots.read(&[2.0], false, evaluate, |r| r[0]);
//! let minus = roots.read(&[2.0], false, evaluate, |r| r[1]);
//! assert!((plus * plus - 2.0).abs() < 1e-15 && minus == -plus);
//! assert_eq!(calls.get(), 1);
//! // Asking for Jacobians the memo does not hold, or new inputs, calls again.
//! roots.read(&[2.0], true, evaluate, |_| ());
//! assert_eq!(calls.get(), 2);
//! ```

use std::sync::{Mutex, PoisonError};

/// The last result `T` of a call on `N` scalar inputs, compared bit for bit
/// (so a hit returns exactly what a new call would).
pub struct SharedEvaluation<const N: usize, T> {
    last: Mutex<Memo<N, T>>,
}

struct Memo<const N: usize, T> {
    /// The inputs' bits; `None`: nothing evaluated yet.
    key: Option<[u64; N]>,
    /// The stamp under which `result` was last read by
    /// [`SharedEvaluation::read_stamped`] or made by [`SharedEvaluation::read_by_stamp`].
    stamp: Option<[u64; 2]>,
    /// Whether `result` holds the Jacobians too.
    jacobians: bool,
    result: T,
}

impl<const N: usize, T> Memo<N, T> {
    /// `evaluate` into the result, then remember it under `key` and `stamp`
    /// (invalid until the call returns: a panic inside leaves no stale key).
    #[inline(always)]
    fn remake(
        &mut self,
        key: Option<[u64; N]>,
        stamp: Option<[u64; 2]>,
        jacobians: bool,
        evaluate: impl FnOnce(&mut T, bool),
    ) {
        self.key = None;
        self.stamp = None;
        evaluate(&mut self.result, jacobians);
        self.key = key;
        self.stamp = stamp;
        self.jacobians = jacobians;
    }
}

impl<const N: usize, T: Default> Default for SharedEvaluation<N, T> {
    fn default() -> Self {
        Self {
            last: Mutex::new(Memo {
                key: None,
                stamp: None,
                jacobians: false,
                result: T::default(),
            }),
        }
    }
}

impl<const N: usize, T: Default> SharedEvaluation<N, T> {
    /// `read` of the result at `inputs`, with Jacobians if `jacobians`: the
    /// remembered one when it was computed at these inputs (with Jacobians,
    /// if asked for), else `evaluate(result, jacobians)` into the buffer,
    /// remembered for the next reader.
    pub fn read<R>(
        &self,
        inputs: &[f64; N],
        jacobians: bool,
        evaluate: impl FnOnce(&mut T, bool),
        read: impl FnOnce(&T) -> R,
    ) -> R {
        let key = inputs.map(f64::to_bits);
        let mut memo = self.last.lock().unwrap_or_else(PoisonError::into_inner);
        if memo.key != Some(key) || (jacobians && !memo.jacobians) {
            memo.remake(Some(key), None, jacobians, evaluate);
        }
        read(&memo.result)
    }

    /// [`SharedEvaluation::read`] keyed by a `stamp` alone (equal stamps
    /// must mean equal inputs): for a memo whose calls are never repeated at
    /// equal inputs under another stamp, where comparing the inputs would
    /// only cost.
    pub fn read_by_stamp<R>(
        &self,
        stamp: [u64; 2],
        jacobians: bool,
        evaluate: impl FnOnce(&mut T, bool),
        read: impl FnOnce(&T) -> R,
    ) -> R {
        let mut memo = self.last.lock().unwrap_or_else(PoisonError::into_inner);
        if memo.stamp != Some(stamp) || (jacobians && !memo.jacobians) {
            memo.remake(None, Some(stamp), jacobians, evaluate);
        }
        read(&memo.result)
    }

    /// [`SharedEvaluation::read`] with a cheaper first test: `stamp` stands
    /// for the inputs (equal stamps must mean equal inputs, e.g. a
    /// [`crate::graph::Values::stamp`] and the variable the call is for).
    /// When it matches the remembered one the inputs are not even gathered;
    /// otherwise `inputs()` are compared bit for bit as by `read` (so a call
    /// made at equal values under another stamp is still found), and a new
    /// call is made from them: `evaluate(result, jacobians, inputs)`.
    pub fn read_stamped<R>(
        &self,
        stamp: [u64; 2],
        inputs: impl FnOnce() -> [f64; N],
        jacobians: bool,
        evaluate: impl FnOnce(&mut T, bool, &[f64; N]),
        read: impl FnOnce(&T) -> R,
    ) -> R {
        let mut memo = self.last.lock().unwrap_or_else(PoisonError::into_inner);
        let covered = !jacobians || memo.jacobians;
        if !(covered && memo.key.is_some() && memo.stamp == Some(stamp)) {
            let inputs = inputs();
            let key = inputs.map(f64::to_bits);
            if memo.key != Some(key) || !covered {
                memo.remake(Some(key), None, jacobians, |result, want| {
                    evaluate(result, want, &inputs)
                });
            }
            memo.stamp = Some(stamp);
        }
        read(&memo.result)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn a_second_reader_at_the_same_inputs_does_not_call_again() {
        let shared = SharedEvaluation::<2, f64>::default();
        let calls = Cell::new(0);
        let call = |out: &mut f64, _: bool, x: [f64; 2]| {
            calls.set(calls.get() + 1);
            *out = x[0] * x[1];
        };
        let x = [3.0, 4.0];
        assert_eq!(shared.read(&x, false, |o, j| call(o, j, x), |r| *r), 12.0);
        assert_eq!(shared.read(&x, false, |o, j| call(o, j, x), |r| *r), 12.0);
        assert_eq!(calls.get(), 1);
        // Jacobians asked for after a value-only call: evaluated again, then kept.
        shared.read(&x, true, |o, j| call(o, j, x), |r| *r);
        shared.read(&x, false, |o, j| call(o, j, x), |r| *r);
        assert_eq!(calls.get(), 2);
        // Other inputs (-0.0 differs from 0.0 in its bits): a new call.
        let y = [3.0, -0.0];
        assert_eq!(shared.read(&y, false, |o, j| call(o, j, y), |r| *r), -0.0);
        assert_eq!(calls.get(), 3);
    }

    /// A stamp hit reads without gathering the inputs; a new stamp with equal
    /// inputs is found by comparing them (no call); new inputs call again.
    /// By stamp alone, every new stamp calls.
    #[test]
    fn stamped_reads_skip_the_inputs_and_fall_back_to_them() {
        let shared = SharedEvaluation::<2, f64>::default();
        let (calls, gathers) = (Cell::new(0), Cell::new(0));
        let read = |stamp: u64, x: [f64; 2]| {
            let inputs = || {
                gathers.set(gathers.get() + 1);
                x
            };
            let evaluate = |out: &mut f64, _: bool, x: &[f64; 2]| {
                calls.set(calls.get() + 1);
                *out = x[0] + x[1];
            };
            shared.read_stamped([stamp, 7], inputs, false, evaluate, |r| *r)
        };
        assert_eq!(read(1, [1.0, 2.0]), 3.0);
        assert_eq!((calls.get(), gathers.get()), (1, 1));
        assert_eq!(read(1, [1.0, 2.0]), 3.0);
        assert_eq!((calls.get(), gathers.get()), (1, 1));
        assert_eq!(read(2, [1.0, 2.0]), 3.0);
        assert_eq!((calls.get(), gathers.get()), (1, 2));
        assert_eq!(read(2, [1.0, 2.0]), 3.0);
        assert_eq!((calls.get(), gathers.get()), (1, 2));
        assert_eq!(read(3, [1.0, 5.0]), 6.0);
        assert_eq!((calls.get(), gathers.get()), (2, 3));
        let by_stamp = SharedEvaluation::<2, f64>::default();
        let count = Cell::new(0);
        let evaluate = |out: &mut f64, _: bool| {
            count.set(count.get() + 1);
            *out = count.get() as f64;
        };
        assert_eq!(by_stamp.read_by_stamp([4, 1], false, evaluate, |r| *r), 1.0);
        assert_eq!(
            by_stamp.read_by_stamp([4, 1], false, |_, _| unreachable!(), |r| *r),
            1.0
        );
        assert_eq!(by_stamp.read_by_stamp([4, 2], false, evaluate, |r| *r), 2.0);
        // Jacobians not held: called again under the same stamp.
        assert_eq!(by_stamp.read_by_stamp([4, 2], true, evaluate, |r| *r), 3.0);
    }
}

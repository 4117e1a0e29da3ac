//! Single gross errors in a calibration of `N` cables (Baarda's data
//! snooping, as [`crate::calib::gross_errors`] does for four cables): after
//! a solve, every reading's normalised residual `w = e / (sigma sqrt(r))`
//! (`r` its redundancy number, [`redundancy_numbers`]) is standard normal
//! when the model holds; the largest `|w|` above the two-sided critical
//! value at the false-alarm rate divided among all readings (Bonferroni) is
//! a gross error. The calibration leaves it out and solves again, one
//! reading at a time, at most a fraction of the readings.
//!
//! An encoder's redundancy number is small here (about 0.004 on the
//! six-cable robot): its cable's own forces absorb most of a wrong length
//! as a different sag, only the equilibrium with the other cables checks
//! it. Its `w` still finds a 0.5 m error, but `-e / r`, Baarda's linear
//! estimate of the error's size, is far off at such a reading (2.4 m for
//! that 0.5 m), so the report gives the residual and `w`, not a size.

use serde::Serialize;

use super::graph::{SuspendedGraph, SuspendedReading};
use crate::error::Result;
use crate::model::DataRow;
use crate::solver::redundancy_numbers;
use crate::stats::chi_square_critical;

/// The factor kinds whose rows are readings (encoders, load cells, the localiser).
pub const READING_KINDS: [&str; 3] = ["catenary_length", "load_cell", "pose_prior"];

/// Redundancy numbers below this are readings the fit cannot check (their
/// `w` would divide by nearly zero).
const MIN_REDUNDANCY: f64 = 1e-6;

/// A reading the tests found to be a gross error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedGrossError {
    /// The pose's row (from 1) and line in its file.
    #[serde(flatten)]
    pub at: DataRow,
    /// Which reading.
    pub reading: SuspendedReading,
    /// Its residual at the fit it was found in (metres, newtons or radians).
    pub residual: f64,
    /// Its sigma.
    pub sigma: f64,
    /// Its redundancy number.
    pub redundancy: f64,
    /// Its normalised residual.
    pub w: f64,
    /// The critical `|w|` it exceeded.
    pub critical: f64,
}

/// The number of readings of a graph (rows of reading factors).
pub fn reading_count(built: &SuspendedGraph) -> usize {
    built.readings.iter().map(Vec::len).sum()
}

/// The reading of the solved `built` with the largest `|w|`, if it exceeds
/// the critical value at `false_alarm` over all its readings; `rows[k]`
/// names pose `k`.
pub fn worst_reading(
    built: &SuspendedGraph,
    false_alarm: f64,
    rows: &[DataRow],
) -> Result<Option<SuspendedGrossError>> {
    let count = reading_count(built).max(1);
    let critical = chi_square_critical(1, false_alarm / count as f64).sqrt();
    let redundancy = redundancy_numbers(&built.graph, &READING_KINDS)?;
    let mut worst: Option<SuspendedGrossError> = None;
    for ((factor, numbers), readings) in built.graph.factors.iter().zip(&redundancy).zip(&built.readings) {
        let Some(numbers) = numbers else {
            continue;
        };
        let Some(residual) = factor.evaluate(&built.graph.values, None) else {
            continue;
        };
        for (row, &(pose, reading)) in readings.iter().enumerate() {
            let (e, sigma, r) = (residual[row], factor.sigmas()[row], numbers[row]);
            if r < MIN_REDUNDANCY {
                continue;
            }
            let w = e / (sigma * r.sqrt());
            if w.abs() > critical && worst.as_ref().is_none_or(|best| w.abs() > best.w.abs()) {
                worst = Some(SuspendedGrossError {
                    at: rows[pose],
                    reading,
                    residual: e,
                    sigma,
                    redundancy: r,
                    w,
                    critical,
                });
            }
        }
    }
    Ok(worst)
}

//! A robot of `N` cables against measured data ([`verify_suspended`]):
//! `sagcal verify` on a robot of 3 to 8 cables.
//!
//! The robot is held as its file gives it (anchors, encoder offsets, cable
//! and platform weights, stiffness); at every row the platform's pose and
//! each cable's end forces are fitted to the row's readings (the
//! localiser's position, every encoder, every load cell), each weighed by
//! its sigma, with the statics (paper eq. 5-8, 14-16) held as tight
//! constraints. The orientation is predicted, never an input (as in the
//! four-cable verify, paper Sec. V-A): its angle to the localiser's is
//! reported beside the fit. Where the four-cable verify closes the model
//! with one reading, `N` cables leave `N - 3` force components free at a
//! position, so the readings close it together, by least squares.
//!
//! What is left is tested, each test at a stated false-alarm rate `a`:
//! - the whole file: the summed chi-square against the `1 - a` quantile of
//!   chi-square with the redundancy's degrees of freedom (`3 + K` per row
//!   for `K` load cells: the pose's six coordinates and `N` free forces
//!   against `3 + N + K` readings);
//! - each row: its chi-square against the `1 - a / rows` quantile of its
//!   own degrees of freedom (Bonferroni over the rows; with the robot held
//!   the rows' fits are independent);
//! - each reading: Baarda's normalised residual `w = e / (sigma sqrt(r))`
//!   (`r` its redundancy number, [`crate::solver::redundancy_numbers`])
//!   against the two-sided `a / readings` normal quantile. A reading with a
//!   small `r` is checked little by the others, so an error of a few sigma
//!   there stays hidden: on the six-cable robot with its one load cell the
//!   encoders' `r` are 0.35 to 0.7 and the load cell's 0.06 (its cable's
//!   forces follow it, only the platform's balance checks it); the report
//!   gives each reading's mean `r` so that this shows.
//!
//! Per cable the mean and RMS of the length residuals summarise what an
//! offset or an anchor error would leave; per load cell the same in newtons;
//! for each, the smallest single error its `w` test finds with 80 % power
//! (Baarda's minimal detectable bias: internal reliability).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::diagnose::suspended::verify_suspended;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! use sagcal::sim::closed_form::Closure;
//! use sagcal::sim::suspended::{measure_suspended, sample_suspended};
//! let robot = SuspendedRobot::builtin("six")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
//! let workspace = robot.workspace.unwrap();
//! let equilibria = sample_suspended(&robot, &workspace, 6, Closure::Yaw { max_yaw_deg: 5.0 }, &mut rng)?;
//! let sigmas = NoisePreset::Paper.sigmas(robot.platform_weight_n);
//! let rows = measure_suspended(&robot, &equilibria, &NoisePreset::None.sigmas(robot.platform_weight_n), &mut rng)?;
//! let report = verify_suspended(&robot, "model", &rows, &CalibrationOptions::new(sigmas), 1e-3)?;
//! // Readings the model made itself: nothing left, 3 + 1 degrees of freedom a row.
//! assert!(report.chi_square < 1e-12 && report.passes, "{}", report.chi_square);
//! assert_eq!(report.degrees_of_freedom, 6 * 4);
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::Serialize;

use super::held_out::fit_poses_robot_held;
use crate::calib::suspended::{SuspendedGraph, SuspendedReading, READING_KINDS};
use crate::calib::CalibrationOptions;
use crate::error::{Error, Result};
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use crate::model::DataRow;
use crate::solver::redundancy_numbers;
use crate::stats::chi_square_critical;

/// The standard normal quantile of 80 %: the power at which
/// [`ResidualSummary::minimal_detectable`] is stated (Baarda's
/// `delta_0 = z_(1 - a/2) + z_power`).
pub const DETECTION_POWER_Z: f64 = 0.841_621_233_572_914_3;

/// Redundancy numbers below this are readings the fit does not check: no
/// normalised residual is formed for them.
const MIN_REDUNDANCY: f64 = 1e-6;

/// One reading after the fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VerifiedReading {
    /// Which reading.
    pub reading: SuspendedReading,
    /// The reading less the model's value: metres, newtons.
    pub residual: f64,
    /// Its sigma (the factor weight).
    pub sigma: f64,
    /// Its redundancy number: the share of an error in it the fit shows.
    pub redundancy: f64,
    /// Its normalised residual `e / (sigma sqrt(r))`; `None` where `r` is
    /// below 1e-6.
    pub w: Option<f64>,
}

/// One row of the data after the fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedVerifiedRow {
    /// The row (from 1) and its line in the file.
    #[serde(flatten)]
    pub at: DataRow,
    /// The localiser's position, metres.
    pub position_m: [f64; 3],
    /// The row's chi-square (its readings' weighted squared residuals).
    pub chi_square: f64,
    /// Its degrees of freedom (the sum of its readings' redundancy numbers).
    pub degrees_of_freedom: usize,
    /// Its limit: the `1 - false_alarm / rows` quantile.
    pub limit: f64,
    /// Whether its chi-square is within the limit.
    pub passes: bool,
    /// The angle between the fitted orientation and the localiser's, degrees.
    pub orientation_error_deg: f64,
    /// Every reading of the row, in the graph's order (encoders, load cells, position).
    pub readings: Vec<VerifiedReading>,
}

impl SuspendedVerifiedRow {
    /// The row's reading `which`, if it has one.
    pub fn reading(&self, which: SuspendedReading) -> Option<&VerifiedReading> {
        self.readings.iter().find(|r| r.reading == which)
    }

    /// The reading with the largest `|w|`, if any was checked.
    pub fn worst(&self) -> Option<&VerifiedReading> {
        self.readings
            .iter()
            .filter(|r| r.w.is_some())
            .max_by(|a, b| a.w.unwrap_or(0.0).abs().total_cmp(&b.w.unwrap_or(0.0).abs()))
    }
}

/// The mean and root mean square of one reading's residuals over the rows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualSummary {
    /// Which reading (its pose index unused).
    pub reading: SuspendedReading,
    /// Mean residual (reading less model): metres or newtons.
    pub mean: f64,
    /// Root mean square residual.
    pub rms: f64,
    /// Its sigma.
    pub sigma: f64,
    /// Mean redundancy number over the rows.
    pub mean_redundancy: f64,
    /// The smallest single error in this reading that its `w` test finds
    /// with 80 % power (Baarda's minimal detectable bias,
    /// `(|w| limit + 0.8416) sigma / sqrt(r)` at the mean `r`): metres or
    /// newtons; `None` where the fit does not check it.
    pub minimal_detectable: Option<f64>,
}

/// A reading beyond the per-reading limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspectReading {
    /// Its row.
    #[serde(flatten)]
    pub at: DataRow,
    /// The reading.
    pub reading: VerifiedReading,
}

/// The verification of a robot of `N` cables against a data file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedVerifyReport {
    /// The robot's name.
    pub robot: String,
    /// Its number of cables.
    pub cables: usize,
    /// The cables with a load cell, from 1.
    pub load_cells: Vec<usize>,
    /// Where the data came from.
    pub data: String,
    /// The false-alarm rate of every test.
    pub false_alarm: f64,
    /// Every row.
    pub rows: Vec<SuspendedVerifiedRow>,
    /// The summed chi-square.
    pub chi_square: f64,
    /// Its degrees of freedom.
    pub degrees_of_freedom: usize,
    /// The `1 - false_alarm` quantile.
    pub limit: f64,
    /// Whether the summed chi-square is within it.
    pub passes: bool,
    /// The critical `|w|` of a single reading (two-sided, `false_alarm`
    /// shared over every checked reading).
    pub reading_limit: f64,
    /// The readings beyond it, largest `|w|` first.
    pub suspect_readings: Vec<SuspectReading>,
    /// Per encoder, then per load cell: the residuals over the rows.
    pub summaries: Vec<ResidualSummary>,
    /// One sentence: what the tests found.
    pub conclusion: String,
}

/// Verify `robot` (held) against `measurements` from `data` (a path or a
/// label), weighing the readings by `options`' sigmas and testing at
/// `false_alarm` (module docs). Fails for no rows, a false-alarm rate
/// outside (0, 1), or a fit that does not converge.
pub fn verify_suspended(
    robot: &SuspendedRobot,
    data: &str,
    measurements: &[SuspendedMeasurement],
    options: &CalibrationOptions,
    false_alarm: f64,
) -> Result<SuspendedVerifyReport> {
    if measurements.is_empty() {
        return Err(Error::InvalidInput(format!("{data}: no rows to verify")));
    }
    if !(false_alarm > 0.0 && false_alarm < 1.0) {
        return Err(Error::InvalidInput(format!(
            "false-alarm rate {false_alarm}: must lie strictly between 0 and 1"
        )));
    }
    let built =
        fit_poses_robot_held(robot, measurements, options, false).map_err(|e| e.during("verifying the rows"))?;
    let rows = verified_rows(&built, measurements, false_alarm)?;
    let chi_square: f64 = rows.iter().map(|r| r.chi_square).sum();
    let degrees_of_freedom: usize = rows.iter().map(|r| r.degrees_of_freedom).sum();
    let limit = chi_square_critical(degrees_of_freedom.max(1), false_alarm);
    let checked = rows.iter().flat_map(|r| &r.readings).filter(|r| r.w.is_some()).count();
    let reading_limit = chi_square_critical(1, false_alarm / checked.max(1) as f64).sqrt();
    let suspect_readings = suspects(&rows, reading_limit);
    let mut report = SuspendedVerifyReport {
        robot: robot.name.clone(),
        cables: robot.cable_count(),
        load_cells: robot.load_cells.iter().map(|c| c + 1).collect(),
        data: data.to_string(),
        false_alarm,
        summaries: summaries(robot, &rows, reading_limit),
        chi_square,
        degrees_of_freedom,
        limit,
        passes: chi_square <= limit,
        reading_limit,
        suspect_readings,
        rows,
        conclusion: String::new(),
    };
    report.conclusion = conclusion(&report);
    Ok(report)
}

/// Each row's readings, chi-square and test.
fn verified_rows(
    built: &SuspendedGraph,
    measurements: &[SuspendedMeasurement],
    false_alarm: f64,
) -> Result<Vec<SuspendedVerifiedRow>> {
    let redundancy = redundancy_numbers(&built.graph, &READING_KINDS)?;
    let mut readings: Vec<Vec<VerifiedReading>> = vec![Vec::new(); measurements.len()];
    for ((factor, numbers), rows) in built.graph.factors.iter().zip(&redundancy).zip(&built.readings) {
        let (Some(numbers), Some(residual)) = (numbers, factor.evaluate(&built.graph.values, None)) else {
            continue;
        };
        for (row, &(pose, reading)) in rows.iter().enumerate() {
            let (e, sigma, r) = (residual[row], factor.sigmas()[row], numbers[row]);
            readings[pose].push(VerifiedReading {
                reading,
                residual: -e,
                sigma,
                redundancy: r,
                w: (r >= MIN_REDUNDANCY).then(|| -e / (sigma * r.sqrt())),
            });
        }
    }
    let share = false_alarm / measurements.len() as f64;
    Ok(measurements
        .iter()
        .zip(readings)
        .zip(&built.poses)
        .enumerate()
        .map(|(k, ((m, readings), vars))| {
            let chi_square: f64 = readings.iter().map(|r| (r.residual / r.sigma).powi(2)).sum();
            let degrees_of_freedom = readings.iter().map(|r| r.redundancy).sum::<f64>().round() as usize;
            let limit = chi_square_critical(degrees_of_freedom.max(1), share);
            SuspendedVerifiedRow {
                at: DataRow::at(k, m.line),
                position_m: m.position_m,
                chi_square,
                degrees_of_freedom,
                limit,
                passes: chi_square <= limit,
                orientation_error_deg: built.graph.values.pose(vars.pose).angle_to_deg(&m.localiser_pose()),
                readings,
            }
        })
        .collect())
}

/// The readings whose `|w|` exceeds `limit`, largest first.
fn suspects(rows: &[SuspendedVerifiedRow], limit: f64) -> Vec<SuspectReading> {
    let mut found: Vec<SuspectReading> = rows
        .iter()
        .flat_map(|row| {
            row.readings
                .iter()
                .filter(|r| r.w.is_some_and(|w| w.abs() > limit))
                .map(|r| SuspectReading {
                    at: row.at,
                    reading: r.clone(),
                })
        })
        .collect();
    found.sort_by(|a, b| {
        let size = |s: &SuspectReading| s.reading.w.unwrap_or(0.0).abs();
        size(b).total_cmp(&size(a))
    });
    found
}

/// Per encoder and per load cell, the residuals' mean and RMS over the rows
/// and the smallest error the `w` test at `reading_limit` finds.
fn summaries(robot: &SuspendedRobot, rows: &[SuspendedVerifiedRow], reading_limit: f64) -> Vec<ResidualSummary> {
    let which = (0..robot.cable_count())
        .map(SuspendedReading::Encoder)
        .chain(robot.load_cells.iter().map(|&c| SuspendedReading::LoadCell(c)));
    which
        .filter_map(|reading| {
            let found: Vec<&VerifiedReading> = rows.iter().filter_map(|row| row.reading(reading)).collect();
            let n = found.len() as f64;
            let first = found.first()?;
            let mean_redundancy = found.iter().map(|r| r.redundancy).sum::<f64>() / n;
            Some(ResidualSummary {
                reading,
                mean: found.iter().map(|r| r.residual).sum::<f64>() / n,
                rms: (found.iter().map(|r| r.residual.powi(2)).sum::<f64>() / n).sqrt(),
                sigma: first.sigma,
                mean_redundancy,
                minimal_detectable: (mean_redundancy >= MIN_REDUNDANCY)
                    .then(|| (reading_limit + DETECTION_POWER_Z) * first.sigma / mean_redundancy.sqrt()),
            })
        })
        .collect()
}

/// The report's conclusion.
fn conclusion(report: &SuspendedVerifyReport) -> String {
    let failing = report.rows.iter().filter(|r| !r.passes).count();
    let whole = if report.passes {
        format!(
            "the robot file describes the data: chi-square {:.1} for {} degrees of freedom (limit {:.1} at {})",
            report.chi_square, report.degrees_of_freedom, report.limit, report.false_alarm
        )
    } else {
        format!(
            "the robot file does not describe the data: chi-square {:.1} for {} degrees of freedom (limit {:.1} at {})",
            report.chi_square, report.degrees_of_freedom, report.limit, report.false_alarm
        )
    };
    format!(
        "{whole}; {failing} of {} rows beyond their own limit; {} readings beyond |w| {:.2}",
        report.rows.len(),
        report.suspect_readings.len(),
        report.reading_limit
    )
}

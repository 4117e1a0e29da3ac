//! Data snooping at one fit: each reading's normalised residual with its
//! redundancy number (Baarda's w-test) and each sensor type's chi-square
//! against its redundancy ([`super::gross_errors`] for the procedure); and
//! a reading left out as a gross error, with its test ([`ExcludedReading`]).

use std::collections::HashMap;

use serde::Serialize;

use super::graph::{build_graph, CalibrationGraph};
use super::options::{CableModel, CalibrationOptions, GrossErrorOptions, OrientationPrior};
use super::refine::{set_effect_estimates, without_estimated};
use super::result::CalibrationResult;
use crate::error::{Error, Result};
use crate::graph::VariableId;
use crate::model::measurement::{PoseMeasurement, Sensor};
use crate::model::robot::CABLE_COUNT;
use crate::model::DataRow;
use crate::solver::redundancy_numbers;
use crate::stats::{chi_square_critical, chi_square_survival};

/// The factor kinds whose rows are readings.
const READING_KINDS: [&str; 4] = ["catenary_length", "rigid_length", "reference_tension", "pose_prior"];

/// The data-snooping test of one reading.
///
/// Its JSON names the reading as every report does
/// ([`crate::model::DataRow`]): `row` (from 1), `line` (`null` without a
/// file), `sensor` (`encoder`, `load_cell`, `position`, `orientation`),
/// `cable` (from 1, for an encoder) and `axis` (`x`, `y`, `z`, for the
/// localiser), then the numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadingTest {
    /// Index of the pose in the measurements given (0-based; `row` - 1 in JSON).
    pub pose: usize,
    /// Line of the pose in its file (0: in-memory data, `null` in JSON).
    pub line: usize,
    /// The reading.
    pub sensor: Sensor,
    /// Model minus reading at the fit (m, N or rad).
    pub residual: f64,
    /// The reading's stated sigma (same unit).
    pub sigma: f64,
    /// Its redundancy number `r` (0..1).
    pub redundancy: f64,
    /// The normalised residual `w = e / (sigma sqrt(r))`.
    pub w: f64,
    /// The estimated error of the reading (reading minus model; same unit):
    /// `-e / r` while it is tested, and for a reading left out, minus its
    /// residual against the final fit (which it did not pull).
    pub estimated_error: f64,
}

impl ReadingTest {
    /// `row 10 (line 12), encoder of cable 1: +5.0000 m off, w = 49.2`.
    pub fn describe(&self) -> String {
        let (value, unit) = match self.sensor {
            Sensor::Encoder(_) | Sensor::Position(_) => (format!("{:+.4}", self.estimated_error), "m"),
            Sensor::LoadCell => (format!("{:+.3}", self.estimated_error), "N"),
            Sensor::Orientation(_) => (format!("{:+.3}", self.estimated_error.to_degrees()), "deg"),
        };
        format!(
            "{}, {}: {value} {unit} off, w = {:.1}",
            row_name(self.pose, self.line),
            self.sensor.describe(),
            self.w
        )
    }
}

impl Serialize for ReadingTest {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        /// The JSON of a [`ReadingTest`].
        #[derive(Serialize)]
        struct Json {
            #[serde(flatten)]
            at: DataRow,
            sensor: &'static str,
            cable: Option<usize>,
            axis: Option<&'static str>,
            residual: f64,
            sigma: f64,
            redundancy: f64,
            w: f64,
            estimated_error: f64,
        }
        const AXES: [&str; 3] = ["x", "y", "z"];
        let (sensor, cable, axis) = match self.sensor {
            Sensor::Encoder(i) => ("encoder", Some(i + 1), None),
            Sensor::LoadCell => ("load_cell", None, None),
            Sensor::Position(a) => ("position", None, AXES.get(a).copied()),
            Sensor::Orientation(a) => ("orientation", None, AXES.get(a).copied()),
        };
        Json {
            at: DataRow::at(self.pose, self.line),
            sensor,
            cable,
            axis,
            residual: self.residual,
            sigma: self.sigma,
            redundancy: self.redundancy,
            w: self.w,
            estimated_error: self.estimated_error,
        }
        .serialize(serializer)
    }
}

/// `row 10 (line 12)` or `row 10` for in-memory data (line 0): the pose of
/// 0-based index `pose` as [`DataRow`] names it.
pub fn row_name(pose: usize, line: usize) -> String {
    DataRow::at(pose, line).to_string()
}

/// The chi-square test of one sensor type.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorTypeTest {
    /// `encoders`, `load cell`, `localiser position` or `localiser orientation`.
    pub sensor: String,
    /// Readings of this type in the fit.
    pub readings: usize,
    /// Sum of their squared normalised residuals.
    pub chi_square: f64,
    /// Its expected value: the sum of their redundancy numbers.
    pub redundancy: f64,
    /// Upper-tail p-value of `chi_square` on `round(redundancy)` degrees of freedom.
    pub p_value: f64,
    /// `p_value` at or above the threshold.
    pub consistent: bool,
}

/// The tests of one fit against the stated noise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConsistencyTest {
    /// Readings tested by the w-test.
    pub readings: usize,
    /// The critical `|w|` (two-sided normal at `alpha / readings`).
    pub critical_w: f64,
    /// The readings with `|w|` above it, largest first.
    pub flagged: Vec<ReadingTest>,
    /// The reading with the largest `|w|`.
    pub largest: Option<ReadingTest>,
    /// Per sensor type.
    pub sensor_types: Vec<SensorTypeTest>,
}

impl ConsistencyTest {
    /// Whether every sensor type passes its chi-square and no reading is flagged.
    pub fn consistent(&self) -> bool {
        self.flagged.is_empty() && self.sensor_types.iter().all(|t| t.consistent)
    }
}

/// A reading left out as a gross error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExcludedReading {
    /// Its test when it was left out.
    pub test: ReadingTest,
    /// A common mistake that explains it, in words, if one does (two cables swapped, ...).
    pub explanation: Option<String>,
}

/// The graph of a fit at its solution: the options as the fit used them
/// (the orientation prior resolved), the estimated effects set.
pub fn graph_at_solution(
    result: &CalibrationResult,
    used: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> CalibrationGraph {
    let mut robot = result.robot.clone();
    robot.effects = without_estimated(&robot.effects, &result.effect_estimates);
    let mut built = build_graph(
        &robot,
        used,
        &result.poses,
        &result.reference_tensions(),
        options.model,
        &options.as_used_by(result),
    );
    set_effect_estimates(&mut built, &result.effect_estimates);
    built
}

/// The measurements a fit used (those of the poses it did not leave out).
pub fn used_measurements(
    result: &CalibrationResult,
    measurements: &[PoseMeasurement],
) -> (Vec<usize>, Vec<PoseMeasurement>) {
    (0..measurements.len())
        .filter(|k| !result.excluded_poses.contains(k))
        .map(|k| (k, measurements[k]))
        .unzip()
}

/// The w-test of every reading and the chi-square of every sensor type at a fit.
pub fn test_fit(
    result: &CalibrationResult,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    check: &GrossErrorOptions,
) -> Result<ConsistencyTest> {
    let (indices, used) = used_measurements(result, measurements);
    let built = graph_at_solution(result, &used, options);
    let numbers = redundancy_numbers(&built.graph, &READING_KINDS)?;
    let with_orientation =
        options.as_used_by(result).orientation_prior == OrientationPrior::On || options.model == CableModel::Rigid;
    let owner = pose_owners(&built);
    let mut tests = Vec::new();
    for (factor, numbers) in built.graph.factors.iter().zip(&numbers) {
        let Some(numbers) = numbers else {
            continue;
        };
        let Some(&k) = factor.variables().iter().find_map(|v| owner.get(v)) else {
            continue;
        };
        let m = &used[k];
        let sensors: Vec<Sensor> = full_rows(factor.kind(), with_orientation)
            .into_iter()
            .filter(|s| !m.excluded.contains(*s))
            .collect();
        let residual = factor
            .evaluate(&built.graph.values, None)
            .ok_or_else(|| Error::NoEquilibrium("a reading's factor is undefined at the fit".into()))?;
        for (row, sensor) in sensors.into_iter().enumerate() {
            let (e, sigma, r) = (residual[row], factor.sigmas()[row], numbers[row]);
            if r < 1e-6 {
                continue; // an uncontrolled reading: no residual can show its error
            }
            tests.push(ReadingTest {
                pose: indices[k],
                line: m.line,
                sensor,
                residual: e,
                sigma,
                redundancy: r,
                w: e / (sigma * r.sqrt()),
                estimated_error: -e / r,
            });
        }
    }
    Ok(summarise(tests, check))
}

/// Every reading's residual (model minus reading) and sigma at a fit, the
/// readings it left out too (evaluated, not fitted), keyed by the index of
/// the pose in `measurements` and the sensor.
pub fn residuals_at_fit(
    result: &CalibrationResult,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> HashMap<(usize, Sensor), (f64, f64)> {
    let (indices, mut used) = used_measurements(result, measurements);
    for m in &mut used {
        m.excluded = crate::model::measurement::ReadingSet::NONE;
    }
    let built = graph_at_solution(result, &used, options);
    let with_orientation =
        options.as_used_by(result).orientation_prior == OrientationPrior::On || options.model == CableModel::Rigid;
    let owner = pose_owners(&built);
    let mut all = HashMap::new();
    for factor in &built.graph.factors {
        let Some(&k) = factor.variables().iter().find_map(|v| owner.get(v)) else {
            continue;
        };
        let Some(residual) = factor.evaluate(&built.graph.values, None) else {
            continue;
        };
        for (row, sensor) in full_rows(factor.kind(), with_orientation).into_iter().enumerate() {
            all.insert((indices[k], sensor), (residual[row], factor.sigmas()[row]));
        }
    }
    all
}

/// Pose and reference-tension variables to the index of their pose.
fn pose_owners(built: &CalibrationGraph) -> HashMap<VariableId, usize> {
    built
        .poses
        .iter()
        .enumerate()
        .flat_map(|(k, p)| [(p.pose, k), (p.reference_tension, k)])
        .collect()
}

/// The readings of a factor kind's rows, before any exclusion.
fn full_rows(kind: &str, with_orientation: bool) -> Vec<Sensor> {
    match kind {
        "catenary_length" | "rigid_length" => (0..CABLE_COUNT).map(Sensor::Encoder).collect(),
        "reference_tension" => vec![Sensor::LoadCell],
        "pose_prior" if with_orientation => (0..3)
            .map(Sensor::Orientation)
            .chain((0..3).map(Sensor::Position))
            .collect(),
        "pose_prior" => (0..3).map(Sensor::Position).collect(),
        _ => Vec::new(),
    }
}

/// Whether a reading belongs to a sensor type.
type SensorFilter = fn(Sensor) -> bool;

/// The flagged readings and the per-type chi-squares of `tests`.
fn summarise(tests: Vec<ReadingTest>, check: &GrossErrorOptions) -> ConsistencyTest {
    let n = tests.len().max(1);
    let critical_w = chi_square_critical(1, check.false_alarm / n as f64).sqrt();
    let mut flagged: Vec<ReadingTest> = tests.iter().copied().filter(|t| t.w.abs() > critical_w).collect();
    flagged.sort_by(|a, b| b.w.abs().total_cmp(&a.w.abs()));
    let largest = tests.iter().copied().max_by(|a, b| a.w.abs().total_cmp(&b.w.abs()));
    let types: [(&str, SensorFilter); 4] = [
        ("encoder", |s| matches!(s, Sensor::Encoder(_))),
        ("load cell", |s| s == Sensor::LoadCell),
        ("localiser position", |s| matches!(s, Sensor::Position(_))),
        ("localiser orientation", |s| matches!(s, Sensor::Orientation(_))),
    ];
    let present = types
        .iter()
        .filter(|(_, of)| tests.iter().any(|t| of(t.sensor)))
        .count()
        .max(1);
    let sensor_types = types
        .iter()
        .filter_map(|(name, of)| {
            let mine: Vec<&ReadingTest> = tests.iter().filter(|t| of(t.sensor)).collect();
            if mine.is_empty() {
                return None;
            }
            let chi_square: f64 = mine.iter().map(|t| (t.residual / t.sigma).powi(2)).sum();
            let redundancy: f64 = mine.iter().map(|t| t.redundancy).sum();
            let p_value = chi_square_survival((redundancy.round() as usize).max(1), chi_square);
            Some(SensorTypeTest {
                sensor: name.to_string(),
                readings: mine.len(),
                chi_square,
                redundancy,
                p_value,
                consistent: p_value >= check.false_alarm / present as f64,
            })
        })
        .collect();
    ConsistencyTest {
        readings: tests.len(),
        critical_w,
        flagged,
        largest,
        sensor_types,
    }
}

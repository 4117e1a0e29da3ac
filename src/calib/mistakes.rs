//! Common mistakes in calibration data, named in plain words
//! ([`super::gross_errors`]):
//!
//! - **a sensor in the wrong unit**: the load cell's readings are about 1000
//!   times (mN) or 1/1000 of (kN) the tensions the straight-cable statics give
//!   at the initial anchors, or 1/9.81 of them (kilograms-force); about 9.81
//!   times them when the robot file's weights are masses in kg; an encoder's readings spread about 1000 (mm) or
//!   100 (cm) times as much over the poses as the anchor-to-attachment
//!   distances do (the spread, because the offsets are unknown). Ratios
//!   within a factor of 3 of those are named; the model's own error at a
//!   guess metres off is far below that;
//! - **a pose outside the robot's frame** (the localiser's position outside
//!   the anchors' horizontal footprint or not below them): such rows are left
//!   out before calibrating;
//! - **two cables' readings swapped in a row**: a flagged encoder reading
//!   whose value fits another cable of the same row, and that cable's reading
//!   fits the first, both within 5 sigma of the fit's predictions;
//! - **an encoder whose offset jumps between rows (re-homing)**: a step in
//!   one cable's residuals over the rows (`offset_step`, the shorter run left
//!   out), or three or more readings of one cable left out with the same
//!   estimated error (within 5 sigma of each other, over 10 sigma from 0);
//! - **a pose whose readings fail together**: three or more readings of one
//!   row left out that nothing above explains.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::mistakes::{before_calibration, without_rows_outside, MistakeKind};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let robot = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
//! let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 8, &mut rng)?;
//! let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
//! let mut data = measure(&robot, &equilibria, &noise, &mut rng);
//! assert!(before_calibration(&robot, &data).is_empty());
//! // The load cell logged in kN, and row 3's position 200 m east (the anchors are at x = +-125 m).
//! for m in &mut data {
//!     m.reference_tension_n /= 1000.0;
//! }
//! data[2].position_m[0] = 200.0;
//! let found = before_calibration(&robot, &data);
//! assert_eq!(found.len(), 2, "{found:#?}");
//! assert_eq!(found[0].kind, MistakeKind::WrongUnit);
//! assert!(found[0].message.contains("they look like kN, not N"), "{}", found[0].message);
//! assert_eq!((found[1].kind, found[1].indices()), (MistakeKind::OutsideFrame, vec![2]));
//! assert!(found[1].message.starts_with("row 3"), "{}", found[1].message);
//! let (kept, rows) = without_rows_outside(&data, &found);
//! assert_eq!((kept.len(), rows), (7, vec![0, 1, 3, 4, 5, 6, 7]));
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;
use serde::Serialize;

use std::collections::HashMap;

use super::snooping::{row_name, ExcludedReading, ReadingTest};
use crate::model::measurement::{PoseMeasurement, Sensor};
use crate::model::plausibility::STANDARD_GRAVITY_M_S2;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{cable_geometry, reference_tension_magnitude_guess};
use crate::model::DataRow;

/// What kind of mistake.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MistakeKind {
    /// A sensor's column is in the wrong unit.
    WrongUnit,
    /// A pose lies outside the robot's frame (left out).
    OutsideFrame,
    /// Two cables' readings swapped in one row.
    SwappedCables,
    /// An encoder's offset jumps between rows.
    Rehoming,
    /// Several readings of one pose fail together.
    FailingPose,
}

/// One mistake found, in words.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Mistake {
    /// Its kind.
    pub kind: MistakeKind,
    /// What it is, naming rows, sensors and cables.
    pub message: String,
    /// The rows concerned, as reports name them (`row` from 1, in the
    /// measurements given, and `line`).
    pub rows: Vec<DataRow>,
}

impl Mistake {
    /// The 0-based indices of [`Mistake::rows`] in the measurements given.
    pub fn indices(&self) -> Vec<usize> {
        self.rows.iter().map(|r| r.row - 1).collect()
    }

    /// Whether the mistake is a whole sensor in the wrong unit (no single
    /// reading is to blame; the data must be fixed).
    pub fn is_unit_mistake(&self) -> bool {
        self.kind == MistakeKind::WrongUnit
    }
}

/// How far a unit ratio may be from its nominal value (a factor).
const UNIT_TOLERANCE: f64 = 3.0;

/// The mistakes visible before any fit: units and poses outside the frame.
/// The units are judged on the rows inside the frame only: the statics at a
/// position no cable can reach (a localiser logged in mm) say nothing about
/// the load cell's unit.
pub fn before_calibration(initial: &Robot, measurements: &[PoseMeasurement]) -> Vec<Mistake> {
    let outside = outside_frame(initial, measurements);
    let (inside, _) = without_rows_outside(measurements, &outside);
    let mut found = Vec::new();
    found.extend(load_cell_unit(initial, &inside));
    found.extend(encoder_units(initial, &inside));
    found.extend(outside);
    found
}

/// `measurements` without the rows named outside the frame, with the index
/// of each kept row in `measurements`.
pub fn without_rows_outside(measurements: &[PoseMeasurement], found: &[Mistake]) -> (Vec<PoseMeasurement>, Vec<usize>) {
    let outside: Vec<usize> = found
        .iter()
        .filter(|m| m.kind == MistakeKind::OutsideFrame)
        .flat_map(Mistake::indices)
        .collect();
    (0..measurements.len())
        .filter(|k| !outside.contains(k))
        .map(|k| (measurements[k], k))
        .unzip()
}

fn median(mut values: Vec<f64>) -> Option<f64> {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    Some(values[values.len() / 2])
}

/// Which unit a ratio of about `ratio` to the expected one suggests.
fn unit_for(ratio: f64, candidates: &[(f64, &'static str)]) -> Option<&'static str> {
    candidates
        .iter()
        .find(|(nominal, _)| ratio > nominal / UNIT_TOLERANCE && ratio < nominal * UNIT_TOLERANCE)
        .map(|(_, unit)| *unit)
}

/// What a load cell reading about `ratio` times the statics' tension means.
/// The statics' tensions are linear in the robot file's weights, so weights
/// written as masses (kg, kg/m: `g` = 9.81 times too light) multiply the
/// ratio that correct weights give (about 1: the straight-cable statics at
/// the initial anchors, so above 1 for heavy cables) by 9.81, and a load
/// cell reading kilograms-force divides it by 9.81.
const LOAD_CELL_UNITS: [(f64, &str); 4] = [
    (1e3, "they look like mN, not N (convert the column to newtons)"),
    (1e-3, "they look like kN, not N (convert the column to newtons)"),
    (
        1.0 / STANDARD_GRAVITY_M_S2,
        "they look like kilograms-force, not N (multiply the column by 9.81)",
    ),
    (
        STANDARD_GRAVITY_M_S2,
        "the robot file's weights look like masses in kg, not weights m g in N: multiply each one given as a mass \
         (`platform_weight_n`, `cable_weight_n_per_m`) by 9.81 (both as masses make the readings about 9.81 times what correct \
         weights give, the platform's alone less; if they are weights, the load cell's unit is 9.81 times too small)",
    ),
];

fn load_cell_unit(initial: &Robot, measurements: &[PoseMeasurement]) -> Option<Mistake> {
    let ratios = measurements
        .iter()
        .map(|m| m.reference_tension_n / reference_tension_magnitude_guess(initial, Vector3::from(m.position_m)))
        .collect();
    let ratio = median(ratios)?;
    let meaning = unit_for(ratio, &LOAD_CELL_UNITS)?;
    Some(Mistake {
        kind: MistakeKind::WrongUnit,
        message: format!(
            "the load cell's readings are {ratio:.3e} times the reference tension the statics give at the initial anchors: \
             {meaning}"
        ),
        rows: Vec::new(),
    })
}

fn encoder_units(initial: &Robot, measurements: &[PoseMeasurement]) -> Vec<Mistake> {
    if measurements.len() < 3 {
        return Vec::new();
    }
    let spread = |values: &[f64]| {
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64).sqrt()
    };
    (0..CABLE_COUNT)
        .filter_map(|i| {
            let readings: Vec<f64> = measurements.iter().map(|m| m.encoder_lengths_m[i]).collect();
            let distances: Vec<f64> = measurements
                .iter()
                .map(|m| {
                    let pose = PlatformPose::from_position(Vector3::from(m.position_m));
                    (initial.anchors_m[i] - cable_geometry(initial, &pose)[i].attachment_world_m).norm()
                })
                .collect();
            let ratio = spread(&readings) / spread(&distances);
            let unit = unit_for(ratio, &[(1e3, "mm"), (1e2, "cm")])?;
            Some(Mistake {
                kind: MistakeKind::WrongUnit,
                message: format!(
                    "the encoder of cable {} varies {ratio:.0} times as much over the poses as the cable's length can: \
                     its readings look like {unit}, not m (convert the column to metres)",
                    i + 1
                ),
                rows: Vec::new(),
            })
        })
        .collect()
}

fn outside_frame(initial: &Robot, measurements: &[PoseMeasurement]) -> Vec<Mistake> {
    let min = initial
        .anchors_m
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |m, a| m.inf(a));
    let max = initial
        .anchors_m
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |m, a| m.sup(a));
    measurements
        .iter()
        .enumerate()
        .filter(|(_, m)| {
            let p = m.position_m;
            p[0] < min.x || p[0] > max.x || p[1] < min.y || p[1] > max.y || p[2] >= min.z
        })
        .map(|(k, m)| Mistake {
            kind: MistakeKind::OutsideFrame,
            rows: vec![DataRow::at(k, m.line)],
            message: format!(
                "{}: the localiser's position [{:.3}, {:.3}, {:.3}] m is outside the robot's frame \
                 (x {:.2} .. {:.2}, y {:.2} .. {:.2}, below z = {:.2} m): no cable can hold the platform there; the row is left out",
                row_name(k, m.line),
                m.position_m[0],
                m.position_m[1],
                m.position_m[2],
                min.x,
                max.x,
                min.y,
                max.y,
                min.z
            ),
        })
        .collect()
}

/// The mistakes that explain readings left out after a fit: swapped cables,
/// re-homed encoders, and poses whose readings fail together. Sets the
/// explanation of the readings concerned. `rows[k]` is the row (0-based, in
/// the data given) of `measurements[k]`; `at_fit` every reading's residual
/// and sigma at the final fit ([`super::gross_errors::residuals_at_fit`]).
pub fn after_calibration(
    measurements: &[PoseMeasurement],
    rows: &[usize],
    at_fit: &HashMap<(usize, Sensor), (f64, f64)>,
    excluded: &mut [ExcludedReading],
) -> Vec<Mistake> {
    let mut found = swapped_cables(measurements, rows, at_fit, excluded);
    found.extend(rehoming(excluded, rows));
    found.extend(failing_poses(measurements, rows, excluded));
    found
}

fn swapped_cables(
    measurements: &[PoseMeasurement],
    rows: &[usize],
    at_fit: &HashMap<(usize, Sensor), (f64, f64)>,
    excluded: &mut [ExcludedReading],
) -> Vec<Mistake> {
    let mut poses: Vec<usize> = excluded
        .iter()
        .filter(|x| matches!(x.test.sensor, Sensor::Encoder(_)))
        .map(|x| x.test.pose)
        .collect();
    poses.dedup();
    let mut found = Vec::new();
    for k in poses {
        let reading = measurements[k].encoder_lengths_m;
        // The reading the fit predicts for each cable, and its sigma.
        let Some(predicted): Option<Vec<(f64, f64)>> = (0..CABLE_COUNT)
            .map(|i| at_fit.get(&(k, Sensor::Encoder(i))).map(|&(e, s)| (reading[i] + e, s)))
            .collect()
        else {
            continue;
        };
        for i in 0..CABLE_COUNT {
            for j in i + 1..CABLE_COUNT {
                let flagged = |c: usize| measurements[k].excluded.contains(Sensor::Encoder(c));
                if !(flagged(i) || flagged(j)) {
                    continue;
                }
                let a = (reading[j] - predicted[i].0) / predicted[i].1;
                let b = (reading[i] - predicted[j].0) / predicted[j].1;
                if a.abs() < 5.0 && b.abs() < 5.0 {
                    let message = format!(
                        "{}: the readings of cables {} and {} are swapped (each fits the other cable to {:.1} and {:.1} sigma)",
                        row_name(rows[k], measurements[k].line),
                        i + 1,
                        j + 1,
                        a.abs(),
                        b.abs()
                    );
                    for x in excluded
                        .iter_mut()
                        .filter(|x| x.test.pose == k && matches!(x.test.sensor, Sensor::Encoder(c) if c == i || c == j))
                    {
                        x.explanation = Some(message.clone());
                    }
                    found.push(Mistake {
                        kind: MistakeKind::SwappedCables,
                        message,
                        rows: vec![DataRow::at(rows[k], measurements[k].line)],
                    });
                }
            }
        }
    }
    found
}

/// Three or more readings of one pose left out and no other explanation:
/// the pose itself is wrong (a localiser blunder, or the robot was not where
/// the row says), and its readings cannot be told apart.
fn failing_poses(measurements: &[PoseMeasurement], rows: &[usize], excluded: &mut [ExcludedReading]) -> Vec<Mistake> {
    let mut found = Vec::new();
    let mut poses: Vec<usize> = excluded.iter().map(|x| x.test.pose).collect();
    poses.sort_unstable();
    poses.dedup();
    for k in poses {
        let mine: Vec<usize> = (0..excluded.len())
            .filter(|&x| excluded[x].test.pose == k && excluded[x].explanation.is_none())
            .collect();
        if mine.len() < 3 {
            continue;
        }
        let names: Vec<String> = mine.iter().map(|&x| excluded[x].test.sensor.describe()).collect();
        let message = format!(
            "{}: {} of its readings fail together ({}): the pose itself looks wrong \
             (a localiser blunder, or the robot was not where the row says); check the row",
            row_name(rows[k], measurements[k].line),
            mine.len(),
            names.join(", ")
        );
        for &x in &mine {
            excluded[x].explanation = Some(message.clone());
        }
        found.push(Mistake {
            kind: MistakeKind::FailingPose,
            message,
            rows: vec![DataRow::at(rows[k], measurements[k].line)],
        });
    }
    found
}

/// An encoder whose offset jumps part-way through the rows (re-homing): per
/// cable, the split of its residual series (in row order) with the largest
/// two-sample t statistic of the means before and after; a step counts when
/// `t` exceeds the normal quantile at `false_alarm` over the cables and
/// splits (Bonferroni) and the jump is over 10 sigma. Returns the cable and
/// the rows of the shorter run (the later one on a tie), to be left out.
pub fn offset_step(
    measurements: &[PoseMeasurement],
    at_fit: &HashMap<(usize, Sensor), (f64, f64)>,
    false_alarm: f64,
) -> Option<(usize, Vec<usize>)> {
    let mut best: Option<(f64, usize, usize, Vec<usize>)> = None;
    for cable in 0..CABLE_COUNT {
        let series: Vec<(usize, f64, f64)> = (0..measurements.len())
            .filter_map(|k| at_fit.get(&(k, Sensor::Encoder(cable))).map(|&(e, s)| (k, e, s)))
            .collect();
        let n = series.len();
        if n < 6 {
            continue;
        }
        let splits = n - 3;
        let critical = crate::stats::chi_square_critical(1, false_alarm / (CABLE_COUNT * splits) as f64).sqrt();
        for split in 2..n - 1 {
            let (before, after) = series.split_at(split);
            let mean = |part: &[(usize, f64, f64)]| part.iter().map(|p| p.1).sum::<f64>() / part.len() as f64;
            let (m1, m2) = (mean(before), mean(after));
            let scatter: f64 = before.iter().map(|p| (p.1 - m1).powi(2)).sum::<f64>()
                + after.iter().map(|p| (p.1 - m2).powi(2)).sum::<f64>();
            let sigma = series[0].2;
            let pooled = (scatter / (n - 2) as f64).sqrt().max(sigma);
            let t = (m1 - m2).abs() / (pooled * (1.0 / before.len() as f64 + 1.0 / after.len() as f64).sqrt());
            if t > critical && (m1 - m2).abs() > 10.0 * sigma && best.as_ref().is_none_or(|b| t > b.0) {
                let shorter = if before.len() < after.len() { before } else { after };
                best = Some((t, cable, split, shorter.iter().map(|p| p.0).collect()));
            }
        }
    }
    best.map(|(_, cable, _, rows)| (cable, rows))
}

/// The re-homing mistake of an offset step of `cable` that was left out:
/// the readings of that cable without a redundancy number (left out as a
/// run, not one by one), named with their mean error at the final fit.
pub fn name_step(cable: usize, rows: &[usize], excluded: &mut [ExcludedReading]) -> Option<Mistake> {
    let mine: Vec<usize> = (0..excluded.len())
        .filter(|&x| excluded[x].test.sensor == Sensor::Encoder(cable) && excluded[x].test.redundancy.is_nan())
        .collect();
    let (first, last) = (&excluded[*mine.first()?].test, &excluded[*mine.last()?].test);
    let mean = mine.iter().map(|&x| excluded[x].test.estimated_error).sum::<f64>() / mine.len() as f64;
    let message = format!(
        "the encoder of cable {} reads {mean:+.4} m off in {} rows, from {} to {}: its offset jumped (re-homed drum?) and those readings are left out",
        cable + 1,
        mine.len(),
        row_name(rows[first.pose], first.line),
        row_name(rows[last.pose], last.line)
    );
    for &x in &mine {
        excluded[x].explanation = Some(message.clone());
    }
    Some(Mistake {
        kind: MistakeKind::Rehoming,
        message,
        rows: mine.iter().map(|&x| step_row(rows, &excluded[x].test)).collect(),
    })
}

/// The row of a reading left out, `rows[k]` being the row of the fit's pose `k`.
fn step_row(rows: &[usize], test: &ReadingTest) -> DataRow {
    DataRow::at(rows[test.pose], test.line)
}

fn rehoming(excluded: &mut [ExcludedReading], rows: &[usize]) -> Vec<Mistake> {
    let mut found = Vec::new();
    for cable in 0..CABLE_COUNT {
        let mut mine: Vec<usize> = (0..excluded.len())
            .filter(|&x| excluded[x].explanation.is_none() && excluded[x].test.sensor == Sensor::Encoder(cable))
            .collect();
        if mine.len() < 3 {
            continue;
        }
        mine.sort_by_key(|&x| excluded[x].test.pose);
        let errors: Vec<f64> = mine.iter().map(|&x| excluded[x].test.estimated_error).collect();
        let sigma = excluded[mine[0]].test.sigma;
        let (lo, hi) = errors
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), e| (l.min(*e), h.max(*e)));
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        if hi - lo > 5.0 * sigma || mean.abs() < 10.0 * sigma {
            continue;
        }
        let first = &excluded[mine[0]].test;
        let last = &excluded[*mine.last().expect("two or more")].test;
        let message = format!(
            "the encoder of cable {} reads {:+.4} m off in {} rows, from {} to {}: its offset jumped (re-homed drum?) and the rows are left out",
            cable + 1,
            errors.iter().sum::<f64>() / errors.len() as f64,
            mine.len(),
            row_name(rows[first.pose], first.line),
            row_name(rows[last.pose], last.line)
        );
        for &x in &mine {
            excluded[x].explanation = Some(message.clone());
        }
        found.push(Mistake {
            kind: MistakeKind::Rehoming,
            message,
            rows: mine.iter().map(|&x| step_row(rows, &excluded[x].test)).collect(),
        });
    }
    found
}

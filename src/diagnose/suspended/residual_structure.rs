//! What a fitted model of `N` cables still leaves in its residuals: score
//! tests of terms no extension of the catalogue need carry, at the model's
//! solution.
//!
//! An extension that passes the chi-square test and predicts held-out poses
//! best can still be a proxy: a fault the catalogue lacks (one drum's gain
//! when the drum gains are not tried, a drift) is partly taken up by an
//! extension that moves the same readings (that cable's weight), and what
//! it cannot take up stays in the residuals as structure too small for the
//! omnibus chi-square. Each term here is one reading's residual linear in
//! one driver, `reading - model = c (driver - its mean)`:
//!
//! - each encoder against its own reading (a drum's gain), its cable's
//!   tension at the solution (that cable's stretch) and the row (a drift);
//! - the encoders together against their readings (a common gain), tension
//!   times reading (the cables' stretch, `T L / EA`) and the row;
//! - each load cell against its cable's tension at the solution (a gain),
//!   the row and a constant (a bias);
//! - each localiser axis against the row (a drift of it or of the rest).
//!
//! Each gets Rao's score test at the fitted model ([`score_system`]): `z`
//! standard normal where the model holds, with the model's anchors, offsets,
//! poses and forces re-fitted along the term (the Frisch-Waugh-Lovell
//! theorem). The extension's own parameter is held at its fitted value; the
//! residuals are then orthogonal to its direction too, so `z`'s variance is
//! at most one and the test errs on the conservative side. A term is
//! structure the model misses when `|z|` exceeds the two-sided limit at
//! `false_alarm / m` over the `m` testable terms (Bonferroni): a model that
//! holds shows one with probability at most `false_alarm`.
//!
//! The terms that describe what a model lacks are a forward selection
//! (each beyond the limit over the terms left, given those chosen, as the
//! four-cable diagnosis's missing terms), and `D_T = b_T^T M_TT^-1 b_T` is
//! the chi-square they would take off it, fitted together (first order).
//! A cause explains what the baseline lacked when the terms `T` that
//! describe the baseline's misfit take no more off the extended model than
//! chi-square with `|T|` degrees of freedom at `1 - false_alarm` allows. An
//! extension that is the physical form of those terms (the encoders'
//! common gain for `encoders against their readings`) leaves nothing of
//! them; a proxy (one cable's weight for one drum's gain) takes up part and
//! leaves the rest ([`super::diagnose_suspended`]). The terms are chosen on
//! the baseline's residuals, whose noise the extended model shares, so a
//! term chosen by its noise (a weak effect) is tested a little above its
//! stated rate: the cost is a cause not named, never a wrong one.

//! ```
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::diagnose::suspended::{residual_structure, SuspendedExtension};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! let robot = SuspendedRobot::builtin("six")?;
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
//! // No poses: the calibration's error, not a verdict.
//! let refused = residual_structure(&robot, &[], (SuspendedExtension::Elastic, 0.0), &options, 1e-3, &[]);
//! assert!(refused.is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::extensions::SuspendedExtension;
use crate::calib::suspended::{
    build_suspended_graph, calibrate_suspended, Exclusions, PoseStart, SuspendedGraph, SuspendedReading, SuspendedStage,
};
use crate::calib::{CalibrationOptions, OrientationPrior};
use crate::diagnose::MOST_DESCRIBING;
use crate::error::Result;
use crate::model::statics::CableTension;
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use crate::solver::{score_system, Direction, ScoreSystem};
use crate::stats::chi_square_critical;

/// One term's score test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualTerm {
    /// The reading (`encoder 3`, `encoders`, `load cell on cable 1`, `localiser x`).
    pub reading: String,
    /// The driver, with its unit.
    pub driver: String,
    /// Readings in the test.
    pub points: usize,
    /// `c` of `reading - model = c (driver - its mean)`, in the reading's
    /// unit per unit of the driver.
    pub coefficient: f64,
    /// Its 1-sigma.
    pub sigma: f64,
    /// `c / sigma`, standard normal where the model holds.
    pub z: f64,
}

impl ResidualTerm {
    /// The term in words: `encoder 3 against its reading (m): z = +5.1`.
    pub fn describe(&self) -> String {
        format!("{} against {}: z = {:+.1}", self.reading, self.driver, self.z)
    }
}

/// A term by its reading and driver, as [`ResidualTerm`] names them.
pub type TermKey = (String, String);

/// The score tests of one fitted model (module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualStructure {
    /// The model: the baseline with this extension at `value`.
    pub extension: SuspendedExtension,
    /// The extension's parameter.
    pub value: f64,
    /// Terms tested.
    pub tested: usize,
    /// The limit of `|z|` (two-sided, `false_alarm / tested`).
    pub limit: f64,
    /// The term of largest `|z|`.
    pub strongest: Option<ResidualTerm>,
    /// Every term beyond the limit, strongest first.
    pub beyond: Vec<ResidualTerm>,
    /// Every term tested, strongest first.
    pub terms: Vec<ResidualTerm>,
    /// The terms that describe what the model lacks: forward selection,
    /// each beyond the limit over the terms left given those before it
    /// ([`crate::diagnose::MOST_DESCRIBING`] at most), with their
    /// coefficients fitted together.
    pub describing: Vec<ResidualTerm>,
    /// The chi-square the describing terms would take off, fitted together
    /// (`b^T M^-1 b`, first order).
    pub describing_drop: f64,
    /// The chi-square the terms given to the tests (the baseline's
    /// describing terms) would still take off this model, fitted together
    /// (0 where none were given).
    pub given_drop: f64,
    /// Its limit: the `1 - false_alarm` quantile of chi-square with a
    /// degree of freedom per given term.
    pub given_limit: f64,
}

impl ResidualStructure {
    /// Whether the residuals hold no term beyond the limit.
    pub fn clean(&self) -> bool {
        self.beyond.is_empty()
    }

    /// Whether the model explains the given terms: what they would still
    /// take off it is within its limit.
    pub fn explains_given(&self) -> bool {
        self.given_drop <= self.given_limit
    }

    /// The describing terms' keys.
    pub fn describing_keys(&self) -> Vec<TermKey> {
        self.describing
            .iter()
            .map(|t| (t.reading.clone(), t.driver.clone()))
            .collect()
    }
}

/// The score tests of the model `extension` at `value` fitted to
/// `measurements` (module docs), at the search's rate `false_alarm`, and
/// the drop of the `given` terms.
pub fn residual_structure(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    (extension, value): (SuspendedExtension, f64),
    options: &CalibrationOptions,
    false_alarm: f64,
    given: &[TermKey],
) -> Result<ResidualStructure> {
    let (keys, system) = fitted_terms(robot, measurements, extension, value, options)?;
    let term = |j: usize, others: &[usize]| {
        let t = system.test(j, others);
        let (reading, driver, points) = keys[j].clone();
        ResidualTerm {
            reading,
            driver,
            points,
            coefficient: t.coefficient,
            sigma: t.sigma,
            z: t.z,
        }
    };
    let mut tested: Vec<ResidualTerm> = (0..keys.len())
        .map(|j| term(j, &[]))
        .filter(|t| t.z.is_finite())
        .collect();
    tested.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    let limit_of = |testable: usize| chi_square_critical(1, false_alarm / testable.max(1) as f64).sqrt();
    let limit = limit_of(tested.len());
    let chosen = system.forward_selection(limit_of, MOST_DESCRIBING);
    let describing = chosen
        .iter()
        .map(|&j| {
            let others: Vec<usize> = chosen.iter().copied().filter(|&k| k != j).collect();
            term(j, &others)
        })
        .collect();
    let given: Vec<usize> = given
        .iter()
        .filter_map(|(reading, driver)| keys.iter().position(|k| &k.0 == reading && &k.1 == driver))
        .collect();
    Ok(ResidualStructure {
        extension,
        value,
        tested: tested.len(),
        limit,
        strongest: tested.first().cloned(),
        beyond: tested.iter().filter(|t| t.z.abs() > limit).cloned().collect(),
        terms: tested,
        describing,
        describing_drop: joint_drop(&system, &chosen),
        given_drop: joint_drop(&system, &given),
        given_limit: match given.len() {
            0 => 0.0,
            count => chi_square_critical(count, false_alarm),
        },
    })
}

/// A term's reading, driver and readings.
type TestedTerm = (String, String, usize);

/// The model fitted, and the score system of every testable term at its
/// solution with each term's reading, driver and readings.
fn fitted_terms(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    extension: SuspendedExtension,
    value: f64,
    options: &CalibrationOptions,
) -> Result<(Vec<TestedTerm>, ScoreSystem)> {
    let (robot, measurements) = extension.apply(robot, measurements, value);
    let fit = calibrate_suspended(&robot, &measurements, options, None, &mut |_| {})?;
    let starts: Vec<PoseStart> = fit
        .poses
        .iter()
        .zip(&fit.forces)
        .map(|(&pose, forces)| PoseStart {
            pose,
            forces: forces.clone(),
        })
        .collect();
    let with_orientation = options.orientation_prior != OrientationPrior::Off;
    let built = build_suspended_graph(
        &fit.robot,
        &measurements,
        &starts,
        SuspendedStage::Catenary,
        options,
        with_orientation,
        &Exclusions::new(),
    );
    let drivers = Drivers {
        measurements: &measurements,
        forces: &fit.forces,
    };
    let mut keys = Vec::new();
    let mut directions: Vec<Direction> = Vec::new();
    for (reading, driver, selects, value) in terms(&robot) {
        let centred = value != Driver::Constant;
        let (direction, points) = direction(&built, &selects, &|k, r| drivers.value(value, k, r), centred);
        if points > 2 {
            keys.push((reading, driver, points));
            directions.push(direction);
        }
    }
    let system = score_system(&built.graph, &directions)?;
    Ok((keys, system))
}

/// `b_S^T M_SS^-1 b_S` of the terms `chosen` fitted together: the
/// chi-square they would take off (0 for none, or a singular information).
fn joint_drop(system: &ScoreSystem, chosen: &[usize]) -> f64 {
    let m = DMatrix::from_fn(chosen.len(), chosen.len(), |a, b| {
        system.information[(chosen[a], chosen[b])]
    });
    let b = DVector::from_fn(chosen.len(), |a, _| system.score[chosen[a]]);
    match m.try_inverse() {
        Some(inverse) if !chosen.is_empty() => b.dot(&(inverse * &b)),
        _ => 0.0,
    }
}

/// A driver's value at a pose and reading.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Driver {
    /// The reading's own value (an encoder's length, m).
    Reading,
    /// The reading's cable's tension at the solution, N.
    Tension,
    /// Tension times the encoder's reading, N m.
    TensionTimesReading,
    /// The row of the pose in the file (0-based).
    Row,
    /// One: a bias (not centred).
    Constant,
}

/// What the drivers read.
struct Drivers<'a> {
    measurements: &'a [SuspendedMeasurement],
    forces: &'a [Vec<CableTension>],
}

impl Drivers<'_> {
    /// `driver` at pose `k` for `reading`.
    fn value(&self, driver: Driver, k: usize, reading: SuspendedReading) -> Option<f64> {
        let cable = match reading {
            SuspendedReading::Encoder(i) | SuspendedReading::LoadCell(i) => Some(i),
            _ => None,
        };
        let tension = |i: usize| {
            let f = self.forces[k][i];
            f.horizontal_n.hypot(f.vertical_n)
        };
        let length = |i: usize| self.measurements[k].encoder_lengths_m[i];
        match driver {
            Driver::Reading => cable.map(length),
            Driver::Tension => cable.map(tension),
            Driver::TensionTimesReading => cable.map(|i| tension(i) * length(i)),
            Driver::Row => Some(k as f64),
            Driver::Constant => Some(1.0),
        }
    }
}

/// Which readings a term holds.
type Selects = Box<dyn Fn(SuspendedReading) -> bool>;

/// Every term (module docs): reading and driver in words, the readings
/// it holds, and its driver.
fn terms(robot: &SuspendedRobot) -> Vec<(String, String, Selects, Driver)> {
    let mut terms: Vec<(String, String, Selects, Driver)> = Vec::new();
    let encoder_drivers = [
        ("its reading (m)", Driver::Reading),
        ("its cable's tension (N)", Driver::Tension),
        ("the row", Driver::Row),
    ];
    for i in 0..robot.cable_count() {
        for (driver, value) in encoder_drivers {
            let selects: Selects = Box::new(move |r| r == SuspendedReading::Encoder(i));
            terms.push((format!("encoder {}", i + 1), driver.into(), selects, value));
        }
    }
    let together = [
        ("their readings (m)", Driver::Reading),
        ("tension times reading (N m)", Driver::TensionTimesReading),
        ("the row", Driver::Row),
    ];
    for (driver, value) in together {
        let selects: Selects = Box::new(|r| matches!(r, SuspendedReading::Encoder(_)));
        terms.push(("encoders".into(), driver.into(), selects, value));
    }
    let cell_drivers = [
        ("its cable's tension (N)", Driver::Tension),
        ("the row", Driver::Row),
        ("a constant (a bias, N)", Driver::Constant),
    ];
    for &cable in &robot.load_cells {
        for (driver, value) in cell_drivers {
            let selects: Selects = Box::new(move |r| r == SuspendedReading::LoadCell(cable));
            terms.push((
                format!("load cell on cable {}", cable + 1),
                driver.into(),
                selects,
                value,
            ));
        }
    }
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let selects: Selects = Box::new(move |r| r == SuspendedReading::Position(axis));
        terms.push((format!("localiser {name}"), "the row".into(), selects, Driver::Row));
    }
    terms
}

/// The whitened direction of a term over `built`'s factors: at each row
/// whose reading `selects` holds, the driver's value (`centred` over the
/// term's readings) over the row's sigma; and the term's readings.
fn direction(
    built: &SuspendedGraph,
    selects: &dyn Fn(SuspendedReading) -> bool,
    value: &dyn Fn(usize, SuspendedReading) -> Option<f64>,
    centred: bool,
) -> (Direction, usize) {
    let rows: Vec<Vec<(usize, f64)>> = built
        .readings
        .iter()
        .map(|readings| {
            readings
                .iter()
                .enumerate()
                .filter(|(_, (_, r))| selects(*r))
                .filter_map(|(row, &(k, r))| value(k, r).filter(|x| x.is_finite()).map(|x| (row, x)))
                .collect()
        })
        .collect();
    let values: Vec<f64> = rows.iter().flatten().map(|(_, x)| *x).collect();
    let points = values.len();
    let mean = match centred {
        true => values.iter().sum::<f64>() / points.max(1) as f64,
        false => 0.0,
    };
    let direction = rows
        .iter()
        .zip(&built.graph.factors)
        .map(|(rows, factor)| {
            (!rows.is_empty()).then(|| {
                let mut weights = vec![0.0; factor.residual_dim()];
                for &(row, x) in rows {
                    weights[row] = (x - mean) / factor.sigmas()[row];
                }
                weights
            })
        })
        .collect();
    (direction, points)
}

//! Model verification against measured data (paper Sec. V-A, Table I).
//!
//! For every kept row of a measurement log, the kineto-static model is closed
//! with the row's *position* and one measured quantity (by default the
//! reference cable's load-cell tension, paper eq. 16), and its predictions
//! are compared with everything else the row measured: the four cable lengths,
//! the tensions of the other cables, and the orientation.
//!
//! The measured orientation is deliberately **not** an input: in the RecurDyn
//! log it disagrees with the model's equilibrium by about 2 degrees and some
//! rows carry permuted angle columns, so it is reported, not trusted
//! ([`OrientationConventionFit`]).
//!
//! A robot file's `[effects]` are applied: with the load-cell closure the
//! extended model's equilibrium and predicted encoder readings
//! ([`crate::calib::predict_with_effects`]) replace the closed form's, so an
//! extension written by `sagcal diagnose --out` can be measured on poses it
//! was never fitted on. Data: a RecurDyn log (every cable's tension) or a
//! sagcal measurement file (the encoder readings as lengths, the load cell
//! as the reference cable's tension).
//!
//! What the length columns hold decides what is compared ([`LengthKind`]): a
//! sagcal measurement file logs encoder readings, the cable length plus the
//! robot file's `length_offsets_m` (as `sagcal simulate` writes them and
//! `sagcal calibrate` estimates them), so the model's prediction is its
//! length plus the offset; a RecurDyn log records the cables' absolute
//! lengths, so the offsets (an encoder's zero, which the simulation has not)
//! are not added there.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::diagnose::verify::{paper_table1, verify, Closure, LengthKind, MeasuredData, MeasuredRow};
//! use sagcal::model::robot::PaperRobot;
//! use sagcal::model::statics::StaticsOptions;
//! use sagcal::model::{DataRow, Robot};
//! use sagcal::sim::closed_form::{sample_equilibria, Workspace};
//! let robot = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
//! let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 3, &mut rng)?;
//! // Rows measured by the model itself (every cable's length and tension) ...
//! let mut rows: Vec<MeasuredRow> = equilibria
//!     .iter()
//!     .enumerate()
//!     .map(|(k, eq)| {
//!         let (roll, pitch, yaw) = eq.pose.roll_pitch_yaw_deg();
//!         MeasuredRow {
//!             at: DataRow::at(k, k + 2),
//!             position_m: eq.pose.position_m.into(),
//!             roll_pitch_yaw_deg: [roll, pitch, yaw],
//!             cable_lengths_m: eq.cable_lengths_m,
//!             tensions_n: eq.tensions.map(|t| Some(t.magnitude_n())),
//!         }
//!     })
//!     .collect();
//! // ... but the first row logs cable 2 1 % long.
//! rows[0].cable_lengths_m[1] *= 1.01;
//! let data = MeasuredData { path: "model".into(), rows, rejected: Vec::new(), lengths: LengthKind::Absolute };
//! let report = verify(&robot, &data, Closure::ReferenceTension, &StaticsOptions::default());
//! assert_eq!(report.rows.len(), 3);
//! // |L - 1.01 L| / (1.01 L) on that reading, 0 on the other 11.
//! let error_pct = report.rows[0].length_error_pct[1];
//! assert!((error_pct - 100.0 * 0.01 / 1.01).abs() < 1e-6, "{error_pct}");
//! assert!((report.mpe_length_pct.unwrap() - error_pct / 12.0).abs() < 1e-6);
//! assert!(report.mpe_force_pct.unwrap() < 1e-6 && report.orientation_error_deg.unwrap() < 1e-6);
//! // The paper's Table I, printed beside it for its robots.
//! assert_eq!(report.paper_table1, Some(paper_table1(PaperRobot::Large)));
//! assert_eq!(paper_table1(PaperRobot::Large).mpe_force_pct, 0.9154);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{UnitQuaternion, Vector3};
use serde::Serialize;

use crate::calib::predict_with_effects;
use crate::error::Error;
use crate::io::measurements::MeasurementSet;
use crate::io::recurdyn::{RecurDynLog, RejectedRow};
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{self, Equilibrium, StaticsOptions};
use crate::model::{DataRow, PlatformPose};

pub use super::paper_table1::{paper_table1, PaperTable1};

/// What one row of the data measured at a static pose.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredRow {
    /// The row (from 1, among the rows kept) and its line in the data file.
    pub at: DataRow,
    /// Platform position, metres.
    pub position_m: [f64; 3],
    /// Angles as the file gives them, degrees: `[pitch, roll, yaw]` columns read as roll, pitch, yaw.
    pub roll_pitch_yaw_deg: [f64; 3],
    /// Cable lengths (or encoder readings), metres.
    pub cable_lengths_m: [f64; CABLE_COUNT],
    /// Tension magnitudes at the attachments, newtons, where measured.
    pub tensions_n: [Option<f64>; CABLE_COUNT],
}

/// What the length columns of a data file hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LengthKind {
    /// Encoder readings: the cable length plus the robot's
    /// `length_offsets_m` (a sagcal measurement file, eq. 14).
    EncoderReadings,
    /// Absolute cable lengths, no encoder zero (a RecurDyn log).
    Absolute,
}

/// The rows of a data file to verify, and the rows its loader rejected.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredData {
    /// The file.
    pub path: String,
    /// Kept rows.
    pub rows: Vec<MeasuredRow>,
    /// Rows the loader rejected, with reasons.
    pub rejected: Vec<RejectedRow>,
    /// What `cable_lengths_m` of the rows hold.
    pub lengths: LengthKind,
}

impl MeasuredData {
    /// A RecurDyn log's rows (every cable's tension where logged).
    pub fn from_recurdyn(log: &RecurDynLog) -> Self {
        let rows = log
            .rows
            .iter()
            .enumerate()
            .map(|(k, row)| MeasuredRow {
                at: DataRow::at(k, row.line),
                position_m: row.position_m,
                roll_pitch_yaw_deg: [row.roll_deg, row.pitch_deg, row.yaw_deg],
                cable_lengths_m: row.cable_lengths_m,
                tensions_n: std::array::from_fn(|i| row.tensions[i].map(|t| t.total_n)),
            })
            .collect();
        Self {
            path: log.path.display().to_string(),
            rows,
            rejected: log.rejected.clone(),
            lengths: LengthKind::Absolute,
        }
    }

    /// A sagcal measurement file's rows: encoder readings as lengths, the
    /// load cell as the tension of `reference_cable` (0-based).
    pub fn from_measurements(set: &MeasurementSet, reference_cable: usize) -> Self {
        let rows = set
            .poses
            .iter()
            .enumerate()
            .map(|(k, m)| MeasuredRow {
                at: DataRow::at(k, m.line),
                position_m: m.position_m,
                roll_pitch_yaw_deg: [m.roll_deg, m.pitch_deg, m.yaw_deg],
                cable_lengths_m: m.encoder_lengths_m,
                tensions_n: std::array::from_fn(|i| (i == reference_cable).then_some(m.reference_tension_n)),
            })
            .collect();
        Self {
            path: set.path.display().to_string(),
            rows,
            rejected: set.rejected.clone(),
            lengths: LengthKind::EncoderReadings,
        }
    }
}

/// Which measurement closes the one-parameter family of equilibria.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Closure {
    /// Position + the reference cable's measured tension magnitude (problem (a)).
    ReferenceTension,
    /// Position + the four measured cable lengths, least squares (problem (b)).
    CableLengths,
}

/// Prediction against measurement for one row.
#[derive(Debug, Clone, Serialize)]
pub struct RowVerification {
    /// The row and its line in the data file (`row`, `line` in JSON).
    #[serde(flatten)]
    pub at: DataRow,
    /// Measured position, metres.
    pub position_m: [f64; 3],
    /// Measured cable lengths (or encoder readings), metres.
    pub measured_length_m: [f64; CABLE_COUNT],
    /// Predicted catenary lengths, metres; for encoder readings the
    /// predicted readings (length plus the robot's offset, [`LengthKind`]).
    pub predicted_length_m: [f64; CABLE_COUNT],
    /// `100 * |predicted - measured| / measured` per cable.
    pub length_error_pct: [f64; CABLE_COUNT],
    /// Measured tension magnitudes, newtons (absent where the log has none).
    pub measured_tension_n: [Option<f64>; CABLE_COUNT],
    /// Predicted tension magnitudes at the attachments, newtons.
    pub predicted_tension_n: [f64; CABLE_COUNT],
    /// Percentage tension error for the measured cables that were not an input.
    pub tension_error_pct: [Option<f64>; CABLE_COUNT],
    /// Measured `(roll, pitch, yaw)` in degrees (R = Rz(yaw) Ry(pitch) Rx(roll)).
    pub measured_roll_pitch_yaw_deg: [f64; 3],
    /// The model's equilibrium orientation as `(roll, pitch, yaw)` in degrees.
    pub predicted_roll_pitch_yaw_deg: [f64; 3],
    /// Angle between measured and predicted orientation, degrees.
    pub orientation_error_deg: f64,
    /// Largest attachment-height residual of the solved equilibrium, metres.
    pub height_residual_m: f64,
}

/// A row the statics could not solve (no equilibrium with positive tensions).
#[derive(Debug, Clone, Serialize)]
pub struct UnsolvedRow {
    /// The row and its line in the data file (`row`, `line` in JSON).
    #[serde(flatten)]
    pub at: DataRow,
    /// Why.
    pub reason: String,
}

/// How well one reading of the three angle columns matches the model's orientations.
#[derive(Debug, Clone, Serialize)]
pub struct OrientationConventionFit {
    /// E.g. `R = Rz(yaw) Ry(pitch) Rx(roll)` with the file's columns named as in its header.
    pub convention: String,
    /// Mean angle to the model's equilibrium over all solved rows, degrees.
    pub mean_error_deg: f64,
    /// Median of the same, degrees.
    pub median_error_deg: f64,
}

/// A row whose angles match the model far better with their columns permuted.
#[derive(Debug, Clone, Serialize)]
pub struct SuspectOrientationRow {
    /// The row and its line in the data file (`row`, `line` in JSON).
    #[serde(flatten)]
    pub at: DataRow,
    /// Error with the documented convention, degrees.
    pub documented_error_deg: f64,
    /// The best alternative reading.
    pub best_convention: String,
    /// Error with that reading, degrees.
    pub best_error_deg: f64,
}

/// The whole verification.
#[derive(Debug, Clone, Serialize)]
pub struct VerifyReport {
    /// Robot name.
    pub robot: String,
    /// Data file.
    pub data: String,
    /// The closing measurement.
    pub closure: Closure,
    /// What the data's length columns hold (and so what was compared).
    pub lengths: LengthKind,
    /// Rows kept by the loader.
    pub rows_kept: usize,
    /// Rows the loader rejected, with reasons.
    pub rows_rejected: Vec<RejectedRow>,
    /// Kept rows the statics could not solve.
    pub rows_unsolved: Vec<UnsolvedRow>,
    /// Per-row results.
    pub rows: Vec<RowVerification>,
    /// Mean percentage error of the cable lengths over all solved rows and
    /// cables (MPE-L); `None` (JSON `null`) when no row was solved.
    pub mpe_length_pct: Option<f64>,
    /// Largest percentage length error; `None` when no row was solved.
    pub max_length_error_pct: Option<f64>,
    /// Mean percentage error of the tensions not used as input (MPE-F);
    /// `None` (JSON `null`) when there is no tension to compare, see `mpe_force_reason`.
    pub mpe_force_pct: Option<f64>,
    /// Why `mpe_force_pct` is `None` (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mpe_force_reason: Option<String>,
    /// Number of tension comparisons behind MPE-F.
    pub force_comparisons: usize,
    /// Mean orientation error with the documented convention, degrees; `None` when no row was solved.
    pub orientation_error_deg: Option<f64>,
    /// Largest orientation error, degrees; `None` when no row was solved.
    pub max_orientation_error_deg: Option<f64>,
    /// Every reading of the angle columns tried, best first.
    pub orientation_conventions: Vec<OrientationConventionFit>,
    /// Rows that look like they carry permuted angle columns.
    pub suspect_orientation_rows: Vec<SuspectOrientationRow>,
    /// The paper's Table I column for this robot, when the robot file names
    /// one of the paper's robots (`paper_robot`); `None` (JSON `null`) otherwise.
    pub paper_table1: Option<PaperTable1>,
}

/// The model's equilibrium for one row under `closure`: the closed form,
/// refined by the extended model where the robot has `[effects]`.
fn solve_row(
    robot: &Robot,
    row: &MeasuredRow,
    lengths: LengthKind,
    closure: Closure,
    options: &StaticsOptions,
) -> crate::Result<Equilibrium> {
    let position = Vector3::from(row.position_m);
    match closure {
        Closure::ReferenceTension => {
            let measured = row.tensions_n[robot.reference_cable].ok_or_else(|| {
                crate::Error::InvalidInput(format!(
                    "{}: no tension for the reference cable {}",
                    row.at,
                    robot.reference_cable + 1
                ))
            })?;
            let closed = logged_branch(robot, row, measured, options);
            match closed {
                Ok(closed) if robot.effects.is_none() => Ok(closed),
                Err(error) if robot.effects.is_none() => Err(error),
                Ok(closed) => predict_with_effects(robot, &closed, measured)
                    .or_else(|error| extended_from_logged(robot, row, measured).map_err(|_| error)),
                Err(error) => extended_from_logged(robot, row, measured).map_err(|_| error),
            }
        }
        Closure::CableLengths if !robot.effects.is_none() => Err(crate::Error::InvalidInput(format!(
            "{}: the cable-lengths closure does not apply the robot file's [effects] ({}); use the reference-tension closure",
            row.at, robot.effects
        ))),
        Closure::CableLengths => {
            let cable_lengths = std::array::from_fn(|i| row.cable_lengths_m[i] - offset(robot, lengths, i));
            statics::solve_with_cable_lengths(robot, position, &cable_lengths, options)
        }
    }
}

/// Two equilibria closer than this (radians) are the same one.
const SAME_EQUILIBRIUM_RAD: f64 = 1e-3;

/// The equilibrium of the branch the robot was in. A position and a
/// reference tension can admit several equilibria (a small square platform
/// also balances turned half a turn, its cables crossed; a platform whose
/// centre of mass is above its attachments hangs steeply tilted; a long,
/// heavy, slack cable lets two equilibria lie a few degrees apart), and the
/// search from level may find another one or none (all found by the property
/// test of whole commands, which verified noise-free simulated data at 64,
/// 180 and 6.7 degrees and 0.07-20 % length error, or not at all at 71 degrees
/// of roll). The localiser saw which one the robot was in: unless the
/// equilibrium from level is the logged orientation itself (within
/// [`SAME_EQUILIBRIUM_RAD`]), the statics are solved again from the logged
/// orientation and, of two distinct equilibria, the one nearer the logged
/// orientation is kept (the most likely branch under any orientation noise
/// that is the same in every direction). The orientation stays predicted (the
/// logged one only starts the search); where the equilibrium is unique both
/// searches end at it and the answer is the solve from level.
fn logged_branch(
    robot: &Robot,
    row: &MeasuredRow,
    reference_tension_n: f64,
    options: &StaticsOptions,
) -> crate::Result<Equilibrium> {
    let position = Vector3::from(row.position_m);
    let logged = logged_rotation(row);
    let turn = |eq: &Equilibrium| eq.pose.rotation.angle_to(&logged);
    let from_logged =
        || statics::solve_with_reference_tension(robot, position, reference_tension_n, Some(logged), options);
    let found = match statics::solve_with_reference_tension(robot, position, reference_tension_n, None, options) {
        Ok(found) => found,
        Err(level_error) => return from_logged().map_err(|_| level_error),
    };
    let found_turn = turn(&found);
    if !found_turn.is_finite() || found_turn <= SAME_EQUILIBRIUM_RAD {
        return Ok(found);
    }
    match from_logged() {
        Ok(other)
            if turn(&other) < found_turn
                && other.pose.rotation.angle_to(&found.pose.rotation) > SAME_EQUILIBRIUM_RAD =>
        {
            Ok(other)
        }
        _ => Ok(found),
    }
}

/// The row's logged orientation, read with the documented convention.
fn logged_rotation(row: &MeasuredRow) -> UnitQuaternion<f64> {
    let [roll, pitch, yaw] = row.roll_pitch_yaw_deg;
    AngleReading::DOCUMENTED.rotation([pitch, roll, yaw])
}

/// The extended model's equilibrium for a row whose closed form has none
/// (a pulley can make a position reachable that the closed form cannot
/// reach): the search starts at the logged pose, with the reference
/// tension along its sag-corrected chord.
fn extended_from_logged(robot: &Robot, row: &MeasuredRow, reference_tension_n: f64) -> crate::Result<Equilibrium> {
    let pose = PlatformPose::new(Vector3::from(row.position_m), logged_rotation(row));
    let start = statics::unsolved_at(robot, pose, reference_tension_n)?;
    predict_with_effects(robot, &start, reference_tension_n)
}

/// What cable `i`'s reading adds to its length: the robot's length offset
/// for encoder readings, nothing for absolute lengths.
fn offset(robot: &Robot, lengths: LengthKind, i: usize) -> f64 {
    match lengths {
        LengthKind::EncoderReadings => robot.length_offsets_m[i],
        LengthKind::Absolute => 0.0,
    }
}

/// The model's prediction of the data's length columns from a solved row:
/// the closed form's lengths plus the offsets for encoder readings; the
/// extended model (`[effects]`) predicts encoder readings (gain and offset
/// applied), turned back into lengths for absolute data.
fn predicted_lengths(robot: &Robot, lengths: LengthKind, equilibrium: &Equilibrium) -> [f64; CABLE_COUNT] {
    let l = equilibrium.cable_lengths_m;
    match (robot.effects.is_none(), lengths) {
        (true, _) => std::array::from_fn(|i| l[i] + offset(robot, lengths, i)),
        (false, LengthKind::EncoderReadings) => l,
        (false, LengthKind::Absolute) => {
            std::array::from_fn(|i| (l[i] - robot.length_offsets_m[i]) / robot.effects.encoder_gain[i])
        }
    }
}

/// The names of the three angle columns as the file gives them, in file order.
const ANGLE_COLUMNS: [&str; 3] = ["pitch", "roll", "yaw"];

/// A reading of the angle columns: which file column plays roll, pitch, yaw,
/// and whether the product is `Rz Ry Rx` (true) or `Rx Ry Rz`.
#[derive(Clone, Copy)]
struct AngleReading {
    roll_pitch_yaw_columns: [usize; 3],
    z_y_x: bool,
}

impl AngleReading {
    const DOCUMENTED: AngleReading = AngleReading {
        roll_pitch_yaw_columns: [1, 0, 2],
        z_y_x: true,
    };

    fn all() -> Vec<AngleReading> {
        let permutations = [[1, 0, 2], [0, 1, 2], [0, 2, 1], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        let mut all = Vec::new();
        for columns in permutations {
            for z_y_x in [true, false] {
                all.push(AngleReading {
                    roll_pitch_yaw_columns: columns,
                    z_y_x,
                });
            }
        }
        all
    }

    fn name(&self) -> String {
        let [r, p, y] = self.roll_pitch_yaw_columns.map(|c| ANGLE_COLUMNS[c]);
        if self.z_y_x {
            format!("R = Rz({y}) Ry({p}) Rx({r})")
        } else {
            format!("R = Rx({r}) Ry({p}) Rz({y})")
        }
    }

    fn rotation(&self, file_angles_deg: [f64; 3]) -> UnitQuaternion<f64> {
        let [roll, pitch, yaw] = self.roll_pitch_yaw_columns.map(|c| file_angles_deg[c].to_radians());
        let rx = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll);
        let ry = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), pitch);
        let rz = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
        if self.z_y_x {
            rz * ry * rx
        } else {
            rx * ry * rz
        }
    }
}

/// The mean, `None` for no values.
fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// The largest value, `None` for no values.
fn max(values: &[f64]) -> Option<f64> {
    values.iter().copied().reduce(f64::max)
}

/// The median, `None` for no values.
fn median(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    match sorted.len() {
        0 => None,
        n if n % 2 == 1 => Some(sorted[n / 2]),
        n => Some(0.5 * (sorted[n / 2 - 1] + sorted[n / 2])),
    }
}

/// Prediction against measurement for one solved row.
fn compare_row(
    robot: &Robot,
    row: &MeasuredRow,
    lengths: LengthKind,
    closure: Closure,
    equilibrium: &Equilibrium,
) -> RowVerification {
    let predicted_length_m = predicted_lengths(robot, lengths, equilibrium);
    let [roll, pitch, yaw] = row.roll_pitch_yaw_deg;
    let measured_rotation = AngleReading::DOCUMENTED.rotation([pitch, roll, yaw]);
    let measured_pose = PlatformPose::new(Vector3::from(row.position_m), measured_rotation);
    let predicted_tension_n: [f64; CABLE_COUNT] = std::array::from_fn(|i| equilibrium.tensions[i].magnitude_n());
    let measured_tension_n = row.tensions_n;
    let tension_error_pct = std::array::from_fn(|i| {
        let is_input = closure == Closure::ReferenceTension && i == robot.reference_cable;
        match measured_tension_n[i] {
            Some(m) if !is_input => Some(100.0 * (predicted_tension_n[i] - m).abs() / m),
            _ => None,
        }
    });
    let (r, p, y) = equilibrium.pose.roll_pitch_yaw_deg();
    RowVerification {
        at: row.at,
        position_m: row.position_m,
        measured_length_m: row.cable_lengths_m,
        predicted_length_m,
        length_error_pct: std::array::from_fn(|i| {
            100.0 * (predicted_length_m[i] - row.cable_lengths_m[i]).abs() / row.cable_lengths_m[i]
        }),
        measured_tension_n,
        predicted_tension_n,
        tension_error_pct,
        measured_roll_pitch_yaw_deg: row.roll_pitch_yaw_deg,
        predicted_roll_pitch_yaw_deg: [r, p, y],
        orientation_error_deg: measured_pose.angle_to_deg(&equilibrium.pose),
        height_residual_m: equilibrium.max_height_residual_m(),
    }
}

/// Each reading of the angle columns against the model's orientations, best
/// first, and the rows that a permuted reading explains far better.
fn orientation_analysis(
    solved: &[(DataRow, [f64; 3], UnitQuaternion<f64>)],
) -> (Vec<OrientationConventionFit>, Vec<SuspectOrientationRow>) {
    let readings = AngleReading::all();
    let errors_per_reading: Vec<Vec<f64>> = readings
        .iter()
        .map(|reading| {
            solved
                .iter()
                .map(|(_, angles, model)| reading.rotation(*angles).angle_to(model).to_degrees())
                .collect()
        })
        .collect();
    // No solved row: no convention to rank.
    let mut conventions: Vec<OrientationConventionFit> = readings
        .iter()
        .zip(&errors_per_reading)
        .filter_map(|(reading, errors)| {
            Some(OrientationConventionFit {
                convention: reading.name(),
                mean_error_deg: mean(errors)?,
                median_error_deg: median(errors)?,
            })
        })
        .collect();
    conventions.sort_by(|a, b| a.mean_error_deg.total_cmp(&b.mean_error_deg));
    // Documented reading is index 0 of `readings`.
    let suspects = solved
        .iter()
        .enumerate()
        .filter_map(|(k, (at, _, _))| {
            let documented = errors_per_reading[0][k];
            let (best, best_error) = readings
                .iter()
                .zip(&errors_per_reading)
                .skip(1)
                .map(|(reading, errors)| (reading, errors[k]))
                .min_by(|a, b| a.1.total_cmp(&b.1))?;
            // A different reading of the columns explains the row at least twice as well,
            // and the documented one is off by more than the typical 2 degrees.
            (best_error < 0.5 * documented && documented > 2.0).then(|| SuspectOrientationRow {
                at: *at,
                documented_error_deg: documented,
                best_convention: best.name(),
                best_error_deg: best_error,
            })
        })
        .collect();
    (conventions, suspects)
}

/// Why no tension could be compared (MPE-F has no value), for `solved` solved rows.
fn no_tension_reason(robot: &Robot, closure: Closure, solved: usize) -> String {
    if solved == 0 {
        return "no row was solved, so no tension was predicted".to_string();
    }
    match closure {
        Closure::ReferenceTension => format!(
            "no tension to compare: the only tension the data logs is reference cable {}'s, an input of this \
             closure (a sagcal measurement file logs the load cell only); `--close-with cable-lengths` predicts it",
            robot.reference_cable + 1
        ),
        Closure::CableLengths => "no tension to compare: the solved rows log no tension".to_string(),
    }
}

/// The error of a verification that verified nothing: no row was kept, or
/// the statics solved none of them (a model that explains no row is not
/// verified by an empty table). `None` when at least one row was verified.
pub fn nothing_verified(report: &VerifyReport) -> Option<Error> {
    if !report.rows.is_empty() {
        return None;
    }
    let why = match report.rows_unsolved.first() {
        Some(first) => format!(
            "the statics solved none of its {} kept rows with this robot ({}: {}{})",
            report.rows_kept,
            first.at,
            first.reason,
            if report.rows_unsolved.len() > 1 {
                "; the others alike or listed above"
            } else {
                ""
            }
        ),
        None => format!(
            "no row was kept ({} rejected by the loader)",
            report.rows_rejected.len()
        ),
    };
    Some(Error::InvalidInput(format!(
        "{}: nothing verified for robot `{}`: {why}",
        report.data, report.robot
    )))
}

/// Verify the model on every kept row of `data`.
pub fn verify(robot: &Robot, data: &MeasuredData, closure: Closure, options: &StaticsOptions) -> VerifyReport {
    let mut rows = Vec::new();
    let mut unsolved = Vec::new();
    let mut solved_orientations = Vec::new();
    for row in &data.rows {
        match solve_row(robot, row, data.lengths, closure, options) {
            Ok(equilibrium) => {
                rows.push(compare_row(robot, row, data.lengths, closure, &equilibrium));
                let [roll, pitch, yaw] = row.roll_pitch_yaw_deg;
                solved_orientations.push((row.at, [pitch, roll, yaw], equilibrium.pose.rotation));
            }
            Err(e) => unsolved.push(UnsolvedRow {
                at: row.at,
                reason: e.to_string(),
            }),
        }
    }
    let (orientation_conventions, suspect_orientation_rows) = orientation_analysis(&solved_orientations);
    let length_errors: Vec<f64> = rows.iter().flat_map(|r| r.length_error_pct).collect();
    let force_errors: Vec<f64> = rows
        .iter()
        .flat_map(|r| r.tension_error_pct.into_iter().flatten())
        .collect();
    let orientation_errors: Vec<f64> = rows.iter().map(|r| r.orientation_error_deg).collect();
    VerifyReport {
        robot: robot.name.clone(),
        data: data.path.clone(),
        closure,
        lengths: data.lengths,
        rows_kept: data.rows.len(),
        rows_rejected: data.rejected.clone(),
        rows_unsolved: unsolved,
        mpe_length_pct: mean(&length_errors),
        max_length_error_pct: max(&length_errors),
        mpe_force_pct: mean(&force_errors),
        mpe_force_reason: force_errors
            .is_empty()
            .then(|| no_tension_reason(robot, closure, rows.len())),
        force_comparisons: force_errors.len(),
        orientation_error_deg: mean(&orientation_errors),
        max_orientation_error_deg: max(&orientation_errors),
        orientation_conventions,
        suspect_orientation_rows,
        paper_table1: robot.paper_robot.map(paper_table1),
        rows,
    }
}

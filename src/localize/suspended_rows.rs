//! Every row of a measurement file of a robot of `N` cables localised
//! ([`localize_suspended_rows`]), with each row's pose, forces, 1-sigma and
//! tests, and the positions against the file's localiser columns.

use serde::Serialize;

use super::suspended::localize_suspended;
use crate::model::sensors::SensorNoise;
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use crate::model::DataRow;

/// One row's result (or why it has none).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedRowReport {
    /// The row (from 1) and its line in the input (`null` for in-memory data).
    #[serde(flatten)]
    pub at: DataRow,
    /// The platform origin, world frame, metres.
    pub position_m: Option<[f64; 3]>,
    /// `(roll, pitch, yaw)`, degrees, `R = Rz(yaw) Ry(pitch) Rx(roll)`.
    pub roll_pitch_yaw_deg: Option<[f64; 3]>,
    /// Every cable's `(f_h, f_v)` at its attachment, newtons.
    pub forces_n: Option<Vec<[f64; 2]>>,
    /// 1-sigma per axis from the reading noise, metres.
    pub position_sigma_m: Option<[f64; 3]>,
    /// The position's 3 x 3 covariance from the reading noise, m^2 (the
    /// ellipses of `sagcal localize --plot`; not in the JSON, whose
    /// per-axis sigmas are its diagonal's roots).
    #[serde(skip)]
    pub position_covariance_m2: Option<[[f64; 3]; 3]>,
    /// The row's chi-square and its degrees of freedom (the load cells).
    pub chi_square: Option<f64>,
    /// See [`SuspendedRowReport::chi_square`].
    pub degrees_of_freedom: Option<usize>,
    /// Whether the chi-square passes its test.
    pub consistent: bool,
    /// Whether the equilibrium is stable at fixed cable lengths.
    pub stable: Option<bool>,
    /// Distance from the file's localiser position, metres.
    pub position_error_m: Option<f64>,
    /// Why the row is flagged: no equilibrium, inconsistent, unstable.
    pub flag: Option<String>,
}

/// Every row of a file localised.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedLocalizationReport {
    /// The robot's name.
    pub robot: String,
    /// Its number of cables.
    pub cables: usize,
    /// One entry per input row.
    pub rows: Vec<SuspendedRowReport>,
    /// Rows with a flag.
    pub rows_flagged: usize,
    /// RMS of the unflagged rows' distances from the localiser, metres.
    pub position_rms_error_m: Option<f64>,
    /// Largest of them, metres.
    pub position_max_error_m: Option<f64>,
}

/// Localise every row of `rows` on the calibrated `robot`, readings weighed
/// by `noise`, each row tested at `false_alarm`; `progress(done, total)`
/// after each row.
pub fn localize_suspended_rows(
    robot: &SuspendedRobot,
    rows: &[SuspendedMeasurement],
    noise: &SensorNoise,
    false_alarm: f64,
    progress: &mut dyn FnMut(usize, usize),
) -> SuspendedLocalizationReport {
    let mut reports = Vec::with_capacity(rows.len());
    for (k, row) in rows.iter().enumerate() {
        let at = DataRow::at(k, row.line);
        reports.push(match localize_suspended(robot, row, noise, false_alarm) {
            Ok(found) => {
                let (roll, pitch, yaw) = found.pose.roll_pitch_yaw_deg();
                let logged = nalgebra::Vector3::from(row.position_m);
                let flag = match (found.consistent, found.stable) {
                    (true, true) => None,
                    (false, _) => Some(format!(
                        "the readings disagree with the robot (chi-square {:.2} for {} degrees of freedom)",
                        found.chi_square, found.degrees_of_freedom
                    )),
                    (true, false) => Some("the equilibrium is unstable at these cable lengths".into()),
                };
                SuspendedRowReport {
                    at,
                    position_m: Some(found.pose.position_m.into()),
                    roll_pitch_yaw_deg: Some([roll, pitch, yaw]),
                    forces_n: Some(found.forces.iter().map(|t| [t.horizontal_n, t.vertical_n]).collect()),
                    position_sigma_m: Some(found.position_sigma_m),
                    position_covariance_m2: found.position_covariance_m2,
                    chi_square: Some(found.chi_square),
                    degrees_of_freedom: Some(found.degrees_of_freedom),
                    consistent: found.consistent,
                    stable: Some(found.stable),
                    position_error_m: Some((found.pose.position_m - logged).norm()),
                    flag,
                }
            }
            Err(e) => SuspendedRowReport {
                at,
                position_m: None,
                roll_pitch_yaw_deg: None,
                forces_n: None,
                position_sigma_m: None,
                position_covariance_m2: None,
                chi_square: None,
                degrees_of_freedom: None,
                consistent: false,
                stable: None,
                position_error_m: None,
                flag: Some(e.to_string()),
            },
        });
        progress(k + 1, rows.len());
    }
    let errors: Vec<f64> = reports
        .iter()
        .filter(|r| r.flag.is_none())
        .filter_map(|r| r.position_error_m)
        .collect();
    SuspendedLocalizationReport {
        robot: robot.name.clone(),
        cables: robot.cable_count(),
        rows_flagged: reports.iter().filter(|r| r.flag.is_some()).count(),
        position_rms_error_m: (!errors.is_empty())
            .then(|| (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt()),
        position_max_error_m: errors.iter().copied().reduce(f64::max),
        rows: reports,
    }
}

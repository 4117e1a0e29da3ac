//! The data file as `sagcal check` reads it: its format told apart as the
//! commands tell it ([`read_data`]), its columns, a few rows, its sensors and
//! its readings against the robot's geometry ([`summarise`]).

use std::path::Path;

use nalgebra::Vector3;

use super::report::{
    CableAgainstGeometry, ColumnSummary, DataFormat, DataSummary, RejectedLine, SampleRow, Sensors, Span,
};
use crate::error::{Error, Result};
use crate::io::authors::{FORCES_FILE, LENGTHS_FILE, ORIENTATION_FILE, POSITION_FILE};
use crate::io::measurements::{pose_values, read_measurements, MeasurementFormat, ReadOptions, MEASUREMENT_HEADER};
use crate::io::readings::{read_readings, ReadingRow, READINGS_HEADER};
use crate::io::recurdyn::{read_recurdyn, LoadOptions};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::cable_geometry;

/// The rows of a data file.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Rows {
    /// Poses with the localiser's reading (sagcal CSV, RecurDyn log, authors' folder).
    Poses(Vec<PoseMeasurement>),
    /// Cable readings alone.
    Readings(Vec<ReadingRow>),
}

/// A data file as read.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct DataRead {
    pub(super) format: DataFormat,
    pub(super) rows: Rows,
    pub(super) rejected: Vec<RejectedLine>,
    /// Rows with every cable's tension (RecurDyn logs).
    pub(super) all_cable_tension_rows: usize,
}

/// How many rows [`summarise`] shows from the start (and the last one after them).
const FIRST_SAMPLES: usize = 3;

/// Read `path` as the commands do: a measurement file (sagcal CSV, RecurDyn
/// log, authors' folder: what `calibrate` reads) or, when its header is
/// neither, a readings-only CSV (what `localize` reads too).
pub(super) fn read_data(path: &Path, robot: &Robot) -> Result<DataRead> {
    let options = ReadOptions {
        reference_cable: robot.reference_cable,
        keep_rounded: false,
    };
    let set = match read_measurements(path, &options) {
        Ok(set) => set,
        Err(Error::Format { .. }) if !path.is_dir() => {
            let file = read_readings(path, robot.reference_cable)?;
            return Ok(DataRead {
                format: DataFormat::ReadingsOnlyCsv,
                rows: Rows::Readings(file.rows),
                rejected: Vec::new(),
                all_cable_tension_rows: 0,
            });
        }
        Err(e) => return Err(e),
    };
    let (format, all_cable_tension_rows) = match set.format {
        MeasurementFormat::Sagcal => (DataFormat::SagcalCsv, 0),
        MeasurementFormat::Authors => (DataFormat::AuthorsFolder, 0),
        MeasurementFormat::RecurDyn => {
            let log = read_recurdyn(path, &LoadOptions::default())?;
            let all = log
                .rows
                .iter()
                .filter(|r| r.tensions.iter().all(Option::is_some))
                .count();
            (DataFormat::RecurdynLog, all)
        }
    };
    Ok(DataRead {
        format,
        rows: Rows::Poses(set.poses),
        rejected: set
            .rejected
            .into_iter()
            .map(|r| RejectedLine {
                line: r.line,
                reason: r.reason,
            })
            .collect(),
        all_cable_tension_rows,
    })
}

/// The summary of `data` read from `path` for `robot`.
pub(super) fn summarise(data: &DataRead, robot: &Robot, path: &Path) -> DataSummary {
    let (values, lines): (Vec<Vec<Option<f64>>>, Vec<usize>) = match &data.rows {
        Rows::Poses(poses) => poses
            .iter()
            .map(|p| (pose_values(p).iter().map(|v| Some(*v)).collect(), p.line))
            .unzip(),
        Rows::Readings(rows) => rows
            .iter()
            .map(|r| {
                let mut v: Vec<Option<f64>> = r.encoder_lengths_m.iter().map(|l| Some(*l)).collect();
                v.push(r.load_cell_n);
                (v, r.line)
            })
            .unzip(),
    };
    let columns: Vec<ColumnSummary> = column_names(data.format, robot.reference_cable)
        .into_iter()
        .enumerate()
        .map(|(c, (column, quantity, unit))| {
            let present: Vec<f64> = values.iter().filter_map(|row| row[c]).collect();
            ColumnSummary {
                column,
                quantity,
                unit: unit.into(),
                rows: present.len(),
                range: Span::of(present),
            }
        })
        .collect();
    let n = values.len();
    let shown: Vec<usize> = (0..n.min(FIRST_SAMPLES))
        .chain((n > FIRST_SAMPLES).then_some(n - 1))
        .collect();
    DataSummary {
        path: path.display().to_string(),
        format: data.format,
        format_description: data.format.describe().into(),
        rows: n,
        lines: Span::of(lines.iter().map(|&l| l as f64)),
        rejected: data.rejected.clone(),
        samples: shown
            .into_iter()
            .map(|k| SampleRow {
                row: k + 1,
                line: lines[k],
                values: values[k].clone(),
            })
            .collect(),
        sensors: sensors(data, robot, &columns),
        usable_by: usable_by(data),
        geometry: match &data.rows {
            Rows::Poses(poses) => against_geometry(robot, poses),
            Rows::Readings(_) => Vec::new(),
        },
        columns,
    }
}

/// Each column: its name in the file, what it measures, its unit.
fn column_names(format: DataFormat, reference_cable: usize) -> Vec<(String, String, &'static str)> {
    let k = reference_cable + 1;
    let quantities: Vec<(String, &'static str)> = ["x", "y", "z"]
        .map(|a| (format!("localiser position {a}, world frame"), "m"))
        .into_iter()
        .chain(["roll", "pitch", "yaw"].map(|a| (format!("localiser {a}, R = Rz(yaw) Ry(pitch) Rx(roll)"), "deg")))
        .chain((1..=CABLE_COUNT).map(|i| (format!("encoder of cable {i} (length + offset)"), "m")))
        .chain([(format!("load cell, cable {k} (tension at the platform)"), "N")])
        .collect();
    let names: Vec<String> = match format {
        DataFormat::SagcalCsv => MEASUREMENT_HEADER.iter().map(|s| s.to_string()).collect(),
        DataFormat::RecurdynLog => ["x", "y", "z", "roll", "pitch", "yaw", "L1", "L2", "L3", "L4"]
            .iter()
            .map(|s| s.to_string())
            .chain([format!("fc{k}")])
            .collect(),
        DataFormat::AuthorsFolder => ["x", "y", "z"]
            .map(|c| format!("{POSITION_FILE} {c}"))
            .into_iter()
            .chain(["roll", "pitch", "yaw"].map(|c| format!("{ORIENTATION_FILE} {c}")))
            .chain((1..=CABLE_COUNT).map(|i| format!("{LENGTHS_FILE} l{i}")))
            .chain([format!("{FORCES_FILE} |(f_h, f_v)|")])
            .collect(),
        DataFormat::ReadingsOnlyCsv => {
            return READINGS_HEADER
                .iter()
                .zip(quantities.into_iter().skip(6))
                .map(|(name, (quantity, unit))| (name.to_string(), quantity, unit))
                .collect()
        }
    };
    names
        .into_iter()
        .zip(quantities)
        .map(|(name, (quantity, unit))| (name, quantity, unit))
        .collect()
}

fn sensors(data: &DataRead, robot: &Robot, columns: &[ColumnSummary]) -> Sensors {
    let load_cell_rows = columns.last().map_or(0, |c| c.rows);
    let rows = match &data.rows {
        Rows::Poses(p) => p.len(),
        Rows::Readings(r) => r.len(),
    };
    let (localiser_position, localiser_orientation, closure) = match &data.rows {
        Rows::Poses(poses) => {
            let level = poses
                .iter()
                .all(|p| p.roll_deg == 0.0 && p.pitch_deg == 0.0 && p.yaw_deg == 0.0);
            let closure = "each pose: the localiser's position and the load cell close the statics (calibrate, \
                           diagnose, verify); localize: the four encoders and the load cell, the logged pose \
                           compared";
            (true, if level { "all zero" } else { "measured" }, closure.to_string())
        }
        Rows::Readings(_) => {
            let closure = match load_cell_rows {
                0 => "the four encoders alone (localize's forward kineto-statics)".to_string(),
                n if n == rows => "the four encoders and the load cell (localize)".to_string(),
                n => format!("the four encoders, and the load cell on {n} of {rows} rows (localize)"),
            };
            (false, "absent", closure)
        }
    };
    Sensors {
        encoders: CABLE_COUNT,
        load_cell_cable: (load_cell_rows > 0).then_some(robot.reference_cable + 1),
        load_cell_rows,
        localiser_position,
        localiser_orientation: localiser_orientation.into(),
        all_cable_tension_rows: data.all_cable_tension_rows,
        closure,
    }
}

fn usable_by(data: &DataRead) -> Vec<String> {
    let commands: &[&str] = match data.rows {
        Rows::Poses(_) => &[
            "calibrate",
            "diagnose",
            "verify",
            "localize",
            "experiment table2",
            "plan --from",
        ],
        Rows::Readings(_) => &["localize"],
    };
    commands.iter().map(|c| c.to_string()).collect()
}

/// Per cable, the readings against the distances from its anchor to its
/// attachment point at the logged poses: their median difference, the
/// slope and the correlation.
pub(super) fn against_geometry(robot: &Robot, poses: &[PoseMeasurement]) -> Vec<CableAgainstGeometry> {
    let distances: Vec<[f64; CABLE_COUNT]> = poses
        .iter()
        .map(|p| {
            let geometry = cable_geometry(robot, &p.localiser_pose());
            std::array::from_fn(|i| (robot.anchors_m[i] - geometry[i].attachment_world_m).norm())
        })
        .collect();
    (0..CABLE_COUNT)
        .map(|i| {
            let d: Vec<f64> = distances.iter().map(|d| d[i]).collect();
            let r: Vec<f64> = poses.iter().map(|p| p.encoder_lengths_m[i]).collect();
            cable_against_geometry(i, &d, &r, robot.length_offsets_m[i])
        })
        .collect()
}

/// Cable `i`'s (0-based) `readings` against its straight `distances` at the
/// same poses, with the robot file's `offset_m`.
pub(super) fn cable_against_geometry(
    i: usize,
    distances: &[f64],
    readings: &[f64],
    offset_m: f64,
) -> CableAgainstGeometry {
    let (slope, correlation) = fit(distances, readings).unzip();
    CableAgainstGeometry {
        cable: i + 1,
        median_reading_minus_distance_m: median(readings.iter().zip(distances).map(|(r, d)| r - d).collect()),
        robot_offset_m: offset_m,
        slope,
        correlation,
    }
}

/// The least-squares slope of `y` on `x` and their correlation; `None` with
/// fewer than 3 points or distances that vary by less than a millimetre
/// (the slope would be noise).
fn fit(x: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let n = x.len() as f64;
    if x.len() < 3 {
        return None;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let syy: f64 = y.iter().map(|v| (v - my).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    if (sxx / n).sqrt() < 1e-3 || syy == 0.0 {
        return None;
    }
    Some((sxy / sxx, sxy / (sxx * syy).sqrt()))
}

/// The median (the upper one of an even count; NaN for none).
pub(super) fn median(mut values: Vec<f64>) -> f64 {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// The corners of the box poses can reach: the anchors' horizontal extent,
/// from the bottom of the robot's workspace to the lowest anchor.
pub(super) fn frame_corners(robot: &Robot, floor_z: f64) -> Vec<Vector3<f64>> {
    let min = robot
        .anchors_m
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |m, a| m.inf(a));
    let max = robot
        .anchors_m
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |m, a| m.sup(a));
    let mut corners = Vec::with_capacity(8);
    for x in [min.x, max.x] {
        for y in [min.y, max.y] {
            for z in [floor_z.min(min.z), min.z] {
                corners.push(Vector3::new(x, y, z));
            }
        }
    }
    corners
}

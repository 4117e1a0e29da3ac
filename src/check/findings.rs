//! The likely mistakes `sagcal check` names. For poses it runs what
//! `calibrate` runs before its fit ([`crate::calib::mistakes::before_calibration`]:
//! a load cell or an encoder in the wrong unit, poses outside the frame;
//! [`crate::calib::screen::check_kept_rows`]: duplicated rows, impossible
//! readings, angles out of range, too few rows, positions that look like mm),
//! and adds what only a look at the whole file shows: poses outside the
//! robot file's `[workspace]`, encoder readings that do not follow the
//! geometry, rows the reader left out. Readings alone carry no pose: their
//! columns are compared with what the robot's frame allows.

use nalgebra::Vector3;

use super::data_file::{frame_corners, median, DataRead, Rows};
use super::report::{row_label, CableAgainstGeometry, CheckWarning, WarningKind};
use crate::calib::mistakes::{before_calibration, without_rows_outside, Mistake, MistakeKind};
use crate::calib::screen::{check_kept_rows, robot_size_m};
use crate::calib::MIN_POSES;
use crate::error::Error;
use crate::io::readings::ReadingRow;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::NoisePreset;
use crate::model::statics::reference_tension_magnitude_guess;
use crate::model::DataRow;
use crate::sim::closed_form::Workspace;

/// At most this many rows are named in one warning.
const NAMED_ROWS: usize = 5;
/// At most this many reasons of rows the reader left out are quoted.
const QUOTED_REASONS: usize = 3;

/// A slope of the readings on the distances outside `1/SLOPE_FACTOR ..
/// SLOPE_FACTOR` (or a correlation below [`MIN_CORRELATION`]) says the
/// readings do not follow the geometry: the sag changes a catenary's excess
/// over its chord by a few per cent of the chord at most, and a robot file a
/// few metres off moves the distances by as much at every pose.
pub(super) const SLOPE_FACTOR: f64 = 2.0;
/// See [`SLOPE_FACTOR`].
pub(super) const MIN_CORRELATION: f64 = 0.5;

/// A unit ratio within this factor of 1000 (100) names mm (cm): the
/// tolerance of [`crate::calib::mistakes`].
pub(super) const UNIT_TOLERANCE: f64 = 3.0;

/// The warnings for `data` read for `robot`, in the order found.
pub(super) fn findings(robot: &Robot, data: &DataRead, geometry: &[CableAgainstGeometry]) -> Vec<CheckWarning> {
    let mut found = Vec::new();
    if !data.rejected.is_empty() {
        let quoted: Vec<String> = data
            .rejected
            .iter()
            .take(QUOTED_REASONS)
            .map(|r| format!("line {}: {}", r.line, r.reason))
            .collect();
        let rest = data.rejected.len().saturating_sub(QUOTED_REASONS);
        found.push(CheckWarning {
            kind: WarningKind::Rejected,
            message: format!(
                "{} rows left out as every command reads the file: {}{}",
                data.rejected.len(),
                quoted.join("; "),
                if rest > 0 {
                    format!("; and {rest} more (--json lists them all)")
                } else {
                    String::new()
                }
            ),
            rows: Vec::new(),
        });
    }
    match &data.rows {
        Rows::Poses(poses) => {
            found.extend(pose_findings(robot, poses));
            found.extend(outside_workspace(robot, poses));
            // Positions mostly outside the frame (in mm?) say nothing of the encoders.
            let outside = found
                .iter()
                .filter(|w| w.kind == WarningKind::OutsideFrame)
                .map(|w| w.rows.len())
                .sum::<usize>();
            if 2 * outside <= poses.len() {
                found.extend(geometry_findings(robot, geometry, &found));
            }
        }
        Rows::Readings(rows) => found.extend(readings_findings(robot, rows)),
    }
    found
}

fn more(count: usize) -> String {
    match count.saturating_sub(NAMED_ROWS) {
        0 => String::new(),
        n => format!("; and {n} more"),
    }
}

/// What `calibrate` finds before its fit, as warnings.
fn pose_findings(robot: &Robot, poses: &[PoseMeasurement]) -> Vec<CheckWarning> {
    let mistakes = before_calibration(robot, poses);
    let (kept, rows) = without_rows_outside(poses, &mistakes);
    let units: Vec<&Mistake> = mistakes.iter().filter(|m| m.is_unit_mistake()).collect();
    let outside: Vec<&Mistake> = mistakes
        .iter()
        .filter(|m| m.kind == MistakeKind::OutsideFrame)
        .collect();
    let mut found: Vec<CheckWarning> = units
        .iter()
        .map(|m| CheckWarning {
            kind: WarningKind::Unit,
            message: format!("{} (calibrate refuses such data)", m.message),
            rows: Vec::new(),
        })
        .collect();
    if let Some(first) = outside.first() {
        let others: Vec<String> = outside[1..]
            .iter()
            .take(NAMED_ROWS)
            .map(|m| m.rows[0].to_string())
            .collect();
        let message = match others.len() {
            0 => first.message.clone(),
            _ => format!(
                "{} rows outside the robot's frame, left out by calibrate: {}; also {}{}",
                outside.len(),
                first.message,
                others.join(", "),
                more(outside.len() - 1)
            ),
        };
        found.push(CheckWarning {
            kind: WarningKind::OutsideFrame,
            message,
            rows: outside.iter().map(|m| m.rows[0]).collect(),
        });
    }
    // As calibrate: the row checks once the units are right, or when too few
    // rows are in the frame (the positions may be in mm).
    if units.is_empty() || kept.len() < MIN_POSES {
        let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
        if let Err(e) = check_kept_rows(robot, poses, &kept, &rows, &noise) {
            let message = match e {
                Error::InvalidInput(message) => message,
                other => other.to_string(),
            };
            found.push(CheckWarning {
                kind: WarningKind::Rows,
                message: format!("calibrate would refuse the data: {message}"),
                rows: Vec::new(),
            });
        }
    }
    found
}

/// Poses inside the frame but outside the robot file's `[workspace]`.
fn outside_workspace(robot: &Robot, poses: &[PoseMeasurement]) -> Option<CheckWarning> {
    let box_m = robot.workspace?;
    let rows: Vec<usize> = (0..poses.len())
        .filter(|&k| (0..3).any(|a| !(box_m.min_m[a]..=box_m.max_m[a]).contains(&poses[k].position_m[a])))
        .collect();
    let first = *rows.first()?;
    let names: Vec<String> = rows
        .iter()
        .take(NAMED_ROWS)
        .map(|&k| row_label(k + 1, poses[k].line))
        .collect();
    let p = poses[first].position_m;
    Some(CheckWarning {
        kind: WarningKind::OutsideWorkspace,
        message: format!(
            "{} of {} rows are outside the robot file's [workspace] (x {} .. {}, y {} .. {}, z {} .. {} m): {}{}; \
             the first at [{:.3}, {:.3}, {:.3}] m (the box is where plan and simulate put poses: is it the robot's, \
             and are the positions in its world frame?)",
            rows.len(),
            poses.len(),
            box_m.min_m[0],
            box_m.max_m[0],
            box_m.min_m[1],
            box_m.max_m[1],
            box_m.min_m[2],
            box_m.max_m[2],
            names.join(", "),
            more(rows.len()),
            p[0],
            p[1],
            p[2]
        ),
        rows: rows.iter().map(|&k| DataRow::at(k, poses[k].line)).collect(),
    })
}

/// Cables whose readings do not follow the distances to the logged poses,
/// or sit farther from them than the robot is large; not for a cable already
/// named in the wrong unit.
fn geometry_findings(robot: &Robot, geometry: &[CableAgainstGeometry], earlier: &[CheckWarning]) -> Vec<CheckWarning> {
    let size_m = robot_size_m(robot);
    let mut found = Vec::new();
    for g in geometry {
        let named = earlier
            .iter()
            .any(|w| w.kind == WarningKind::Unit && w.message.contains(&format!("encoder of cable {} ", g.cable)));
        if named {
            continue;
        }
        if let (Some(slope), Some(correlation)) = (g.slope, g.correlation) {
            if !(1.0 / SLOPE_FACTOR..=SLOPE_FACTOR).contains(&slope) || correlation < MIN_CORRELATION {
                found.push(CheckWarning {
                    kind: WarningKind::Geometry,
                    message: format!(
                        "the encoder of cable {c} does not follow the distance from anchor {c} to the platform at the \
                         logged poses (slope {slope:.3}, correlation {correlation:.3}; about 1 and 1 for readings of \
                         this robot): are the encoder columns in the robot's cable order, the anchors right, the \
                         positions in the robot's world frame?",
                        c = g.cable
                    ),
                    rows: Vec::new(),
                });
                continue;
            }
        }
        let excess = g.median_reading_minus_distance_m - g.robot_offset_m;
        if excess.abs() > size_m {
            found.push(CheckWarning {
                kind: WarningKind::Geometry,
                message: format!(
                    "the encoder of cable {c} reads {excess:+.3} m from the distance between anchor {c} and the \
                     platform (median over the rows, the robot file's offset {:.3} m taken off), more than the \
                     robot's {size_m:.3} m size: an encoder zeroed that far from the cable's length, another unit, \
                     or another robot's data?",
                    g.robot_offset_m,
                    c = g.cable
                ),
                rows: Vec::new(),
            });
        }
    }
    found
}

/// Readings alone: each encoder's spread against the longest straight line
/// from its anchor to the frame; the load cell against the straight-cable
/// statics over the workspace.
fn readings_findings(robot: &Robot, rows: &[ReadingRow]) -> Vec<CheckWarning> {
    let workspace = Workspace::default_for(robot);
    let corners = frame_corners(robot, workspace.min_m[2]);
    let reach = robot.attachments_m.iter().map(|b| b.norm()).fold(0.0, f64::max);
    let mut found = Vec::new();
    for i in 0..CABLE_COUNT {
        let longest = corners
            .iter()
            .map(|c| (robot.anchors_m[i] - c).norm())
            .fold(0.0, f64::max)
            + reach;
        let values: Vec<f64> = rows.iter().map(|r| r.encoder_lengths_m[i]).collect();
        let spread = values.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v))
            - values.iter().fold(f64::INFINITY, |m, v| m.min(*v));
        if spread > UNIT_TOLERANCE * longest {
            found.push(CheckWarning {
                kind: WarningKind::Unit,
                message: format!(
                    "the encoder of cable {} spans {spread:.4e} over the rows, {:.0} times the longest straight line \
                     from its anchor to the robot's frame ({longest:.3} m): its readings cannot be metres \
                     (mm or cm? convert the column to metres)",
                    i + 1,
                    spread / longest
                ),
                rows: Vec::new(),
            });
        }
    }
    found.extend(readings_load_cell(robot, rows, &workspace));
    found
}

/// The load cell's median reading against the straight-cable statics' median over the workspace.
fn readings_load_cell(robot: &Robot, rows: &[ReadingRow], workspace: &Workspace) -> Option<CheckWarning> {
    let readings: Vec<f64> = rows.iter().filter_map(|r| r.load_cell_n).collect();
    if readings.is_empty() {
        return None;
    }
    let grid = |a: usize, t: f64| workspace.min_m[a] + t * (workspace.max_m[a] - workspace.min_m[a]);
    let mut guesses = Vec::new();
    for tx in [0.0, 0.5, 1.0] {
        for ty in [0.0, 0.5, 1.0] {
            for tz in [0.0, 0.5, 1.0] {
                let p = Vector3::new(grid(0, tx), grid(1, ty), grid(2, tz));
                guesses.push(reference_tension_magnitude_guess(robot, p));
            }
        }
    }
    let ratio = median(readings) / median(guesses);
    let unit = [(1e3, "mN"), (1e-3, "kN")]
        .iter()
        .find(|(nominal, _)| ratio > nominal / UNIT_TOLERANCE && ratio < nominal * UNIT_TOLERANCE)?
        .1;
    Some(CheckWarning {
        kind: WarningKind::Unit,
        message: format!(
            "the load cell's median reading is {ratio:.3e} times the reference tension the straight-cable statics \
             give over the robot's workspace: it looks like {unit}, not N (convert the column to newtons)"
        ),
        rows: Vec::new(),
    })
}

//! `sagcal check` on a robot of 3 to 8 cables ([`check_suspended_files`]):
//! what was understood from its robot file (the cables, their load cells
//! and weights, the `2N - 6` force components the statics leave free, the
//! workspace) and from its measurement file (columns, units, ranges, a few
//! rows, the encoders against the geometry), and the likely mistakes, each
//! a [`CheckWarning`] as for four cables:
//!
//! - too few rows for `calibrate` ([`crate::calib::suspended::min_poses`]),
//!   and rows that repeat another;
//! - positions outside the anchors' footprint or above the lowest anchor,
//!   or in millimetres; positions outside the robot file's `[workspace]`;
//! - encoders in millimetres or centimetres (their readings less the
//!   offsets against the straight distances from anchor to attachment at
//!   the logged poses), readings shorter than that straight line (a cable
//!   is never shorter than its chord), and readings that do not follow the
//!   geometry (slope and correlation, as for four cables);
//! - load cells in kN or mN: the readings against the tension of the
//!   nominal model's equilibrium at the logged position and yaw
//!   ([`crate::model::suspended::solve_at`]).
//!
//! ```
//! use sagcal::check::check_suspended_files;
//! let robot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/six.toml");
//! let report = check_suspended_files(&robot, None)?;
//! assert_eq!((report.robot.cables, report.robot.free_force_components), (6, 6));
//! assert_eq!(report.robot.load_cells, vec![1]);
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::path::Path;

use nalgebra::{Vector2, Vector3};
use serde::Serialize;

use super::data_file::{cable_against_geometry, median};
use super::findings::{MIN_CORRELATION, SLOPE_FACTOR, UNIT_TOLERANCE};
use super::report::{
    CableAgainstGeometry, CheckWarning, ColumnSummary, SampleRow, Span, WarningKind, WorkspaceSummary,
};
use crate::calib::suspended::min_poses;
use crate::error::Result;
use crate::io::suspended_measurements::{read_suspended_measurements, row_values, suspended_header};
use crate::model::geometry::Footprint;
use crate::model::plausibility::STANDARD_GRAVITY_M_S2;
use crate::model::robot::Workspace;
use crate::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedMeasurement, SuspendedRobot};
use crate::model::DataRow;

/// Positions whose median largest coordinate exceeds this many robot sizes
/// (the anchors' footprint or height) are in millimetres: a platform in
/// metres stays within one size of the origin, and in millimetres a
/// position a tenth of a size from it reads a hundred sizes.
const MM_POSITIONS_SIZES: f64 = 30.0;
/// How many rows [`check_suspended_files`] shows from the start (and the last one after them).
const FIRST_SAMPLES: usize = 3;
/// At most this many rows are named in one warning.
const NAMED_ROWS: usize = 5;
/// A reading shorter than the straight line by more than this is named,
/// metres: ten times the paper's encoder sigma, so that noise is not.
const SHORTER_THAN_CHORD_M: f64 = 0.1;

/// What `sagcal check` found for a robot of 3 to 8 cables.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedCheckReport {
    /// The robot.
    pub robot: SuspendedRobotSummary,
    /// The data, if a data file was given.
    pub data: Option<SuspendedDataSummary>,
    /// Likely mistakes, in the order found; empty when none.
    pub warnings: Vec<CheckWarning>,
}

/// A robot of 3 to 8 cables as read from its file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedRobotSummary {
    /// The robot file, as given.
    pub path: String,
    /// The robot's name.
    pub name: String,
    /// The number of cables `N`.
    pub cables: usize,
    /// The cables with a load cell, 1-based.
    pub load_cells: Vec<usize>,
    /// The end-force components the statics leave free at a pose, `2N - 6`.
    pub free_force_components: usize,
    /// Anchors, world frame, metres, in cable order.
    pub anchors_m: Vec<[f64; 3]>,
    /// Attachment points, platform frame, metres.
    pub attachments_m: Vec<[f64; 3]>,
    /// The anchors' extent along world x, y and z, metres.
    pub anchor_span_m: [Span; 3],
    /// The narrowest extent of the anchors' horizontal footprint, metres.
    pub footprint_width_m: f64,
    /// The largest distance between two anchors' projections on the floor, metres.
    pub footprint_diameter_m: f64,
    /// The largest distance of an attachment point from the platform's origin, metres.
    pub platform_reach_m: f64,
    /// Platform weight, newtons.
    pub platform_weight_n: f64,
    /// Platform mass at 9.81 m/s^2, kilograms.
    pub platform_mass_kg: f64,
    /// Each cable's weight per metre, newtons per metre.
    pub cable_weights_n_per_m: Vec<f64>,
    /// Each cable's axial stiffness `EA`, newtons (`None`: inextensible).
    pub axial_stiffness_n: Vec<Option<f64>>,
    /// Centre of mass, platform frame, metres.
    pub com_offset_m: [f64; 3],
    /// Encoder length offsets, metres, in cable order.
    pub length_offsets_m: Vec<f64>,
    /// The box calibration poses are drawn from (`plan`, `simulate`).
    pub workspace: WorkspaceSummary,
}

/// A measurement file of a robot of 3 to 8 cables as read.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedDataSummary {
    /// The file, as given.
    pub path: String,
    /// Its format in words.
    pub format_description: String,
    /// Data rows read.
    pub rows: usize,
    /// The first and last row's file line.
    pub lines: Span,
    /// Each column: its name, quantity, unit and range.
    pub columns: Vec<ColumnSummary>,
    /// A few rows as read, in the order of the columns.
    pub samples: Vec<SampleRow>,
    /// The commands that take this data.
    pub usable_by: Vec<String>,
    /// Per cable, the encoder readings against the straight distance from
    /// its anchor to its attachment at the logged poses.
    pub geometry: Vec<CableAgainstGeometry>,
}

/// Read the robot file of 3 to 8 cables at `robot_path` and, if given, its
/// measurement file at `data_path`, and say what was understood and what
/// looks wrong (module docs). An unreadable or invalid file is an error
/// naming it; a likely mistake in readable data is a warning.
pub fn check_suspended_files(robot_path: &Path, data_path: Option<&Path>) -> Result<SuspendedCheckReport> {
    let robot = SuspendedRobot::from_file(robot_path)?;
    check_suspended_robot_and_data(&robot, robot_path, data_path)
}

/// [`check_suspended_files`] for a robot already read from `robot_path`.
pub fn check_suspended_robot_and_data(
    robot: &SuspendedRobot,
    robot_path: &Path,
    data_path: Option<&Path>,
) -> Result<SuspendedCheckReport> {
    let summary = robot_summary(robot, robot_path);
    let Some(path) = data_path else {
        return Ok(SuspendedCheckReport {
            robot: summary,
            data: None,
            warnings: Vec::new(),
        });
    };
    let rows = read_suspended_measurements(path, robot)?;
    let data = data_summary(robot, &rows, path);
    let warnings = findings(robot, &rows, &data.geometry);
    Ok(SuspendedCheckReport {
        robot: summary,
        data: Some(data),
        warnings,
    })
}

/// What `robot`, read from `path`, holds.
fn robot_summary(robot: &SuspendedRobot, path: &Path) -> SuspendedRobotSummary {
    let footprint = Footprint::of_anchors(&robot.anchors_m);
    let workspace = robot
        .workspace
        .unwrap_or_else(|| Workspace::around_anchor_points(&robot.anchors_m));
    let axis = |k: usize| Span::of(robot.anchors_m.iter().map(|a| a[k]));
    SuspendedRobotSummary {
        path: path.display().to_string(),
        name: robot.name.clone(),
        cables: robot.cable_count(),
        load_cells: robot.load_cells.iter().map(|c| c + 1).collect(),
        free_force_components: robot.free_components(),
        anchors_m: robot.anchors_m.iter().map(|a| [a.x, a.y, a.z]).collect(),
        attachments_m: robot.attachments_m.iter().map(|b| [b.x, b.y, b.z]).collect(),
        anchor_span_m: [axis(0), axis(1), axis(2)],
        footprint_width_m: footprint.width_m,
        footprint_diameter_m: footprint.diameter_m,
        platform_reach_m: robot.attachments_m.iter().map(|b| b.norm()).fold(0.0, f64::max),
        platform_weight_n: robot.platform_weight_n,
        platform_mass_kg: robot.platform_weight_n / STANDARD_GRAVITY_M_S2,
        cable_weights_n_per_m: robot.cable_weights_n_per_m.clone(),
        axial_stiffness_n: robot
            .axial_stiffness_n
            .iter()
            .map(|ea| ea.is_finite().then_some(*ea))
            .collect(),
        com_offset_m: robot.com_offset_m.into(),
        length_offsets_m: robot.length_offsets_m.clone(),
        workspace: WorkspaceSummary {
            min_m: workspace.min_m,
            max_m: workspace.max_m,
            source: if robot.workspace.is_some() {
                "robot file".into()
            } else {
                "derived from the anchors".into()
            },
        },
    }
}

/// The columns, a few rows and the geometry of `rows`, read from `path`.
fn data_summary(robot: &SuspendedRobot, rows: &[SuspendedMeasurement], path: &Path) -> SuspendedDataSummary {
    let values: Vec<Vec<f64>> = rows.iter().map(row_values).collect();
    let columns: Vec<ColumnSummary> = suspended_header(robot)
        .into_iter()
        .zip(quantities(robot))
        .enumerate()
        .map(|(c, (column, (quantity, unit)))| ColumnSummary {
            column,
            quantity,
            unit: unit.into(),
            rows: values.len(),
            range: Span::of(values.iter().map(|v| v[c])),
        })
        .collect();
    let n = rows.len();
    let shown = (0..n.min(FIRST_SAMPLES)).chain((n > FIRST_SAMPLES).then_some(n - 1));
    SuspendedDataSummary {
        path: path.display().to_string(),
        format_description: format!(
            "sagcal CSV of {} cables (x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m..l{}_m,{})",
            robot.cable_count(),
            robot.cable_count(),
            robot
                .load_cells
                .iter()
                .map(|c| format!("f{}_n", c + 1))
                .collect::<Vec<_>>()
                .join(",")
        ),
        rows: n,
        lines: Span::of(rows.iter().map(|r| r.line as f64)),
        columns,
        samples: shown
            .map(|k| SampleRow {
                row: k + 1,
                line: rows[k].line,
                values: values[k].iter().map(|v| Some(*v)).collect(),
            })
            .collect(),
        usable_by: ["calibrate", "diagnose", "verify", "localize", "plan --from"]
            .map(String::from)
            .to_vec(),
        geometry: against_geometry(robot, rows),
    }
}

/// What each column of `robot`'s file measures, and its unit.
fn quantities(robot: &SuspendedRobot) -> Vec<(String, &'static str)> {
    ["x", "y", "z"]
        .map(|a| (format!("localiser position {a}, world frame"), "m"))
        .into_iter()
        .chain(["roll", "pitch", "yaw"].map(|a| (format!("localiser {a}, R = Rz(yaw) Ry(pitch) Rx(roll)"), "deg")))
        .chain((1..=robot.cable_count()).map(|i| (format!("encoder of cable {i} (length + offset)"), "m")))
        .chain(
            robot
                .load_cells
                .iter()
                .map(|c| (format!("load cell, cable {} (tension at the platform)", c + 1), "N")),
        )
        .collect()
}

/// The straight distance from each anchor to its attachment at `row`'s logged pose, metres.
fn chords(robot: &SuspendedRobot, row: &SuspendedMeasurement) -> Vec<f64> {
    let pose = row.localiser_pose();
    robot
        .anchors_m
        .iter()
        .zip(&robot.attachments_m)
        .map(|(a, b)| (a - (pose.position_m + pose.rotation * b)).norm())
        .collect()
}

/// Per cable, the readings against the straight distances at the logged poses.
fn against_geometry(robot: &SuspendedRobot, rows: &[SuspendedMeasurement]) -> Vec<CableAgainstGeometry> {
    let distances: Vec<Vec<f64>> = rows.iter().map(|r| chords(robot, r)).collect();
    (0..robot.cable_count())
        .map(|i| {
            let d: Vec<f64> = distances.iter().map(|d| d[i]).collect();
            let r: Vec<f64> = rows.iter().map(|row| row.encoder_lengths_m[i]).collect();
            cable_against_geometry(i, &d, &r, robot.length_offsets_m[i])
        })
        .collect()
}

/// `rows` as `row 3 (line 5), ...`, at most [`NAMED_ROWS`].
fn named(rows: &[DataRow]) -> String {
    let mut text: Vec<String> = rows.iter().take(NAMED_ROWS).map(ToString::to_string).collect();
    if rows.len() > NAMED_ROWS {
        text.push(format!("and {} more", rows.len() - NAMED_ROWS));
    }
    text.join(", ")
}

/// A warning of `kind` about `rows` (none: the whole file).
fn warning(kind: WarningKind, message: String, rows: Vec<DataRow>) -> CheckWarning {
    CheckWarning { kind, message, rows }
}

/// The likely mistakes in `rows` for `robot` (module docs), in this order:
/// rows, positions, workspace, encoders, load cells.
fn findings(
    robot: &SuspendedRobot,
    rows: &[SuspendedMeasurement],
    geometry: &[CableAgainstGeometry],
) -> Vec<CheckWarning> {
    let at = |k: usize| DataRow::at(k, rows[k].line);
    let mut found = Vec::new();
    let needed = min_poses(robot, false);
    if rows.len() < needed {
        found.push(warning(
            WarningKind::Rows,
            format!(
                "{} rows: calibrate needs at least {needed} poses of robot `{}` ({} anchor and offset unknowns)",
                rows.len(),
                robot.name,
                4 * robot.cable_count()
            ),
            Vec::new(),
        ));
    }
    let repeated: Vec<DataRow> = (1..rows.len())
        .filter(|&k| {
            rows[..k]
                .iter()
                .any(|earlier| row_values(earlier) == row_values(&rows[k]))
        })
        .map(at)
        .collect();
    if !repeated.is_empty() {
        found.push(warning(
            WarningKind::Rows,
            format!("rows that repeat an earlier row value for value: {}", named(&repeated)),
            repeated,
        ));
    }
    let positions = position_findings(robot, rows);
    let positions_in_mm = positions.iter().any(|w| w.kind == WarningKind::Unit);
    found.extend(positions);
    if positions_in_mm {
        // The encoders and load cells are judged at the logged poses: not at poses in mm.
        return found;
    }
    found.extend(encoder_findings(robot, rows, geometry));
    found.extend(load_cell_findings(robot, rows));
    found
}

/// Positions in millimetres, outside the anchors' frame, outside the robot
/// file's workspace.
fn position_findings(robot: &SuspendedRobot, rows: &[SuspendedMeasurement]) -> Vec<CheckWarning> {
    let at = |k: usize| DataRow::at(k, rows[k].line);
    let footprint = Footprint::of_anchors(&robot.anchors_m);
    let size = footprint
        .diameter_m
        .max(robot.anchors_m.iter().map(|a| a.z.abs()).fold(0.0, f64::max));
    let reach = median(rows.iter().map(|r| Vector3::from(r.position_m).amax()).collect());
    if reach > MM_POSITIONS_SIZES * size {
        return vec![warning(
            WarningKind::Unit,
            format!(
                "the positions look like mm, not m: their median largest coordinate is {reach:.0}, the robot {size:.1} m across"
            ),
            Vec::new(),
        )];
    }
    let lowest_anchor = robot.anchors_m.iter().map(|a| a.z).fold(f64::INFINITY, f64::min);
    let outside: Vec<DataRow> = (0..rows.len())
        .filter(|&k| {
            let p = rows[k].position_m;
            footprint.outside_m(&Vector2::new(p[0], p[1])) > 0.0 || p[2] >= lowest_anchor
        })
        .map(at)
        .collect();
    let mut found = Vec::new();
    if !outside.is_empty() {
        found.push(warning(
            WarningKind::OutsideFrame,
            format!(
                "{} positions outside the anchors' footprint or above the lowest anchor ({lowest_anchor:.3} m): {}",
                outside.len(),
                named(&outside)
            ),
            outside,
        ));
    }
    if let Some(w) = robot.workspace {
        let beyond: Vec<DataRow> = (0..rows.len())
            .filter(|&k| (0..3).any(|a| rows[k].position_m[a] < w.min_m[a] || rows[k].position_m[a] > w.max_m[a]))
            .map(at)
            .collect();
        if !beyond.is_empty() {
            found.push(warning(
                WarningKind::OutsideWorkspace,
                format!(
                    "{} positions outside the robot file's [workspace] {w}: {}",
                    beyond.len(),
                    named(&beyond)
                ),
                beyond,
            ));
        }
    }
    found
}

/// Encoders in mm or cm, readings shorter than the straight line, readings
/// that do not follow the geometry.
fn encoder_findings(
    robot: &SuspendedRobot,
    rows: &[SuspendedMeasurement],
    geometry: &[CableAgainstGeometry],
) -> Vec<CheckWarning> {
    let distances: Vec<Vec<f64>> = rows.iter().map(|r| chords(robot, r)).collect();
    let mut found = Vec::new();
    for i in 0..robot.cable_count() {
        let cable = i + 1;
        let ratio = median(
            rows.iter()
                .zip(&distances)
                .map(|(r, d)| (r.encoder_lengths_m[i] - robot.length_offsets_m[i]) / d[i])
                .collect(),
        );
        if let Some(unit) = [(1e3, "mm"), (1e2, "cm")]
            .iter()
            .find(|(scale, _)| (ratio / scale).ln().abs() < UNIT_TOLERANCE.ln())
            .map(|(_, unit)| *unit)
        {
            found.push(warning(
                WarningKind::Unit,
                format!(
                    "column l{cable}_m: the readings less the offset are {ratio:.3e} times the straight distance from \
                     anchor {cable} to its attachment: they look like {unit}, not m"
                ),
                Vec::new(),
            ));
            continue;
        }
        let shorter: Vec<DataRow> = (0..rows.len())
            .filter(|&k| {
                rows[k].encoder_lengths_m[i] - robot.length_offsets_m[i] < distances[k][i] - SHORTER_THAN_CHORD_M
            })
            .map(|k| DataRow::at(k, rows[k].line))
            .collect();
        if !shorter.is_empty() {
            found.push(warning(
                WarningKind::Geometry,
                format!(
                    "cable {cable}: the reading less the offset is more than {SHORTER_THAN_CHORD_M} m shorter than the \
                     straight line from its anchor to its attachment (a cable is never shorter than its chord) at {} \
                     rows: {}; the offset or the anchor may be wrong",
                    shorter.len(),
                    named(&shorter)
                ),
                shorter,
            ));
        }
        let g = &geometry[i];
        let follows = match (g.slope, g.correlation) {
            (Some(slope), Some(r)) => (1.0 / SLOPE_FACTOR..=SLOPE_FACTOR).contains(&slope) && r >= MIN_CORRELATION,
            _ => true,
        };
        if !follows {
            found.push(warning(
                WarningKind::Geometry,
                format!(
                    "column l{cable}_m does not follow the distance from anchor {cable} to its attachment: slope {:.3}, \
                     correlation {:.3} (about 1 for readings of this cable; columns swapped, or anchor {cable} wrong?)",
                    g.slope.unwrap_or(f64::NAN),
                    g.correlation.unwrap_or(f64::NAN)
                ),
                Vec::new(),
            ));
        }
    }
    found
}

/// Load cells in kN or mN: each against the nominal model's tension at the
/// logged position and yaw (rows without an equilibrium skipped).
fn load_cell_findings(robot: &SuspendedRobot, rows: &[SuspendedMeasurement]) -> Vec<CheckWarning> {
    let predicted: Vec<Option<Vec<f64>>> = rows
        .iter()
        .map(|row| {
            let pose = row.localiser_pose();
            let closure = if robot.cable_count() > 3 {
                Closure::Yaw {
                    yaw_rad: pose.yaw_rad(),
                }
            } else {
                Closure::Level
            };
            let eq = solve_at(robot, pose.position_m, closure, &EquilibriumOptions::default()).ok()?;
            Some(robot.load_cells.iter().map(|&c| eq.tensions[c].magnitude_n()).collect())
        })
        .collect();
    let mut found = Vec::new();
    for (j, &cable) in robot.load_cells.iter().enumerate() {
        let ratio = median(
            rows.iter()
                .zip(&predicted)
                .filter_map(|(row, p)| Some(row.load_cell_tensions_n[j] / p.as_ref()?[j]))
                .collect(),
        );
        let unit = [(1e-3, "kN"), (1e3, "mN")]
            .iter()
            .find(|(scale, _)| (ratio / scale).ln().abs() < UNIT_TOLERANCE.ln())
            .map(|(_, unit)| *unit);
        if let Some(unit) = unit {
            found.push(warning(
                WarningKind::Unit,
                format!(
                    "column f{}_n: the load cell's readings are {ratio:.3e} times the tension the nominal model's \
                     equilibrium gives at the logged poses: they look like {unit}, not N",
                    cable + 1
                ),
                Vec::new(),
            ));
        }
    }
    found
}

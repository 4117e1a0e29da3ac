//! The graph of a calibration of `N` cables: the anchors and length offsets,
//! and per pose the platform's pose and every cable's `(f_h, f_v)`.
//!
//! Per pose, the catenary graph has `2N + 6` unknowns and `2N + 6 + L + 3`
//! equations (`N` lengths, `N` heights, six of equilibrium, `L` load cells,
//! three localiser positions; three more with its orientation), so each pose
//! adds `L + 3` (or `L + 6`) to what the `4N` anchor and offset unknowns
//! are determined by ([`min_poses`]).

use std::collections::BTreeSet;

use nalgebra::{DVector, Vector3};
use serde::Serialize;

use super::factors::{
    CableConstants, CableLoadCellFactor, CableRow, CableVariables, CatenaryCableFactor, EquilibriumFactor,
    StraightCableFactor,
};
use crate::calib::factors::PosePriorFactor;
use crate::calib::options::CalibrationOptions;
use crate::graph::{Factor, FactorGraph, MaskedFactor, RobustKernel, Values, VariableId, VariableValue};
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};

/// The equilibrium factor's force sigma as a fraction of the platform's
/// weight (its moment rows: times the attachment radius). A model equation,
/// as tight as the attachment-height constraint is against a cable's span
/// (0.1 mm in tens of metres).
pub const EQUILIBRIUM_SIGMA_PER_WEIGHT: f64 = 1e-5;

/// Which cable model the graph holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SuspendedStage {
    /// Massless straight cables and the localiser's full pose: no forces.
    Straight,
    /// The paper's catenaries with every cable's forces and the equilibrium.
    Catenary,
}

/// Where one pose starts: the platform's pose and every cable's forces.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseStart {
    /// The platform's pose.
    pub pose: PlatformPose,
    /// Each cable's `(f_h, f_v)` at its attachment, cable order (empty for
    /// the straight stage).
    pub forces: Vec<CableTension>,
}

/// One reading of a pose of a robot of `N` cables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SuspendedReading {
    /// The encoder of cable `i` (0-based).
    Encoder(usize),
    /// The load cell on cable `i` (0-based).
    LoadCell(usize),
    /// The localiser's position along world axis `0..3`.
    Position(usize),
    /// The localiser's orientation about axis `0..3` of its rotation error.
    Orientation(usize),
}

/// Readings a graph leaves out: `(pose index, reading)`.
pub type Exclusions = BTreeSet<(usize, SuspendedReading)>;

/// One pose's variables.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SuspendedPoseVariables {
    /// The platform's pose.
    pub pose: VariableId,
    /// Each cable's `(f_h, f_v)`, cable order (empty in the straight stage).
    pub forces: Vec<VariableId>,
}

/// A graph and its variable ids.
pub struct SuspendedGraph {
    /// The graph.
    pub graph: FactorGraph,
    /// Each cable's anchor.
    pub anchors: Vec<VariableId>,
    /// Each cable's length offset.
    pub length_offsets: Vec<VariableId>,
    /// Per measurement.
    pub poses: Vec<SuspendedPoseVariables>,
    /// Per factor (graph order), the readings its residual rows are, row by
    /// row as `(pose index, reading)`; empty for the model's equations.
    pub readings: Vec<Vec<(usize, SuspendedReading)>>,
}

/// A graph being built, with the readings of its factors' rows.
struct Builder {
    graph: FactorGraph,
    readings: Vec<Vec<(usize, SuspendedReading)>>,
}

impl Builder {
    /// Add `factor`, whose rows are `readings`.
    fn add(&mut self, factor: Box<dyn Factor>, readings: Vec<(usize, SuspendedReading)>) {
        self.graph.factors.push(factor);
        self.readings.push(readings);
    }
}

/// The fewest poses that determine `robot`'s `4N` anchor and offset
/// unknowns (module docs), and never fewer than four.
pub fn min_poses(robot: &SuspendedRobot, with_orientation: bool) -> usize {
    let per_pose = robot.load_cells.len() + if with_orientation { 6 } else { 3 };
    (4 * robot.cable_count()).div_ceil(per_pose).max(4)
}

/// The graph of `stage` for `measurements`, starting from `robot`'s anchors
/// and offsets and `starts`' poses and forces, without the `excluded` readings.
pub fn build_suspended_graph(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    starts: &[PoseStart],
    stage: SuspendedStage,
    options: &CalibrationOptions,
    with_orientation: bool,
    excluded: &Exclusions,
) -> SuspendedGraph {
    let mut built = Builder {
        graph: FactorGraph::new(),
        readings: Vec::new(),
    };
    let vector = |v: &[f64]| VariableValue::Vector(DVector::from_column_slice(v));
    let n = robot.cable_count();
    let values = &mut built.graph.values;
    let anchors: Vec<VariableId> = (0..n)
        .map(|i| values.insert(format!("anchor {}", i + 1), vector(robot.anchors_m[i].as_slice())))
        .collect();
    let length_offsets: Vec<VariableId> = (0..n)
        .map(|i| values.insert(format!("length offset {}", i + 1), vector(&[robot.length_offsets_m[i]])))
        .collect();
    let mut poses = Vec::with_capacity(measurements.len());
    for (k, (m, start)) in measurements.iter().zip(starts).enumerate() {
        let vars = insert_pose(&mut built.graph.values, k, start, stage);
        let with_orientation = with_orientation || stage == SuspendedStage::Straight;
        add_pose_prior(&mut built, k, vars.pose, m, options, with_orientation, excluded);
        for i in (0..n).filter(|&i| !excluded.contains(&(k, SuspendedReading::Encoder(i)))) {
            let cable = [anchors[i], length_offsets[i]];
            add_cable(&mut built, robot, (k, i), &vars, cable, m.encoder_lengths_m[i], options);
        }
        if stage == SuspendedStage::Catenary {
            add_statics(&mut built, robot, (k, &vars), &anchors, m, options, excluded);
            let mut group = vec![vars.pose];
            group.extend_from_slice(&vars.forces);
            built.graph.local_groups.push(group);
        } else {
            built.graph.local_groups.push(vec![vars.pose]);
        }
        poses.push(vars);
    }
    SuspendedGraph {
        graph: built.graph,
        anchors,
        length_offsets,
        poses,
        readings: built.readings,
    }
}

/// Pose `k`'s localiser prior, its orientation rows if `with_orientation`,
/// without the excluded axes.
fn add_pose_prior(
    built: &mut Builder,
    k: usize,
    pose: VariableId,
    m: &SuspendedMeasurement,
    options: &CalibrationOptions,
    with_orientation: bool,
    excluded: &Exclusions,
) {
    let prior = PosePriorFactor::new(
        pose,
        &m.localiser_pose(),
        options.noise.position_sigma_m,
        with_orientation.then_some(options.noise.orientation_sigma_rad),
        options.robust.pose_prior,
    );
    // Rows `[orientation (3)]; position (3)]`, the orientation rows only with its prior.
    let mut rows: Vec<SuspendedReading> = Vec::with_capacity(6);
    if with_orientation {
        rows.extend((0..3).map(SuspendedReading::Orientation));
    }
    rows.extend((0..3).map(SuspendedReading::Position));
    let dropped: Vec<usize> = (0..rows.len()).filter(|&r| excluded.contains(&(k, rows[r]))).collect();
    let kept: Vec<(usize, SuspendedReading)> = rows
        .iter()
        .enumerate()
        .filter(|(r, _)| !dropped.contains(r))
        .map(|(_, &reading)| (k, reading))
        .collect();
    if dropped.is_empty() {
        built.add(Box::new(prior), kept);
    } else if let Some(masked) = MaskedFactor::new(Box::new(prior), &dropped) {
        built.add(Box::new(masked), kept);
    }
}

/// Pose `k`'s variables with `start`'s values.
fn insert_pose(values: &mut Values, k: usize, start: &PoseStart, stage: SuspendedStage) -> SuspendedPoseVariables {
    let pose = values.insert(format!("pose {}", k + 1), VariableValue::Pose(start.pose));
    let forces = match stage {
        SuspendedStage::Straight => Vec::new(),
        SuspendedStage::Catenary => start
            .forces
            .iter()
            .enumerate()
            .map(|(i, t)| {
                values.insert(
                    format!("forces {} of pose {}", i + 1, k + 1),
                    VariableValue::Vector(DVector::from_column_slice(&[t.horizontal_n, t.vertical_n])),
                )
            })
            .collect(),
    };
    SuspendedPoseVariables { pose, forces }
}

/// Cable `i`'s length (and, with its forces, height) factor at pose `k`:
/// straight without forces, a catenary with them.
fn add_cable(
    built: &mut Builder,
    robot: &SuspendedRobot,
    (k, i): (usize, usize),
    vars: &SuspendedPoseVariables,
    [anchor, length_offset]: [VariableId; 2],
    encoder_length_m: f64,
    options: &CalibrationOptions,
) {
    let noise = &options.noise;
    let encoder = vec![(k, SuspendedReading::Encoder(i))];
    let Some(&forces) = vars.forces.get(i) else {
        let straight = StraightCableFactor::new(
            [vars.pose, anchor, length_offset],
            robot.attachments_m[i],
            encoder_length_m,
            noise.encoder_sigma_m,
            options.robust.encoder,
        );
        built.add(Box::new(straight), encoder);
        return;
    };
    let variables = CableVariables {
        pose: vars.pose,
        forces,
        anchor,
        length_offset,
    };
    let constants = CableConstants::of(robot, i);
    let cable = |row, sigma_m, kernel| {
        Box::new(CatenaryCableFactor::new(
            variables,
            constants,
            encoder_length_m,
            row,
            sigma_m,
            kernel,
        ))
    };
    built.add(
        cable(CableRow::Length, noise.encoder_sigma_m, options.robust.encoder),
        encoder,
    );
    built.add(
        cable(CableRow::Height, options.height_sigma_m, RobustKernel::None),
        Vec::new(),
    );
}

/// Pose `k`'s equilibrium and load cells (without the excluded ones).
fn add_statics(
    built: &mut Builder,
    robot: &SuspendedRobot,
    (k, vars): (usize, &SuspendedPoseVariables),
    anchors: &[VariableId],
    m: &SuspendedMeasurement,
    options: &CalibrationOptions,
    excluded: &Exclusions,
) {
    let equilibrium = EquilibriumFactor::new(
        vars.pose,
        &vars.forces,
        anchors,
        &robot.attachments_m,
        robot.com_offset_m,
        robot.platform_weight_n,
        EQUILIBRIUM_SIGMA_PER_WEIGHT * robot.platform_weight_n,
        robot.attachment_radius_m().max(1e-3),
    );
    built.add(Box::new(equilibrium), Vec::new());
    for (&cable, &reading) in robot.load_cells.iter().zip(&m.load_cell_tensions_n) {
        let cell = (k, SuspendedReading::LoadCell(cable));
        if excluded.contains(&cell) {
            continue;
        }
        let factor = CableLoadCellFactor::new(
            vars.forces[cable],
            reading,
            options.noise.load_cell_sigma_n,
            options.robust.load_cell,
        );
        built.add(Box::new(factor), vec![cell]);
    }
}

/// The anchors and offsets of a solved graph in `template`'s robot.
pub fn robot_from_suspended_graph(template: &SuspendedRobot, built: &SuspendedGraph) -> SuspendedRobot {
    let mut robot = template.clone();
    let values = &built.graph.values;
    for i in 0..robot.cable_count() {
        robot.anchors_m[i] = Vector3::from_column_slice(values.vector(built.anchors[i]).as_slice());
        robot.length_offsets_m[i] = values.vector(built.length_offsets[i])[0];
    }
    robot
}

/// The poses and forces of a solved graph.
pub fn pose_starts_from_graph(built: &SuspendedGraph) -> Vec<PoseStart> {
    let values = &built.graph.values;
    built
        .poses
        .iter()
        .map(|vars| PoseStart {
            pose: *values.pose(vars.pose),
            forces: vars
                .forces
                .iter()
                .map(|&id| {
                    let f = values.vector(id);
                    CableTension {
                        horizontal_n: f[0],
                        vertical_n: f[1],
                    }
                })
                .collect(),
        })
        .collect()
}

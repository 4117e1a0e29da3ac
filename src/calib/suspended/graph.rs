//! The graph of a calibration of `N` cables: the anchors and length offsets,
//! and per pose the platform's pose and every cable's `(f_h, f_v)`.
//!
//! Per pose, the catenary graph has `2N + 6` unknowns and `2N + 6 + L + 3`
//! equations (`N` lengths, `N` heights, six of equilibrium, `L` load cells,
//! three localiser positions; three more with its orientation), so each pose
//! adds `L + 3` (or `L + 6`) to what the `4N` anchor and offset unknowns
//! are determined by ([`min_poses`]).

use nalgebra::{DVector, Vector3};

use super::factors::{
    CableConstants, CableLoadCellFactor, CableRow, CableVariables, CatenaryCableFactor, EquilibriumFactor,
    StraightCableFactor,
};
use crate::calib::factors::PosePriorFactor;
use crate::calib::options::CalibrationOptions;
use crate::graph::{FactorGraph, RobustKernel, Values, VariableId, VariableValue};
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
}

/// The fewest poses that determine `robot`'s `4N` anchor and offset
/// unknowns (module docs), and never fewer than four.
pub fn min_poses(robot: &SuspendedRobot, with_orientation: bool) -> usize {
    let per_pose = robot.load_cells.len() + if with_orientation { 6 } else { 3 };
    (4 * robot.cable_count()).div_ceil(per_pose).max(4)
}

/// The graph of `stage` for `measurements`, starting from `robot`'s anchors
/// and offsets and `starts`' poses and forces.
pub fn build_suspended_graph(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    starts: &[PoseStart],
    stage: SuspendedStage,
    options: &CalibrationOptions,
    with_orientation: bool,
) -> SuspendedGraph {
    let mut graph = FactorGraph::new();
    let vector = |v: &[f64]| VariableValue::Vector(DVector::from_column_slice(v));
    let n = robot.cable_count();
    let anchors: Vec<VariableId> = (0..n)
        .map(|i| {
            graph
                .values
                .insert(format!("anchor {}", i + 1), vector(robot.anchors_m[i].as_slice()))
        })
        .collect();
    let length_offsets: Vec<VariableId> = (0..n)
        .map(|i| {
            graph
                .values
                .insert(format!("length offset {}", i + 1), vector(&[robot.length_offsets_m[i]]))
        })
        .collect();
    let mut poses = Vec::with_capacity(measurements.len());
    for (k, (m, start)) in measurements.iter().zip(starts).enumerate() {
        let vars = insert_pose(&mut graph.values, k, start, stage);
        let orientation_sigma =
            (with_orientation || stage == SuspendedStage::Straight).then_some(options.noise.orientation_sigma_rad);
        graph.add(PosePriorFactor::new(
            vars.pose,
            &m.localiser_pose(),
            options.noise.position_sigma_m,
            orientation_sigma,
            options.robust.pose_prior,
        ));
        for i in 0..n {
            add_cable(
                &mut graph,
                robot,
                i,
                &vars,
                [anchors[i], length_offsets[i]],
                m.encoder_lengths_m[i],
                options,
            );
        }
        if stage == SuspendedStage::Catenary {
            add_statics(&mut graph, robot, &vars, &anchors, m, options);
            let mut group = vec![vars.pose];
            group.extend_from_slice(&vars.forces);
            graph.local_groups.push(group);
        } else {
            graph.local_groups.push(vec![vars.pose]);
        }
        poses.push(vars);
    }
    SuspendedGraph {
        graph,
        anchors,
        length_offsets,
        poses,
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

/// Cable `i`'s length (and, with its forces, height) factor at one pose:
/// straight without forces, a catenary with them.
fn add_cable(
    graph: &mut FactorGraph,
    robot: &SuspendedRobot,
    i: usize,
    vars: &SuspendedPoseVariables,
    [anchor, length_offset]: [VariableId; 2],
    encoder_length_m: f64,
    options: &CalibrationOptions,
) {
    let noise = &options.noise;
    match vars.forces.get(i) {
        None => graph.add(StraightCableFactor::new(
            [vars.pose, anchor, length_offset],
            robot.attachments_m[i],
            encoder_length_m,
            noise.encoder_sigma_m,
            options.robust.encoder,
        )),
        Some(&forces) => {
            let variables = CableVariables {
                pose: vars.pose,
                forces,
                anchor,
                length_offset,
            };
            let constants = CableConstants {
                attachment_m: robot.attachments_m[i],
                weight_n_per_m: robot.cable_weights_n_per_m[i],
            };
            for (row, sigma_m, kernel) in [
                (CableRow::Length, noise.encoder_sigma_m, options.robust.encoder),
                (CableRow::Height, options.height_sigma_m, RobustKernel::None),
            ] {
                graph.add(CatenaryCableFactor::new(
                    variables,
                    constants,
                    encoder_length_m,
                    row,
                    sigma_m,
                    kernel,
                ));
            }
        }
    }
}

/// One pose's equilibrium and load cells.
fn add_statics(
    graph: &mut FactorGraph,
    robot: &SuspendedRobot,
    vars: &SuspendedPoseVariables,
    anchors: &[VariableId],
    m: &SuspendedMeasurement,
    options: &CalibrationOptions,
) {
    graph.add(EquilibriumFactor::new(
        vars.pose,
        &vars.forces,
        anchors,
        &robot.attachments_m,
        robot.com_offset_m,
        robot.platform_weight_n,
        EQUILIBRIUM_SIGMA_PER_WEIGHT * robot.platform_weight_n,
        robot.attachment_radius_m().max(1e-3),
    ));
    for (&cable, &reading) in robot.load_cells.iter().zip(&m.load_cell_tensions_n) {
        graph.add(CableLoadCellFactor::new(
            vars.forces[cable],
            reading,
            options.noise.load_cell_sigma_n,
            options.robust.load_cell,
        ));
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

//! The variables and factors of one calibration problem, and the checks the
//! measurements pass before a problem is built.

use std::sync::Arc;

use nalgebra::{DVector, Vector3};

use super::effect_factors::{
    EffectVariables, ExtendedHeightFactor, ExtendedLengthFactor, ExtendedMemo, LoadCellFactor, MountedPosePriorFactor,
};
use super::factors::{
    AttachmentHeightFactor, CalibrationVariables, CatenaryCall, CatenaryLengthFactor, CatenaryMemo, PosePriorFactor,
    PoseVariables, ReferenceTensionFactor, RigidLengthFactor, SlotOrder, TensionGuardFactor, TensionSource,
};
use super::options::{CableModel, CalibrationOptions, OrientationPrior};
use crate::error::{Error, Result};
use crate::graph::{Factor, FactorGraph, MaskedFactor, Values, VariableValue};
use crate::model::effect_kind::{EffectKind, EffectSet};
use crate::model::effects::Effects;
use crate::model::measurement::{PoseMeasurement, Sensor};
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::CableTension;

/// The minimum number of poses: each adds 8 unknowns (pose, reference tension)
/// and 12 equations (4 encoders, 1 load cell, 3 position priors, 4 heights),
/// so `4 N >= 16` global unknowns.
pub const MIN_POSES: usize = 4;

/// Check the measurements before building a problem.
pub fn validate_measurements(measurements: &[PoseMeasurement]) -> Result<()> {
    if measurements.len() < MIN_POSES {
        return Err(Error::InvalidInput(format!(
            "{} poses cannot determine 12 anchor coordinates and 4 offsets: each pose adds 4 independent equations, so at least {MIN_POSES} distinct poses are needed (the paper uses 9 to 35)",
            measurements.len()
        )));
    }
    let first = Vector3::from(measurements[0].position_m);
    let spread = measurements
        .iter()
        .map(|m| (Vector3::from(m.position_m) - first).norm())
        .fold(0.0, f64::max);
    if spread < 1e-3 {
        return Err(Error::InvalidInput(format!(
            "all {} poses are at the same position ({:?}): the anchors are not observable from one place; move the platform across the workspace",
            measurements.len(),
            measurements[0].position_m
        )));
    }
    for (k, m) in measurements.iter().enumerate() {
        let fields = m
            .position_m
            .iter()
            .chain(&m.encoder_lengths_m)
            .chain([&m.roll_deg, &m.pitch_deg, &m.yaw_deg]);
        if fields.into_iter().any(|v| !v.is_finite())
            || !(m.reference_tension_n.is_finite() && m.reference_tension_n > 0.0)
        {
            return Err(Error::InvalidInput(format!(
                "{}: values must be finite and the tension positive",
                crate::model::DataRow::at(k, m.line)
            )));
        }
    }
    Ok(())
}

/// The localiser's pose of a measurement.
pub(super) fn measured_pose(m: &PoseMeasurement) -> PlatformPose {
    m.localiser_pose()
}

/// The graph and its variable ids.
pub struct CalibrationGraph {
    /// The graph.
    pub graph: FactorGraph,
    /// Anchors and offsets.
    pub globals: CalibrationVariables,
    /// Per pose.
    pub poses: Vec<PoseVariables>,
    /// The effect parameters, when the graph uses the extended model (the
    /// robot has `[effects]`, or one is estimated); `None`: the baseline factors.
    pub effects: Option<EffectVariables>,
}

/// Build the graph for `model` with initial values: anchors/offsets from
/// `robot`, poses from `poses`, reference tensions from `tensions`.
pub fn build_graph(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    poses: &[PlatformPose],
    tensions: &[CableTension],
    model: CableModel,
    options: &CalibrationOptions,
) -> CalibrationGraph {
    let mut graph = FactorGraph::new();
    let globals = insert_anchors_and_offsets(&mut graph.values, robot);
    let extended = model == CableModel::Catenary && (!robot.effects.is_none() || !options.free_effects.is_empty());
    let effect_variables = extended.then(|| insert_effect_variables(&mut graph.values, robot, options.free_effects));
    let mut slot_order = SlotOrder::new(robot);
    if extended {
        // The vertical centre-of-mass shift is a known input (see `EffectVariables::com_shift`).
        slot_order.com_offset_m.z += robot.effects.com_shift_m[2];
    }
    let factors = PoseFactors {
        slots: Arc::new(slot_order),
        globals,
        effects: effect_variables,
        model,
        options,
        tension_floor_n: 0.01 * robot.platform_weight_n / CABLE_COUNT as f64,
        // With local refinement (`LmParams::local_refinement`) every pose is
        // re-linearised by the refinement just before the solver linearises
        // it at the same point: a memo per pose (3.2 kB each) lets the
        // solver read that call. Without, one memo serves every pose and
        // stays in cache (per-pose memos slowed a 10 000-pose solve by 20 %).
        catenary_memo: (!options.lm.local_refinement).then(|| Arc::new(CatenaryMemo::default())),
        extended_memo: Arc::new(ExtendedMemo::default()),
    };
    let mut pose_variables = Vec::with_capacity(measurements.len());
    for (k, m) in measurements.iter().enumerate() {
        let pose = graph
            .values
            .insert(format!("pose {}", k + 1), VariableValue::Pose(poses[k]));
        let reference_tension = graph.values.insert(
            format!("reference tension {}", k + 1),
            VariableValue::Vector(DVector::from_row_slice(&[
                tensions[k].horizontal_n,
                tensions[k].vertical_n,
            ])),
        );
        let vars = PoseVariables {
            pose,
            reference_tension,
        };
        factors.add(&mut graph, vars, m);
        pose_variables.push(vars);
        graph.local_groups.push(vec![vars.pose, vars.reference_tension]);
    }
    CalibrationGraph {
        graph,
        globals,
        poses: pose_variables,
        effects: effect_variables,
    }
}

/// The anchor and length-offset variables with `robot`'s values.
fn insert_anchors_and_offsets(values: &mut Values, robot: &Robot) -> CalibrationVariables {
    let anchors = std::array::from_fn(|i| {
        values.insert(
            format!("anchor {}", i + 1),
            VariableValue::Vector(DVector::from_column_slice(robot.anchors_m[i].as_slice())),
        )
    });
    let length_offsets = std::array::from_fn(|i| {
        values.insert(
            format!("length offset {}", i + 1),
            VariableValue::Vector(DVector::from_element(1, robot.length_offsets_m[i])),
        )
    });
    CalibrationVariables {
        anchors,
        length_offsets,
    }
}

/// What every pose's factors share: the robot's slot order, the global and
/// effect variables, the cable model and the options.
struct PoseFactors<'a> {
    slots: Arc<SlotOrder>,
    globals: CalibrationVariables,
    effects: Option<EffectVariables>,
    model: CableModel,
    options: &'a CalibrationOptions,
    /// The positivity guard's minimum horizontal tension, and its sigma: 1 %
    /// of the platform's weight share per cable, newtons.
    tension_floor_n: f64,
    /// The last catenary call, read by the length, height and guard factors
    /// of the pose it was made for (the paper's model; see [`CatenaryCall`]);
    /// `None`: one memo per pose.
    catenary_memo: Option<Arc<CatenaryMemo>>,
    /// The same for the extended model's length and height factors.
    extended_memo: Arc<ExtendedMemo>,
}

impl PoseFactors<'_> {
    /// The memo of the next pose's catenary call (see [`PoseFactors::catenary_memo`]).
    fn catenary_memo(&self) -> Arc<CatenaryMemo> {
        match &self.catenary_memo {
            Some(shared) => shared.clone(),
            None => Arc::new(CatenaryMemo::default()),
        }
    }

    /// One pose's factors: the pose prior, then the cable model's factors.
    fn add(&self, graph: &mut FactorGraph, vars: PoseVariables, m: &PoseMeasurement) {
        let noise = &self.options.noise;
        let orientation_sigma = (self.options.orientation_prior == OrientationPrior::On
            || self.model == CableModel::Rigid)
            .then_some(noise.orientation_sigma_rad);
        let prior: Box<dyn Factor> = match (orientation_sigma, self.effects) {
            (Some(orientation_sigma), Some(effects)) if self.model == CableModel::Catenary => {
                Box::new(MountedPosePriorFactor::new(
                    vars.pose,
                    effects.localiser_mount,
                    &measured_pose(m),
                    noise.position_sigma_m,
                    orientation_sigma,
                    self.options.robust.pose_prior,
                ))
            }
            _ => Box::new(PosePriorFactor::new(
                vars.pose,
                &measured_pose(m),
                noise.position_sigma_m,
                orientation_sigma,
                self.options.robust.pose_prior,
            )),
        };
        // Rows `[orientation (3)]; position (3)]`, the orientation rows only with its prior.
        let orientation_rows = if orientation_sigma.is_some() { 3 } else { 0 };
        let dropped: Vec<usize> = m
            .excluded
            .iter()
            .filter_map(|sensor| match sensor {
                Sensor::Orientation(a) if orientation_rows == 3 => Some(a),
                Sensor::Position(a) => Some(orientation_rows + a),
                _ => None,
            })
            .collect();
        push_masked(graph, prior, &dropped);
        match (self.model, self.effects) {
            (CableModel::Rigid, _) => self.add_rigid(graph, vars, m),
            (CableModel::Catenary, Some(effects)) => {
                self.add_extended(graph, vars, m, effects);
                self.add_tension_guard(
                    graph,
                    TensionSource::Own {
                        slots: self.slots.clone(),
                        globals: self.globals,
                        pose: vars,
                    },
                );
            }
            (CableModel::Catenary, None) => {
                let call = CatenaryCall::new(
                    self.slots.clone(),
                    self.globals,
                    vars,
                    &m.encoder_lengths_m,
                    self.catenary_memo(),
                );
                let call = if self.catenary_memo.is_none() {
                    call.comparing_inputs()
                } else {
                    call
                };
                self.add_catenary(graph, &call, m);
                self.add_tension_guard(graph, TensionSource::Shared(call));
            }
        }
    }

    /// The straight-cable length factor; the reference tension is held fixed.
    fn add_rigid(&self, graph: &mut FactorGraph, vars: PoseVariables, m: &PoseMeasurement) {
        graph.values.set_fixed(vars.reference_tension, true);
        let lengths = RigidLengthFactor::new(
            self.slots.clone(),
            self.globals,
            vars,
            &m.encoder_lengths_m,
            self.options.noise.encoder_sigma_m,
            self.options.robust.encoder,
        );
        push_masked(graph, Box::new(lengths), &encoder_rows(m));
    }

    /// The paper's factors: catenary length (eq. 14) and attachment height
    /// (eq. 15), both from the pose's one catenary `call`, and reference tension (eq. 16).
    fn add_catenary(&self, graph: &mut FactorGraph, call: &CatenaryCall, m: &PoseMeasurement) {
        let noise = &self.options.noise;
        let lengths = CatenaryLengthFactor::new(call.clone(), noise.encoder_sigma_m, self.options.robust.encoder);
        push_masked(graph, Box::new(lengths), &encoder_rows(m));
        graph.add(AttachmentHeightFactor::new(call.clone(), self.options.height_sigma_m));
        let cell = ReferenceTensionFactor::new(
            call.reference_tension(),
            m.reference_tension_n,
            noise.load_cell_sigma_n,
            self.options.robust.load_cell,
        );
        push_masked(graph, Box::new(cell), &load_cell_rows(m));
    }

    /// The extended model's factors: length and height with the effect
    /// parameters, and the load cell with bias and gain.
    fn add_extended(
        &self,
        graph: &mut FactorGraph,
        vars: PoseVariables,
        m: &PoseMeasurement,
        effects: EffectVariables,
    ) {
        let noise = &self.options.noise;
        let lengths = ExtendedLengthFactor::new(
            self.slots.clone(),
            self.globals,
            effects,
            vars,
            &m.encoder_lengths_m,
            noise.encoder_sigma_m,
            self.options.robust.encoder,
            self.extended_memo.clone(),
        )
        .at(m.order);
        push_masked(graph, Box::new(lengths), &encoder_rows(m));
        graph.add(ExtendedHeightFactor::new(
            self.slots.clone(),
            self.globals,
            effects,
            vars,
            self.options.height_sigma_m,
            self.extended_memo.clone(),
        ));
        let cell = LoadCellFactor::new(
            vars.reference_tension,
            effects.load_cell,
            m.reference_tension_n,
            noise.load_cell_sigma_n,
            self.options.robust.load_cell,
        )
        .in_time(
            effects.load_cell_drift,
            effects.load_cell_friction,
            m.order,
            self.slots.cables[0],
        );
        push_masked(graph, Box::new(cell), &load_cell_rows(m));
    }

    /// Every cable's tension kept positive (inactive at the optimum).
    fn add_tension_guard(&self, graph: &mut FactorGraph, source: TensionSource) {
        graph.add(TensionGuardFactor::new(
            source,
            self.tension_floor_n,
            self.tension_floor_n,
        ));
    }
}

/// Add `factor` without its rows `dropped` (readings left out as gross
/// errors, [`PoseMeasurement::excluded`]); a factor with every row dropped is left out.
fn push_masked(graph: &mut FactorGraph, factor: Box<dyn Factor>, dropped: &[usize]) {
    if dropped.is_empty() {
        graph.factors.push(factor);
    } else if let Some(masked) = MaskedFactor::new(factor, dropped) {
        graph.factors.push(Box::new(masked));
    }
}

/// The length factors' rows (robot cable order) of the excluded encoders.
fn encoder_rows(m: &PoseMeasurement) -> Vec<usize> {
    (0..CABLE_COUNT)
        .filter(|i| m.excluded.contains(Sensor::Encoder(*i)))
        .collect()
}

/// The load-cell factor's row, if the reading is excluded.
fn load_cell_rows(m: &PoseMeasurement) -> Vec<usize> {
    if m.excluded.contains(Sensor::LoadCell) {
        vec![0]
    } else {
        Vec::new()
    }
}

/// The effect-parameter variables with the values of `robot.effects`, all
/// fixed except those of `free`.
fn insert_effect_variables(values: &mut Values, robot: &Robot, free: EffectSet) -> EffectVariables {
    let e = &robot.effects;
    let mut vector =
        |name: &str, data: &[f64]| values.insert(name, VariableValue::Vector(DVector::from_column_slice(data)));
    let variables = EffectVariables {
        axial_compliance: vector("axial compliance (1/MN)", &[e.axial_compliance_per_mn()]),
        pulley_radius: vector("pulley radius", &[e.pulley_radius_m]),
        encoder_gain_errors: vector("encoder gain errors", &e.encoder_gain.map(|g| g - 1.0)),
        load_cell: vector(
            "load cell bias and gain error",
            &[e.load_cell_bias_n, e.load_cell_gain - 1.0],
        ),
        com_shift: vector("centre of mass shift", &e.com_shift_m[..2]),
        inverse_segments_squared: vector("inverse segments squared", &[e.inverse_segments_squared()]),
        common_gain_error: vector("common encoder gain error", &[0.0]),
        localiser_mount: vector("localiser mount (deg)", &e.localiser_mount_deg),
        platform_weight_error: vector("platform weight error", &[e.platform_weight_scale - 1.0]),
        cable_weight_error: vector("cable weight error", &[e.cable_weight_scale - 1.0]),
        encoder_drift: vector(
            "encoder drift (mm per row)",
            &e.encoder_drift_m_per_row.map(|d| d * 1e3),
        ),
        encoder_backlash: vector("encoder backlash (mm)", &e.encoder_backlash_m.map(|b| b * 1e3)),
        load_cell_drift: vector("load cell drift (N per row)", &[e.load_cell_drift_n_per_row]),
        load_cell_friction: vector("load cell friction", &[e.load_cell_friction]),
        attachment_shift: vector(
            "attachment shifts",
            &e.attachment_shift_m.iter().flatten().copied().collect::<Vec<_>>(),
        ),
    };
    for kind in EffectKind::ALL {
        values.set_fixed(variables.of(kind), !free.contains(kind));
    }
    variables
}

/// The effects held in the graph's effect variables (the inverse of
/// `insert_effect_variables`); a compliance `<= 0` reads as an inextensible cable.
pub fn effects_from_graph(template: &Robot, built: &CalibrationGraph) -> Option<Effects> {
    let vars = built.effects?;
    let values = &built.graph.values;
    let compliance = values.vector(vars.axial_compliance)[0];
    let gains = values.vector(vars.encoder_gain_errors);
    let common = values.vector(vars.common_gain_error)[0];
    let cell = values.vector(vars.load_cell);
    let com = values.vector(vars.com_shift);
    let inverse_segments_squared = values.vector(vars.inverse_segments_squared)[0];
    Some(Effects {
        axial_stiffness_n: (compliance > 0.0).then(|| 1e6 / compliance),
        pulley_radius_m: values.vector(vars.pulley_radius)[0],
        encoder_gain: std::array::from_fn(|i| 1.0 + gains[i] + common),
        load_cell_bias_n: cell[0],
        load_cell_gain: 1.0 + cell[1],
        com_shift_m: [com[0], com[1], template.effects.com_shift_m[2]],
        cable_segments: (inverse_segments_squared > 0.0).then(|| 1.0 / inverse_segments_squared.sqrt()),
        localiser_mount_deg: std::array::from_fn(|i| values.vector(vars.localiser_mount)[i]),
        platform_weight_scale: 1.0 + values.vector(vars.platform_weight_error)[0],
        cable_weight_scale: 1.0 + values.vector(vars.cable_weight_error)[0],
        encoder_drift_m_per_row: std::array::from_fn(|i| values.vector(vars.encoder_drift)[i] * 1e-3),
        encoder_backlash_m: std::array::from_fn(|i| values.vector(vars.encoder_backlash)[i] * 1e-3),
        load_cell_drift_n_per_row: values.vector(vars.load_cell_drift)[0],
        load_cell_friction: values.vector(vars.load_cell_friction)[0],
        attachment_shift_m: {
            let shift = values.vector(vars.attachment_shift);
            std::array::from_fn(|i| [shift[2 * i], shift[2 * i + 1]])
        },
    })
}

/// The robot with the graph's current anchors and offsets.
pub fn robot_from_graph(template: &Robot, built: &CalibrationGraph) -> Robot {
    let mut robot = template.clone();
    for i in 0..CABLE_COUNT {
        let a = built.graph.values.vector(built.globals.anchors[i]);
        robot.anchors_m[i] = Vector3::new(a[0], a[1], a[2]);
        robot.length_offsets_m[i] = built.graph.values.vector(built.globals.length_offsets[i])[0];
    }
    if let Some(effects) = effects_from_graph(template, built) {
        robot.effects = effects;
    }
    robot
}

//! The apex-solver peer (issue 5): apex-solver 1.5's sparse Levenberg-Marquardt
//! on the benchmark problem of [`sagcal::experiments::benchmark`].
//!
//! **Problem.** Built from [`BenchmarkProblem::graph`], factor by factor: its
//! factor list, variable connectivity and per-row sigmas are read from the
//! sagcal graph itself; the constants a factor keeps privately (encoder
//! readings, load-cell reading, prior pose, robot constants) are taken from
//! the same measurements and robot the graph was built from. Every apex factor
//! calls the same SymForce-generated residual with its analytic Jacobians
//! (`sagcal::generated::{catenary_length_residual, attachment_height_residual,
//! reference_tension_residual, pose_prior_residual}`), with the slot order
//! (reference cable first) and the robot-order rows of sagcal's factor
//! wrappers; the residual is not whitened inside the factor but by apex's
//! diagonal `NoiseModel::from_sigmas(factor.sigmas())`, and no loss function is
//! attached (the benchmark has no robust kernels; any other factor kind, a
//! robust kernel, a fixed variable or the extended effect model is an error).
//! The tests check every factor's residual and Jacobian against sagcal's
//! `Factor::evaluate` and apex's costs against sagcal's `FactorGraph::cost`.
//!
//! **Variables and the pose tangent.** sagcal's pose retracts as
//! `(R Exp(dtheta), p + dp)` with tangent `[dtheta, dp]` (right perturbation of
//! the rotation, position additive in the world frame). apex's `SE3` retracts
//! as `X Exp(xi)`, which moves the translation in the body frame and couples it
//! to the rotation, so it is not used. Each pose is instead two apex variables,
//! an `SO3` (parameters `[qw, qx, qy, qz]`, `plus = R * Exp(dtheta)`, apex's
//! `right_plus`) and an `Rn` of dimension 3 (`plus = p + dp`). Their product is
//! exactly sagcal's retraction, so the generated pose Jacobian needs no
//! conversion: its columns 0..3 are the `SO3` block and 3..6 the position
//! block. This is checked numerically (test `jacobians_match_central_differences_through_apex_retraction`:
//! central differences with every variable moved by apex's own
//! `ManifoldVariable::apply_tangent_step`). Anchors (R^3), length offsets
//! (R^1) and reference tensions (R^2) are `Rn` variables.
//!
//! **Cost convention.** apex's cost is `sum 1/2 |S r|^2` with `S = diag(1/sigma)`
//! here, i.e. already sagcal's `sum 1/2 |r / sigma|^2`: `reported_final_cost`
//! is apex's `final_cost` unchanged.
//!
//! **Stopping rule** ([`BenchmarkProblem::stopping`]) mapped to
//! `LevenbergMarquardtConfig`, and what differs:
//!
//! | sagcal | apex | note |
//! | --- | --- | --- |
//! | at most 100 linearisations | `max_iterations = 99` | apex counts from 0 and tests `iteration >= max_iterations` after the step, so 99 allows 100 linearisations. But apex spends one iteration (and one full re-linearisation at the unchanged point) on every *rejected* step, where sagcal re-solves inside one iteration; its budget therefore counts trial steps, not accepted ones. |
//! | stop when an accepted step lowers the cost by less than 1e-10 of the cost before it | `cost_tolerance = 1e-10` | same formula (`|c - c_new| / max(c, 1e-10)`), but apex skips the test on its first iteration. |
//! | stop when `|J^T r|_inf < 1e-10` (checked before each step, at the current point) | `gradient_tolerance = 1e-10` | apex tests the Euclidean norm `|J^T r|_2` (stricter) of the linearisation the accepted step was taken from, i.e. one step later. |
//! | stop when `|dx| < 1e-12 (1 + |x|)`, `|x|` over vector variables and pose positions | `parameter_tolerance = 1e-12` | apex: `|dx| <= 1e-12 (|x| + 1e-12)` with `|x|` over all stored parameters, which adds the quaternions (1 per pose to `|x|^2`) and drops sagcal's `1 +`. |
//! | initial damping (sagcal's default, 1e-10), Nielsen update (`lambda *= max(1/3, 1 - (2 rho - 1)^3)`, `nu` doubling on rejection), lambda >= 1e-15 | `damping` = the same value, `DampingUpdate::Nielsen`, `damping_nu = 2`, `damping_min = 1e-15` | identical. |
//! | damping matrix `lambda clamp(diag(J^T J), 1e-6, 1e32)` | `min_diagonal = 1e-6`, `max_diagonal = 1e32`, no Jacobi scaling | identical. |
//! | accept a step iff the cost decreases and the predicted decrease is positive | `min_relative_decrease = 0` (accept iff `rho > 0`) | identical up to apex's 1e-15 guard on the predicted decrease. |
//! | give up when lambda exceeds 1e16 without an acceptable step | `damping_max = 1e16`, `max_consecutive_rejected_steps = 1` | apex stops after a rejection that leaves lambda at its cap (its lambda is clamped to 1e16). |
//!
//! The linear solver is apex's default `SparseCholesky`: faer's sparse LLT of
//! `J^T J + lambda D` with faer's default (AMD) ordering, symbolic
//! factorisation cached, like sagcal's own faer sparse Cholesky; no Schur
//! elimination on either side. (apex forms `J^T J` from an assembled sparse
//! `J` with faer's sparse product; sagcal accumulates `J^T J` block-wise.)
//!
//! **Single thread.** apex parallelises residual/Jacobian assembly with rayon
//! and forms `J^T J` with faer's rayon-parallel kernels (`Par::global()`,
//! `Rayon(current_num_threads)`). The solve runs inside a one-thread rayon
//! pool (`ThreadPoolBuilder::new().num_threads(1)`), where every parallel
//! iterator and faer's `Par::rayon(0)` see one thread.
//!
//! **Timing.** `setup_seconds`: building the sagcal graph, translating it and
//! building apex's `Problem` (its symbolic structure and initial cost are
//! computed inside `optimize` and so belong to `solve_seconds`).
//! `solve_seconds`: the `LevenbergMarquardt::optimize` call alone (pool
//! creation excluded). `iterations`: apex's Jacobian evaluations (=
//! linearisations; equal to its `iterations`, rejected steps included).

use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

use apex_solver::core::problem::Problem;
use apex_solver::core::VarKey;
use apex_solver::factors::Factor as ApexFactor;
use apex_solver::linalg::{JacobianMode, LinearSolverType};
use apex_solver::optimizer::levenberg_marquardt::{DampingUpdate, LevenbergMarquardt, LevenbergMarquardtConfig};
use apex_solver::{ManifoldType, NoiseModel};
use faer::mat::MatMut;
use nalgebra::{Quaternion, SMatrix, UnitQuaternion, Vector2, Vector3, Vector4};

use sagcal::experiments::benchmark::BenchmarkProblem;
use sagcal::calib::factors::{SlotOrder, EPSILON};
use sagcal::calib::CalibrationGraph;
use sagcal::generated;
use sagcal::graph::{Factor as SagcalFactor, RobustKernel, VariableId, VariableValue};
use sagcal::model::pose::PlatformPose;
use sagcal::model::robot::CABLE_COUNT;

use crate::common::{PeerRun, Solution};

/// Solve `problem` with apex-solver's Levenberg-Marquardt (see the module docs).
/// `max_iterations`: sagcal's linearisation budget (the benchmark's is
/// [`BenchmarkProblem::stopping`]'s; a smaller one for the instruction counts).
pub fn solve(problem: &BenchmarkProblem, max_iterations: usize) -> Result<PeerRun, String> {
    run(problem, max_iterations).map(|(run, _)| run)
}

/// What apex reports besides the [`PeerRun`] (read by the tests).
#[derive(Debug, Clone)]
#[cfg_attr(not(test), allow(dead_code))]
struct ApexReport {
    /// apex's cost at the initial values (sagcal's convention).
    initial_cost: f64,
    /// apex's termination status.
    status: String,
}

fn run(problem: &BenchmarkProblem, max_iterations: usize) -> Result<(PeerRun, ApexReport), String> {
    let setup_start = Instant::now();
    let built = problem.graph();
    let apex = ApexProblem::new(problem, &built)?;
    let mut apex_problem = apex.problem;
    let mut lm = LevenbergMarquardt::with_config(lm_config(max_iterations));
    let setup_seconds = setup_start.elapsed().as_secs_f64();

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| format!("apex: cannot build a one-thread rayon pool: {e}"))?;
    let (result, solve_seconds) = pool.install(|| {
        let start = Instant::now();
        let result = lm.optimize(&mut apex_problem);
        (result, start.elapsed().as_secs_f64())
    });
    let result = result.map_err(|e| format!("apex: optimize failed: {e}"))?;

    let read = |key: VarKey| -> Result<&[f64], String> {
        result
            .parameters
            .get(key)
            .map(|v| v.as_param_slice())
            .ok_or_else(|| "apex: a variable is missing from the result".to_string())
    };
    let vector = |id: VariableId| -> Result<&[f64], String> {
        match apex.keys.get(&id) {
            Some(Keys::Vector(key)) => read(*key),
            _ => Err(format!("apex: variable {} is not a vector", id.0)),
        }
    };
    let mut anchors_m = [[0.0; 3]; CABLE_COUNT];
    let mut length_offsets_m = [0.0; CABLE_COUNT];
    for i in 0..CABLE_COUNT {
        let a = vector(built.globals.anchors[i])?;
        anchors_m[i] = [a[0], a[1], a[2]];
        length_offsets_m[i] = vector(built.globals.length_offsets[i])?[0];
    }
    let mut poses = Vec::with_capacity(built.poses.len());
    let mut reference_tensions_n = Vec::with_capacity(built.poses.len());
    for vars in &built.poses {
        let Some(Keys::Pose { rotation, position }) = apex.keys.get(&vars.pose) else {
            return Err("apex: a pose variable has no rotation/position keys".into());
        };
        poses.push(pose_from_params(read(*rotation)?, read(*position)?));
        let t = vector(vars.reference_tension)?;
        reference_tensions_n.push([t[0], t[1]]);
    }
    let iterations = result
        .convergence_info
        .as_ref()
        .map_or(result.iterations, |info| info.jacobian_evaluations);
    let report = ApexReport {
        initial_cost: result.initial_cost,
        status: result.status.to_string(),
    };
    let run = PeerRun {
        reported_final_cost: result.final_cost,
        iterations,
        solve_seconds,
        setup_seconds,
        solution: Solution {
            anchors_m,
            length_offsets_m,
            poses,
            reference_tensions_n,
        },
    };
    Ok((run, report))
}

/// The stopping rule of [`BenchmarkProblem::stopping`] as apex's LM options (table in the module docs).
fn lm_config(max_iterations: usize) -> LevenbergMarquardtConfig {
    let stopping = BenchmarkProblem::stopping();
    let mut config = LevenbergMarquardtConfig::new()
        .with_linear_solver_type(LinearSolverType::SparseCholesky)
        .with_max_iterations(max_iterations.max(1) - 1)
        .with_cost_tolerance(stopping.relative_cost_tolerance)
        .with_gradient_tolerance(stopping.gradient_tolerance)
        .with_parameter_tolerance(stopping.relative_step_tolerance)
        .with_damping(stopping.initial_damping)
        .with_damping_bounds(1e-15, stopping.max_damping)
        .with_damping_update(DampingUpdate::Nielsen)
        .with_diagonal_bounds(1e-6, 1e32)
        .with_min_relative_decrease(0.0)
        .with_jacobi_scaling(false)
        .with_compute_covariances(false);
    config.damping_nu = 2.0;
    config.max_consecutive_rejected_steps = 1;
    config.timeout = None;
    config.min_cost_threshold = None;
    config.max_condition_number = None;
    config
}

/// The apex variables of one sagcal variable.
#[derive(Debug, Clone, Copy)]
enum Keys {
    /// A platform pose: an `SO3` and an `Rn(3)`.
    Pose { rotation: VarKey, position: VarKey },
    /// A Euclidean vector: one `Rn`.
    Vector(VarKey),
}

/// Which part of a sagcal variable an apex factor argument is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Arg {
    /// The rotation of a pose, apex parameters `[qw, qx, qy, qz]`.
    Rotation(VariableId),
    /// The position of a pose, metres.
    Position(VariableId),
    /// A vector variable.
    Vector(VariableId),
}

/// The benchmark graph as an apex `Problem`, with the sagcal-to-apex variable map.
struct ApexProblem {
    problem: Problem,
    keys: HashMap<VariableId, Keys>,
}

impl ApexProblem {
    fn new(problem: &BenchmarkProblem, built: &CalibrationGraph) -> Result<Self, String> {
        let mut apex = Problem::new(JacobianMode::Sparse);
        let mut keys = HashMap::with_capacity(built.graph.values.len());
        for (id, variable) in built.graph.values.iter() {
            if variable.fixed {
                return Err(format!("apex: fixed variable `{}` not supported", variable.name));
            }
            let entry = match &variable.value {
                VariableValue::Pose(pose) => {
                    let (rotation, position) = pose_params(pose);
                    Keys::Pose {
                        rotation: apex.add_variable(ManifoldType::SO3, rotation.to_vec().into()),
                        position: apex.add_variable(ManifoldType::RN, position.to_vec().into()),
                    }
                }
                VariableValue::Vector(v) => {
                    Keys::Vector(apex.add_variable(ManifoldType::RN, v.as_slice().to_vec().into()))
                }
            };
            keys.insert(id, entry);
        }
        let translator = Translator::new(problem, built)?;
        for factor in &built.graph.factors {
            let translated = translator.translate(factor.as_ref())?;
            let variable_keys = translated
                .args
                .iter()
                .map(|arg| match (arg, keys.get(&arg.id())) {
                    (Arg::Rotation(_), Some(Keys::Pose { rotation, .. })) => Ok(*rotation),
                    (Arg::Position(_), Some(Keys::Pose { position, .. })) => Ok(*position),
                    (Arg::Vector(_), Some(Keys::Vector(key))) => Ok(*key),
                    _ => Err(format!("apex: {} factor: variable kind mismatch", factor.kind())),
                })
                .collect::<Result<Vec<_>, _>>()?;
            let noise = NoiseModel::from_sigmas(factor.sigmas().as_slice())
                .map_err(|e| format!("apex: {} factor sigmas: {e}", factor.kind()))?;
            apex.try_add_residual_block_with_noise(&variable_keys, translated.factor, None, noise)
                .map_err(|e| format!("apex: {} factor: {e}", factor.kind()))?;
        }
        Ok(Self { problem: apex, keys })
    }
}

impl Arg {
    fn id(&self) -> VariableId {
        match *self {
            Arg::Rotation(id) | Arg::Position(id) | Arg::Vector(id) => id,
        }
    }
}

/// One sagcal factor as an apex factor, and the apex arguments it reads, in order.
struct Translated {
    factor: Box<dyn ApexFactor + Send + Sync>,
    args: Vec<Arg>,
}

/// Turns the benchmark graph's factors into apex factors.
struct Translator<'a> {
    problem: &'a BenchmarkProblem,
    built: &'a CalibrationGraph,
    slots: Arc<SlotOrder>,
    /// Pose and reference-tension variable -> measurement index.
    pose_index: HashMap<VariableId, usize>,
}

impl<'a> Translator<'a> {
    fn new(problem: &'a BenchmarkProblem, built: &'a CalibrationGraph) -> Result<Self, String> {
        if built.effects.is_some() {
            return Err("apex: the extended effect model is not supported".into());
        }
        if built.poses.len() != problem.measurements.len() {
            return Err("apex: graph poses and measurements differ in number".into());
        }
        let mut pose_index = HashMap::with_capacity(2 * built.poses.len());
        for (k, vars) in built.poses.iter().enumerate() {
            pose_index.insert(vars.pose, k);
            pose_index.insert(vars.reference_tension, k);
        }
        Ok(Self {
            problem,
            built,
            // As `build_graph(&problem.initial, ...)` (no effects: no centre-of-mass shift).
            slots: Arc::new(SlotOrder::new(&problem.initial)),
            pose_index,
        })
    }

    fn translate(&self, factor: &dyn SagcalFactor) -> Result<Translated, String> {
        let kind = factor.kind();
        if factor.robust_kernel() != RobustKernel::None {
            return Err(format!("apex: {kind} factor has a robust kernel (not supported)"));
        }
        let vars = factor.variables();
        let k = *vars
            .first()
            .and_then(|v| self.pose_index.get(v))
            .ok_or_else(|| format!("apex: {kind} factor does not start with a pose variable"))?;
        let pv = self.built.poses[k];
        let g = &self.built.globals;
        let m = &self.problem.measurements[k];
        let expect = |list: Vec<VariableId>| -> Result<(), String> {
            if vars == list.as_slice() {
                Ok(())
            } else {
                Err(format!("apex: {kind} factor of pose {k}: unexpected variables"))
            }
        };
        let pose_args = [Arg::Rotation(pv.pose), Arg::Position(pv.pose)];
        let cable_args = |with_offsets: bool| -> Vec<Arg> {
            let mut args = pose_args.to_vec();
            args.push(Arg::Vector(pv.reference_tension));
            args.extend(g.anchors.iter().map(|&a| Arg::Vector(a)));
            if with_offsets {
                args.extend(g.length_offsets.iter().map(|&o| Arg::Vector(o)));
            }
            args
        };
        let cable_vars = |with_offsets: bool| -> Vec<VariableId> {
            let mut list = vec![pv.pose, pv.reference_tension];
            list.extend(g.anchors);
            if with_offsets {
                list.extend(g.length_offsets);
            }
            list
        };
        let translated = match kind {
            "catenary_length" => {
                expect(cable_vars(true))?;
                Translated {
                    factor: Box::new(CatenaryLength {
                        slots: self.slots.clone(),
                        encoder_lengths_m: self.slots.to_slots(&m.encoder_lengths_m),
                    }),
                    args: cable_args(true),
                }
            }
            "attachment_height" => {
                expect(cable_vars(false))?;
                Translated {
                    factor: Box::new(AttachmentHeight {
                        slots: self.slots.clone(),
                    }),
                    args: cable_args(false),
                }
            }
            "reference_tension" => {
                expect(vec![pv.reference_tension])?;
                Translated {
                    factor: Box::new(ReferenceTension {
                        measured_tension_n: m.reference_tension_n,
                    }),
                    args: vec![Arg::Vector(pv.reference_tension)],
                }
            }
            "pose_prior" => {
                expect(vec![pv.pose])?;
                // As `calib::measured_pose`.
                let prior = PlatformPose::from_roll_pitch_yaw_deg(
                    Vector3::from(m.position_m),
                    m.roll_deg,
                    m.pitch_deg,
                    m.yaw_deg,
                );
                let with_orientation = match factor.residual_dim() {
                    6 => true,
                    3 => false,
                    n => return Err(format!("apex: pose prior with {n} rows")),
                };
                Translated {
                    factor: Box::new(PosePrior {
                        prior_position_m: prior.position_m,
                        prior_rotation_xyzw: prior.rotation_xyzw(),
                        with_orientation,
                    }),
                    args: pose_args.to_vec(),
                }
            }
            other => return Err(format!("apex: factor kind `{other}` not supported")),
        };
        if translated.factor.residual_dim() != factor.residual_dim() {
            return Err(format!("apex: {kind} factor: residual dimension mismatch"));
        }
        Ok(translated)
    }
}

/// apex parameters of a pose: `SO3` `[qw, qx, qy, qz]` and position.
fn pose_params(pose: &PlatformPose) -> ([f64; 4], [f64; 3]) {
    let q = pose.rotation.quaternion();
    let p = pose.position_m;
    ([q.w, q.i, q.j, q.k], [p.x, p.y, p.z])
}

/// A pose from apex parameters, the quaternion taken as is (apex keeps it normalised).
fn pose_from_params(rotation: &[f64], position: &[f64]) -> PlatformPose {
    PlatformPose::new(
        Vector3::new(position[0], position[1], position[2]),
        UnitQuaternion::new_unchecked(Quaternion::new(rotation[0], rotation[1], rotation[2], rotation[3])),
    )
}

/// apex `SO3` parameters `[qw, qx, qy, qz]` as the generated code's `[x, y, z, w]`.
fn rotation_xyzw(p: &[f64]) -> Vector4<f64> {
    Vector4::new(p[1], p[2], p[3], p[0])
}

fn vector3(p: &[f64]) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

/// Anchors in slot order from the four anchor arguments (robot order).
fn gather_anchors(slots: &SlotOrder, anchors: &[&[f64]]) -> SMatrix<f64, 3, 4> {
    let mut out = SMatrix::<f64, 3, 4>::zeros();
    for (slot, &cable) in slots.cables.iter().enumerate() {
        out.set_column(slot, &vector3(anchors[cable]));
    }
    out
}

/// Catenary length factor (sagcal's `CatenaryLengthFactor`). Arguments:
/// rotation, position, reference tension, anchors 1..4, offsets 1..4 (24
/// columns); rows in robot cable order.
struct CatenaryLength {
    slots: Arc<SlotOrder>,
    /// Encoder readings, slot order.
    encoder_lengths_m: Vector4<f64>,
}

impl ApexFactor for CatenaryLength {
    fn linearize(&self, params: &[&[f64]], residual: &mut [f64], jacobian: Option<MatMut<'_, f64>>) {
        let s = &*self.slots;
        let rotation = rotation_xyzw(params[0]);
        let position = vector3(params[1]);
        let tension = Vector2::new(params[2][0], params[2][1]);
        let anchors = gather_anchors(s, &params[3..7]);
        let offsets = Vector4::from_fn(|slot, _| params[7 + s.cables[slot]][0]);
        let mut j_pose = SMatrix::<f64, 4, 6>::zeros();
        let mut j_tension = SMatrix::<f64, 4, 2>::zeros();
        let mut j_anchors = SMatrix::<f64, 4, 12>::zeros();
        let mut j_offsets = SMatrix::<f64, 4, 4>::zeros();
        let want = jacobian.is_some();
        let r = generated::catenary_length_residual(
            &position,
            &rotation,
            &tension,
            &anchors,
            &s.attachments_m,
            &s.com_offset_m,
            s.platform_weight_n,
            s.cable_weight_n_per_m,
            &offsets,
            &self.encoder_lengths_m,
            EPSILON,
            want.then_some(&mut j_pose),
            want.then_some(&mut j_tension),
            want.then_some(&mut j_anchors),
            want.then_some(&mut j_offsets),
        );
        for (slot, &row) in s.cables.iter().enumerate() {
            residual[row] = r[slot];
        }
        if let Some(mut j) = jacobian {
            for (slot, &row) in s.cables.iter().enumerate() {
                for c in 0..6 {
                    j[(row, c)] = j_pose[(slot, c)];
                }
                for c in 0..2 {
                    j[(row, 6 + c)] = j_tension[(slot, c)];
                }
                for (anchor_slot, &cable) in s.cables.iter().enumerate() {
                    for d in 0..3 {
                        j[(row, 8 + 3 * cable + d)] = j_anchors[(slot, 3 * anchor_slot + d)];
                    }
                    j[(row, 20 + cable)] = j_offsets[(slot, anchor_slot)];
                }
            }
        }
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    fn jacobian_shape(&self) -> (usize, usize) {
        (CABLE_COUNT, 24)
    }
}

/// Attachment height factor (sagcal's `AttachmentHeightFactor`). Arguments:
/// rotation, position, reference tension, anchors 1..4 (20 columns); rows in
/// robot cable order.
struct AttachmentHeight {
    slots: Arc<SlotOrder>,
}

impl ApexFactor for AttachmentHeight {
    fn linearize(&self, params: &[&[f64]], residual: &mut [f64], jacobian: Option<MatMut<'_, f64>>) {
        let s = &*self.slots;
        let rotation = rotation_xyzw(params[0]);
        let position = vector3(params[1]);
        let tension = Vector2::new(params[2][0], params[2][1]);
        let anchors = gather_anchors(s, &params[3..7]);
        let mut j_pose = SMatrix::<f64, 4, 6>::zeros();
        let mut j_tension = SMatrix::<f64, 4, 2>::zeros();
        let mut j_anchors = SMatrix::<f64, 4, 12>::zeros();
        let want = jacobian.is_some();
        let r = generated::attachment_height_residual(
            &position,
            &rotation,
            &tension,
            &anchors,
            &s.attachments_m,
            &s.com_offset_m,
            s.platform_weight_n,
            s.cable_weight_n_per_m,
            EPSILON,
            want.then_some(&mut j_pose),
            want.then_some(&mut j_tension),
            want.then_some(&mut j_anchors),
        );
        for (slot, &row) in s.cables.iter().enumerate() {
            residual[row] = r[slot];
        }
        if let Some(mut j) = jacobian {
            for (slot, &row) in s.cables.iter().enumerate() {
                for c in 0..6 {
                    j[(row, c)] = j_pose[(slot, c)];
                }
                for c in 0..2 {
                    j[(row, 6 + c)] = j_tension[(slot, c)];
                }
                for (anchor_slot, &cable) in s.cables.iter().enumerate() {
                    for d in 0..3 {
                        j[(row, 8 + 3 * cable + d)] = j_anchors[(slot, 3 * anchor_slot + d)];
                    }
                }
            }
        }
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    fn jacobian_shape(&self) -> (usize, usize) {
        (CABLE_COUNT, 20)
    }
}

/// Load-cell factor (sagcal's `ReferenceTensionFactor`). Argument: reference tension.
struct ReferenceTension {
    measured_tension_n: f64,
}

impl ApexFactor for ReferenceTension {
    fn linearize(&self, params: &[&[f64]], residual: &mut [f64], jacobian: Option<MatMut<'_, f64>>) {
        let tension = Vector2::new(params[0][0], params[0][1]);
        let mut j_tension = SMatrix::<f64, 1, 2>::zeros();
        let want = jacobian.is_some();
        let r = generated::reference_tension_residual(
            &tension,
            self.measured_tension_n,
            EPSILON,
            want.then_some(&mut j_tension),
        );
        residual[0] = r[0];
        if let Some(mut j) = jacobian {
            j[(0, 0)] = j_tension[(0, 0)];
            j[(0, 1)] = j_tension[(0, 1)];
        }
    }
    fn residual_dim(&self) -> usize {
        1
    }
    fn jacobian_shape(&self) -> (usize, usize) {
        (1, 2)
    }
}

/// Pose prior (sagcal's `PosePriorFactor`). Arguments: rotation, position (6
/// columns); rows `[rotation (3), position (3)]`, or the position rows only.
struct PosePrior {
    prior_position_m: Vector3<f64>,
    prior_rotation_xyzw: Vector4<f64>,
    with_orientation: bool,
}

impl ApexFactor for PosePrior {
    fn linearize(&self, params: &[&[f64]], residual: &mut [f64], jacobian: Option<MatMut<'_, f64>>) {
        let rotation = rotation_xyzw(params[0]);
        let position = vector3(params[1]);
        let mut j_pose = SMatrix::<f64, 6, 6>::zeros();
        let want = jacobian.is_some();
        let r = generated::pose_prior_residual(
            &position,
            &rotation,
            &self.prior_position_m,
            &self.prior_rotation_xyzw,
            EPSILON,
            want.then_some(&mut j_pose),
        );
        let first = if self.with_orientation { 0 } else { 3 };
        for row in 0..6 - first {
            residual[row] = r[first + row];
        }
        if let Some(mut j) = jacobian {
            for row in 0..6 - first {
                for c in 0..6 {
                    j[(row, c)] = j_pose[(first + row, c)];
                }
            }
        }
    }
    fn residual_dim(&self) -> usize {
        if self.with_orientation {
            6
        } else {
            3
        }
    }
    fn jacobian_shape(&self) -> (usize, usize) {
        (self.residual_dim(), 6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::common::solution_values;
    use apex_solver::apex_manifolds::{rn::Rn, so3::SO3, LieGroup};
    use apex_solver::core::variable::{ManifoldVariable, Variable};
    use nalgebra::DMatrix;
    use sagcal::graph::Values;

    /// The apex parameters of argument `arg` at sagcal `values`.
    fn arg_params(values: &Values, arg: Arg) -> Vec<f64> {
        match arg {
            Arg::Rotation(id) => pose_params(values.pose(id)).0.to_vec(),
            Arg::Position(id) => pose_params(values.pose(id)).1.to_vec(),
            Arg::Vector(id) => values.vector(id).as_slice().to_vec(),
        }
    }

    /// An apex variable holding `params` of `arg`'s manifold.
    fn apex_variable(arg: Arg, params: &[f64]) -> Box<dyn ManifoldVariable> {
        match arg {
            Arg::Rotation(_) => Box::new(Variable::new(SO3::from_param_slice(params))),
            Arg::Position(_) | Arg::Vector(_) => Box::new(Variable::new(Rn::from_param_slice(params))),
        }
    }

    fn tangent_dim(arg: Arg, params: &[f64]) -> usize {
        match arg {
            Arg::Rotation(_) => 3,
            _ => params.len(),
        }
    }

    /// Residual and (column-major) Jacobian of an apex factor at `params`.
    fn linearize(factor: &dyn ApexFactor, params: &[Vec<f64>]) -> (Vec<f64>, DMatrix<f64>) {
        let slices: Vec<&[f64]> = params.iter().map(|p| p.as_slice()).collect();
        let (rows, cols) = factor.jacobian_shape();
        let mut residual = vec![f64::NAN; rows];
        let mut buffer = vec![f64::NAN; rows * cols];
        factor.linearize(
            &slices,
            &mut residual,
            Some(MatMut::from_column_major_slice_mut(&mut buffer, rows, cols)),
        );
        let mut plain = vec![f64::NAN; rows];
        factor.linearize(&slices, &mut plain, None);
        assert_eq!(residual, plain, "residual with and without Jacobian");
        (residual, DMatrix::from_column_slice(rows, cols, &buffer))
    }

    fn problem(poses: usize) -> BenchmarkProblem {
        BenchmarkProblem::new(poses, 7).expect("benchmark problem")
    }

    /// Every translated factor gives sagcal's residual and Jacobian, column for
    /// column (sagcal's pose block `[dtheta, dp]` = apex's `SO3` then `Rn(3)` block).
    #[test]
    fn factors_match_sagcal_evaluate() {
        let p = problem(6);
        let built = p.graph();
        let translator = Translator::new(&p, &built).unwrap();
        let values = &built.graph.values;
        let mut kinds = HashMap::new();
        for factor in &built.graph.factors {
            *kinds.entry(factor.kind()).or_insert(0) += 1;
            let t = translator.translate(factor.as_ref()).unwrap();
            let params: Vec<Vec<f64>> = t.args.iter().map(|&a| arg_params(values, a)).collect();
            let (residual, jacobian) = linearize(t.factor.as_ref(), &params);
            let rows = factor.residual_dim();
            let mut blocks: Vec<DMatrix<f64>> = factor
                .variables()
                .iter()
                .map(|&v| DMatrix::zeros(rows, values.tangent_dim(v)))
                .collect();
            let expected = factor.evaluate(values, Some(&mut blocks)).unwrap();
            assert_eq!(residual.as_slice(), expected.as_slice(), "{} residual", factor.kind());
            // sagcal's blocks side by side are apex's columns in the same order
            // (a pose block of 6 = the SO3 block and the Rn(3) block).
            let sagcal_jacobian = DMatrix::from_fn(rows, jacobian.ncols(), |r, c| {
                let mut c = c;
                for b in &blocks {
                    if c < b.ncols() {
                        return b[(r, c)];
                    }
                    c -= b.ncols();
                }
                f64::NAN
            });
            assert_eq!(jacobian, sagcal_jacobian, "{} Jacobian", factor.kind());
        }
        assert_eq!(kinds.len(), 4, "{kinds:?}");
        assert!(kinds.values().all(|&n| n == 6), "{kinds:?}");
    }

    /// The analytic Jacobians are the derivatives along apex's own retraction:
    /// central differences with every argument moved by
    /// `ManifoldVariable::apply_tangent_step` (`SO3`: `R Exp(d)`; `Rn`: `x + d`).
    #[test]
    fn jacobians_match_central_differences_through_apex_retraction() {
        let p = problem(3);
        let built = p.graph();
        let translator = Translator::new(&p, &built).unwrap();
        let values = &built.graph.values;
        let mut worst: f64 = 0.0;
        let mut worst_left: f64 = 0.0;
        for factor in &built.graph.factors {
            let t = translator.translate(factor.as_ref()).unwrap();
            let params: Vec<Vec<f64>> = t.args.iter().map(|&a| arg_params(values, a)).collect();
            let (_, jacobian) = linearize(t.factor.as_ref(), &params);
            let mut column = 0;
            for (i, &arg) in t.args.iter().enumerate() {
                let dim = tangent_dim(arg, &params[i]);
                // Step sizes by the argument's scale: radians, metres, newtons.
                let h = match arg {
                    Arg::Vector(id) if built.poses.iter().any(|v| v.reference_tension == id) => 1e-4,
                    _ => 1e-6,
                };
                for d in 0..dim {
                    let moved = |sign: f64| {
                        let mut var = apex_variable(arg, &params[i]);
                        let mut step = vec![0.0; dim];
                        step[d] = sign * h;
                        var.apply_tangent_step(&step);
                        let mut moved = params.clone();
                        moved[i] = var.as_param_slice().to_vec();
                        linearize(t.factor.as_ref(), &moved).0
                    };
                    let (plus, minus) = (moved(1.0), moved(-1.0));
                    if let Arg::Rotation(_) = arg {
                        // Negative control: a left perturbation `Exp(d) R` (not
                        // apex's retraction) must not match the analytic columns.
                        let left = |sign: f64| {
                            let q = &params[i];
                            let rotation = UnitQuaternion::new_unchecked(Quaternion::new(q[0], q[1], q[2], q[3]));
                            let mut axis = Vector3::zeros();
                            axis[d] = sign * h;
                            let moved_rotation = UnitQuaternion::from_scaled_axis(axis) * rotation;
                            let mut moved = params.clone();
                            moved[i] = pose_params(&PlatformPose::new(Vector3::zeros(), moved_rotation))
                                .0
                                .to_vec();
                            linearize(t.factor.as_ref(), &moved).0
                        };
                        let (plus, minus) = (left(1.0), left(-1.0));
                        for r in 0..jacobian.nrows() {
                            let fd = (plus[r] - minus[r]) / (2.0 * h);
                            let analytic = jacobian[(r, column + d)];
                            worst_left = worst_left.max((fd - analytic).abs() / (1.0 + analytic.abs()));
                        }
                    }
                    for r in 0..jacobian.nrows() {
                        let fd = (plus[r] - minus[r]) / (2.0 * h);
                        let analytic = jacobian[(r, column + d)];
                        let error = (fd - analytic).abs() / (1.0 + analytic.abs());
                        worst = worst.max(error);
                        assert!(
                            error < 1e-5,
                            "{} row {r} column {} ({arg:?}): analytic {analytic:e} vs central difference {fd:e}",
                            factor.kind(),
                            column + d
                        );
                    }
                }
                column += dim;
            }
            assert_eq!(column, jacobian.ncols());
        }
        eprintln!(
            "largest relative Jacobian error against central differences: {worst:.2e} \
             (through a left rotation perturbation instead: {worst_left:.2e})"
        );
        assert!(worst_left > 1e-3, "the check cannot tell left from right perturbations");
    }

    /// At 35 poses: apex's initial and final costs equal sagcal's cost of the
    /// same values (identical residuals and weights), and apex's final cost
    /// agrees with sagcal's own Levenberg-Marquardt.
    #[test]
    fn apex_matches_sagcal_at_35_poses() {
        let p = problem(35);
        let built = p.graph();
        let initial_sagcal = built.graph.cost(&built.graph.values).unwrap();
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        let (run, report) = run(&p, BenchmarkProblem::stopping().max_iterations).unwrap();
        eprintln!(
            "initial cost: apex {:.15e}, sagcal {initial_sagcal:.15e} (relative difference {:.1e}); apex stopped: {}",
            report.initial_cost,
            rel(report.initial_cost, initial_sagcal),
            report.status
        );
        assert!(rel(report.initial_cost, initial_sagcal) < 1e-12);
        let values = solution_values(&built, &run.solution);
        let at_solution = built.graph.cost(&values).unwrap();
        eprintln!(
            "apex: reported final cost {:.15e}, sagcal's cost at apex's solution {at_solution:.15e} \
             (relative difference {:.1e}); {} iterations, solve {:.4} s, setup {:.4} s",
            run.reported_final_cost,
            rel(run.reported_final_cost, at_solution),
            run.iterations,
            run.solve_seconds,
            run.setup_seconds
        );
        assert!(rel(run.reported_final_cost, at_solution) < 1e-12);

        let mut graph = p.graph();
        let start = Instant::now();
        let summary = sagcal::solver::optimize(&mut graph.graph, &BenchmarkProblem::stopping()).unwrap();
        let sagcal_seconds = start.elapsed().as_secs_f64();
        eprintln!(
            "sagcal: initial cost {:.15e}, final cost {:.15e}, {} iterations ({:?}), {sagcal_seconds:.4} s; \
             relative difference to apex {:.1e}",
            summary.initial_cost,
            summary.final_cost,
            summary.iterations,
            summary.termination,
            rel(run.reported_final_cost, summary.final_cost)
        );
        assert!(rel(summary.initial_cost, report.initial_cost) < 1e-12);
        assert!(rel(run.reported_final_cost, summary.final_cost) < 1e-9);
    }

    /// One run at 1000 poses (slow: `cargo test --release -- --ignored --nocapture`).
    #[test]
    #[ignore]
    fn apex_at_1000_poses() {
        let p = problem(1000);
        let built = p.graph();
        let (run, report) = run(&p, BenchmarkProblem::stopping().max_iterations).unwrap();
        let at_solution = built.graph.cost(&solution_values(&built, &run.solution)).unwrap();
        let mut graph = p.graph();
        let start = Instant::now();
        let summary = sagcal::solver::optimize(&mut graph.graph, &BenchmarkProblem::stopping()).unwrap();
        let sagcal_seconds = start.elapsed().as_secs_f64();
        eprintln!(
            "1000 poses: apex initial {:.15e}, final {:.15e} (sagcal cost there {at_solution:.15e}), {} iterations ({}), \
             solve {:.3} s, setup {:.3} s; sagcal final {:.15e}, {} iterations ({:?}), {sagcal_seconds:.3} s",
            report.initial_cost,
            run.reported_final_cost,
            run.iterations,
            report.status,
            run.solve_seconds,
            run.setup_seconds,
            summary.final_cost,
            summary.iterations,
            summary.termination
        );
    }
}

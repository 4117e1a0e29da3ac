//! Gauss-Newton with the model's equations as constraints (fixed size, no
//! allocation).
//!
//! Each step linearises the attachment heights `h(x) + H dx = 0` (eq. 15, 4
//! rows, exact) and the whitened measurements `r(x) + J dx` (encoders, load
//! cell, prior; least squares) and solves the KKT system
//! ```text
//! [ J^T J  H^T ] [dx    ]   [ -J^T r ]
//! [ H      0   ] [lambda] = [ -h     ]
//! ```
//! The top-left 8 x 8 block of the KKT matrix's inverse at the solution is
//! the covariance of the unknowns from the reading noise with the model
//! equations tight, `Z (Z^T J^T J Z)^-1 Z^T` with `Z` a basis of `H`'s null
//! space; with the four encoders only it is the square system's `J^-1 J^-T`.
//! Steps are halved until the model is defined (no slack cable) and the
//! merit `|r|^2 + |h / sigma_h|^2` decreases.

use nalgebra::{SMatrix, SVector, Vector2, Vector6};

use super::equations::{
    model_at_pose, prior_residual, ModelAtPose, ParameterPartials, SlotRobot, MEASUREMENT_ROWS, PARAMETERS, UNKNOWNS,
};
use crate::model::pose::PlatformPose;

const KKT: usize = UNKNOWNS + 4;

/// One reading in slot order, with its sigmas.
#[derive(Debug, Clone, Copy)]
pub struct Observation {
    /// Encoder readings, slot order, metres.
    pub encoders_m: nalgebra::Vector4<f64>,
    /// Encoder sigma, metres.
    pub encoder_sigma_m: f64,
    /// Load cell reading and sigma, newtons.
    pub load_cell: Option<(f64, f64)>,
    /// Prior pose of the platform, position and orientation sigmas.
    pub prior: Option<(PlatformPose, f64, f64)>,
}

impl Observation {
    /// Number of measurement rows present.
    pub fn rows(&self) -> usize {
        4 + usize::from(self.load_cell.is_some()) + if self.prior.is_some() { 6 } else { 0 }
    }
}

/// A converged (or abandoned) iteration.
#[derive(Debug, Clone, Copy)]
pub struct Solution {
    /// The pose.
    pub pose: PlatformPose,
    /// The model there.
    pub model: ModelAtPose,
    /// Whitened measurement residuals (absent rows zero).
    pub whitened: SVector<f64, MEASUREMENT_ROWS>,
    /// Covariance of `[pose tangent (6), f_ref (2)]` from the reading noise.
    pub covariance: SMatrix<f64, UNKNOWNS, UNKNOWNS>,
    /// The inverse of the KKT matrix at the solution (tension unknowns in
    /// units of the platform weight; NaN where singular).
    pub kkt_inverse: SMatrix<f64, KKT, KKT>,
    /// Iterations used.
    pub iterations: usize,
    /// Whether the heights hold and the last step was negligible.
    pub converged: bool,
}

/// Whitened measurement residuals and their Jacobian at `pose`.
fn whitened(
    model: &ModelAtPose,
    pose: &PlatformPose,
    observation: &Observation,
) -> (SVector<f64, MEASUREMENT_ROWS>, SMatrix<f64, MEASUREMENT_ROWS, UNKNOWNS>) {
    let mut r = SVector::<f64, MEASUREMENT_ROWS>::zeros();
    let mut j = SMatrix::<f64, MEASUREMENT_ROWS, UNKNOWNS>::zeros();
    let s = observation.encoder_sigma_m;
    r.fixed_rows_mut::<4>(0)
        .copy_from(&((model.encoders_m - observation.encoders_m) / s));
    j.fixed_rows_mut::<4>(0).copy_from(&(model.d_encoders / s));
    if let Some((reading, sigma)) = observation.load_cell {
        r[4] = (model.load_cell_n - reading) / sigma;
        j.set_row(4, &(model.d_load_cell / sigma));
    }
    if let Some((prior, position_sigma, orientation_sigma)) = observation.prior {
        let (residual, jacobian) = prior_residual(pose, &prior);
        for k in 0..6 {
            let sigma = if k < 3 { orientation_sigma } else { position_sigma };
            r[5 + k] = residual[k] / sigma;
            for c in 0..6 {
                j[(5 + k, c)] = jacobian[(k, c)] / sigma;
            }
        }
    }
    (r, j)
}

/// Unknowns are scaled so that the tension columns are in units of `scale_n`.
fn kkt_matrix(
    j: &SMatrix<f64, MEASUREMENT_ROWS, UNKNOWNS>,
    h: &SMatrix<f64, 4, UNKNOWNS>,
    damping: f64,
) -> SMatrix<f64, KKT, KKT> {
    let mut kkt = SMatrix::<f64, KKT, KKT>::zeros();
    let a = j.transpose() * j;
    kkt.fixed_view_mut::<UNKNOWNS, UNKNOWNS>(0, 0).copy_from(&a);
    for k in 0..UNKNOWNS {
        kkt[(k, k)] += damping * (a[(k, k)] + 1e-12);
    }
    kkt.fixed_view_mut::<4, UNKNOWNS>(UNKNOWNS, 0).copy_from(h);
    kkt.fixed_view_mut::<UNKNOWNS, 4>(0, UNKNOWNS).copy_from(&h.transpose());
    kkt
}

fn scaled(mut m: SMatrix<f64, 4, UNKNOWNS>, scale_n: f64) -> SMatrix<f64, 4, UNKNOWNS> {
    m.column_mut(6).scale_mut(scale_n);
    m.column_mut(7).scale_mut(scale_n);
    m
}

/// The merit of a trial: the whitened readings and the heights counted as
/// readings as precise as the encoders (each step aims the heights at zero).
fn merit(model: &ModelAtPose, pose: &PlatformPose, observation: &Observation) -> f64 {
    whitened(model, pose, observation).0.norm_squared() + (model.heights_m / observation.encoder_sigma_m).norm_squared()
}

/// Iterate from `(pose, reference_n)` until the step is negligible;
/// `None` if the model is undefined at the start.
pub fn solve(
    robot: &SlotRobot,
    observation: &Observation,
    mut pose: PlatformPose,
    mut reference_n: Vector2<f64>,
    max_iterations: usize,
    height_tolerance_m: f64,
) -> Option<Solution> {
    let scale_n = robot.platform_weight_n;
    let mut model = model_at_pose(robot, &pose, &reference_n)?;
    let mut last_step = f64::INFINITY;
    let mut iterations = 0;
    let mut damping = 0.0;
    while iterations < max_iterations {
        iterations += 1;
        crate::steps::tick();
        let (r, mut j) = whitened(&model, &pose, observation);
        j.column_mut(6).scale_mut(scale_n);
        j.column_mut(7).scale_mut(scale_n);
        let h = scaled(model.d_heights, scale_n);
        let mut rhs = SVector::<f64, KKT>::zeros();
        rhs.fixed_rows_mut::<UNKNOWNS>(0).copy_from(&(-(j.transpose() * r)));
        rhs.fixed_rows_mut::<4>(UNKNOWNS).copy_from(&(-model.heights_m));
        let current = merit(&model, &pose, observation);
        let mut accepted = false;
        let mut proposed = f64::INFINITY;
        // Levenberg-Marquardt on the measurement block; the heights' rows stay exact.
        for _ in 0..12 {
            let Some(step) = kkt_matrix(&j, &h, damping).lu().solve(&rhs) else {
                damping = (damping * 10.0).max(1e-9);
                continue;
            };
            let norm = step.fixed_rows::<UNKNOWNS>(0).norm();
            proposed = proposed.min(norm);
            let trial_pose = pose.retract(&Vector6::from_fn(|k, _| step[k]));
            let trial_reference = reference_n + Vector2::new(step[6], step[7]) * scale_n;
            // Near the solution the merit's fixed height weight can refuse the
            // Newton step that restores the heights (its Lagrange multiplier
            // exceeds the weight): a short step that halves the heights is taken too.
            let trial = model_at_pose(robot, &trial_pose, &trial_reference).filter(|t| {
                merit(t, &trial_pose, observation) <= current * (1.0 + 1e-12)
                    || (norm < 1e-2 && t.heights_m.amax() <= 0.5 * model.heights_m.amax() + 1e-13)
            });
            if let Some(trial) = trial {
                last_step = norm;
                (pose, reference_n, model) = (trial_pose, trial_reference, trial);
                damping = if damping > 1e-9 { damping * 0.1 } else { 0.0 };
                accepted = true;
                break;
            }
            damping = (damping * 10.0).max(1e-6);
        }
        if !accepted {
            // No trial decreases the merit: converged if the step left was negligible.
            last_step = proposed;
            break;
        }
        if last_step < 1e-13 {
            break;
        }
    }
    let mut solution = finish(robot, observation, pose, model, height_tolerance_m);
    solution.iterations = iterations;
    solution.converged &= last_step < 1e-6;
    Some(solution)
}

/// The solution at `pose`: covariance from the KKT inverse; `converged`
/// from the heights only (the caller adds the step test).
fn finish(
    robot: &SlotRobot,
    observation: &Observation,
    pose: PlatformPose,
    model: ModelAtPose,
    height_tolerance_m: f64,
) -> Solution {
    let scale_n = robot.platform_weight_n;
    let (r, mut j) = whitened(&model, &pose, observation);
    j.column_mut(6).scale_mut(scale_n);
    j.column_mut(7).scale_mut(scale_n);
    let h = scaled(model.d_heights, scale_n);
    let mut covariance = SMatrix::<f64, UNKNOWNS, UNKNOWNS>::from_element(f64::NAN);
    let mut kkt_inverse = SMatrix::<f64, KKT, KKT>::from_element(f64::NAN);
    if let Some(inverse) = kkt_matrix(&j, &h, 0.0).try_inverse() {
        kkt_inverse = inverse;
        covariance = inverse.fixed_view::<UNKNOWNS, UNKNOWNS>(0, 0).into_owned();
        for a in 0..UNKNOWNS {
            for b in 0..UNKNOWNS {
                let sa = if a >= 6 { scale_n } else { 1.0 };
                let sb = if b >= 6 { scale_n } else { 1.0 };
                covariance[(a, b)] *= sa * sb;
            }
        }
    }
    let heights_hold = model.heights_m.amax() <= height_tolerance_m;
    Solution {
        pose,
        model,
        whitened: r,
        covariance,
        kkt_inverse,
        iterations: 0,
        converged: heights_hold,
    }
}

/// `d pose tangent / d parameters` at the solution (implicit function
/// theorem on the KKT conditions): a parameter change `dtheta` moves the
/// whitened readings by `J_theta dtheta` and the heights by `H_theta dtheta`,
/// so `[dx; dlambda] = -K^-1 [J^T J_theta; H_theta] dtheta`. Exact for the
/// square system (encoders only), first order in the residuals otherwise.
pub fn parameter_sensitivity(
    robot: &SlotRobot,
    observation: &Observation,
    solution: &Solution,
    partials: &ParameterPartials,
) -> SMatrix<f64, 6, PARAMETERS> {
    let scale_n = robot.platform_weight_n;
    let (_, mut j) = whitened(&solution.model, &solution.pose, observation);
    j.column_mut(6).scale_mut(scale_n);
    j.column_mut(7).scale_mut(scale_n);
    let mut j_theta = SMatrix::<f64, MEASUREMENT_ROWS, PARAMETERS>::zeros();
    j_theta
        .fixed_rows_mut::<4>(0)
        .copy_from(&(partials.d_encoders / observation.encoder_sigma_m));
    if let Some((_, sigma)) = observation.load_cell {
        j_theta.set_row(4, &(partials.d_load_cell / sigma));
    }
    let mut rhs = SMatrix::<f64, KKT, PARAMETERS>::zeros();
    rhs.fixed_rows_mut::<UNKNOWNS>(0).copy_from(&(j.transpose() * j_theta));
    rhs.fixed_rows_mut::<4>(UNKNOWNS).copy_from(&partials.d_heights);
    -(solution.kkt_inverse.fixed_rows::<6>(0) * rhs)
}

/// The reference tension that best meets the four attachment heights (eq. 15)
/// at a fixed `pose`, by a few Gauss-Newton steps from `start` (the start is
/// kept where the model is undefined): a warm start's pose is then matched
/// by its tensions and the full iteration starts near the solution.
pub fn fit_reference_tension(robot: &SlotRobot, pose: &PlatformPose, start: Vector2<f64>) -> Vector2<f64> {
    let mut reference = start;
    for _ in 0..4 {
        let Some(model) = model_at_pose(robot, pose, &reference) else {
            break;
        };
        let j = model.d_heights.fixed_columns::<2>(6).into_owned();
        let Some(step) = (j.transpose() * j)
            .try_inverse()
            .map(|inverse| -(inverse * (j.transpose() * model.heights_m)))
        else {
            break;
        };
        let trial = reference + step;
        match model_at_pose(robot, pose, &trial) {
            Some(t) if t.heights_m.norm() < model.heights_m.norm() => reference = trial,
            _ => break,
        }
        if step.norm() < 1e-9 * reference.norm() {
            break;
        }
    }
    reference
}

//! The Fisher information one pose adds to the global parameters, with its
//! own variables eliminated exactly.
//!
//! The calibration's graph (paper Sec. IV) has, per pose `k`, local variables
//! `x_k` (platform pose, 6, and reference tension `(f_h, f_v)`, 2) and global
//! ones `theta` (12 anchor coordinates, 4 length offsets, and the effect
//! parameters when the extended model is used). Its whitened Jacobian at the
//! truth is block-arrow shaped: pose `k`'s factors read `theta` and `x_k`
//! only. The Fisher information of `theta` with every `x_k` unknown is then
//! the Schur complement (Kay, *Fundamentals of Statistical Signal Processing:
//! Estimation Theory*, 1993, Sec. 3.8 and the partitioned-inverse identity)
//! ```text
//! I(theta) = sum_k  J_g,k^T (1 - P_k) J_g,k,   P_k = J_l,k (J_l,k^T J_l,k)^-1 J_l,k^T,
//! ```
//! a sum over poses, because the local blocks of different poses never
//! couple. Its inverse is exactly the marginal covariance that
//! [`crate::calib::cramer_rao_bound`] reads from the sparse `H^-1`.
//!
//! Each term is computed from a QR factorisation of the pose's local columns
//! `J_l = Q R`: the rows of `Q^T J_g` past the first `dim x_k` span the
//! complement of `J_l`'s range, so `Z = (Q^T J_g)[8..]` gives `I_k = Z^T Z`
//! without forming `(J_l^T J_l)^-1`. The term is stored as a low-rank factor
//! `U_k` (`I_k = U_k U_k^T`, from the eigen-decomposition of `I_k`, keeping
//! eigenvalues above `1e-13` of the largest): a pose adds at most
//! `rows - 8` independent equations (4 with position priors only, 7 with the
//! orientation prior), which is what makes the design's rank-k updates cheap.
//! [`candidate_information`] computes the terms of every candidate, in
//! parallel.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::calib::{CalibrationOptions, OrientationPrior};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::statics::{solve_level, StaticsOptions};
//! use sagcal::model::Robot;
//! use sagcal::plan::pose_information;
//! let robot = Robot::builtin("large")?;
//! let eq = solve_level(&robot, Vector3::new(5.0, -4.0, 14.0), &StaticsOptions::default())?;
//! let paper = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
//! // 16 globals. With the orientation prior: 11 readings and 4 height constraints
//! // less 8 local unknowns, 7 equations; with position priors only, 4.
//! let on = CalibrationOptions { orientation_prior: OrientationPrior::On, ..paper };
//! let off = CalibrationOptions { orientation_prior: OrientationPrior::Off, ..paper };
//! let info = pose_information(&robot, &eq, &on)?;
//! assert_eq!((info.dim(), info.rank(), pose_information(&robot, &eq, &off)?.rank()), (16, 7, 4));
//! // Fisher information scales as 1 / sigma^2: every sigma doubled, a quarter of it.
//! let mut noise = on.noise;
//! noise.encoder_sigma_m *= 2.0;
//! noise.load_cell_sigma_n *= 2.0;
//! noise.position_sigma_m *= 2.0;
//! noise.orientation_sigma_rad *= 2.0;
//! let doubled = CalibrationOptions { noise, height_sigma_m: 2.0 * on.height_sigma_m, ..on };
//! let quarter = pose_information(&robot, &eq, &doubled)?;
//! assert!((quarter.matrix() * 4.0 - info.matrix()).norm() < 1e-9 * info.matrix().norm());
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{DMatrix, SymmetricEigen};
use rayon::prelude::*;

use crate::calib::{build_graph, CalibrationOptions, RobustKernels};
use crate::error::{Error, Result};
use crate::graph::{linearize_factor, FactorGraph, VariableId};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::Equilibrium;

/// Eigenvalues of a pose's information below this fraction of its largest are dropped.
const RANK_TOLERANCE: f64 = 1e-13;

/// One pose's information about the global parameters, `I_k = U_k U_k^T`.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseInformation {
    /// The low-rank factor `U_k`: one row per global parameter (anchors
    /// 1..N x, y, z; offsets 1..N; effect parameters), one column per
    /// independent equation the pose adds. Units: 1 / (parameter unit).
    pub factor: DMatrix<f64>,
    /// The robot's cables `N`: the first `3N` rows are the anchors'
    /// coordinates ([`anchor_parameters`]), the next `N` the offsets.
    pub cables: usize,
}

impl PoseInformation {
    /// The full information matrix `U_k U_k^T`.
    pub fn matrix(&self) -> DMatrix<f64> {
        &self.factor * self.factor.transpose()
    }

    /// Number of global parameters.
    pub fn dim(&self) -> usize {
        self.factor.nrows()
    }

    /// Number of independent equations this pose adds about the globals.
    pub fn rank(&self) -> usize {
        self.factor.ncols()
    }
}

/// What the sensors read, noise-free, at a true equilibrium of `truth`
/// (encoders include the true offsets), as `cramer_rao_bound` linearises it.
pub fn noise_free_reading(truth: &Robot, equilibrium: &Equilibrium) -> PoseMeasurement {
    let (roll_deg, pitch_deg, yaw_deg) = equilibrium.pose.roll_pitch_yaw_deg();
    PoseMeasurement {
        line: 0,
        position_m: equilibrium.pose.position_m.into(),
        roll_deg,
        pitch_deg,
        yaw_deg,
        encoder_lengths_m: std::array::from_fn(|i| equilibrium.cable_lengths_m[i] + truth.length_offsets_m[i]),
        reference_tension_n: equilibrium.tensions[truth.reference_cable].magnitude_n(),
        excluded: Default::default(),
        order: None,
    }
}

/// The information pose `equilibrium` adds about the global parameters of the
/// calibration `options` describe (robust kernels off, as in the bound),
/// linearised at the truth (module docs).
pub fn pose_information(
    truth: &Robot,
    equilibrium: &Equilibrium,
    options: &CalibrationOptions,
) -> Result<PoseInformation> {
    let plain = CalibrationOptions {
        robust: RobustKernels::default(),
        ..*options
    };
    let reading = noise_free_reading(truth, equilibrium);
    let reference = equilibrium.tensions[truth.reference_cable];
    let built = build_graph(
        truth,
        std::slice::from_ref(&reading),
        &[equilibrium.pose],
        &[reference],
        options.model,
        &plain,
    );
    let locals = [built.poses[0].pose, built.poses[0].reference_tension];
    graph_information(&built.graph, &locals, CABLE_COUNT, &reading.position_m)
}

/// The information about the global parameters of `graph` (every free
/// variable but `locals`, in the order of their ids: the anchors of the
/// robot's `cables`, its offsets, then any effect parameters) of a graph of
/// one pose whose own variables are `locals`, these eliminated exactly
/// (module docs); the errors name the pose by its position `position_m`.
pub fn graph_information(
    graph: &FactorGraph,
    locals: &[VariableId],
    cables: usize,
    position_m: &[f64; 3],
) -> Result<PoseInformation> {
    let values = &graph.values;
    // Column layout: free globals in variable order (anchors, offsets,
    // effects), then the free locals.
    let mut column = vec![None; values.len()];
    let mut globals = 0;
    for (id, variable) in values.iter() {
        if !variable.fixed && !locals.contains(&id) {
            column[id.0] = Some(globals);
            globals += values.tangent_dim(id);
        }
    }
    let mut width = globals;
    for &id in locals {
        if !values.variable(id).fixed {
            column[id.0] = Some(width);
            width += values.tangent_dim(id);
        }
    }
    let rows: usize = graph.factors.iter().map(|f| f.residual_dim()).sum();
    let mut jacobian = DMatrix::zeros(rows, width);
    let mut row = 0;
    for factor in &graph.factors {
        let linearized = linearize_factor(factor.as_ref(), values).map_err(|what| {
            Error::InvalidInput(format!(
                "pose at {:?}: the {} factor cannot be linearised: {what}",
                position_m,
                factor.kind()
            ))
        })?;
        for (&id, block) in factor.variables().iter().zip(&linearized.jacobians) {
            if let Some(c) = column[id.0] {
                jacobian.view_mut((row, c), block.shape()).copy_from(block);
            }
        }
        row += factor.residual_dim();
    }
    let local_dim = width - globals;
    if rows <= local_dim {
        return Err(Error::InvalidInput(format!(
            "pose at {:?}: {rows} equations cannot determine its {local_dim} own unknowns and add information",
            position_m
        )));
    }
    let global_part = jacobian.columns(0, globals).into_owned();
    let information = eliminate_locals(global_part, jacobian.columns(globals, local_dim).into_owned());
    Ok(PoseInformation {
        factor: low_rank_factor(&information),
        cables,
    })
}

/// The information of every candidate (in parallel), at the nominal robot.
pub fn candidate_information(
    nominal: &Robot,
    candidates: &[Equilibrium],
    options: &CalibrationOptions,
) -> Result<Vec<PoseInformation>> {
    candidates
        .par_iter()
        .map(|eq| pose_information(nominal, eq, options))
        .collect()
}

/// `J_g^T (1 - P_l) J_g` by the QR factorisation of `J_l` (module docs).
fn eliminate_locals(mut global: DMatrix<f64>, local: DMatrix<f64>) -> DMatrix<f64> {
    let local_dim = local.ncols();
    let qr = local.qr();
    qr.q_tr_mul(&mut global);
    let complement = global.rows(local_dim, global.nrows() - local_dim);
    complement.transpose() * complement
}

/// `U` with `U U^T = information` from the eigen-decomposition, dropping
/// eigenvalues below [`RANK_TOLERANCE`] of the largest.
fn low_rank_factor(information: &DMatrix<f64>) -> DMatrix<f64> {
    let symmetric = (information + information.transpose()) * 0.5;
    let eigen = SymmetricEigen::new(symmetric);
    let largest = eigen.eigenvalues.iter().fold(0.0f64, |m, v| m.max(*v));
    let kept: Vec<usize> = (0..eigen.eigenvalues.len())
        .filter(|&k| eigen.eigenvalues[k] > RANK_TOLERANCE * largest)
        .collect();
    DMatrix::from_fn(information.nrows(), kept.len(), |r, c| {
        let k = kept[c];
        eigen.eigenvectors[(r, k)] * eigen.eigenvalues[k].sqrt()
    })
}

/// The anchor coordinates' rows of the global parameters of a robot of
/// `cables` cables: `0..3N`.
pub fn anchor_parameters(cables: usize) -> std::ops::Range<usize> {
    0..3 * cables
}

/// The length offsets' rows of the global parameters: `3N..4N`.
pub fn offset_parameters(cables: usize) -> std::ops::Range<usize> {
    3 * cables..4 * cables
}

/// Index ranges of the global parameters of four cables: anchor coordinates `0..12`, offsets `12..16`.
pub const ANCHOR_PARAMETERS: std::ops::Range<usize> = 0..3 * CABLE_COUNT;
/// The length offsets' rows of the global parameters.
pub const OFFSET_PARAMETERS: std::ops::Range<usize> = 3 * CABLE_COUNT..4 * CABLE_COUNT;

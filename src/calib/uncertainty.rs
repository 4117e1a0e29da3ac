//! How well the calibration knows its parameters: the marginal covariance of
//! anchors, offsets and effect parameters, the Cramer-Rao bound, and the
//! errors against a known truth.

use nalgebra::{DMatrix, Matrix3, Vector3};
use serde::Serialize;

use super::graph::{build_graph, CalibrationGraph};
use super::options::{CalibrationOptions, RobustKernels};
use super::result::{EffectEstimate, ParameterUncertainty};
use crate::error::{Error, Result};
use crate::graph::{FactorGraph, VariableId};
use crate::model::effect_kind::EffectKind;
use crate::model::measurement::PoseMeasurement;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{CableTension, Equilibrium};
use crate::solver::{
    marginal_covariance, marginal_covariance_cached, marginal_covariance_over_local_gauge, Covariance,
};

/// The fitted parameters of `kind` in `built` with 1-sigma from the marginal covariance.
pub(super) fn effect_estimate(built: &CalibrationGraph, kind: EffectKind) -> Result<EffectEstimate> {
    let vars = built
        .effects
        .ok_or_else(|| Error::InvalidInput("the graph has no effect parameters".into()))?;
    let id = vars.of(kind);
    let raw = built.graph.values.vector(id).clone();
    let values = EffectEstimate::values_from_variable(kind, raw.as_slice());
    let covariance: Vec<Vec<f64>> = match marginal_covariance(&built.graph, &[id])? {
        Covariance::Full(c) => (0..raw.len())
            .map(|r| (0..raw.len()).map(|k| c[(r, k)]).collect())
            .collect(),
        Covariance::RankDeficient(_) => vec![vec![f64::NAN; raw.len()]; raw.len()],
    };
    let sigmas = (0..raw.len()).map(|k| covariance[k][k].max(0.0).sqrt()).collect();
    Ok(EffectEstimate {
        effect: kind,
        names: kind.parameter_names().iter().map(|n| n.to_string()).collect(),
        values,
        sigmas,
        covariance,
    })
}

/// Marginal covariance of anchors and offsets at the graph's current values.
pub fn parameter_uncertainty(built: &CalibrationGraph) -> Result<ParameterUncertainty> {
    anchor_and_offset_uncertainty(&built.graph, &built.globals.anchors, &built.globals.length_offsets)
}

/// Marginal covariance of the `anchors` (3-vectors) and `length_offsets`
/// (1-vectors, one per anchor) of `graph` at its current values: the
/// inverse of the information `J^T Sigma^-1 J` with every other variable
/// marginalised out.
pub fn anchor_and_offset_uncertainty(
    graph: &FactorGraph,
    anchors: &[VariableId],
    length_offsets: &[VariableId],
) -> Result<ParameterUncertainty> {
    let selected: Vec<VariableId> = anchors.iter().chain(length_offsets).copied().collect();
    let covariance =
        super::system_scope::with_system_cache(|cache| marginal_covariance_cached(graph, &selected, cache))?;
    Ok(match covariance {
        Covariance::Full(c) => uncertainty_from_covariance(&c, anchors.len()),
        Covariance::RankDeficient(directions) => ParameterUncertainty::RankDeficient { directions },
    })
}

/// [`anchor_and_offset_uncertainty`] for a graph whose local groups (each
/// pose's variables) may hold directions the readings leave undetermined
/// (the forces of a robot of many light cables): their covariance with a
/// vague prior of 1-sigma `largest_sigma` on every local coordinate
/// ([`marginal_covariance_over_local_gauge`]), and `(group, directions)` of
/// each group with directions the readings know less well than that.
pub fn anchor_and_offset_uncertainty_over_local_gauge(
    graph: &FactorGraph,
    anchors: &[VariableId],
    length_offsets: &[VariableId],
    largest_sigma: f64,
) -> Result<(ParameterUncertainty, Vec<(usize, usize)>)> {
    let selected: Vec<VariableId> = anchors.iter().chain(length_offsets).copied().collect();
    let found = marginal_covariance_over_local_gauge(graph, &selected, largest_sigma)?;
    let uncertainty = match found.covariance {
        Covariance::Full(c) => uncertainty_from_covariance(&c, anchors.len()),
        Covariance::RankDeficient(directions) => ParameterUncertainty::RankDeficient { directions },
    };
    Ok((uncertainty, found.undetermined))
}

/// The uncertainty of `cables` anchors and offsets from their joint covariance.
fn uncertainty_from_covariance(c: &DMatrix<f64>, cables: usize) -> ParameterUncertainty {
    let anchor_covariance_m2: Vec<[[f64; 3]; 3]> = (0..cables)
        .map(|i| std::array::from_fn(|r| std::array::from_fn(|col| c[(3 * i + r, 3 * i + col)])))
        .collect();
    let anchor_sigma_m = anchor_covariance_m2
        .iter()
        .map(|m| std::array::from_fn(|k| m[k][k].max(0.0).sqrt()))
        .collect();
    let offset_sigma_m = (0..cables)
        .map(|i| c[(3 * cables + i, 3 * cables + i)].max(0.0).sqrt())
        .collect();
    ParameterUncertainty::Full {
        anchor_covariance_m2,
        anchor_sigma_m,
        offset_sigma_m,
        covariance_m2: (0..c.nrows())
            .map(|r| (0..c.ncols()).map(|k| c[(r, k)]).collect())
            .collect(),
    }
}

/// The Cramer-Rao bound of anchors and offsets: the inverse Fisher information
/// `(J^T Sigma^-1 J)^-1` at the true parameters and true equilibria, for the
/// factors of `options` (no robust kernels).
pub fn cramer_rao_bound(
    truth: &Robot,
    equilibria: &[Equilibrium],
    options: &CalibrationOptions,
) -> Result<ParameterUncertainty> {
    let measurements: Vec<PoseMeasurement> = equilibria
        .iter()
        .map(|eq| {
            let (roll_deg, pitch_deg, yaw_deg) = eq.pose.roll_pitch_yaw_deg();
            PoseMeasurement {
                line: 0,
                position_m: eq.pose.position_m.into(),
                roll_deg,
                pitch_deg,
                yaw_deg,
                encoder_lengths_m: std::array::from_fn(|i| eq.cable_lengths_m[i] + truth.length_offsets_m[i]),
                reference_tension_n: eq.tensions[truth.reference_cable].magnitude_n(),
                excluded: Default::default(),
                order: None,
            }
        })
        .collect();
    let poses: Vec<PlatformPose> = equilibria.iter().map(|e| e.pose).collect();
    let tensions: Vec<CableTension> = equilibria.iter().map(|e| e.tensions[truth.reference_cable]).collect();
    let plain = CalibrationOptions {
        robust: RobustKernels::default(),
        ..*options
    };
    let built = build_graph(truth, &measurements, &poses, &tensions, options.model, &plain);
    parameter_uncertainty(&built)
}

/// Anchor and offset errors of a calibrated robot against the truth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CalibrationError {
    /// Mean over anchors of the Euclidean error, metres (the authors' program's metric).
    pub anchor_mean_euclidean_m: f64,
    /// Mean absolute error over the 12 anchor coordinates, metres.
    pub anchor_coordinate_mae_m: f64,
    /// Largest Euclidean anchor error, metres.
    pub anchor_max_euclidean_m: f64,
    /// Mean absolute offset error, metres.
    pub offset_mae_m: f64,
}

impl CalibrationError {
    /// Compare `estimate` with `truth`.
    pub fn between(estimate: &Robot, truth: &Robot) -> Self {
        let anchor: Vec<Vector3<f64>> = (0..CABLE_COUNT)
            .map(|i| estimate.anchors_m[i] - truth.anchors_m[i])
            .collect();
        let euclid: Vec<f64> = anchor.iter().map(|d| d.norm()).collect();
        Self {
            anchor_mean_euclidean_m: euclid.iter().sum::<f64>() / CABLE_COUNT as f64,
            anchor_coordinate_mae_m: anchor.iter().map(|d| d.abs().sum()).sum::<f64>() / (3 * CABLE_COUNT) as f64,
            anchor_max_euclidean_m: euclid.iter().copied().fold(0.0, f64::max),
            offset_mae_m: (0..CABLE_COUNT)
                .map(|i| (estimate.length_offsets_m[i] - truth.length_offsets_m[i]).abs())
                .sum::<f64>()
                / CABLE_COUNT as f64,
        }
    }
}

/// Per anchor, `sqrt(trace Sigma_i)`: the RMS Euclidean error the bound allows, metres.
pub fn anchor_rms_bound_m(uncertainty: &ParameterUncertainty) -> Option<Vec<f64>> {
    match uncertainty {
        ParameterUncertainty::Full {
            anchor_covariance_m2, ..
        } => Some(
            anchor_covariance_m2
                .iter()
                .map(|m| Matrix3::from_fn(|r, c| m[r][c]).trace().max(0.0).sqrt())
                .collect(),
        ),
        ParameterUncertainty::RankDeficient { .. } => None,
    }
}

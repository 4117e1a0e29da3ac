//! What a calibration returns: the calibrated robot, its uncertainty, the
//! solver stages, the residual statistics per factor type, and the test of
//! the localiser's orientations ([`OrientationCheck`]).

use serde::Serialize;

use crate::graph::{whitened_squared_norm, FactorGraph};
use crate::model::effect_kind::EffectKind;
use crate::model::pose::PlatformPose;
use crate::model::robot::{ParameterCovariance, Robot};
use crate::model::statics::CableTension;
use crate::solver::{SolveSummary, UnobservableDirection};

/// One solver stage of a calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageSummary {
    /// `rigid`, `catenary`.
    pub name: String,
    /// The solver's account.
    pub summary: SolveSummary,
}

/// Normalised residuals `r / sigma` of one factor type at the solution.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FactorStatistics {
    /// Factor type.
    pub kind: String,
    /// Number of factors.
    pub factors: usize,
    /// Number of residual components.
    pub components: usize,
    /// Root mean square of `r / sigma` (about 1 when the stated noise is right).
    pub rms: f64,
    /// Largest `|r / sigma|`.
    pub max_abs: f64,
    /// Sum of `(r / sigma)^2`.
    pub chi_square: f64,
}

/// What the data say about the calibrated parameters' uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ParameterUncertainty {
    /// The information matrix is full rank.
    Full {
        /// Per anchor, its 3x3 covariance, m^2 (row-major).
        anchor_covariance_m2: Vec<[[f64; 3]; 3]>,
        /// Per anchor, the 1-sigma of x, y, z, metres.
        anchor_sigma_m: Vec<[f64; 3]>,
        /// Per offset, its 1-sigma, metres.
        offset_sigma_m: Vec<f64>,
        /// The joint covariance, m^2, `4N` rows of `4N` (16 for four
        /// cables): anchors 1..N (x, y, z each), then offsets 1..N (what
        /// `localize` propagates).
        covariance_m2: Vec<Vec<f64>>,
    },
    /// Some directions of parameter space are not observable from these poses.
    RankDeficient {
        /// The unobservable directions.
        directions: Vec<UnobservableDirection>,
    },
}

impl ParameterUncertainty {
    /// The joint covariance of anchors and offsets, when full rank.
    pub fn covariance(&self) -> Option<ParameterCovariance> {
        match self {
            Self::Full { covariance_m2, .. } => Some(ParameterCovariance::from_fn(|r, k| covariance_m2[r][k])),
            Self::RankDeficient { .. } => None,
        }
    }
}

/// The consistency test of the localiser's orientations with the fitted
/// statics, and what the calibration did with it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OrientationCheck {
    /// Whether the final calibration used the orientation prior.
    pub prior_used: bool,
    /// `sum |log(R_measured^T R_fitted)|^2 / sigma^2` over the poses, with the prior on.
    pub chi_square: f64,
    /// Number of orientation residual components (3 per pose).
    pub components: usize,
    /// The 99.9 % quantile of chi-square with `components` degrees of freedom
    /// (Wilson-Hilferty); above it the orientations are declared inconsistent.
    pub limit: f64,
    /// Mean angle between measured and fitted orientations, degrees.
    pub mean_angle_deg: f64,
}

/// The result of a calibration.
#[derive(Debug, Clone)]
pub struct CalibrationResult {
    /// The calibrated robot (anchors and length offsets replaced).
    pub robot: Robot,
    /// Uncertainty of anchors and offsets.
    pub uncertainty: ParameterUncertainty,
    /// Solver stages in order.
    pub stages: Vec<StageSummary>,
    /// Residual statistics per factor type at the solution.
    pub factor_statistics: Vec<FactorStatistics>,
    /// Estimated platform poses.
    pub poses: Vec<PlatformPose>,
    /// Estimated reference tensions `(f_h, f_v)` (catenary model), newtons.
    pub reference_tensions_n: Vec<[f64; 2]>,
    /// Indices (into the measurements) of poses left out of the final stage:
    /// no positive-tension equilibrium near them with the calibrated anchors.
    pub excluded_poses: Vec<usize>,
    /// The orientation consistency test (catenary model with
    /// [`crate::calib::OrientationPrior::Auto`]; `None` otherwise).
    pub orientation_check: Option<OrientationCheck>,
    /// The estimated effects ([`crate::calib::CalibrationOptions::free_effects`]),
    /// with 1-sigma, in catalogue order.
    pub effect_estimates: Vec<EffectEstimate>,
}

impl EffectEstimate {
    /// Report values (gains as `1 + error`) from the effect variable's contents.
    pub fn values_from_variable(kind: EffectKind, raw: &[f64]) -> Vec<f64> {
        let scale = |(i, v): (usize, &f64)| if kind.is_scale(i) { 1.0 + v } else { *v };
        raw.iter().enumerate().map(scale).collect()
    }

    /// The effect variable's contents (gain errors) for these estimates: the
    /// inverse of [`EffectEstimate::values_from_variable`].
    pub fn variable_values(&self) -> Vec<f64> {
        let error = |(i, v): (usize, &f64)| if self.effect.is_scale(i) { v - 1.0 } else { *v };
        self.values.iter().enumerate().map(error).collect()
    }
}

/// An effect's estimated parameters with their 1-sigma uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectEstimate {
    /// The effect.
    pub effect: EffectKind,
    /// Parameter names ([`EffectKind::parameter_names`]).
    pub names: Vec<String>,
    /// Estimates, in the units of the names (gains as `1 + error`).
    pub values: Vec<f64>,
    /// 1-sigma of each estimate (NaN where the information matrix is singular).
    pub sigmas: Vec<f64>,
    /// The estimates' marginal covariance, in the variable's units (gain
    /// errors; NaN where the information matrix is singular).
    pub covariance: Vec<Vec<f64>>,
}

impl CalibrationResult {
    /// The last stage's summary.
    pub fn final_stage(&self) -> &SolveSummary {
        &self
            .stages
            .last()
            .expect("a calibration has at least one stage")
            .summary
    }

    /// Whether the last stage stopped at a minimum.
    pub fn converged(&self) -> bool {
        self.final_stage().termination.converged()
    }

    /// The estimated reference tensions as [`CableTension`]s (one per pose used).
    pub fn reference_tensions(&self) -> Vec<CableTension> {
        self.reference_tensions_n
            .iter()
            .map(|t| CableTension {
                horizontal_n: t[0],
                vertical_n: t[1],
            })
            .collect()
    }
}

/// Per factor type: count, RMS and max of the normalised residuals.
pub fn factor_statistics(graph: &FactorGraph) -> Vec<FactorStatistics> {
    let mut stats: Vec<FactorStatistics> = Vec::new();
    for factor in &graph.factors {
        let Some(residual) = factor.evaluate(&graph.values, None) else {
            continue;
        };
        let sigmas = factor.sigmas();
        let s = whitened_squared_norm(&residual, sigmas);
        let max_abs = residual
            .iter()
            .zip(sigmas.iter())
            .map(|(r, s)| (r / s).abs())
            .fold(0.0, f64::max);
        let entry = match stats.iter_mut().find(|e| e.kind == factor.kind()) {
            Some(e) => e,
            None => {
                stats.push(FactorStatistics {
                    kind: factor.kind().to_string(),
                    factors: 0,
                    components: 0,
                    rms: 0.0,
                    max_abs: 0.0,
                    chi_square: 0.0,
                });
                stats.last_mut().expect("just pushed")
            }
        };
        entry.factors += 1;
        entry.components += residual.len();
        entry.chi_square += s;
        entry.max_abs = entry.max_abs.max(max_abs);
    }
    for e in &mut stats {
        e.rms = (e.chi_square / e.components.max(1) as f64).sqrt();
    }
    stats
}

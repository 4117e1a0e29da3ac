//! The Cramer-Rao bound of a set of poses from their per-pose information
//! (see `information`): `Sigma = (sum_k I_k)^-1`, summarised as the
//! root-mean-square errors it allows.
//!
//! ```
//! use nalgebra::DMatrix;
//! use sagcal::plan::information::PoseInformation;
//! use sagcal::plan::plan_bound;
//! // Sixteen poses, each measuring one global parameter with sigma 2 cm: Sigma = (0.02 m)^2 1,
//! // so the RMS anchor error is sqrt(3) x 2 cm and the RMS offset error 2 cm.
//! let poses: Vec<PoseInformation> = (0..16)
//!     .map(|k| PoseInformation { factor: DMatrix::from_fn(16, 1, |r, _| if r == k { 1.0 / 0.02 } else { 0.0 }), cables: 4 })
//!     .collect();
//! let all: Vec<usize> = (0..16).collect();
//! let bound = plan_bound(&poses, &all).unwrap();
//! assert!((bound.anchor_rms_m - 3f64.sqrt() * 0.02).abs() < 1e-12);
//! assert!((bound.offset_rms_m - 0.02).abs() < 1e-12);
//! // Fifteen of them leave a parameter undetermined: no bound.
//! assert!(plan_bound(&poses, &all[..15]).is_none());
//! ```

use nalgebra::DMatrix;
use serde::Serialize;

use super::information::{anchor_parameters, offset_parameters, PoseInformation};

/// A direction whose variance exceeds this, (m)^2, is not determined (the
/// limit `marginal_covariance` uses: a 10 km standard deviation).
const UNDETERMINED_VARIANCE: f64 = 1e8;

/// The bound of a pose set on anchors and offsets.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanBound {
    /// RMS Euclidean anchor error the bound allows, `sqrt(trace Sigma_anchors / N)`, metres.
    pub anchor_rms_m: f64,
    /// RMS length-offset error, `sqrt(trace Sigma_offsets / N)`, metres.
    pub offset_rms_m: f64,
    /// Per anchor, the 3x3 covariance block, m^2.
    pub anchor_covariance_m2: Vec<[[f64; 3]; 3]>,
}

/// `sum_k I_k` over `chosen` plus `ridge` on the diagonal.
pub fn information_sum(poses: &[PoseInformation], chosen: &[usize], ridge: f64) -> DMatrix<f64> {
    let n = poses.first().map_or(0, PoseInformation::dim);
    let mut sum = DMatrix::from_diagonal_element(n, n, ridge);
    for &k in chosen {
        let u = &poses[k].factor;
        sum.gemm(1.0, u, &u.transpose(), 1.0);
    }
    sum
}

/// The covariance `M^-1` of a positive definite information `M` (`None` if it is not).
pub fn covariance_of(information: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let inverse = information.clone().cholesky()?.inverse();
    let symmetric = (&inverse + inverse.transpose()) * 0.5;
    (0..symmetric.nrows())
        .all(|k| symmetric[(k, k)].is_finite() && symmetric[(k, k)] > 0.0)
        .then_some(symmetric)
}

/// The bound of the poses `chosen` (no ridge); `None` when they do not
/// determine every anchor and offset (fewer than 4 distinct poses, or a
/// degenerate arrangement).
pub fn plan_bound(poses: &[PoseInformation], chosen: &[usize]) -> Option<PlanBound> {
    let covariance = covariance_of(&information_sum(poses, chosen, 0.0))?;
    let determined = (0..covariance.nrows()).all(|k| covariance[(k, k)] < UNDETERMINED_VARIANCE);
    determined.then(|| bound_from_covariance(&covariance, poses.first().map_or(0, |p| p.cables)))
}

/// The summary of a joint covariance of the global parameters of a robot of `cables` cables.
pub fn bound_from_covariance(covariance: &DMatrix<f64>, cables: usize) -> PlanBound {
    let trace = |range: std::ops::Range<usize>| range.map(|k| covariance[(k, k)]).sum::<f64>();
    PlanBound {
        anchor_rms_m: (trace(anchor_parameters(cables)) / cables as f64).sqrt(),
        offset_rms_m: (trace(offset_parameters(cables)) / cables as f64).sqrt(),
        anchor_covariance_m2: (0..cables)
            .map(|i| std::array::from_fn(|r| std::array::from_fn(|c| covariance[(3 * i + r, 3 * i + c)])))
            .collect(),
    }
}

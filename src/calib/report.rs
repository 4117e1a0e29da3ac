//! A calibration's result as a serialisable report (what `sagcal calibrate --json` prints).

use serde::Serialize;

use super::{
    CableModel, CalibrationError, CalibrationResult, FactorStatistics, OrientationCheck, ParameterUncertainty,
    StageSummary,
};
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::solver::Termination;

/// Everything a user needs from one calibration.
#[derive(Debug, Clone, Serialize)]
pub struct CalibrationReport {
    /// Robot name.
    pub robot: String,
    /// Cable model.
    pub model: CableModel,
    /// Number of poses in the final solve.
    pub poses_used: usize,
    /// File lines (or 1-based indices for in-memory data) of poses left out: no equilibrium near them.
    pub excluded_poses: Vec<usize>,
    /// Calibrated anchors, world frame, metres (4 x 3).
    pub anchors_m: Vec<[f64; 3]>,
    /// 1-sigma of each anchor coordinate, metres (`null` where not observable).
    pub anchor_sigma_m: Option<Vec<[f64; 3]>>,
    /// Calibrated minus nominal anchors, metres.
    pub anchor_change_m: Vec<[f64; 3]>,
    /// Calibrated length offsets, metres.
    pub length_offsets_m: Vec<f64>,
    /// 1-sigma of each offset, metres (`null` where not observable).
    pub offset_sigma_m: Option<Vec<f64>>,
    /// Full uncertainty, or the unobservable directions.
    pub uncertainty: ParameterUncertainty,
    /// Normalised residual statistics per factor type.
    pub factor_statistics: Vec<FactorStatistics>,
    /// Solver stages.
    pub stages: Vec<StageSummary>,
    /// Cost of the final stage.
    pub final_cost: f64,
    /// Iterations over all stages.
    pub iterations: usize,
    /// Why the final stage stopped.
    pub termination: Termination,
    /// Whether the final stage stopped at a minimum.
    pub converged: bool,
    /// Error against the truth, when it is known (simulations).
    pub error_against_truth: Option<CalibrationError>,
    /// The test of the localiser's orientations against the statics (`--orientation-prior auto`).
    pub orientation_check: Option<OrientationCheck>,
}

impl CalibrationReport {
    /// Build the report; `lines[k]` names pose `k` in messages.
    pub fn new(
        result: &CalibrationResult,
        nominal: &Robot,
        model: CableModel,
        lines: &[usize],
        truth: Option<&Robot>,
    ) -> Self {
        let (anchor_sigma_m, offset_sigma_m) = match &result.uncertainty {
            ParameterUncertainty::Full {
                anchor_sigma_m,
                offset_sigma_m,
                ..
            } => (Some(anchor_sigma_m.clone()), Some(offset_sigma_m.clone())),
            ParameterUncertainty::RankDeficient { .. } => (None, None),
        };
        let final_stage = result.final_stage();
        Self {
            robot: result.robot.name.clone(),
            model,
            poses_used: result.poses.len(),
            excluded_poses: result
                .excluded_poses
                .iter()
                .map(|&k| lines.get(k).copied().unwrap_or(k + 1))
                .collect(),
            anchors_m: result.robot.anchors_m.iter().map(|a| [a.x, a.y, a.z]).collect(),
            anchor_sigma_m,
            anchor_change_m: (0..CABLE_COUNT)
                .map(|i| {
                    let d = result.robot.anchors_m[i] - nominal.anchors_m[i];
                    [d.x, d.y, d.z]
                })
                .collect(),
            length_offsets_m: result.robot.length_offsets_m.to_vec(),
            offset_sigma_m,
            uncertainty: result.uncertainty.clone(),
            factor_statistics: result.factor_statistics.clone(),
            stages: result.stages.clone(),
            final_cost: final_stage.final_cost,
            iterations: result.stages.iter().map(|s| s.summary.iterations).sum(),
            termination: final_stage.termination,
            converged: result.converged(),
            error_against_truth: truth.map(|t| CalibrationError::between(&result.robot, t)),
            orientation_check: result.orientation_check,
        }
    }
}

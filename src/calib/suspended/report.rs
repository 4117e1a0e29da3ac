//! What a calibration of `N` cables tells its user
//! ([`SuspendedCalibrationReport`]): the anchors and offsets with their
//! 1-sigma, how far they moved from the nominal robot, the residuals per
//! factor type, the solver's stages and the chi-square test of the fit.

use serde::Serialize;

use super::calibrate::SuspendedCalibration;
use super::gross_errors::SuspendedGrossError;
use crate::calib::result::{FactorStatistics, ParameterUncertainty, StageSummary};
use crate::model::suspended::SuspendedRobot;
use crate::stats::chi_square_quantile_999;

/// A pose whose cable forces the readings do not determine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct UndeterminedForces {
    /// The pose, 1-based (the row of the data).
    pub pose: usize,
    /// Directions of its forces that change no reading.
    pub directions: usize,
}

/// The report of one calibration of `N` cables (serialised as the
/// command's `--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedCalibrationReport {
    /// Robot name.
    pub robot: String,
    /// Number of cables.
    pub cables: usize,
    /// The cables with a load cell, 1-based.
    pub load_cells: Vec<usize>,
    /// Each cable's axial stiffness `EA` the model used, newtons (`null`:
    /// an inextensible cable).
    pub axial_stiffness_n: Vec<Option<f64>>,
    /// Number of poses.
    pub poses_used: usize,
    /// Calibrated anchors, world frame, metres (N x 3).
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
    /// Whether the final stage stopped at a minimum.
    pub converged: bool,
    /// The fit's chi-square, `sum (r / sigma)^2`.
    pub chi_square: f64,
    /// Its degrees of freedom: residual rows minus unknowns.
    pub degrees_of_freedom: usize,
    /// The chi-square's 99.9 % quantile for those degrees of freedom: a fit
    /// with the stated noise exceeds it once in a thousand.
    pub chi_square_limit: f64,
    /// Whether the chi-square is within its limit (the model and the stated
    /// noise explain the readings).
    pub consistent: bool,
    /// The poses (1-based) whose start fell back to the measured pose.
    pub poses_without_start: Vec<usize>,
    /// The poses whose cable forces the readings do not determine, each
    /// with the number of force directions that change no reading (the
    /// anchors' and offsets' 1-sigma leave them out; they do not touch them).
    pub undetermined_forces: Vec<UndeterminedForces>,
    /// The readings left out as gross errors, in the order found.
    pub readings_left_out: Vec<SuspendedGrossError>,
    /// Whether a gross error was still found with the most readings the
    /// tests may leave out already out.
    pub search_exhausted: bool,
}

impl SuspendedCalibrationReport {
    /// Why the fit is not to be trusted, naming the test; `None` when it
    /// passes its chi-square test and the solver converged.
    pub fn inconsistency(&self) -> Option<String> {
        let chi_square = format!(
            "chi-square {:.1} for {} degrees of freedom, 99.9 % limit {:.1}",
            self.chi_square, self.degrees_of_freedom, self.chi_square_limit
        );
        if self.search_exhausted {
            return Some(format!(
                "after {} readings left out, the tests for single gross errors still find one ({chi_square}): the model, not single readings, disagrees with the data",
                self.readings_left_out.len()
            ));
        }
        match (self.converged, self.chi_square <= self.chi_square_limit) {
            (true, true) => None,
            (true, false) => Some(format!(
                "the readings disagree with the model of {} cables or with the stated noise ({chi_square}); look for a blunder in the data or a wrong robot file",
                self.cables
            )),
            (false, _) => Some(format!("the solver did not converge ({chi_square})")),
        }
    }

    /// The report of `result`, calibrated from `nominal`.
    pub fn new(nominal: &SuspendedRobot, result: &SuspendedCalibration) -> Self {
        let robot = &result.robot;
        let (anchor_sigma_m, offset_sigma_m) = match &result.uncertainty {
            ParameterUncertainty::Full {
                anchor_sigma_m,
                offset_sigma_m,
                ..
            } => (Some(anchor_sigma_m.clone()), Some(offset_sigma_m.clone())),
            ParameterUncertainty::RankDeficient { .. } => (None, None),
        };
        let chi_square = 2.0 * result.final_cost;
        let chi_square_limit = chi_square_quantile_999(result.degrees_of_freedom.max(1));
        let converged = result.stages.last().is_some_and(|s| s.summary.termination.converged());
        Self {
            robot: robot.name.clone(),
            cables: robot.cable_count(),
            load_cells: robot.load_cells.iter().map(|c| c + 1).collect(),
            axial_stiffness_n: robot
                .axial_stiffness_n
                .iter()
                .map(|ea| ea.is_finite().then_some(*ea))
                .collect(),
            poses_used: result.poses.len(),
            anchors_m: robot.anchors_m.iter().map(|a| (*a).into()).collect(),
            anchor_sigma_m,
            anchor_change_m: robot
                .anchors_m
                .iter()
                .zip(&nominal.anchors_m)
                .map(|(a, n)| (a - n).into())
                .collect(),
            length_offsets_m: robot.length_offsets_m.clone(),
            offset_sigma_m,
            uncertainty: result.uncertainty.clone(),
            factor_statistics: result.statistics.clone(),
            stages: result.stages.clone(),
            converged,
            chi_square,
            degrees_of_freedom: result.degrees_of_freedom,
            chi_square_limit,
            consistent: converged && chi_square <= chi_square_limit && !result.search_exhausted,
            poses_without_start: result.fell_back.iter().map(|k| k + 1).collect(),
            undetermined_forces: result
                .undetermined_forces
                .iter()
                .map(|&(pose, directions)| UndeterminedForces {
                    pose: pose + 1,
                    directions,
                })
                .collect(),
            readings_left_out: result.left_out.clone(),
            search_exhausted: result.search_exhausted,
        }
    }
}

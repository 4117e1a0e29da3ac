//! A calibration's result as a serialisable report, and the checked
//! calibration's report with its gross-error tests ([`CheckedReport`]: what
//! `sagcal calibrate --json` prints and `sagcal.calibrate(...).report` holds).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::report::CalibrationReport;
//! use sagcal::calib::{calibrate, CableModel, CalibrationOptions};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let truth = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
//! let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 10, &mut rng)?;
//! // Noise-free readings (weighted by the paper's sigmas): the fit lands on the truth.
//! let data = measure(&truth, &equilibria, &NoisePreset::None.sigmas(truth.platform_weight_n), &mut rng);
//! let mut nominal = truth.clone();
//! nominal.anchors_m[0].x += 0.2; // the drawing puts anchor 1 0.2 m off
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(truth.platform_weight_n));
//! let result = calibrate(&nominal, &data, &options)?;
//! let report = CalibrationReport::new(&result, &nominal, CableModel::Catenary, &[], Some(&truth));
//! assert_eq!((report.poses_used, report.converged), (10, true));
//! // Calibrated minus nominal: the 0.2 m the drawing was off, back.
//! assert!((report.anchor_change_m[0][0] + 0.2).abs() < 1e-4, "{:?}", report.anchor_change_m);
//! assert!(report.error_against_truth.unwrap().anchor_mean_euclidean_m < 1e-4);
//! let json = serde_json::to_value(&report).unwrap();
//! assert_eq!(json["anchors_m"][0][0], report.anchors_m[0][0]);
//! assert_eq!(json["robot"], "large");
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::Serialize;

use super::gross_errors::{CheckedCalibration, ConsistencyTest, ExcludedReading, Verdict};
use super::mistakes::Mistake;
use super::options::CableModel;
use super::result::{CalibrationResult, FactorStatistics, OrientationCheck, ParameterUncertainty, StageSummary};
use super::uncertainty::CalibrationError;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::DataRow;
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
    /// Poses left out, no equilibrium being near them: each its `row` (from
    /// 1, in the data given) and `line` (`null` for in-memory data).
    pub excluded_poses: Vec<DataRow>,
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
    /// Build the report; `rows[k]` names the fit's pose `k` (without it:
    /// its 1-based index, no line).
    pub fn new(
        result: &CalibrationResult,
        nominal: &Robot,
        model: CableModel,
        rows: &[DataRow],
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
                .map(|&k| rows.get(k).copied().unwrap_or(DataRow::at(k, 0)))
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

/// What the gross-error tests found and did (the `gross_errors` section of
/// the checked report).
#[derive(Debug, Clone, Serialize)]
pub struct GrossErrorReport {
    /// `consistent`, or `inconsistent` with its reason.
    pub verdict: Verdict,
    /// Readings left out, each with its row, sensor, estimated error, `w` and explanation.
    pub excluded_readings: Vec<ExcludedReading>,
    /// For an inconsistent fit: the readings the search had left out before
    /// it gave up (the fit reported uses them; omitted when empty).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub set_aside_readings: Vec<ExcludedReading>,
    /// Common mistakes recognised (units, swapped cables, re-homing, poses outside the frame).
    pub mistakes: Vec<Mistake>,
    /// The tests of the final fit.
    pub tests: ConsistencyTest,
}

impl GrossErrorReport {
    /// The report of a checked calibration.
    pub fn new(checked: &CheckedCalibration) -> Self {
        Self {
            verdict: checked.verdict.clone(),
            excluded_readings: checked.excluded.clone(),
            set_aside_readings: checked.set_aside.clone(),
            mistakes: checked.mistakes.clone(),
            tests: checked.test.clone(),
        }
    }
}

/// A checked calibration's report: the calibration's, with its gross-error
/// tests beside it (what `sagcal calibrate --json` prints).
#[derive(Debug, Clone, Serialize)]
pub struct CheckedReport {
    /// The calibration (its keys at the top level of the JSON).
    #[serde(flatten)]
    pub report: CalibrationReport,
    /// The gross-error tests.
    pub gross_errors: GrossErrorReport,
}

//! Step 1: the baseline model fitted to the data, its chi-square test per
//! sensor, and the quantities every comparison with it needs.

use super::fitted_graph::rebuild;
use super::options::DiagnoseOptions;
use super::progress::Progress;
use super::residual_tests::FactorTest;
use super::residual_tests::{factor_tests, measurement_components, total_chi_square, variance_factor};
use super::variance_components::noise_the_data_show;
use crate::calib::{
    calibrate, CalibrationGraph, CalibrationOptions, CalibrationResult, OrientationPrior, PreparedCalibration,
};
use crate::error::{Error, Result};
use crate::model::effect_kind::EffectSet;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::stats::{self};

/// The baseline model fitted to the data: the calibration, the poses it
/// used, its graph at the fit and the quantities every comparison needs.
pub(super) struct Baseline {
    /// The baseline calibration.
    pub(super) result: CalibrationResult,
    /// Its options with the orientation prior resolved.
    pub(super) options: CalibrationOptions,
    /// The measurements of the poses it used.
    pub(super) used: Vec<PoseMeasurement>,
    /// Its graph at the fit.
    pub(super) graph: CalibrationGraph,
    /// Measurement residual components `n`.
    pub(super) components: usize,
    /// Unknowns of the baseline: 8 per pose and 16 global.
    pub(super) unknowns: usize,
    /// Chi-square over all factors.
    pub(super) chi_square: f64,
    /// Degrees of freedom (measurements + statics constraints - unknowns).
    pub(super) dof: usize,
    /// The a posteriori variance factor (1 unless the data are more precise than stated).
    pub(super) variance_factor: f64,
    /// The baseline's BIC.
    pub(super) bic: f64,
    /// Mean load-cell reading over the poses used, newtons.
    pub(super) mean_reference_tension_n: f64,
    /// The initial guess every calibration starts from, with the cleaned
    /// measurements and the stages of their calibration that the
    /// orientation prior and the free effects do not enter.
    pub(super) start: PreparedCalibration,
}

impl Baseline {
    /// Calibrate with the baseline model (`options.calibration` without a free effect).
    pub(super) fn fit(
        robot: &Robot,
        measurements: &[PoseMeasurement],
        options: &DiagnoseOptions,
        progress: &mut Progress<'_>,
    ) -> Result<Self> {
        // Every sensor is evidence: the localiser's orientation is a prior
        // unless the user turned it off; "it is unreliable" is a hypothesis.
        let orientation_prior = match options.calibration.orientation_prior {
            OrientationPrior::Off => OrientationPrior::Off,
            _ => OrientationPrior::On,
        };
        let base_options = CalibrationOptions {
            free_effects: EffectSet::NONE,
            orientation_prior,
            ..options.calibration
        };
        progress.step("baseline calibration");
        let start = PreparedCalibration::new(robot, measurements, &base_options);
        let result = start.calibrate(&base_options)?;
        let resolved = base_options.as_used_by(&result);
        let used: Vec<PoseMeasurement> = (0..measurements.len())
            .filter(|k| !result.excluded_poses.contains(k))
            .map(|k| measurements[k])
            .collect();
        if used.len() < 2 * options.folds {
            return Err(Error::InvalidInput(format!(
                "diagnose: {} usable poses are too few for {}-fold cross-validation (need at least {})",
                used.len(),
                options.folds,
                2 * options.folds
            )));
        }
        let graph = rebuild(&result, &used, &resolved);
        let components = measurement_components(&graph.graph);
        let unknowns = 8 * used.len() + 4 * CABLE_COUNT;
        let constraints = CABLE_COUNT * used.len();
        let chi_square = total_chi_square(&graph.graph);
        let dof = (components + constraints).saturating_sub(unknowns).max(1);
        let mut base = Self {
            result,
            options: resolved,
            used,
            graph,
            components,
            unknowns,
            chi_square,
            dof,
            variance_factor: variance_factor(chi_square, dof),
            bic: f64::NAN,
            mean_reference_tension_n: f64::NAN,
            start,
        };
        base.mean_reference_tension_n =
            base.used.iter().map(|m| m.reference_tension_n).sum::<f64>() / base.used.len() as f64;
        base.bic = base.bic_of(chi_square, 0);
        Ok(base)
    }

    /// [`calibrate`] of `measurements` from the initial guess under
    /// `options`, from the shared stages where the measurements are the
    /// baseline's (the same result, [`PreparedCalibration`]).
    pub(super) fn calibrate(
        &self,
        measurements: &[PoseMeasurement],
        options: &CalibrationOptions,
    ) -> Result<CalibrationResult> {
        if measurements == self.start.measurements() {
            self.start.calibrate(options)
        } else {
            calibrate(self.start.initial(), measurements, options)
        }
    }

    /// The BIC of a fit with chi-square `chi` and `added` parameters more than the baseline.
    pub(super) fn bic_of(&self, chi: f64, added: usize) -> f64 {
        stats::bic(chi, self.variance_factor, self.unknowns + added, self.components)
    }
}

/// The baseline fit and its chi-square test per sensor. Where the data are
/// more precise than stated, each sensor by its own factor, the baseline is
/// fitted again with the noise the data show ([`noise_the_data_show`]),
/// which the options returned carry into every later test.
pub(super) fn fit_baseline(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    options: &DiagnoseOptions,
    progress: &mut Progress<'_>,
) -> Result<(Baseline, Vec<FactorTest>, Option<SensorNoise>, DiagnoseOptions)> {
    let base = Baseline::fit(robot, measurements, options, progress)?;
    let tests = factor_tests(&base.graph.graph, base.components, base.dof);
    let shown = (base.variance_factor < 1.0)
        .then(|| noise_the_data_show(&options.calibration.noise, &tests))
        .flatten();
    let Some(noise) = shown else {
        return Ok((base, tests, None, options.clone()));
    };
    let rescaled = DiagnoseOptions {
        calibration: CalibrationOptions {
            noise,
            ..options.calibration
        },
        ..options.clone()
    };
    progress.grow(1);
    let base = Baseline::fit(robot, measurements, &rescaled, progress)?;
    let tests = factor_tests(&base.graph.graph, base.components, base.dof);
    Ok((base, tests, Some(noise), rescaled))
}

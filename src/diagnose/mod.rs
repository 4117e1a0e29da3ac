//! What the calibration model gets wrong: `sagcal diagnose`.
//!
//! Given measurements, [`diagnose`]
//!
//! 1. calibrates with the baseline model (the paper's closed-form catenary)
//!    and tests the normalised residuals against the stated sensor noise with
//!    a chi-square test per factor type ([`FactorTest`]);
//! 2. relates the residuals to physical drivers of each cable and pose
//!    (tension, tension x length, cable length, sag, elevation, pulley wrap
//!    angle, platform position) by correlation, and says which carry structure
//!    ([`DriverTest`], `|t| > 3.29`, two-sided p < 0.001);
//! 3. fits every candidate effect of the catalogue ([`EffectKind`]) as an
//!    extension of the factor graph (extra parameter variables,
//!    [`crate::calib::effect_factors`]), scores each by the Bayesian
//!    information criterion `BIC = chi^2 + k ln n` (Schwarz 1978) and by
//!    K-fold cross-validation over held-out poses, and declares an effect only
//!    when the evidence is strong (`BIC` lower than the baseline's by at least
//!    [`DiagnoseOptions::min_bic_drop`], 10 = "very strong" on the Kass &
//!    Raftery 1995 scale, and a lower held-out residual); otherwise `none`;
//! 4. reports the verdict, the effect's parameters with 1-sigma, and the gain:
//!    held-out residual RMS before and after and, given the truth, anchor and
//!    offset errors before and after.
//!
//! Held-out residual: for each fold the model is re-fitted without the
//! fold's poses; each held-out pose's own variables (pose, reference tension)
//! are then fitted to its measurements with the anchors, offsets and effect
//! parameters held, and its whitened measurement residuals (encoders, load
//! cell, localiser) are collected. `cv_rms` is their root mean square (about 1
//! when the model and the stated noise are right).

mod candidates;
mod drivers;
mod report;
mod residual_tests;
mod selection;
pub mod verify;

use crate::calib::{calibrate, CalibrationGraph, CalibrationOptions, CalibrationResult};
use crate::error::{Error, Result};
use crate::model::effects::EffectKind;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::stats::{self, chi_square_quantile_999};

pub use candidates::{CandidateFit, ParameterValue};
pub use drivers::{DriverSeries, DriverTest, DRIVERS, DRIVER_T_LIMIT};
pub use report::{error_over_sigma, Diagnosis, Gain};
pub use residual_tests::{FactorTest, MEASUREMENT_KINDS};

use candidates::{fit_candidates, rebuild};
use drivers::{driver_series, driver_tests, samples};
use residual_tests::{factor_tests, measurement_components, total_chi_square, variance_factor};
use selection::{choose, cross_validate};

/// How to diagnose.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// The baseline calibration's options (their `free_effect` is ignored).
    pub calibration: CalibrationOptions,
    /// The candidate extensions to fit.
    pub candidates: Vec<EffectKind>,
    /// Folds of the cross-validation over poses (>= 2).
    pub folds: usize,
    /// How much lower than the baseline's a candidate's BIC must be to declare it.
    pub min_bic_drop: f64,
}

impl DiagnoseOptions {
    /// Every candidate of the catalogue, 5 folds, a BIC drop of 10.
    pub fn new(calibration: CalibrationOptions) -> Self {
        Self {
            calibration,
            candidates: EffectKind::ALL.to_vec(),
            folds: 5,
            min_bic_drop: 10.0,
        }
    }
}

/// The progress of a diagnosis: `report(done, total, what)` before each fit.
struct Progress<'a> {
    done: usize,
    total: usize,
    report: &'a mut dyn FnMut(usize, usize, &str),
}

impl Progress<'_> {
    /// Report `what` as the next step.
    fn step(&mut self, what: &str) {
        (self.report)(self.done, self.total, what);
        self.done += 1;
    }

    /// Count `steps` steps as done without reporting them.
    fn skip(&mut self, steps: usize) {
        self.done += steps;
    }

    /// Report the end.
    fn finish(&mut self) {
        (self.report)(self.total, self.total, "done");
    }
}

/// The baseline model fitted to the data: the calibration, the poses it
/// used, its graph at the fit and the quantities every comparison needs.
struct Baseline {
    /// The baseline calibration.
    result: CalibrationResult,
    /// Its options with the orientation prior resolved.
    options: CalibrationOptions,
    /// The measurements of the poses it used.
    used: Vec<PoseMeasurement>,
    /// Its graph at the fit.
    graph: CalibrationGraph,
    /// Measurement residual components `n`.
    components: usize,
    /// Unknowns of the baseline: 8 per pose and 16 global.
    unknowns: usize,
    /// Chi-square over all factors.
    chi_square: f64,
    /// Degrees of freedom (measurements + statics constraints - unknowns).
    dof: usize,
    /// The a posteriori variance factor (1 unless the data are more precise than stated).
    variance_factor: f64,
    /// The baseline's BIC.
    bic: f64,
}

impl Baseline {
    /// Calibrate with the baseline model (`options.calibration` without a free effect).
    fn fit(
        robot: &Robot,
        measurements: &[PoseMeasurement],
        options: &DiagnoseOptions,
        progress: &mut Progress<'_>,
    ) -> Result<Self> {
        let base_options = CalibrationOptions {
            free_effect: None,
            ..options.calibration
        };
        progress.step("baseline calibration");
        let result = calibrate(robot, measurements, &base_options)?;
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
        };
        base.bic = base.bic_of(chi_square, 0);
        Ok(base)
    }

    /// The BIC of a fit with chi-square `chi` and `added` parameters more than the baseline.
    fn bic_of(&self, chi: f64, added: usize) -> f64 {
        stats::bic(chi, self.variance_factor, self.unknowns + added, self.components)
    }
}

/// Diagnose `measurements` of `robot` (the initial guess; its `[effects]` are
/// known inputs), optionally against the `truth`. `progress(done, total, what)`
/// is called before each fit.
pub fn diagnose(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    truth: Option<&Robot>,
    options: &DiagnoseOptions,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<Diagnosis> {
    if options.folds < 2 {
        return Err(Error::InvalidInput(format!(
            "diagnose: at least 2 cross-validation folds are needed, got {}",
            options.folds
        )));
    }
    let total = (1 + options.candidates.len()) * (1 + options.folds);
    let mut progress = Progress {
        done: 0,
        total,
        report: progress,
    };
    // 1. The baseline calibration, its residuals tested against the stated noise.
    let base = Baseline::fit(robot, measurements, options, &mut progress)?;
    let factor_tests = factor_tests(&base.graph.graph, base.components, base.dof);
    // 2. The residuals against the physical drivers.
    let base_samples = samples(&base.result, &base.used, &base.graph)?;
    let drivers = driver_tests(&base_samples);
    let baseline_cv = cross_validate(&base.result, &base.used, &base.options, options.folds, &mut |what| {
        progress.step(&format!("baseline: {what}"))
    })?;
    // 3. Every candidate fitted and scored; the verdict.
    let (candidates, fits) = fit_candidates(&base, measurements, truth, options, &mut progress);
    progress.finish();
    let choice = choose(&candidates, baseline_cv, options.min_bic_drop);
    // 4. The report: what the verdict's extension gains, and the structure left.
    let winner_fit = choice
        .winner
        .and_then(|i| fits.iter().find(|(k, _)| k.name() == candidates[i].effect));
    let after = winner_fit.map_or(&base.result, |(_, r)| r);
    let cv_after = choice.winner.map_or(baseline_cv, |i| candidates[i].cv_rms);
    let gain = report::gain(truth, &base.result.robot, &after.robot, baseline_cv, cv_after);
    let (drivers_after, series) = match winner_fit {
        Some((kind, result)) => {
            let candidate_options = CalibrationOptions {
                free_effect: Some(*kind),
                ..base.options
            };
            let after_samples = samples(result, &base.used, &rebuild(result, &base.used, &candidate_options))?;
            let series = driver_series(&drivers, &base_samples, Some((*kind, &after_samples)));
            (driver_tests(&after_samples), series)
        }
        None => (Vec::new(), driver_series(&drivers, &base_samples, None)),
    };
    Ok(Diagnosis {
        robot: robot.name.clone(),
        poses_used: base.used.len(),
        measurement_components: base.components,
        baseline_chi_square: base.chi_square,
        baseline_dof: base.dof,
        baseline_consistent: base.chi_square <= chi_square_quantile_999(base.dof),
        variance_factor: base.variance_factor,
        factor_tests,
        drivers,
        drivers_after,
        baseline_bic: base.bic,
        baseline_cv_rms: baseline_cv,
        candidates,
        verdict: choice.verdict,
        reason: choice.reason,
        gain,
        baseline_error_over_sigma: truth.map(|t| error_over_sigma(&base.result.robot, t, &base.result.uncertainty)),
        robot_after: after.robot.clone(),
        series,
    })
}

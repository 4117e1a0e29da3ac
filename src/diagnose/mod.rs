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

pub mod verify;

use nalgebra::Vector3;
use serde::Serialize;

use crate::calib::{
    build_graph, calibrate, refine_with_effect, CableModel, CalibrationError, CalibrationGraph, CalibrationOptions,
    CalibrationResult, EffectEstimate, ParameterUncertainty,
};
use crate::error::{Error, Result};
use crate::graph::{whitened_squared_norm, FactorGraph, VariableValue};
use crate::model::effects::EffectKind;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{self, CableTension};
use crate::solver::optimize;
use crate::stats::{self, chi_square_quantile_001, chi_square_quantile_999, correlation};

/// The factor types that are measurements (the others are model constraints).
pub const MEASUREMENT_KINDS: [&str; 3] = ["catenary_length", "reference_tension", "pose_prior"];

/// Two-sided p < 0.001 for a correlation's t statistic (normal approximation).
pub const DRIVER_T_LIMIT: f64 = 3.29;

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

/// Chi-square test of one factor type's normalised residuals against the stated noise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FactorTest {
    /// Factor type (`catenary_length`, `reference_tension`, `pose_prior`).
    pub kind: String,
    /// Residual components.
    pub components: usize,
    /// Sum of `(r / sigma)^2`.
    pub chi_square: f64,
    /// Its expectation: the components times the fit's overall `dof / components`.
    pub expected: f64,
    /// The 99.9 % quantile of chi-square with `expected` degrees of freedom.
    pub limit: f64,
    /// `chi_square <= limit`.
    pub consistent: bool,
}

/// Correlation of one residual with one physical driver over the poses (and cables).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriverTest {
    /// The residual (`encoder`, `load_cell`, `position_x|y|z`), normalised by its sigma.
    pub residual: String,
    /// The driver (see [`DRIVERS`]).
    pub driver: String,
    /// Number of points.
    pub points: usize,
    /// Pearson correlation.
    pub correlation: f64,
    /// `r sqrt((n - 2) / (1 - r^2))`.
    pub t_statistic: f64,
    /// `|t| > 3.29`: the residual carries structure along this driver.
    pub significant: bool,
}

/// One estimated parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterValue {
    /// Name ([`EffectKind::parameter_names`]).
    pub name: String,
    /// Estimate.
    pub value: f64,
    /// 1-sigma (NaN when not observable).
    pub sigma: f64,
}

/// One candidate extension, fitted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateFit {
    /// The effect's name.
    pub effect: String,
    /// Estimated parameters (empty when the fit failed).
    pub params: Vec<ParameterValue>,
    /// Parameters added to the baseline.
    pub added_parameters: usize,
    /// Sum of squared normalised residuals at the fit.
    pub chi_square: f64,
    /// `chi_square + k ln n`.
    pub bic: f64,
    /// `bic - baseline bic` (negative: preferred over the baseline).
    pub delta_bic: f64,
    /// Held-out residual RMS (normalised).
    pub cv_rms: f64,
    /// Whether the solver converged.
    pub converged: bool,
    /// Mean absolute anchor-coordinate error against the truth, metres.
    pub anchor_mae_m: Option<f64>,
    /// Why the fit failed, if it did.
    pub error: Option<String>,
    /// `None` when the estimate is physically possible; else why not (e.g. a
    /// negative pulley radius): such a fit only mimics another effect and is
    /// never declared.
    pub inadmissible: Option<String>,
}

/// Why an estimate is physically impossible (a negative compliance or pulley
/// radius, more than 3 sigma below zero), if it is.
fn inadmissible(estimate: &EffectEstimate) -> Option<String> {
    if estimate.sigmas.iter().any(|s| !s.is_finite()) {
        return Some("not identifiable from these poses (singular information matrix)".into());
    }
    let (value, sigma) = (estimate.values[0], estimate.sigmas[0]);
    let what = match estimate.effect {
        EffectKind::Elastic => "axial compliance",
        EffectKind::Pulley => "pulley radius",
        _ => return None,
    };
    (value < -3.0 * sigma.max(0.0) || (value < 0.0 && !sigma.is_finite()))
        .then(|| format!("negative {what} ({value:.3e} +- {sigma:.1e})"))
}

/// What the chosen extension gains.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gain {
    /// Held-out normalised residual RMS of the baseline.
    pub residual_rms_before: f64,
    /// Held-out normalised residual RMS of the verdict's model (the baseline's for `none`).
    pub residual_rms_after: f64,
    /// Mean absolute anchor-coordinate error of the baseline against the truth, metres.
    pub anchor_mae_before_m: Option<f64>,
    /// The same for the verdict's model.
    pub anchor_mae_after_m: Option<f64>,
    /// Mean Euclidean anchor error of the baseline, metres (Table II's metric).
    pub anchor_mean_euclidean_before_m: Option<f64>,
    /// The same for the verdict's model.
    pub anchor_mean_euclidean_after_m: Option<f64>,
    /// Mean absolute length-offset error of the baseline, metres.
    pub offset_mae_before_m: Option<f64>,
    /// The same for the verdict's model.
    pub offset_mae_after_m: Option<f64>,
}

/// Normalised residuals against one driver, before and after the extension (for plots).
#[derive(Debug, Clone, PartialEq)]
pub struct DriverSeries {
    /// Residual name.
    pub residual: String,
    /// Driver name with unit.
    pub driver: String,
    /// `(driver, residual / sigma)` with the baseline model.
    pub before: Vec<(f64, f64)>,
    /// The same with the verdict's model (`None` for `none`).
    pub after: Option<Vec<(f64, f64)>>,
}

/// The diagnosis of one dataset.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnosis {
    /// Robot name.
    pub robot: String,
    /// Poses used (those with an equilibrium).
    pub poses_used: usize,
    /// Measurement residual components `n` (encoders, load cell, localiser).
    pub measurement_components: usize,
    /// Baseline chi-square over all factors.
    pub baseline_chi_square: f64,
    /// Its degrees of freedom (measurements + statics constraints - unknowns).
    pub baseline_dof: usize,
    /// Whether the baseline's chi-square is within the 99.9 % quantile.
    pub baseline_consistent: bool,
    /// The a posteriori variance factor dividing every chi-square in the BIC
    /// (1 unless the data are more precise than the stated noise).
    pub variance_factor: f64,
    /// Per factor type.
    pub factor_tests: Vec<FactorTest>,
    /// Residual-driver correlations of the baseline, strongest first.
    pub drivers: Vec<DriverTest>,
    /// The same with the verdict's model (empty for `none`): the structure left.
    pub drivers_after: Vec<DriverTest>,
    /// Baseline BIC.
    pub baseline_bic: f64,
    /// Baseline held-out residual RMS.
    pub baseline_cv_rms: f64,
    /// Every candidate.
    pub candidates: Vec<CandidateFit>,
    /// The effect found, or `none`.
    pub verdict: String,
    /// Why, in one sentence.
    pub reason: String,
    /// What the verdict's extension gains.
    pub gain: Gain,
    /// Given the truth: the baseline's anchor error over its stated 1-sigma
    /// ([`error_over_sigma`]); above 1 the model error is visible in the anchors.
    pub baseline_error_over_sigma: Option<f64>,
    /// The verdict's calibrated robot (anchors, offsets, effects); the baseline's for `none`.
    #[serde(skip)]
    pub robot_after: Robot,
    /// Residual against the winning driver (or the strongest, for `none`).
    #[serde(skip)]
    pub series: DriverSeries,
}

/// Per pose of a fitted model: the drivers and normalised residuals.
#[derive(Debug, Clone, PartialEq)]
struct PoseSample {
    /// Per cable: driver values in the order of [`DRIVERS`].
    cable_drivers: [[f64; CABLE_DRIVER_COUNT]; CABLE_COUNT],
    /// Platform position, metres.
    position_m: Vector3<f64>,
    /// Measured load-cell tension, newtons.
    measured_tension_n: f64,
    /// Encoder residual / sigma, per cable.
    encoder: [f64; CABLE_COUNT],
    /// Load-cell residual / sigma.
    load_cell: f64,
    /// Localiser position residual / sigma.
    position: [f64; 3],
}

const CABLE_DRIVER_COUNT: usize = 7;

/// The per-cable drivers, with units.
pub const DRIVERS: [&str; CABLE_DRIVER_COUNT] = [
    "tension at the pulley (N)",
    "tension x length (kN m)",
    "cable length (m)",
    "mid-span sag (m)",
    "elevation (deg)",
    "pulley wrap angle (deg)",
    "platform height (m)",
];

/// The driver and residual that show `effect` best.
fn winning_driver(effect: EffectKind) -> (&'static str, &'static str) {
    match effect {
        EffectKind::Elastic => ("encoder", DRIVERS[1]),
        EffectKind::Pulley => ("encoder", DRIVERS[5]),
        EffectKind::EncoderScale => ("encoder", DRIVERS[2]),
        EffectKind::LoadCell => ("load_cell", "measured tension (N)"),
        EffectKind::Com => ("encoder", DRIVERS[0]),
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
    let mut done = 0;
    let mut step = |what: &str, done: &mut usize| {
        progress(*done, total, what);
        *done += 1;
    };
    let base_options = CalibrationOptions {
        free_effect: None,
        ..options.calibration
    };
    step("baseline calibration", &mut done);
    let baseline = calibrate(robot, measurements, &base_options)?;
    let resolved = base_options.as_used_by(&baseline);
    let used: Vec<PoseMeasurement> = (0..measurements.len())
        .filter(|k| !baseline.excluded_poses.contains(k))
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

    let base_graph = rebuild(&baseline, &used, &resolved);
    let n = measurement_components(&base_graph.graph);
    let unknowns = 8 * used.len() + 4 * CABLE_COUNT;
    let constraints = CABLE_COUNT * used.len();
    let base_chi = total_chi_square(&base_graph.graph);
    let dof = (n + constraints).saturating_sub(unknowns).max(1);
    // A posteriori variance factor (geodesy's "variance of unit weight"): when
    // the baseline's chi-square is below the 0.1 % quantile for its degrees of
    // freedom the data are more precise than the stated noise (e.g. simulated
    // data without noise), and the information criteria use the residual
    // scale the data show, `chi^2 / s^2` with `s^2 = chi^2 / dof`. Never
    // scaled up: a too-large chi-square is what the candidates must explain.
    let variance_factor = if base_chi < chi_square_quantile_001(dof) {
        base_chi / dof as f64
    } else {
        1.0
    };
    let bic = |chi: f64, added: usize| stats::bic(chi, variance_factor, unknowns + added, n);
    let baseline_bic = bic(base_chi, 0);
    let factor_tests = factor_tests(&base_graph.graph, n, dof);
    let base_samples = samples(&baseline, &used, &base_graph)?;
    let drivers = driver_tests(&base_samples);
    let baseline_cv = cross_validate(&baseline, &used, &resolved, options.folds, &mut |what| {
        step(&format!("baseline: {what}"), &mut done)
    })?;

    let mut candidates = Vec::new();
    let mut fits: Vec<(EffectKind, CalibrationResult)> = Vec::new();
    for &kind in &options.candidates {
        step(&format!("fit {kind}"), &mut done);
        let candidate_options = CalibrationOptions {
            free_effect: Some(kind),
            ..resolved
        };
        let fitted = refine_with_effect(&baseline, measurements, &candidate_options).and_then(|result| {
            let cv = cross_validate(&result, &used, &candidate_options, options.folds, &mut |what| {
                step(&format!("{kind}: {what}"), &mut done)
            })?;
            Ok((result, cv))
        });
        match fitted {
            Ok((result, cv_rms)) => {
                let graph = rebuild(&result, &used, &candidate_options);
                let chi = total_chi_square(&graph.graph);
                let estimate = result.effect_estimate.clone().expect("refine_with_effect sets it");
                candidates.push(CandidateFit {
                    effect: kind.name().to_string(),
                    params: parameters(&estimate),
                    added_parameters: kind.parameter_count(),
                    chi_square: chi,
                    bic: bic(chi, kind.parameter_count()),
                    delta_bic: bic(chi, kind.parameter_count()) - baseline_bic,
                    cv_rms,
                    converged: result.converged(),
                    anchor_mae_m: truth.map(|t| CalibrationError::between(&result.robot, t).anchor_coordinate_mae_m),
                    error: None,
                    inadmissible: inadmissible(&estimate),
                });
                fits.push((kind, result));
            }
            Err(e) => {
                done += options.folds;
                candidates.push(CandidateFit {
                    effect: kind.name().to_string(),
                    params: Vec::new(),
                    added_parameters: kind.parameter_count(),
                    chi_square: f64::NAN,
                    bic: f64::NAN,
                    delta_bic: f64::NAN,
                    cv_rms: f64::NAN,
                    converged: false,
                    anchor_mae_m: None,
                    error: Some(e.to_string()),
                    inadmissible: None,
                })
            }
        }
    }
    progress(total, total, "done");

    // The verdict: the lowest BIC among candidates that beat the baseline by
    // `min_bic_drop` and predict held-out poses better.
    let winner = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| {
            c.converged && c.inadmissible.is_none() && c.delta_bic <= -options.min_bic_drop && c.cv_rms < baseline_cv
        })
        .min_by(|a, b| a.1.bic.total_cmp(&b.1.bic))
        .map(|(i, _)| i);
    let best_other = candidates
        .iter()
        .filter(|c| c.delta_bic.is_finite() && c.inadmissible.is_none())
        .min_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic));
    let (verdict, reason) = match winner {
        Some(i) => {
            let c = &candidates[i];
            (
                c.effect.clone(),
                format!(
                    "{} lowers the BIC by {:.1} (threshold {:.0}) with {} parameter(s) and the held-out residual RMS from {:.3} to {:.3}",
                    c.effect, -c.delta_bic, options.min_bic_drop, c.added_parameters, baseline_cv, c.cv_rms
                ),
            )
        }
        None => (
            "none".to_string(),
            match best_other {
                Some(c) => format!(
                    "no candidate is significant: the best, {}, changes the BIC by {:+.1} (needs <= -{:.0}) and the held-out residual RMS from {:.3} to {:.3}",
                    c.effect, c.delta_bic, options.min_bic_drop, baseline_cv, c.cv_rms
                ),
                None => "no candidate could be fitted".to_string(),
            },
        ),
    };
    let winner_fit = winner.and_then(|i| fits.iter().find(|(k, _)| k.name() == candidates[i].effect));
    let after = winner_fit.map_or(&baseline, |(_, r)| r);
    let error = |r: &Robot| truth.map(|t| CalibrationError::between(r, t));
    let (before_error, after_error) = (error(&baseline.robot), error(&after.robot));
    let gain = Gain {
        residual_rms_before: baseline_cv,
        residual_rms_after: winner.map_or(baseline_cv, |i| candidates[i].cv_rms),
        anchor_mae_before_m: before_error.map(|e| e.anchor_coordinate_mae_m),
        anchor_mae_after_m: after_error.map(|e| e.anchor_coordinate_mae_m),
        anchor_mean_euclidean_before_m: before_error.map(|e| e.anchor_mean_euclidean_m),
        anchor_mean_euclidean_after_m: after_error.map(|e| e.anchor_mean_euclidean_m),
        offset_mae_before_m: before_error.map(|e| e.offset_mae_m),
        offset_mae_after_m: after_error.map(|e| e.offset_mae_m),
    };
    let mut drivers_after = Vec::new();
    let series = match winner_fit {
        Some((kind, result)) => {
            let candidate_options = CalibrationOptions {
                free_effect: Some(*kind),
                ..resolved
            };
            let after_samples = samples(result, &used, &rebuild(result, &used, &candidate_options))?;
            drivers_after = driver_tests(&after_samples);
            let (residual, driver) = winning_driver(*kind);
            let driver = if *kind == EffectKind::Com {
                strongest_driver(&drivers, "encoder")
            } else {
                driver
            };
            DriverSeries {
                residual: residual.to_string(),
                driver: driver.to_string(),
                before: series_of(&base_samples, residual, driver),
                after: Some(series_of(&after_samples, residual, driver)),
            }
        }
        None => {
            let strongest = drivers.first();
            let residual = strongest.map_or("encoder", |d| d.residual.as_str());
            let driver = strongest.map_or(DRIVERS[0], |d| d.driver.as_str());
            DriverSeries {
                residual: residual.to_string(),
                driver: driver.to_string(),
                before: series_of(&base_samples, residual, driver),
                after: None,
            }
        }
    };
    Ok(Diagnosis {
        robot: robot.name.clone(),
        poses_used: used.len(),
        measurement_components: n,
        baseline_chi_square: base_chi,
        baseline_dof: dof,
        baseline_consistent: base_chi <= chi_square_quantile_999(dof),
        variance_factor,
        factor_tests,
        drivers,
        drivers_after,
        baseline_bic,
        baseline_cv_rms: baseline_cv,
        candidates,
        verdict,
        reason,
        gain,
        baseline_error_over_sigma: truth.map(|t| error_over_sigma(&baseline.robot, t, &baseline.uncertainty)),
        robot_after: after.robot.clone(),
        series,
    })
}

/// Mean over anchors of `|error| / sqrt(trace Sigma)` (NaN without a full-rank covariance).
pub fn error_over_sigma(estimate: &Robot, truth: &Robot, uncertainty: &ParameterUncertainty) -> f64 {
    match crate::calib::anchor_rms_bound_m(uncertainty) {
        Some(bounds) => {
            (0..CABLE_COUNT)
                .map(|i| (estimate.anchors_m[i] - truth.anchors_m[i]).norm() / bounds[i])
                .sum::<f64>()
                / CABLE_COUNT as f64
        }
        None => f64::NAN,
    }
}

fn parameters(estimate: &EffectEstimate) -> Vec<ParameterValue> {
    estimate
        .names
        .iter()
        .zip(&estimate.values)
        .zip(&estimate.sigmas)
        .map(|((name, value), sigma)| ParameterValue {
            name: name.clone(),
            value: *value,
            sigma: *sigma,
        })
        .collect()
}

/// The graph of a fitted calibration (values at the fit), with the effect's
/// variable set from its estimate (the robot file's effects cannot hold a
/// negative compliance).
fn rebuild(result: &CalibrationResult, used: &[PoseMeasurement], options: &CalibrationOptions) -> CalibrationGraph {
    let mut built = build_graph(
        &result.robot,
        used,
        &result.poses,
        &result.reference_tensions(),
        CableModel::Catenary,
        options,
    );
    if let (Some(vars), Some(estimate)) = (built.effects, &result.effect_estimate) {
        built.graph.values.set(
            vars.of(estimate.effect),
            VariableValue::Vector(nalgebra::DVector::from_vec(estimate.variable_values())),
        );
    }
    built
}

fn measurement_components(graph: &FactorGraph) -> usize {
    graph
        .factors
        .iter()
        .filter(|f| MEASUREMENT_KINDS.contains(&f.kind()))
        .map(|f| f.residual_dim())
        .sum()
}

/// Chi-square of the measurement and statics factors (not the inactive tension guard).
fn total_chi_square(graph: &FactorGraph) -> f64 {
    graph
        .factors
        .iter()
        .filter(|f| f.kind() != "tension_guard")
        .filter_map(|f| {
            f.evaluate(&graph.values, None)
                .map(|r| whitened_squared_norm(&r, f.sigmas()))
        })
        .sum()
}

fn factor_tests(graph: &FactorGraph, components: usize, dof: usize) -> Vec<FactorTest> {
    MEASUREMENT_KINDS
        .iter()
        .map(|kind| {
            let mut count = 0;
            let mut chi = 0.0;
            for f in graph.factors.iter().filter(|f| f.kind() == *kind) {
                if let Some(r) = f.evaluate(&graph.values, None) {
                    count += r.len();
                    chi += whitened_squared_norm(&r, f.sigmas());
                }
            }
            let expected = count as f64 * dof as f64 / components.max(1) as f64;
            let limit = chi_square_quantile_999(expected.round().max(1.0) as usize);
            FactorTest {
                kind: kind.to_string(),
                components: count,
                chi_square: chi,
                expected,
                limit,
                consistent: chi <= limit,
            }
        })
        .collect()
}

/// Drivers and normalised residuals of every pose of a fitted model.
fn samples(result: &CalibrationResult, used: &[PoseMeasurement], built: &CalibrationGraph) -> Result<Vec<PoseSample>> {
    let graph = &built.graph;
    let normalised = |kind: &str| -> Vec<Vec<f64>> {
        graph
            .factors
            .iter()
            .filter(|f| f.kind() == kind)
            .map(|f| {
                let r = f
                    .evaluate(&graph.values, None)
                    .unwrap_or_else(|| nalgebra::DVector::from_element(f.residual_dim(), f64::NAN));
                r.iter().zip(f.sigmas().iter()).map(|(r, s)| r / s).collect()
            })
            .collect()
    };
    let encoders = normalised("catenary_length");
    let cells = normalised("reference_tension");
    let priors = normalised("pose_prior");
    let robot = &result.robot;
    let references = result.reference_tensions();
    (0..used.len())
        .map(|k| {
            let pose = &result.poses[k];
            let tensions = statics::cable_tensions(robot, pose, references[k])?;
            let cables = statics::catenaries(robot, pose, &tensions);
            let geometry = statics::cable_geometry(robot, pose);
            let cable_drivers = std::array::from_fn(|i| {
                let c = &cables[i];
                let length = c.length_m();
                let top_vertical = c.anchor_vertical_tension_n();
                let top = c.horizontal_tension_n.hypot(top_vertical);
                let sag = robot.cable_weight_n_per_m * c.span_m * c.span_m / (8.0 * c.horizontal_tension_n);
                [
                    top,
                    top * length / 1e3,
                    length,
                    sag,
                    geometry[i].height_difference_m.atan2(geometry[i].span_m).to_degrees(),
                    (std::f64::consts::FRAC_PI_2 + (top_vertical / c.horizontal_tension_n).atan()).to_degrees(),
                    pose.position_m.z,
                ]
            });
            let prior = &priors[k];
            let position_rows = prior.len() - 3;
            Ok(PoseSample {
                cable_drivers,
                position_m: pose.position_m,
                measured_tension_n: used[k].reference_tension_n,
                encoder: std::array::from_fn(|i| encoders[k][i]),
                load_cell: cells[k][0],
                position: std::array::from_fn(|i| prior[position_rows + i]),
            })
        })
        .collect()
}

/// `(driver, residual)` points of one residual against one driver.
fn series_of(samples: &[PoseSample], residual: &str, driver: &str) -> Vec<(f64, f64)> {
    let mut points = Vec::new();
    for s in samples {
        let pose_driver = match driver {
            "measured tension (N)" => Some(s.measured_tension_n),
            "platform x (m)" => Some(s.position_m.x),
            "platform y (m)" => Some(s.position_m.y),
            _ => None,
        };
        match residual {
            "encoder" => {
                for i in 0..CABLE_COUNT {
                    let x = pose_driver
                        .or_else(|| DRIVERS.iter().position(|d| *d == driver).map(|d| s.cable_drivers[i][d]));
                    if let Some(x) = x {
                        points.push((x, s.encoder[i]));
                    }
                }
            }
            other => {
                let y = match other {
                    "load_cell" => s.load_cell,
                    "position_x" => s.position[0],
                    "position_y" => s.position[1],
                    _ => s.position[2],
                };
                let x = pose_driver.or_else(|| {
                    DRIVERS
                        .iter()
                        .position(|d| *d == driver)
                        .map(|d| s.cable_drivers.iter().map(|c| c[d]).sum::<f64>() / CABLE_COUNT as f64)
                });
                if let Some(x) = x {
                    points.push((x, y));
                }
            }
        }
    }
    points
}

fn driver_tests(samples: &[PoseSample]) -> Vec<DriverTest> {
    let residuals = ["encoder", "load_cell", "position_x", "position_y", "position_z"];
    let mut drivers: Vec<&str> = DRIVERS.to_vec();
    drivers.extend(["measured tension (N)", "platform x (m)", "platform y (m)"]);
    let mut tests = Vec::new();
    for residual in residuals {
        for driver in &drivers {
            let points = series_of(samples, residual, driver);
            let (r, t) = correlation(&points);
            if r.is_finite() {
                tests.push(DriverTest {
                    residual: residual.to_string(),
                    driver: driver.to_string(),
                    points: points.len(),
                    correlation: r,
                    t_statistic: t,
                    significant: t.abs() > DRIVER_T_LIMIT,
                });
            }
        }
    }
    tests.sort_by(|a, b| b.t_statistic.abs().total_cmp(&a.t_statistic.abs()));
    tests
}

fn strongest_driver<'a>(drivers: &'a [DriverTest], residual: &str) -> &'a str {
    drivers
        .iter()
        .find(|d| d.residual == residual)
        .map_or(DRIVERS[0], |d| d.driver.as_str())
}

/// K-fold cross-validation of a fitted model over poses (module docs):
/// the held-out normalised measurement residual RMS.
fn cross_validate(
    fit: &CalibrationResult,
    used: &[PoseMeasurement],
    options: &CalibrationOptions,
    folds: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<f64> {
    let mut sum = 0.0;
    let mut count = 0usize;
    let full = rebuild(fit, used, options);
    for fold in 0..folds {
        progress(&format!("cross-validation fold {}/{folds}", fold + 1));
        let (train, test): (Vec<usize>, Vec<usize>) = (0..used.len()).partition(|k| k % folds != fold);
        let subset = |indices: &[usize]| -> CalibrationGraph { subgraph(&full, fit, used, indices, options) };
        let mut trained = subset(&train);
        optimize(&mut trained.graph, &options.lm)
            .map_err(|e| Error::InvalidInput(format!("cross-validation fold {}: {e}", fold + 1)))?;
        let mut held_out = subset(&test);
        for id in global_ids(&trained) {
            held_out
                .graph
                .values
                .set(id, trained.graph.values.variable(id).value.clone());
            held_out.graph.values.set_fixed(id, true);
        }
        optimize(&mut held_out.graph, &options.lm)
            .map_err(|e| Error::InvalidInput(format!("cross-validation fold {} (held-out poses): {e}", fold + 1)))?;
        for f in held_out
            .graph
            .factors
            .iter()
            .filter(|f| MEASUREMENT_KINDS.contains(&f.kind()))
        {
            let r = f.evaluate(&held_out.graph.values, None).ok_or_else(|| {
                Error::NoEquilibrium(format!(
                    "cross-validation fold {}: a held-out pose went slack",
                    fold + 1
                ))
            })?;
            sum += whitened_squared_norm(&r, f.sigmas());
            count += r.len();
        }
    }
    Ok((sum / count.max(1) as f64).sqrt())
}

/// The graph of a subset of the poses, with every value (globals, effects,
/// poses, tensions) taken from `full` and the same variables free.
fn subgraph(
    full: &CalibrationGraph,
    fit: &CalibrationResult,
    used: &[PoseMeasurement],
    indices: &[usize],
    options: &CalibrationOptions,
) -> CalibrationGraph {
    let measurements: Vec<PoseMeasurement> = indices.iter().map(|&k| used[k]).collect();
    let poses: Vec<_> = indices.iter().map(|&k| fit.poses[k]).collect();
    let all_tensions = fit.reference_tensions();
    let tensions: Vec<CableTension> = indices.iter().map(|&k| all_tensions[k]).collect();
    let mut built = build_graph(
        &fit.robot,
        &measurements,
        &poses,
        &tensions,
        CableModel::Catenary,
        options,
    );
    for id in global_ids(&built) {
        built.graph.values.set(id, full.graph.values.variable(id).value.clone());
    }
    built
}

/// Anchors, offsets and effect parameters (ids are the same in every graph
/// built with the same options: they are inserted first).
fn global_ids(built: &CalibrationGraph) -> Vec<crate::graph::VariableId> {
    let mut ids: Vec<_> = built
        .globals
        .anchors
        .iter()
        .chain(&built.globals.length_offsets)
        .copied()
        .collect();
    if let Some(e) = built.effects {
        ids.extend(EffectKind::ALL.map(|k| e.of(k)));
    }
    ids
}

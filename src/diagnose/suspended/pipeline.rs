//! [`diagnose_suspended`]: the baseline's test, every extension fitted,
//! tested and cross-validated, and the verdict.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use serde::Serialize;

use super::extensions::{SuspendedExtension, NOT_MODELLED};
use super::held_out::cross_validated_chi_square;
use super::profile::{calibrate_with, fit_profile};
use super::residual_structure::{residual_structure, ResidualStructure, ResidualTerm, TermKey};
use super::truth::TruthError;
use crate::calib::CalibrationOptions;
use crate::error::{Error, Result};
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};
use crate::stats::chi_square_critical;

/// Two extensions are told apart when the sum of their poses' paired
/// held-out chi-square differences exceeds this many of its standard
/// errors (Vuong, *Econometrica* 57, 1989: the test of non-nested models
/// by their pointwise log-likelihood differences; here two-sided 5 %).
/// Closer than that, the readings cannot tell which of them acts.
pub const INDISTINGUISHABLE_Z: f64 = 1.96;

/// How the diagnosis is run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedDiagnoseSettings {
    /// The extensions tried (default: every one that applies).
    pub extensions: Vec<SuspendedExtension>,
    /// Folds of the cross-validation over poses.
    pub folds: usize,
    /// The false-alarm rate of the baseline's test and of the whole search
    /// (shared by the extensions' tests, Bonferroni).
    pub false_alarm: f64,
}

/// The baseline model's fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedBaseline {
    /// Its chi-square.
    pub chi_square: f64,
    /// Its degrees of freedom.
    pub degrees_of_freedom: usize,
    /// The chi-square's `1 - false_alarm` quantile.
    pub limit: f64,
    /// Whether the chi-square is within it.
    pub passes: bool,
    /// The summed held-out chi-square ([`super::held_out`]).
    pub held_out_chi_square: f64,
    /// Per pose, its held-out chi-square.
    pub held_out_per_pose: Vec<f64>,
}

/// One extension's fit and scores.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedExtensionFit {
    /// The extension.
    pub extension: SuspendedExtension,
    /// Its parameter, with unit.
    pub parameter: String,
    /// The parameter's fitted value (NaN where the fit failed).
    pub value: f64,
    /// Its 1-sigma.
    pub sigma: f64,
    /// The chi-square with the parameter fitted.
    pub chi_square: f64,
    /// The likelihood ratio `chi2(baseline) - chi2(extension)`.
    pub likelihood_ratio: f64,
    /// Whether it exceeds the one-degree-of-freedom quantile at the search's share of the false-alarm rate.
    pub significant: bool,
    /// The summed held-out chi-square, the parameter fitted on each fold's training poses.
    pub held_out_chi_square: f64,
    /// The baseline's held-out chi-square less this one: what the extension predicts better.
    pub held_out_gain: f64,
    /// Per pose, its held-out chi-square (empty where the fit failed).
    pub held_out_per_pose: Vec<f64>,
    /// The values a real robot could have.
    pub plausible_range: String,
    /// Whether the fitted value is among them.
    pub plausible: bool,
    /// Whether the extended model passes the chi-square test.
    pub passes: bool,
    /// Why the fit failed.
    pub failure: Option<String>,
}

/// What the diagnosis concludes.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SuspendedVerdict {
    /// No extension is significant and better on held-out poses, and the
    /// baseline passes its test: no cause is named.
    Consistent,
    /// One extension is significant, predicts held-out poses better than
    /// the baseline and than every other (by [`INDISTINGUISHABLE_Z`]
    /// standard errors of [`paired_z`]), its value is physical, and the
    /// extended model passes the chi-square test.
    Named {
        /// The cause.
        extension: SuspendedExtension,
    },
    /// As `Named`, but its fitted value no real robot has: it stands in
    /// for a cause outside the catalogue.
    StandIn {
        /// The stand-in.
        extension: SuspendedExtension,
    },
    /// As `Named`, but the extended model still fails the chi-square test,
    /// or its residuals still hold a term it lacks
    /// ([`super::residual_structure`]): the extension takes up part of a
    /// misfit whose cause (or a second one) is outside the catalogue; it is
    /// not named as the cause.
    Partial {
        /// The extension that takes up part of the misfit.
        extension: SuspendedExtension,
    },
    /// Several extensions are significant and predict held-out poses alike.
    Indistinguishable {
        /// The extensions, best first.
        extensions: Vec<SuspendedExtension>,
    },
    /// The baseline fails its test and no extension is both significant and better on held-out poses.
    Unexplained,
}

/// The diagnosis of a robot of `N` cables.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedDiagnosis {
    /// The robot.
    pub robot: String,
    /// Its cables.
    pub cables: usize,
    /// Poses.
    pub poses: usize,
    /// The settings.
    pub settings: SuspendedDiagnoseSettings,
    /// The likelihood-ratio statistic's limit (one degree of freedom, Bonferroni).
    pub likelihood_ratio_limit: f64,
    /// The baseline.
    pub baseline: SuspendedBaseline,
    /// Every extension, in the settings' order.
    pub extensions: Vec<SuspendedExtensionFit>,
    /// The score tests of the baseline's residuals
    /// ([`super::residual_structure`]).
    pub baseline_structure: ResidualStructure,
    /// The score tests of the residuals of the model that would be named
    /// (`null` where none would be), with the drop of the baseline's
    /// describing terms in it.
    pub named_structure: Option<ResidualStructure>,
    /// The verdict.
    pub verdict: SuspendedVerdict,
    /// The verdict in words.
    pub conclusion: String,
    /// What the model cannot name.
    pub not_modelled: String,
    /// Where the truth is known, each model's anchors and offsets against
    /// it ([`super::errors_against_truth`]; empty otherwise).
    pub against_truth: Vec<TruthError>,
}

impl SuspendedDiagnosis {
    /// The models to compare with a truth ([`super::errors_against_truth`]):
    /// the baseline, then every extension that was fitted, at its fitted value.
    pub fn fitted_models(&self) -> Vec<(SuspendedExtension, f64)> {
        let baseline = (SuspendedExtension::Elastic, 0.0);
        let fitted = self
            .extensions
            .iter()
            .filter(|f| f.failure.is_none())
            .map(|f| (f.extension, f.value));
        std::iter::once(baseline).chain(fitted).collect()
    }
}

/// Diagnose `measurements` against `robot` (module docs of
/// [`super`]); `progress(done, total)` as fits finish.
pub fn diagnose_suspended(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    settings: &SuspendedDiagnoseSettings,
    options: &CalibrationOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<SuspendedDiagnosis> {
    validate(settings)?;
    let extensions: Vec<SuspendedExtension> = settings
        .extensions
        .iter()
        .copied()
        .filter(|e| e.applies_to(robot))
        .collect();
    let total = 2 * (1 + extensions.len());
    let done = AtomicUsize::new(0);
    let tick = || progress(done.fetch_add(1, Ordering::SeqCst) + 1, total);
    let baseline = baseline(robot, measurements, settings, options, &tick)?;
    let likelihood_ratio_limit = chi_square_critical(1, settings.false_alarm / extensions.len().max(1) as f64);
    let fits: Vec<SuspendedExtensionFit> = extensions
        .par_iter()
        .map(|&extension| {
            let scores = Scores {
                robot,
                measurements,
                options,
                baseline: &baseline,
                likelihood_ratio_limit,
                false_alarm: settings.false_alarm,
            };
            scores.fit(extension, settings.folds, &tick)
        })
        .collect();
    let structure = |extension: SuspendedExtension, value: f64, given: &[TermKey]| {
        residual_structure(
            robot,
            measurements,
            (extension, value),
            options,
            settings.false_alarm,
            given,
        )
    };
    let null = SuspendedExtension::Elastic;
    let baseline_structure = structure(null, null.null_value(), &[])?;
    let context = Checked {
        baseline_structure: &baseline_structure,
    };
    let checked = context.check(verdict(&baseline, &fits), &fits, &|fit, given| {
        structure(fit.extension, fit.value, given)
    })?;
    Ok(SuspendedDiagnosis {
        robot: robot.name.clone(),
        cables: robot.cable_count(),
        poses: measurements.len(),
        settings: settings.clone(),
        likelihood_ratio_limit,
        conclusion: conclusion(&checked, &baseline, &fits, &context),
        baseline,
        extensions: fits,
        baseline_structure,
        named_structure: checked.structure,
        verdict: checked.verdict,
        not_modelled: NOT_MODELLED.into(),
        against_truth: Vec::new(),
    })
}

/// Folds and false-alarm rate within reach.
fn validate(settings: &SuspendedDiagnoseSettings) -> Result<()> {
    if settings.folds < 2 {
        return Err(Error::InvalidInput(format!(
            "folds: {} folds cannot hold poses out; at least 2",
            settings.folds
        )));
    }
    if !(settings.false_alarm > 0.0 && settings.false_alarm < 0.5) {
        return Err(Error::InvalidInput(format!(
            "false_alarm: {} is not a rate in (0, 0.5)",
            settings.false_alarm
        )));
    }
    Ok(())
}

/// The baseline's fit, test and held-out score.
fn baseline(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    settings: &SuspendedDiagnoseSettings,
    options: &CalibrationOptions,
    tick: &(dyn Fn() + Sync),
) -> Result<SuspendedBaseline> {
    let null = SuspendedExtension::Elastic;
    let fit = calibrate_with(robot, measurements, null, null.null_value(), options)?;
    tick();
    let held_out_per_pose = cross_validated_chi_square(robot, measurements, null, false, settings.folds, options)?;
    tick();
    let chi_square = 2.0 * fit.final_cost;
    let limit = chi_square_critical(fit.degrees_of_freedom, settings.false_alarm);
    Ok(SuspendedBaseline {
        chi_square,
        degrees_of_freedom: fit.degrees_of_freedom,
        limit,
        passes: chi_square <= limit,
        held_out_chi_square: held_out_per_pose.iter().sum(),
        held_out_per_pose,
    })
}

/// What scoring an extension shares.
struct Scores<'a> {
    robot: &'a SuspendedRobot,
    measurements: &'a [SuspendedMeasurement],
    options: &'a CalibrationOptions,
    baseline: &'a SuspendedBaseline,
    likelihood_ratio_limit: f64,
    false_alarm: f64,
}

impl Scores<'_> {
    /// `extension` fitted on every pose, tested, and cross-validated; a
    /// failed fit is reported, not fatal.
    fn fit(&self, extension: SuspendedExtension, folds: usize, tick: &(dyn Fn() + Sync)) -> SuspendedExtensionFit {
        let mut row = SuspendedExtensionFit {
            extension,
            parameter: extension.parameter(),
            value: f64::NAN,
            sigma: f64::NAN,
            chi_square: f64::NAN,
            likelihood_ratio: f64::NAN,
            significant: false,
            held_out_chi_square: f64::NAN,
            held_out_gain: f64::NAN,
            held_out_per_pose: Vec::new(),
            plausible_range: extension.plausible_range(self.robot, self.measurements),
            plausible: false,
            passes: false,
            failure: None,
        };
        let fitted = fit_profile(self.robot, self.measurements, extension, self.options);
        tick();
        let held_out = cross_validated_chi_square(self.robot, self.measurements, extension, true, folds, self.options);
        tick();
        match (fitted, held_out) {
            (Ok(fit), Ok(held_out)) => {
                let dof = self.baseline.degrees_of_freedom.saturating_sub(1).max(1);
                row.value = fit.value;
                row.sigma = fit.sigma;
                row.chi_square = fit.chi_square;
                row.likelihood_ratio = self.baseline.chi_square - fit.chi_square;
                row.significant = row.likelihood_ratio > self.likelihood_ratio_limit;
                row.held_out_chi_square = held_out.iter().sum();
                row.held_out_gain = self.baseline.held_out_chi_square - row.held_out_chi_square;
                row.held_out_per_pose = held_out;
                row.plausible = extension.is_plausible(self.robot, self.measurements, fit.value);
                row.passes = fit.chi_square <= chi_square_critical(dof, self.false_alarm);
            }
            (Err(e), _) | (_, Err(e)) => row.failure = Some(e.to_string()),
        }
        row
    }
}

/// Whether `fit` is a candidate cause: significant and better on held-out poses.
fn is_candidate(fit: &SuspendedExtensionFit) -> bool {
    fit.failure.is_none() && fit.significant && fit.held_out_gain > 0.0
}

/// The verdict from the baseline and the extensions (see [`SuspendedVerdict`]).
fn verdict(baseline: &SuspendedBaseline, fits: &[SuspendedExtensionFit]) -> SuspendedVerdict {
    let mut candidates: Vec<&SuspendedExtensionFit> = fits.iter().filter(|f| is_candidate(f)).collect();
    candidates.sort_by(|a, b| a.held_out_chi_square.total_cmp(&b.held_out_chi_square));
    let Some(best) = candidates.first() else {
        return if baseline.passes {
            SuspendedVerdict::Consistent
        } else {
            SuspendedVerdict::Unexplained
        };
    };
    let alike: Vec<SuspendedExtension> = candidates
        .iter()
        .filter(|f| paired_z(&f.held_out_per_pose, &best.held_out_per_pose) < INDISTINGUISHABLE_Z)
        .map(|f| f.extension)
        .collect();
    let extension = best.extension;
    if alike.len() > 1 {
        SuspendedVerdict::Indistinguishable { extensions: alike }
    } else if !best.plausible {
        SuspendedVerdict::StandIn { extension }
    } else if !best.passes {
        SuspendedVerdict::Partial { extension }
    } else {
        SuspendedVerdict::Named { extension }
    }
}

/// The verdict once the residuals' score tests have spoken
/// ([`super::residual_structure`]).
struct CheckedVerdict {
    verdict: SuspendedVerdict,
    /// The named model's tests (`Named` before the check).
    structure: Option<ResidualStructure>,
}

/// What the check of a verdict reads.
struct Checked<'a> {
    baseline_structure: &'a ResidualStructure,
}

impl Checked<'_> {
    /// `verdict` checked against the residuals' score tests:
    /// - `Consistent` becomes `Unexplained` where the baseline's residuals
    ///   hold a term beyond the limit (a misfit the omnibus chi-square is
    ///   too blunt to see);
    /// - `Named` becomes `Partial` where the extended model does not explain
    ///   the terms that describe what the baseline lacks (they still take
    ///   more off it than their limit: the extension is a proxy that took
    ///   up part of them), or where its own residuals still hold a term
    ///   beyond the limit.
    ///
    /// `structure(fit, given)` runs the tests of an extension's model.
    fn check(
        &self,
        verdict: SuspendedVerdict,
        fits: &[SuspendedExtensionFit],
        structure: &dyn Fn(&SuspendedExtensionFit, &[TermKey]) -> Result<ResidualStructure>,
    ) -> Result<CheckedVerdict> {
        let unchanged = |verdict| CheckedVerdict {
            verdict,
            structure: None,
        };
        let extension = match verdict {
            SuspendedVerdict::Consistent if !self.baseline_structure.clean() => {
                return Ok(unchanged(SuspendedVerdict::Unexplained));
            }
            SuspendedVerdict::Named { extension } => extension,
            other => return Ok(unchanged(other)),
        };
        let fit = fits
            .iter()
            .find(|f| f.extension == extension)
            .expect("a verdict names a fit");
        let tested = structure(fit, &self.baseline_structure.describing_keys())?;
        let verdict = match tested.explains_given() && tested.clean() {
            true => SuspendedVerdict::Named { extension },
            false => SuspendedVerdict::Partial { extension },
        };
        Ok(CheckedVerdict {
            verdict,
            structure: Some(tested),
        })
    }
}

/// Vuong's statistic of `worse` against `better`: the sum of the poses'
/// held-out chi-square differences over its standard error from their
/// sample variance (0 for a model against itself).
pub fn paired_z(worse: &[f64], better: &[f64]) -> f64 {
    let differences: Vec<f64> = worse.iter().zip(better).map(|(w, b)| w - b).collect();
    let n = differences.len() as f64;
    let sum: f64 = differences.iter().sum();
    if n < 2.0 || sum == 0.0 {
        return 0.0;
    }
    let mean = sum / n;
    let variance = differences.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
    sum / (n * variance).sqrt()
}

/// The verdict in words.
fn conclusion(
    checked: &CheckedVerdict,
    baseline: &SuspendedBaseline,
    fits: &[SuspendedExtensionFit],
    context: &Checked<'_>,
) -> String {
    let fit_of = |e: SuspendedExtension| fits.iter().find(|f| f.extension == e).expect("a verdict names a fit");
    let cause = |e: SuspendedExtension| {
        let f = fit_of(e);
        format!(
            "{} ({} = {} +- {}) predicts the held-out poses better by {:.1} in chi-square",
            e.name(),
            f.parameter,
            e.value_text(f.value),
            e.value_text(f.sigma),
            f.held_out_gain
        )
    };
    let terms = |s: &ResidualStructure, terms: &[ResidualTerm]| {
        let listed: Vec<String> = terms.iter().take(3).map(ResidualTerm::describe).collect();
        format!(
            "{}; limit |z| {:.2} over {} terms",
            listed.join("; "),
            s.limit,
            s.tested
        )
    };
    let outside = "it takes up part of a misfit whose cause is outside this catalogue";
    match &checked.verdict {
        SuspendedVerdict::Consistent => format!(
            "the baseline model explains the readings (chi-square {:.1} for {}, limit {:.1}, and no term beyond the limit in its residuals): no cause is named",
            baseline.chi_square, baseline.degrees_of_freedom, baseline.limit
        ),
        SuspendedVerdict::Named { extension } => format!(
            "named cause: {}; the extended model passes the chi-square test (chi-square {:.1}) and its residuals hold no term beyond the limit",
            cause(*extension), fit_of(*extension).chi_square
        ),
        SuspendedVerdict::Partial { extension } if !fit_of(*extension).passes => format!(
            "no cause named: {} but the extended model still fails the chi-square test (chi-square {:.1}): {outside}, or a second cause is",
            cause(*extension), fit_of(*extension).chi_square
        ),
        SuspendedVerdict::Partial { extension } => match &checked.structure {
            Some(s) if !s.explains_given() => format!(
                "no cause named: {} and passes the chi-square test but leaves what the baseline lacked ({}): \
                 those terms still take {:.1} off its chi-square (limit {:.1}): {outside}",
                cause(*extension),
                terms(context.baseline_structure, &context.baseline_structure.describing),
                s.given_drop,
                s.given_limit
            ),
            Some(s) => format!(
                "no cause named: {} and passes the chi-square test but its residuals still hold what it lacks ({}): {outside}",
                cause(*extension),
                terms(s, &s.beyond)
            ),
            None => format!("no cause named: {}: {outside}", cause(*extension)),
        },
        SuspendedVerdict::StandIn { extension } => {
            let f = fit_of(*extension);
            format!(
                "stand-in: {} predicts the held-out poses best, but its fitted {} = {} is outside what a real robot has ({}): \
                 it stands in for a cause the model lacks, not named as the cause",
                extension.name(), f.parameter, extension.value_text(f.value), f.plausible_range
            )
        }
        SuspendedVerdict::Indistinguishable { extensions } => {
            let best = fit_of(extensions[0]);
            let still = if best.passes {
                String::new()
            } else {
                format!(
                    "; the best of them still fails the chi-square test (chi-square {:.1}): a cause outside this catalogue may be acting",
                    best.chi_square
                )
            };
            format!(
                "no cause named: the readings cannot tell apart {}: each is significant, and their held-out chi-squares, pose by pose, differ by less than {INDISTINGUISHABLE_Z} standard errors{still}",
                extensions.iter().map(|e| e.name()).collect::<Vec<_>>().join(", ")
            )
        }
        SuspendedVerdict::Unexplained if baseline.passes => format!(
            "the baseline passes the chi-square test (chi-square {:.1} for {}, limit {:.1}), but its residuals hold what it lacks ({}), \
             and no extension both passes its test and predicts the held-out poses better: the cause is outside this catalogue (for example {NOT_MODELLED})",
            baseline.chi_square, baseline.degrees_of_freedom, baseline.limit,
            terms(context.baseline_structure, &context.baseline_structure.beyond)
        ),
        SuspendedVerdict::Unexplained => format!(
            "the baseline fails (chi-square {:.1} for {}, limit {:.1}) and no extension both passes its test and predicts the held-out poses better: the cause is outside this catalogue (for example {NOT_MODELLED})",
            baseline.chi_square, baseline.degrees_of_freedom, baseline.limit
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tests of a model with `beyond` terms beyond the limit, the
    /// baseline's describing terms `describing`, and `given_drop` left of
    /// given terms (limit 10.83, one term at 1e-3).
    fn structure(beyond: usize, describing: usize, given_drop: f64) -> ResidualStructure {
        let term = ResidualTerm {
            reading: "encoder 3".into(),
            driver: "its reading (m)".into(),
            points: 30,
            coefficient: 0.005,
            sigma: 0.001,
            z: 5.0,
        };
        ResidualStructure {
            extension: SuspendedExtension::Elastic,
            value: 0.0,
            tested: 27,
            limit: 4.13,
            strongest: Some(term.clone()),
            beyond: vec![term.clone(); beyond],
            terms: vec![term.clone(); 27],
            describing: vec![term; describing],
            describing_drop: 25.0,
            given_drop,
            given_limit: 10.83,
        }
    }

    fn fit(extension: SuspendedExtension) -> SuspendedExtensionFit {
        SuspendedExtensionFit {
            extension,
            parameter: extension.parameter(),
            value: 1.25,
            sigma: 0.08,
            chi_square: 180.0,
            likelihood_ratio: 40.0,
            significant: true,
            held_out_chi_square: 300.0,
            held_out_gain: 30.0,
            held_out_per_pose: vec![10.0; 30],
            plausible_range: "0.50 .. 1.50".into(),
            plausible: true,
            passes: true,
            failure: None,
        }
    }

    /// The verdict `verdict` checked with the baseline's tests `baseline`
    /// and the named model's `named`.
    fn checked(verdict: SuspendedVerdict, baseline: &ResidualStructure, named: ResidualStructure) -> SuspendedVerdict {
        let weight = SuspendedExtension::OneCableWeight(2);
        let context = Checked {
            baseline_structure: baseline,
        };
        let run = |_: &SuspendedExtensionFit, given: &[TermKey]| {
            assert_eq!(given.len(), baseline.describing.len());
            Ok(named.clone())
        };
        context.check(verdict, &[fit(weight)], &run).unwrap().verdict
    }

    #[test]
    fn a_named_model_must_explain_what_the_baseline_lacked_and_leave_nothing() {
        let weight = SuspendedExtension::OneCableWeight(2);
        let named = SuspendedVerdict::Named { extension: weight };
        let partial = SuspendedVerdict::Partial { extension: weight };
        let baseline = structure(1, 1, 0.0);
        // It explains the baseline's term and leaves none: named.
        assert_eq!(checked(named.clone(), &baseline, structure(0, 0, 3.0)), named);
        // The baseline's term still takes 15.4 off it (limit 10.83): a proxy.
        assert_eq!(checked(named.clone(), &baseline, structure(0, 0, 15.4)), partial);
        // A term of its own beyond the limit.
        assert_eq!(checked(named.clone(), &baseline, structure(1, 0, 0.0)), partial);
    }

    #[test]
    fn a_consistent_baseline_must_leave_no_term() {
        let anything = structure(0, 0, 0.0);
        let consistent = SuspendedVerdict::Consistent;
        assert_eq!(
            checked(consistent.clone(), &structure(0, 0, 0.0), anything.clone()),
            consistent
        );
        assert_eq!(
            checked(consistent, &structure(2, 1, 0.0), anything.clone()),
            SuspendedVerdict::Unexplained
        );
        // Other verdicts pass as they are.
        let unexplained = SuspendedVerdict::Unexplained;
        assert_eq!(
            checked(unexplained.clone(), &structure(2, 1, 0.0), anything),
            unexplained
        );
    }
}

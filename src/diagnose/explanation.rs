//! Step 4b: is everything explained? After the selection the final model
//! must pass the per-sensor chi-square tests at the stated false-alarm rate
//! (`false_alarm / 3` per sensor, [`super::residual_tests`]) and hold no
//! stand-in ([`super::stand_ins`]). The verdict:
//!
//! - `none`: nothing is wrong (no hypothesis, and the baseline passes);
//! - `X` (`X+Y`, ...): the effects named explain the data;
//! - `unexplained`: something is wrong and the catalogue does not hold it;
//! - `X+unexplained`: `X` explains part of it.
//!
//! A cause is named only when the data prefer it: where another hypothesis
//! tested at the step that added it comes within [`AMBIGUOUS_BIC`] of its
//! BIC (`chi^2 / s^2 + k ln n`; a difference below 2 is, on Kass and
//! Raftery's scale of `2 ln B`, "not worth more than a bare mention"), the
//! two explain the data about equally and the verdict names them as
//! `X|Y`, one of the two, not `X`. (An effect and one nested in it, four
//! drum gains and one common gain, are not rivals: the nested check of the
//! selection decides between them.)
//!
//! The final model must also leave no structure: no term of
//! [`super::missing_terms`] (a reading's residual linear in a physical
//! driver, the row or the direction of motion) beyond the Bonferroni limit
//! of Rao's score test at `false_alarm`. The score test counts what the fit
//! does to the residuals, so a model that holds fails it with probability
//! at most `false_alarm`; with the sensor tests, a model that holds is called
//! unexplained with probability at most `2 false_alarm`. (The correlations of
//! step 2 count every cable's residual at a pose as an independent point;
//! as a test they rejected 1 in 10 `none` cases of the small robot, far
//! above the stated rate, and are only reported.) The strongest term left is
//! the proposed missing term.
//!
//! A model that does not explain the data names its causes only where they
//! are needed beyond the terms proposed for the baseline
//! ([`CausesGivenTerms`]: their likelihood ratio given
//! those terms, at `false_alarm`, from the baseline and the model each
//! refitted with the terms as corrections of the readings, `term_refit`);
//! otherwise they fitted part of what is wrong as proxies, and the verdict
//! is `unexplained`.
//!
//! With it: the share of the baseline's excess chi-square (above its degrees
//! of freedom) that the final model leaves, the residual-driver
//! correlations that still carry structure, and the terms it misses.

use serde::Serialize;

use super::baseline::Baseline;
use super::candidates::{CandidateFit, Hypothesis, Model, WEIGHT_SCALING};
use super::drivers::{DriverTest, PoseSample};
use super::missing_terms::{causes_given_terms, missing_terms, CausesGivenTerms, MissingTerm, TermsFound};
use super::residual_tests::{factor_tests_at, measurement_components, FactorTest};
use super::selection::SelectionStep;
use super::stand_ins::{
    orientation_stand_in, own_sensor, partial_stand_in, stand_in, weight_family_plausible, StandIn,
};
use super::term_refit::fit_with_terms;
use crate::calib::CalibrationGraph;
use crate::error::Result;
use crate::model::effect_kind::EffectKind;
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::CABLE_COUNT;

/// The BIC margin below which two hypotheses explain the data about equally (module docs).
pub const AMBIGUOUS_BIC: f64 = 2.0;

/// A cause the data do not tell from another hypothesis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ambiguity {
    /// The hypothesis the selection added.
    pub cause: String,
    /// The hypothesis tested at the same step that comes within [`AMBIGUOUS_BIC`].
    pub rival: String,
    /// The rival's BIC less the cause's.
    pub bic_margin: f64,
}

/// Whether the final model explains the data, and what it leaves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Explanation {
    /// The final model passes every per-sensor test and holds no stand-in.
    pub explained: bool,
    /// The effects named as causes (the final model's effects less the stand-ins), in the order added.
    pub causes: Vec<String>,
    /// The final model's hypotheses that fit as proxies, not causes.
    pub stand_ins: Vec<StandIn>,
    /// Causes the data do not tell from another hypothesis (named `X|Y` in the verdict).
    pub ambiguous: Vec<Ambiguity>,
    /// The final model (its hypotheses joined by `+`, stand-ins included; `none`: the baseline).
    pub final_model: String,
    /// The final model's chi-square over all factors.
    pub final_chi_square: f64,
    /// Its degrees of freedom.
    pub final_dof: usize,
    /// The per-sensor tests of the final model at `false_alarm / 3` each.
    pub final_tests: Vec<FactorTest>,
    /// The share of the baseline's excess chi-square the final model leaves
    /// (`None` when the baseline has no excess).
    pub unexplained_share: Option<f64>,
    /// The residual-driver correlations of the final model that still carry
    /// structure (`|t| > 3.29`, each at p < 0.001).
    pub structure_left: Vec<String>,
    /// The `|z|` above which a term the final model lacks is structure it
    /// does not explain: two-sided `p < false_alarm / m` over its `m`
    /// testable terms (Bonferroni, `missing_terms`).
    pub structure_limit_t: f64,
    /// The terms beyond it, in words: structure the final model misses (part
    /// of `explained`, module docs).
    pub structure_unexplained: Vec<String>,
    /// The same terms, strongest first.
    pub missing_terms: Vec<MissingTerm>,
    /// The missing terms proposed (a sparse regression of the residuals,
    /// `missing_terms`), with coefficients fitted together.
    pub proposed_terms: Vec<MissingTerm>,
    /// The model the terms are missing from: the final model, or the
    /// baseline where the final model holds a stand-in.
    pub terms_missing_from: String,
    /// Where the final model does not explain the data and names causes:
    /// whether the causes are still needed given the terms proposed for the
    /// baseline ([`CausesGivenTerms`]).
    pub causes_given_terms: Option<CausesGivenTerms>,
    /// The effects that fit part of what is wrong but are not needed given
    /// those terms: proxies, not named as causes.
    pub explained_away: Vec<String>,
}

impl Explanation {
    /// `none`, the causes joined by `+`, `unexplained`, or the causes and `+unexplained` (module docs).
    pub fn verdict(&self) -> String {
        let named: Vec<String> = self
            .causes
            .iter()
            .map(|c| match self.ambiguous.iter().find(|a| &a.cause == c) {
                Some(a) => format!("{}|{}", a.cause, a.rival),
                None => c.clone(),
            })
            .collect();
        match (named.is_empty(), self.explained) {
            (true, true) => "none".into(),
            (false, true) => named.join("+"),
            (true, false) => "unexplained".into(),
            (false, false) => format!("{}+unexplained", named.join("+")),
        }
    }

    /// Why the data are not explained, in one sentence (empty when they are).
    pub fn sentence(&self) -> String {
        if self.explained {
            return String::new();
        }
        let mut parts = Vec::new();
        if let (false, Some(check)) = (self.explained_away.is_empty(), &self.causes_given_terms) {
            parts.push(format!(
                "{} fit{} part of it, but not beyond the terms that describe what the baseline misses (likelihood ratio {:.1} on {} dof given them, p = {:.2e}; {:.1} alone): a proxy, not a cause",
                self.explained_away.join(", "),
                if self.explained_away.len() == 1 { "s" } else { "" },
                check.likelihood_ratio,
                check.dof,
                check.p_value,
                check.likelihood_ratio_alone
            ));
        }
        if !self.stand_ins.is_empty() {
            let names: Vec<&str> = self.stand_ins.iter().map(|s| s.hypothesis.as_str()).collect();
            parts.push(format!("stand-ins: {}", names.join(", ")));
        }
        let failing: Vec<String> = self
            .final_tests
            .iter()
            .filter(|t| !t.consistent)
            .map(|t| {
                format!(
                    "{} chi-square {:.1} above its limit {:.1}",
                    t.kind, t.chi_square, t.limit
                )
            })
            .collect();
        if !failing.is_empty() {
            parts.push(format!(
                "the final model fails the sensor tests ({})",
                failing.join(", ")
            ));
            if let Some(share) = self.unexplained_share {
                parts.push(format!(
                    "it leaves {:.0} % of the baseline's excess chi-square",
                    share * 100.0
                ));
            }
        }
        if !self.proposed_terms.is_empty() {
            let terms: Vec<String> = self.proposed_terms.iter().map(MissingTerm::formula).collect();
            parts.push(format!(
                "the residuals of {} follow drivers (|z| above {:.2}); the terms that explain them: {}",
                self.terms_missing_from,
                self.structure_limit_t,
                terms.join("; ")
            ));
        } else if !self.structure_left.is_empty() {
            parts.push(format!("structure left: {}", self.structure_left.join("; ")));
        }
        format!("not explained by the catalogue: {}", parts.join("; "))
    }
}

/// The explanation of `model` (the final model of the search, with its
/// residual-driver tests `drivers` and the samples of its poses) against the
/// baseline; `time_order`: the rows are in the order taken.
pub(super) fn explain(
    base: &Baseline,
    model: &Model,
    (drivers, samples, base_samples): (&[DriverTest], &[PoseSample], &[PoseSample]),
    (steps, candidates): (&[SelectionStep], &[CandidateFit]),
    (false_alarm, time_order): (f64, bool),
    measurements: &[PoseMeasurement],
) -> Result<Explanation> {
    let graph = super::fitted_graph::rebuild(&model.result, &base.used, &model.options);
    let components = measurement_components(&graph.graph);
    let effect_parameters = model.options.free_effects.parameter_count();
    let unknowns = 8 * base.used.len() + 4 * CABLE_COUNT + effect_parameters;
    let constraints = CABLE_COUNT * base.used.len();
    let dof = (components + constraints).saturating_sub(unknowns).max(1);
    let tests = factor_tests_at(&graph.graph, components, dof, false_alarm);
    let stand_ins = stand_ins_of(base, model, &tests);
    let mut causes: Vec<String> = model
        .hypotheses
        .iter()
        .filter(|h| matches!(h, Hypothesis::Effect(_)))
        .map(|h| h.name().to_string())
        .filter(|name| !stand_ins.iter().any(|s| &s.hypothesis == name))
        .collect();
    let excess_before = base.chi_square - base.dof as f64;
    let excess_after = (model.chi_square - dof as f64).max(0.0);
    // Terms missing from a model with a stand-in would be missing from a
    // proxy: they are sought in the baseline instead.
    let base_terms = || missing_terms(&base.graph, &base.used, base_samples, time_order, false_alarm);
    let (of, terms) = match stand_ins.is_empty() {
        true => (
            match model.hypotheses.is_empty() {
                true => "the baseline".to_string(),
                false => model.name(),
            },
            missing_terms(&graph, &base.used, samples, time_order, false_alarm)?,
        ),
        false => ("the baseline".to_string(), base_terms()?),
    };
    let explained = stand_ins.is_empty() && tests.iter().all(|t| t.consistent) && terms.missing.is_empty();
    // Causes of a model that does not explain the data must be needed
    // beyond the terms that describe what is wrong.
    let mut given_terms = None;
    let mut explained_away = Vec::new();
    if !explained && !causes.is_empty() {
        let described = match stand_ins.is_empty() {
            true => base_terms()?,
            false => terms.clone(),
        };
        if !described.describing_keys.is_empty() {
            let check = match stand_ins.is_empty() {
                true => check_causes(
                    base,
                    (model, &graph, samples),
                    base_samples,
                    &described,
                    (false_alarm, measurements),
                )?,
                false => {
                    // The causes alone: the final model without its stand-ins.
                    let alone = causes_alone(model, &stand_ins, base, measurements)?;
                    let alone_graph = super::fitted_graph::rebuild(&alone.result, &base.used, &alone.options);
                    let alone_samples = super::drivers::samples(&alone.result, &base.used, &alone.options)?;
                    let fitted = (&alone, &alone_graph, alone_samples.as_slice());
                    check_causes(base, fitted, base_samples, &described, (false_alarm, measurements))?
                }
            };
            if !check.needed {
                explained_away = std::mem::take(&mut causes);
            }
            given_terms = Some(check);
        }
    }
    let ambiguous = causes.iter().filter_map(|c| rival(c, steps, candidates)).collect();
    let describe = |d: &DriverTest| format!("{} vs {}, t = {:+.1}", d.residual, d.driver, d.t_statistic);
    Ok(Explanation {
        explained,
        causes,
        stand_ins,
        ambiguous,
        final_model: model.name(),
        final_chi_square: model.chi_square,
        final_dof: dof,
        final_tests: tests,
        unexplained_share: (excess_before > 0.0).then(|| (excess_after / excess_before).min(1.0)),
        structure_left: drivers.iter().filter(|d| d.significant).map(describe).collect(),
        structure_limit_t: terms.limit,
        structure_unexplained: terms.missing.iter().map(MissingTerm::formula).collect(),
        missing_terms: terms.missing,
        proposed_terms: terms.proposed,
        terms_missing_from: of,
        causes_given_terms: given_terms,
        explained_away,
    })
}

/// The stand-ins of `model` (`stand_ins`), given its per-sensor tests.
fn stand_ins_of(base: &Baseline, model: &Model, tests: &[FactorTest]) -> Vec<StandIn> {
    let failing = |sensor: &str| tests.iter().find(|t| t.kind == sensor && !t.consistent);
    let estimates = &model.result.effect_estimates;
    // Two weight scalings fitted together are judged by their family.
    let family_plausible = weight_family_plausible(estimates, &base.result.robot, base.mean_reference_tension_n);
    let mut stand_ins: Vec<StandIn> = estimates
        .iter()
        .filter_map(|e| {
            stand_in(e, &base.result.robot, base.mean_reference_tension_n)
                .filter(|_| !(family_plausible && WEIGHT_SCALING.contains(&e.effect)))
                .or_else(|| failing(own_sensor(e.effect)).map(|t| partial_stand_in(e, t)))
        })
        .collect();
    if model.hypotheses.contains(&Hypothesis::OrientationFree) {
        stand_ins.push(orientation_stand_in());
    }
    stand_ins
}

/// [`causes_given_terms`] of a fitted model (its graph and samples) against
/// the baseline: the likelihood ratio of the causes given the terms from
/// the baseline and the model each refitted with the terms as corrections of
/// the readings ([`fit_with_terms`]); where a refit fails or does not
/// converge, its first-order value.
fn check_causes(
    base: &Baseline,
    (model, graph, samples): (&Model, &CalibrationGraph, &[PoseSample]),
    base_samples: &[PoseSample],
    described: &TermsFound,
    (false_alarm, measurements): (f64, &[PoseMeasurement]),
) -> Result<CausesGivenTerms> {
    let first_order = causes_given_terms(
        ((&base.graph, base_samples), (graph, samples)),
        &base.used,
        described,
        (
            (base.chi_square - model.chi_square) / base.variance_factor,
            base.variance_factor,
            model.options.free_effects.parameter_count(),
        ),
        false_alarm,
    )?;
    let known = &base.result.robot.effects;
    let keys = &described.describing_keys;
    let refitted =
        fit_with_terms((&base.result, &base.options, known), measurements, base_samples, keys).and_then(|b| {
            Ok((
                b,
                fit_with_terms((&model.result, &model.options, known), measurements, base_samples, keys)?,
            ))
        });
    match refitted {
        Ok((with_base, with_model)) if with_base.converged && with_model.converged => Ok(first_order.refitted(
            (with_base.chi_square - with_model.chi_square) / base.variance_factor,
            false_alarm,
        )),
        _ => Ok(first_order),
    }
}

/// `model` without its stand-ins (freed orientations included), refitted.
fn causes_alone(
    model: &Model,
    stand_ins: &[StandIn],
    base: &Baseline,
    measurements: &[PoseMeasurement],
) -> Result<Model> {
    let kept = model
        .hypotheses
        .iter()
        .copied()
        .filter(|h| matches!(h, Hypothesis::Effect(_)) && !stand_ins.iter().any(|s| s.hypothesis == h.name()))
        .collect();
    model.refit(kept, base, measurements)
}

/// The hypothesis tested at the step that added `cause` whose BIC comes
/// closest to it, if within [`AMBIGUOUS_BIC`] (a converged, admissible fit).
fn rival(cause: &str, steps: &[SelectionStep], candidates: &[CandidateFit]) -> Option<Ambiguity> {
    let step = steps.iter().find(|s| s.added == cause)?.step;
    let at_step = |c: &&CandidateFit| c.step == step && c.converged && c.inadmissible.is_none();
    let added = candidates.iter().filter(at_step).find(|c| c.effect == cause)?;
    candidates
        .iter()
        .filter(at_step)
        .filter(|c| c.effect != cause && c.delta_bic.is_finite() && !nested(cause, &c.effect))
        .map(|c| (c, c.delta_bic - added.delta_bic))
        .filter(|(_, margin)| *margin < AMBIGUOUS_BIC)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(c, margin)| Ambiguity {
            cause: cause.to_string(),
            rival: c.effect.clone(),
            bic_margin: margin,
        })
}

/// Whether one of two hypotheses is nested in the other.
fn nested(a: &str, b: &str) -> bool {
    match (EffectKind::parse(a), EffectKind::parse(b)) {
        (Ok(a), Ok(b)) => a.nested_in() == Some(b) || b.nested_in() == Some(a),
        _ => false,
    }
}

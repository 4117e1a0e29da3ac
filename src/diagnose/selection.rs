//! Step 3b: model selection by forward selection with likelihood-ratio tests
//! at a stated false-alarm rate, backward checks, and each selected model's
//! held-out residual by K-fold cross-validation over poses.
//!
//! At each step every hypothesis not yet in the model is fitted as its
//! extension and tested by the likelihood ratio `D = (chi^2_model -
//! chi^2_extended) / s^2` (`s^2` the a posteriori variance factor), which is
//! chi-square with the added parameters' degrees of freedom when the
//! hypothesis adds nothing (Wilks). A hypothesis is significant when its
//! p-value is below `alpha / m`, `m` the hypotheses tested at the step
//! (Bonferroni): on data the model describes, the probability of declaring
//! anything is at most `alpha`, and each later step adds a spurious effect
//! with probability at most `alpha` too. Of the significant hypotheses the
//! one with the lowest BIC (`D` less `k ln n`: the most evidence per
//! parameter, so that a 2-parameter centre-of-mass shift that explains a tilt
//! beats freeing 3 orientation parameters per pose) is added and the model
//! refitted; every
//! earlier hypothesis is then tested for removal at the same level
//! (backward check), an effect that contains a simpler one (four drum gains,
//! one common gain) is replaced by it where the data do not reject the
//! simpler one, and the search goes on until nothing is significant.

use rayon::prelude::*;
use serde::Serialize;

use super::candidates::{inadmissible, test_hypothesis, CandidateFit, Hypothesis, Model};
use super::fitted_graph::rebuild;
use super::progress::Progress;
use super::residual_tests::MEASUREMENT_KINDS;
use super::search::Search;
use crate::calib::{
    build_graph, CableModel, CalibrationGraph, CalibrationOptions, CalibrationResult, OrientationPrior,
};
use crate::error::{Error, Result};
use crate::graph::whitened_squared_norm;
use crate::model::effect_kind::EffectKind;
use crate::model::measurement::PoseMeasurement;
use crate::model::statics::CableTension;
use crate::solver::optimize;
use crate::stats::chi_square_survival;

/// One step of the forward selection.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SelectionStep {
    /// 1-based step.
    pub step: usize,
    /// The hypothesis added.
    pub added: String,
    /// Its likelihood-ratio statistic against the previous model.
    pub lr_statistic: f64,
    /// Its degrees of freedom.
    pub added_parameters: usize,
    /// Its p-value.
    pub p_value: f64,
    /// The p-value it had to beat.
    pub p_threshold: f64,
    /// Hypotheses removed by the backward check after the addition, and
    /// effects replaced by a simpler nested one (`encoder-scale by encoder-gain`).
    pub removed: Vec<String>,
}

/// The outcome of the search.
pub(super) struct Selection {
    /// The selected model.
    pub model: Model,
    /// Every hypothesis tested, at every step.
    pub candidates: Vec<CandidateFit>,
    /// The steps that added something.
    pub steps: Vec<SelectionStep>,
}

/// The hypotheses the search may add (`options.candidates`, and the
/// orientation freed when the baseline uses the localiser's orientations;
/// without them the localiser mount has no evidence and is left out).
fn hypotheses(search: &Search<'_>) -> Vec<Hypothesis> {
    let orientations = search.base.options.orientation_prior == OrientationPrior::On;
    let mut all: Vec<Hypothesis> = search
        .options
        .candidates
        .iter()
        .filter(|k| orientations || **k != EffectKind::LocaliserMount)
        .map(|k| Hypothesis::Effect(*k))
        .collect();
    if search.options.orientation_hypothesis && orientations {
        all.push(Hypothesis::OrientationFree);
    }
    all
}

/// Forward selection from the baseline (module docs).
pub(super) fn forward_selection(search: &Search<'_>, progress: &mut Progress<'_>) -> Selection {
    let mut model = Model::baseline(search.base);
    let mut candidates = Vec::new();
    let mut steps = Vec::new();
    let all = hypotheses(search);
    for step in 1..=all.len() {
        let open: Vec<Hypothesis> = all.iter().copied().filter(|h| model.can_add(*h)).collect();
        if open.is_empty() {
            break;
        }
        progress.grow(open.len());
        // The hypotheses' fits are independent: fitted in parallel, compared in order.
        let names: Vec<&str> = open.iter().map(|h| h.name()).collect();
        progress.step(&format!("step {step}: fit {}", names.join(", ")));
        let fits: Vec<(Option<Model>, CandidateFit)> = open
            .par_iter()
            .map(|&hypothesis| test_hypothesis(search, &model, hypothesis, open.len(), step))
            .collect();
        progress.advance(open.len() - 1);
        let mut best: Option<(f64, Model, usize)> = None;
        for (fit, row) in fits {
            if let (Some(fit), true) = (fit, row.significant) {
                let score = row.delta_bic;
                if best.as_ref().is_none_or(|(b, _, _)| score < *b) {
                    best = Some((score, fit, candidates.len()));
                }
            }
            candidates.push(row);
        }
        let Some((_, extended, index)) = best else {
            break;
        };
        let row = &candidates[index];
        let mut selected = SelectionStep {
            step,
            added: row.effect.clone(),
            lr_statistic: row.lr_statistic,
            added_parameters: row.added_parameters,
            p_value: row.p_value,
            p_threshold: row.p_threshold,
            removed: Vec::new(),
        };
        let checked = backward_check(search, extended, row.p_threshold, &mut selected.removed, progress);
        let simpler = simplify_nested(search, checked, row.p_threshold, &mut selected.removed, progress);
        model = simplify_orientation(search, simpler, row.p_threshold, &mut selected.removed, progress);
        steps.push(selected);
    }
    Selection {
        model,
        candidates,
        steps,
    }
}

/// Remove every earlier hypothesis of `model` whose removal the data do not
/// reject at `p_threshold` (all but the one just added).
fn backward_check(
    search: &Search<'_>,
    mut model: Model,
    p_threshold: f64,
    removed: &mut Vec<String>,
    progress: &mut Progress<'_>,
) -> Model {
    let earlier: Vec<Hypothesis> = model.hypotheses[..model.hypotheses.len() - 1].to_vec();
    for hypothesis in earlier {
        progress.grow(1);
        progress.step(&format!("backward check: {}", hypothesis.name()));
        let Ok(reduced) = model.without(hypothesis, search.base, search.measurements) else {
            continue;
        };
        let dof = reduced.added_parameters(hypothesis, search.base.used.len());
        let lr = (reduced.chi_square - model.chi_square) / search.base.variance_factor;
        if chi_square_survival(dof, lr.max(0.0)) >= p_threshold {
            removed.push(hypothesis.name().to_string());
            model = reduced;
        }
    }
    model
}

/// Replace every effect of `model` that contains a simpler one (the per-drum
/// gains contain one common gain) by the simpler one where the data do not
/// reject it at `p_threshold`: the likelihood ratio of the difference, on the
/// parameters the simpler effect drops.
fn simplify_nested(
    search: &Search<'_>,
    mut model: Model,
    p_threshold: f64,
    replaced: &mut Vec<String>,
    progress: &mut Progress<'_>,
) -> Model {
    for inner in EffectKind::ALL {
        let Some(outer) = inner.nested_in() else {
            continue;
        };
        let Some(at) = model.hypotheses.iter().position(|h| *h == Hypothesis::Effect(outer)) else {
            continue;
        };
        progress.grow(1);
        progress.step(&format!("nested check: {} for {}", inner.name(), outer.name()));
        let mut hypotheses = model.hypotheses.clone();
        hypotheses[at] = Hypothesis::Effect(inner);
        let Ok(simpler) = model.refit(hypotheses, search.base, search.measurements) else {
            continue;
        };
        let dof = outer.parameter_count() - inner.parameter_count();
        let lr = (simpler.chi_square - model.chi_square) / search.base.variance_factor;
        if chi_square_survival(dof, lr.max(0.0)) >= p_threshold {
            replaced.push(format!("{} by {}", outer.name(), inner.name()));
            model = simpler;
        }
    }
    model
}

/// Replace freed orientations (3 parameters per pose) by one localiser mount
/// (3 in all) where the data do not reject the structured fault at
/// `p_threshold`: the likelihood ratio on the `3 (poses - 1)` parameters the
/// mount drops. Where the mount alone is rejected, the freed orientations
/// may also be standing in for a physical effect that tilts the platform
/// (a centre-of-mass shift) as well as the mount: the best effect `X`
/// significant beside the mount is found, and `mount + X` replaces the
/// orientations if the data do not reject it against `orientation + X`
/// (nested, the same `3 (poses - 1)` parameters).
fn simplify_orientation(
    search: &Search<'_>,
    model: Model,
    p_threshold: f64,
    replaced: &mut Vec<String>,
    progress: &mut Progress<'_>,
) -> Model {
    let mount = Hypothesis::Effect(EffectKind::LocaliserMount);
    let Some(at) = model.hypotheses.iter().position(|h| *h == Hypothesis::OrientationFree) else {
        return model;
    };
    if !search.options.candidates.contains(&EffectKind::LocaliserMount) {
        return model;
    }
    let (base, measurements) = (search.base, search.measurements);
    let dof = 3 * base.used.len() - EffectKind::LocaliserMount.parameter_count();
    let rejected = |simpler: &Model, full: &Model| {
        let lr = (simpler.chi_square - full.chi_square) / base.variance_factor;
        chi_square_survival(dof, lr.max(0.0)) < p_threshold
    };
    progress.grow(1);
    progress.step("nested check: localiser-mount for orientation");
    let mut hypotheses = model.hypotheses.clone();
    hypotheses[at] = mount;
    let Ok(simpler) = model.refit(hypotheses, base, measurements) else {
        return model;
    };
    if !rejected(&simpler, &model) {
        replaced.push(format!("orientation by {}", EffectKind::LocaliserMount.name()));
        return simpler;
    }
    let Some((effect, with_effect)) = best_effect_beside(search, &simpler, p_threshold, progress) else {
        return model;
    };
    progress.grow(1);
    progress.step(&format!(
        "nested check: localiser-mount+{} for orientation",
        effect.name()
    ));
    let Ok(full) = model.with(Hypothesis::Effect(effect), base, measurements) else {
        return model;
    };
    if rejected(&with_effect, &full) {
        return model;
    }
    replaced.push(format!(
        "orientation by {}+{}",
        EffectKind::LocaliserMount.name(),
        effect.name()
    ));
    with_effect
}

/// The effect whose addition to `model` lowers its chi-square most among
/// those significant at `p_threshold`, with the extended fit.
fn best_effect_beside(
    search: &Search<'_>,
    model: &Model,
    p_threshold: f64,
    progress: &mut Progress<'_>,
) -> Option<(EffectKind, Model)> {
    let mut best: Option<(EffectKind, Model)> = None;
    for &effect in &search.options.candidates {
        let hypothesis = Hypothesis::Effect(effect);
        if !model.can_add(hypothesis) {
            continue;
        }
        progress.grow(1);
        progress.step(&format!("fit localiser-mount+{}", effect.name()));
        let Ok(fit) = model.with(hypothesis, search.base, search.measurements) else {
            continue;
        };
        let dof = model.added_parameters(hypothesis, search.base.used.len());
        let lr = (model.chi_square - fit.chi_square) / search.base.variance_factor;
        let admissible = fit.estimate(effect).is_none_or(|e| inadmissible(e).is_none());
        let significant = fit.result.converged() && admissible && chi_square_survival(dof, lr.max(0.0)) < p_threshold;
        if significant && best.as_ref().is_none_or(|(_, b)| fit.chi_square < b.chi_square) {
            best = Some((effect, fit));
        }
    }
    best
}

/// The first effect of a model's hypotheses (for the plotted driver).
pub(super) fn first_effect(model: &Model) -> Option<EffectKind> {
    model.hypotheses.iter().find_map(|h| match h {
        Hypothesis::Effect(kind) => Some(*kind),
        Hypothesis::OrientationFree => None,
    })
}

/// K-fold cross-validation of a fitted model over poses (module docs):
/// the held-out normalised measurement residual RMS.
pub(super) fn cross_validate(
    fit: &CalibrationResult,
    used: &[PoseMeasurement],
    options: &CalibrationOptions,
    folds: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<f64> {
    let full = rebuild(fit, used, options);
    // The folds are independent: solved in parallel, summed in fold order
    // (the same sum, term by term, as one fold after the other).
    for fold in 0..folds {
        progress(&format!("cross-validation fold {}/{folds}", fold + 1));
    }
    let terms: Vec<Result<Vec<(f64, usize)>>> = (0..folds)
        .into_par_iter()
        .map(|fold| held_out_terms(&full, fit, used, options, folds, fold))
        .collect();
    let mut sum = 0.0;
    let mut count = 0usize;
    for fold_terms in terms {
        for (squared, rows) in fold_terms? {
            sum += squared;
            count += rows;
        }
    }
    Ok((sum / count.max(1) as f64).sqrt())
}

/// One fold of [`cross_validate`]: train on the poses not in `fold`, solve
/// the held-out poses with the trained globals held; per held-out
/// measurement factor, its whitened squared residual and its rows.
fn held_out_terms(
    full: &CalibrationGraph,
    fit: &CalibrationResult,
    used: &[PoseMeasurement],
    options: &CalibrationOptions,
    folds: usize,
    fold: usize,
) -> Result<Vec<(f64, usize)>> {
    let (train, test): (Vec<usize>, Vec<usize>) = (0..used.len()).partition(|k| k % folds != fold);
    let subset = |indices: &[usize]| -> CalibrationGraph { subgraph(full, fit, used, indices, options) };
    let mut trained = subset(&train);
    optimize(&mut trained.graph, &options.lm).map_err(|e| e.during(format!("cross-validation fold {}", fold + 1)))?;
    let mut held_out = subset(&test);
    for id in global_ids(&trained) {
        held_out
            .graph
            .values
            .set(id, trained.graph.values.variable(id).value.clone());
        held_out.graph.values.set_fixed(id, true);
    }
    optimize(&mut held_out.graph, &options.lm)
        .map_err(|e| e.during(format!("cross-validation fold {} (held-out poses)", fold + 1)))?;
    held_out
        .graph
        .factors
        .iter()
        .filter(|f| MEASUREMENT_KINDS.contains(&f.kind()))
        .map(|f| {
            let r = f.evaluate(&held_out.graph.values, None).ok_or_else(|| {
                Error::NoEquilibrium(format!(
                    "cross-validation fold {}: a held-out pose went slack",
                    fold + 1
                ))
            })?;
            Ok((whitened_squared_norm(&r, f.sigmas()), r.len()))
        })
        .collect()
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

//! Step 3c: declare only what predicts. Under a wrong model almost every
//! parameter lowers the in-sample chi-square, so each effect the forward
//! selection added must also pass two tests on what it predicts:
//!
//! - **held-out residual**: the model with it has a lower held-out residual
//!   RMS (K-fold cross-validation over poses, `selection::cross_validate`)
//!   than the model without it;
//! - **anchors**: it does not make the anchors worse by their own covariance:
//!   the anchors' expected squared error with it, `tr Sigma_with`, is no
//!   larger than without it, `tr Sigma_without + |a_with - a_without|^2` (the
//!   variance the extension adds must buy at least the bias it removes, the
//!   bias estimated by the anchors' shift).
//!
//! The checks follow the selection's order: from the baseline, each
//! hypothesis is added in turn to the model of those kept so far and kept
//! only when it passes both against that model (so that two effects that
//! together predict worse than neither are both caught). Where every effect
//! passes, the selected model stands as it is. The `orientation` hypothesis
//! is kept without these checks: its held-out residual leaves out the very
//! readings it frees, so it is not comparable; it is a stand-in in the
//! verdict anyway.

use serde::Serialize;

use super::candidates::{Hypothesis, Model};
use super::progress::Progress;
use super::search::Search;
use super::selection::cross_validate;
use crate::calib::{anchor_rms_bound_m, CalibrationResult};
use crate::model::robot::CABLE_COUNT;

/// An effect the forward selection added that does not predict.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotPredictive {
    /// The effect.
    pub hypothesis: String,
    /// The model it was taken out of.
    pub model: String,
    /// Held-out residual RMS with it.
    pub cv_rms_with: f64,
    /// Held-out residual RMS without it.
    pub cv_rms_without: f64,
    /// The anchors' expected squared error with it, `tr Sigma`, m^2 (`None`
    /// without a full-rank covariance).
    pub anchor_mse_with_m2: Option<f64>,
    /// Without it: `tr Sigma + |shift|^2`, m^2.
    pub anchor_mse_without_m2: Option<f64>,
    /// Which test it failed, in words.
    pub why: String,
}

/// The selected model's held-out residual RMS, then [`keep_predictive`].
pub(super) fn predictive_model(
    search: &Search<'_>,
    selected: &Model,
    baseline_cv_rms: f64,
    progress: &mut Progress<'_>,
) -> crate::error::Result<(Model, f64, Vec<NotPredictive>)> {
    let selected_cv_rms = if selected.hypotheses.is_empty() {
        baseline_cv_rms
    } else {
        cross_validate(
            &selected.result,
            &search.base.used,
            &selected.options,
            search.options.folds,
            &mut |what| progress.step(&format!("{}: {what}", selected.name())),
        )?
    };
    Ok(keep_predictive(
        search,
        selected.clone(),
        selected_cv_rms,
        baseline_cv_rms,
        progress,
    ))
}

/// The model with every effect that does not predict taken out (module
/// docs), its held-out residual RMS, and what was taken out.
fn keep_predictive(
    search: &Search<'_>,
    selected: Model,
    selected_cv_rms: f64,
    baseline_cv_rms: f64,
    progress: &mut Progress<'_>,
) -> (Model, f64, Vec<NotPredictive>) {
    let (base, measurements) = (search.base, search.measurements);
    let mut removed = Vec::new();
    let mut kept = Model::baseline(base);
    let mut kept_cv = baseline_cv_rms;
    for &hypothesis in &selected.hypotheses {
        let extended = if kept.hypotheses.len() + 1 == selected.hypotheses.len() && removed.is_empty() {
            Ok(selected.clone())
        } else {
            kept.with(hypothesis, base, measurements)
        };
        let Ok(extended) = extended else {
            continue;
        };
        if hypothesis == Hypothesis::OrientationFree {
            kept_cv = match cv_of(&extended, selected_cv_rms, &selected, search) {
                Some(cv) => cv,
                None => continue,
            };
            kept = extended;
            continue;
        }
        progress.grow(1);
        progress.step(&format!(
            "prediction check: {} beside {}",
            hypothesis.name(),
            kept.name()
        ));
        let Some(cv) = cv_of(&extended, selected_cv_rms, &selected, search) else {
            continue;
        };
        let mse = anchor_mse(&extended.result, &kept.result);
        let worse_held_out = cv >= kept_cv;
        let worse_anchors = mse.is_some_and(|(with, without)| with > without);
        if worse_held_out || worse_anchors {
            let why = match (worse_held_out, worse_anchors) {
                (true, true) => "it neither lowers the held-out residual nor makes the anchors better",
                (true, false) => "it does not lower the held-out residual",
                _ => "it adds more variance to the anchors than the bias it removes",
            };
            removed.push(NotPredictive {
                hypothesis: hypothesis.name().into(),
                model: kept.name(),
                cv_rms_with: cv,
                cv_rms_without: kept_cv,
                anchor_mse_with_m2: mse.map(|m| m.0),
                anchor_mse_without_m2: mse.map(|m| m.1),
                why: why.into(),
            });
            continue;
        }
        kept = extended;
        kept_cv = cv;
    }
    // Each kept effect predicted beside the others; the model as a whole
    // must also predict better than the baseline (freed orientations join
    // without that check, and may carry an effect that only predicts beside them).
    if !kept.hypotheses.is_empty() && kept_cv >= baseline_cv_rms {
        removed.push(NotPredictive {
            hypothesis: kept.name(),
            model: "none".into(),
            cv_rms_with: kept_cv,
            cv_rms_without: baseline_cv_rms,
            anchor_mse_with_m2: None,
            anchor_mse_without_m2: None,
            why: "together they do not lower the baseline's held-out residual".into(),
        });
        return (Model::baseline(base), baseline_cv_rms, removed);
    }
    (kept, kept_cv, removed)
}

/// The held-out residual RMS of `model` (the selected model's, already computed, for itself).
fn cv_of(model: &Model, selected_cv_rms: f64, selected: &Model, search: &Search<'_>) -> Option<f64> {
    if model.hypotheses == selected.hypotheses && model.chi_square == selected.chi_square {
        return Some(selected_cv_rms);
    }
    cross_validate(
        &model.result,
        &search.base.used,
        &model.options,
        search.options.folds,
        &mut |_| {},
    )
    .ok()
}

/// The anchors' expected squared error with the extension (`tr Sigma_with`)
/// and without it (`tr Sigma_without + |a_with - a_without|^2`), m^2.
fn anchor_mse(with: &CalibrationResult, without: &CalibrationResult) -> Option<(f64, f64)> {
    let trace = |r: &CalibrationResult| {
        anchor_rms_bound_m(&r.uncertainty).map(|bounds| bounds.iter().map(|b| b * b).sum::<f64>())
    };
    let shift: f64 = (0..CABLE_COUNT)
        .map(|i| (with.robot.anchors_m[i] - without.robot.anchors_m[i]).norm_squared())
        .sum();
    Some((trace(with)?, trace(without)? + shift))
}

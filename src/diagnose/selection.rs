//! Step 3b: model selection. Each candidate's held-out residual by K-fold
//! cross-validation over poses, and the verdict: the lowest BIC among the
//! candidates that beat the baseline's by the threshold and predict held-out
//! poses better.

use super::candidates::{rebuild, CandidateFit};
use super::residual_tests::MEASUREMENT_KINDS;
use crate::calib::{build_graph, CableModel, CalibrationGraph, CalibrationOptions, CalibrationResult};
use crate::error::{Error, Result};
use crate::graph::whitened_squared_norm;
use crate::model::effects::EffectKind;
use crate::model::measurement::PoseMeasurement;
use crate::model::statics::CableTension;
use crate::solver::optimize;

/// The verdict of the selection.
pub(super) struct Verdict {
    /// Index of the declared candidate, if any.
    pub winner: Option<usize>,
    /// Its effect's name, or `none`.
    pub verdict: String,
    /// Why, in one sentence.
    pub reason: String,
}

/// The lowest BIC among the candidates that beat the baseline's by
/// `min_bic_drop`, predict held-out poses better than `baseline_cv` and are
/// admissible; `none` otherwise.
pub(super) fn choose(candidates: &[CandidateFit], baseline_cv: f64, min_bic_drop: f64) -> Verdict {
    let winner = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| {
            c.converged && c.inadmissible.is_none() && c.delta_bic <= -min_bic_drop && c.cv_rms < baseline_cv
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
                    c.effect, -c.delta_bic, min_bic_drop, c.added_parameters, baseline_cv, c.cv_rms
                ),
            )
        }
        None => (
            "none".to_string(),
            match best_other {
                Some(c) => format!(
                    "no candidate is significant: the best, {}, changes the BIC by {:+.1} (needs <= -{:.0}) and the held-out residual RMS from {:.3} to {:.3}",
                    c.effect, c.delta_bic, min_bic_drop, baseline_cv, c.cv_rms
                ),
                None => "no candidate could be fitted".to_string(),
            },
        ),
    };
    Verdict {
        winner,
        verdict,
        reason,
    }
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

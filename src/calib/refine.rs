//! The extended model's refit of a baseline calibration
//! ([`refine_with_effects`]), and the estimated effects carried between a
//! result and a graph ([`without_estimated`], [`set_effect_estimates`]).

use super::graph::{build_graph, CalibrationGraph};
use super::options::{CableModel, CalibrationOptions};
use super::pipeline::{finish, solve_stage};
use super::result::{CalibrationResult, EffectEstimate};
use super::system_scope;
use super::uncertainty::effect_estimate;
use crate::error::{Error, Result};
use crate::model::effect_kind::EffectKind;
use crate::model::effects::Effects;
use crate::model::measurement::PoseMeasurement;

/// Re-estimate anchors, offsets and the parameters of `options.free_effects`
/// (none: the model of `options` as it is, e.g. without the orientation prior)
/// with the extended model, starting from `baseline` (its anchors, offsets,
/// poses, tensions and estimated effects; its excluded poses stay out).
/// `options` should be the ones `baseline` was made with, resolved by
/// [`CalibrationOptions::as_used_by`].
pub fn refine_with_effects(
    baseline: &CalibrationResult,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<CalibrationResult> {
    let _shared_system = system_scope::Scope::enter();
    let kinds = options.free_effects;
    let used: Vec<PoseMeasurement> = (0..measurements.len())
        .filter(|k| !baseline.excluded_poses.contains(k))
        .map(|k| measurements[k])
        .collect();
    if used.len() != baseline.poses.len() {
        return Err(Error::InvalidInput(format!(
            "refine_with_effects: {} measurements used but the baseline has {} poses",
            used.len(),
            baseline.poses.len()
        )));
    }
    let mut built = build_graph(
        &baseline.robot,
        &used,
        &baseline.poses,
        &baseline.reference_tensions(),
        CableModel::Catenary,
        options,
    );
    set_effect_estimates(&mut built, &baseline.effect_estimates);
    let mut stages = baseline.stages.clone();
    let name = format!("extended ({kinds}, orientation prior {})", options.orientation_prior);
    stages.push(solve_stage(&name, &mut built, &options.lm)?);
    let estimates = kinds
        .iter()
        .map(|kind| effect_estimate(&built, kind))
        .collect::<Result<Vec<_>>>()?;
    let mut result = finish(&baseline.robot, built, stages, baseline.excluded_poses.clone())?;
    result.orientation_check = baseline.orientation_check;
    result.effect_estimates = estimates;
    Ok(result)
}

/// `effects` with the estimated effects back at their neutral values (a
/// common gain taken out of each drum's gain, where [`robot_from_graph`](super::robot_from_graph)
/// folded it in), so that a graph built from them takes `estimates` on top
/// ([`set_effect_estimates`]) without counting them twice.
pub fn without_estimated(effects: &Effects, estimates: &[EffectEstimate]) -> Effects {
    let neutral = Effects::default();
    let mut out = *effects;
    for estimate in estimates {
        match estimate.effect {
            EffectKind::Elastic => out.axial_stiffness_n = neutral.axial_stiffness_n,
            EffectKind::Pulley => out.pulley_radius_m = neutral.pulley_radius_m,
            EffectKind::EncoderScale => out.encoder_gain = neutral.encoder_gain,
            EffectKind::LoadCell => {
                out.load_cell_bias_n = neutral.load_cell_bias_n;
                out.load_cell_gain = neutral.load_cell_gain;
            }
            EffectKind::Com => {
                out.com_shift_m[0] = 0.0;
                out.com_shift_m[1] = 0.0;
            }
            EffectKind::CommonGain => {
                let common = estimate.values[0] - 1.0;
                out.encoder_gain = out.encoder_gain.map(|g| g - common);
            }
            EffectKind::Segments => out.cable_segments = neutral.cable_segments,
            EffectKind::LocaliserMount => out.localiser_mount_deg = neutral.localiser_mount_deg,
            EffectKind::PlatformWeight => out.platform_weight_scale = neutral.platform_weight_scale,
            EffectKind::CableWeight => out.cable_weight_scale = neutral.cable_weight_scale,
            EffectKind::EncoderDrift => out.encoder_drift_m_per_row = neutral.encoder_drift_m_per_row,
            EffectKind::EncoderBacklash => out.encoder_backlash_m = neutral.encoder_backlash_m,
            EffectKind::LoadCellDrift => out.load_cell_drift_n_per_row = neutral.load_cell_drift_n_per_row,
            EffectKind::LoadCellFriction => out.load_cell_friction = neutral.load_cell_friction,
            EffectKind::Attachments => out.attachment_shift_m = neutral.attachment_shift_m,
        }
    }
    out
}

/// Set the graph's effect variables to `estimates` (a fit's values, which
/// the robot's `[effects]` cannot always hold: a negative compliance).
pub fn set_effect_estimates(built: &mut CalibrationGraph, estimates: &[EffectEstimate]) {
    let Some(vars) = built.effects else {
        return;
    };
    for estimate in estimates {
        built.graph.values.set(
            vars.of(estimate.effect),
            crate::graph::VariableValue::Vector(nalgebra::DVector::from_vec(estimate.variable_values())),
        );
    }
}

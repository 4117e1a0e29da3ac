//! How far an effect's parameter is identifiable apart from the anchors
//! (the hidden-effect experiment's evidence for leaving a pulley radius out
//! of the detection score, module docs of [`super::hidden_effects`]): the
//! parameter's 1-sigma from the Fisher information `J^T Sigma^-1 J` at the
//! true equilibria with and without the anchors free, its multiple
//! correlation with them, and the anchor shift that mimics it (the
//! regression `Sigma_ap / Sigma_pp`).

use nalgebra::{DMatrix, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::hidden_options::HiddenEffectOptions;
use crate::calib::{build_graph, calibrate, CableModel, CalibrationError, CalibrationOptions};
use crate::error::{Error, Result};
use crate::model::effect_kind::{EffectKind, EffectSet};
use crate::model::effects::Effects;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::NoisePreset;
use crate::model::statics::CableTension;
use crate::sim::closed_form::{sample_equilibria_with, Workspace};
use crate::sim::effects::{measure_with_effects, solve_with_effects};
use crate::solver::{marginal_covariance, Covariance};

/// Evidence that an effect's parameter is (not) identifiable apart from the anchors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identifiability {
    /// Robot name.
    pub robot: String,
    /// The effect examined.
    pub effect: String,
    /// Its true value.
    pub value: f64,
    /// Poses.
    pub poses: usize,
    /// 1-sigma of the parameter from the Fisher information with anchors and offsets free.
    pub sigma: f64,
    /// 1-sigma with anchors and offsets known (the parameter alone).
    pub sigma_alone: f64,
    /// Multiple correlation of the parameter with the anchors and offsets,
    /// `sqrt(1 - sigma_alone^2 / sigma^2)`: 1 = fully absorbed.
    pub correlation_with_anchors: f64,
    /// The anchor shift that mimics the effect, `Sigma_ap / Sigma_pp * value`, per anchor, metres.
    pub mimicking_anchor_shift_m: Vec<[f64; 3]>,
    /// Baseline calibration of noise-free data with the effect: chi-square left (stated noise).
    pub baseline_chi_square: f64,
    /// Its degrees of freedom.
    pub baseline_dof: usize,
    /// The baseline's mean Euclidean anchor error (the bias the effect causes), metres.
    pub baseline_anchor_bias_m: f64,
    /// That bias over the anchors' stated 1-sigma ([`crate::diagnose::error_over_sigma`]).
    pub baseline_bias_over_sigma: f64,
    /// The mimicking shift's mean Euclidean size, metres.
    pub mimicking_shift_mean_m: f64,
}

/// At least a calibration's poses and one segment per cable.
fn check_counts(poses: usize, segments: usize) -> Result<()> {
    if poses < crate::calib::MIN_POSES || segments < 1 {
        return Err(Error::InvalidInput(format!(
            "identifiability: at least {} poses (--poses) and 1 segment per cable (--segments) are needed, got {poses} and {segments}",
            crate::calib::MIN_POSES
        )));
    }
    Ok(())
}

/// The identifiability of a pulley radius (or any effect) on `truth`: Fisher
/// information at the true equilibria of the discretised robot, and the bias
/// of a baseline calibration of noise-free data.
pub fn identifiability(
    truth: &Robot,
    effect: EffectKind,
    effects: &Effects,
    poses: usize,
    seed: u64,
    options: &HiddenEffectOptions,
) -> Result<Identifiability> {
    check_counts(poses, options.segments)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let equilibria = sample_equilibria_with(truth, &Workspace::default_for(truth), poses, options.closure, &mut rng)?;
    let solved = solve_with_effects(truth, effects, &equilibria, options.segments)?;
    let noise = options.noise.sigmas(truth.platform_weight_n);
    let free = NoisePreset::None.sigmas(truth.platform_weight_n);
    let measurements = measure_with_effects(truth, effects, &equilibria, &free, options.segments, &mut rng)?;
    let mut known = truth.clone();
    known.effects = *effects;
    let calibration = CalibrationOptions {
        free_effects: EffectSet::of(effect),
        ..CalibrationOptions::new(noise)
    };
    let true_poses: Vec<_> = solved.iter().map(|s| s.pose).collect();
    let true_tensions: Vec<CableTension> = solved
        .iter()
        .map(|s| {
            let f = s.cables[truth.reference_cable].platform_force_n;
            CableTension {
                horizontal_n: f.x.hypot(f.y),
                vertical_n: f.z,
            }
        })
        .collect();
    let built = build_graph(
        &known,
        &measurements,
        &true_poses,
        &true_tensions,
        CableModel::Catenary,
        &calibration,
    );
    let vars = built.effects.expect("extended graph");
    let parameter = vars.of(effect);
    let mut selected: Vec<_> = built.globals.anchors.to_vec();
    selected.extend(built.globals.length_offsets);
    selected.push(parameter);
    let joint = match marginal_covariance(&built.graph, &selected)? {
        Covariance::Full(c) => c,
        Covariance::RankDeficient(_) => {
            return Err(Error::InvalidInput(
                "identifiability: the information matrix is singular".into(),
            ))
        }
    };
    // The parameter's first component follows the 12 anchor coordinates and 4 offsets.
    let p = 3 * CABLE_COUNT + CABLE_COUNT;
    let sigma = joint[(p, p)].sqrt();
    let information: DMatrix<f64> = joint
        .clone()
        .try_inverse()
        .ok_or_else(|| Error::InvalidInput("identifiability: singular covariance".into()))?;
    let sigma_alone = (1.0 / information[(p, p)]).sqrt();
    let value = EffectKind::parameters(effect, effects)[0];
    let shifts: Vec<[f64; 3]> = (0..CABLE_COUNT)
        .map(|i| std::array::from_fn(|c| joint[(3 * i + c, p)] / joint[(p, p)] * value))
        .collect();
    let mimicking_shift_mean_m = shifts.iter().map(|s| Vector3::from(*s).norm()).sum::<f64>() / CABLE_COUNT as f64;
    // The bias: a baseline calibration (effect ignored) of the noise-free data.
    let baseline = calibrate(truth, &measurements, &CalibrationOptions::new(noise))?;
    let statistics = &baseline.factor_statistics;
    let chi: f64 = statistics
        .iter()
        .filter(|s| s.kind != "tension_guard")
        .map(|s| s.chi_square)
        .sum();
    let components: usize = statistics
        .iter()
        .filter(|s| crate::diagnose::MEASUREMENT_KINDS.contains(&s.kind.as_str()))
        .map(|s| s.components)
        .sum();
    let dof = (components + 4 * poses).saturating_sub(8 * poses + 16);
    Ok(Identifiability {
        robot: truth.name.clone(),
        effect: effect.name().into(),
        value,
        poses,
        sigma,
        sigma_alone,
        correlation_with_anchors: (1.0 - (sigma_alone / sigma).powi(2)).max(0.0).sqrt(),
        mimicking_anchor_shift_m: shifts,
        baseline_chi_square: chi,
        baseline_dof: dof,
        baseline_anchor_bias_m: CalibrationError::between(&baseline.robot, truth).anchor_mean_euclidean_m,
        baseline_bias_over_sigma: crate::diagnose::error_over_sigma(&baseline.robot, truth, &baseline.uncertainty),
        mimicking_shift_mean_m,
    })
}

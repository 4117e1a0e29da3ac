//! How to calibrate: the cable model, the orientation prior, robust kernels
//! and the solver settings; and how to check a calibration: the settings of
//! its gross-error tests ([`GrossErrorOptions`]).

use serde::Serialize;

use crate::error::ParseError;

use crate::graph::RobustKernel;
use crate::model::effect_kind::EffectSet;
use crate::model::sensors::SensorNoise;
use crate::solver::LmParams;

/// The cable model of the length factor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CableModel {
    /// Heavy inextensible cable (paper eq. 1-4, 14-16). The default.
    Catenary,
    /// Massless straight cable (the paper's Sec. VI-A baseline).
    Rigid,
}

impl std::fmt::Display for CableModel {
    /// `catenary` or `rigid`: what [`CableModel::parse`] reads.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            CableModel::Catenary => "catenary",
            CableModel::Rigid => "rigid",
        })
    }
}

impl CableModel {
    /// Parse `catenary` or `rigid`.
    pub fn parse(text: &str) -> std::result::Result<Self, ParseError> {
        match text {
            "catenary" => Ok(CableModel::Catenary),
            "rigid" => Ok(CableModel::Rigid),
            other => Err(ParseError::UnknownChoice {
                what: "cable model",
                given: other.to_string(),
                choices: " (catenary, rigid)".to_string(),
            }),
        }
    }
}

/// Whether the localiser's orientation enters the calibration as a prior.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OrientationPrior {
    /// Position-only pose priors: the statics alone decide the orientation
    /// (the paper's orientation correction `Delta R` with no prior on it).
    Off,
    /// Full pose priors with the noise's orientation sigma.
    On,
    /// Calibrate with the orientation prior, test whether the localiser's
    /// orientations agree with the fitted statics (chi-square of the
    /// orientation residuals at 99.9 %), and drop the prior if they do not.
    /// The default.
    Auto,
}

impl OrientationPrior {
    /// Parse `auto`, `on` or `off`.
    pub fn parse(text: &str) -> std::result::Result<Self, ParseError> {
        match text {
            "auto" => Ok(OrientationPrior::Auto),
            "on" => Ok(OrientationPrior::On),
            "off" => Ok(OrientationPrior::Off),
            other => Err(ParseError::UnknownChoice {
                what: "orientation prior",
                given: other.to_string(),
                choices: " (auto, on, off)".to_string(),
            }),
        }
    }
}

impl std::fmt::Display for OrientationPrior {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            OrientationPrior::Off => "off",
            OrientationPrior::On => "on",
            OrientationPrior::Auto => "auto",
        })
    }
}

/// Robust kernels per factor type.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct RobustKernels {
    /// On the encoder (length) factors.
    pub encoder: RobustKernel,
    /// On the load-cell factor.
    pub load_cell: RobustKernel,
    /// On the pose priors.
    pub pose_prior: RobustKernel,
}

/// How to calibrate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibrationOptions {
    /// Cable model of the final stage.
    pub model: CableModel,
    /// Sensor sigmas used as the factors' noise.
    pub noise: SensorNoise,
    /// Constrain the orientation by the localiser too (default: decide by a
    /// consistency test, see the module docs). The rigid model always uses
    /// it: without statics nothing else fixes the orientation.
    pub orientation_prior: OrientationPrior,
    /// Sigma of the attachment-height constraint, metres (a model equation: tight).
    pub height_sigma_m: f64,
    /// Robust kernels.
    pub robust: RobustKernels,
    /// Solver settings.
    pub lm: LmParams,
    /// The effects of the catalogue whose parameters are estimated too (the
    /// extended model, [`crate::calib::effect_factors`]); empty: the effects
    /// of the robot file (`[effects]`, default none) are known inputs, held fixed.
    pub free_effects: EffectSet,
}

impl CalibrationOptions {
    /// Catenary model, automatic orientation prior, 0.1 mm height constraint, no robust kernels.
    pub fn new(noise: SensorNoise) -> Self {
        Self {
            model: CableModel::Catenary,
            noise,
            orientation_prior: OrientationPrior::Auto,
            height_sigma_m: 1e-4,
            robust: RobustKernels::default(),
            lm: LmParams::default(),
            free_effects: EffectSet::NONE,
        }
    }
}

/// Settings of the gross-error tests.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GrossErrorOptions {
    /// False-alarm rate of each test (per reading: over all readings, Bonferroni;
    /// per sensor type: over the types). Default 1e-3.
    pub false_alarm: f64,
    /// At most this fraction of the readings is left out as gross errors
    /// (and at least one); more failing readings mean an inconsistent model. Default 0.05.
    pub max_excluded_fraction: f64,
}

impl Default for GrossErrorOptions {
    fn default() -> Self {
        Self {
            false_alarm: 1e-3,
            max_excluded_fraction: 0.05,
        }
    }
}

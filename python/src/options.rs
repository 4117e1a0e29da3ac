//! The calibration solver's options as keyword arguments: the same names,
//! defaults, checks and messages as the command's shared flags
//! (`--model`, `--noise`, `--encoder-sigma-m`, ... in `src/cli/mod.rs`).

use pyo3::prelude::*;
use sagcal::calib::{CableModel, CalibrationOptions, OrientationPrior, RobustKernels};
use sagcal::graph::RobustKernel;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;

use crate::invalid;

/// The solver keywords of `calibrate` and `diagnose`, as given.
pub struct SolverArgs<'a> {
    /// `catenary` or `rigid`.
    pub model: &'a str,
    /// `paper`, `authors` (or `none`, refused: the factors need sigmas).
    pub noise: &'a str,
    /// Override of the encoder sigma, metres.
    pub encoder_sigma_m: Option<f64>,
    /// Override of the load-cell sigma, newtons.
    pub load_cell_sigma_n: Option<f64>,
    /// Override of the localiser position sigma, metres.
    pub position_sigma_m: Option<f64>,
    /// `auto`, `on` or `off`.
    pub orientation_prior: &'a str,
    /// Robust kernels: `none`, `huber[:k]`, `cauchy[:c]`.
    pub robust_encoder: &'a str,
    /// On the load-cell factors.
    pub robust_load_cell: &'a str,
    /// On the pose priors.
    pub robust_pose: &'a str,
}

/// Parse a keyword's value; the error names the keyword.
pub fn parse<T>(keyword: &str, value: &str, parser: fn(&str) -> Result<T, String>) -> PyResult<T> {
    parser(value).map_err(|e| invalid(format!("{keyword}: {e}")))
}

/// The noise preset named by `noise`.
pub fn noise_preset(noise: &str) -> PyResult<NoisePreset> {
    parse("noise", noise, NoisePreset::parse)
}

impl SolverArgs<'_> {
    /// The calibration options for `robot`, as `SolverArgs::options` of the command builds them.
    pub fn options(&self, robot: &Robot) -> PyResult<CalibrationOptions> {
        let mut noise = noise_preset(self.noise)?.sigmas(robot.platform_weight_n);
        for (value, target, name) in [
            (self.encoder_sigma_m, &mut noise.encoder_sigma_m, "encoder_sigma_m"),
            (
                self.load_cell_sigma_n,
                &mut noise.load_cell_sigma_n,
                "load_cell_sigma_n",
            ),
            (self.position_sigma_m, &mut noise.position_sigma_m, "position_sigma_m"),
        ] {
            if let Some(v) = value {
                if !(v.is_finite() && v > 0.0) {
                    return Err(invalid(format!("{name} must be a positive number, got {v}")));
                }
                *target = v;
            }
        }
        if [noise.encoder_sigma_m, noise.load_cell_sigma_n, noise.position_sigma_m]
            .iter()
            .any(|s| *s <= 0.0)
        {
            return Err(invalid("sensor sigmas must be positive to weight the factors"));
        }
        let mut options = CalibrationOptions::new(noise);
        options.model = parse("model", self.model, CableModel::parse)?;
        options.orientation_prior = parse("orientation_prior", self.orientation_prior, OrientationPrior::parse)?;
        options.robust = RobustKernels {
            encoder: parse("robust_encoder", self.robust_encoder, RobustKernel::parse)?,
            load_cell: parse("robust_load_cell", self.robust_load_cell, RobustKernel::parse)?,
            pose_prior: parse("robust_pose", self.robust_pose, RobustKernel::parse)?,
        };
        Ok(options)
    }
}

/// Check a false-alarm rate as the command does.
pub fn false_alarm(value: f64, name: &str) -> PyResult<f64> {
    if value > 0.0 && value < 1.0 {
        Ok(value)
    } else {
        Err(invalid(format!("{name} must be between 0 and 1, got {value}")))
    }
}

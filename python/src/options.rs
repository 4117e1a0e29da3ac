//! The calibration solver's keyword arguments, parsed into the library's
//! [`SolverSettings`], which checks them (`sagcal::calib::SolverSettings::options`,
//! its messages naming the keywords as Python spells them).

use pyo3::prelude::*;
use sagcal::calib::{CableModel, OrientationPrior, RobustKernels, SolverSettings};
use sagcal::graph::RobustKernel;
use sagcal::model::sensors::NoisePreset;

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
pub fn parse<T, E: std::fmt::Display>(keyword: &str, value: &str, parser: fn(&str) -> Result<T, E>) -> PyResult<T> {
    parser(value).map_err(|e| invalid(format!("{keyword}: {e}")))
}

/// The noise preset named by `noise`.
pub fn noise_preset(noise: &str) -> PyResult<NoisePreset> {
    parse("noise", noise, NoisePreset::parse)
}

impl SolverArgs<'_> {
    /// The library's solver settings these keywords name (each name parsed,
    /// the numbers checked by [`SolverSettings::options`]).
    pub fn settings(&self) -> PyResult<SolverSettings> {
        Ok(SolverSettings {
            noise: noise_preset(self.noise)?,
            model: parse("model", self.model, CableModel::parse)?,
            encoder_sigma_m: self.encoder_sigma_m,
            load_cell_sigma_n: self.load_cell_sigma_n,
            position_sigma_m: self.position_sigma_m,
            orientation_prior: parse("orientation_prior", self.orientation_prior, OrientationPrior::parse)?,
            robust: RobustKernels {
                encoder: parse("robust_encoder", self.robust_encoder, RobustKernel::parse)?,
                load_cell: parse("robust_load_cell", self.robust_load_cell, RobustKernel::parse)?,
                pose_prior: parse("robust_pose", self.robust_pose, RobustKernel::parse)?,
            },
        })
    }
}

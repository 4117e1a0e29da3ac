//! The flags of the calibration solver shared by the commands that calibrate
//! (`calibrate`, `diagnose`): [`SolverArgs`], flattened into their flags.

/// Options of the calibration solver shared by the commands that calibrate.
#[derive(Debug, Clone, clap::Args)]
pub(super) struct SolverArgs {
    /// Cable model: `catenary` (heavy cable, the default) or `rigid` (massless straight cable).
    #[arg(long, default_value = "catenary", value_parser = sagcal::calib::CableModel::parse)]
    model: sagcal::calib::CableModel,
    /// Sensor noise used as factor weights: `paper` (10 mm, 5 N / 1 N, 5 mm, 0.01 rad) or `authors`.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    noise: sagcal::model::sensors::NoisePreset,
    /// Override the encoder sigma, metres.
    #[arg(long)]
    encoder_sigma_m: Option<f64>,
    /// Override the load-cell sigma, newtons.
    #[arg(long)]
    load_cell_sigma_n: Option<f64>,
    /// Override the localiser position sigma, metres.
    #[arg(long)]
    position_sigma_m: Option<f64>,
    /// The localiser's orientation as a prior: `auto` (used unless a chi-square test finds it
    /// inconsistent with the fitted statics), `on` or `off` (the statics decide).
    #[arg(long, default_value = "auto", value_parser = sagcal::calib::OrientationPrior::parse)]
    orientation_prior: sagcal::calib::OrientationPrior,
    /// Robust kernel on the encoder factors: none, huber[:k], cauchy[:c].
    #[arg(long, default_value = "none", value_parser = sagcal::graph::RobustKernel::parse)]
    robust_encoder: sagcal::graph::RobustKernel,
    /// Robust kernel on the load-cell factors.
    #[arg(long, default_value = "none", value_parser = sagcal::graph::RobustKernel::parse)]
    robust_load_cell: sagcal::graph::RobustKernel,
    /// Robust kernel on the pose priors.
    #[arg(long, default_value = "none", value_parser = sagcal::graph::RobustKernel::parse)]
    robust_pose: sagcal::graph::RobustKernel,
}

impl SolverArgs {
    /// The library's solver settings these flags give.
    pub(super) fn settings(&self) -> sagcal::calib::SolverSettings {
        sagcal::calib::SolverSettings {
            model: self.model,
            noise: self.noise,
            encoder_sigma_m: self.encoder_sigma_m,
            load_cell_sigma_n: self.load_cell_sigma_n,
            position_sigma_m: self.position_sigma_m,
            orientation_prior: self.orientation_prior,
            robust: sagcal::calib::RobustKernels {
                encoder: self.robust_encoder,
                load_cell: self.robust_load_cell,
                pose_prior: self.robust_pose,
            },
        }
    }
}

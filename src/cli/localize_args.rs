//! The flags of `sagcal localize` ([`LocalizeArgs`]), for robots of four
//! cables and of 3 to 8.

use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub(super) struct LocalizeArgs {
    /// The calibrated robot (TOML): anchors, length offsets, `[effects]`.
    #[arg(long)]
    pub(super) robot: PathBuf,
    /// Readings: `l1_m,l2_m,l3_m,l4_m[,f_ref_n]`, a sagcal measurement file, a RecurDyn log or
    /// the authors' dataset folder.
    #[arg(long)]
    pub(super) data: PathBuf,
    /// Use the input's localiser pose as a prior (by default it is only compared with).
    #[arg(long)]
    pub(super) pose_prior: bool,
    /// Sensor sigmas of the readings: paper or authors.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    pub(super) noise: sagcal::model::sensors::NoisePreset,
    /// False-alarm rate of each row's chi-square consistency test.
    #[arg(long, default_value_t = 1e-3)]
    pub(super) false_alarm: f64,
    /// Leave the robot file's recorded calibration covariance out of the sigmas.
    #[arg(long)]
    pub(super) no_calibration_uncertainty: bool,
    /// Skip the multistart search for every equilibrium of each row (about
    /// 1000 starts per row): for long trajectories, each row warm-started
    /// from the previous one.
    #[arg(long)]
    pub(super) fast: bool,
    /// Write the poses as CSV (atomically).
    #[arg(long)]
    pub(super) out: Option<PathBuf>,
    /// Draw the localised poses with their 1-sigma ellipses (top and side
    /// views), beside the input's poses when it has them (PNG if the name ends in `.png`, SVG otherwise).
    #[arg(long)]
    pub(super) plot: Option<PathBuf>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub(super) json: bool,
}

//! The flags of `sagcal calibrate` ([`CalibrateArgs`]), for robots of four
//! cables and of 3 to 8.

use std::path::PathBuf;

use super::solver_args::SolverArgs;

#[derive(Debug, clap::Args)]
pub(super) struct CalibrateArgs {
    /// Nominal robot description (TOML): the initial guess of anchors and offsets.
    #[arg(long)]
    pub(super) robot: PathBuf,
    /// Measurements: sagcal CSV (see docs/measurements.md), a RecurDyn log, or the authors' dataset folder
    /// (`pos_i_cpp_test.csv`, `R_i_cpp_test.csv`, `lc_meas_cpp_test.csv`, `forces_cpp_test.csv`).
    #[arg(long)]
    pub(super) data: PathBuf,
    /// Write the calibrated robot (TOML) here.
    #[arg(long)]
    pub(super) out: Option<PathBuf>,
    /// Write a plot of nominal and calibrated anchors with error ellipses here (PNG if the name ends in `.png`, SVG otherwise).
    #[arg(long)]
    pub(super) plot: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub(super) json: bool,
    /// Write the calibrated robot even when the fit fails its own consistency
    /// tests (the verdict is recorded in the file's header comment).
    #[arg(long)]
    pub(super) accept_inconsistent: bool,
    /// False-alarm rate of the gross-error tests (per reading, over all
    /// readings; per sensor type, over the types).
    #[arg(long, default_value_t = 1e-3)]
    pub(super) false_alarm: f64,
    #[command(flatten)]
    pub(super) solver: SolverArgs,
}

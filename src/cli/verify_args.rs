//! The flags of `sagcal verify` ([`VerifyArgs`], [`ClosureArg`]), for
//! robots of four cables and of 3 to 8.

use std::path::PathBuf;

use clap::ValueEnum;

/// Which measurement closes the statics in the four-cable `verify`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(super) enum ClosureArg {
    /// Position + the reference cable's load-cell tension (default).
    ReferenceTension,
    /// Position + the four measured cable lengths (least squares).
    CableLengths,
}

#[derive(Debug, clap::Args)]
pub(super) struct VerifyArgs {
    /// Robot description (TOML), e.g. robots/large.toml or a file `sagcal calibrate --out` wrote.
    #[arg(long)]
    pub(super) robot: PathBuf,
    /// Measurement log: RecurDyn CSV, sagcal CSV or the authors' dataset folder.
    #[arg(long)]
    pub(super) data: PathBuf,
    /// Four cables: the measurement that closes the one-parameter family of equilibria
    /// (default reference-tension). Robots of 3 to 8 cables are closed by every reading at once.
    #[arg(long, value_enum)]
    pub(super) close_with: Option<ClosureArg>,
    /// Keep rows whose pose was transcribed rounded to 0.01 m (rejected by default; four cables).
    #[arg(long)]
    pub(super) keep_rounded: bool,
    /// Robots of 3 to 8 cables: the sensor noise that weighs the readings, `paper` (default) or
    /// `authors`.
    #[arg(long, value_parser = sagcal::model::sensors::NoisePreset::parse)]
    pub(super) noise: Option<sagcal::model::sensors::NoisePreset>,
    /// Robots of 3 to 8 cables: the false-alarm rate of the file's, each row's and each
    /// reading's test (default 0.001).
    #[arg(long)]
    pub(super) false_alarm: Option<f64>,
    /// Print the full report as JSON instead of tables.
    #[arg(long)]
    pub(super) json: bool,
}

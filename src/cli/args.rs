//! The command line's shape: [`Cli`], its subcommands ([`Command`],
//! [`ExperimentCommand`]) and the flags of `completions`. Each command's own
//! flags sit beside the command (`calibrate::CalibrateArgs`, ...); clap reads
//! the doc comments as help text.

use clap::{Parser, Subcommand};

use super::calibrate::CalibrateArgs;
use super::check::CheckArgs;
use super::demo::DemoArgs;
use super::diagnose_args::DiagnoseArgs;
use super::experiment::Table2Args;
use super::hidden_args::HiddenEffectsArgs;
use super::init::InitArgs;
use super::localize::LocalizeArgs;
use super::localize_experiment::LocalizeExperimentArgs;
use super::plan_args::PlanArgs;
use super::simulate_args::SimulateArgs;
use super::verify_args::VerifyArgs;

/// Self-calibration of suspended cable-driven parallel robots with sagging cables.
#[derive(Debug, Parser)]
#[command(name = "sagcal", version, about, long_about = None)]
pub(super) struct Cli {
    #[command(subcommand)]
    pub(super) command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub(super) enum Command {
    /// Simulate the built-in large robot, calibrate it from a perturbed guess, plot the anchors (the default).
    Demo(DemoArgs),
    /// Write a new robot file (TOML, every key commented) from your robot's anchors, attachments and weights.
    Init(InitArgs),
    /// Say what sagcal understood from a robot file and a data file, before any fit, and what looks wrong.
    Check(CheckArgs),
    /// Estimate anchors and encoder length offsets from measurements.
    Calibrate(CalibrateArgs),
    /// Write simulated measurements of a robot (sagcal's CSV format).
    Simulate(SimulateArgs),
    /// Check the kineto-static model against measured data (the paper's Table I).
    Verify(VerifyArgs),
    /// Find what the model gets wrong: test residuals, fit the catalogue of effects, report the gain.
    Diagnose(DiagnoseArgs),
    /// Localise the calibrated robot: pose and tensions from its cable readings.
    Localize(LocalizeArgs),
    /// Choose the calibration poses that make the anchors observable (optimal design on the Cramer-Rao bound).
    Plan(PlanArgs),
    /// Reproduce the paper's experiments.
    #[command(subcommand)]
    Experiment(ExperimentCommand),
    /// Print a shell completion script (e.g. `sagcal completions bash > ~/.local/share/bash-completion/completions/sagcal`).
    Completions(CompletionsArgs),
}

#[derive(Debug, clap::Args)]
pub(super) struct CompletionsArgs {
    /// The shell: bash, zsh, fish (also elvish, powershell).
    #[arg(value_enum)]
    pub(super) shell: clap_complete::Shell,
}

#[derive(Debug, Subcommand)]
pub(super) enum ExperimentCommand {
    /// The paper's Table II calibration protocol with the Cramer-Rao bound.
    Table2(Table2Args),
    /// Hide effects in simulated data and score `sagcal diagnose`.
    HiddenEffects(HiddenEffectsArgs),
    /// Calibrate by the Table II protocol, then localise the held-out poses.
    Localize(LocalizeExperimentArgs),
}

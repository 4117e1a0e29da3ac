//! Command-line parsing and dispatch. Every command returns a `Result`; errors
//! are printed once, to stderr, with exit code 1 (2 for usage errors).

mod output;
mod verify;

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

/// Self-calibration of suspended cable-driven parallel robots with sagging cables.
#[derive(Debug, Parser)]
#[command(name = "sagcal", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Check the kineto-static model against measured data (the paper's Table I).
    Verify(VerifyArgs),
}

/// Which measurement closes the statics in `verify`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ClosureArg {
    /// Position + the reference cable's load-cell tension (default).
    ReferenceTension,
    /// Position + the four measured cable lengths (least squares).
    CableLengths,
}

#[derive(Debug, clap::Args)]
struct VerifyArgs {
    /// Robot description (TOML), e.g. robots/large.toml.
    #[arg(long)]
    robot: PathBuf,
    /// Measurement log (RecurDyn CSV).
    #[arg(long)]
    data: PathBuf,
    /// The measurement that closes the one-parameter family of equilibria.
    #[arg(long, value_enum, default_value = "reference-tension")]
    close_with: ClosureArg,
    /// Keep rows whose pose was transcribed rounded to 0.01 m (rejected by default).
    #[arg(long)]
    keep_rounded: bool,
    /// Print the full report as JSON instead of tables.
    #[arg(long)]
    json: bool,
}

/// Parse the command line, run the command, return the process exit code.
pub fn run() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    let result = match cli.command {
        Command::Verify(args) => verify::run(&args),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e}");
            1
        }
    }
}

//! The dispatch: parse the command line, run the command, turn its result
//! into the process exit code.

use std::path::PathBuf;

use clap::{CommandFactory, Parser};

use super::args::{Cli, Command, ExperimentCommand};
use super::calibrate;
use super::check;
use super::demo::{self, DemoArgs};
use super::diagnose;
use super::experiment;
use super::hidden;
use super::init;
use super::localize;
use super::localize_experiment;
use super::plan;
use super::simulate;
use super::verify;

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
    if let Err(message) = sagcal::simd::check_switch() {
        eprintln!("error: {message}");
        return 2;
    }
    let result = match cli.command {
        None => demo::run(&DemoArgs {
            seed: 1,
            poses: 35,
            out_dir: PathBuf::from("sagcal-demo"),
            json: false,
        }),
        Some(Command::Demo(args)) => demo::run(&args),
        Some(Command::Init(args)) => init::run(&args),
        Some(Command::Check(args)) => check::run(&args),
        Some(Command::Calibrate(args)) => calibrate::run(&args),
        Some(Command::Simulate(args)) => simulate::run(&args),
        Some(Command::Verify(args)) => verify::run(&args),
        Some(Command::Diagnose(args)) => diagnose::run(&args),
        Some(Command::Localize(args)) => localize::run(&args),
        Some(Command::Plan(args)) => plan::run(&args),
        Some(Command::Experiment(ExperimentCommand::Table2(args))) => experiment::run(&args),
        Some(Command::Experiment(ExperimentCommand::HiddenEffects(args))) => hidden::run(&args),
        Some(Command::Experiment(ExperimentCommand::Localize(args))) => localize_experiment::run_experiment(&args),
        Some(Command::Completions(args)) => {
            clap_complete::generate(args.shell, &mut Cli::command(), "sagcal", &mut std::io::stdout());
            Ok(())
        }
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e}");
            1
        }
    }
}

//! Command-line parsing and dispatch. Every command returns a `Result`; errors
//! are printed once, to stderr, with exit code 1 (2 for usage errors).
//!
//! The command line's shape is in `args`, each command's flags beside the
//! command's run (`calibrate::CalibrateArgs`, ...), the flags of the
//! calibration solver in `solver_args`, the value parsers several commands
//! share in `parse`, and the dispatch in `run`.

mod args;
mod calibrate;
mod calibrate_args;
mod calibrate_suspended;
mod calibration_tables;
mod check;
mod check_suspended;
mod check_tables;
mod demo;
mod diagnose;
mod diagnose_args;
mod diagnose_suspended;
mod experiment;
mod experiment_suspended;
mod gross_errors;
mod hidden;
mod hidden_args;
mod hidden_suspended;
mod init;
mod localize;
mod localize_args;
mod localize_experiment;
mod localize_suspended;
mod output;
mod parse;
mod plan;
mod plan_args;
mod plan_suspended;
mod plan_tables;
mod robot_kind;
mod run;
mod simulate;
mod simulate_args;
mod simulate_suspended;
mod solver_args;
mod table2_args;
mod verify;
mod verify_args;
mod verify_suspended;

pub use run::run;

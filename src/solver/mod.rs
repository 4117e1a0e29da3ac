//! A sparse Levenberg-Marquardt for [`crate::graph::FactorGraph`]s.
//!
//! Each iteration linearises every factor once (whitened by its sigmas,
//! reweighted by its robust kernel), assembles `H = J^T J` and `g = J^T r`
//! into the pattern analysed once by [`LinearSystem`] (which eliminates the
//! graph's local groups block by block when the structure allows, see the
//! `schur` module, else uses faer's sparse Cholesky), and tries damped steps
//! `(H + lambda D) dx = -g` with `D = clamp(diag H)` (Marquardt scaling).
//! A trial is accepted when the gain ratio
//! `rho = (actual cost decrease) / (decrease predicted by the linear model)`
//! is positive; lambda then follows Nielsen's rule
//! (`lambda *= max(1/3, 1 - (2 rho - 1)^3)`), and on rejection or a failed
//! factorisation it grows by `nu`, `nu` doubling (Madsen, Nielsen & Tingleff,
//! *Methods for Non-Linear Least Squares Problems*, 2004, Sec. 3.2). A
//! rejected step reuses the linearisation.
//!
//! Graphs may name groups of *local* variables
//! ([`FactorGraph::local_groups`]); every trial point then has each group
//! re-minimised with the rest held before its cost is judged (nonlinear
//! elimination, see the `local` module), which keeps long steps of the global
//! variables on the curved valley of a tight model constraint.
//!
//! The calibration builds its graph and calls [`optimize`]; the benchmark
//! problem shows the loop on its own:
//!
//! ```
//! use sagcal::experiments::benchmark::BenchmarkProblem;
//! use sagcal::solver::optimize;
//!
//! let problem = BenchmarkProblem::new(9, 1)?;
//! let mut built = problem.graph();
//! let summary = optimize(&mut built.graph, &BenchmarkProblem::stopping()).map_err(sagcal::Error::from)?;
//! assert!(summary.final_cost < 1e-3 * summary.initial_cost);
//! # Ok::<(), sagcal::Error>(())
//! ```
//!
//! [`FactorGraph::local_groups`]: crate::graph::FactorGraph::local_groups

mod accumulate;
mod covariance;
mod dense;
mod levenberg_marquardt;
mod linear_system;
mod linearization;
mod local;
mod local_gauge;
mod params;
mod redundancy;
mod schur;
mod score;
mod shapes;
mod simd;
mod sparse_cholesky;
mod summary;
mod system_cache;

pub use crate::error::SolverError;
pub use covariance::{marginal_covariance, marginal_covariance_cached, Covariance, UnobservableDirection};
pub use levenberg_marquardt::{optimize, optimize_cached};
pub use linear_system::LinearSystem;
pub use local_gauge::{marginal_covariance_over_local_gauge, LocalGaugeCovariance};
pub use params::LmParams;
pub use redundancy::redundancy_numbers;
pub use score::{score_system, score_tests, Direction, ScoreSystem, ScoreTest};
pub use shapes::Fallbacks;
pub use summary::{IterationSummary, SolveSummary, Termination};
pub use system_cache::SystemCache;

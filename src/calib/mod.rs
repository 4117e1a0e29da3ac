//! Self-calibration (paper Sec. IV): estimate the four anchors and the four
//! encoder length offsets from the robot's own sensors at static poses.
//!
//! The factor graph has, per pose `k`, the platform pose `X_k` and the
//! reference-cable tension `(f_h, f_v)_k`, and globally the anchors `p_a,i`
//! and offsets `l_i^0`. Factors: catenary length (eq. 14), attachment height
//! (eq. 15), reference tension (eq. 16), pose prior, and a positivity guard
//! on every cable's horizontal tension (inactive at the optimum).
//!
//! **Orientation.** The paper adds an orientation-correction variable
//! `Delta R_k` so that the statics, not the localiser's orientation, decide
//! how the platform hangs. sagcal's pose variable already carries the full
//! orientation, and the pose prior's orientation part is switchable
//! ([`OrientationPrior`]). Where the localiser's orientation agrees with the
//! statics it is information (on the small robot it halves the anchor error);
//! where it does not (the RecurDyn log is ~1.9 degrees off the model's
//! equilibria, 3 sigma under the paper's noise and 20 under the authors') a
//! tight prior would fight the statics and bias the anchors by metres. The
//! default, [`OrientationPrior::Auto`], decides from the data: it calibrates
//! with the prior, tests the orientation residuals by chi-square, and if they
//! are inconsistent calibrates again without it, which is the paper's
//! `Delta R` with no prior on it. The decision is in
//! [`CalibrationResult::orientation_check`].
//!
//! **Initialisation** ([`calibrate`]): (1) a rigid massless-cable calibration
//! from the initial guess (a benign trilateration-like problem), (2) a per-pose
//! warm-up: the statics (problem (a)) at each measured position and load-cell
//! tension with the stage-1 anchors gives every pose a consistent orientation
//! and tension, (3) the full catenary graph. Eq. (17)-(18) alone often start
//! with negative tensions in other cables; this sequence does not.
//!
//! **Basins.** The rigid stage fits, cable by cable, one anchor and one
//! offset to that cable's lengths (the poses are held by their priors): it
//! knows nothing of the statics. Where the cables are nearly vertical and the
//! poses form a narrow column under the anchors (the authors' small robot,
//! `robots/small-authors.toml`: anchors 4.7 m apart in x, poses 9 to 24 m
//! below them), the lengths barely change when an anchor slides along its
//! mean cable direction (the offset takes up the difference) or turns about
//! the column, so the rigid fit of a guess several metres off can leave one
//! anchor tens of metres along that valley or on the wrong side of the
//! column. The platform's force balance and orientation would tell, but only
//! the catenary stages see them, and LM from such a start ends in a minimum
//! whose cost is hundreds of times what the noise allows. Three remedies, none
//! with a tuned constant:
//! - the start with the lower warm-up cost is solved first and kept if its
//!   minimum passes the chi-square test of its cost (99.9 % quantile at the
//!   redundancy; the common case, one solve); otherwise both starts (the
//!   guess and the rigid fit) are solved to the end and the lower final cost
//!   wins (a converged solve first, then the one leaving out fewer poses): a
//!   start's warm-up cost says little about its basin;
//! - if the two did not reach one minimum and the better fails the
//!   chi-square test of its cost (99.9 % quantile at the redundancy), or no
//!   start had an equilibrium at enough poses, the anchors mixed cable by
//!   cable from the guess and the rigid fit are solved too (14 more starts):
//!   a wrong rigid minimum for one cable then does not spoil the others;
//! - with [`OrientationPrior::Auto`] a failed orientation test can be a wrong
//!   basin of the fit with the prior rather than a localiser at odds with the
//!   statics, so the fit with the prior is repeated from the fit without it
//!   before the prior is dropped (`orientation.rs`).
//!
//! What stays lost: a guess whose anchors are on the wrong side of the pose
//! column (a 10 m perturbation of a robot 4.7 m wide swaps anchors or puts
//! them below the poses), so that neither the guess, the rigid fit, nor any
//! mix of them holds the platform with positive tensions at enough poses; and
//! with few poses and no orientation prior, minima of equal depth along a
//! poorly observed direction.
//!
//! **Solving.** Each pose's variables (platform pose, reference tension) form
//! a local group of the graph: after every trial step the solver re-fits each
//! pose to its own factors with the anchors and offsets held, so a step of
//! the anchors is judged with every pose back on its statics. Without it the
//! 0.1 mm attachment-height constraint bends the valley so sharply that LM
//! creeps along it (the small robot, with its nearly vertical cables, hit
//! 500 iterations in most trials).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::{calibrate, CalibrationOptions};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let truth = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
//! let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 15, &mut rng)?;
//! let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
//! let data = measure(&truth, &equilibria, &noise, &mut rng);
//! // The operator's guess: anchor 2 measured 3 m off, every encoder offset 1 m off.
//! let mut guess = truth.clone();
//! guess.anchors_m[1].x += 3.0;
//! guess.length_offsets_m = [1.0; 4];
//! let result = calibrate(&guess, &data, &CalibrationOptions::new(noise))?;
//! let error_m = (result.robot.anchors_m[1] - truth.anchors_m[1]).norm();
//! assert!(error_m < 1.0, "anchor 2 is {error_m} m off after calibration");
//! # Ok::<(), sagcal::Error>(())
//! ```

pub mod effect_factors;
mod entry;
pub mod factors;
mod fit_progress;
mod graph;
pub mod gross_errors;
mod init;
mod job;
mod load_cell_factor;
pub mod mistakes;
mod mounted_pose_prior;
mod options;
mod orientation;
mod pipeline;
mod predict;
mod prepared;
mod refine;
pub mod report;
mod result;
pub mod screen;
mod settings;

mod snooping;
pub mod suspended;
mod system_scope;
mod uncertainty;

pub use entry::calibrate;
pub use graph::{
    build_graph, effects_from_graph, robot_from_graph, validate_measurements, CalibrationGraph, MIN_POSES,
};
pub use init::warm_start;
pub use job::{calibrate_job, calibrate_job_with_progress, refusal, CalibrationJob};
pub use options::{CableModel, CalibrationOptions, OrientationPrior, RobustKernels};
pub use predict::predict_with_effects;
pub use prepared::PreparedCalibration;
pub use refine::{refine_with_effects, set_effect_estimates, without_estimated};
pub use result::{
    factor_statistics, CalibrationResult, EffectEstimate, FactorStatistics, OrientationCheck, ParameterUncertainty,
    StageSummary,
};
pub use settings::{check_false_alarm, CalibrationSettings, SolverSettings};
pub use uncertainty::{
    anchor_and_offset_uncertainty, anchor_rms_bound_m, cramer_rao_bound, parameter_uncertainty, CalibrationError,
};

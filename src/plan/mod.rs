//! Planning the calibration (the paper's Sec. VI future work:
//! "observation-aware trajectory generation"): which static poses to visit
//! so that the anchors and offsets are best determined, and in what order.
//!
//! 1. [`information`]: each candidate pose's Fisher information about the
//!    global parameters, its own pose and tension eliminated exactly (the
//!    Schur complement of the calibration's graph at the nominal robot).
//! 2. [`design`]: the A-optimal (or D-optimal) choice of `N` candidates,
//!    greedy with rank-k updates, then Fedorov exchanges.
//! 3. [`bound`]: the Cramer-Rao bound of a pose set from those terms.
//! 4. [`order`]: a short visiting order (nearest neighbour + 2-opt).
//! 5. [`candidates`]: the tension and clearance margins a candidate keeps.
//!
//! [`plan_poses`] runs 1-4 and compares the plan with random pose sets of
//! the same candidates. [`suspended_information`] gives step 1 for a robot of
//! any number of cables `N` (its `3N` anchor coordinates and `N` offsets);
//! steps 2-4 take its terms as they are.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::plan::{candidate_information, choose_poses, plan_bound, DesignOptions};
//! use sagcal::sim::closed_form::{sample_equilibria, Workspace};
//!
//! let robot = Robot::builtin("small")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let candidates = sample_equilibria(&robot, &Workspace::default_for(&robot), 40, &mut rng)?;
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(robot.platform_weight_n));
//! let information = candidate_information(&robot, &candidates, &options)?;
//! let design = choose_poses(&information, &DesignOptions::new(9))?;
//! let planned = plan_bound(&information, &design.chosen).expect("9 poses determine the anchors");
//! let first_nine: Vec<usize> = (0..9).collect();
//! let arbitrary = plan_bound(&information, &first_nine).expect("determined");
//! assert!(planned.anchor_rms_m < arbitrary.anchor_rms_m);
//! # Ok::<(), sagcal::Error>(())
//! ```

pub mod bound;
pub mod candidates;
pub mod design;
pub mod information;
pub mod order;
mod plan_poses;
mod random;
pub mod suspended_information;

pub use bound::{plan_bound, PlanBound};
pub use candidates::{distinct_platform_poses, distinct_poses, Margins};
pub use design::{
    choose_more_poses, choose_more_poses_with_progress, choose_poses, Criterion, Design, DesignOptions, DesignProgress,
};
pub use information::{candidate_information, pose_information, PoseInformation};
pub use order::{path_length_m, visiting_order};
pub use plan_poses::{plan_poses, Plan};
pub use random::{random_bounds, RandomBounds, RANDOM_DRAWS};

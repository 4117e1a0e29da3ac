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
//! the same candidates.
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

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

pub use bound::{plan_bound, PlanBound};
pub use candidates::{distinct_poses, Margins};
pub use design::{choose_more_poses, choose_poses, Criterion, Design, DesignOptions};
pub use information::{pose_information, PoseInformation};
pub use order::{path_length_m, visiting_order};

use crate::calib::{CalibrationOptions, MIN_POSES};
use crate::error::{Error, Result};
use crate::model::robot::Robot;
use crate::model::statics::Equilibrium;

/// The mean bound of random pose sets of one size drawn from the candidates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RandomBounds {
    /// Poses per set.
    pub poses: usize,
    /// Sets drawn.
    pub draws: usize,
    /// Sets whose poses did not determine every parameter (left out of the means).
    pub undetermined: usize,
    /// Mean over the determined sets of the RMS anchor error bound, metres.
    pub anchor_rms_m: f64,
    /// Mean over the determined sets of the RMS offset error bound, metres.
    pub offset_rms_m: f64,
    /// Per anchor, the mean over the determined sets of its 3x3 covariance, m^2 (for the figure).
    #[serde(skip)]
    pub anchor_covariance_m2: Vec<[[f64; 3]; 3]>,
}

/// The information of every candidate (in parallel), at the nominal robot.
pub fn candidate_information(
    nominal: &Robot,
    candidates: &[Equilibrium],
    options: &CalibrationOptions,
) -> Result<Vec<PoseInformation>> {
    candidates
        .par_iter()
        .map(|eq| pose_information(nominal, eq, options))
        .collect()
}

/// The bounds of `draws` random sets of `poses` distinct candidates (seeded).
pub fn random_bounds(information: &[PoseInformation], poses: usize, draws: usize, seed: u64) -> RandomBounds {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut anchor = Vec::with_capacity(draws);
    let mut offset = Vec::with_capacity(draws);
    let mut covariance = vec![[[0.0; 3]; 3]; crate::model::robot::CABLE_COUNT];
    let mut indices: Vec<usize> = (0..information.len()).collect();
    let poses = poses.min(information.len());
    for _ in 0..draws {
        for i in 0..poses {
            let j = rng.random_range(i..indices.len());
            indices.swap(i, j);
        }
        if let Some(b) = plan_bound(information, &indices[..poses]) {
            anchor.push(b.anchor_rms_m);
            offset.push(b.offset_rms_m);
            for (sum, c) in covariance.iter_mut().zip(&b.anchor_covariance_m2) {
                for r in 0..3 {
                    for k in 0..3 {
                        sum[r][k] += c[r][k];
                    }
                }
            }
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let determined = anchor.len().max(1) as f64;
    for c in covariance.iter_mut().flatten().flatten() {
        *c /= determined;
    }
    RandomBounds {
        anchor_covariance_m2: covariance,
        poses,
        draws,
        undetermined: draws - anchor.len(),
        anchor_rms_m: if anchor.is_empty() { f64::NAN } else { mean(&anchor) },
        offset_rms_m: if offset.is_empty() { f64::NAN } else { mean(&offset) },
    }
}

/// A plan: the chosen candidates in visiting order, their bound, and random sets for comparison.
#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    /// Candidate indices in visiting order.
    pub order: Vec<usize>,
    /// The bound of the plan.
    pub bound: PlanBound,
    /// Random sets of the same size from the same candidates.
    pub random: RandomBounds,
    /// Random sets of 35 poses (the paper's largest Table II column), if there are that many candidates.
    pub random35: Option<RandomBounds>,
    /// Length of the visiting path, metres.
    pub path_length_m: f64,
    /// The search's details.
    pub design: Design,
}

/// Random sets drawn for each comparison.
pub const RANDOM_DRAWS: usize = 100;

/// Choose, order and compare (module docs); `seed` draws the random sets,
/// `start_m` is where the path begins (the point nearest it is visited first).
pub fn plan_poses(
    candidates: &[Equilibrium],
    information: &[PoseInformation],
    options: &DesignOptions,
    start_m: &Vector3<f64>,
    seed: u64,
) -> Result<Plan> {
    let design = choose_poses(information, options)?;
    let bound = plan_bound(information, &design.chosen).ok_or_else(|| undetermined(candidates, &design.chosen))?;
    let points: Vec<Vector3<f64>> = design.chosen.iter().map(|&k| candidates[k].pose.position_m).collect();
    let order: Vec<usize> = visiting_order(&points, start_m)
        .into_iter()
        .map(|i| design.chosen[i])
        .collect();
    let ordered: Vec<Vector3<f64>> = order.iter().map(|&k| candidates[k].pose.position_m).collect();
    Ok(Plan {
        path_length_m: path_length_m(&ordered),
        bound,
        random: random_bounds(information, options.poses, RANDOM_DRAWS, seed),
        random35: (information.len() >= 35).then(|| random_bounds(information, 35, RANDOM_DRAWS, seed ^ 35)),
        order,
        design,
    })
}

/// Why the poses `chosen` do not determine every anchor and offset: too
/// few, too few distinct, or an arrangement that leaves a direction free.
fn undetermined(candidates: &[Equilibrium], chosen: &[usize]) -> Error {
    let poses: Vec<Equilibrium> = chosen.iter().map(|&k| candidates[k].clone()).collect();
    let distinct = distinct_poses(&poses, MIN_POSES).len();
    let why = if chosen.len() < MIN_POSES {
        format!("choose at least {MIN_POSES}")
    } else if distinct < MIN_POSES {
        format!("only {distinct} of them are distinct poses, and at least {MIN_POSES} are needed")
    } else {
        "their arrangement leaves a direction of the anchors or offsets free: draw the candidates over a wider box"
            .into()
    };
    Error::InvalidInput(format!(
        "the {} chosen poses do not determine every anchor and offset (each pose gives 4 equations for the 12 anchor coordinates and 4 offsets): {why}",
        chosen.len()
    ))
}

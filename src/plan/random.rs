//! The bounds of random pose sets drawn from the candidates, the
//! comparison a plan is judged by: [`random_bounds`] draws [`RANDOM_DRAWS`]
//! sets (seeded) and averages their Cramer-Rao bounds ([`RandomBounds`]).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::bound::plan_bound;
use super::information::PoseInformation;

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

/// The bounds of `draws` random sets of `poses` distinct candidates (seeded).
pub fn random_bounds(information: &[PoseInformation], poses: usize, draws: usize, seed: u64) -> RandomBounds {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut anchor = Vec::with_capacity(draws);
    let mut offset = Vec::with_capacity(draws);
    let cables = information.first().map_or(0, |p| p.cables);
    let mut covariance = vec![[[0.0; 3]; 3]; cables];
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

/// Random sets drawn for each comparison.
pub const RANDOM_DRAWS: usize = 100;

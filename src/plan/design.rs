//! Choosing the poses: greedy selection with rank-k updates, then Fedorov
//! exchange passes (Fedorov, *Theory of Optimal Experiments*, 1972, Ch. 3;
//! Atkinson, Donev & Tobias, *Optimum Experimental Designs*, 2007, Ch. 12).
//!
//! The information of a set of poses is `M = sum_k U_k U_k^T` (see
//! `information`). With `C = M^-1`, adding pose `k` changes the covariance by
//! the Sherman-Morrison-Woodbury identity (Golub & Van Loan, *Matrix
//! Computations*, 4th ed., 2013, Sec. 2.1.4)
//! ```text
//! (M + U U^T)^-1 = C - W S^-1 W^T,   W = C U,   S = 1 + U^T C U,
//! ```
//! so the A-criterion (trace of the anchor block of the covariance) falls by
//! `trace_A(W S^-1 W^T) = sum_{a in anchors} |L^-1 w_a|^2` (`S = L L^T`,
//! `w_a` row `a` of `W`), and the D-criterion (`log det M`) rises by
//! `log det S = 2 sum log L_ii` (the matrix determinant lemma). One sweep
//! over all candidates is one product `C [U_1 .. U_K]` and a small Cholesky
//! per candidate: `O(K n^2 r)` for `n` globals and rank `r`.
//!
//! **Singular start.** Fewer than 4 poses leave `M` singular (each pose adds
//! at most 4 to 7 independent equations about the 16 globals, and with the
//! statics alone 4 per pose is the paper's count). The search therefore runs
//! on `M + delta 1` with a ridge `delta` of `1e-9` times the mean diagonal of
//! one pose's information (reported in [`Design::ridge`]): while a direction
//! is undetermined its variance is `~1/delta`, so the first steps choose the
//! poses that determine the most directions, and once `M` is regular the
//! ridge changes the criterion by about `1e-9` relative. The reported bounds
//! are computed without it.
//!
//! After every greedy step and every exchange, `C` is recomputed from `M` by
//! Cholesky (`O(n^3)`, negligible next to a sweep), so the updates never
//! accumulate rounding.
//!
//! ```
//! use nalgebra::DMatrix;
//! use sagcal::plan::information::PoseInformation;
//! use sagcal::plan::{choose_poses, DesignOptions};
//! // 32 candidates: each global parameter measured once with sigma 1 (candidates 0..16)
//! // and once with sigma 1/2 (16..32). The A-criterion weighs the 12 anchor coordinates:
//! // the A-optimal 12 poses are their precise measurements, and the trace of the anchor
//! // covariance is then 12 x (1/2)^2 = 3.
//! let unit = |k: usize, w: f64| PoseInformation { factor: DMatrix::from_fn(16, 1, |r, _| if r == k { w } else { 0.0 }), cables: 4 };
//! let candidates: Vec<PoseInformation> = (0..16).map(|k| unit(k, 1.0)).chain((0..16).map(|k| unit(k, 2.0))).collect();
//! let design = choose_poses(&candidates, &DesignOptions::new(12))?;
//! let mut chosen = design.chosen.clone();
//! chosen.sort();
//! assert_eq!(chosen, (16..28).collect::<Vec<_>>());
//! assert!((design.value - 3.0).abs() < 1e-6);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::DMatrix;
use serde::Serialize;

use super::bound::{covariance_of, information_sum};
use super::information::{anchor_parameters, PoseInformation};
use crate::error::{Error, ParseError, Result};

/// The ridge of the search, relative to the mean diagonal of one pose's information.
pub const RIDGE_FRACTION: f64 = 1e-9;

/// What the design minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// A-optimal: the trace of the anchors' covariance (the mean squared
    /// Euclidean anchor error the bound allows, times 4).
    A,
    /// D-optimal: `-log det` of the information of all globals (the volume of
    /// the confidence ellipsoid of anchors and offsets together).
    D,
}

impl Criterion {
    /// Parse `a` or `d`.
    pub fn parse(text: &str) -> std::result::Result<Self, ParseError> {
        match text.to_ascii_lowercase().as_str() {
            "a" => Ok(Self::A),
            "d" => Ok(Self::D),
            other => Err(ParseError::UnknownChoice {
                what: "design criterion",
                given: other.to_string(),
                choices: " (a, d)".to_string(),
            }),
        }
    }
}

impl std::fmt::Display for Criterion {
    /// `A` or `D`, as in `A-optimal`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::A => "A",
            Self::D => "D",
        })
    }
}

/// Settings of the search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DesignOptions {
    /// Poses to choose.
    pub poses: usize,
    /// The criterion.
    pub criterion: Criterion,
    /// Largest number of exchange passes (each tries to swap every chosen pose once).
    pub max_exchange_passes: usize,
    /// Stop the exchanges when a pass improves the criterion by less than
    /// this fraction (of its value for A, in absolute `log det` for D).
    pub exchange_tolerance: f64,
}

impl DesignOptions {
    /// A-optimal, up to 5 exchange passes, stopping below a 0.1 % gain per pass.
    pub fn new(poses: usize) -> Self {
        Self {
            poses,
            criterion: Criterion::A,
            max_exchange_passes: 5,
            exchange_tolerance: 1e-3,
        }
    }
}

/// The chosen poses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// Candidate indices, in the order the greedy pass chose them (exchanges replace in place).
    pub chosen: Vec<usize>,
    /// The search's ridge `delta` (module docs), in the information's units.
    pub ridge: f64,
    /// The criterion after the greedy pass (with the ridge).
    pub greedy_value: f64,
    /// The criterion after the exchanges (with the ridge).
    pub value: f64,
    /// Swaps made by the exchange passes.
    pub exchanges: usize,
    /// Exchange passes run (the last one made no swap unless the limit stopped it).
    pub passes: usize,
}

/// All candidates' factors side by side, `[U_1 .. U_K]`, and each one's columns.
struct Stack {
    factors: DMatrix<f64>,
    columns: Vec<(usize, usize)>,
    max_rank: usize,
    cables: usize,
}

impl Stack {
    fn new(poses: &[PoseInformation]) -> Self {
        let n = poses[0].dim();
        let total: usize = poses.iter().map(PoseInformation::rank).sum();
        let mut factors = DMatrix::zeros(n, total);
        let mut columns = Vec::with_capacity(poses.len());
        let mut at = 0;
        for p in poses {
            factors.columns_mut(at, p.rank()).copy_from(&p.factor);
            columns.push((at, p.rank()));
            at += p.rank();
        }
        let max_rank = poses.iter().map(PoseInformation::rank).max().unwrap_or(0);
        Self {
            factors,
            columns,
            max_rank,
            cables: poses[0].cables,
        }
    }

    /// For every candidate, how much adding it improves the criterion at covariance `c`
    /// (decrease of the A-criterion, increase of `log det M`).
    fn gains(&self, c: &DMatrix<f64>, criterion: Criterion) -> Vec<f64> {
        let n = c.nrows();
        let w = c * &self.factors;
        let r_max = self.max_rank;
        let anchors = anchor_parameters(self.cables).len().min(n);
        let mut s = vec![0.0; r_max * r_max];
        let mut y = vec![0.0; r_max * anchors];
        let u_all = self.factors.as_slice();
        let w_all = w.as_slice();
        self.columns
            .iter()
            .map(|&(at, r)| {
                // S = 1 + U^T W (r x r, lower triangle), then its Cholesky in place.
                for a in 0..r {
                    let ua = &u_all[(at + a) * n..(at + a + 1) * n];
                    for b in 0..=a {
                        let wb = &w_all[(at + b) * n..(at + b + 1) * n];
                        let dot: f64 = ua.iter().zip(wb).map(|(x, y)| x * y).sum();
                        s[a * r_max + b] = dot + if a == b { 1.0 } else { 0.0 };
                    }
                }
                if !cholesky_in_place(&mut s, r, r_max) {
                    return f64::NEG_INFINITY;
                }
                match criterion {
                    Criterion::D => 2.0 * (0..r).map(|a| s[a * r_max + a].ln()).sum::<f64>(),
                    Criterion::A => {
                        // Y = L^-1 W_A^T, row a of Y over the anchor rows; gain = |Y|^2.
                        let mut gain = 0.0;
                        for a in 0..r {
                            let wa = &w_all[(at + a) * n..(at + a) * n + anchors];
                            for i in 0..anchors {
                                let mut v = wa[i];
                                for b in 0..a {
                                    v -= s[a * r_max + b] * y[b * anchors + i];
                                }
                                v /= s[a * r_max + a];
                                y[a * anchors + i] = v;
                                gain += v * v;
                            }
                        }
                        gain
                    }
                }
            })
            .collect()
    }
}

/// Cholesky of the `r x r` lower triangle stored with row stride `stride`; `false` if not positive definite.
fn cholesky_in_place(s: &mut [f64], r: usize, stride: usize) -> bool {
    for j in 0..r {
        let mut d = s[j * stride + j];
        for k in 0..j {
            d -= s[j * stride + k] * s[j * stride + k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        s[j * stride + j] = d;
        for i in j + 1..r {
            let mut v = s[i * stride + j];
            for k in 0..j {
                v -= s[i * stride + k] * s[j * stride + k];
            }
            s[i * stride + j] = v / d;
        }
    }
    true
}

/// The criterion at information `m` (with its covariance `c`).
fn criterion_value(m: &DMatrix<f64>, c: &DMatrix<f64>, criterion: Criterion, cables: usize) -> f64 {
    match criterion {
        Criterion::A => anchor_parameters(cables).map(|k| c[(k, k)]).sum(),
        Criterion::D => m.clone().cholesky().map_or(f64::INFINITY, |l| {
            -2.0 * l.l().diagonal().iter().map(|d| d.ln()).sum::<f64>()
        }),
    }
}

/// The ridge of the search for these candidates (module docs).
pub fn search_ridge(poses: &[PoseInformation]) -> f64 {
    let n = poses[0].dim() as f64;
    let mean_trace = poses
        .iter()
        .map(|p| p.factor.iter().map(|v| v * v).sum::<f64>())
        .sum::<f64>()
        / poses.len() as f64;
    RIDGE_FRACTION * mean_trace / n
}

/// The criterion after adding each candidate to `chosen`, by the rank-k
/// update (module docs), with the search's `ridge`; candidates already in
/// `chosen` are evaluated as if added a second time.
pub fn updated_values(
    poses: &[PoseInformation],
    chosen: &[usize],
    ridge: f64,
    criterion: Criterion,
) -> Option<Vec<f64>> {
    let m = information_sum(poses, chosen, ridge);
    let c = covariance_of(&m)?;
    let base = criterion_value(&m, &c, criterion, poses[0].cables);
    let gains = Stack::new(poses).gains(&c, criterion);
    Some(gains.into_iter().map(|g| base - g).collect())
}

/// How far the search is, for a progress display: reported at the start of
/// the greedy pass and of each exchange pass, and after each sweep over the
/// candidates (one greedy step, or one chosen pose tried for a swap).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DesignProgress {
    /// The greedy pass has chosen `chosen` of the `poses` to choose
    /// (reported from 0).
    Greedy {
        /// Poses chosen so far.
        chosen: usize,
        /// Poses to choose.
        poses: usize,
    },
    /// Exchange pass `pass` (from 1; at most `max_passes`, fewer when a pass
    /// gains too little) has tried to swap `tried` of the `poses` chosen
    /// (reported from 0).
    Exchange {
        /// The pass, from 1.
        pass: usize,
        /// [`DesignOptions::max_exchange_passes`].
        max_passes: usize,
        /// Chosen poses tried in this pass.
        tried: usize,
        /// Chosen poses a pass tries.
        poses: usize,
    },
}

/// Choose `options.poses` of the candidates `poses` (module docs).
pub fn choose_poses(poses: &[PoseInformation], options: &DesignOptions) -> Result<Design> {
    choose_more_poses(poses, &[], options)
}

/// Choose `options.poses` more candidates to go with the poses `fixed`
/// already measured (the sequential mode): the greedy pass starts from them
/// and the exchanges never remove them. [`Design::chosen`] lists the new ones only.
pub fn choose_more_poses(poses: &[PoseInformation], fixed: &[usize], options: &DesignOptions) -> Result<Design> {
    choose_more_poses_with_progress(poses, fixed, options, &mut |_| {})
}

/// [`choose_more_poses`], telling `progress` how far the search is
/// ([`DesignProgress`]; it changes nothing chosen).
///
/// ```
/// use nalgebra::DMatrix;
/// use sagcal::plan::information::PoseInformation;
/// use sagcal::plan::{choose_more_poses_with_progress, DesignOptions, DesignProgress};
/// let unit = |k: usize| PoseInformation { factor: DMatrix::from_fn(16, 1, |r, _| if r == k % 16 { 1.0 } else { 0.5 }), cables: 4 };
/// let candidates: Vec<PoseInformation> = (0..40).map(unit).collect();
/// let mut greedy = Vec::new();
/// choose_more_poses_with_progress(&candidates, &[], &DesignOptions::new(16), &mut |step| {
///     if let DesignProgress::Greedy { chosen, poses } = step {
///         greedy.push((chosen, poses));
///     }
/// })?;
/// assert_eq!(greedy, (0..=16).map(|k| (k, 16)).collect::<Vec<_>>());
/// # Ok::<(), sagcal::Error>(())
/// ```
pub fn choose_more_poses_with_progress(
    poses: &[PoseInformation],
    fixed: &[usize],
    options: &DesignOptions,
    progress: &mut dyn FnMut(DesignProgress),
) -> Result<Design> {
    if options.poses == 0 || options.poses + fixed.len() > poses.len() || fixed.iter().any(|&k| k >= poses.len()) {
        return Err(Error::InvalidInput(format!(
            "cannot choose {} poses from {} candidates",
            options.poses,
            poses.len()
        )));
    }
    let stack = Stack::new(poses);
    let ridge = search_ridge(poses);
    let singular =
        || Error::InvalidInput("the candidates' information is not positive definite even with the ridge".into());
    let mut chosen: Vec<usize> = fixed.to_vec();
    let mut taken = vec![false; poses.len()];
    for &k in fixed {
        taken[k] = true;
    }
    let wanted = options.poses;
    progress(DesignProgress::Greedy {
        chosen: 0,
        poses: wanted,
    });
    for step in 1..=wanted {
        crate::steps::add(poses.len() as u64);
        let c = covariance_of(&information_sum(poses, &chosen, ridge)).ok_or_else(singular)?;
        let gains = stack.gains(&c, options.criterion);
        let best = best_free(&gains, &taken).ok_or_else(singular)?;
        taken[best] = true;
        chosen.push(best);
        progress(DesignProgress::Greedy {
            chosen: step,
            poses: wanted,
        });
    }
    let value_of = |chosen: &[usize]| -> Result<f64> {
        let m = information_sum(poses, chosen, ridge);
        let c = covariance_of(&m).ok_or_else(singular)?;
        Ok(criterion_value(&m, &c, options.criterion, poses[0].cables))
    };
    let greedy_value = value_of(&chosen)?;
    let (mut exchanges, mut passes) = (0, 0);
    let mut value = greedy_value;
    while passes < options.max_exchange_passes {
        passes += 1;
        let mut swapped = false;
        let exchange = |tried| DesignProgress::Exchange {
            pass: passes,
            max_passes: options.max_exchange_passes,
            tried,
            poses: wanted,
        };
        for (tried, slot) in (fixed.len()..chosen.len()).enumerate() {
            progress(exchange(tried));
            crate::steps::add(poses.len() as u64);
            let current = chosen[slot];
            let others: Vec<usize> = chosen.iter().copied().filter(|&k| k != current).collect();
            let c = covariance_of(&information_sum(poses, &others, ridge)).ok_or_else(singular)?;
            let gains = stack.gains(&c, options.criterion);
            let Some(best) = best_free(&gains, &taken) else {
                continue;
            };
            if gains[best] > gains[current] + 1e-9 * gains[current].abs() {
                taken[current] = false;
                taken[best] = true;
                chosen[slot] = best;
                exchanges += 1;
                swapped = true;
            }
        }
        progress(exchange(wanted));
        if !swapped {
            break;
        }
        let before = value;
        value = value_of(&chosen)?;
        let gain = match options.criterion {
            Criterion::A => (before - value) / before.abs(),
            Criterion::D => before - value,
        };
        if gain < options.exchange_tolerance {
            break;
        }
    }
    Ok(Design {
        value,
        chosen: chosen.split_off(fixed.len()),
        ridge,
        greedy_value,
        exchanges,
        passes,
    })
}

/// The candidate with the largest finite gain not yet taken (the lowest index on ties).
fn best_free(gains: &[f64], taken: &[bool]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (k, &g) in gains.iter().enumerate() {
        if taken[k] || !g.is_finite() {
            continue;
        }
        if best.is_none_or(|b| g > gains[b]) {
            best = Some(k);
        }
    }
    best
}

//! The shapes the solver has fixed-size kernels for, in one table, and a
//! count of the work that falls outside it.
//!
//! A calibration graph (`calib::build_graph`) gives the solver few shapes.
//! Per pose, a group of [`GROUP`] = 8 local tangent columns (the platform
//! pose, [`POSE`] = 6, and its reference tension, [`TENSION`] = 2; the pose
//! alone when the tension is fixed, as in the rigid-cable stage); globally
//! [`GLOBALS`] = 16 columns (four anchors, [`ANCHORS`] = 12, then four
//! length offsets). Its factors have [`CABLE_ROWS`] = 4 rows (the catenary
//! length and height factors and the tension guard: one row per cable),
//! [`PRIOR_ROWS`] = 6 or [`POSITION_PRIOR_ROWS`] = 3 (a pose prior with or
//! without orientation) or 1 (the load cell, the reference-tension factor).
//!
//! Where a shape is known at compile time the loops unroll and vectorise
//! (and, on the AVX2 path, go to the kernels of `simd`):
//!
//! | where | shapes |
//! |---|---|
//! | `accumulate`: a factor's rows | 1, [`CABLE_ROWS`], [`PRIOR_ROWS`] |
//! | `accumulate`: products of two runs of columns | [`run_shapes!`]: `(GROUP, GROUP)`, `(GROUP, GLOBALS)`, `(GLOBALS, GLOBALS)`, `(GROUP, ANCHORS)`, `(ANCHORS, ANCHORS)`, `(GROUP, 1)`; portable also [`portable_run_shapes!`], AVX2 (four rows only) [`avx2_run_shapes!`] |
//! | `schur`: a group's elimination | `M` = [`GROUP`] or [`POSE`] against `G` = [`GLOBALS`] (AVX2: `GROUP` x `GLOBALS`, `simd::elimination`) |
//! | `schur`: a group's substitutions in the solve | `GROUP` x `GLOBALS` |
//! | `local`: a group's normal equations (rows x columns) | `CABLE_ROWS` x `GROUP`, `PRIOR_ROWS` x `POSE`, `POSITION_PRIOR_ROWS` x `POSE` |
//!
//! (`graph`, a layer below, weighs the Jacobians of 1-, 4- and 6-row factors
//! with fixed-size loops of its own, the 4-row one also for AVX2.)
//!
//! Any other shape is still solved, by the general loops: the same values
//! bit for bit, only slower. So that a new factor shape does not slow the
//! solver unnoticed, every [`super::LinearSystem`] counts the products,
//! group eliminations and group substitutions that took a general loop
//! ([`super::LinearSystem::fallbacks`]); a test (`tests/solver.rs`) asserts
//! that the catenary calibration graph's count stays zero. Two stages of a
//! calibration are known to fall outside the table: the rigid-cable stage
//! (groups of `POSE` against `GLOBALS`: its eliminations have kernels, its
//! `(POSE, GLOBALS)` products and its substitutions do not) and pose priors
//! without orientation (three rows: the accumulation has no kernel for them,
//! the local refinement has).

use std::sync::atomic::{AtomicUsize, Ordering};

/// Tangent columns of a platform pose (three of rotation, three of position).
pub(super) const POSE: usize = 6;
/// Tangent columns of a reference tension (horizontal, vertical).
pub(super) const TENSION: usize = 2;
/// Tangent columns of one pose's local group, `M`: its pose and its reference tension.
pub(super) const GROUP: usize = POSE + TENSION;
/// Tangent columns of the four anchors (three coordinates each).
pub(super) const ANCHORS: usize = 12;
/// Tangent columns of the globals, `G`: the four anchors, then the four length offsets.
pub(super) const GLOBALS: usize = ANCHORS + 4;
/// Rows of a factor with one row per cable (length, height, tension guard).
pub(super) const CABLE_ROWS: usize = 4;
/// Rows of a pose prior on position and orientation.
pub(super) const PRIOR_ROWS: usize = 6;
/// Rows of a pose prior on position alone.
pub(super) const POSITION_PRIOR_ROWS: usize = 3;

/// Calls `$kernels!` with the run shapes `(columns of a, columns of b,
/// diagonal block)` that both paths have kernels for (a pose's group,
/// the anchors and offsets, the anchors alone; `1`: the gradient of a run
/// of a pose's group), and the `$extra` ones. The names are this module's
/// constants: the caller imports them.
macro_rules! run_shapes {
    ($kernels:ident $(, $extra:tt)*) => {
        $kernels!(
            (GROUP, GROUP, true),
            (GROUP, GLOBALS, false),
            (GLOBALS, GLOBALS, true),
            (GROUP, ANCHORS, false),
            (ANCHORS, ANCHORS, true),
            (GROUP, 1, false)
            $(, $extra)*
        )
    };
}

/// [`run_shapes!`] and the portable path's own: a pose alone (its prior), a
/// reference tension, a one-column variable.
macro_rules! portable_run_shapes {
    ($kernels:ident) => {
        run_shapes!($kernels, (POSE, POSE, true), (TENSION, TENSION, true), (1, 1, true))
    };
}

/// [`run_shapes!`] and the AVX2 path's own (four-row factors only): the
/// gradients of a run of the globals and of the anchors.
macro_rules! avx2_run_shapes {
    ($kernels:ident) => {
        run_shapes!($kernels, (GLOBALS, 1, false), (ANCHORS, 1, false))
    };
}

pub(super) use {avx2_run_shapes, portable_run_shapes, run_shapes};

/// How often a linear system took a general loop for a shape outside the
/// table (the module docs), since it was built.
#[derive(Debug, Default)]
pub(super) struct FallbackCounter {
    products: AtomicUsize,
    eliminations: AtomicUsize,
    substitutions: AtomicUsize,
}

impl FallbackCounter {
    /// One product of two runs added by the general loop.
    #[cold]
    #[inline(never)]
    pub(super) fn product(&self) {
        self.products.fetch_add(1, Ordering::Relaxed);
    }

    /// One group eliminated by the general loops.
    #[cold]
    #[inline(never)]
    pub(super) fn elimination(&self) {
        self.eliminations.fetch_add(1, Ordering::Relaxed);
    }

    /// `count` group substitutions of a solve by the general loops.
    #[cold]
    #[inline(never)]
    pub(super) fn substitutions(&self, count: usize) {
        self.substitutions.fetch_add(count, Ordering::Relaxed);
    }

    /// The counts so far.
    pub(super) fn read(&self) -> Fallbacks {
        Fallbacks {
            products: self.products.load(Ordering::Relaxed),
            eliminations: self.eliminations.load(Ordering::Relaxed),
            substitutions: self.substitutions.load(Ordering::Relaxed),
        }
    }
}

/// The work a [`super::LinearSystem`] did by general loops because a shape
/// had no fixed-size kernel (the table of the `shapes` module), since it was
/// built: zero for the catenary calibration graph with orientation priors.
/// The results are the same either way; only the speed differs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Fallbacks {
    /// Products `J_a^T J_b` of two runs of a factor's columns.
    pub products: usize,
    /// Local groups eliminated (their Cholesky factor, `W = L^-1 B` and `W^T W`).
    pub eliminations: usize,
    /// Local groups' substitutions in a solve (two per group and solve).
    pub substitutions: usize,
}

impl Fallbacks {
    /// All of them.
    pub fn total(&self) -> usize {
        self.products + self.eliminations + self.substitutions
    }
}

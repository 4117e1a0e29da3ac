//! The solver's AVX2 kernels, and the one way the solver chooses them.
//!
//! - `gram`: the Gram-block kernel `block (+ or -)= A^T B` shared by the
//!   `J^T J` accumulation (`accumulate`), the local refinement (`local`) and
//!   the block elimination (`schur`), and the four-row gather it reads from.
//! - `elimination`: one pose group's elimination against the globals
//!   (`schur`'s `eliminate_group` for the shape of the calibration graph).
//!
//! Each kernel computes every entry by the operations of the portable loop
//! it stands for, in the same order and without fused multiply-add, so the
//! two paths agree to the last bit (the unit tests beside each kernel and
//! beside each call site compare them).
//!
//! Which path runs is decided in one place, [`avx2`] (`crate::simd`: the
//! environment variable `SAGCAL_SIMD=portable|avx2|auto`, read once, and the
//! CPU check). That function lives in a leaf module of the crate rather
//! than here because `graph`, a layer below `solver`, weighs its four-row
//! factors with an AVX2 kernel too and must follow the same switch; here it
//! is re-exported so that the solver's call sites read `simd::avx2()`. Every
//! call site has the same form: a portable function generic over a
//! `const AVX2: bool` (or with no parameter where the compiler vectorises it
//! alone), a wrapper compiled with `#[target_feature(enable = "avx2")]` that
//! inlines it with `AVX2 = true`, and
//!
//! ```text
//! #[cfg(target_arch = "x86_64")]
//! if simd::avx2() {
//!     // SAFETY: `simd::avx2()` is true only where the CPU has AVX2.
//!     return unsafe { self.factorize_avx2(hessian, damping) };
//! }
//! self.factorize_any::<false>(hessian, damping)
//! ```
//!
//! (`FactorRuns::accumulate`, `SchurLayout::factorize`,
//! `SchurLayout::solve`, the local refinement's eight-column normal
//! equations). The intrinsics are called only from code compiled for AVX2
//! behind that test. The tests of the kernels ask
//! `crate::simd::avx2_under_test`, which follows the switch and fails when
//! it asks for AVX2 on a CPU without it.

pub(super) mod elimination;
pub(super) mod gram;

pub(super) use crate::simd::avx2;
#[cfg(test)]
pub(super) use crate::simd::avx2_under_test;

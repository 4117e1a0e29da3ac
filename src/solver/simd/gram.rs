//! The Gram-block kernel shared by the `J^T J` accumulation and the block
//! elimination, written with AVX2 intrinsics.
//!
//! `block[i + j * stride] (+ or -)= sum_r a[r][i] * b[r][j]` for two blocks
//! stored row by row (`a`: `R x CA`, `b`: `R x CB`), `i` over `CA` (a multiple
//! of four: one 256-bit lane group per four neighbouring `i`), `j` over `CB`.
//! Every lane computes exactly the scalar loop's sequence
//! `s = a0 b0; s = s + a1 b1; ...; h = h (+ or -) s`, each product and sum
//! rounded on its own (no fused multiply-add), so the results are bit for
//! bit those of the portable loops (unit tests compare them). The compiler's
//! own vectorisation of those loops kept their bounds checks and loop
//! counters: about four instructions per multiply-add against one here
//! (BENCHMARKS.md section 2).

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    __m256d, _mm256_add_pd, _mm256_blendv_pd, _mm256_castpd256_pd128, _mm256_extractf128_pd, _mm256_loadu_pd,
    _mm256_mul_pd, _mm256_set1_pd, _mm256_storeu_pd, _mm256_sub_pd, _mm_storeh_pd, _mm_storel_pd,
};

/// Lane masks of the diagonal lane group of a lower triangle: entry `k`
/// selects lanes `l >= k` (sign bit set) for column `j` with `j % 4 == k`.
#[cfg(target_arch = "x86_64")]
const LOWER_LANES: [[f64; 4]; 4] = [
    [-1.0, -1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0, -1.0],
    [1.0, 1.0, 1.0, -1.0],
];

/// `block[i + j * stride] += sum_r a[r * CA + i] * b[r * CB + j]` for
/// `j < CB` and `i < CA` (`LOWER`: only `i >= j`, the lower triangle of a
/// diagonal block; the entries above it are left untouched), or `-=` when
/// `SUBTRACT`. The sums run over `r = 0..R` in order.
///
/// # Safety
/// The CPU must support AVX2. The slices are checked for length (a panic,
/// not undefined behaviour, if one is short).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) unsafe fn gram_block<
    const R: usize,
    const CA: usize,
    const CB: usize,
    const LOWER: bool,
    const SUBTRACT: bool,
>(
    a: &[f64],
    b: &[f64],
    stride: usize,
    block: &mut [f64],
) {
    const { assert!(CA % 4 == 0 && R > 0 && CB > 0) };
    assert!(a.len() >= R * CA && b.len() >= R * CB && block.len() >= (CB - 1) * stride + CA);
    let (a, b, h) = (a.as_ptr(), b.as_ptr(), block.as_mut_ptr());
    for j in 0..CB {
        let first_group = if LOWER { j / 4 } else { 0 };
        for group in first_group..CA / 4 {
            let i = 4 * group;
            // SAFETY: `r * CA + i + 3 < R * CA`, `r * CB + j < R * CB` and
            // `i + 3 + j * stride < (CB - 1) * stride + CA` (asserted above).
            unsafe {
                let mut sum: __m256d = _mm256_mul_pd(_mm256_loadu_pd(a.add(i)), _mm256_set1_pd(*b.add(j)));
                for r in 1..R {
                    let product = _mm256_mul_pd(_mm256_loadu_pd(a.add(r * CA + i)), _mm256_set1_pd(*b.add(r * CB + j)));
                    sum = _mm256_add_pd(sum, product);
                }
                let target = h.add(i + j * stride);
                let old = _mm256_loadu_pd(target);
                let mut new = if SUBTRACT {
                    _mm256_sub_pd(old, sum)
                } else {
                    _mm256_add_pd(old, sum)
                };
                if LOWER && group == first_group {
                    let lanes = _mm256_loadu_pd(LOWER_LANES[j % 4].as_ptr());
                    new = _mm256_blendv_pd(old, new, lanes);
                }
                _mm256_storeu_pd(target, new);
            }
        }
    }
}

/// Copy a four-row column-major block (`block[r + 4 c]`, `c < n`) into
/// columns `first..first + n` of `rows`, a row-major buffer of four rows of
/// `width` (`rows[r * width + first + c]`): the layout [`gram_block`] reads.
/// One 256-bit load and four 64-bit stores per column. A copy: bit for bit.
///
/// # Safety
/// The CPU must support AVX2. The lengths are checked (a panic if short).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) unsafe fn scatter_four_rows(block: &[f64], rows: &mut [f64], width: usize, first: usize) {
    let n = block.len() / 4;
    assert!(block.len() % 4 == 0 && first + n <= width && rows.len() >= 4 * width);
    let (from, to) = (block.as_ptr(), rows.as_mut_ptr());
    for c in 0..n {
        // SAFETY: `4 c + 3 < block.len()` and `3 width + first + c < 4 width` (asserted above).
        unsafe {
            let column = _mm256_loadu_pd(from.add(4 * c));
            let (low, high) = (_mm256_castpd256_pd128(column), _mm256_extractf128_pd(column, 1));
            let at = to.add(first + c);
            _mm_storel_pd(at, low);
            _mm_storeh_pd(at.add(width), low);
            _mm_storel_pd(at.add(2 * width), high);
            _mm_storeh_pd(at.add(3 * width), high);
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    /// The scalar loop the kernel must reproduce bit for bit.
    fn scalar<const R: usize, const CA: usize, const CB: usize>(
        a: &[f64],
        b: &[f64],
        stride: usize,
        block: &mut [f64],
        lower: bool,
        subtract: bool,
    ) {
        for j in 0..CB {
            for i in (if lower { j } else { 0 })..CA {
                let mut sum = a[i] * b[j];
                for r in 1..R {
                    sum += a[r * CA + i] * b[r * CB + j];
                }
                if subtract {
                    block[i + j * stride] -= sum;
                } else {
                    block[i + j * stride] += sum;
                }
            }
        }
    }

    /// Values with many significant bits, so that any change of the
    /// summation order or a fused multiply-add shows in the last bit.
    fn values(n: usize, seed: u64) -> Vec<f64> {
        (0..n as u64)
            .map(|k| {
                let x = (k
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(seed * 1442695040888963407)
                    >> 11) as f64;
                (x / (1u64 << 53) as f64 - 0.5) * 3.7
            })
            .collect()
    }

    fn check<const R: usize, const CA: usize, const CB: usize, const LOWER: bool, const SUBTRACT: bool>(stride: usize) {
        let (a, b) = (values(R * CA, 1), values(R * CB, 2));
        let start = values((CB - 1) * stride + CA + 3, 3);
        let mut expected = start.clone();
        scalar::<R, CA, CB>(&a, &b, stride, &mut expected, LOWER, SUBTRACT);
        let mut got = start.clone();
        // SAFETY: the test runs only where the CPU has AVX2.
        unsafe { gram_block::<R, CA, CB, LOWER, SUBTRACT>(&a, &b, stride, &mut got) };
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&got),
            bits(&expected),
            "R {R} CA {CA} CB {CB} lower {LOWER} subtract {SUBTRACT}"
        );
        // The kernel did something: at least one entry moved.
        assert_ne!(bits(&got), bits(&start));
    }

    /// Every shape the solver uses, and entries outside the block (above the
    /// lower triangle, between the columns, past the end) left untouched.
    #[test]
    fn the_kernel_matches_the_scalar_loop_bit_for_bit() {
        if !crate::simd::avx2_under_test() {
            return;
        }
        check::<4, 8, 8, true, false>(8);
        check::<4, 8, 16, false, false>(8);
        check::<4, 16, 16, true, false>(16);
        check::<4, 8, 12, false, false>(8);
        check::<4, 12, 12, true, false>(13);
        check::<4, 8, 1, false, false>(0);
        check::<1, 16, 16, true, false>(16);
        check::<8, 16, 16, true, true>(16);
        check::<6, 16, 16, true, true>(17);
    }

    /// Every four-row shape of the AVX2 path's table
    /// (`shapes::avx2_run_shapes!`), with a gap between the columns.
    #[test]
    fn every_shape_of_the_table_matches_the_scalar_loop() {
        use crate::solver::shapes::{avx2_run_shapes, run_shapes, ANCHORS, CABLE_ROWS, GLOBALS, GROUP};
        if !crate::simd::avx2_under_test() {
            return;
        }
        macro_rules! checks {
            ($(($ca:tt, $cb:tt, $same:literal)),*) => {
                $(check::<CABLE_ROWS, $ca, $cb, $same, false>($ca + 1);)*
            };
        }
        avx2_run_shapes!(checks);
    }

    /// The copy puts entry `r` of column `c` at `r * width + first + c`
    /// and leaves the other columns alone.
    #[test]
    fn four_row_columns_are_copied_row_by_row() {
        if !crate::simd::avx2_under_test() {
            return;
        }
        let (width, first) = (13, 5);
        let block = values(4 * 6, 4);
        let mut rows = vec![f64::NAN; 4 * width];
        // SAFETY: the test runs only where the CPU has AVX2.
        unsafe { scatter_four_rows(&block, &mut rows, width, first) };
        for r in 0..4 {
            for c in 0..width {
                let got = rows[r * width + c];
                match c.checked_sub(first).filter(|&k| k < 6) {
                    Some(k) => assert_eq!(got.to_bits(), block[r + 4 * k].to_bits(), "row {r} column {c}"),
                    None => assert!(got.is_nan(), "row {r} column {c} was written"),
                }
            }
        }
    }
}

//! The elimination of one 8-column group (a pose and its reference tension)
//! against 16 global columns, written with AVX2 intrinsics: the Cholesky
//! factor `L` of the damped block, `W = L^-1 B` and `reduced -= W^T W`.
//!
//! Every entry goes through the operations of the portable loops of
//! `schur.rs` and `dense.rs` in the same order, each rounded on its own (no fused
//! multiply-add): `L[i][j] = (a[i][j] - a[i][0] a[j][0] - ...) / l_jj` with
//! the pivot `l_jj^2 = a[j][j] - a[j][0]^2 - ...`, and `W` row by row
//! (`w_j = w_j / l_jj`, then `w_i -= l_ij w_j` for the rows below), so the
//! factors are bit for bit the portable ones (unit test). Column `j` of `L`
//! is two 256-bit registers (rows 0-3 and 4-7); `W` is worked on as 8 rows
//! of 16, four registers each.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    __m256d, _mm256_blendv_pd, _mm256_div_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_storeu_pd,
    _mm256_sub_pd,
};

use crate::solver::shapes::{GLOBALS, GROUP};

/// Group dimension (`GROUP` of the table of `shapes`).
const M: usize = GROUP;
/// Global dimension (`GLOBALS` of the table of `shapes`).
const G: usize = GLOBALS;
// The registers below are laid out for 8 x 16: another shape in the table needs another kernel.
const _: () = assert!(M == 8 && G == 16);

/// Lane masks per column `j` of the rows below it: entry `j` holds, for the
/// rows 0..8, a set sign bit where the row is greater than `j`.
#[cfg(target_arch = "x86_64")]
const BELOW: [[f64; M]; M] = {
    let mut masks = [[1.0; M]; M];
    let mut j = 0;
    while j < M {
        let mut i = j + 1;
        while i < M {
            masks[j][i] = -1.0;
            i += 1;
        }
        j += 1;
    }
    masks
};

/// Factor `block` (`D`, 8 x 8, then `B`, 8 x 16, column-major; `D` already
/// damped) into `L` and `W = L^-1 B` in place and subtract `W^T W` from the
/// lower triangle of `reduced` (16 x 16, column-major); `false` (and
/// `reduced` untouched) if a pivot is not positive and finite.
///
/// # Safety
/// The CPU must support AVX2. The lengths are checked (a panic if short).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn eliminate_group(block: &mut [f64], reduced: &mut [f64]) -> bool {
    assert!(block.len() >= M * M + M * G && reduced.len() >= G * G);
    let (d, w) = block.split_at_mut(M * M);
    // SAFETY: `d` holds 8 columns of 8 (asserted above).
    if !unsafe { cholesky(d) } {
        return false;
    }
    // W row by row: rows[r][c] = B[r][c].
    let mut rows = [[0.0f64; G]; M];
    for (c, column) in w[..M * G].chunks_exact(M).enumerate() {
        for r in 0..M {
            rows[r][c] = column[r];
        }
    }
    // SAFETY: `rows` is 8 x 16 and `d` 8 x 8.
    unsafe { forward_substitute_rows(d, &mut rows) };
    for (c, column) in w[..M * G].chunks_exact_mut(M).enumerate() {
        for r in 0..M {
            column[r] = rows[r][c];
        }
    }
    let rows = rows.as_flattened();
    // SAFETY: the CPU has AVX2 (this function's contract).
    unsafe { super::gram::gram_block::<M, G, G, true, true>(rows, rows, G, reduced) };
    true
}

/// In-place Cholesky of the lower triangle of an 8 x 8 column-major `a`
/// (`cholesky_in_place` of `dense.rs`, bit for bit); `false` unless every
/// pivot is positive and finite. The entries above the diagonal are not written.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn cholesky(a: &mut [f64]) -> bool {
    let a = &mut a[..M * M];
    let p = a.as_mut_ptr();
    for j in 0..M {
        // SAFETY: every offset below is `< M * M`.
        unsafe {
            let column = p.add(j * M);
            let (original_low, original_high) = (_mm256_loadu_pd(column), _mm256_loadu_pd(column.add(4)));
            let (mut low, mut high): (__m256d, __m256d) = (original_low, original_high);
            for k in 0..j {
                let ajk = _mm256_set1_pd(*p.add(j + k * M));
                let previous = p.add(k * M);
                low = _mm256_sub_pd(low, _mm256_mul_pd(_mm256_loadu_pd(previous), ajk));
                high = _mm256_sub_pd(high, _mm256_mul_pd(_mm256_loadu_pd(previous.add(4)), ajk));
            }
            // Lane j is the pivot's running sum, the same sequence as the scalar loop's.
            let mut sums = [0.0f64; M];
            _mm256_storeu_pd(sums.as_mut_ptr(), low);
            _mm256_storeu_pd(sums.as_mut_ptr().add(4), high);
            let pivot = sums[j];
            if !(pivot > 0.0 && pivot.is_finite()) {
                return false;
            }
            let pivot = pivot.sqrt();
            let divisor = _mm256_set1_pd(pivot);
            let below = BELOW[j].as_ptr();
            let low = _mm256_blendv_pd(original_low, _mm256_div_pd(low, divisor), _mm256_loadu_pd(below));
            let high = _mm256_blendv_pd(
                original_high,
                _mm256_div_pd(high, divisor),
                _mm256_loadu_pd(below.add(4)),
            );
            _mm256_storeu_pd(column, low);
            _mm256_storeu_pd(column.add(4), high);
            *column.add(j) = pivot;
        }
    }
    true
}

/// `X <- L^-1 X` for the 16 columns of `rows` (row `r` of `X` in
/// `rows[r]`), `L` the 8 x 8 column-major factor in `l`: per column the
/// operations of `forward_substitute` of `dense.rs`, in its order.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn forward_substitute_rows(l: &[f64], rows: &mut [[f64; G]; M]) {
    let l = &l[..M * M];
    for j in 0..M {
        // SAFETY: each row holds 16 values: four registers at 0, 4, 8, 12.
        unsafe {
            let divisor = _mm256_set1_pd(l[j + j * M]);
            let xj: [__m256d; 4] =
                std::array::from_fn(|q| _mm256_div_pd(_mm256_loadu_pd(rows[j].as_ptr().add(4 * q)), divisor));
            for (q, value) in xj.iter().enumerate() {
                _mm256_storeu_pd(rows[j].as_mut_ptr().add(4 * q), *value);
            }
            for i in j + 1..M {
                let lij = _mm256_set1_pd(l[i + j * M]);
                let row = rows[i].as_mut_ptr();
                for (q, value) in xj.iter().enumerate() {
                    let x = _mm256_loadu_pd(row.add(4 * q));
                    _mm256_storeu_pd(row.add(4 * q), _mm256_sub_pd(x, _mm256_mul_pd(lij, *value)));
                }
            }
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::solver::dense::{cholesky_in_place, forward_substitute};

    /// A damped block of a pose (8 x 8, positive definite, many significant
    /// bits) and its 8 x 16 coupling, eliminated by the portable loops and
    /// by the kernel: the same `L`, `W` and reduced system, bit for bit; an
    /// indefinite block fails in both and leaves `reduced` alone.
    #[test]
    fn the_kernel_eliminates_exactly_as_the_portable_loops() {
        if !crate::simd::avx2_under_test() {
            return;
        }
        let value = |k: usize| ((k * 7919 % 1009) as f64 / 1009.0 - 0.5) * 1.7 + 1e-3 * (k as f64).sin();
        let j = nalgebra::DMatrix::from_fn(12, M, |r, c| value(r * M + c));
        let mut d = (j.transpose() * &j).as_slice().to_vec();
        for i in 0..M {
            d[i + i * M] += 0.25;
        }
        let b: Vec<f64> = (0..M * G).map(|k| value(500 + k)).collect();
        let reduced_start: Vec<f64> = (0..G * G).map(|k| 10.0 + value(2000 + k)).collect();
        // The portable loops.
        let (mut l, mut w, mut reduced) = (d.clone(), b.clone(), reduced_start.clone());
        assert!(cholesky_in_place(&mut l, M));
        for column in w.chunks_exact_mut(M) {
            forward_substitute(&l, M, column);
        }
        for jj in 0..G {
            for ii in jj..G {
                let mut sum = w[ii * M] * w[jj * M];
                for r in 1..M {
                    sum += w[ii * M + r] * w[jj * M + r];
                }
                reduced[ii + jj * G] -= sum;
            }
        }
        // The kernel.
        let mut block: Vec<f64> = d.iter().chain(&b).copied().collect();
        let mut kernel_reduced = reduced_start.clone();
        // SAFETY: the CPU has AVX2 (`avx2_under_test` above).
        assert!(unsafe { eliminate_group(&mut block, &mut kernel_reduced) });
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for col in 0..M {
            for row in col..M {
                assert_eq!(
                    block[row + col * M].to_bits(),
                    l[row + col * M].to_bits(),
                    "L ({row}, {col})"
                );
            }
            for row in 0..col {
                assert_eq!(
                    block[row + col * M].to_bits(),
                    d[row + col * M].to_bits(),
                    "above ({row}, {col})"
                );
            }
        }
        assert_eq!(bits(&block[M * M..]), bits(&w), "W");
        assert_eq!(bits(&kernel_reduced), bits(&reduced), "reduced");
        // An indefinite block.
        let mut bad: Vec<f64> = d.iter().chain(&b).copied().collect();
        bad[3 + 3 * M] = -1.0;
        let mut untouched = reduced_start.clone();
        // SAFETY: as above.
        assert!(!unsafe { eliminate_group(&mut bad, &mut untouched) });
        assert_eq!(bits(&untouched), bits(&reduced_start));
    }
}

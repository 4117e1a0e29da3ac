//! Whitening and weighing: the whitened squared norm `|r / sigma|^2` and
//! the kernels that multiply a factor's Jacobian blocks by its row weights
//! (fixed-row loops and their AVX2 build, bit for bit the general loop).

use nalgebra::DVector;

/// `|r / sigma|^2`.
pub fn whitened_squared_norm(residual: &DVector<f64>, sigmas: &DVector<f64>) -> f64 {
    squared_norm_over(residual.as_slice(), sigmas)
}

/// [`whitened_squared_norm`] of a residual slice.
pub(super) fn squared_norm_over(residual: &[f64], sigmas: &DVector<f64>) -> f64 {
    // Over slices: nalgebra's strided matrix iterator costs several times the arithmetic here.
    residual
        .iter()
        .zip(sigmas.as_slice())
        .map(|(r, s)| (r / s) * (r / s))
        .sum()
}

/// [`weigh_columns`] for four rows (a column is one 256-bit register)
/// compiled for AVX2: the same products and running sums, bit for bit
/// (no FMA; unit test).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn weigh_four_rows_avx2<'a>(
    blocks: impl Iterator<Item = &'a mut [f64]>,
    weights: &[f64],
) -> (bool, bool) {
    weigh_columns::<4, false>(blocks, weights)
}

/// Multiply every column of `blocks` (column-major, `weights.len()` rows)
/// by the row weights, entry by entry; returns whether every weighted entry
/// is finite and (only computed when `ZERO`, else `false`) whether all are
/// zero. `R` rows known at compile time (`R = 0`: any), so that the rows of
/// a column are multiplied side by side; the checks keep one running sum per
/// row (`v * 0.0` is NaN exactly when `v` is not finite, a sum of `|v|` is
/// zero exactly when every `v` is), whose order does not change the answer.
#[inline(always)]
pub(super) fn weigh_columns<'a, const R: usize, const ZERO: bool>(
    blocks: impl Iterator<Item = &'a mut [f64]>,
    weights: &[f64],
) -> (bool, bool) {
    let rows = weights.len();
    if R != 0 && rows == R {
        let weights: [f64; R] = std::array::from_fn(|r| weights[r]);
        let mut not_finite = [0.0; R];
        let mut magnitude = [0.0; R];
        for block in blocks {
            for column in block.chunks_exact_mut(R) {
                for r in 0..R {
                    let v = column[r] * weights[r];
                    column[r] = v;
                    not_finite[r] += v * 0.0;
                    if ZERO {
                        magnitude[r] += v.abs();
                    }
                }
            }
        }
        let finite = !not_finite.iter().any(|v| v.is_nan());
        return (finite, ZERO && magnitude.iter().all(|&m| m == 0.0));
    }
    let mut not_finite = 0.0;
    let mut magnitude = 0.0;
    for block in blocks {
        for column in block.chunks_exact_mut(rows) {
            for (entry, weight) in column.iter_mut().zip(weights) {
                let v = *entry * weight;
                *entry = v;
                not_finite += v * 0.0;
                if ZERO {
                    magnitude += v.abs();
                }
            }
        }
    }
    (!f64::is_nan(not_finite), ZERO && magnitude == 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fixed-row kernels weigh exactly as the general loop and agree on
    /// finiteness and all-zero, for finite, infinite, NaN and zero entries.
    #[test]
    fn fixed_row_weighing_matches_the_general_loop() {
        fn check<const R: usize>(entries: &[f64], weights: &[f64]) {
            let (mut fixed, mut general) = (entries.to_vec(), entries.to_vec());
            let a = weigh_columns::<R, true>(std::iter::once(fixed.as_mut_slice()), weights);
            let b = weigh_columns::<0, true>(std::iter::once(general.as_mut_slice()), weights);
            assert_eq!(a, b, "{entries:?}");
            assert!(fixed.iter().zip(&general).all(|(x, y)| x.to_bits() == y.to_bits()));
            let expected_finite = entries
                .iter()
                .zip(weights.iter().cycle())
                .all(|(e, w)| (e * w).is_finite());
            assert_eq!(a.0, expected_finite);
            assert_eq!(a.1, entries.iter().all(|&e| e == 0.0));
            assert!(!weigh_columns::<R, false>(std::iter::once(entries.to_vec().as_mut_slice()), weights).1);
            #[cfg(target_arch = "x86_64")]
            if R == 4 && crate::simd::avx2_under_test() {
                let mut avx2 = entries.to_vec();
                // SAFETY: the CPU has AVX2 (`avx2_under_test` just above).
                let c = unsafe { weigh_four_rows_avx2(std::iter::once(avx2.as_mut_slice()), weights) };
                assert_eq!(c.0, a.0, "{entries:?}");
                assert!(avx2.iter().zip(&general).all(|(x, y)| x.to_bits() == y.to_bits()));
            }
        }
        let weights4 = [0.5, 3.0, 1e-3, 7.0];
        let mut entries: Vec<f64> = (0..24).map(|k| (k as f64 * 0.37).sin()).collect();
        check::<4>(&entries, &weights4);
        entries[13] = f64::INFINITY;
        check::<4>(&entries, &weights4);
        entries[13] = f64::NAN;
        check::<4>(&entries, &weights4);
        check::<4>(&[0.0; 24], &weights4);
        check::<4>(&[-0.0; 8], &weights4);
        let weights6 = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let entries6: Vec<f64> = (0..36).map(|k| k as f64 - 17.0).collect();
        check::<6>(&entries6, &weights6);
        check::<1>(&[2.0, f64::NEG_INFINITY], &[0.25]);
        check::<1>(&[0.0, 0.0], &[0.25]);
    }
}

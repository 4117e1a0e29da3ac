//! The small dense helpers the solver's files share: a column-major
//! Cholesky and its two triangular substitutions, a dot product of known
//! length, and zeroed buffers.
//!
//! A leaf: it names no other solver module, so the accumulation
//! (`accumulate`), the block elimination (`schur`), the linear system and
//! the local refinement (`local`) all use it without importing each other.
//! Each function's operations and their order are part of the bit-for-bit
//! contract: the AVX2 kernels of `simd` reproduce them exactly (unit tests).

/// In-place Cholesky `A = L L^T` of the lower triangle of a column-major
/// `n x n` matrix; `false` unless every pivot is positive and finite.
#[inline(always)]
pub(super) fn cholesky_in_place(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut pivot = a[j + j * n];
        for k in 0..j {
            pivot -= a[j + k * n] * a[j + k * n];
        }
        if !(pivot > 0.0 && pivot.is_finite()) {
            return false;
        }
        let pivot = pivot.sqrt();
        a[j + j * n] = pivot;
        for i in j + 1..n {
            let mut sum = a[i + j * n];
            for k in 0..j {
                sum -= a[i + k * n] * a[j + k * n];
            }
            a[i + j * n] = sum / pivot;
        }
    }
    true
}

/// `x <- L^-1 x` for the lower-triangular factor in `l` (column-major `n x n`).
#[inline(always)]
pub(super) fn forward_substitute(l: &[f64], n: usize, x: &mut [f64]) {
    for j in 0..n {
        let xj = x[j] / l[j + j * n];
        x[j] = xj;
        for i in j + 1..n {
            x[i] -= l[i + j * n] * xj;
        }
    }
}

/// `x <- L^-T x` for the lower-triangular factor in `l` (column-major `n x n`).
#[inline(always)]
pub(super) fn backward_substitute(l: &[f64], n: usize, x: &mut [f64]) {
    for j in (0..n).rev() {
        let mut sum = x[j];
        for i in j + 1..n {
            sum -= l[i + j * n] * x[i];
        }
        x[j] = sum / l[j + j * n];
    }
}

/// `len` zeros, written in 1 kB pieces: one `memset` (or `calloc`) of a
/// large buffer is a `rep stosb`, which callgrind counts once per byte and
/// which is slower than vector stores below a few pages.
pub(super) fn zeroed(len: usize) -> Vec<f64> {
    let mut zeros = Vec::with_capacity(len);
    fill_zeros(&mut zeros, len);
    zeros
}

/// Make `buffer` `len` zeros, in 1 kB pieces (see [`zeroed`]).
pub(super) fn fill_zeros(buffer: &mut Vec<f64>, len: usize) {
    const PIECE: [f64; 128] = [0.0; 128];
    buffer.truncate(len);
    for piece in buffer.chunks_mut(PIECE.len()) {
        piece.copy_from_slice(&PIECE[..piece.len()]);
    }
    while buffer.len() < len {
        let missing = (len - buffer.len()).min(PIECE.len());
        buffer.extend_from_slice(&PIECE[..missing]);
    }
}

/// `a . b` for two columns of `R` entries (`R = 0`: of equal length).
#[inline(always)]
pub(super) fn dot<const R: usize>(a: &[f64], b: &[f64]) -> f64 {
    if R == 0 {
        return a.iter().zip(b).map(|(x, y)| x * y).sum();
    }
    let (a, b) = (&a[..R], &b[..R]);
    let mut sum = 0.0;
    for r in 0..R {
        sum += a[r] * b[r];
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reused buffer of any length, shorter or longer than asked, comes
    /// back as exactly `len` zeros (lengths around the 128-entry pieces).
    #[test]
    fn fill_zeros_gives_len_zeros_from_any_buffer() {
        for start in [0usize, 5, 128, 300] {
            for len in [0usize, 1, 127, 128, 129, 1000] {
                let mut buffer: Vec<f64> = (0..start).map(|k| k as f64 + 0.5).collect();
                fill_zeros(&mut buffer, len);
                assert_eq!(buffer.len(), len, "from {start}");
                assert!(buffer.iter().all(|&v| v == 0.0), "from {start} to {len}");
            }
        }
        assert_eq!(zeroed(257), vec![0.0; 257]);
    }
}

//! Block elimination of the local variables (the Schur complement).
//!
//! When every factor touches at most one group of local variables (one
//! platform pose and its reference tension) besides the global ones (anchors,
//! offsets), `H` is block-arrowhead:
//! ```text
//! [ A    B_1^T ... B_n^T ] [x_g]   [b_g]
//! [ B_1  D_1           0 ] [x_1] = [b_1]
//! [ ...       ...        ] [...]   [...]
//! [ B_n  0           D_n ] [x_n]   [b_n]
//! ```
//! With `D_k = L_k L_k^T` and `W_k = L_k^-1 B_k`, the globals solve the
//! reduced system `(A - sum W_k^T W_k) x_g = b_g - sum W_k^T L_k^-1 b_k`
//! and every group back-substitutes `x_k = L_k^-T (L_k^-1 b_k - W_k x_g)`
//! (Triggs et al., *Bundle Adjustment - A Modern Synthesis*, 2000, Sec. 6.1).
//! This is exactly sparse Cholesky with the groups eliminated first (the
//! fill-reducing order AMD finds for this pattern), written for the structure:
//! the per-group blocks are small dense (`m <= 8`) and the reduced system is
//! dense (`g = 16` for anchors and offsets), so each factorisation is a loop
//! of fixed-size kernels with no symbolic bookkeeping (the sizes of the
//! table of `shapes`; other sizes take general loops, counted).

use super::dense::{backward_substitute, cholesky_in_place, forward_substitute, zeroed};
use super::shapes::{FallbackCounter, GLOBALS, GROUP, POSE};
use super::simd;

/// Where every stored entry of `H` goes, and the dense blocks it fills.
pub(super) struct SchurLayout {
    /// Tangent dimension of the global (non-eliminated) variables; they come first.
    globals: usize,
    /// Per group: first tangent index and dimension.
    groups: Vec<(usize, usize)>,
    /// Per group: offset of its `D_k` (then `B_k`) in the block buffer.
    group_base: Vec<usize>,
    /// Per tangent index past the globals, its group.
    group_of: Vec<usize>,
    /// Block buffer: `A` (globals x globals, column-major), then per group
    /// `D_k` (m x m) and `B_k` (m x globals), column-major; after
    /// factorisation `A` holds the Cholesky factor of the reduced system,
    /// `D_k` its `L_k` and `B_k` its `W_k`.
    values: Vec<f64>,
    factored: bool,
    /// The groups whose substitutions in a solve take the general loops
    /// ([`has_substitution_kernel`]), counted once per solve rather than in
    /// its loops.
    groups_without_kernel: usize,
}

impl SchurLayout {
    /// A layout for `H` whose lower triangle has entries at `indices`
    /// (`(row, col)`, `row >= col`, tangent indices with the globals first;
    /// one entry per block between two variables is enough, it stands for
    /// the block), with `groups` `(first index, dimension)`. `None` if an
    /// entry couples two groups.
    #[cfg(test)]
    pub(super) fn new(indices: &[(usize, usize)], globals: usize, groups: Vec<(usize, usize)>) -> Option<Self> {
        let layout = Self::zones(globals, groups);
        let coupled = indices.iter().any(|&(row, col)| {
            row >= globals && col >= globals && layout.group_of[row - globals] != layout.group_of[col - globals]
        });
        (!coupled).then_some(layout)
    }

    /// The layout of `globals` and `groups` known not to be coupled
    /// ([`SchurLayout::new`] without the coupling test).
    pub(super) fn zones(globals: usize, groups: Vec<(usize, usize)>) -> Self {
        let mut group_base = Vec::with_capacity(groups.len());
        let mut size = globals * globals;
        for &(_, m) in &groups {
            group_base.push(size);
            size += m * m + m * globals;
        }
        let dim = groups.last().map_or(globals, |&(start, m)| start + m);
        let mut group_of = vec![usize::MAX; dim.saturating_sub(globals)];
        for (k, &(start, m)) in groups.iter().enumerate() {
            group_of[start - globals..start - globals + m].fill(k);
        }
        let groups_without_kernel = groups
            .iter()
            .filter(|&&(_, m)| !has_substitution_kernel(m, globals))
            .count();
        Self {
            globals,
            groups,
            group_base,
            group_of,
            values: zeroed(size),
            factored: false,
            groups_without_kernel,
        }
    }

    /// The globals' dimension (the reduced system's size).
    pub(super) fn globals(&self) -> usize {
        self.globals
    }

    /// One past the last tangent index of the zone of index `i`: the
    /// globals' end, or its group's.
    pub(super) fn zone_end(&self, i: usize) -> usize {
        if i < self.globals {
            return self.globals;
        }
        let (start, m) = self.groups[self.group_of[i - self.globals]];
        start + m
    }

    /// Where the entry `(row, col)` of `H` (`row >= col`, not coupling two
    /// groups) sits in the block buffer, and the stride between its columns.
    pub(super) fn place(&self, row: usize, col: usize) -> (usize, usize) {
        let g = self.globals;
        if row < g {
            return (row + col * g, g);
        }
        let k = self.group_of[row - g];
        let (start, m) = self.groups[k];
        if col < g {
            (self.group_base[k] + m * m + (row - start) + col * m, m)
        } else {
            (self.group_base[k] + (row - start) + (col - start) * m, m)
        }
    }

    /// Length of the block buffer (the storage of `H` it is factored from).
    pub(super) fn storage_len(&self) -> usize {
        self.values.len()
    }

    /// Factor `H + diag(damping)`, `hessian` in the layout of the block
    /// buffer ([`SchurLayout::place`]; only lower triangles are read);
    /// `false` if a block or the reduced system is not positive definite.
    ///
    /// On the AVX2 path (`simd::avx2`) the same code runs compiled for it
    /// (no FMA: the values are bit for bit those of the SSE2 build). A group
    /// of a shape outside the table of `shapes` is counted in `fallbacks`.
    pub(super) fn factorize(&mut self, hessian: &[f64], damping: &[f64], fallbacks: &FallbackCounter) -> bool {
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: `factorize_avx2` only needs AVX2, which the CPU has (`simd::avx2`).
            return unsafe { self.factorize_avx2(hessian, damping, fallbacks) };
        }
        self.factorize_any::<false>(hessian, damping, fallbacks)
    }

    /// [`SchurLayout::factorize_any`] compiled with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn factorize_avx2(&mut self, hessian: &[f64], damping: &[f64], fallbacks: &FallbackCounter) -> bool {
        self.factorize_any::<true>(hessian, damping, fallbacks)
    }

    /// [`SchurLayout::factorize`] for the instruction set it is inlined into
    /// (`AVX2`: only from [`SchurLayout::factorize_avx2`]).
    #[inline(always)]
    fn factorize_any<const AVX2: bool>(
        &mut self,
        hessian: &[f64],
        damping: &[f64],
        fallbacks: &FallbackCounter,
    ) -> bool {
        self.factored = false;
        let g = self.globals;
        // Each block is copied from `hessian` just before it is factored
        // (while it is in cache), not the whole buffer up front.
        let (reduced, blocks) = self.values.split_at_mut(g * g);
        reduced.copy_from_slice(&hessian[..g * g]);
        for (i, d) in damping[..g].iter().enumerate() {
            reduced[i + i * g] += d;
        }
        for (k, &(start, m)) in self.groups.iter().enumerate() {
            let base = self.group_base[k] - g * g;
            let block = &mut blocks[base..base + m * m + m * g];
            block.copy_from_slice(&hessian[g * g + base..g * g + base + m * m + m * g]);
            let group_damping = &damping[start..start + m];
            let eliminated = match m {
                GROUP => eliminate_group::<GROUP, AVX2>(block, group_damping, reduced, g, fallbacks),
                POSE => eliminate_group::<POSE, AVX2>(block, group_damping, reduced, g, fallbacks),
                _ => eliminate_group::<0, AVX2>(block, group_damping, reduced, g, fallbacks),
            };
            if !eliminated {
                return false;
            }
        }
        if g > 0 && !cholesky_in_place(reduced, g) {
            return false;
        }
        // Every entry of the factors is finite here, without a scan: a
        // non-finite `L[i][j]` (`i > j`, of `L_k` or of the reduced system)
        // enters pivot `i` squared, and a non-finite entry of `W_k` column
        // `c` enters the reduced pivot `c` squared; a non-finite pivot fails
        // above (unit test `a_non_finite_entry_anywhere_fails`).
        self.factored = true;
        self.factored
    }

    /// Solve with the last successful factorisation; `None` if there is none.
    ///
    /// On the AVX2 path (`simd::avx2`) the same code runs compiled for it
    /// (no FMA, and every sum keeps its order: bit for bit the SSE2 build's
    /// values). A group of a shape outside the table of `shapes` is counted
    /// in `fallbacks`.
    pub(super) fn solve(&self, rhs: &[f64], fallbacks: &FallbackCounter) -> Option<Vec<f64>> {
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: `solve_avx2` only needs AVX2, which the CPU has (`simd::avx2`).
            return unsafe { self.solve_avx2(rhs, fallbacks) };
        }
        self.solve_any(rhs, fallbacks)
    }

    /// [`SchurLayout::solve_any`] compiled with AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn solve_avx2(&self, rhs: &[f64], fallbacks: &FallbackCounter) -> Option<Vec<f64>> {
        self.solve_any(rhs, fallbacks)
    }

    /// [`SchurLayout::solve`] for the instruction set it is inlined into.
    #[inline(always)]
    fn solve_any(&self, rhs: &[f64], fallbacks: &FallbackCounter) -> Option<Vec<f64>> {
        if !self.factored {
            return None;
        }
        if self.groups_without_kernel > 0 {
            // Two substitutions per group, in the two loops below.
            fallbacks.substitutions(2 * self.groups_without_kernel);
        }
        let g = self.globals;
        let (reduced, _) = self.values.split_at(g * g);
        let mut x = rhs.to_vec();
        // y_k = L_k^-1 b_k; b_g -= W_k^T y_k.
        for (k, &(start, m)) in self.groups.iter().enumerate() {
            let base = self.group_base[k];
            let (d, w) = self.values[base..base + m * m + m * g].split_at(m * m);
            let (global_part, rest) = x.split_at_mut(g);
            let y = &mut rest[start - g..start - g + m];
            // The shapes of `has_substitution_kernel`.
            match (m, g) {
                (GROUP, GLOBALS) => reduce_right_hand_side::<GROUP, GLOBALS>(d, w, y, global_part),
                _ => reduce_right_hand_side::<0, 0>(d, w, y, global_part),
            }
        }
        if g > 0 {
            forward_substitute(reduced, g, &mut x[..g]);
            backward_substitute(reduced, g, &mut x[..g]);
        }
        // x_k = L_k^-T (y_k - W_k x_g).
        for (k, &(start, m)) in self.groups.iter().enumerate() {
            let base = self.group_base[k];
            let (d, w) = self.values[base..base + m * m + m * g].split_at(m * m);
            let (global_part, rest) = x.split_at_mut(g);
            let y = &mut rest[start - g..start - g + m];
            match (m, g) {
                (GROUP, GLOBALS) => back_substitute_group::<GROUP, GLOBALS>(d, w, global_part, y),
                _ => back_substitute_group::<0, 0>(d, w, global_part, y),
            }
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }
}

impl SchurLayout {
    /// The globals' part of [`SchurLayout::solve`] for a right-hand side
    /// that is zero outside the globals (`rhs_globals`): the groups add
    /// exact zeros to the reduced right-hand side (`b_g - W_k^T L_k^-1 0`
    /// is `b_g` to the bit), so only the reduced system is solved. `None`
    /// if there is no factorisation or a value is not finite (the groups'
    /// part of the solution is not computed, so not checked).
    pub(super) fn solve_globals(&self, rhs_globals: &[f64]) -> Option<Vec<f64>> {
        let g = self.globals;
        if !self.factored || rhs_globals.len() != g {
            return None;
        }
        let mut x = rhs_globals.to_vec();
        let reduced = &self.values[..g * g];
        forward_substitute(reduced, g, &mut x);
        backward_substitute(reduced, g, &mut x);
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// `a^T (H + damping)^-1 a` with the last successful factorisation, for an
    /// `a` that is zero outside the globals and a few groups (one factor's
    /// row): the groups where `a` is zero contribute exact zeros to the
    /// reduced right-hand side and to the product, so only the others are
    /// visited. The value is that of [`SchurLayout::solve`] followed by the
    /// dot product, bit for bit. `None` if there is no factorisation.
    pub(super) fn inverse_quadratic_form(&self, a: &[f64]) -> Option<f64> {
        if !self.factored {
            return None;
        }
        let g = self.globals;
        let (reduced, _) = self.values.split_at(g * g);
        let touched: Vec<usize> = (0..self.groups.len())
            .filter(|&k| {
                let (start, m) = self.groups[k];
                a[start..start + m].iter().any(|&v| v != 0.0)
            })
            .collect();
        let mut x_global = a[..g].to_vec();
        let mut y: Vec<Vec<f64>> = Vec::with_capacity(touched.len());
        // y_k = L_k^-1 b_k; b_g -= W_k^T y_k (as in `solve`, touched groups only).
        for &k in &touched {
            let (start, m) = self.groups[k];
            let base = self.group_base[k];
            let (d, w) = self.values[base..base + m * m + m * g].split_at(m * m);
            let mut yk = a[start..start + m].to_vec();
            forward_substitute(d, m, &mut yk);
            for (j, bj) in x_global.iter_mut().enumerate() {
                *bj -= w[j * m..(j + 1) * m]
                    .iter()
                    .zip(yk.iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            }
            y.push(yk);
        }
        if g > 0 {
            forward_substitute(reduced, g, &mut x_global);
            backward_substitute(reduced, g, &mut x_global);
        }
        let mut form: f64 = a[..g].iter().zip(&x_global).map(|(a, x)| a * x).sum();
        // x_k = L_k^-T (y_k - W_k x_g), then the product over the group.
        for (&k, yk) in touched.iter().zip(&mut y) {
            let (start, m) = self.groups[k];
            let base = self.group_base[k];
            let (d, w) = self.values[base..base + m * m + m * g].split_at(m * m);
            for (j, &xj) in x_global.iter().enumerate() {
                for (yi, wi) in yk.iter_mut().zip(&w[j * m..(j + 1) * m]) {
                    *yi -= wi * xj;
                }
            }
            backward_substitute(d, m, yk);
            // Term by term, continuing the sum in index order as the dot product does.
            for (a, x) in a[start..start + m].iter().zip(yk.iter()) {
                form += a * x;
            }
        }
        form.is_finite().then_some(form)
    }
}

/// Whether a group of `m` columns against `g` globals has fixed-size
/// substitutions (the arms of [`SchurLayout::solve_any`]'s matches).
fn has_substitution_kernel(m: usize, g: usize) -> bool {
    matches!((m, g), (GROUP, GLOBALS))
}

/// `y <- L^-1 y` and `b_g -= W^T y` for one group (`L` `m x m`, `W` `m x g`,
/// column-major); `M`, `G` the sizes when known at compile time (`0`: any).
#[inline(always)]
fn reduce_right_hand_side<const M: usize, const G: usize>(
    l: &[f64],
    w: &[f64],
    y: &mut [f64],
    global_part: &mut [f64],
) {
    let m = if M == 0 { y.len() } else { M };
    let g = if G == 0 { global_part.len() } else { G };
    let (y, global_part, w) = (&mut y[..m], &mut global_part[..g], &w[..m * g]);
    forward_substitute(l, m, y);
    if M != 0 && G != 0 {
        // The dot products side by side, one per global column, each
        // summed in order of `i` from `-0.0` as `Iterator::sum` does.
        let mut sums = [-0.0; G];
        for (i, &yi) in y.iter().enumerate() {
            for (j, sum) in sums.iter_mut().enumerate() {
                *sum += w[i + j * M] * yi;
            }
        }
        for (bj, sum) in global_part.iter_mut().zip(sums.iter()) {
            *bj -= sum;
        }
        return;
    }
    for (bj, wj) in global_part.iter_mut().zip(w.chunks_exact(m)) {
        *bj -= wj.iter().zip(y.iter()).map(|(a, b)| a * b).sum::<f64>();
    }
}

/// `y <- L^-T (y - W x_g)` for one group (see [`reduce_right_hand_side`]).
#[inline(always)]
fn back_substitute_group<const M: usize, const G: usize>(l: &[f64], w: &[f64], global_part: &[f64], y: &mut [f64]) {
    let m = if M == 0 { y.len() } else { M };
    let g = if G == 0 { global_part.len() } else { G };
    let (y, global_part, w) = (&mut y[..m], &global_part[..g], &w[..m * g]);
    // `y_i -= sum_j W_ij x_j`, the terms subtracted in order of `j`.
    let subtract = |y: &mut [f64]| {
        for (&xj, wj) in global_part.iter().zip(w.chunks_exact(m)) {
            for (yi, wi) in y.iter_mut().zip(wj) {
                *yi -= wi * xj;
            }
        }
    };
    if M != 0 {
        // On a local copy, which the compiler keeps in vector registers.
        let mut local = [0.0; M];
        local.copy_from_slice(y);
        subtract(&mut local);
        y.copy_from_slice(&local);
    } else {
        subtract(y);
    }
    backward_substitute(l, m, y);
}

/// Factor one group's damped `D` in place (`block` = `D`, then `B`, column-major)
/// into `L`, turn `B` into `W = L^-1 B`, and subtract `W^T W` from the
/// reduced system's lower triangle. `M` is the group dimension when known at
/// compile time (the loops then unroll), `0` for any; a shape `(M, g)`
/// outside the table of `shapes` takes the general loops and is counted in
/// `fallbacks`.
#[inline(always)]
fn eliminate_group<const M: usize, const AVX2: bool>(
    block: &mut [f64],
    damping: &[f64],
    reduced: &mut [f64],
    g: usize,
    fallbacks: &FallbackCounter,
) -> bool {
    let m = if M == 0 { damping.len() } else { M };
    for i in 0..m {
        block[i + i * m] += damping[i];
    }
    #[cfg(target_arch = "x86_64")]
    if AVX2 && M == GROUP && g == GLOBALS {
        // SAFETY: `AVX2` only from `factorize_avx2`, which runs only where the CPU has AVX2.
        return unsafe { simd::elimination::eliminate_group(block, reduced) };
    }
    let (d, w) = block.split_at_mut(m * m);
    if !cholesky_in_place(d, m) {
        return false;
    }
    for column in w.chunks_exact_mut(m) {
        forward_substitute(d, m, column);
    }
    match (M, g) {
        (GROUP, GLOBALS) => subtract_gram::<GROUP, GLOBALS, AVX2>(w, reduced),
        (POSE, GLOBALS) => subtract_gram::<POSE, GLOBALS, AVX2>(w, reduced),
        _ => {
            fallbacks.elimination();
            for j in 0..g {
                let wj = &w[j * m..(j + 1) * m];
                for i in j..g {
                    let wi = &w[i * m..(i + 1) * m];
                    let mut sum = wi[0] * wj[0];
                    for r in 1..m {
                        sum += wi[r] * wj[r];
                    }
                    reduced[i + j * g] -= sum;
                }
            }
        }
    }
    true
}

/// `reduced -= W^T W` (lower triangle) for `W` (`M x G`, column-major) known
/// in size: `W` is copied row by row so that neighbouring entries of a
/// column of `reduced` are neighbouring SIMD lanes; each entry sums its `M`
/// products in order, as the general loop does.
#[inline(always)]
fn subtract_gram<const M: usize, const G: usize, const AVX2: bool>(w: &[f64], reduced: &mut [f64]) {
    let w = &w[..M * G];
    let mut rows = [[0.0f64; G]; M];
    for (i, column) in w.chunks_exact(M).enumerate() {
        for r in 0..M {
            rows[r][i] = column[r];
        }
    }
    let reduced = &mut reduced[..G * G];
    #[cfg(target_arch = "x86_64")]
    if AVX2 && G == GLOBALS {
        let rows = rows.as_flattened();
        // SAFETY: `AVX2` only from `factorize_avx2`, which runs only where the CPU has AVX2.
        unsafe { simd::gram::gram_block::<M, GLOBALS, GLOBALS, true, true>(rows, rows, GLOBALS, reduced) };
        return;
    }
    for j in 0..G {
        let column = &mut reduced[j * G..(j + 1) * G];
        for i in j..G {
            let mut sum = rows[0][i] * rows[0][j];
            for row in &rows[1..] {
                sum += row[i] * row[j];
            }
            column[i] -= sum;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower-triangle entries of an arrowhead pattern: `g` globals, groups of `m`, dimension `dim`.
    fn arrowhead_indices(g: usize, m: usize, dim: usize) -> Vec<(usize, usize)> {
        let mut indices = Vec::new();
        for c in 0..dim {
            for r in c..dim {
                if r < g || c < g || (r - g) / m == (c - g) / m {
                    indices.push((r, c));
                }
            }
        }
        indices
    }

    /// The block elimination of `h + diag(damping)`, an arrowhead matrix of
    /// `g` globals and `n` groups of `m` (`shape` = `(g, m, n)`), factored.
    fn factored_arrowhead(h: &nalgebra::DMatrix<f64>, shape: (usize, usize, usize), damping: &[f64]) -> SchurLayout {
        let (g, m, n) = shape;
        let dim = g + m * n;
        let indices = arrowhead_indices(g, m, dim);
        let groups = (0..n).map(|k| (g + k * m, m)).collect();
        let mut layout = SchurLayout::new(&indices, g, groups).expect("arrowhead");
        let mut entries = vec![0.0; layout.storage_len()];
        for &(r, c) in &indices {
            entries[layout.place(r, c).0] = h[(r, c)];
        }
        assert!(layout.factorize(&entries, damping, &FallbackCounter::default()));
        layout
    }

    /// A random arrowhead SPD system solved by elimination matches a dense solve.
    #[test]
    fn elimination_matches_dense_cholesky() {
        let (g, m, n) = (3usize, 2usize, 4usize);
        let dim = g + m * n;
        // Deterministic pseudo-random Jacobian with arrowhead structure.
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut h = nalgebra::DMatrix::<f64>::zeros(dim, dim);
        for k in 0..n {
            for _ in 0..4 {
                let mut row = nalgebra::DVector::<f64>::zeros(dim);
                for i in 0..g {
                    row[i] = next();
                }
                for i in 0..m {
                    row[g + k * m + i] = next();
                }
                h += &row * row.transpose();
            }
        }
        let damping: Vec<f64> = (0..dim).map(|i| 0.1 + 0.01 * i as f64).collect();
        let mut layout = factored_arrowhead(&h, (g, m, n), &damping);
        // The build for the CPU's instruction set (AVX2 where it has it) and
        // the portable one give the same factors bit for bit.
        let factors: Vec<u64> = layout.values.iter().map(|v| v.to_bits()).collect();
        let mut entries = vec![0.0; layout.storage_len()];
        for &(r, c) in &arrowhead_indices(g, m, dim) {
            entries[layout.place(r, c).0] = h[(r, c)];
        }
        let fallbacks = FallbackCounter::default();
        assert!(layout.factorize_any::<false>(&entries, &damping, &fallbacks));
        assert_eq!(layout.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), factors);
        let rhs: Vec<f64> = (0..dim).map(|i| (i as f64).sin()).collect();
        let x = layout.solve(&rhs, &fallbacks).expect("solution");
        // Groups of 2 against 3 globals have no kernel (the table of
        // `shapes`): each group's elimination and its two substitutions take
        // the general loops, and are counted.
        let expected = super::super::shapes::Fallbacks {
            products: 0,
            eliminations: n,
            substitutions: 2 * n,
        };
        assert_eq!(fallbacks.read(), expected);
        let damped = &h + nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_vec(damping));
        let dense = damped.cholesky().expect("SPD").solve(&nalgebra::DVector::from_vec(rhs));
        let worst = x
            .iter()
            .zip(dense.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "elimination vs dense: {worst:e}");
    }

    /// The quadratic form over a row touching the globals and one group is
    /// the full solve's dot product bit for bit, and matches the dense inverse.
    #[test]
    fn inverse_quadratic_form_equals_the_full_solve() {
        let (g, m, n) = (3usize, 2usize, 5usize);
        let dim = g + m * n;
        let mut h = nalgebra::DMatrix::<f64>::zeros(dim, dim);
        for k in 0..n {
            for r in 0..4 {
                let mut row = nalgebra::DVector::<f64>::zeros(dim);
                for i in 0..g {
                    row[i] = ((k * 7 + r * 3 + i) as f64 * 0.37).sin();
                }
                for i in 0..m {
                    row[g + k * m + i] = ((k * 5 + r + 11 * i) as f64 * 0.53).cos();
                }
                h += &row * row.transpose();
            }
        }
        let damping: Vec<f64> = (0..dim).map(|i| 0.05 + 0.01 * i as f64).collect();
        let layout = factored_arrowhead(&h, (g, m, n), &damping);
        let damped = &h + nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_vec(damping));
        let inverse = damped.cholesky().expect("SPD").inverse();
        for group in [0, 2, 4] {
            let mut a = vec![0.0; dim];
            for (i, v) in a.iter_mut().enumerate().take(g) {
                *v = 0.3 + i as f64;
            }
            a[g + group * m] = -1.25;
            a[g + group * m + 1] = 0.5;
            let x = layout.solve(&a, &FallbackCounter::default()).expect("solution");
            let full: f64 = a.iter().zip(&x).map(|(a, x)| a * x).sum();
            let form = layout.inverse_quadratic_form(&a).expect("form");
            assert_eq!(form.to_bits(), full.to_bits(), "group {group}");
            let va = nalgebra::DVector::from_vec(a);
            let dense = (va.transpose() * &inverse * &va)[(0, 0)];
            assert!((form - dense).abs() < 1e-10 * dense.abs(), "{form} vs {dense}");
        }
        // A right-hand side zero outside the globals (a covariance's unit
        // column, and a general one with a negative zero): the reduced
        // solve gives the globals' part of the full solve, bit for bit.
        for rhs_globals in [vec![0.0, 1.0, 0.0], vec![0.7, -0.0, -2.5]] {
            let mut rhs = vec![0.0; dim];
            rhs[..g].copy_from_slice(&rhs_globals);
            let full = layout.solve(&rhs, &FallbackCounter::default()).expect("solution");
            let globals = layout.solve_globals(&rhs_globals).expect("solution");
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&globals), bits(&full[..g]), "{rhs_globals:?}");
            for (i, x) in globals.iter().enumerate() {
                let expected: f64 = (0..g).map(|j| inverse[(i, j)] * rhs_globals[j]).sum();
                assert!(
                    (x - expected).abs() < 1e-10 * expected.abs().max(1e-3),
                    "{x} vs {expected}"
                );
            }
        }
    }

    /// A NaN or an infinity at any stored entry of the lower triangle
    /// (globals, a group's block, a coupling block) fails the factorisation.
    #[test]
    fn a_non_finite_entry_anywhere_fails() {
        let (g, m, n) = (3usize, 2usize, 3usize);
        let dim = g + m * n;
        let indices = arrowhead_indices(g, m, dim);
        let groups: Vec<(usize, usize)> = (0..n).map(|k| (g + k * m, m)).collect();
        let mut layout = SchurLayout::new(&indices, g, groups).expect("arrowhead");
        // A diagonally dominant SPD matrix: factorises as it is.
        let mut entries = vec![0.0; layout.storage_len()];
        for &(r, c) in &indices {
            entries[layout.place(r, c).0] = if r == c { 10.0 } else { 0.1 + 0.01 * (r + c) as f64 };
        }
        let damping = vec![0.0; dim];
        assert!(layout.factorize(&entries, &damping, &FallbackCounter::default()));
        for &(r, c) in &indices {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut broken = entries.clone();
                broken[layout.place(r, c).0] = bad;
                assert!(
                    !layout.factorize(&broken, &damping, &FallbackCounter::default()),
                    "({r}, {c}) = {bad}"
                );
                assert!(layout.solve(&vec![1.0; dim], &FallbackCounter::default()).is_none());
            }
        }
    }

    #[test]
    fn coupled_groups_are_rejected_and_indefinite_blocks_fail() {
        assert!(SchurLayout::new(&[(3, 2)], 1, vec![(1, 2), (3, 2)]).is_none());
        let mut layout = SchurLayout::new(&[(0, 0), (1, 1)], 1, vec![(1, 1)]).expect("layout");
        assert_eq!(layout.storage_len(), 3);
        assert_eq!(layout.place(1, 1).0, 1);
        assert!(!layout.factorize(&[1.0, -1.0, 0.0], &[0.0, 0.0], &FallbackCounter::default()));
        assert!(layout.solve(&[1.0, 1.0], &FallbackCounter::default()).is_none());
    }

    /// The group substitutions for `M = 8, G = 16` (local copies, dot
    /// products side by side) give the general loops' values bit for bit.
    #[test]
    fn fixed_size_substitutions_match_the_general_loops() {
        let entry = |k: usize| (k as f64 * 0.618_033_988_749_895).sin() * (1.0 + k as f64 / 7.0);
        let mut l: Vec<f64> = (0..64).map(|k| 0.1 * entry(k)).collect();
        (0..8).for_each(|j| l[j + 8 * j] = 2.0 + entry(j).abs());
        let w: Vec<f64> = (0..128).map(|k| entry(k + 64)).collect();
        let y: Vec<f64> = (0..8).map(|k| entry(k + 200)).collect();
        let globals: Vec<f64> = (0..16).map(|k| entry(k + 300)).collect();
        let (mut y_fixed, mut y_any, mut g_fixed, mut g_any) = (y.clone(), y.clone(), globals.clone(), globals.clone());
        reduce_right_hand_side::<GROUP, GLOBALS>(&l, &w, &mut y_fixed, &mut g_fixed);
        reduce_right_hand_side::<0, 0>(&l, &w, &mut y_any, &mut g_any);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!((bits(&y_fixed), bits(&g_fixed)), (bits(&y_any), bits(&g_any)));
        assert!(g_fixed.iter().zip(&globals).all(|(a, b)| a != b));
        back_substitute_group::<GROUP, GLOBALS>(&l, &w, &globals, &mut y_fixed);
        back_substitute_group::<0, 0>(&l, &w, &globals, &mut y_any);
        assert_eq!(bits(&y_fixed), bits(&y_any));
    }
}

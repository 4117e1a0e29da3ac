//! A taut tension distribution for straight cables ([`taut_tensions`]):
//! the tensions along the cables' lines that balance the platform's wrench
//! and stay nearest an even share, none below a tenth of it.
//!
//! With the lines' wrench matrix `L` (6 x N: per cable its unit pull and
//! that pull's moment, moment rows divided by the attachment radius so
//! that forces and moments weigh alike), the wrench `w` and the even share
//! `e`, the tensions `t = t_min + y` solve the nonnegative least squares
//! ```text
//! min_y>=0 | [ L ; mu I ] (t_min + y) - [ w ; mu e ] |^2,   t_min = e / 10,
//! ```
//! by Lawson and Hanson's active-set method (*Solving Least Squares
//! Problems*, 1974, ch. 23). `mu` (1e-3) keeps the wrench nearly exact
//! where taut tensions can carry it, and the even share where the lines
//! leave the tensions free (more than six cables). Where no taut
//! distribution balances the wrench (a platform outside the cables' reach,
//! or three or four cables at an orientation they cannot hold), the
//! result is the closest: a start for the equilibrium's Newton solve, not
//! an equilibrium.

use nalgebra::{DMatrix, DVector};

/// The weight of the tensions' distance from the even share against the
/// wrench's residual (module docs).
const EVEN_SHARE_WEIGHT: f64 = 1e-3;

/// The tensions of the module docs for the lines `lines` (6 x N, unscaled:
/// unit pulls and their moments in metres), the wrench `wrench`, the even
/// share `even` (newtons) and the platform's attachment radius (metres).
pub(super) fn taut_tensions(lines: &DMatrix<f64>, wrench: &DVector<f64>, even: f64, radius_m: f64) -> DVector<f64> {
    let n = lines.ncols();
    let floor = 0.1 * even;
    let mut a = DMatrix::zeros(6 + n, n);
    let mut b = DVector::zeros(6 + n);
    for r in 0..6 {
        let scale = if r < 3 { 1.0 } else { 1.0 / radius_m };
        for c in 0..n {
            a[(r, c)] = lines[(r, c)] * scale;
        }
        b[r] = wrench[r] * scale;
    }
    for c in 0..n {
        a[(6 + c, c)] = EVEN_SHARE_WEIGHT;
        b[6 + c] = EVEN_SHARE_WEIGHT * even;
    }
    let b = &b - &a * DVector::from_element(n, floor);
    let y = nonnegative_least_squares(&a, &b);
    y.add_scalar(floor)
}

/// `argmin_{x >= 0} |a x - b|` (Lawson and Hanson's NNLS).
fn nonnegative_least_squares(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let tolerance = 1e-12 * a.amax().max(1.0) * b.amax().max(1.0);
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    for _ in 0..3 * n {
        let gradient = a.transpose() * (b - a * &x);
        let entering = (0..n)
            .filter(|&j| !passive[j] && gradient[j] > tolerance)
            .max_by(|&i, &j| gradient[i].total_cmp(&gradient[j]));
        let Some(j) = entering else {
            break;
        };
        passive[j] = true;
        for _ in 0..3 * n {
            let s = passive_solution(a, b, &passive);
            if (0..n).filter(|&k| passive[k]).all(|k| s[k] > 0.0) {
                x = s;
                break;
            }
            // Step from x towards s as far as every passive entry stays >= 0.
            let alpha = (0..n)
                .filter(|&k| passive[k] && s[k] <= 0.0)
                .map(|k| x[k] / (x[k] - s[k]))
                .fold(1.0, f64::min);
            x += (&s - &x) * alpha;
            for k in 0..n {
                if passive[k] && x[k] <= tolerance {
                    passive[k] = false;
                    x[k] = 0.0;
                }
            }
        }
    }
    x
}

/// The least-squares solution on the passive columns, zero elsewhere.
fn passive_solution(a: &DMatrix<f64>, b: &DVector<f64>, passive: &[bool]) -> DVector<f64> {
    let columns: Vec<usize> = (0..passive.len()).filter(|&k| passive[k]).collect();
    if columns.is_empty() {
        return DVector::zeros(passive.len());
    }
    let sub = DMatrix::from_fn(a.nrows(), columns.len(), |r, c| a[(r, columns[c])]);
    let solved = sub
        .svd(true, true)
        .solve(b, 1e-14)
        .unwrap_or_else(|_| DVector::zeros(columns.len()));
    let mut s = DVector::zeros(passive.len());
    for (c, &k) in columns.iter().enumerate() {
        s[k] = solved[c];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a brute force over the active sets: every subset of columns
    /// solved unconstrained, the feasible one of least residual.
    #[test]
    fn nnls_is_the_best_feasible_subset() {
        let a = DMatrix::from_row_slice(
            5,
            4,
            &[
                1.0, 0.2, -0.5, 0.3, //
                0.1, 1.0, 0.4, -0.7, //
                -0.3, 0.5, 1.0, 0.2, //
                0.6, -0.2, 0.1, 1.0, //
                0.2, 0.3, -0.4, 0.5,
            ],
        );
        for b in [
            DVector::from_vec(vec![1.0, -2.0, 0.5, 0.3, -1.0]),
            DVector::from_vec(vec![0.3, 0.2, 0.1, 0.4, 0.2]),
            DVector::from_vec(vec![-1.0, -1.0, -1.0, -1.0, -1.0]),
        ] {
            let x = nonnegative_least_squares(&a, &b);
            assert!(x.iter().all(|v| *v >= 0.0));
            let best = (0u32..16)
                .filter_map(|mask| {
                    let passive: Vec<bool> = (0..4).map(|k| mask & (1 << k) != 0).collect();
                    let s = passive_solution(&a, &b, &passive);
                    s.iter().all(|v| *v >= -1e-12).then(|| (&a * &s - &b).norm())
                })
                .fold(f64::INFINITY, f64::min);
            assert!(((&a * &x - &b).norm() - best).abs() < 1e-10, "{x} vs {best}");
        }
    }

    /// Eight lines around a platform and a wrench that uneven taut tensions
    /// carry: carried to within the even-share weight's pull, every
    /// tension at least a tenth of the even share.
    #[test]
    fn taut_tensions_carry_the_weight() {
        let n = 8;
        let mut lines = DMatrix::zeros(6, n);
        for i in 0..n {
            let angle = std::f64::consts::TAU * i as f64 / n as f64;
            let e = nalgebra::Vector3::new(0.8 * angle.cos(), 0.8 * angle.sin(), 0.6);
            let r = nalgebra::Vector3::new(0.5 * angle.cos(), 0.5 * angle.sin(), 0.1);
            let m = r.cross(&e);
            lines.set_column(i, &DVector::from_vec(vec![e.x, e.y, e.z, m.x, m.y, m.z]));
        }
        // A wrench taut cables can carry: that of uneven positive tensions.
        let uneven = DVector::from_fn(n, |i, _| 80.0 + 40.0 * (i as f64).cos());
        let wrench = &lines * &uneven;
        let even = wrench[2] / (0.6 * n as f64);
        let t = taut_tensions(&lines, &wrench, even, 0.5);
        assert!(t.iter().all(|v| *v >= 0.1 * even - 1e-9), "{t}");
        let residual = &lines * &t - &wrench;
        assert!(residual.amax() < 1e-3, "{} {residual}", t.transpose());
    }
}

//! The statistics sagcal's tests rest on: chi-square quantiles, Pearson
//! correlation with its t statistic, and the Bayesian information criterion.
//!
//! # The chi-square quantile and its error
//!
//! Quantiles use the Wilson-Hilferty cube-root normal approximation
//! `k (1 - 2/(9k) + z sqrt(2/(9k)))^3` (Johnson, Kotz & Balakrishnan,
//! *Continuous Univariate Distributions*, vol. 1, 1994, eq. 18.24). Against
//! the exact quantile (the regularised incomplete gamma function inverted by
//! bisection, `tests/stats.rs`), its relative error over `k <= 1000` is, at
//! the 99.9 % point, at most 1.75 % for `k >= 3`, 0.2 % for `k >= 30` and
//! 0.01 % for `k >= 300`; at the 0.1 % point, at most 6.5 % for `k >= 10`,
//! 0.7 % for `k >= 30` and 0.08 % for `k >= 100`.
//! The calibration and diagnosis test sums of tens to hundreds of
//! components, where the approximation moves the false-alarm rate of a
//! nominal 0.1 % test by a small fraction of itself.

/// Standard normal quantile at 0.999 (and, negated, at 0.001).
pub const NORMAL_QUANTILE_999: f64 = 3.0902;

/// The 99.9 % quantile of chi-square with `k` degrees of freedom
/// (Wilson-Hilferty; error in the module docs).
pub fn chi_square_quantile_999(k: usize) -> f64 {
    chi_square_quantile(k, NORMAL_QUANTILE_999)
}

/// The 0.1 % quantile of chi-square with `k` degrees of freedom
/// (Wilson-Hilferty; error in the module docs).
pub fn chi_square_quantile_001(k: usize) -> f64 {
    chi_square_quantile(k, -NORMAL_QUANTILE_999)
}

/// The quantile of chi-square with `k` degrees of freedom at the standard
/// normal quantile `z` (Wilson-Hilferty, see the module docs).
pub fn chi_square_quantile(k: usize, z: f64) -> f64 {
    let k = k.max(1) as f64;
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + z * c.sqrt()).max(0.0).powi(3)
}

/// Pearson correlation `r` of the finite points and its t statistic
/// `t = r sqrt((n - 2) / (1 - r^2))` (Student's t with `n - 2` degrees of
/// freedom under no correlation). `(NaN, NaN)` for fewer than 3 finite
/// points; `(0, 0)` when either coordinate is constant.
pub fn correlation(points: &[(f64, f64)]) -> (f64, f64) {
    let points: Vec<&(f64, f64)> = points.iter().filter(|(x, y)| x.is_finite() && y.is_finite()).collect();
    let n = points.len() as f64;
    if n < 3.0 {
        return (f64::NAN, f64::NAN);
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in points.iter().map(|p| (p.0 - mx, p.1 - my)) {
        sxy += x * y;
        sxx += x * x;
        syy += y * y;
    }
    if sxx <= 0.0 || syy <= 0.0 {
        return (0.0, 0.0);
    }
    let r = (sxy / (sxx * syy).sqrt()).clamp(-1.0, 1.0);
    let t = r * ((n - 2.0) / (1.0 - r * r).max(1e-300)).sqrt();
    (r, t)
}

/// The Bayesian information criterion of a least-squares fit (Schwarz 1978):
/// `chi^2 / variance_factor + parameters ln(observations)`, where `chi^2` is
/// the whitened residual sum of squares and `variance_factor` the a
/// posteriori variance factor (1 when the stated noise is right).
pub fn bic(chi_square: f64, variance_factor: f64, parameters: usize, observations: usize) -> f64 {
    chi_square / variance_factor + parameters as f64 * (observations as f64).ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn correlation_matches_a_closed_form() {
        // y = 2x + 1 exactly: r = 1; y = x^2 on a symmetric grid: r = 0.
        let line: Vec<(f64, f64)> = (0..10).map(|k| (k as f64, 2.0 * k as f64 + 1.0)).collect();
        let (r, _) = correlation(&line);
        assert!((r - 1.0).abs() < 1e-12);
        let parabola: Vec<(f64, f64)> = (-5..=5).map(|k| (k as f64, (k * k) as f64)).collect();
        assert!(correlation(&parabola).0.abs() < 1e-12);
        // Deviations (-1.5, -0.5, 0.5, 1.5) and (-1.5, 0.5, -0.5, 1.5): sxy = 4, sxx = syy = 5, r = 0.8.
        let x = [1.0, 2.0, 3.0, 4.0];
        let y = [1.0, 3.0, 2.0, 4.0];
        let points: Vec<(f64, f64)> = x.iter().zip(y).map(|(a, b)| (*a, b)).collect();
        let (r, t) = correlation(&points);
        assert!((r - 0.8).abs() < 1e-12, "{r}");
        assert!((t - 0.8 * (2.0f64 / 0.36).sqrt()).abs() < 1e-12);
    }
}

//! `sagcal::stats` against independent computations: the Wilson-Hilferty
//! chi-square quantiles against the exact quantile (the regularised
//! incomplete gamma function, inverted by bisection), and the error bounds
//! the module documents.

use sagcal::stats::{bic, chi_square_quantile_001, chi_square_quantile_999};

/// `ln Gamma(k / 2)` exactly for a positive integer `k`, by the recurrence
/// `Gamma(a + 1) = a Gamma(a)` from `Gamma(1) = 1` and `Gamma(1/2) = sqrt(pi)`.
fn ln_gamma_half(k: usize) -> f64 {
    let (mut a, mut value) = if k % 2 == 0 {
        (1.0, 0.0)
    } else {
        (0.5, 0.5 * std::f64::consts::PI.ln())
    };
    while a < k as f64 / 2.0 - 0.25 {
        value += a.ln();
        a += 1.0;
    }
    value
}

/// The chi-square distribution function with `k` degrees of freedom at `x`:
/// the regularised lower incomplete gamma `P(k/2, x/2)`, by its series below
/// `a + 1` and by the continued fraction of `Q = 1 - P` above (Press et al.,
/// *Numerical Recipes*, 3rd ed., sec. 6.2).
fn chi_square_cdf(k: usize, x: f64) -> f64 {
    let a = k as f64 / 2.0;
    let x = x / 2.0;
    if x <= 0.0 {
        return 0.0;
    }
    let front = (a * x.ln() - x - ln_gamma_half(k)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..100_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-17 {
                break;
            }
        }
        sum * front
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        1.0 - front * h
    }
}

/// The exact `p` quantile of chi-square with `k` degrees of freedom, by bisection.
fn exact_quantile(k: usize, p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, k as f64 + 30.0 * (2.0 * k as f64).sqrt() + 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi_square_cdf(k, mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn the_exact_quantile_matches_tables() {
    // Abramowitz & Stegun Table 26.8 and NIST's chi-square table.
    for (k, p, q) in [
        (1, 0.999, 10.828),
        (10, 0.999, 29.588),
        (100, 0.999, 149.449),
        (10, 0.001, 1.479),
        (100, 0.001, 61.918),
        (2, 0.95, 5.991),
    ] {
        let exact = exact_quantile(k, p);
        assert!((exact - q).abs() < 1e-3, "k = {k}, p = {p}: {exact} vs the table's {q}");
    }
}

/// An approximate chi-square quantile as a function of the degrees of freedom.
type Quantile = fn(usize) -> f64;

/// The largest relative error of `approximation` against the exact `p`
/// quantile over `k` in `from..=to`.
fn worst_relative_error(approximation: Quantile, p: f64, from: usize, to: usize) -> f64 {
    (from..=to)
        .map(|k| (approximation(k) / exact_quantile(k, p) - 1.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn wilson_hilferty_stays_within_its_documented_error() {
    // The bounds stated in `sagcal::stats`' module docs, measured here.
    let cases: [(Quantile, f64, usize, f64); 6] = [
        (chi_square_quantile_999, 0.999, 3, 0.0175),
        (chi_square_quantile_999, 0.999, 30, 0.002),
        (chi_square_quantile_999, 0.999, 300, 0.0001),
        (chi_square_quantile_001, 0.001, 10, 0.065),
        (chi_square_quantile_001, 0.001, 30, 0.007),
        (chi_square_quantile_001, 0.001, 100, 0.0008),
    ];
    for (approximation, p, from, bound) in cases {
        let worst = worst_relative_error(approximation, p, from, 1000);
        println!("p = {p}, k in {from}..=1000: worst relative error {worst:.2e} (bound {bound})");
        assert!(worst < bound, "p = {p}, k >= {from}: {worst} >= {bound}");
    }
}

#[test]
fn bic_is_chi_square_plus_the_parameter_penalty() {
    // 12 parameters, 385 observations, chi-square 400 at variance factor 2.
    let expected = 200.0 + 12.0 * 385f64.ln();
    assert!((bic(400.0, 2.0, 12, 385) - expected).abs() < 1e-12);
}

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

#[test]
fn ln_gamma_matches_factorials_and_half_integers() {
    use sagcal::stats::ln_gamma;
    for k in 1..60 {
        let exact = ln_gamma_half(k);
        let got = ln_gamma(k as f64 / 2.0);
        assert!(
            (got - exact).abs() < 1e-12 * exact.abs().max(1.0),
            "k = {k}: {got} vs {exact}"
        );
    }
    // Gamma(0.1) = 9.513507698668732 (A&S Table 6.1, via Gamma(1.1) / 0.1).
    assert!((ln_gamma(0.1) - 9.513_507_698_668_732f64.ln()).abs() < 1e-13);
}

#[test]
fn the_library_quantile_matches_tables_and_the_independent_one() {
    use sagcal::stats::{chi_square_critical, chi_square_survival};
    for (k, alpha, q) in [
        (1, 0.001, 10.828),
        (10, 0.001, 29.588),
        (100, 0.001, 149.449),
        (2, 0.05, 5.991),
    ] {
        assert!((chi_square_critical(k, alpha) - q).abs() < 1e-3, "k = {k}");
    }
    for k in [1, 3, 7, 30, 105, 385] {
        for alpha in [0.05, 1e-3, 1e-6] {
            let library = chi_square_critical(k, alpha);
            let independent = exact_quantile(k, 1.0 - alpha);
            assert!(
                (library / independent - 1.0).abs() < 1e-9,
                "k = {k}, alpha = {alpha}: {library} vs {independent}"
            );
            assert!((chi_square_survival(k, library) / alpha - 1.0).abs() < 1e-9);
        }
    }
}

/// The standard normal upper tail `P(Z > z)`, by Simpson's rule on the
/// density (independent of the incomplete gamma function).
fn normal_upper_tail(z: f64) -> f64 {
    let (a, b, n) = (z, z.max(0.0) + 40.0, 200_000);
    let h = (b - a) / n as f64;
    let f = |t: f64| (-0.5 * t * t).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let mut sum = f(a) + f(b);
    for i in 1..n {
        sum += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

#[test]
fn noncentral_survival_matches_the_one_degree_closed_form() {
    use sagcal::stats::noncentral_chi_square_survival;
    // chi-square(1, lambda) is (Z + sqrt(lambda))^2: P(> c) = P(Z > sqrt(c) - mu) + P(Z > sqrt(c) + mu).
    for lambda in [0.0, 0.5, 4.0, 14.7, 60.0] {
        for c in [1.0f64, 3.841, 10.828] {
            let mu = f64::sqrt(lambda);
            let expected = normal_upper_tail(c.sqrt() - mu) + normal_upper_tail(c.sqrt() + mu);
            let got = noncentral_chi_square_survival(1, lambda, c);
            assert!(
                (got - expected).abs() < 1e-9,
                "lambda {lambda}, c {c}: {got} vs {expected}"
            );
        }
    }
}

#[test]
fn noncentral_survival_matches_a_seeded_simulation() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    use sagcal::stats::noncentral_chi_square_survival;
    // k = 4, lambda = 9 (shift 1.5 on each axis), c = 18.467 (the 0.1 % critical value).
    let seed = 7;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (trials, c) = (400_000, 18.467);
    let mut above = 0;
    for _ in 0..trials {
        let s: f64 = (0..4)
            .map(|_| {
                let z: f64 = StandardNormal.sample(&mut rng);
                (z + 1.5).powi(2)
            })
            .sum();
        above += usize::from(s > c);
    }
    let simulated = above as f64 / trials as f64;
    let exact = noncentral_chi_square_survival(4, 9.0, c);
    let standard_error = (exact * (1.0 - exact) / trials as f64).sqrt();
    println!("seed {seed}: simulated {simulated:.5}, series {exact:.5} (standard error {standard_error:.5})");
    assert!((simulated - exact).abs() < 5.0 * standard_error);
}

#[test]
fn the_noncentrality_for_a_power_matches_the_normal_case() {
    use sagcal::stats::{chi_square_critical, noncentrality_for_power};
    // One degree of freedom at alpha = 0.05, power 0.8: lambda = (1.95996 + 0.84162)^2 = 7.8489.
    let lambda = noncentrality_for_power(1, chi_square_critical(1, 0.05), 0.8);
    assert!((lambda - 7.8489).abs() < 1e-3, "{lambda}");
}

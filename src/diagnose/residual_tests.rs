//! Step 1: the baseline's residuals tested against the stated noise, one
//! chi-square test per factor type, and the a posteriori variance factor.

use serde::Serialize;

use crate::graph::{whitened_squared_norm, FactorGraph};
use crate::solver::redundancy_numbers;
use crate::stats::{chi_square_critical, chi_square_quantile_001, chi_square_quantile_999};

/// The factor types that are measurements (the others are model constraints).
pub const MEASUREMENT_KINDS: [&str; 3] = ["catenary_length", "reference_tension", "pose_prior"];

/// Chi-square test of one factor type's normalised residuals against the stated noise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FactorTest {
    /// Factor type (`catenary_length`, `reference_tension`, `pose_prior`).
    pub kind: String,
    /// Residual components.
    pub components: usize,
    /// Sum of `(r / sigma)^2`.
    pub chi_square: f64,
    /// Its expectation when the model holds: the sensor's redundancy (the
    /// sum of its rows' redundancy numbers).
    pub expected: f64,
    /// The critical value of chi-square with `expected` degrees of freedom at
    /// the test's level (the baseline's: the 99.9 % quantile).
    pub limit: f64,
    /// `chi_square <= limit`.
    pub consistent: bool,
}

/// Residual components of the measurement factors.
pub(super) fn measurement_components(graph: &FactorGraph) -> usize {
    graph
        .factors
        .iter()
        .filter(|f| MEASUREMENT_KINDS.contains(&f.kind()))
        .map(|f| f.residual_dim())
        .sum()
}

/// Chi-square of the measurement and statics factors (not the inactive tension guard).
pub(super) fn total_chi_square(graph: &FactorGraph) -> f64 {
    graph
        .factors
        .iter()
        .filter(|f| f.kind() != "tension_guard")
        .filter_map(|f| {
            f.evaluate(&graph.values, None)
                .map(|r| whitened_squared_norm(&r, f.sigmas()))
        })
        .sum()
}

/// The chi-square test of each measurement factor type at the 99.9 % quantile.
pub(super) fn factor_tests(graph: &FactorGraph, components: usize, dof: usize) -> Vec<FactorTest> {
    tests_with_limit(graph, components, dof, chi_square_quantile_999)
}

/// The chi-square test of each measurement factor type, each at the level
/// `false_alarm / 3` (Bonferroni over the three sensors: on data the model
/// describes, the probability that any of them fails is at most `false_alarm`).
pub(super) fn factor_tests_at(graph: &FactorGraph, components: usize, dof: usize, false_alarm: f64) -> Vec<FactorTest> {
    let level = false_alarm / MEASUREMENT_KINDS.len() as f64;
    tests_with_limit(graph, components, dof, |k| chi_square_critical(k, level))
}

/// The tests with the critical value `quantile(expected)`. A sensor's
/// expected chi-square is its redundancy, the sum of its rows' redundancy
/// numbers `r_i = 1 - h_i` ([`crate::solver::redundancy_numbers`]): the
/// share of the fit's degrees of freedom its residuals keep (the orientation
/// prior's rows give much of theirs to the poses they fix, the encoders'
/// keep more). Where the information matrix cannot be factored, the
/// components' share of the fit's degrees of freedom stands in for it.
fn tests_with_limit(
    graph: &FactorGraph,
    components: usize,
    dof: usize,
    quantile: impl Fn(usize) -> f64,
) -> Vec<FactorTest> {
    let redundancy = redundancy_numbers(graph, &MEASUREMENT_KINDS).ok();
    MEASUREMENT_KINDS
        .iter()
        .map(|kind| {
            let mut count = 0;
            let mut chi = 0.0;
            let mut kept = 0.0;
            for (index, f) in graph.factors.iter().enumerate().filter(|(_, f)| f.kind() == *kind) {
                if let Some(r) = f.evaluate(&graph.values, None) {
                    count += r.len();
                    chi += whitened_squared_norm(&r, f.sigmas());
                    if let Some(numbers) = redundancy.as_ref().and_then(|all| all[index].as_ref()) {
                        kept += numbers.iter().sum::<f64>();
                    }
                }
            }
            let expected = match redundancy {
                Some(_) => kept,
                None => count as f64 * dof as f64 / components.max(1) as f64,
            };
            let limit = quantile(expected.round().max(1.0) as usize);
            FactorTest {
                kind: kind.to_string(),
                components: count,
                chi_square: chi,
                expected,
                limit,
                consistent: chi <= limit,
            }
        })
        .collect()
}

/// The a posteriori variance factor (geodesy's "variance of unit weight"):
/// when the baseline's chi-square is below the 0.1 % quantile for its degrees
/// of freedom the data are more precise than the stated noise (e.g. simulated
/// data without noise), and the information criteria use the residual scale
/// the data show, `chi^2 / s^2` with `s^2 = chi^2 / dof`. Never scaled up: a
/// too-large chi-square is what the candidates must explain.
pub(super) fn variance_factor(baseline_chi_square: f64, dof: usize) -> f64 {
    if baseline_chi_square < chi_square_quantile_001(dof) {
        baseline_chi_square / dof as f64
    } else {
        1.0
    }
}

//! Score tests of a term the model lacks, at a least-squares solution.
//!
//! With `A` the whitened Jacobian, `r` the whitened residual at the
//! solution and `P = A (A^T A)^-1 A^T` the hat matrix, a term `c d` added to
//! the model's predictions (`d` a direction over the residual rows, whitened:
//! a driver's value over the row's sigma) has the least-squares estimate
//!
//! `c = -d^T r / I`, with `I = d^T (I - P) d = d^T d - g^T (A^T A)^-1 g`, `g = A^T d`,
//!
//! and standard deviation `1 / sqrt(I)` (the model's own parameters
//! re-fitted with it: the Frisch-Waugh-Lovell theorem). Because `A^T r = 0`
//! at the solution, `r = (I - P) e` to first order in the noise `e`, so
//! `z = c sqrt(I)` is standard normal when the model holds: Rao's score
//! (Lagrange multiplier) test of `c = 0`, which counts every correlation the
//! fit puts between residuals (the readings of one pose share its pose and
//! tension) and every share of `d` that the model's own parameters absorb.
//! `I` near zero means the model already holds the term; it is then not
//! testable and `z` is NaN.

use super::redundancy::{factored_information, whitened_rows};
use crate::error::SolverError;
use nalgebra::{DMatrix, DVector};

use crate::graph::FactorGraph;

/// A direction over the residual rows of a graph: per factor (graph order),
/// the weight of each whitened residual row, or `None` where it has none.
pub type Direction = Vec<Option<Vec<f64>>>;

/// The score test of one added term (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScoreTest {
    /// The term's estimated coefficient `c` (the units of the direction's
    /// physical reading per unit of its driver).
    pub coefficient: f64,
    /// Its standard deviation `1 / sqrt(I)`.
    pub sigma: f64,
    /// `z = c / sigma`, standard normal when the model holds (NaN when the
    /// model already holds the term).
    pub z: f64,
    /// The share of `d^T d` the model does not absorb, `I / d^T d`.
    pub new_share: f64,
}

/// Several added terms at once: `M = D^T (I - P) D` (the information of
/// their coefficients with the model's parameters re-fitted) and
/// `b = -D^T r` (their scores), from which every test of one term given
/// others follows (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ScoreSystem {
    /// `M`, one row and column per direction.
    pub information: DMatrix<f64>,
    /// `b`.
    pub score: DVector<f64>,
    /// `d^T d` per direction.
    pub norms: Vec<f64>,
}

impl ScoreSystem {
    /// The test of term `j` with the terms `given` added to the model too
    /// (their coefficients re-fitted with it): with `S = given`,
    /// `I = M_jj - M_jS M_SS^-1 M_Sj` and `c = (b_j - M_jS M_SS^-1 b_S) / I`.
    pub fn test(&self, j: usize, given: &[usize]) -> ScoreTest {
        let (mut information, mut score) = (self.information[(j, j)], self.score[j]);
        if !given.is_empty() {
            let m_ss = DMatrix::from_fn(given.len(), given.len(), |a, b| self.information[(given[a], given[b])]);
            let m_sj = DVector::from_fn(given.len(), |a, _| self.information[(given[a], j)]);
            let b_s = DVector::from_fn(given.len(), |a, _| self.score[given[a]]);
            if let Some(inverse) = m_ss.try_inverse() {
                let weights = inverse * &m_sj;
                information -= m_sj.dot(&weights);
                score -= b_s.dot(&weights);
            }
        }
        let new_share = if self.norms[j] > 0.0 {
            information / self.norms[j]
        } else {
            0.0
        };
        if new_share > 1e-9 {
            let coefficient = score / information;
            let sigma = information.sqrt().recip();
            ScoreTest {
                coefficient,
                sigma,
                z: coefficient / sigma,
                new_share,
            }
        } else {
            ScoreTest {
                coefficient: f64::NAN,
                sigma: f64::NAN,
                z: f64::NAN,
                new_share,
            }
        }
    }

    /// Every term added at once: their coefficients fitted together,
    /// `c = M^-1 b`, and the chi-square drop they make, `b^T M^-1 b` (to
    /// first order: the Gauss-Newton step from the model's solution); `None`
    /// where `M` is singular (terms the data do not tell apart).
    pub fn joint_fit(&self) -> Option<(DVector<f64>, f64)> {
        let inverse = self.information.clone().try_inverse()?;
        let coefficients = inverse * &self.score;
        let drop = self.score.dot(&coefficients);
        Some((coefficients, drop))
    }

    /// Forward selection of terms (a sparse regression of the residuals on
    /// the directions): at each step the term of largest `|z|` given those
    /// chosen, while it exceeds `limit(untested)` (`untested`: the testable
    /// terms not chosen yet), at most `most` terms. Returns the terms in the
    /// order chosen.
    pub fn forward_selection(&self, limit: impl Fn(usize) -> f64, most: usize) -> Vec<usize> {
        let mut chosen: Vec<usize> = Vec::new();
        while chosen.len() < most {
            let tests: Vec<(usize, f64)> = (0..self.score.len())
                .filter(|j| !chosen.contains(j))
                .map(|j| (j, self.test(j, &chosen).z))
                .filter(|(_, z)| z.is_finite())
                .collect();
            let best = tests.iter().max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
            match best {
                Some(&(j, z)) if z.abs() > limit(tests.len()) => chosen.push(j),
                _ => break,
            }
        }
        chosen
    }
}

/// The score test of each of `directions` at the graph's values, which must
/// be a least-squares solution of the graph (module docs).
pub fn score_tests(graph: &FactorGraph, directions: &[Direction]) -> Result<Vec<ScoreTest>, SolverError> {
    let system = score_system(graph, directions)?;
    Ok((0..directions.len()).map(|j| system.test(j, &[])).collect())
}

/// The [`ScoreSystem`] of `directions` at the graph's values, which must be
/// a least-squares solution of the graph.
pub fn score_system(graph: &FactorGraph, directions: &[Direction]) -> Result<ScoreSystem, SolverError> {
    const WHAT: &str = "score tests";
    let mut system = factored_information(graph, WHAT)?;
    let touched: Vec<bool> = (0..graph.factors.len())
        .map(|f| directions.iter().any(|d| d.get(f).is_some_and(Option::is_some)))
        .collect();
    let mut rows = Vec::with_capacity(graph.factors.len());
    for (factor, touched) in graph.factors.iter().zip(&touched) {
        rows.push(match touched {
            true => Some(whitened_rows(graph, factor.as_ref(), &system, WHAT)?),
            false => None,
        });
    }
    let count = directions.len();
    let mut gradients = Vec::with_capacity(count);
    let mut score = DVector::zeros(count);
    for (j, direction) in directions.iter().enumerate() {
        let mut g = vec![0.0; system.dim];
        for (weights, factor_rows) in direction.iter().zip(&rows) {
            let (Some(weights), Some((residual, jacobian))) = (weights, factor_rows) else {
                continue;
            };
            if weights.len() != residual.len() {
                return Err(SolverError::DirectionShape {
                    what: WHAT,
                    weights: weights.len(),
                    rows: residual.len(),
                });
            }
            for ((w, r), a) in weights.iter().zip(residual).zip(jacobian) {
                score[j] -= w * r;
                for (g, a) in g.iter_mut().zip(a) {
                    *g += w * a;
                }
            }
        }
        gradients.push(g);
    }
    let solved: Vec<Vec<f64>> = gradients
        .iter()
        .map(|g| system.solve_factored(g))
        .collect::<Option<_>>()
        .ok_or(SolverError::SolveFailed { what: WHAT })?;
    let mut information = DMatrix::zeros(count, count);
    for j in 0..count {
        for k in j..count {
            let direct: f64 = directions[j]
                .iter()
                .zip(&directions[k])
                .filter_map(|(a, b)| Some(a.as_ref()?.iter().zip(b.as_ref()?).map(|(a, b)| a * b).sum::<f64>()))
                .sum();
            let absorbed: f64 = gradients[j].iter().zip(&solved[k]).map(|(g, x)| g * x).sum();
            information[(j, k)] = direct - absorbed;
            information[(k, j)] = direct - absorbed;
        }
    }
    let norms = directions
        .iter()
        .map(|d| d.iter().flatten().flatten().map(|w| w * w).sum())
        .collect();
    Ok(ScoreSystem {
        information,
        score,
        norms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::{Factor, Values, VariableId, VariableValue};
    use crate::solver::{optimize, LmParams};

    /// A reading `y_k = a + b x_k` of a straight line with standard deviation `sigma`.
    struct LinePoint {
        variables: [VariableId; 1],
        x: f64,
        y: f64,
        noise: crate::graph::Noise,
    }

    impl Factor for LinePoint {
        fn variables(&self) -> &[VariableId] {
            &self.variables
        }
        fn residual_dim(&self) -> usize {
            1
        }
        fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
            let p = values.vector(self.variables[0]);
            if let Some(blocks) = jacobians {
                blocks[0][(0, 0)] = 1.0;
                blocks[0][(0, 1)] = self.x;
            }
            Some(DVector::from_element(1, p[0] + p[1] * self.x - self.y))
        }
        fn noise(&self) -> &crate::graph::Noise {
            &self.noise
        }
        fn kind(&self) -> &'static str {
            "line"
        }
    }

    /// Readings of a parabola fitted by a line: the score test of the term
    /// `c x^2` gives the coefficient and sigma of the quadratic least-squares
    /// fit (normal equations solved independently here), and a term the
    /// line already holds (`x`) is not testable.
    #[test]
    fn score_test_is_the_added_regressor_of_ordinary_least_squares() {
        let xs: Vec<f64> = (0..9).map(|k| k as f64 * 0.5 - 2.0).collect();
        let noise = [0.03, -0.02, 0.05, 0.0, -0.04, 0.01, 0.02, -0.03, 0.04];
        let ys: Vec<f64> = xs
            .iter()
            .zip(noise)
            .map(|(x, e)| 1.0 + 0.5 * x + 0.2 * x * x + e)
            .collect();
        let sigma = 0.1;
        let mut graph = FactorGraph::new();
        let p = graph.values.insert("p", VariableValue::Vector(DVector::zeros(2)));
        for (&x, &y) in xs.iter().zip(&ys) {
            graph.add(LinePoint {
                variables: [p],
                x,
                y,
                noise: crate::graph::Noise::gaussian(DVector::from_element(1, sigma)),
            });
        }
        optimize(&mut graph, &LmParams::default()).unwrap();
        let quadratic: Direction = xs.iter().map(|x| Some(vec![x * x / sigma])).collect();
        let linear: Direction = xs.iter().map(|x| Some(vec![x / sigma])).collect();
        let tests = score_tests(&graph, &[quadratic, linear]).unwrap();
        // Ordinary least squares of y on [1, x, x^2], with weights 1 / sigma^2.
        let design = DMatrix::from_fn(xs.len(), 3, |k, j| xs[k].powi(j as i32) / sigma);
        let rhs = DVector::from_iterator(ys.len(), ys.iter().map(|y| y / sigma));
        let normal = design.transpose() * &design;
        let inverse = normal.clone().try_inverse().unwrap();
        let beta = &inverse * design.transpose() * rhs;
        assert!(
            (tests[0].coefficient - beta[2]).abs() < 1e-9,
            "{:?} vs {}",
            tests[0],
            beta[2]
        );
        assert!((tests[0].sigma - inverse[(2, 2)].sqrt()).abs() < 1e-9);
        assert!((tests[0].z - beta[2] / inverse[(2, 2)].sqrt()).abs() < 1e-6);
        assert!(tests[1].z.is_nan() && tests[1].new_share < 1e-9);
        // Given the quadratic term, the cubic one is the fourth regressor of [1, x, x^2, x^3].
        let cubic: Direction = xs.iter().map(|x| Some(vec![x * x * x / sigma])).collect();
        let quadratic: Direction = xs.iter().map(|x| Some(vec![x * x / sigma])).collect();
        let system = score_system(&graph, &[quadratic, cubic]).unwrap();
        let design = DMatrix::from_fn(xs.len(), 4, |k, j| xs[k].powi(j as i32) / sigma);
        let rhs = DVector::from_iterator(ys.len(), ys.iter().map(|y| y / sigma));
        let inverse = (design.transpose() * &design).try_inverse().unwrap();
        let beta = &inverse * design.transpose() * rhs;
        let given = system.test(1, &[0]);
        assert!((given.coefficient - beta[3]).abs() < 1e-9, "{given:?} vs {}", beta[3]);
        assert!((given.sigma - inverse[(3, 3)].sqrt()).abs() < 1e-9);
        // Both added at once: the last two coefficients of that regression,
        // and the chi-square drop from the line's fit to the cubic's.
        let (joint, drop) = system.joint_fit().unwrap();
        assert!(
            (joint[0] - beta[2]).abs() < 1e-9 && (joint[1] - beta[3]).abs() < 1e-9,
            "{joint:?}"
        );
        let chi_square = |fit: &DVector<f64>, columns: usize| -> f64 {
            xs.iter()
                .zip(&ys)
                .map(|(x, y)| ((0..columns).map(|j| fit[j] * x.powi(j as i32)).sum::<f64>() - y) / sigma)
                .map(|r| r * r)
                .sum()
        };
        let line = graph.values.vector(p).clone();
        assert!(
            (drop - (chi_square(&line, 2) - chi_square(&beta, 4))).abs() < 1e-6,
            "{drop} vs {} - {}",
            chi_square(&line, 2),
            chi_square(&beta, 4)
        );
        // The quadratic term is chosen (z about 14); the cubic one, of noise, is not after it.
        assert_eq!(system.forward_selection(|_| 3.0, 5), vec![0]);
        assert!(system.forward_selection(|_| 3.0, 0).is_empty());
    }
}

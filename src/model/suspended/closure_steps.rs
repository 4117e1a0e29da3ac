//! The steps of [`super::solve_at`]'s iteration on one position's
//! [`Problem`]: the Gauss-Newton corrections that balance the platform, the
//! projected step towards the target, and the Newton step on the closure's
//! first-order conditions (the equilibrium module's docs).

use nalgebra::{DMatrix, DVector};

use super::equilibrium::Problem;

impl Problem<'_> {
    /// The projected step of the module docs and its multipliers `mu` (the
    /// Lagrange multipliers of `e` in `1/2 |x - t|_M^2 + mu^T e`); with
    /// `towards_target` false only its correction, the minimum-`M`-norm
    /// step that balances the linearised equations.
    pub(super) fn step(
        &self,
        x: &DVector<f64>,
        e: &DVector<f64>,
        jacobian: &DMatrix<f64>,
        towards_target: bool,
    ) -> Option<(DVector<f64>, DVector<f64>)> {
        let towards = if towards_target {
            &self.target - x
        } else {
            DVector::zeros(x.len())
        };
        let inverse_metric = self.metric.map(|m| 1.0 / m);
        let weighted = DMatrix::from_fn(jacobian.nrows(), jacobian.ncols(), |r, c| {
            jacobian[(r, c)] * inverse_metric[c]
        });
        let gram = &weighted * jacobian.transpose();
        let multipliers = gram.lu().solve(&(e + jacobian * &towards))?;
        Some((towards - weighted.transpose() * &multipliers, multipliers))
    }

    /// Gauss-Newton corrections (the minimum-norm step that balances the
    /// linearised equations, in the metric `M` where `in_metric`, else in
    /// the unknowns' own units, where a tilt the balance needs is as
    /// available as a tension; halved until the unbalance falls) from `x`
    /// until the platform is balanced to `tolerance`, each taking one of
    /// `budget`; the unbalance left where they stall or run out.
    pub(super) fn restore(
        &self,
        mut x: DVector<f64>,
        mut e: DVector<f64>,
        tolerance: f64,
        in_metric: bool,
        budget: &mut usize,
    ) -> std::result::Result<(DVector<f64>, DVector<f64>), f64> {
        while e.amax() > tolerance {
            if *budget == 0 {
                return Err(e.amax());
            }
            *budget -= 1;
            let correction = self
                .jacobian(&x)
                .and_then(|jacobian| {
                    if in_metric {
                        self.step(&x, &e, &jacobian, false).map(|(correction, _)| correction)
                    } else {
                        let gram = &jacobian * jacobian.transpose();
                        Some(-(jacobian.transpose() * gram.lu().solve(&e)?))
                    }
                })
                .ok_or(e.amax())?;
            let mut scale = 1.0;
            loop {
                let trial = &x + &correction * scale;
                if let Some(trial_e) = self.equations(&trial) {
                    if trial_e.amax() <= (e.amax() * (1.0 - 0.5 * scale)).max(tolerance) {
                        (x, e) = (trial, trial_e);
                        break;
                    }
                }
                scale *= 0.5;
                if scale < 1e-12 {
                    return Err(e.amax());
                }
            }
        }
        Ok((x, e))
    }

    /// Half the squared `M`-distance of `x` from the target.
    pub(super) fn distance(&self, x: &DVector<f64>) -> f64 {
        0.5 * (x - &self.target).component_mul(&(x - &self.target)).dot(&self.metric)
    }

    /// The Hessian of `mu^T e` by second central differences of that scalar
    /// (step `1e-4` of each unknown's scale: truncation and rounding both
    /// near `1e-8` of its entries).
    fn multiplier_curvature(&self, x: &DVector<f64>, mu: &DVector<f64>) -> Option<DMatrix<f64>> {
        let n = x.len();
        let steps = DVector::from_fn(n, |j, _| 1e-4 * x[j].abs().max(1e-2));
        let value = |dj: (usize, f64), dk: (usize, f64)| -> Option<f64> {
            let mut moved = x.clone();
            moved[dj.0] += dj.1 * steps[dj.0];
            moved[dk.0] += dk.1 * steps[dk.0];
            Some(mu.dot(&self.equations(&moved)?))
        };
        let mut hessian = DMatrix::zeros(n, n);
        for j in 0..n {
            for k in j..n {
                let second = value((j, 1.0), (k, 1.0))? - value((j, 1.0), (k, -1.0))? - value((j, -1.0), (k, 1.0))?
                    + value((j, -1.0), (k, -1.0))?;
                hessian[(j, k)] = second / (4.0 * steps[j] * steps[k]);
                hessian[(k, j)] = hessian[(j, k)];
            }
        }
        Some(hessian)
    }

    /// The Newton step on the first-order conditions of the closure
    /// (sequential quadratic programming with the Lagrangian's Hessian
    /// `H = M + sum mu_k d2e_k`): the solution of
    /// `[H J^T; J 0] [dx; mu'] = [-M (x - t); -e]`. The projected step
    /// leaves out the curvature term and so converges only linearly where
    /// the metric is flat (the tensions, the yaw); this one converges
    /// quadratically near the answer. `None` where `H` is not positive on
    /// the step (far from the answer) or the system is singular.
    pub(super) fn newton_step(
        &self,
        x: &DVector<f64>,
        e: &DVector<f64>,
        jacobian: &DMatrix<f64>,
        mu: &DVector<f64>,
    ) -> Option<DVector<f64>> {
        let n = x.len();
        let m = e.len();
        let curvature = self.multiplier_curvature(x, mu)?;
        let mut rhs = DVector::zeros(n + m);
        rhs.rows_mut(0, n)
            .copy_from(&(-(x - &self.target).component_mul(&self.metric)));
        rhs.rows_mut(n, m).copy_from(&(-e));
        let mut hessian = curvature;
        for j in 0..n {
            hessian[(j, j)] += self.metric[j];
        }
        let mut kkt = DMatrix::zeros(n + m, n + m);
        kkt.view_mut((0, 0), (n, n)).copy_from(&hessian);
        kkt.view_mut((0, n), (n, m)).copy_from(&jacobian.transpose());
        kkt.view_mut((n, 0), (m, n)).copy_from(jacobian);
        let solution = kkt.lu().solve(&rhs)?;
        let dx = solution.rows(0, n).into_owned();
        let positive = dx.dot(&(&hessian * &dx)) > 0.0;
        (positive && dx.iter().all(|v| v.is_finite())).then_some(dx)
    }
}

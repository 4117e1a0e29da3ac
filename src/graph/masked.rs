//! A factor with some of its rows left out: the readings a gross-error test
//! removed (`crate::calib::gross_errors`). The rows are dropped, not
//! down-weighted, so the per-type statistics count only the readings used.
//!
//! ```
//! use nalgebra::{DMatrix, DVector};
//! use sagcal::graph::{Factor, FactorGraph, MaskedFactor, Noise, Values, VariableId, VariableValue};
//! /// Two readings of a 2-vector, `z`, with sigma 1 each.
//! struct Readings { variable: [VariableId; 1], z: [f64; 2], noise: Noise }
//! impl Factor for Readings {
//!     fn variables(&self) -> &[VariableId] { &self.variable }
//!     fn residual_dim(&self) -> usize { 2 }
//!     fn evaluate(&self, values: &Values, _: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
//!         let x = values.vector(self.variable[0]);
//!         Some(DVector::from_vec(vec![x[0] - self.z[0], x[1] - self.z[1]]))
//!     }
//!     fn noise(&self) -> &Noise { &self.noise }
//!     fn kind(&self) -> &'static str { "readings" }
//! }
//! let mut values = Values::new();
//! let x = values.insert("x", VariableValue::Vector(DVector::zeros(2)));
//! let readings = || Box::new(Readings { variable: [x], z: [1.0, 40.0], noise: Noise::gaussian(DVector::from_element(2, 1.0)) });
//! // The second reading is a gross error: drop its row, keep the first.
//! let masked = MaskedFactor::new(readings(), &[1]).unwrap();
//! assert_eq!(masked.residual_dim(), 1);
//! assert_eq!(FactorGraph::factor_cost(&masked, &values), Some(0.5)); // only (0 - 1)^2 / 2 is left
//! assert!(MaskedFactor::new(readings(), &[0, 1]).is_none()); // nothing left to say
//! ```

use nalgebra::{DMatrix, DVector};

use super::factor::Factor;
use super::noise::Noise;
use super::values::{Values, VariableId};

/// `inner` without the residual rows `dropped` (indices into its residual).
pub struct MaskedFactor {
    inner: Box<dyn Factor>,
    /// The rows of `inner` that are kept, in order.
    kept: Vec<usize>,
    /// The kept rows' sigmas, under `inner`'s kernel.
    noise: Noise,
}

impl MaskedFactor {
    /// `inner` without the rows `dropped`; `None` when every row is dropped
    /// (the factor then has nothing left to say and is left out whole).
    pub fn new(inner: Box<dyn Factor>, dropped: &[usize]) -> Option<Self> {
        let kept: Vec<usize> = (0..inner.residual_dim()).filter(|r| !dropped.contains(r)).collect();
        if kept.is_empty() {
            return None;
        }
        let sigmas = DVector::from_iterator(kept.len(), kept.iter().map(|&r| inner.sigmas()[r]));
        let noise = Noise::new(sigmas, inner.robust_kernel());
        Some(Self { inner, kept, noise })
    }
}

impl Factor for MaskedFactor {
    fn variables(&self) -> &[VariableId] {
        self.inner.variables()
    }
    fn residual_dim(&self) -> usize {
        self.kept.len()
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        let rows = self.inner.residual_dim();
        let residual = match jacobians {
            None => self.inner.evaluate(values, None)?,
            Some(blocks) => {
                let mut full: Vec<DMatrix<f64>> = blocks.iter().map(|b| DMatrix::zeros(rows, b.ncols())).collect();
                let residual = self.inner.evaluate(values, Some(&mut full))?;
                for (block, full) in blocks.iter_mut().zip(&full) {
                    for (k, &r) in self.kept.iter().enumerate() {
                        block.row_mut(k).copy_from(&full.row(r));
                    }
                }
                residual
            }
        };
        Some(DVector::from_iterator(
            self.kept.len(),
            self.kept.iter().map(|&r| residual[r]),
        ))
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        self.inner.kind()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::VariableValue;

    /// `r = [x0, 2 x0, 3 x0]` on one scalar variable.
    struct Three {
        variables: [VariableId; 1],
        noise: Noise,
    }

    impl Factor for Three {
        fn variables(&self) -> &[VariableId] {
            &self.variables
        }
        fn residual_dim(&self) -> usize {
            3
        }
        fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
            let x = values.vector(self.variables[0])[0];
            if let Some(blocks) = jacobians {
                blocks[0].copy_from(&DMatrix::from_column_slice(3, 1, &[1.0, 2.0, 3.0]));
            }
            Some(DVector::from_column_slice(&[x, 2.0 * x, 3.0 * x]))
        }
        fn noise(&self) -> &Noise {
            &self.noise
        }
        fn kind(&self) -> &'static str {
            "three"
        }
    }

    #[test]
    fn drops_the_rows_and_keeps_the_rest() {
        let mut values = Values::default();
        let x = values.insert("x", VariableValue::Vector(DVector::from_element(1, 2.0)));
        let inner = Box::new(Three {
            variables: [x],
            noise: Noise::gaussian(DVector::from_column_slice(&[0.1, 0.2, 0.3])),
        });
        let masked = MaskedFactor::new(inner, &[1]).unwrap();
        assert_eq!(masked.residual_dim(), 2);
        assert_eq!(masked.sigmas().as_slice(), &[0.1, 0.3]);
        let mut blocks = vec![DMatrix::zeros(2, 1)];
        let r = masked.evaluate(&values, Some(&mut blocks)).unwrap();
        assert_eq!(r.as_slice(), &[2.0, 6.0]);
        assert_eq!(blocks[0].as_slice(), &[1.0, 3.0]);
        let all = Box::new(Three {
            variables: [x],
            noise: Noise::gaussian(DVector::from_element(3, 1.0)),
        });
        assert!(MaskedFactor::new(all, &[0, 1, 2]).is_none());
    }
}

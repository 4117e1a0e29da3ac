//! The extended model's force factor: the load cell's reading with its zero
//! and span errors (`generated::load_cell_residual`, eq. 16 extended) and,
//! for a pose whose place in time and motion is known, its creep with the
//! row and the friction of a pulley before a drum-side load cell
//! ([`crate::model::effects::Effects::time_and_motion`]).
//!
//! The reading is `b + e row + (1 + g)(1 - k s) |T|`: the friction enters as
//! the effective gain error `g' = (1 + g)(1 - k s) - 1` of the generated
//! residual and the creep as the effective bias `b' = b + e row`, so
//! `d r / d g = (1 - k s) d r / d g'`, `d r / d k = -s (1 + g) d r / d g'`
//! and `d r / d e = row d r / d b'`.
//!
//! ```
//! use nalgebra::{DMatrix, DVector};
//! use sagcal::calib::effect_factors::LoadCellFactor;
//! use sagcal::graph::{Factor, RobustKernel, Values, VariableValue};
//! use sagcal::model::measurement::ReadingOrder;
//! let vector = |v: &[f64]| VariableValue::Vector(DVector::from_column_slice(v));
//! let mut values = Values::new();
//! let tension = values.insert("reference tension", vector(&[300.0, 400.0])); // |T| = 500 N
//! let cell = values.insert("load cell", vector(&[2.0, 0.01])); // bias 2 N, gain 1.01
//! let drift = values.insert("load cell drift", vector(&[0.1])); // N per row
//! let friction = values.insert("load cell friction", vector(&[0.02]));
//! // Row 10, the reference cable (cable 1) last reeled in: s = -1.
//! let order = ReadingOrder { row: 10, direction: [-1, 1, 1, 1] };
//! let factor = LoadCellFactor::new(tension, cell, 510.0, 5.0, RobustKernel::None)
//!     .in_time(drift, friction, Some(order), 0);
//! let mut blocks = vec![DMatrix::zeros(1, 2), DMatrix::zeros(1, 2), DMatrix::zeros(1, 1), DMatrix::zeros(1, 1)];
//! let r = factor.evaluate(&values, Some(&mut blocks)).unwrap()[0];
//! // 2 + 0.1 x 10 + 1.01 x 1.02 x 500 - 510 = 8.1 N.
//! assert!((r - 8.1).abs() < 1e-9);
//! // d r / d(bias, gain error) = (1, 1.02 x 500), d r / d drift = 10, d r / d k = 1.01 x 500.
//! assert!((blocks[1][(0, 1)] - 510.0).abs() < 1e-9 && (blocks[2][(0, 0)] - 10.0).abs() < 1e-12);
//! assert!((blocks[3][(0, 0)] - 505.0).abs() < 1e-9);
//! ```

use nalgebra::{DMatrix, DVector, SMatrix};

use super::factors::{tension_argument, EPSILON};
use crate::generated;
use crate::graph::{evaluate_through_into, Factor, Noise, RobustKernel, Values, VariableId};
use crate::model::measurement::ReadingOrder;

/// Force factor with a load-cell model: `bias + (1 + gain_error) |(f_h, f_v)| - f_m`,
/// with creep and friction once placed in time ([`LoadCellFactor::in_time`]).
pub struct LoadCellFactor {
    /// The reference tension, `[bias_n, gain_error]`, and (in time) the creep and the friction.
    variables: Vec<VariableId>,
    measured_tension_n: f64,
    /// The pose's row (0: order unknown) and the reference cable's direction of last motion.
    row: f64,
    direction: f64,
    noise: Noise,
}

impl LoadCellFactor {
    /// A load-cell reading `measured_tension_n` with standard deviation `sigma_n`;
    /// `load_cell` is the `[bias_n, gain_error]` variable.
    pub fn new(
        tension: VariableId,
        load_cell: VariableId,
        measured_tension_n: f64,
        sigma_n: f64,
        kernel: RobustKernel,
    ) -> Self {
        Self {
            variables: vec![tension, load_cell],
            measured_tension_n,
            row: 0.0,
            direction: 0.0,
            noise: Noise::new(DVector::from_element(1, sigma_n), kernel),
        }
    }

    /// The factor with the load cell's creep `drift` (`[e]`, N per row) and
    /// pulley friction `friction` (`[k]`) as two more variables, for a pose at
    /// `order` whose load cell reads `reference_cable` (robot order). Without
    /// an order both act as zero.
    pub fn in_time(
        mut self,
        drift: VariableId,
        friction: VariableId,
        order: Option<ReadingOrder>,
        reference_cable: usize,
    ) -> Self {
        self.variables.truncate(2);
        self.variables.extend([drift, friction]);
        if let Some(order) = order {
            self.row = order.row as f64;
            self.direction = f64::from(order.direction[reference_cable.min(order.direction.len() - 1)]);
        }
        self
    }
}

impl Factor for LoadCellFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        1
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        evaluate_through_into(self, values, jacobians)
    }
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        let tension = tension_argument(values, self.variables[0]);
        let cell = values.vector(self.variables[1]);
        let in_time = self.variables.len() == 4;
        let (drift, friction) = if in_time {
            (values.vector(self.variables[2])[0], values.vector(self.variables[3])[0])
        } else {
            (0.0, 0.0)
        };
        let factor = 1.0 - friction * self.direction;
        let bias = cell[0] + drift * self.row;
        let gain = (1.0 + cell[1]) * factor - 1.0;
        let mut j_tension = SMatrix::<f64, 1, 2>::zeros();
        let mut j_bias = SMatrix::<f64, 1, 1>::zeros();
        let mut j_gain = SMatrix::<f64, 1, 1>::zeros();
        let want = jacobians.is_some();
        let r = generated::load_cell_residual(
            &tension,
            bias,
            gain,
            self.measured_tension_n,
            EPSILON,
            want.then_some(&mut j_tension),
            want.then_some(&mut j_bias),
            want.then_some(&mut j_gain),
        );
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j_tension);
            blocks[1][(0, 0)] = j_bias[(0, 0)];
            blocks[1][(0, 1)] = j_gain[(0, 0)] * factor;
            if in_time {
                blocks[2][(0, 0)] = j_bias[(0, 0)] * self.row;
                blocks[3][(0, 0)] = -j_gain[(0, 0)] * self.direction * (1.0 + cell[1]);
            }
        }
        residual[0] = r[0];
        true
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "reference_tension"
    }
}

//! What every peer returns, and the shared stopping rule.

use nalgebra::DVector;
use sagcal::experiments::benchmark::BenchmarkProblem;
use sagcal::calib::CalibrationGraph;
use sagcal::graph::{Values, VariableValue};
use sagcal::model::pose::PlatformPose;
use sagcal::model::robot::CABLE_COUNT;

/// A solver's solution of the benchmark problem, in sagcal's variables, so
/// that the harness can evaluate sagcal's own cost at it.
#[derive(Debug, Clone)]
pub struct Solution {
    /// Anchors, robot cable order, metres.
    pub anchors_m: [[f64; 3]; 4],
    /// Length offsets, robot cable order, metres.
    pub length_offsets_m: [f64; 4],
    /// Platform poses, one per measurement.
    pub poses: Vec<PlatformPose>,
    /// Reference tensions `(f_h, f_v)`, newtons, one per measurement.
    pub reference_tensions_n: Vec<[f64; 2]>,
}

/// One solve by a peer.
#[derive(Debug, Clone)]
pub struct PeerRun {
    /// The final cost as the peer reports it, converted to sagcal's convention
    /// `sum 1/2 |r / sigma|^2` (e.g. halved if the peer reports `sum |r/sigma|^2`).
    pub reported_final_cost: f64,
    /// Linearisations (outer iterations) the peer made.
    pub iterations: usize,
    /// Wall time of the solve alone (graph construction excluded), seconds.
    pub solve_seconds: f64,
    /// Wall time of building the peer's problem from the benchmark problem, seconds.
    pub setup_seconds: f64,
    /// The solution.
    pub solution: Solution,
}

/// sagcal's values of `built`'s variables at `solution`.
pub fn solution_values(built: &CalibrationGraph, solution: &Solution) -> Values {
    let mut values = built.graph.values.clone();
    for i in 0..CABLE_COUNT {
        values.set(
            built.globals.anchors[i],
            VariableValue::Vector(DVector::from_column_slice(&solution.anchors_m[i])),
        );
        values.set(
            built.globals.length_offsets[i],
            VariableValue::Vector(DVector::from_element(1, solution.length_offsets_m[i])),
        );
    }
    for (k, vars) in built.poses.iter().enumerate() {
        values.set(vars.pose, VariableValue::Pose(solution.poses[k]));
        values.set(
            vars.reference_tension,
            VariableValue::Vector(DVector::from_column_slice(&solution.reference_tensions_n[k])),
        );
    }
    values
}

/// sagcal's own cost `sum 1/2 |r / sigma|^2` of `problem` at `solution`: the
/// independent check that a peer solved the identical problem.
pub fn sagcal_cost_at(problem: &BenchmarkProblem, solution: &Solution) -> Option<f64> {
    let built = problem.graph();
    built.graph.cost(&solution_values(&built, solution))
}

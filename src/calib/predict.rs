//! What a robot with `[effects]` predicts at a pose closed by its position
//! and load-cell reading: the extended model's equilibrium and the encoder
//! readings it implies, so that an extension written by `diagnose --out` can
//! be checked on poses it was never fitted on (`sagcal verify`).
//!
//! The closure is the one of `verify` (paper Table I): the position and the
//! reference cable's tension fix the orientation (3) and the reference
//! tension (2) through the four attachment heights and the load cell
//! (eq. 15-16, extended). It is solved as a one-pose factor graph with the
//! anchors, offsets and effects held, the position prior tight, no
//! orientation prior and the encoders weightless: their residuals are then
//! the predicted readings minus zero.

use nalgebra::Vector3;

use super::graph::build_graph;
use super::options::{CableModel, CalibrationOptions, OrientationPrior};
use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::model::statics::{self, Equilibrium};
use crate::solver::optimize;

/// Sigmas of the closure: the position and load cell exact (to far below
/// any sensor's noise), the encoders weightless.
const CLOSURE_NOISE: SensorNoise = SensorNoise {
    encoder_sigma_m: 1e6,
    load_cell_sigma_n: 1e-4,
    position_sigma_m: 1e-8,
    orientation_sigma_rad: 1.0,
};

/// The extended model's equilibrium at `start`'s position with the load cell
/// reading `load_cell_n`, starting from `start` (the closed-form equilibrium
/// there): the pose, the tensions (eq. 11 with the shifted centre of mass)
/// and, as `cable_lengths_m`, the encoder readings the model predicts
/// (gains and offsets applied).
pub fn predict_with_effects(robot: &Robot, start: &Equilibrium, load_cell_n: f64) -> Result<Equilibrium> {
    let (roll_deg, pitch_deg, yaw_deg) = start.pose.roll_pitch_yaw_deg();
    let measurement = PoseMeasurement {
        line: 0,
        position_m: start.pose.position_m.into(),
        roll_deg,
        pitch_deg,
        yaw_deg,
        encoder_lengths_m: [0.0; CABLE_COUNT],
        reference_tension_n: load_cell_n,
        excluded: Default::default(),
        order: None,
    };
    let options = CalibrationOptions {
        orientation_prior: OrientationPrior::Off,
        ..CalibrationOptions::new(CLOSURE_NOISE)
    };
    let reference = start.tensions[robot.reference_cable];
    let mut built = build_graph(
        robot,
        &[measurement],
        &[start.pose],
        &[reference],
        CableModel::Catenary,
        &options,
    );
    for id in built.globals.anchors.iter().chain(&built.globals.length_offsets) {
        built.graph.values.set_fixed(*id, true);
    }
    let summary = optimize(&mut built.graph, &options.lm)?;
    if !summary.termination.converged() {
        return Err(Error::NoEquilibrium(format!(
            "the extended model has no equilibrium at {:?} with the load cell at {load_cell_n} N ({:?})",
            start.pose.position_m.as_slice(),
            summary.termination
        )));
    }
    let values = &built.graph.values;
    let pose = *values.pose(built.poses[0].pose);
    let t = values.vector(built.poses[0].reference_tension);
    let reference = statics::CableTension {
        horizontal_n: t[0],
        vertical_n: t[1],
    };
    let readings = built
        .graph
        .factors
        .iter()
        .find(|f| f.kind() == "catenary_length")
        .and_then(|f| f.evaluate(values, None))
        .ok_or_else(|| Error::NoEquilibrium("the extended model's cables went slack".into()))?;
    let mut shifted = crate::model::robot::with_true_attachments(robot, &robot.effects);
    shifted.com_offset_m += Vector3::from(robot.effects.com_shift_m);
    Ok(Equilibrium {
        pose,
        tensions: statics::cable_tensions(&shifted, &pose, reference)?,
        cable_lengths_m: std::array::from_fn(|i| readings[i]),
        height_residuals_m: [0.0; CABLE_COUNT],
        iterations: summary.iterations,
    })
}

//! Localisation of a calibrated robot of `N` cables
//! ([`localize_suspended`]): its pose and every cable's forces from the
//! encoder and load-cell readings of one row.
//!
//! The unknowns are the pose and the `2N` forces; the equations are the `N`
//! catenary lengths (eq. 14 with the calibrated offsets), the `N`
//! attachment heights (eq. 15), the six of equilibrium (eq. 5-8) and the `L`
//! load cells (eq. 16): `L` more equations than unknowns, so a row is
//! tested by its chi-square with `L` degrees of freedom. The factors are the
//! calibration's ([`crate::calib::suspended::factors`]) with the anchors and
//! offsets held.
//!
//! The start: the straight-cable position of the readings (trilateration,
//! Gauss-Newton on `||a_i - (p + b_i)|| = z_i - l0_i` with the platform
//! level), then the equilibrium [`solve_at`] finds there, then
//! Levenberg-Marquardt on the whole row.
//!
//! ```
//! use sagcal::localize::suspended::localize_suspended;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedMeasurement, SuspendedRobot};
//! use nalgebra::Vector3;
//! let robot = SuspendedRobot::builtin("six")?;
//! let truth = solve_at(&robot, Vector3::new(3.0, -2.0, 12.0), Closure::Level, &EquilibriumOptions::default())?;
//! let (roll_deg, pitch_deg, yaw_deg) = (0.0, 0.0, 0.0); // the localiser is not read
//! let row = SuspendedMeasurement {
//!     line: 0,
//!     position_m: [0.0; 3],
//!     roll_deg,
//!     pitch_deg,
//!     yaw_deg,
//!     encoder_lengths_m: truth.cable_lengths_m.clone(),
//!     load_cell_tensions_n: vec![truth.tensions[0].magnitude_n()],
//! };
//! let found = localize_suspended(&robot, &row, &NoisePreset::Paper.sigmas(robot.platform_weight_n), 1e-3)?;
//! assert!((found.pose.position_m - truth.pose.position_m).norm() < 1e-9);
//! assert!(found.consistent && found.stable);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{DVector, Matrix3, Vector3};
use serde::Serialize;

use crate::calib::suspended::factors::{
    CableConstants, CableLoadCellFactor, CableRow, CableVariables, CatenaryCableFactor, EquilibriumFactor,
};
use crate::calib::suspended::{chord_shares, EQUILIBRIUM_SIGMA_PER_WEIGHT};
use crate::error::{Error, Result};
use crate::graph::{FactorGraph, RobustKernel, VariableId, VariableValue};
use crate::model::pose::PlatformPose;
use crate::model::sensors::SensorNoise;
use crate::model::statics::CableTension;
use crate::model::suspended::{
    smallest_stiffness, solve_at, stiffness, Closure, EquilibriumOptions, SuspendedEquilibrium, SuspendedMeasurement,
    SuspendedRobot,
};
use crate::solver::{marginal_covariance, optimize, Covariance, LmParams};
use crate::stats::chi_square_critical;

/// The attachment-height constraint's sigma, metres (as in calibration).
const HEIGHT_SIGMA_M: f64 = 1e-4;

/// One row localised.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuspendedLocalization {
    /// The platform's pose.
    #[serde(skip)]
    pub pose: PlatformPose,
    /// Every cable's `(f_h, f_v)` at its attachment, newtons.
    #[serde(skip)]
    pub forces: Vec<CableTension>,
    /// 1-sigma of the position per axis from the reading noise, metres.
    pub position_sigma_m: [f64; 3],
    /// The position's 3 x 3 covariance from the reading noise, m^2
    /// (`None` where the readings leave it undetermined).
    #[serde(skip)]
    pub position_covariance_m2: Option<[[f64; 3]; 3]>,
    /// The row's chi-square, `sum (r / sigma)^2`.
    pub chi_square: f64,
    /// Its degrees of freedom: the number of load cells.
    pub degrees_of_freedom: usize,
    /// Whether the chi-square is within its critical value at the false-alarm rate.
    pub consistent: bool,
    /// Whether the equilibrium is stable at fixed cable lengths.
    pub stable: bool,
    /// Solver iterations.
    pub iterations: usize,
}

/// Localise `row`'s encoder and load-cell readings (its localiser columns
/// are not read) on the calibrated `robot`, the readings weighed by
/// `noise`, the row tested at `false_alarm`.
pub fn localize_suspended(
    robot: &SuspendedRobot,
    row: &SuspendedMeasurement,
    noise: &SensorNoise,
    false_alarm: f64,
) -> Result<SuspendedLocalization> {
    let lengths: Vec<f64> = row
        .encoder_lengths_m
        .iter()
        .zip(&robot.length_offsets_m)
        .map(|(z, offset)| z - offset)
        .collect();
    let position = straight_position(robot, &lengths)?;
    let (pose, forces) = match solve_at(robot, position, Closure::Level, &EquilibriumOptions::default()) {
        Ok(eq) => (eq.pose, eq.tensions),
        Err(_) => {
            let level = PlatformPose::from_position(position);
            (level, chord_shares(robot, &level))
        }
    };
    let (mut graph, pose_id, force_ids) = row_graph(robot, row, noise, &pose, &forces);
    let params = LmParams {
        local_refinement: false,
        ..LmParams::default()
    };
    let summary = optimize(&mut graph, &params)?;
    if !summary.termination.converged() {
        return Err(Error::NoEquilibrium(format!(
            "no equilibrium of robot `{}` explains the readings ({})",
            robot.name, summary.termination
        )));
    }
    let pose = *graph.values.pose(pose_id);
    let forces: Vec<CableTension> = force_ids
        .iter()
        .map(|&id| {
            let f = graph.values.vector(id);
            CableTension {
                horizontal_n: f[0],
                vertical_n: f[1],
            }
        })
        .collect();
    // The pose's tangent is [rotation (3); position (3)].
    let position_covariance_m2 = match marginal_covariance(&graph, &[pose_id])? {
        Covariance::Full(c) => Some([3, 4, 5].map(|i| [3, 4, 5].map(|j| c[(i, j)]))),
        Covariance::RankDeficient(_) => None,
    };
    let position_sigma_m =
        position_covariance_m2.map_or([f64::INFINITY; 3], |c| [0, 1, 2].map(|k| c[k][k].max(0.0).sqrt()));
    let chi_square = 2.0 * summary.final_cost;
    let degrees_of_freedom = robot.load_cells.len();
    // The model's own lengths at the solution (the readings' noise aside).
    let equilibrium = SuspendedEquilibrium {
        pose,
        cable_lengths_m: robot.catenaries(&pose, &forces).iter().map(|c| c.length_m()).collect(),
        height_residuals_m: robot.height_residuals(&pose, &forces),
        tensions: forces.clone(),
        iterations: summary.iterations,
    };
    let stable = stiffness(robot, &equilibrium).is_some_and(|k| smallest_stiffness(&k) > 0.0);
    Ok(SuspendedLocalization {
        pose,
        forces,
        position_sigma_m,
        position_covariance_m2,
        chi_square,
        degrees_of_freedom,
        consistent: chi_square <= chi_square_critical(degrees_of_freedom.max(1), false_alarm),
        stable,
        iterations: summary.iterations,
    })
}

/// The position of a level platform whose straight cables have `lengths_m`:
/// Gauss-Newton on `||a_i - (p + b_i)|| - l_i` (a textbook trilateration),
/// from below the anchors' centroid; fails where it does not converge.
fn straight_position(robot: &SuspendedRobot, lengths_m: &[f64]) -> Result<Vector3<f64>> {
    let n = robot.cable_count() as f64;
    let centroid = robot.anchors_m.iter().sum::<Vector3<f64>>() / n;
    let mean_length = lengths_m.iter().sum::<f64>() / n;
    let mut p = centroid - Vector3::new(0.0, 0.0, 0.5 * mean_length);
    let cost = |p: &Vector3<f64>| -> f64 {
        (0..robot.cable_count())
            .map(|i| ((robot.anchors_m[i] - p - robot.attachments_m[i]).norm() - lengths_m[i]).powi(2))
            .sum()
    };
    for _ in 0..100 {
        let mut normal = Matrix3::zeros();
        let mut gradient = Vector3::zeros();
        for ((anchor, attachment), length) in robot.anchors_m.iter().zip(&robot.attachments_m).zip(lengths_m) {
            let chord = anchor - p - attachment;
            let distance = chord.norm();
            // d||a - p - b|| / dp = -(a - p - b) / ||a - p - b||.
            let row = -chord / distance.max(1e-12);
            let residual = distance - length;
            normal += row * row.transpose();
            gradient += row * residual;
        }
        let Some(step) = (normal + Matrix3::identity() * 1e-9).lu().solve(&(-gradient)) else {
            break;
        };
        let mut scale = 1.0;
        let before = cost(&p);
        while scale > 1e-6 && cost(&(p + step * scale)) > before {
            scale /= 2.0;
        }
        p += step * scale;
        if (step * scale).norm() < 1e-10 {
            return Ok(p);
        }
    }
    if p.iter().all(|v| v.is_finite()) {
        Ok(p)
    } else {
        Err(Error::NoEquilibrium(format!(
            "robot `{}`: no position of straight cables has the lengths read",
            robot.name
        )))
    }
}

/// The graph of one row: the anchors and offsets held, the pose and forces
/// from `pose` and `forces`.
fn row_graph(
    robot: &SuspendedRobot,
    row: &SuspendedMeasurement,
    noise: &SensorNoise,
    pose: &PlatformPose,
    forces: &[CableTension],
) -> (FactorGraph, VariableId, Vec<VariableId>) {
    let mut graph = FactorGraph::new();
    let vector = |v: &[f64]| VariableValue::Vector(DVector::from_column_slice(v));
    let n = robot.cable_count();
    let pose_id = graph.values.insert("pose", VariableValue::Pose(*pose));
    let force_ids: Vec<VariableId> = forces
        .iter()
        .enumerate()
        .map(|(i, t)| {
            graph
                .values
                .insert(format!("forces {}", i + 1), vector(&[t.horizontal_n, t.vertical_n]))
        })
        .collect();
    let mut anchors = Vec::with_capacity(n);
    for (i, &forces) in force_ids.iter().enumerate() {
        let anchor = graph
            .values
            .insert(format!("anchor {}", i + 1), vector(robot.anchors_m[i].as_slice()));
        let offset = graph
            .values
            .insert(format!("length offset {}", i + 1), vector(&[robot.length_offsets_m[i]]));
        graph.values.set_fixed(anchor, true);
        graph.values.set_fixed(offset, true);
        anchors.push(anchor);
        let variables = CableVariables {
            pose: pose_id,
            forces,
            anchor,
            length_offset: offset,
        };
        let constants = CableConstants::of(robot, i);
        for (cable_row, sigma_m) in [
            (CableRow::Length, noise.encoder_sigma_m),
            (CableRow::Height, HEIGHT_SIGMA_M),
        ] {
            graph.add(CatenaryCableFactor::new(
                variables,
                constants,
                row.encoder_lengths_m[i],
                cable_row,
                sigma_m,
                RobustKernel::None,
            ));
        }
    }
    graph.add(EquilibriumFactor::new(
        pose_id,
        &force_ids,
        &anchors,
        &robot.attachments_m,
        robot.com_offset_m,
        robot.platform_weight_n,
        EQUILIBRIUM_SIGMA_PER_WEIGHT * robot.platform_weight_n,
        robot.attachment_radius_m(),
    ));
    for (&cable, &reading) in robot.load_cells.iter().zip(&row.load_cell_tensions_n) {
        graph.add(CableLoadCellFactor::new(
            force_ids[cable],
            reading,
            noise.load_cell_sigma_n,
            RobustKernel::None,
        ));
    }
    (graph, pose_id, force_ids)
}

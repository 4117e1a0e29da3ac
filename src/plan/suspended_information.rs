//! Each candidate pose's Fisher information about the anchors and offsets
//! of a robot of `N` cables ([`suspended_pose_information`]): the
//! calibration graph of `N` cables ([`build_suspended_graph`]) of that one
//! pose at the nominal robot, noise-free readings, its pose and its cables'
//! forces eliminated exactly (the Schur complement), as
//! [`super::information::pose_information`] does for four cables. The
//! global parameters are the anchors' `3N` coordinates (cable order) then
//! the `N` offsets, so the plan's design, bound and random sets take these
//! terms as they take the four-cable ones.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedRobot};
//! use sagcal::plan::suspended_information::suspended_pose_information;
//! let six = SuspendedRobot::builtin("six")?;
//! let eq = solve_at(&six, Vector3::new(1.0, -2.0, 12.0), Closure::Level, &EquilibriumOptions::default())?;
//! let options = CalibrationOptions::new(NoisePreset::Paper.sigmas(six.platform_weight_n));
//! let information = suspended_pose_information(&six, &eq, &options)?;
//! // 18 anchor coordinates and 6 offsets. One pose gives 6 encoders, 1 load
//! // cell and 3 localiser coordinates (no orientation prior), with 6 heights
//! // and 6 equations of equilibrium: 22 rows, less the pose's 6 and the
//! // forces' 12 unknowns, leave 4 directions of the globals determined.
//! assert_eq!((information.dim(), information.cables), (24, 6));
//! assert_eq!(information.rank(), 4);
//! # Ok::<(), sagcal::Error>(())
//! ```

use rayon::prelude::*;

use super::information::{graph_information, PoseInformation};
use crate::calib::suspended::{build_suspended_graph, Exclusions, PoseStart, SuspendedStage};
use crate::calib::{CalibrationOptions, OrientationPrior, RobustKernels};
use crate::error::Result;
use crate::model::suspended::{SuspendedEquilibrium, SuspendedMeasurement, SuspendedRobot};

/// What `robot`'s sensors would read, without noise, at `equilibrium`: the
/// drums' paid-out lengths ([`SuspendedEquilibrium::paid_out_lengths_m`])
/// plus the offsets, each load cell's tension, the pose.
pub fn noise_free_suspended_reading(
    robot: &SuspendedRobot,
    equilibrium: &SuspendedEquilibrium,
) -> SuspendedMeasurement {
    let (roll_deg, pitch_deg, yaw_deg) = equilibrium.pose.roll_pitch_yaw_deg();
    SuspendedMeasurement {
        line: 0,
        position_m: equilibrium.pose.position_m.into(),
        roll_deg,
        pitch_deg,
        yaw_deg,
        encoder_lengths_m: equilibrium
            .paid_out_lengths_m(robot)
            .iter()
            .zip(&robot.length_offsets_m)
            .map(|(l, o)| l + o)
            .collect(),
        load_cell_tensions_n: robot
            .load_cells
            .iter()
            .map(|&c| equilibrium.tensions[c].magnitude_n())
            .collect(),
    }
}

/// The information one pose at `equilibrium` gives about `robot`'s anchors
/// and offsets (module docs), with the factors' noise of `options` and the
/// localiser's orientation as a prior where `options.orientation_prior` is
/// `On`.
pub fn suspended_pose_information(
    robot: &SuspendedRobot,
    equilibrium: &SuspendedEquilibrium,
    options: &CalibrationOptions,
) -> Result<PoseInformation> {
    let plain = CalibrationOptions {
        robust: RobustKernels::default(),
        ..*options
    };
    let reading = noise_free_suspended_reading(robot, equilibrium);
    let start = PoseStart {
        pose: equilibrium.pose,
        forces: equilibrium.tensions.clone(),
    };
    let built = build_suspended_graph(
        robot,
        std::slice::from_ref(&reading),
        std::slice::from_ref(&start),
        SuspendedStage::Catenary,
        &plain,
        options.orientation_prior == OrientationPrior::On,
        &Exclusions::new(),
    );
    let pose = &built.poses[0];
    let locals: Vec<_> = std::iter::once(pose.pose).chain(pose.forces.iter().copied()).collect();
    graph_information(&built.graph, &locals, robot.cable_count(), &reading.position_m)
}

/// [`suspended_pose_information`] of every candidate, in parallel.
pub fn suspended_candidate_information(
    nominal: &SuspendedRobot,
    candidates: &[SuspendedEquilibrium],
    options: &CalibrationOptions,
) -> Result<Vec<PoseInformation>> {
    candidates
        .par_iter()
        .map(|eq| suspended_pose_information(nominal, eq, options))
        .collect()
}

//! Where the catenary graph of `N` cables starts: every pose's equilibrium
//! at its measured position for the anchors of the straight-cable stage,
//! and the length offsets in closed form.

use super::graph::PoseStart;
use crate::model::catenary::Catenary;
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;
use crate::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedMeasurement, SuspendedRobot};

/// Each pose's start for `robot`: the equilibrium [`solve_at`] finds at the
/// measured position (its yaw held at the localiser's from four cables on,
/// the one equilibrium of three); where there is none, the measured pose
/// with every cable carrying an even share of the weight along its chord
/// (the paper's eq. 17-18 for `N` cables). The second element lists the
/// poses that fell back.
pub fn catenary_starts(robot: &SuspendedRobot, measurements: &[SuspendedMeasurement]) -> (Vec<PoseStart>, Vec<usize>) {
    let options = EquilibriumOptions::default();
    let mut fell_back = Vec::new();
    let starts = measurements
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let measured = m.localiser_pose();
            let closure = if robot.cable_count() > 3 {
                Closure::Yaw {
                    yaw_rad: measured.yaw_rad(),
                }
            } else {
                Closure::Level
            };
            match solve_at(robot, measured.position_m, closure, &options) {
                Ok(eq) => PoseStart {
                    pose: eq.pose,
                    forces: eq.tensions,
                },
                Err(_) => {
                    fell_back.push(k);
                    PoseStart {
                        pose: measured,
                        forces: chord_shares(robot, &measured),
                    }
                }
            }
        })
        .collect();
    (starts, fell_back)
}

/// Every cable with `f_v = m_e g / N` and `f_h = f_v / tan(alpha)`, alpha
/// its chord's elevation (the paper's eq. 17-18 with `N` cables).
pub fn chord_shares(robot: &SuspendedRobot, pose: &PlatformPose) -> Vec<CableTension> {
    let vertical_n = robot.platform_weight_n / robot.cable_count() as f64;
    let rotation = pose.rotation_matrix();
    (0..robot.cable_count())
        .map(|i| {
            let chord = robot.anchors_m[i] - (pose.position_m + rotation * robot.attachments_m[i]);
            let alpha = chord.z.atan2(chord.xy().norm()).max(1e-3);
            CableTension {
                horizontal_n: vertical_n / alpha.tan(),
                vertical_n,
            }
        })
        .collect()
}

/// The length offsets that make the mean length residual of every cable
/// zero at `starts`: `l0_i = mean_k (z_enc,ik - l_C,ik)` (eq. 14 solved for
/// its one linear unknown).
pub fn offsets_in_closed_form(
    robot: &SuspendedRobot,
    measurements: &[SuspendedMeasurement],
    starts: &[PoseStart],
) -> Vec<f64> {
    let mut sums = vec![0.0; robot.cable_count()];
    for (m, start) in measurements.iter().zip(starts) {
        let catenaries: Vec<Catenary> = robot.catenaries(&start.pose, &start.forces);
        for (i, catenary) in catenaries.iter().enumerate() {
            sums[i] += m.encoder_lengths_m[i] - catenary.length_m();
        }
    }
    sums.iter().map(|s| s / measurements.len().max(1) as f64).collect()
}

/// The straight stage's offsets: `l0_i = mean_k (z_enc,ik - ||a_i - (p_k + R_k b_i)||)`
/// at the measured poses.
pub fn straight_offsets(robot: &SuspendedRobot, measurements: &[SuspendedMeasurement]) -> Vec<f64> {
    let mut sums = vec![0.0; robot.cable_count()];
    for m in measurements {
        let pose = m.localiser_pose();
        let rotation = pose.rotation_matrix();
        for (i, sum) in sums.iter_mut().enumerate() {
            let chord = robot.anchors_m[i] - (pose.position_m + rotation * robot.attachments_m[i]);
            *sum += m.encoder_lengths_m[i] - chord.norm();
        }
    }
    sums.iter().map(|s| s / measurements.len().max(1) as f64).collect()
}

//! The robot's geometry and masses. Files are read and validated into a
//! [`Robot`] by `io::robot_file`; the physics never sees a file.
//!
//! ```
//! use sagcal::model::robot::{Robot, CALIBRATED_PARAMETERS};
//! let robot = Robot::builtin("large")?;
//! // Its cable is an aramid rope of 4 mm radius at 1440 kg/m^3: g_c = pi r^2 rho g.
//! let g_c = std::f64::consts::PI * 0.004f64.powi(2) * 1440.0 * 9.81;
//! assert!((robot.cable_weight_n_per_m - g_c).abs() < 1e-12);
//! assert!((robot.platform_weight_n - 34.0 * 9.81).abs() < 1e-9); // a 34 kg platform
//! // Robot files count cables from 1, the robot from 0: the load cell is on cable 1.
//! assert_eq!(robot.reference_cable, 0);
//! // Calibrated: 4 anchors of 3 coordinates and 4 encoder offsets.
//! assert_eq!(CALIBRATED_PARAMETERS, 4 * 3 + 4);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{SMatrix, Vector3};
use serde::{Deserialize, Serialize};

pub use crate::model::cables::CABLE_COUNT;
use crate::model::effects::Effects;

/// Number of calibrated parameters: the anchors' 12 coordinates, then the 4
/// encoder length offsets.
pub const CALIBRATED_PARAMETERS: usize = 3 * CABLE_COUNT + CABLE_COUNT;

/// Covariance of the calibrated parameters, m^2, in the order
/// `[a1x, a1y, a1z, ..., a4z, l1^0, ..., l4^0]` (cable order).
pub type ParameterCovariance = SMatrix<f64, CALIBRATED_PARAMETERS, CALIBRATED_PARAMETERS>;

/// A suspended 4-cable robot (paper Sec. III-A).
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    /// Human-readable name.
    pub name: String,
    /// Anchors `p_a,i` (pulley exit points), world frame, metres.
    pub anchors_m: [Vector3<f64>; CABLE_COUNT],
    /// Attachment points `p_b,i`, platform frame, metres.
    pub attachments_m: [Vector3<f64>; CABLE_COUNT],
    /// Centre of mass `b_com` in the platform frame, metres.
    pub com_offset_m: Vector3<f64>,
    /// Platform weight `m_e g`, newtons.
    pub platform_weight_n: f64,
    /// Cable weight per metre `g_c = rho_c g`, newtons per metre.
    pub cable_weight_n_per_m: f64,
    /// 0-based index of the reference cable (the one with the load cell).
    pub reference_cable: usize,
    /// Encoder length offsets `l_i^0`, metres (zero for a nominal robot).
    pub length_offsets_m: [f64; CABLE_COUNT],
    /// The box of platform positions calibration poses are drawn from, if the
    /// robot file gives one.
    pub workspace: Option<Workspace>,
    /// Effects known to act on this robot beyond the closed-form model (the
    /// robot file's optional `[effects]`, written by `simulate --truth` and
    /// `diagnose --out`; the calibration holds them fixed unless it estimates
    /// them). Default: none.
    pub effects: Effects,
    /// Which of the paper's robots this is, if the robot file says so (its
    /// optional `paper_robot`); only used to print the paper's numbers beside sagcal's.
    pub paper_robot: Option<PaperRobot>,
    /// The marginal covariance of the anchors and offsets from the
    /// calibration that produced them (the robot file's optional
    /// `[calibration]`, written by `calibrate --out`); `None` for a nominal
    /// robot. `localize` propagates it into its pose uncertainty.
    pub calibration_covariance_m2: Option<ParameterCovariance>,
}

/// The two robots of the paper's Sec. V (Table I): a robot file names one with
/// `paper_robot = "large"` or `"small"`; a robot without it is none of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PaperRobot {
    /// The large-scale robot (240 x 220 x 50 m, 34 kg; `robots/large.toml`).
    Large,
    /// The small-scale robot (12.5 x 4.5 x 28.5 m, 4.4 kg; `robots/small.toml`).
    Small,
}

impl PaperRobot {
    /// The name used in robot files and reports: `large` or `small`.
    pub fn name(self) -> &'static str {
        match self {
            PaperRobot::Large => "large",
            PaperRobot::Small => "small",
        }
    }
}

/// An axis-aligned box of platform positions, world frame, metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Workspace {
    /// Lower corner.
    pub min_m: [f64; 3],
    /// Upper corner.
    pub max_m: [f64; 3],
}

impl Workspace {
    /// The centre of the box, world frame, metres.
    pub fn centre(&self) -> Vector3<f64> {
        (Vector3::from(self.min_m) + Vector3::from(self.max_m)) * 0.5
    }
}

impl std::fmt::Display for Workspace {
    /// `[-6, -4, 2] .. [6, 4, 9] m`: the corners, each coordinate to 0.1 mm
    /// (without the binary noise of a computed bound, `29.700000000000003`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let corner = |p: &[f64; 3]| -> String {
            let parts: Vec<String> = p.iter().map(|x| short_metres(*x)).collect();
            format!("[{}]", parts.join(", "))
        };
        write!(f, "{} .. {} m", corner(&self.min_m), corner(&self.max_m))
    }
}

/// `x` metres to 0.1 mm, without trailing zeros: `-29.7`, `0.96`, `6`.
fn short_metres(x: f64) -> String {
    let text = format!("{x:.4}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    match text {
        "-0" => "0".to_string(),
        other => other.to_string(),
    }
}

/// `robot` with its attachment points where `effects` puts them: each moved
/// horizontally by `effects.attachment_shift_m` (`attachments`), platform frame.
pub fn with_true_attachments(robot: &Robot, effects: &Effects) -> Robot {
    let mut true_robot = robot.clone();
    for (attachment, [dx, dy]) in true_robot.attachments_m.iter_mut().zip(effects.attachment_shift_m) {
        attachment.x += dx;
        attachment.y += dy;
    }
    true_robot
}

/// `robot` as it truly is under `effects`' weight errors: the platform's
/// weight and the cables' weight per metre times their scales
/// (`platform-weight`, `cable-weight`).
pub fn with_true_weights(robot: &Robot, effects: &Effects) -> Robot {
    let mut true_robot = robot.clone();
    true_robot.platform_weight_n *= effects.platform_weight_scale;
    true_robot.cable_weight_n_per_m *= effects.cable_weight_scale;
    true_robot
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_workspace_prints_its_corners_without_binary_noise() {
        let computed = Workspace {
            min_m: [-30.0, -0.3 * 99.0, 0.96],
            max_m: [30.0, 29.700000000000003, 27.839999999999996],
        };
        assert_eq!(computed.to_string(), "[-30, -29.7, 0.96] .. [30, 29.7, 27.84] m");
        let small = Workspace {
            min_m: [-0.00001, 0.00005, 1.23456],
            max_m: [f64::NAN, f64::INFINITY, 2.0],
        };
        assert_eq!(small.to_string(), "[0, 0.0001, 1.2346] .. [NaN, inf, 2] m");
    }
}

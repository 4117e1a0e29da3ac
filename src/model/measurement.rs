//! One static pose's measurements: what the robot's own sensors read there.

use serde::{Deserialize, Serialize};

/// One static pose: localiser pose, encoder readings and load-cell tension.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseMeasurement {
    /// 1-based line in the file it was read from (comments and blank lines
    /// counted, the header of a comment-free file is line 1); 0 for in-memory data.
    pub line: usize,
    /// Localiser position of the platform frame origin in the world frame, metres.
    pub position_m: [f64; 3],
    /// Roll angle (rotation about x, applied first), degrees.
    pub roll_deg: f64,
    /// Pitch angle (rotation about y), degrees.
    pub pitch_deg: f64,
    /// Yaw angle (rotation about z, applied last), degrees: `R = Rz(yaw) Ry(pitch) Rx(roll)`.
    pub yaw_deg: f64,
    /// Encoder readings of cables 1..4, metres: true cable length plus an
    /// unknown per-cable offset (any finite value).
    pub encoder_lengths_m: [f64; 4],
    /// Load-cell tension of the reference cable at the platform attachment, newtons (positive).
    pub reference_tension_n: f64,
}

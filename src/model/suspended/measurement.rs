//! What a robot of `N` cables measures at one static pose
//! ([`SuspendedMeasurement`]): the four-cable row
//! ([`crate::model::PoseMeasurement`]) with `N` encoders and a tension for
//! each load cell.

/// One static pose's readings on a robot of `N` cables.
#[derive(Debug, Clone, PartialEq)]
pub struct SuspendedMeasurement {
    /// The row's line in its file (from 1, header and comments counted); 0
    /// for a row that was not read from a file.
    pub line: usize,
    /// Localiser position of the platform frame's origin, world frame, metres.
    pub position_m: [f64; 3],
    /// Localiser roll, degrees (`R = Rz(yaw) Ry(pitch) Rx(roll)`).
    pub roll_deg: f64,
    /// Localiser pitch, degrees.
    pub pitch_deg: f64,
    /// Localiser yaw, degrees.
    pub yaw_deg: f64,
    /// Each cable's encoder reading (catenary length plus the cable's
    /// unknown offset, paper eq. 14), metres, in cable order.
    pub encoder_lengths_m: Vec<f64>,
    /// Each load cell's tension at its attachment, newtons, in the order of
    /// the robot's `load_cells`.
    pub load_cell_tensions_n: Vec<f64>,
}

impl SuspendedMeasurement {
    /// The localiser's pose: its position and `R = Rz(yaw) Ry(pitch) Rx(roll)`.
    pub fn localiser_pose(&self) -> crate::model::pose::PlatformPose {
        crate::model::pose::PlatformPose::from_roll_pitch_yaw_deg(
            self.position_m.into(),
            self.roll_deg,
            self.pitch_deg,
            self.yaw_deg,
        )
    }
}

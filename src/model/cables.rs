//! How many cables the modelled robot has: a leaf that the robot, its
//! effects and everything above share (re-exported as
//! [`crate::model::robot::CABLE_COUNT`]).

/// Number of cables of the suspended robot modelled by sagcal.
pub const CABLE_COUNT: usize = 4;

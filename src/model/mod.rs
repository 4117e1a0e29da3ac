//! Cable physics and the robot's kineto-statics (paper Sec. III).

pub mod catenary;
pub mod effect_ranges;
pub mod effects;
pub mod measurement;
pub mod pose;
pub mod robot;
pub mod sensors;
pub mod statics;

pub use catenary::Catenary;
pub use effects::Effects;
pub use measurement::PoseMeasurement;
pub use pose::PlatformPose;
pub use robot::{Robot, CABLE_COUNT};

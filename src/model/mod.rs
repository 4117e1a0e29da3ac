//! Cable physics and the robot's kineto-statics (paper Sec. III): the
//! catenary of one heavy cable (eq. 1-4, [`catenary`]), the robot and its
//! parameters ([`robot`]), the statics that balance the four cables against
//! gravity (eq. 5-11, [`statics`]), the effects the paper's model lacks
//! ([`effects`]), the sensors and their noise ([`sensors`]) and one pose's
//! measurements ([`measurement`]) and how reports name a row of data
//! ([`data_row`]); the geometry a suspended robot needs
//! ([`geometry`]) and the magnitudes no real robot falls outside
//! ([`plausibility`]); the typical magnitudes of each effect
//! ([`effect_ranges`]) and the largest any real robot could show
//! ([`effect_limits`]); the statics of a platform on any number of cables,
//! three to eight and more ([`suspended`]). No file format is seen here.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::model::statics::{solve_with_reference_tension, StaticsOptions};
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! // Where the platform hangs at (5, -3, 12) m when the reference cable pulls 700 N.
//! let eq = solve_with_reference_tension(&robot, Vector3::new(5.0, -3.0, 12.0), 700.0, None, &StaticsOptions::default())?;
//! let reference = eq.tensions[robot.reference_cable];
//! assert!((reference.magnitude_n() - 700.0).abs() < 1e-6);
//! // Every cable pulls, and each hangs longer than the straight line to its anchor.
//! for (i, t) in eq.tensions.iter().enumerate() {
//!     assert!(t.is_taut());
//!     let attachment = eq.pose.position_m + eq.pose.rotation * robot.attachments_m[i];
//!     assert!(eq.cable_lengths_m[i] > (robot.anchors_m[i] - attachment).norm());
//! }
//! # Ok::<(), sagcal::Error>(())
//! ```

mod cables;
pub mod catenary;
pub mod data_row;
pub mod effect_kind;
pub mod effect_limits;
pub mod effect_ranges;
pub mod effect_specs;
pub mod effects;
pub mod geometry;
pub mod measurement;
pub mod plausibility;
pub mod pose;
pub mod robot;
pub mod sensors;
pub mod statics;
pub mod suspended;

pub use catenary::Catenary;
pub use data_row::DataRow;
pub use effects::Effects;
pub use measurement::PoseMeasurement;
pub use pose::PlatformPose;
pub use robot::{Robot, CABLE_COUNT};

//! Files: robot descriptions and measurement logs. The lowest layer: it knows
//! formats and validation of single values, no physics.

pub mod atomic;
pub mod authors;
pub mod measurements;
pub mod readings;
pub mod recurdyn;
pub mod robot_file;

pub use atomic::write_atomically;

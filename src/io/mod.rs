//! Files: robot descriptions and measurement logs. The lowest layer: it knows
//! formats and validation of single values, no physics.
//!
//! - [`robot_file`]: the robot description (TOML);
//! - [`suspended_file`]: a robot of 3 to 8 cables, per-cable weights and load cells;
//!   [`suspended_measurements`]: its measurement file;
//! - [`robot_init`]: a new, commented robot file from a few numbers (`sagcal init`);
//! - [`measurements`]: what `calibrate`, `diagnose` and `verify` read: sagcal's
//!   CSV, a RecurDyn log ([`recurdyn`]) or the authors' dataset folder
//!   ([`authors`]), told apart by the header or by being a folder;
//! - [`readings`]: what `localize` reads (cable readings alone, or any of the above);
//! - [`atomic`]: a single file written whole or not at all ([`write_atomically`]);
//! - [`outputs`]: every file of one command written together, all or none,
//!   never over one of the command's inputs ([`OutputSet`]).
//!
//! Errors name the file, the line and the column ([`crate::Error::Field`]).
//!
//! ```
//! use sagcal::io::measurements::{read_measurements, write_measurements, ReadOptions};
//! use sagcal::model::PoseMeasurement;
//! let pose = PoseMeasurement {
//!     line: 0,
//!     position_m: [1.5, -2.0, 12.0],
//!     roll_deg: 0.1,
//!     pitch_deg: -0.2,
//!     yaw_deg: 0.3,
//!     encoder_lengths_m: [183.3, 169.2, 155.6, 170.9],
//!     reference_tension_n: 698.7,
//!     excluded: Default::default(),
//!     order: None,
//! };
//! let path = std::env::temp_dir().join(format!("sagcal-io-doc-{}.csv", std::process::id()));
//! write_measurements(&path, &["written by the io docs".into()], &[pose])?;
//! let set = read_measurements(&path, &ReadOptions::default())?;
//! assert_eq!(set.poses[0].encoder_lengths_m, pose.encoder_lengths_m);
//! assert_eq!(set.poses[0].line, 3, "a comment, the header, then the row");
//! # std::fs::remove_file(&path).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

pub mod atomic;
pub mod authors;
pub mod measurements;
pub mod outputs;
pub mod readings;
pub mod recurdyn;
pub mod robot_file;
pub mod robot_init;
mod robot_text;
pub mod suspended_file;
pub mod suspended_measurements;

pub use atomic::write_atomically;
pub use outputs::OutputSet;

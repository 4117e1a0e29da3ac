//! What sagcal understood from a user's files, before any fit (`sagcal
//! check`, `sagcal.check` in Python): the robot (cables, the anchors' span,
//! the reference cable, the weights, the effects, the workspace), the data
//! file's format as the commands detect it (sagcal CSV, readings-only CSV,
//! RecurDyn log, the authors' folder), its rows, each column's unit and
//! range, a few rows as read (`row 1 (line 3)`: the data row counted from 1
//! and its file line), the sensors present, the encoder readings against the
//! robot's geometry, and warnings for likely mistakes: a column in the wrong
//! unit, poses outside the frame or the workspace, readings that do not
//! follow the geometry, rows `calibrate` would refuse. The unit and row
//! checks are `calibrate`'s own ([`crate::calib::mistakes`],
//! [`crate::calib::screen`]), so `check` warns of what `calibrate` refuses.
//!
//! One [`CheckReport`] is both the text `sagcal check` prints and its JSON;
//! a robot of 3 to 8 cables and its measurement file get a
//! [`SuspendedCheckReport`] ([`check_suspended_files`]).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::check::{check_files, DataFormat, WarningKind};
//! use sagcal::io::measurements::write_measurements;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let dir = std::env::temp_dir().join(format!("sagcal-check-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let robot = Robot::builtin("large")?;
//! let robot_path = dir.join("large.toml");
//! std::fs::write(&robot_path, robot.to_file_contents().to_toml()?).unwrap();
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
//! let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 8, &mut rng)?;
//! let mut poses = measure(&robot, &equilibria, &NoisePreset::Paper.sigmas(robot.platform_weight_n), &mut rng);
//! let data = dir.join("m.csv");
//! write_measurements(&data, &["eight poses".into()], &poses)?;
//! let report = check_files(&robot_path, Some(&data))?;
//! let read = report.data.as_ref().unwrap();
//! // A comment, the header, then row 1 on line 3.
//! assert_eq!((read.format, read.rows, read.samples[0].line), (DataFormat::SagcalCsv, 8, 3));
//! assert!(report.warnings.is_empty(), "{:?}", report.warnings);
//! // The load cell logged in kN: named, as calibrate names it.
//! for pose in &mut poses {
//!     pose.reference_tension_n /= 1e3;
//! }
//! write_measurements(&data, &[], &poses)?;
//! let report = check_files(&robot_path, Some(&data))?;
//! assert_eq!(report.warnings[0].kind, WarningKind::Unit);
//! assert!(report.warnings[0].message.contains("look like kN"), "{}", report.warnings[0].message);
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

mod data_file;
mod findings;
mod job;
mod report;
mod robot_summary;
mod suspended;

pub use job::{check_files, check_robot_and_data};
pub use report::{
    row_label, CableAgainstGeometry, CheckReport, CheckWarning, ColumnSummary, DataFormat, DataSummary, RejectedLine,
    RobotSummary, SampleRow, Sensors, Span, WarningKind, WorkspaceSummary,
};
pub use suspended::{
    check_suspended_files, check_suspended_robot_and_data, SuspendedCheckReport, SuspendedDataSummary,
    SuspendedRobotSummary,
};

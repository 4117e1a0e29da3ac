//! The check of a robot file and a data file ([`check_files`]).

use std::path::Path;

use super::data_file::{read_data, summarise};
use super::findings::findings;
use super::report::{CheckReport, RobotSummary};
use crate::error::Result;
use crate::model::Robot;

/// Read the robot file at `robot_path` and, if given, the data at
/// `data_path` (any format a command reads), and say what was understood
/// and what looks wrong. An unreadable or invalid file is an error naming
/// it; a likely mistake in readable data is a warning of the report.
pub fn check_files(robot_path: &Path, data_path: Option<&Path>) -> Result<CheckReport> {
    let robot = Robot::from_file(robot_path)?;
    check_robot_and_data(&robot, robot_path, data_path)
}

/// [`check_files`] for a robot already read from `robot_path`.
pub fn check_robot_and_data(robot: &Robot, robot_path: &Path, data_path: Option<&Path>) -> Result<CheckReport> {
    let summary = RobotSummary::of(robot, robot_path);
    let Some(path) = data_path else {
        return Ok(CheckReport {
            robot: summary,
            data: None,
            warnings: Vec::new(),
        });
    };
    let data = read_data(path, robot)?;
    let described = summarise(&data, robot, path);
    let warnings = findings(robot, &data, &described.geometry);
    Ok(CheckReport {
        robot: summary,
        data: Some(described),
        warnings,
    })
}

//! `sagcal.check`: what sagcal understood from a robot file and a data
//! file, before any fit, as `sagcal check --json` prints it
//! (`sagcal::check`, shared with `src/cli/check.rs`).

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use sagcal::check::{check_files, check_robot_and_data};

use crate::data::as_path;
use crate::json::to_python;
use crate::robot::Robot;
use crate::{invalid, to_py};

/// What sagcal understood from ``robot`` (a robot file's path, or a
/// :class:`Robot`) and ``data`` (the path of a sagcal CSV, a readings-only
/// CSV, a RecurDyn log or the authors' dataset folder), as ``sagcal check
/// --json`` prints it: a dict with ``robot`` (cables, anchors' span,
/// reference cable, weights, effects, workspace), ``data`` (the detected
/// format, the rows, each column's unit and range, a few rows as read with
/// their data row counted from 1 and their file line, the sensors present,
/// the encoder readings against the robot's geometry; ``None`` without
/// ``data``) and ``warnings`` (likely mistakes: a column in mm or kN, poses
/// outside the frame or the workspace, readings that do not follow the
/// geometry, rows ``sagcal calibrate`` would refuse).
///
/// An unreadable or invalid file raises :class:`FileError` or
/// :class:`RobotError` with the command's message.
#[pyfunction]
#[pyo3(signature = (robot, data = None))]
pub fn check<'py>(
    py: Python<'py>,
    robot: &Bound<'py, PyAny>,
    data: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let data: Option<PathBuf> = match data {
        None => None,
        Some(d) => Some(as_path(d).ok_or_else(|| invalid("data: the path of a data file or folder"))?),
    };
    let report = if let Some(path) = as_path(robot) {
        py.detach(|| check_files(&path, data.as_deref()))
    } else {
        let robot: PyRef<'_, Robot> = robot
            .extract()
            .map_err(|_| invalid("robot: a sagcal.Robot or the path of a robot file"))?;
        let inner = robot.inner.clone();
        let label = format!("<Robot `{}`>", inner.name);
        py.detach(|| check_robot_and_data(&inner, Path::new(&label), data.as_deref()))
    }
    .map_err(to_py)?;
    to_python(py, &report)
}

//! `sagcal.check`: what sagcal understood from a robot file and a data
//! file, before any fit, as `sagcal check --json` prints it
//! (`sagcal::check`, shared with `src/cli/check.rs`).

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use sagcal::check::{check_files, check_robot_and_data, check_suspended_files, check_suspended_robot_and_data};

use crate::data::as_path;
use crate::json::to_python;
use crate::robot::Robot;
use crate::suspended::SuspendedRobot;
use crate::{invalid, to_py};

/// What sagcal understood from ``robot`` (a robot file's path, a
/// :class:`Robot` or a :class:`SuspendedRobot`) and ``data`` (the path of a sagcal CSV, a readings-only
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
/// A robot of 3 to 8 cables and its measurement file get the report of
/// ``sagcal check`` for such a robot: ``robot`` with its load cells, free
/// force components and per-cable weights, ``data`` with its columns,
/// rows and geometry.
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
    if let Some(path) = as_path(robot) {
        return match py.detach(|| check_files(&path, data.as_deref())) {
            Ok(report) => to_python(py, &report),
            Err(sagcal::Error::Robot { message, .. }) if message.contains("field `cables`") => {
                let report = py
                    .detach(|| check_suspended_files(&path, data.as_deref()))
                    .map_err(to_py)?;
                to_python(py, &report)
            }
            Err(e) => Err(to_py(e)),
        };
    }
    if let Ok(suspended) = robot.extract::<PyRef<'_, SuspendedRobot>>() {
        let inner = suspended.inner.clone();
        let label = format!("<SuspendedRobot `{}`>", inner.name);
        let report = py
            .detach(|| check_suspended_robot_and_data(&inner, Path::new(&label), data.as_deref()))
            .map_err(to_py)?;
        return to_python(py, &report);
    }
    let report = {
        let robot: PyRef<'_, Robot> = robot
            .extract()
            .map_err(|_| invalid("robot: a sagcal.Robot, a sagcal.SuspendedRobot or the path of a robot file"))?;
        let inner = robot.inner.clone();
        let label = format!("<Robot `{}`>", inner.name);
        py.detach(|| check_robot_and_data(&inner, Path::new(&label), data.as_deref()))
    }
    .map_err(to_py)?;
    to_python(py, &report)
}

//! Measurements in: an (N, 11) array in the columns of sagcal's measurement
//! file, or the path of any file `sagcal calibrate --data` reads.

use std::path::PathBuf;

use pyo3::prelude::*;
use sagcal::io::measurements::{
    measurement_from_values, pose_values, MeasurementFormat, ReadOptions, MEASUREMENT_HEADER,
};
use sagcal::model::PoseMeasurement;

use crate::arrays::{out2, rows};
use crate::{invalid, to_py};

/// What an array of measurements is called in messages.
pub const ARRAY_LABEL: &str = "measurements";

/// Measurements with the name of their source.
pub struct Data {
    /// The poses, in row order (an array's with line 0: reports name them by their 1-based row).
    pub poses: Vec<PoseMeasurement>,
    /// The file (as given), or [`ARRAY_LABEL`] for an array.
    pub label: PathBuf,
    /// Whether the rows are in the order the poses were taken: a sagcal
    /// measurement file or an array (not a RecurDyn log or an authors' folder).
    pub rows_in_time_order: bool,
}

/// Read `value`: a path (`str` or `os.PathLike`: sagcal CSV, RecurDyn log, or
/// whatever `read_measurements` accepts) or an (N, 11) array whose rows are
/// checked as a file's rows are (`row` in messages is 1-based).
pub fn measurements(value: &Bound<'_, PyAny>, reference_cable: usize) -> PyResult<Data> {
    if let Some(path) = as_path(value) {
        let set = sagcal::io::measurements::read_measurements(
            &path,
            &ReadOptions {
                reference_cable,
                keep_rounded: false,
            },
        )
        .map_err(to_py)?;
        return Ok(Data {
            rows_in_time_order: set.format == MeasurementFormat::Sagcal,
            poses: set.poses,
            label: path,
        });
    }
    // An array's rows are the order the poses were taken in.
    let mut poses = from_rows(&rows::<11>(value, ARRAY_LABEL)?)?;
    sagcal::model::measurement::mark_time_order(&mut poses);
    Ok(Data {
        poses,
        label: PathBuf::from(ARRAY_LABEL),
        rows_in_time_order: true,
    })
}

/// Measurements from array rows, each checked as a file's row is (`row` in messages is 1-based).
fn from_rows(rows: &[[f64; 11]]) -> PyResult<Vec<PoseMeasurement>> {
    let label = PathBuf::from(ARRAY_LABEL);
    rows.iter()
        .enumerate()
        .map(|(i, row)| measurement_from_values(&label, i + 1, row))
        .collect::<sagcal::Result<Vec<_>>>()
        .map_err(to_py)
}

/// `value` as a path if it is a `str` or an `os.PathLike`.
pub fn as_path(value: &Bound<'_, PyAny>) -> Option<PathBuf> {
    let is_path = value.is_instance_of::<pyo3::types::PyString>()
        || value
            .py()
            .import("os")
            .and_then(|os| value.is_instance(&os.getattr("PathLike")?))
            .unwrap_or(false);
    is_path.then(|| value.extract::<PathBuf>().ok()).flatten()
}

/// The measurements as an (N, 11) array.
pub fn to_array<'py>(py: Python<'py>, poses: &[PoseMeasurement]) -> PyResult<Bound<'py, PyAny>> {
    let rows: Vec<[f64; 11]> = poses.iter().map(pose_values).collect();
    out2(py, &rows)
}

/// Read a measurement file as ``sagcal calibrate --data`` does: sagcal's CSV
/// or a RecurDyn log (told apart by the header).
///
/// Returns an (N, 11) float64 array in the columns of sagcal's measurement
/// file, :data:`MEASUREMENT_COLUMNS`: ``x_m, y_m, z_m, roll_deg, pitch_deg,
/// yaw_deg, l1_m, l2_m, l3_m, l4_m, f_ref_n``. ``reference_cable`` (1..4)
/// picks a RecurDyn log's load-cell column, as the robot file's does for the
/// command. Rows a RecurDyn log rejects are left out, as the command leaves
/// them out. Raises :class:`SagcalError` with the command's message.
#[pyfunction]
#[pyo3(signature = (path, reference_cable = 1))]
pub fn read_measurements<'py>(py: Python<'py>, path: PathBuf, reference_cable: usize) -> PyResult<Bound<'py, PyAny>> {
    if !(1..=4).contains(&reference_cable) {
        return Err(invalid(format!(
            "reference_cable must be a cable number 1..4, got {reference_cable}"
        )));
    }
    let set = sagcal::io::measurements::read_measurements(
        &path,
        &ReadOptions {
            reference_cable: reference_cable - 1,
            keep_rounded: false,
        },
    )
    .map_err(to_py)?;
    to_array(py, &set.poses)
}

/// Write an (N, 11) array as a sagcal measurement file (atomically), each of
/// ``comments`` as a ``# ...`` line before the header.
///
/// Values are written with full round-trip precision, so
/// :func:`read_measurements` gives back the same array bit for bit. The rows
/// are checked as :func:`calibrate` checks an array: a non-finite value or a
/// reference tension that is not positive raises :class:`SagcalError` naming
/// the row (1-based) and the column, and nothing is written.
#[pyfunction]
#[pyo3(signature = (path, measurements, comments = None))]
pub fn write_measurements(
    path: PathBuf,
    measurements: &Bound<'_, PyAny>,
    comments: Option<Vec<String>>,
) -> PyResult<()> {
    let poses = from_rows(&rows::<11>(measurements, ARRAY_LABEL)?)?;
    sagcal::io::measurements::write_measurements(&path, &comments.unwrap_or_default(), &poses).map_err(to_py)
}

/// The column names of a measurement array, in order.
pub fn columns() -> Vec<&'static str> {
    MEASUREMENT_HEADER.to_vec()
}

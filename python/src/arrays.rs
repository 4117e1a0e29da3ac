//! numpy arrays in and out: anything `numpy.asarray(x, dtype=float64)` takes
//! (arrays, lists, tuples) is accepted, its shape checked, and results go out
//! as new float64 arrays.

use numpy::ndarray::{Array, Array1, Array2, Array3, Dimension};
use numpy::prelude::*;
use numpy::{PyArrayDyn, PyReadonlyArrayDyn};
use pyo3::prelude::*;

use crate::invalid;

/// The shape as Python prints it: `(3, 10)`, `(4,)`, `()`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// `value` as a float64 array: its shape and its values in row-major order.
/// `what` names the argument in the error.
fn float_array(value: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let float64 = numpy.getattr("float64")?;
    let converted = numpy
        .call_method1("asarray", (value, float64))
        .map_err(|e| invalid(format!("{what}: not an array of numbers: {}", e.value(py))))?;
    let array = converted
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|e| invalid(format!("{what}: not an array of numbers: {e}")))?;
    let readonly: PyReadonlyArrayDyn<'_, f64> = array.readonly();
    let view = readonly.as_array();
    Ok((view.shape().to_vec(), view.iter().copied().collect()))
}

/// Row-major values as rows of `C`.
fn split_rows<const C: usize>(values: &[f64]) -> Vec<[f64; C]> {
    values
        .chunks_exact(C)
        .map(|row| std::array::from_fn(|k| row[k]))
        .collect()
}

/// The rows of an `(N, width)` array with `N >= 1`, `width` known only at
/// run time (a robot's number of cables and load cells); `columns` names
/// the columns in the error.
pub fn dynamic_rows(value: &Bound<'_, PyAny>, width: usize, columns: &str, what: &str) -> PyResult<Vec<Vec<f64>>> {
    let (shape, values) = float_array(value, what)?;
    if shape.len() != 2 || shape[1] != width || shape[0] == 0 {
        return Err(invalid(format!(
            "{what} must be an (N, {width}) array with N >= 1 ({columns}), got shape {}",
            shape_text(&shape)
        )));
    }
    Ok(values.chunks_exact(width).map(<[f64]>::to_vec).collect())
}

/// The rows of an `(N, C)` array with `N >= 1`.
pub fn rows<const C: usize>(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; C]>> {
    let (shape, values) = float_array(value, what)?;
    if shape.len() != 2 || shape[1] != C || shape[0] == 0 {
        return Err(invalid(format!(
            "{what} must be an (N, {C}) array with N >= 1, got shape {}",
            shape_text(&shape)
        )));
    }
    Ok(split_rows(&values))
}

/// The rows of an `(R, C)` array (`R` given).
pub fn exact_rows<const C: usize>(value: &Bound<'_, PyAny>, count: usize, what: &str) -> PyResult<Vec<[f64; C]>> {
    let (shape, values) = float_array(value, what)?;
    if shape != [count, C] {
        return Err(invalid(format!(
            "{what} must be an array of shape ({count}, {C}), got shape {}",
            shape_text(&shape)
        )));
    }
    Ok(split_rows(&values))
}

/// The values of an `(N,)` array (`N` given).
pub fn vector(value: &Bound<'_, PyAny>, len: usize, what: &str) -> PyResult<Vec<f64>> {
    let (shape, values) = float_array(value, what)?;
    if shape != [len] {
        return Err(invalid(format!(
            "{what} must be an array of shape ({len},), got shape {}",
            shape_text(&shape)
        )));
    }
    Ok(values)
}

/// The values of a one-dimensional array of any length.
pub fn any_vector(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let (shape, values) = float_array(value, what)?;
    if shape.len() != 1 {
        return Err(invalid(format!(
            "{what} must be a one-dimensional array, got shape {}",
            shape_text(&shape)
        )));
    }
    Ok(values)
}

/// A fixed-size vector (`(N,)` array).
pub fn fixed<const N: usize>(value: &Bound<'_, PyAny>, what: &str) -> PyResult<[f64; N]> {
    let values = vector(value, N, what)?;
    Ok(std::array::from_fn(|k| values[k]))
}

/// A new read-only `(N,)` float64 array (every property returns a fresh
/// copy; read-only, so that editing it in place fails instead of changing nothing).
pub fn out1<'py>(py: Python<'py>, values: &[f64]) -> PyResult<Bound<'py, PyAny>> {
    frozen(py, Array1::from(values.to_vec()))
}

/// A new read-only `(N, C)` float64 array from rows.
pub fn out2<'py, const C: usize>(py: Python<'py>, rows: &[[f64; C]]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    frozen(
        py,
        Array2::from_shape_vec((rows.len(), C), flat).expect("rows of C values"),
    )
}

/// A new read-only `(N, R, C)` float64 array from matrices.
pub fn out3<'py, const R: usize, const C: usize>(
    py: Python<'py>,
    matrices: &[[[f64; C]; R]],
) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = matrices.iter().flatten().flatten().copied().collect();
    frozen(
        py,
        Array3::from_shape_vec((matrices.len(), R, C), flat).expect("matrices of R x C values"),
    )
}

/// `array` as a read-only numpy array.
pub(crate) fn frozen<'py, D: Dimension>(py: Python<'py>, array: Array<f64, D>) -> PyResult<Bound<'py, PyAny>> {
    let out = array.into_pyarray(py);
    out.call_method1("setflags", (false,))?;
    Ok(out.into_any())
}

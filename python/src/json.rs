//! Reports as plain Python objects: a serde value through JSON, so a result's
//! `report` is exactly what the command prints with `--json`.

use pyo3::prelude::*;
use serde::Serialize;

use crate::invalid;

/// `value` as Python dicts, lists, floats, ints, strings, bools and `None`
/// (`json.loads` of its JSON; non-finite floats become `None`, as in the
/// command's JSON).
pub fn to_python<'py>(py: Python<'py>, value: &impl Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| invalid(format!("cannot serialise the report: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

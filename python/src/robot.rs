//! `sagcal.Robot`: a robot description (`robots/*.toml`) with its geometry,
//! masses, encoder offsets and effects as numpy arrays and floats.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use sagcal::io::robot_file::{RobotFile, WorkspaceEntry};
use sagcal::model::effects::Effects;
use sagcal::model::robot::{PaperRobot, CABLE_COUNT};

use crate::arrays::{exact_rows, fixed, out1, out2};
use crate::to_py;

/// A suspended four-cable robot: anchors, attachment points, weights, the
/// reference cable with the load cell, encoder length offsets and the effects
/// beyond the closed-form model (a robot TOML file, see ``robots/large.toml``).
///
/// Read one with :meth:`Robot.from_toml` or :meth:`Robot.builtin`. Every
/// attribute can be read and set; a value the robot file would refuse raises
/// :class:`SagcalError` with the file loader's message and leaves the robot
/// unchanged. Array attributes return new read-only float64 arrays: copy,
/// edit and assign back (``a = robot.anchors_m.copy(); a[0, 2] -= 1.0;
/// robot.anchors_m = a``).
#[pyclass(module = "sagcal", name = "Robot", eq)]
#[derive(Clone, PartialEq)]
pub struct Robot {
    /// The robot.
    pub inner: sagcal::model::Robot,
}

impl Robot {
    /// Wrap a library robot.
    pub fn new(inner: sagcal::model::Robot) -> Self {
        Self { inner }
    }

    /// Change the file representation with `edit` and validate the result as
    /// the robot file loader does; `field` names the attribute in errors.
    fn edit(&mut self, field: &str, edit: impl FnOnce(&mut RobotFile)) -> PyResult<()> {
        let mut file = self.inner.to_file_contents();
        edit(&mut file);
        let label = PathBuf::from(format!("<Robot.{field}>"));
        self.inner = sagcal::model::Robot::try_from_file_contents(file, &label).map_err(to_py)?;
        Ok(())
    }
}

#[pymethods]
impl Robot {
    /// Read and validate a robot TOML file.
    ///
    /// Raises :class:`SagcalError` with the message ``sagcal`` prints for the
    /// same file (missing file, TOML syntax, a field out of range).
    #[staticmethod]
    fn from_toml(path: PathBuf) -> PyResult<Self> {
        sagcal::model::Robot::from_file(&path).map(Self::new).map_err(to_py)
    }

    /// One of the robots built into sagcal: ``"large"`` or ``"small"`` (the
    /// paper's two robots, ``robots/large.toml`` and ``robots/small.toml``).
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        sagcal::model::Robot::builtin(name).map(Self::new).map_err(to_py)
    }

    /// Write the robot as a TOML file (atomically: on error the file is left as it was).
    fn to_toml(&self, path: PathBuf) -> PyResult<()> {
        sagcal::io::write_atomically(&path, self.toml()?.as_bytes()).map_err(to_py)
    }

    /// The robot file's text (TOML), as :meth:`to_toml` writes it.
    fn toml(&self) -> PyResult<String> {
        self.inner.to_file_contents().to_toml().map_err(to_py)
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        self.clone()
    }

    fn __copy__(&self) -> Self {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot(name={:?}, anchors_m={:?}, length_offsets_m={:?})",
            self.inner.name,
            self.inner.anchors_m.map(|a| [a.x, a.y, a.z]),
            self.inner.length_offsets_m
        )
    }

    /// Human-readable name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    #[setter]
    fn set_name(&mut self, name: String) {
        self.inner.name = name;
    }

    /// Anchors (pulley exit points) of cables 1..4, world frame, metres: a (4, 3) array.
    #[getter]
    fn anchors_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.inner.anchors_m.map(|a| [a.x, a.y, a.z]))
    }

    #[setter]
    fn set_anchors_m(&mut self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let anchors = four_points(value, "anchors_m")?;
        self.edit("anchors_m", |f| {
            for (cable, a) in f.cables.iter_mut().zip(anchors) {
                cable.anchor_m = a;
            }
        })
    }

    /// Attachment points of cables 1..4 on the platform, platform frame, metres: a (4, 3) array.
    #[getter]
    fn attachments_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.inner.attachments_m.map(|a| [a.x, a.y, a.z]))
    }

    #[setter]
    fn set_attachments_m(&mut self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let attachments = four_points(value, "attachments_m")?;
        self.edit("attachments_m", |f| {
            for (cable, a) in f.cables.iter_mut().zip(attachments) {
                cable.attachment_m = a;
            }
        })
    }

    /// Centre of mass in the platform frame, metres: a (3,) array.
    #[getter]
    fn com_offset_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out1(py, self.inner.com_offset_m.as_slice())
    }

    #[setter]
    fn set_com_offset_m(&mut self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let com = fixed::<3>(value, "com_offset_m")?;
        self.edit("com_offset_m", |f| f.com_offset_m = com)
    }

    /// Platform weight ``m_e g``, newtons (positive).
    #[getter]
    fn platform_weight_n(&self) -> f64 {
        self.inner.platform_weight_n
    }

    #[setter]
    fn set_platform_weight_n(&mut self, value: f64) -> PyResult<()> {
        self.edit("platform_weight_n", |f| f.platform_weight_n = value)
    }

    /// Cable weight per metre ``g_c = rho_c g``, newtons per metre (>= 0; 0: massless cables).
    #[getter]
    fn cable_weight_n_per_m(&self) -> f64 {
        self.inner.cable_weight_n_per_m
    }

    #[setter]
    fn set_cable_weight_n_per_m(&mut self, value: f64) -> PyResult<()> {
        self.edit("cable_weight_n_per_m", |f| f.cable_weight_n_per_m = value)
    }

    /// The cable with the load cell, numbered 1..4 as in the robot file
    /// (its anchor is ``anchors_m[reference_cable - 1]``).
    #[getter]
    fn reference_cable(&self) -> usize {
        self.inner.reference_cable + 1
    }

    #[setter]
    fn set_reference_cable(&mut self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let Ok(cable) = value.extract::<usize>() else {
            return Err(crate::invalid(format!(
                "reference_cable must be a cable number 1..4, got {}",
                value.repr().map_or_else(|_| "?".into(), |r| r.to_string())
            )));
        };
        self.edit("reference_cable", |f| f.reference_cable = cable)
    }

    /// Encoder length offsets ``l_i^0`` of cables 1..4, metres (encoder = cable length + offset): a (4,) array.
    #[getter]
    fn length_offsets_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out1(py, &self.inner.length_offsets_m)
    }

    #[setter]
    fn set_length_offsets_m(&mut self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let offsets = fixed::<CABLE_COUNT>(value, "length_offsets_m")?;
        self.edit("length_offsets_m", |f| f.length_offsets_m = Some(offsets.to_vec()))
    }

    /// The box of platform positions poses are drawn from: ``(min_m, max_m)``,
    /// two (3,) arrays, world frame, metres; ``None`` when the file gives none
    /// (sagcal then derives one from the anchors).
    #[getter]
    fn workspace<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyTuple>>> {
        self.inner
            .workspace
            .map(|w| PyTuple::new(py, [out1(py, &w.min_m)?, out1(py, &w.max_m)?]))
            .transpose()
    }

    #[setter]
    fn set_workspace(&mut self, value: Option<(Bound<'_, PyAny>, Bound<'_, PyAny>)>) -> PyResult<()> {
        let entry = match value {
            None => None,
            Some((min, max)) => Some(WorkspaceEntry {
                min_m: fixed::<3>(&min, "workspace min_m")?,
                max_m: fixed::<3>(&max, "workspace max_m")?,
            }),
        };
        self.edit("workspace", |f| f.workspace = entry)
    }

    /// Which of the paper's robots this is (``"large"``, ``"small"``) or ``None``.
    #[getter]
    fn paper_robot(&self) -> Option<&'static str> {
        self.inner.paper_robot.map(PaperRobot::name)
    }

    /// The effects beyond the closed-form model (the robot file's ``[effects]``),
    /// a dict with every key: ``axial_stiffness_n`` (float or None: inextensible),
    /// ``pulley_radius_m``, ``encoder_gain`` (4,), ``load_cell_bias_n``,
    /// ``load_cell_gain``, ``com_shift_m`` (3,), ``cable_segments`` (float or
    /// None: the smooth cable), ``localiser_mount_deg`` (3,).
    ///
    /// Set it with a dict of some of these keys (the others take their
    /// no-effect values); an unknown key or a value out of range raises
    /// :class:`SagcalError`.
    #[getter]
    fn effects<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = &self.inner.effects;
        let dict = PyDict::new(py);
        dict.set_item("axial_stiffness_n", e.axial_stiffness_n)?;
        dict.set_item("pulley_radius_m", e.pulley_radius_m)?;
        dict.set_item("encoder_gain", out1(py, &e.encoder_gain)?)?;
        dict.set_item("load_cell_bias_n", e.load_cell_bias_n)?;
        dict.set_item("load_cell_gain", e.load_cell_gain)?;
        dict.set_item("com_shift_m", out1(py, &e.com_shift_m)?)?;
        dict.set_item("cable_segments", e.cable_segments)?;
        dict.set_item("localiser_mount_deg", out1(py, &e.localiser_mount_deg)?)?;
        dict.set_item("platform_weight_scale", e.platform_weight_scale)?;
        dict.set_item("cable_weight_scale", e.cable_weight_scale)?;
        dict.set_item("encoder_drift_m_per_row", out1(py, &e.encoder_drift_m_per_row)?)?;
        dict.set_item("encoder_backlash_m", out1(py, &e.encoder_backlash_m)?)?;
        dict.set_item("load_cell_drift_n_per_row", e.load_cell_drift_n_per_row)?;
        dict.set_item("load_cell_friction", e.load_cell_friction)?;
        dict.set_item("attachment_shift_m", out2(py, &e.attachment_shift_m)?)?;
        Ok(dict)
    }

    #[setter]
    fn set_effects(&mut self, value: &Bound<'_, PyDict>) -> PyResult<()> {
        let effects = effects_from_dict(value)?;
        self.edit("effects", |f| f.effects = Some(effects))
    }
}

/// Four points as a (4, 3) array.
fn four_points(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    exact_rows::<3>(value, CABLE_COUNT, what)
}

/// Effects from a dict of the robot file's `[effects]` keys (numbers, arrays or `None`).
fn effects_from_dict(dict: &Bound<'_, PyDict>) -> PyResult<Effects> {
    let label = Path::new("<Robot.effects>");
    let fail = |message: String| {
        to_py(sagcal::Error::Robot {
            path: label.to_path_buf(),
            message: format!("table `effects`: {message}"),
        })
    };
    let mut table = serde_json::Map::new();
    for (key, value) in dict.iter() {
        let key: String = key.extract()?;
        let json = if value.is_none() {
            serde_json::Value::Null
        } else if let Ok(number) = value.extract::<f64>() {
            number_json(number).ok_or_else(|| fail(format!("`{key}` is not finite")))?
        } else if key == "attachment_shift_m" {
            // Four `[dx, dy]` pairs: a (4, 2) array, as the getter gives it.
            let pairs = exact_rows::<2>(&value, CABLE_COUNT, &key)?;
            let rows: Option<Vec<serde_json::Value>> = pairs
                .into_iter()
                .map(|pair| {
                    pair.into_iter()
                        .map(number_json)
                        .collect::<Option<Vec<_>>>()
                        .map(serde_json::Value::Array)
                })
                .collect();
            serde_json::Value::Array(rows.ok_or_else(|| fail(format!("`{key}` is not finite")))?)
        } else {
            let values = crate::arrays::any_vector(&value, &key)?;
            let numbers: Option<Vec<serde_json::Value>> = values.into_iter().map(number_json).collect();
            serde_json::Value::Array(numbers.ok_or_else(|| fail(format!("`{key}` is not finite")))?)
        };
        table.insert(key, json);
    }
    serde_json::from_value(serde_json::Value::Object(table)).map_err(|e| fail(e.to_string()))
}

/// A finite number as JSON.
fn number_json(value: f64) -> Option<serde_json::Value> {
    serde_json::Number::from_f64(value).map(serde_json::Value::Number)
}

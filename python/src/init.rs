//! `sagcal.init_robot`: a new, commented robot file from a few numbers, as
//! `sagcal init` writes it (`sagcal::io::robot_init`, shared with
//! `src/cli/init.rs`).

use std::path::PathBuf;

use pyo3::prelude::*;
use sagcal::error::FrontEnd;
use sagcal::io::robot_init::{robot_file_text, write_robot_file, Heaviness, RobotInit};
use sagcal::model::robot::Workspace;

use crate::arrays::{any_vector, fixed, rows};
use crate::{invalid, to_py};

/// The text of a new robot file (TOML, a comment on every key: meaning,
/// frame, unit, sign), as ``sagcal init`` writes it; with ``out``, also
/// written there (atomically; an existing file only with ``force=True``).
///
/// ``anchors_m`` are the four anchors (pulley exit points), world frame with
/// z up, metres, and ``attachments_m`` the four attachment points, platform
/// frame, metres: (4, 3) arrays in cable order. The platform's mass
/// (``platform_mass_kg``) or weight (``platform_weight_n``), the cables'
/// mass (``cable_mass_per_m_kg``) or weight (``cable_weight_n_per_m``) per
/// metre; optionally ``axial_stiffness_n`` (EA, N; omitted: inextensible),
/// ``com_offset_m`` (platform frame, m; default the origin),
/// ``reference_cable`` (1..4, the load cell's; default 1), ``workspace``
/// (``x0, x1, y0, y1, z0, z1``, m), ``name``. ``from_template`` (``"large"``
/// or ``"small"``) starts from a built-in robot: every value not given is
/// the template's.
///
/// The robot passes the checks of ``sagcal.Robot.from_toml`` and of
/// magnitudes typed by hand (millimetres for metres, ...) before anything
/// is written, and the text reads back to the same robot. A refusal raises
/// :class:`InvalidInputError` naming the keyword.
#[pyfunction]
#[pyo3(signature = (
    anchors_m = None,
    attachments_m = None,
    *,
    platform_mass_kg = None,
    platform_weight_n = None,
    cable_mass_per_m_kg = None,
    cable_weight_n_per_m = None,
    axial_stiffness_n = None,
    com_offset_m = None,
    reference_cable = None,
    workspace = None,
    name = None,
    from_template = None,
    out = None,
    force = false,
))]
#[allow(clippy::too_many_arguments)]
pub fn init_robot(
    py: Python<'_>,
    anchors_m: Option<&Bound<'_, PyAny>>,
    attachments_m: Option<&Bound<'_, PyAny>>,
    platform_mass_kg: Option<f64>,
    platform_weight_n: Option<f64>,
    cable_mass_per_m_kg: Option<f64>,
    cable_weight_n_per_m: Option<f64>,
    axial_stiffness_n: Option<f64>,
    com_offset_m: Option<&Bound<'_, PyAny>>,
    reference_cable: Option<usize>,
    workspace: Option<&Bound<'_, PyAny>>,
    name: Option<String>,
    from_template: Option<String>,
    out: Option<PathBuf>,
    force: bool,
) -> PyResult<String> {
    let init = RobotInit {
        template: from_template,
        name,
        anchors_m: anchors_m
            .map(|a| rows::<3>(a, "anchors_m"))
            .transpose()?
            .unwrap_or_default(),
        attachments_m: attachments_m
            .map(|a| rows::<3>(a, "attachments_m"))
            .transpose()?
            .unwrap_or_default(),
        platform: heaviness(
            ("platform_mass_kg", platform_mass_kg),
            ("platform_weight_n", platform_weight_n),
        )?,
        cable: heaviness(
            ("cable_mass_per_m_kg", cable_mass_per_m_kg),
            ("cable_weight_n_per_m", cable_weight_n_per_m),
        )?,
        axial_stiffness_n,
        com_offset_m: com_offset_m.map(|c| fixed::<3>(c, "com_offset_m")).transpose()?,
        reference_cable,
        workspace: workspace.map(workspace_box).transpose()?,
    };
    let new = py
        .detach(|| match &out {
            Some(path) => write_robot_file(&init, FrontEnd::Python, path, force),
            None => robot_file_text(&init, FrontEnd::Python),
        })
        .map_err(to_py)?;
    Ok(new.text)
}

/// A mass or a weight, not both.
fn heaviness(mass: (&str, Option<f64>), weight: (&str, Option<f64>)) -> PyResult<Option<Heaviness>> {
    match (mass.1, weight.1) {
        (Some(_), Some(_)) => Err(invalid(format!("{} and {}: give one of them", mass.0, weight.0))),
        (Some(kg), None) => Ok(Some(Heaviness::MassKg(kg))),
        (None, Some(n)) => Ok(Some(Heaviness::WeightN(n))),
        (None, None) => Ok(None),
    }
}

/// `x0, x1, y0, y1, z0, z1` as a box.
fn workspace_box(value: &Bound<'_, PyAny>) -> PyResult<Workspace> {
    let v = any_vector(value, "workspace")?;
    let [x0, x1, y0, y1, z0, z1] = <[f64; 6]>::try_from(v.as_slice()).map_err(|_| {
        invalid(format!(
            "workspace: six numbers x0, x1, y0, y1, z0, z1, got {}",
            v.len()
        ))
    })?;
    Ok(Workspace {
        min_m: [x0, y0, z0],
        max_m: [x1, y1, z1],
    })
}

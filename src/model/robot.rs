//! The robot's geometry and masses, validated.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::io::robot_file::{CableEntry, RobotFile, WorkspaceEntry};
use crate::model::effects::Effects;

/// Number of cables of the suspended robot modelled by sagcal.
pub const CABLE_COUNT: usize = 4;

/// A suspended 4-cable robot (paper Sec. III-A).
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    /// Human-readable name.
    pub name: String,
    /// Anchors `p_a,i` (pulley exit points), world frame, metres.
    pub anchors_m: [Vector3<f64>; CABLE_COUNT],
    /// Attachment points `p_b,i`, platform frame, metres.
    pub attachments_m: [Vector3<f64>; CABLE_COUNT],
    /// Centre of mass `b_com` in the platform frame, metres.
    pub com_offset_m: Vector3<f64>,
    /// Platform weight `m_e g`, newtons.
    pub platform_weight_n: f64,
    /// Cable weight per metre `g_c = rho_c g`, newtons per metre.
    pub cable_weight_n_per_m: f64,
    /// 0-based index of the reference cable (the one with the load cell).
    pub reference_cable: usize,
    /// Encoder length offsets `l_i^0`, metres (zero for a nominal robot).
    pub length_offsets_m: [f64; CABLE_COUNT],
    /// The box of platform positions calibration poses are drawn from, if the
    /// robot file gives one.
    pub workspace: Option<Workspace>,
    /// Effects known to act on this robot beyond the closed-form model (the
    /// robot file's optional `[effects]`, written by `simulate --truth`; the
    /// calibration ignores it). Default: none.
    pub effects: Effects,
}

/// An axis-aligned box of platform positions, world frame, metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Workspace {
    /// Lower corner.
    pub min_m: [f64; 3],
    /// Upper corner.
    pub max_m: [f64; 3],
}

impl Robot {
    /// Read a robot TOML file and validate it.
    pub fn from_file(path: &Path) -> Result<Self> {
        Self::try_from_file_contents(RobotFile::read(path)?, path)
    }

    /// Validate parsed file contents; `path` is only used in error messages.
    pub fn try_from_file_contents(file: RobotFile, path: &Path) -> Result<Self> {
        let fail = |message: String| Error::Robot {
            path: path.to_path_buf(),
            message,
        };
        if file.cables.len() != CABLE_COUNT {
            return Err(fail(format!(
                "field `cables`: sagcal models a suspended robot with {CABLE_COUNT} cables, the file has {}",
                file.cables.len()
            )));
        }
        if file.reference_cable < 1 || file.reference_cable > CABLE_COUNT {
            return Err(fail(format!(
                "field `reference_cable`: cable {} does not exist (cables are numbered 1..{CABLE_COUNT})",
                file.reference_cable
            )));
        }
        let finite3 = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
        for (i, CableEntry { anchor_m, attachment_m }) in file.cables.iter().enumerate() {
            if !finite3(anchor_m) {
                return Err(fail(format!("cable {}: field `anchor_m` is not finite", i + 1)));
            }
            if !finite3(attachment_m) {
                return Err(fail(format!("cable {}: field `attachment_m` is not finite", i + 1)));
            }
        }
        if !finite3(&file.com_offset_m) {
            return Err(fail("field `com_offset_m` is not finite".into()));
        }
        if !(file.platform_weight_n.is_finite() && file.platform_weight_n > 0.0) {
            return Err(fail(format!(
                "field `platform_weight_n` must be a positive weight in newtons, got {}",
                file.platform_weight_n
            )));
        }
        if !(file.cable_weight_n_per_m.is_finite() && file.cable_weight_n_per_m >= 0.0) {
            return Err(fail(format!(
                "field `cable_weight_n_per_m` must be >= 0, got {}",
                file.cable_weight_n_per_m
            )));
        }
        let anchors_m: [Vector3<f64>; CABLE_COUNT] = std::array::from_fn(|i| Vector3::from(file.cables[i].anchor_m));
        let attachments_m: [Vector3<f64>; CABLE_COUNT] =
            std::array::from_fn(|i| Vector3::from(file.cables[i].attachment_m));
        for i in 0..CABLE_COUNT {
            for j in i + 1..CABLE_COUNT {
                if (anchors_m[i] - anchors_m[j]).norm() < 1e-6 {
                    return Err(fail(format!(
                        "cables {} and {}: coincident anchors at {:?}; every cable needs its own pulley",
                        i + 1,
                        j + 1,
                        file.cables[i].anchor_m
                    )));
                }
                if (attachments_m[i] - attachments_m[j]).norm() < 1e-9 {
                    return Err(fail(format!(
                        "cables {} and {}: coincident attachment points; the statics need distinct ones",
                        i + 1,
                        j + 1
                    )));
                }
            }
        }
        let length_offsets_m = match &file.length_offsets_m {
            None => [0.0; CABLE_COUNT],
            Some(v) if v.len() == CABLE_COUNT && v.iter().all(|x| x.is_finite()) => [v[0], v[1], v[2], v[3]],
            Some(v) => {
                return Err(fail(format!(
                    "field `length_offsets_m` needs {CABLE_COUNT} finite values, got {v:?}"
                )))
            }
        };
        let workspace = match file.workspace {
            None => None,
            Some(WorkspaceEntry { min_m, max_m }) => {
                if !(0..3).all(|k| min_m[k].is_finite() && max_m[k].is_finite() && min_m[k] <= max_m[k]) {
                    return Err(fail(format!(
                        "field `workspace`: `min_m` {min_m:?} must be finite and <= `max_m` {max_m:?} on every axis"
                    )));
                }
                Some(Workspace { min_m, max_m })
            }
        };
        let effects = file.effects.unwrap_or_default();
        effects.validate().map_err(|e| fail(format!("table `effects`: {e}")))?;
        Ok(Robot {
            name: file.name,
            anchors_m,
            attachments_m,
            com_offset_m: Vector3::from(file.com_offset_m),
            platform_weight_n: file.platform_weight_n,
            cable_weight_n_per_m: file.cable_weight_n_per_m,
            reference_cable: file.reference_cable - 1,
            length_offsets_m,
            workspace,
            effects,
        })
    }

    /// The file representation of this robot.
    pub fn to_file_contents(&self) -> RobotFile {
        RobotFile {
            name: self.name.clone(),
            reference_cable: self.reference_cable + 1,
            platform_weight_n: self.platform_weight_n,
            cable_weight_n_per_m: self.cable_weight_n_per_m,
            com_offset_m: self.com_offset_m.into(),
            cables: (0..CABLE_COUNT)
                .map(|i| CableEntry {
                    anchor_m: self.anchors_m[i].into(),
                    attachment_m: self.attachments_m[i].into(),
                })
                .collect(),
            length_offsets_m: if self.length_offsets_m.iter().all(|&x| x == 0.0) {
                None
            } else {
                Some(self.length_offsets_m.to_vec())
            },
            workspace: self.workspace.map(|w| WorkspaceEntry {
                min_m: w.min_m,
                max_m: w.max_m,
            }),
            effects: (!self.effects.is_none()).then_some(self.effects),
        }
    }

    /// The built-in robots shipped in `robots/` (`large`, `small`), compiled into the binary.
    pub fn builtin(name: &str) -> Result<Self> {
        let text = match name {
            "large" => include_str!("../../robots/large.toml"),
            "small" => include_str!("../../robots/small.toml"),
            other => {
                return Err(Error::InvalidInput(format!(
                    "unknown built-in robot `{other}` (known: large, small)"
                )))
            }
        };
        let path = PathBuf::from(format!("<built-in {name}>"));
        let file: RobotFile = toml::from_str(text).map_err(|e| Error::Format {
            path: path.clone(),
            message: e.to_string(),
        })?;
        Self::try_from_file_contents(file, &path)
    }
}

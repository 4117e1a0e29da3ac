//! The robot description file (TOML).
//!
//! ```toml
//! name = "large"
//! reference_cable = 1              # 1-based index of the cable with the load cell
//! platform_weight_n = 333.54       # m_e g
//! cable_weight_n_per_m = 0.7100703113867337   # g_c = rho_c g
//! com_offset_m = [0.0, 0.0, -0.12] # centre of mass in the platform frame
//!
//! [[cables]]                       # one table per cable, in cable order
//! anchor_m = [-125.0, -110.0, 48.0]      # pulley exit point, world frame
//! attachment_m = [-0.21, -0.21, -0.011]  # attachment point, platform frame
//!
//! [workspace]                      # optional: where calibration poses are drawn
//! min_m = [-30.0, -30.0, 1.0]
//! max_m = [30.0, 30.0, 28.0]
//!
//! [effects]                        # optional: effects beyond the closed-form model
//! axial_stiffness_n = 3e6          # (written by `simulate --truth`, `diagnose --out`; calibrate, localize and verify apply them as known)
//!
//! [calibration]                    # optional: written by `calibrate --out`
//! covariance_m2 = [[...], ...]     # 16 x 16: a1x, a1y, a1z, ..., a4z, l1^0, ..., l4^0
//! ```
//!
//! An optional top-level `paper_robot = "large"` (or `"small"`) says the file
//! describes one of the paper's two robots, so that `sagcal verify` prints that
//! robot's column of the paper's Table I beside its own numbers; a robot
//! without it gets no paper column. Files written from a robot (`calibrate
//! --out`, `diagnose --out`, `simulate --truth`) keep it: they describe the
//! same robot.
//!
//! ```
//! use sagcal::model::Robot;
//! let small = Robot::builtin("small")?;
//! let dir = std::env::temp_dir().join(format!("sagcal-robot-file-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! // Written and read back, the robot is the same, to the last bit.
//! let path = dir.join("small.toml");
//! std::fs::write(&path, small.to_file_contents().to_toml()?).unwrap();
//! assert_eq!(Robot::from_file(&path)?, small);
//! // A reference cable that does not exist is an error naming the file.
//! let text = std::fs::read_to_string(&path).unwrap().replace("reference_cable = 1", "reference_cable = 7");
//! std::fs::write(&path, text).unwrap();
//! let message = Robot::from_file(&path).unwrap_err().to_string();
//! assert!(message.contains("small.toml") && message.contains("reference_cable"), "{message}");
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::effects::Effects;
use crate::model::robot::{PaperRobot, ParameterCovariance, Robot, Workspace, CABLE_COUNT, CALIBRATED_PARAMETERS};
use crate::model::{geometry, plausibility};

/// One cable of a robot file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CableEntry {
    /// Anchor (pulley exit point) in the world frame, metres.
    pub anchor_m: [f64; 3],
    /// Attachment point on the platform, platform frame, metres.
    pub attachment_m: [f64; 3],
}

/// The contents of a robot TOML file, before validation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotFile {
    /// Human-readable name.
    pub name: String,
    /// Which of the paper's robots this file describes (optional: `large` or
    /// `small`); `sagcal verify` prints that robot's paper Table I column.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paper_robot: Option<PaperRobot>,
    /// 1-based index of the reference cable (the one with the load cell).
    pub reference_cable: usize,
    /// Platform weight `m_e g`, newtons.
    pub platform_weight_n: f64,
    /// Cable weight per metre `g_c`, newtons per metre.
    pub cable_weight_n_per_m: f64,
    /// Centre of mass in the platform frame, metres.
    pub com_offset_m: [f64; 3],
    /// The cables in order; sagcal's model needs exactly four.
    pub cables: Vec<CableEntry>,
    /// Encoder length offsets `l_i^0`, metres (absent in a nominal robot: zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_offsets_m: Option<Vec<f64>>,
    /// The box of platform positions the robot is calibrated over (optional;
    /// absent: sagcal derives one from the anchors).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub workspace: Option<WorkspaceEntry>,
    /// Effects known to act on this robot beyond the closed-form model
    /// (optional; written by `simulate --truth` and `diagnose --out`). The
    /// calibration models them with their values held fixed (unless
    /// estimated: `calib::build_graph`), as the localisation and `verify` do.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effects: Option<Effects>,
    /// What the calibration that produced the anchors and offsets knows of
    /// them (optional; written by `calibrate --out`, read by `localize`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<CalibrationEntry>,
}

/// The `[calibration]` table of a robot file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationEntry {
    /// Marginal covariance of the calibrated parameters, m^2, 16 rows of 16:
    /// anchors 1..4 (x, y, z each), then length offsets 1..4.
    pub covariance_m2: Vec<Vec<f64>>,
}

impl CalibrationEntry {
    /// The entry of a covariance matrix.
    pub fn from_covariance(c: &ParameterCovariance) -> Self {
        Self {
            covariance_m2: (0..CALIBRATED_PARAMETERS)
                .map(|r| (0..CALIBRATED_PARAMETERS).map(|k| c[(r, k)]).collect())
                .collect(),
        }
    }

    /// The covariance matrix, validated: 16 x 16, finite, symmetric (to
    /// 1e-9 of its largest entry) and positive semi-definite (no eigenvalue
    /// below -1e-9 of the largest); the error says which.
    pub fn covariance(&self) -> std::result::Result<ParameterCovariance, String> {
        let n = CALIBRATED_PARAMETERS;
        if self.covariance_m2.len() != n || self.covariance_m2.iter().any(|r| r.len() != n) {
            return Err(format!(
                "field `calibration.covariance_m2`: must be {n} rows of {n} numbers (anchors x, y, z of cables 1..4, then offsets 1..4)"
            ));
        }
        let c = ParameterCovariance::from_fn(|r, k| self.covariance_m2[r][k]);
        if let Some((r, k)) = (0..n)
            .flat_map(|r| (0..n).map(move |k| (r, k)))
            .find(|&(r, k)| !c[(r, k)].is_finite())
        {
            return Err(format!(
                "field `calibration.covariance_m2`: row {} column {} is not a finite number",
                r + 1,
                k + 1
            ));
        }
        let scale = c.amax().max(f64::MIN_POSITIVE);
        if (c - c.transpose()).amax() > 1e-9 * scale {
            return Err("field `calibration.covariance_m2`: the matrix is not symmetric".into());
        }
        let smallest = c.symmetric_eigenvalues().min();
        if smallest < -1e-9 * scale {
            return Err(format!(
                "field `calibration.covariance_m2`: not a covariance (an eigenvalue is {smallest:e} m^2 < 0)"
            ));
        }
        Ok(c)
    }
}

/// The `[workspace]` table of a robot file: an axis-aligned box of platform positions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorkspaceEntry {
    /// Lower corner, world frame, metres.
    pub min_m: [f64; 3],
    /// Upper corner, world frame, metres.
    pub max_m: [f64; 3],
}

impl WorkspaceEntry {
    /// The box, validated: finite corners, `min_m <= max_m` on every axis.
    pub(super) fn validated(self) -> std::result::Result<Workspace, String> {
        let WorkspaceEntry { min_m, max_m } = self;
        if !(0..3).all(|k| min_m[k].is_finite() && max_m[k].is_finite() && min_m[k] <= max_m[k]) {
            return Err(format!(
                "field `workspace`: `min_m` {min_m:?} must be finite and <= `max_m` {max_m:?} on every axis"
            ));
        }
        Ok(Workspace { min_m, max_m })
    }
}

impl RobotFile {
    /// Read and parse a robot file (no physical validation: see `model::Robot`).
    /// A file of another number of cables (with the fields only such a
    /// robot has) is refused for its number of cables.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        toml::from_str(&text).map_err(|e| match cable_count(&text).filter(|&n| n != CABLE_COUNT) {
            Some(n) => Error::Robot {
                path: path.to_path_buf(),
                message: format!(
                    "field `cables`: the file has {n} cables; this command models {CABLE_COUNT} (`simulate`, `calibrate`, `diagnose`, `localize`, `plan`, `verify`, `check`, `experiment table2` and `experiment hidden-effects` take 3 to 8)"
                ),
            },
            None => Error::Format {
                path: path.to_path_buf(),
                message: format!("not a valid robot file: {e}"),
            },
        })
    }

    /// Serialise to TOML text (the `[calibration]` covariance one row per line).
    pub fn to_toml(&self) -> Result<String> {
        let without = Self {
            calibration: None,
            ..self.clone()
        };
        let mut text =
            toml::to_string(&without).map_err(|e| Error::InvalidInput(format!("cannot serialise robot: {e}")))?;
        if let Some(calibration) = &self.calibration {
            text += "\n[calibration]\n# Covariance of the calibrated parameters, m^2: anchors 1..4 (x, y, z), then offsets 1..4.\ncovariance_m2 = [\n";
            for row in &calibration.covariance_m2 {
                let cells: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
                text += &format!("    [{}],\n", cells.join(", "));
            }
            text += "]\n";
        }
        Ok(text)
    }
}

impl RobotFile {
    /// Each field on its own: four cables, a reference cable among them,
    /// finite points, positive platform weight, non-negative cable weight.
    fn check_fields(&self) -> std::result::Result<(), String> {
        if self.cables.len() != CABLE_COUNT {
            return Err(format!(
                "field `cables`: the file has {} cables; this command models {CABLE_COUNT} (`simulate`, `calibrate`, `diagnose`, `localize`, `plan`, `verify`, `check`, `experiment table2` and `experiment hidden-effects` take 3 to 8)",
                self.cables.len()
            ));
        }
        if self.reference_cable < 1 || self.reference_cable > CABLE_COUNT {
            return Err(format!(
                "field `reference_cable`: cable {} does not exist (cables are numbered 1..{CABLE_COUNT})",
                self.reference_cable
            ));
        }
        let points = self.cables.iter().map(|c| (&c.anchor_m, &c.attachment_m));
        check_points_and_platform(points, &self.com_offset_m, self.platform_weight_n)?;
        if !(self.cable_weight_n_per_m.is_finite() && self.cable_weight_n_per_m >= 0.0) {
            return Err(format!(
                "field `cable_weight_n_per_m` must be >= 0, got {}",
                self.cable_weight_n_per_m
            ));
        }
        Ok(())
    }

    /// The encoder offsets, zero where the file gives none.
    fn length_offsets(&self) -> std::result::Result<[f64; CABLE_COUNT], String> {
        match &self.length_offsets_m {
            None => Ok([0.0; CABLE_COUNT]),
            Some(v) if v.len() == CABLE_COUNT && v.iter().all(|x| x.is_finite()) => Ok([v[0], v[1], v[2], v[3]]),
            Some(v) => Err(format!(
                "field `length_offsets_m` needs {CABLE_COUNT} finite values, got {v:?}"
            )),
        }
    }
}

/// Every cable's anchor and attachment (in cable order), the centre of
/// mass finite, and the platform's weight a positive number of newtons;
/// the error names the cable and the field.
pub(super) fn check_points_and_platform<'a>(
    cables: impl Iterator<Item = (&'a [f64; 3], &'a [f64; 3])>,
    com_offset_m: &[f64; 3],
    platform_weight_n: f64,
) -> std::result::Result<(), String> {
    let finite3 = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
    for (i, (anchor_m, attachment_m)) in cables.enumerate() {
        if !finite3(anchor_m) {
            return Err(format!("cable {}: field `anchor_m` is not finite", i + 1));
        }
        if !finite3(attachment_m) {
            return Err(format!("cable {}: field `attachment_m` is not finite", i + 1));
        }
    }
    if !finite3(com_offset_m) {
        return Err("field `com_offset_m` is not finite".into());
    }
    if !(platform_weight_n.is_finite() && platform_weight_n > 0.0) {
        return Err(format!(
            "field `platform_weight_n` must be a positive weight in newtons, got {platform_weight_n}"
        ));
    }
    Ok(())
}

/// The number of `[[cables]]` tables in a robot file's text, nothing else
/// validated; `None` where the text is no TOML or has no cables.
pub fn cable_count(text: &str) -> Option<usize> {
    let table = toml::from_str::<toml::Table>(text).ok()?;
    Some(table.get("cables")?.as_array()?.len())
}

/// Every cable has its own pulley and its own attachment point.
pub(super) fn distinct_points(
    anchors_m: &[Vector3<f64>],
    attachments_m: &[Vector3<f64>],
) -> std::result::Result<(), String> {
    for i in 0..anchors_m.len() {
        for j in i + 1..anchors_m.len() {
            if (anchors_m[i] - anchors_m[j]).norm() < 1e-6 {
                let anchor: [f64; 3] = anchors_m[i].into();
                return Err(format!(
                    "cables {} and {}: coincident anchors at {anchor:?}; every cable needs its own pulley",
                    i + 1,
                    j + 1,
                ));
            }
            if (attachments_m[i] - attachments_m[j]).norm() < 1e-9 {
                return Err(format!(
                    "cables {} and {}: coincident attachment points; the statics need distinct ones",
                    i + 1,
                    j + 1
                ));
            }
        }
    }
    Ok(())
}

/// Effects in their ranges; what a suspended robot needs and what no real one falls outside (each message says why).
fn suspended_and_plausible(robot: &Robot) -> std::result::Result<(), String> {
    robot.effects.validate().map_err(|e| format!("table `effects`: {e}"))?;
    plausibility::check_masses(robot)?;
    geometry::check_robot(robot)?;
    plausibility::check_effects(robot, &robot.effects).map_err(|e| format!("table `effects`: {e}"))
}

/// Conversions between [`Robot`] and its file: reading validates every field
/// (errors name the file and the field), writing gives the file contents.
impl Robot {
    /// Read a robot TOML file and validate it.
    pub fn from_file(path: &Path) -> Result<Self> {
        Self::try_from_file_contents(RobotFile::read(path)?, path)
    }

    /// Validate parsed file contents (a suspended robot of plausible magnitudes: [`geometry`], [`plausibility`]);
    /// `path` is only used in error messages.
    pub fn try_from_file_contents(file: RobotFile, path: &Path) -> Result<Self> {
        let fail = |message: String| Error::Robot {
            path: path.to_path_buf(),
            message,
        };
        file.check_fields().map_err(fail)?;
        let anchors_m: [Vector3<f64>; CABLE_COUNT] = std::array::from_fn(|i| Vector3::from(file.cables[i].anchor_m));
        let attachments_m: [Vector3<f64>; CABLE_COUNT] =
            std::array::from_fn(|i| Vector3::from(file.cables[i].attachment_m));
        distinct_points(&anchors_m, &attachments_m).map_err(fail)?;
        let length_offsets_m = file.length_offsets().map_err(fail)?;
        let workspace = file
            .workspace
            .map(WorkspaceEntry::validated)
            .transpose()
            .map_err(fail)?;
        let calibration_covariance_m2 = file
            .calibration
            .as_ref()
            .map(CalibrationEntry::covariance)
            .transpose()
            .map_err(fail)?;
        let robot = Robot {
            name: file.name,
            anchors_m,
            attachments_m,
            com_offset_m: Vector3::from(file.com_offset_m),
            platform_weight_n: file.platform_weight_n,
            cable_weight_n_per_m: file.cable_weight_n_per_m,
            reference_cable: file.reference_cable - 1,
            length_offsets_m,
            workspace,
            effects: file.effects.unwrap_or_default(),
            paper_robot: file.paper_robot,
            calibration_covariance_m2,
        };
        suspended_and_plausible(&robot).map_err(fail)?;
        Ok(robot)
    }

    /// The file representation of this robot.
    pub fn to_file_contents(&self) -> RobotFile {
        RobotFile {
            name: self.name.clone(),
            paper_robot: self.paper_robot,
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
            calibration: self
                .calibration_covariance_m2
                .as_ref()
                .map(CalibrationEntry::from_covariance),
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

//! A robot file with any number of cables from 3 to 8 ([`SuspendedRobot`]).
//!
//! The same TOML as the four-cable file (`robot_file`), with per-cable
//! weights and load cells on any cables:
//!
//! ```toml
//! name = "six"
//! platform_weight_n = 2943.0             # m_e g
//! cable_weight_n_per_m = 3.924           # every cable's g_c, unless its entry gives its own
//! com_offset_m = [0.0, 0.0, -0.5]
//! load_cells = [1]                       # 1-based: the cables with a load cell (one or more)
//!
//! [[cables]]                             # 3 to 8 tables, in cable order
//! anchor_m = [30.0, 0.0, 25.0]
//! attachment_m = [0.766, 0.6428, 0.3]
//! weight_n_per_m = 3.924                 # optional: this cable's own weight per metre
//! axial_stiffness_n = 5.0e6              # optional: this cable's own EA
//! ```
//!
//! `axial_stiffness_n` (newtons, top level for every cable or in a cable's
//! table for its own) makes the cables elastic: the model pays out Irvine's
//! unstretched length (`generated::suspended_elastic_cable_residual`).
//! Without it the cables are inextensible.
//!
//! A four-cable file reads too: its `reference_cable` is its load cell
//! (where it gives no `load_cells`). Its `paper_robot` and `[calibration]`
//! are read and not used here; a `[effects]` table is refused, as the
//! N-cable model has none of the catalogue's effects (the cables' known
//! stiffness is `axial_stiffness_n` instead).
//!
//! ```
//! use sagcal::model::suspended::SuspendedRobot;
//! let eight = SuspendedRobot::builtin("eight")?;
//! assert_eq!((eight.cable_count(), eight.load_cells.clone()), (8, vec![0, 4]));
//! // The paper's large robot, read as N cables: its load cell on its reference cable.
//! let large = SuspendedRobot::builtin("large")?;
//! assert_eq!((large.cable_count(), large.load_cells.clone()), (4, vec![0]));
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::robot_file::{CalibrationEntry, WorkspaceEntry};
use crate::error::{Error, Result};
use crate::model::effects::Effects;
use crate::model::robot::PaperRobot;
use crate::model::suspended::{SuspendedRobot, MIN_CABLES};

/// The most cables a robot file may name.
pub const MAX_CABLES: usize = 8;

/// The built-in robots of any number of cables, compiled into the binary.
pub const BUILTIN_SUSPENDED: [&str; 5] = ["three", "large", "small", "six", "eight"];

/// One cable of an N-cable robot file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CableEntry {
    anchor_m: [f64; 3],
    attachment_m: [f64; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    weight_n_per_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    axial_stiffness_n: Option<f64>,
}

/// The contents of an N-cable robot file, before validation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SuspendedFile {
    name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    paper_robot: Option<PaperRobot>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    reference_cable: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    load_cells: Option<Vec<usize>>,
    platform_weight_n: f64,
    cable_weight_n_per_m: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    axial_stiffness_n: Option<f64>,
    com_offset_m: [f64; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    length_offsets_m: Option<Vec<f64>>,
    cables: Vec<CableEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    workspace: Option<WorkspaceEntry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    effects: Option<Effects>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    calibration: Option<CalibrationEntry>,
}

impl SuspendedFile {
    /// The load cells, 0-based and ascending: `load_cells`, else the
    /// `reference_cable`; each an existing cable, none twice, at least one.
    fn load_cells(&self) -> std::result::Result<Vec<usize>, String> {
        let n = self.cables.len();
        let given =
            match (&self.load_cells, self.reference_cable) {
                (Some(cells), _) => cells.clone(),
                (None, Some(cable)) => vec![cable],
                (None, None) => return Err(
                    "field `load_cells` is missing: list the 1-based cables with a load cell, e.g. `load_cells = [1]`"
                        .into(),
                ),
            };
        if given.is_empty() {
            return Err(
                "field `load_cells`: at least one cable needs a load cell (the tensions' scale comes from it)".into(),
            );
        }
        let mut cells = Vec::with_capacity(given.len());
        for cable in given {
            if cable < 1 || cable > n {
                return Err(format!(
                    "field `load_cells`: cable {cable} does not exist (cables are numbered 1..{n})"
                ));
            }
            if cells.contains(&(cable - 1)) {
                return Err(format!("field `load_cells`: cable {cable} is listed twice"));
            }
            cells.push(cable - 1);
        }
        cells.sort_unstable();
        Ok(cells)
    }

    /// Each cable's weight per metre: its own, else the file's.
    fn cable_weights(&self) -> std::result::Result<Vec<f64>, String> {
        let weigh = |w: f64, field: String| {
            if w.is_finite() && w >= 0.0 {
                Ok(w)
            } else {
                Err(format!("{field} must be >= 0 newtons per metre, got {w}"))
            }
        };
        let shared = weigh(self.cable_weight_n_per_m, "field `cable_weight_n_per_m`".into())?;
        self.cables
            .iter()
            .enumerate()
            .map(|(i, c)| match c.weight_n_per_m {
                Some(w) => weigh(w, format!("cable {}: field `weight_n_per_m`", i + 1)),
                None => Ok(shared),
            })
            .collect()
    }

    /// Each cable's axial stiffness: its own, else the file's, else
    /// inextensible (`f64::INFINITY`); a given one finite and positive.
    fn axial_stiffnesses(&self) -> std::result::Result<Vec<f64>, String> {
        let stiff = |ea: Option<f64>, field: String| match ea {
            None => Ok(None),
            Some(ea) if ea.is_finite() && ea > 0.0 => Ok(Some(ea)),
            Some(ea) => Err(format!(
                "{field} must be a finite EA > 0 newtons (leave it out for an inextensible cable), got {ea}"
            )),
        };
        let shared = stiff(self.axial_stiffness_n, "field `axial_stiffness_n`".into())?;
        self.cables
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let own = stiff(
                    c.axial_stiffness_n,
                    format!("cable {}: field `axial_stiffness_n`", i + 1),
                )?;
                Ok(own.or(shared).unwrap_or(f64::INFINITY))
            })
            .collect()
    }

    /// The validated robot (errors name the field; the caller adds the file).
    fn robot(self) -> std::result::Result<SuspendedRobot, String> {
        let n = self.cables.len();
        if !(MIN_CABLES..=MAX_CABLES).contains(&n) {
            return Err(format!(
                "field `cables`: the file has {n} cables; sagcal models {MIN_CABLES} to {MAX_CABLES}"
            ));
        }
        if self.effects.as_ref().is_some_and(|e| !e.is_none()) {
            return Err(
                "table `effects`: the model of 3 to 8 cables has none of the effects of the catalogue; \
                 remove the table or use a four-cable robot (a known stiffness of the cables is the key \
                 `axial_stiffness_n`, for every cable or in a cable's own table)"
                    .into(),
            );
        }
        let points = self.cables.iter().map(|c| (&c.anchor_m, &c.attachment_m));
        super::robot_file::check_points_and_platform(points, &self.com_offset_m, self.platform_weight_n)?;
        let anchors_m: Vec<Vector3<f64>> = self.cables.iter().map(|c| Vector3::from(c.anchor_m)).collect();
        let attachments_m: Vec<Vector3<f64>> = self.cables.iter().map(|c| Vector3::from(c.attachment_m)).collect();
        super::robot_file::distinct_points(&anchors_m, &attachments_m)?;
        let load_cells = self.load_cells()?;
        let weights = self.cable_weights()?;
        let axial_stiffness_n = self.axial_stiffnesses()?;
        let length_offsets_m = match &self.length_offsets_m {
            None => vec![0.0; n],
            Some(v) if v.len() == n && v.iter().all(|x| x.is_finite()) => v.clone(),
            Some(v) => return Err(format!("field `length_offsets_m` needs {n} finite values, got {v:?}")),
        };
        let workspace = self.workspace.map(WorkspaceEntry::validated).transpose()?;
        let mut robot = SuspendedRobot::new(
            anchors_m,
            attachments_m,
            weights,
            Vector3::from(self.com_offset_m),
            self.platform_weight_n,
        )
        .map_err(|e| e.to_string())?;
        robot.name = self.name;
        robot.load_cells = load_cells;
        robot.length_offsets_m = length_offsets_m;
        robot.axial_stiffness_n = axial_stiffness_n;
        robot.workspace = workspace;
        crate::model::suspended::check_suspended(&robot)?;
        Ok(robot)
    }
}

/// Reading a robot of any number of cables from its file.
impl SuspendedRobot {
    /// Read an N-cable robot TOML file and validate it; errors name the file and the field.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Self::from_text(&text, path)
    }

    /// The built-in robots ([`BUILTIN_SUSPENDED`]): `three`, `six`,
    /// `eight`, and the paper's `large` and `small` read as N cables.
    pub fn builtin(name: &str) -> Result<Self> {
        let text = match name {
            "three" => include_str!("../../robots/three.toml"),
            "six" => include_str!("../../robots/six.toml"),
            "eight" => include_str!("../../robots/eight.toml"),
            "large" => include_str!("../../robots/large.toml"),
            "small" => include_str!("../../robots/small.toml"),
            other => {
                return Err(Error::InvalidInput(format!(
                    "unknown built-in robot `{other}` (known: {})",
                    BUILTIN_SUSPENDED.join(", ")
                )))
            }
        };
        Self::from_text(text, &PathBuf::from(format!("<built-in {name}>")))
    }

    /// The robot as the text of its file (which [`SuspendedRobot::from_file`]
    /// reads back to the same robot), with `covariance_m2` (anchors 1..N
    /// x, y, z, then offsets 1..N; m^2) as its `[calibration]` table if given.
    pub fn to_toml(&self, covariance_m2: Option<&[Vec<f64>]>) -> Result<String> {
        let shared = self.cable_weights_n_per_m.first().copied().unwrap_or(0.0);
        // One stiffness for every cable is written once; otherwise each
        // elastic cable's own, an inextensible cable's left out.
        let first_stiffness = self.axial_stiffness_n.first().copied().unwrap_or(f64::INFINITY);
        let shared_stiffness = self
            .axial_stiffness_n
            .iter()
            .all(|ea| *ea == first_stiffness)
            .then_some(first_stiffness)
            .filter(|ea| ea.is_finite());
        let own_stiffness = |i: usize| {
            let ea = self.axial_stiffness_n[i];
            (shared_stiffness.is_none() && ea.is_finite()).then_some(ea)
        };
        let file = SuspendedFile {
            name: self.name.clone(),
            paper_robot: None,
            reference_cable: None,
            load_cells: Some(self.load_cells.iter().map(|c| c + 1).collect()),
            platform_weight_n: self.platform_weight_n,
            cable_weight_n_per_m: shared,
            axial_stiffness_n: shared_stiffness,
            com_offset_m: self.com_offset_m.into(),
            length_offsets_m: Some(self.length_offsets_m.clone()),
            cables: (0..self.cable_count())
                .map(|i| CableEntry {
                    anchor_m: self.anchors_m[i].into(),
                    attachment_m: self.attachments_m[i].into(),
                    weight_n_per_m: (self.cable_weights_n_per_m[i] != shared).then_some(self.cable_weights_n_per_m[i]),
                    axial_stiffness_n: own_stiffness(i),
                })
                .collect(),
            workspace: self.workspace.map(|w| WorkspaceEntry {
                min_m: w.min_m,
                max_m: w.max_m,
            }),
            effects: None,
            calibration: None,
        };
        let mut text =
            toml::to_string(&file).map_err(|e| Error::InvalidInput(format!("cannot serialise robot: {e}")))?;
        if let Some(covariance) = covariance_m2 {
            text += &format!(
                "\n[calibration]\n# Covariance of the calibrated parameters, m^2: anchors 1..{n} (x, y, z), then offsets 1..{n}.\ncovariance_m2 = [\n",
                n = self.cable_count()
            );
            for row in covariance {
                let cells: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
                text += &format!("    [{}],\n", cells.join(", "));
            }
            text += "]\n";
        }
        Ok(text)
    }

    fn from_text(text: &str, path: &Path) -> Result<Self> {
        let file: SuspendedFile = toml::from_str(text).map_err(|e| Error::Format {
            path: path.to_path_buf(),
            message: format!("not a valid robot file: {e}"),
        })?;
        file.robot().map_err(|message| Error::Robot {
            path: path.to_path_buf(),
            message,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> std::result::Result<SuspendedRobot, String> {
        SuspendedRobot::from_text(text, Path::new("rig.toml")).map_err(|e| e.to_string())
    }

    const SIX: &str = include_str!("../../robots/six.toml");

    #[test]
    fn a_written_robot_reads_back_the_same() {
        for name in ["three", "large", "six", "eight"] {
            let mut robot = SuspendedRobot::builtin(name).unwrap();
            robot.length_offsets_m = (0..robot.cable_count()).map(|i| 0.1 * i as f64 - 0.05).collect();
            robot.cable_weights_n_per_m[1] *= 1.5;
            robot.anchors_m[0].x += 1.0 / 3.0;
            let text = robot.to_toml(None).unwrap();
            assert_eq!(read(&text).unwrap(), robot, "{name}:\n{text}");
            // Elastic cables: one stiffness for all, then one cable inextensible among them.
            let mut elastic = robot.clone();
            elastic.axial_stiffness_n = vec![4.5e6; robot.cable_count()];
            let text = elastic.to_toml(None).unwrap();
            assert_eq!(read(&text).unwrap(), elastic, "{name}:\n{text}");
            elastic.axial_stiffness_n[0] = f64::INFINITY;
            elastic.axial_stiffness_n[2] = 3e6 / 7.0;
            let text = elastic.to_toml(None).unwrap();
            assert_eq!(read(&text).unwrap(), elastic, "{name}:\n{text}");
            let n = 4 * robot.cable_count();
            let covariance: Vec<Vec<f64>> = (0..n)
                .map(|r| (0..n).map(|k| if r == k { 1e-4 } else { 0.0 }).collect())
                .collect();
            let with = robot.to_toml(Some(&covariance)).unwrap();
            assert_eq!(read(&with).unwrap(), robot);
            assert!(with.contains(&format!("anchors 1..{}", robot.cable_count())));
        }
    }

    #[test]
    fn every_builtin_robot_reads() {
        for (name, n) in [("three", 3), ("large", 4), ("small", 4), ("six", 6), ("eight", 8)] {
            let robot = SuspendedRobot::builtin(name).unwrap();
            assert_eq!(robot.cable_count(), n, "{name}");
        }
        let large = crate::model::Robot::builtin("large").unwrap();
        assert_eq!(
            SuspendedRobot::builtin("large").unwrap(),
            SuspendedRobot::from_robot(&large)
        );
    }

    /// The new robots hang their platform in stable equilibrium across their
    /// workspace: at its corners and its centre, level closure, every cable
    /// taut and the stiffness at fixed lengths positive.
    #[test]
    fn the_new_robots_hang_stably_across_their_workspace() {
        use crate::model::suspended::{smallest_stiffness, solve_at, stiffness, Closure, EquilibriumOptions};
        for name in ["three", "six", "eight"] {
            let robot = SuspendedRobot::builtin(name).unwrap();
            let w = robot.workspace.unwrap();
            let mut points: Vec<Vector3<f64>> = (0..8)
                .map(|k| {
                    Vector3::from_fn(|axis, _| {
                        if k >> axis & 1 == 1 {
                            w.max_m[axis]
                        } else {
                            w.min_m[axis]
                        }
                    })
                })
                .collect();
            points.push(Vector3::from_fn(|axis, _| 0.5 * (w.min_m[axis] + w.max_m[axis])));
            for position in points {
                let eq = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default())
                    .unwrap_or_else(|e| panic!("{name} at {position:?}: {e}"));
                let stiffness = smallest_stiffness(&stiffness(&robot, &eq).unwrap());
                let (roll, pitch, yaw) = eq.pose.roll_pitch_yaw_deg();
                println!(
                    "{name} at {:?}: roll {roll:.2} pitch {pitch:.2} yaw {yaw:.2} deg, tensions {:.0}..{:.0} N, stiffness {stiffness:.3e}, {} iterations",
                    position.as_slice(),
                    eq.tensions.iter().map(|t| t.magnitude_n()).fold(f64::INFINITY, f64::min),
                    eq.tensions.iter().map(|t| t.magnitude_n()).fold(0.0, f64::max),
                    eq.iterations
                );
                assert!(stiffness > 0.0, "{name} at {position:?}: unstable ({stiffness})");
            }
        }
    }

    #[test]
    fn per_cable_weights_and_load_cells_are_read() {
        let text = SIX.replacen(
            "attachment_m = [0.766, 0.6428, 0.3]",
            "attachment_m = [0.766, 0.6428, 0.3]\nweight_n_per_m = 5.0",
            1,
        );
        let text = text.replace("load_cells = [1]", "load_cells = [4, 2]");
        let robot = read(&text).unwrap();
        assert_eq!(robot.cable_weights_n_per_m[0], 5.0);
        assert_eq!(robot.cable_weights_n_per_m[1], 3.924);
        assert_eq!(robot.load_cells, vec![1, 3]);
        assert!(!robot.is_elastic());
        let text = text
            .replace("com_offset_m", "axial_stiffness_n = 5e6\ncom_offset_m")
            .replacen(
                "weight_n_per_m = 5.0",
                "weight_n_per_m = 5.0\naxial_stiffness_n = 2e6",
                1,
            );
        let robot = read(&text).unwrap();
        assert_eq!(robot.axial_stiffness_n, [2e6, 5e6, 5e6, 5e6, 5e6, 5e6]);
        assert_eq!(robot.axial_compliance_per_mn(1), 0.2);
    }

    /// Each blunder is refused with the file, the field and the reason.
    #[test]
    fn blunders_name_the_field() {
        let two_cables = {
            let cut = SIX.match_indices("[[cables]]").nth(2).unwrap().0;
            format!(
                "{}\n[workspace]\nmin_m = [-8.0, -8.0, 8.0]\nmax_m = [8.0, 8.0, 16.0]\n",
                &SIX[..cut]
            )
        };
        let nine = format!(
            "{}\n{}",
            SIX.replace("\n[workspace]", "\n[[cables]]\nanchor_m = [0, 30, 25]\nattachment_m = [0, 1, 0.2]\n[[cables]]\nanchor_m = [0, -30, 25]\nattachment_m = [0, -1, 0.2]\n[[cables]]\nanchor_m = [20, 20, 25]\nattachment_m = [0.7, 0.7, 0.2]\n\n[workspace]"),
            ""
        );
        for (text, expected) in [
            (two_cables, "the file has 2 cables; sagcal models 3 to 8"),
            (nine, "the file has 9 cables"),
            (
                SIX.replace("load_cells = [1]", "load_cells = [7]"),
                "cable 7 does not exist (cables are numbered 1..6)",
            ),
            (
                SIX.replace("load_cells = [1]", "load_cells = [2, 2]"),
                "cable 2 is listed twice",
            ),
            (
                SIX.replace("load_cells = [1]", "load_cells = []"),
                "at least one cable needs a load cell",
            ),
            (SIX.replace("load_cells = [1]", ""), "field `load_cells` is missing"),
            (
                SIX.replacen(
                    "attachment_m = [0.766, 0.6428, 0.3]",
                    "attachment_m = [0.766, 0.6428, 0.3]\nweight_n_per_m = -1.0",
                    1,
                ),
                "cable 1: field `weight_n_per_m` must be >= 0",
            ),
            (
                SIX.replace("anchor_m = [-30, 0, 25]", "anchor_m = [30, 0, 25]"),
                "cables 1 and 4: coincident anchors",
            ),
            (
                SIX.replace("min_m = [-8.0, -8.0, 8.0]", "min_m = [-8.0, -8.0, 30.0]"),
                "field `workspace`",
            ),
            (
                format!("{SIX}\n[effects]\naxial_stiffness_n = 3e6\n"),
                "table `effects`",
            ),
            (SIX.replace("com_offset_m", "com_offset"), "not a valid robot file"),
            (
                SIX.replace("com_offset_m", "axial_stiffness_n = 0.0\ncom_offset_m"),
                "field `axial_stiffness_n` must be a finite EA > 0",
            ),
            (
                SIX.replacen(
                    "attachment_m = [0.766, 0.6428, 0.3]",
                    "attachment_m = [0.766, 0.6428, 0.3]\naxial_stiffness_n = -1e6",
                    1,
                ),
                "cable 1: field `axial_stiffness_n` must be a finite EA > 0",
            ),
        ] {
            let message = read(&text).unwrap_err();
            assert!(
                message.contains("rig.toml") && message.contains(expected),
                "{expected}: {message}"
            );
        }
    }
}

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
//! axial_stiffness_n = 3e6          # (written by `simulate --truth`; the calibration ignores it)
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::effects::Effects;

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
    /// (optional; written by `simulate --truth`; the calibration ignores it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effects: Option<Effects>,
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

impl RobotFile {
    /// Read and parse a robot file (no physical validation: see `model::Robot`).
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        toml::from_str(&text).map_err(|e| Error::Format {
            path: path.to_path_buf(),
            message: format!("not a valid robot file: {e}"),
        })
    }

    /// Serialise to TOML text.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string_pretty(self).map_err(|e| Error::InvalidInput(format!("cannot serialise robot: {e}")))
    }
}

//! The text of a new robot file ([`super::robot_init`]): the format of
//! [`crate::io::robot_file`] with a comment above every key saying what it
//! means, its frame, unit and sign.

use crate::io::robot_file::{RobotFile, WorkspaceEntry};

/// What the comments say of how values were given.
#[derive(Debug, Default)]
pub(crate) struct Notes {
    /// ` (4.4 kg x 9.81 m/s^2)` when the platform's weight was given as a mass, else empty.
    pub(crate) platform: String,
    /// The same for the cables' weight per metre.
    pub(crate) cable: String,
    /// The built-in robot the file started from.
    pub(crate) template: Option<String>,
}

/// A float as TOML writes it back bit for bit: always with a `.` or an exponent.
fn number(v: f64) -> String {
    format!("{v:?}")
}

fn point(p: &[f64; 3]) -> String {
    format!("[{}, {}, {}]", number(p[0]), number(p[1]), number(p[2]))
}

/// The robot file's text (the format of [`crate::io::robot_file`]), a
/// comment above every key saying what it means, its frame, unit and sign.
pub(crate) fn commented_text(file: &RobotFile, notes: &Notes) -> String {
    let name = toml::Value::String(file.name.clone()).to_string();
    let mut text = String::new();
    text += "# A robot file for sagcal, written by `sagcal init`";
    if let Some(template) = &notes.template {
        text += &format!(" from the built-in `{template}` robot");
    }
    text += ". What every key means: docs/robot-file.md.\n\
             # Units: metres, newtons. The world frame has z up (against gravity); the platform frame is\n\
             # fixed to the platform, its origin the point whose position the localiser reports.\n\n";
    text += &format!("# The robot's name, printed in reports.\nname = {name}\n\n");
    text += &format!(
        "# The cable whose tension the load cell measures (the f_ref_n column of the measurements),\n\
         # 1-based, in the order of the [[cables]] tables below.\nreference_cable = {}\n\n",
        file.reference_cable
    );
    text += &format!(
        "# Platform weight m_e g, newtons{}, > 0: the platform with its payload,\n\
         # everything the cables carry but the cables themselves.\nplatform_weight_n = {}\n\n",
        notes.platform,
        number(file.platform_weight_n)
    );
    text += &format!(
        "# Cable weight per metre g_c = rho_c g, newtons per metre{}, >= 0\n\
         # (the same for every cable; 0: massless straight cables, no sag).\ncable_weight_n_per_m = {}\n\n",
        notes.cable,
        number(file.cable_weight_n_per_m)
    );
    text += &format!(
        "# The platform's centre of mass (with its payload), platform frame, metres;\n\
         # z < 0 is below the platform frame's origin (a hanging payload keeps the platform level).\n\
         com_offset_m = {}\n",
        point(&file.com_offset_m)
    );
    for (i, cable) in file.cables.iter().enumerate() {
        text += &format!(
            "\n# Cable {k}: from its anchor to its attachment point on the platform.\n[[cables]]\n\
             # Anchor of cable {k}: the point where it leaves its pulley (pulley exit point), world frame, metres.\n\
             anchor_m = {}\n\
             # Attachment point of cable {k} on the platform, platform frame, metres.\nattachment_m = {}\n",
            point(&cable.anchor_m),
            point(&cable.attachment_m),
            k = i + 1
        );
    }
    text += &workspace_text(file.workspace.as_ref());
    if let Some(ea) = file.effects.and_then(|e| e.axial_stiffness_n) {
        text += &format!(
            "\n# Effects beyond the closed-form model, known: calibrate holds them fixed, localize and verify apply them.\n\
             [effects]\n\
             # Axial stiffness EA of every cable (Young's modulus x cross-section), newtons, > 0:\n\
             # a cable of length L under tension T is longer by about L T / EA (absent: inextensible).\n\
             axial_stiffness_n = {}\n",
            number(ea)
        );
    }
    text
}

fn workspace_text(workspace: Option<&WorkspaceEntry>) -> String {
    match workspace {
        Some(w) => format!(
            "\n# Where the platform goes during calibration: a box of platform-origin positions, world frame;\n\
             # `plan` and `simulate` draw poses in it. Its top must be below the lowest anchor.\n[workspace]\n\
             # Lower corner (x, y, z), world frame, metres.\nmin_m = {}\n\
             # Upper corner (x, y, z), world frame, metres.\nmax_m = {}\n",
            point(&w.min_m),
            point(&w.max_m)
        ),
        None => "\n# No [workspace]: `plan` and `simulate` draw poses from a box under the anchors derived from them\n\
                 # (`sagcal check --robot FILE` prints it); add a [workspace] table with min_m and max_m to choose it.\n"
            .to_string(),
    }
}

//! The catalogue of effects as hypotheses: [`EffectKind`] names one effect
//! of [`crate::model::effects::Effects`] as a model extension `sagcal
//! diagnose` can fit (its parameters, their units and neutral values), and
//! [`EffectSet`] a set of them fitted at once.
//!
//! ```
//! use sagcal::model::effect_kind::{EffectKind, EffectSet};
//! use sagcal::model::effects::Effects;
//! let mut effects = Effects::default();
//! effects.apply_spec("platform-weight:scale=1.1")?;
//! let kind = EffectKind::parse("platform-weight")?;
//! // Reported as the scale, fitted as its error.
//! assert_eq!(kind.parameters(&effects), vec![1.1]);
//! assert!((kind.variable_values(&effects)[0] - 0.1).abs() < 1e-12);
//! assert!(kind.present_in(&effects) && !EffectKind::CableWeight.present_in(&effects));
//! let set: EffectSet = [EffectKind::Com, kind].into_iter().collect();
//! assert_eq!(set.to_string(), "com+platform-weight");
//! assert_eq!(set.parameter_count(), 3);
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::error::ParseError;

use crate::model::effects::Effects;
use crate::model::robot::CABLE_COUNT;

/// One effect of the catalogue, as a model extension `sagcal diagnose` can fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EffectKind {
    /// Finite axial stiffness (Irvine's elastic catenary); parameter the compliance `1e6 / EA` (1/MN).
    Elastic,
    /// Pulley radius (exit-point motion and wrapped arc); parameter `r`.
    Pulley,
    /// Per-cable encoder gain (drum radius error); four parameters.
    EncoderScale,
    /// Bias and gain of the reference cable's load cell; two parameters.
    LoadCell,
    /// Horizontal centre-of-mass shift from the nominal one; two parameters
    /// (a vertical shift is not identifiable from nearly level poses).
    Com,
    /// One encoder gain shared by the four drums (a common drum-radius or
    /// counts-per-metre error); one parameter. Nested in [`EffectKind::EncoderScale`].
    CommonGain,
    /// The cable as a chain of `n` straight finite elements; one parameter, `1/n^2`.
    Segments,
    /// The localiser's mounting rotation (a rotation vector, degrees); three
    /// parameters shared by every pose. Nested in freeing every pose's
    /// orientation (`sagcal diagnose`'s `orientation` hypothesis).
    LocaliserMount,
    /// The platform's weight (an unmodelled payload); one parameter, the
    /// scale of the robot file's weight.
    PlatformWeight,
    /// The cables' weight per metre (a wrong cable specification); one
    /// parameter, the scale of the robot file's weight per metre.
    CableWeight,
    /// Per-drum creep of the encoder readings with the row; four parameters,
    /// millimetres per row. Needs rows in time order ([`EffectKind::needs_time_order`]).
    EncoderDrift,
    /// Per-drum backlash: the reading `+b` off after paying out, `-b` after
    /// reeling in; four parameters, millimetres. Needs rows in time order.
    EncoderBacklash,
    /// Creep of the load cell's zero with the row; one parameter, newtons
    /// per row. Needs rows in time order.
    LoadCellDrift,
    /// Friction of a pulley between the cable and a drum-side load cell
    /// (reading `T (1 - k s)`); one parameter `k = mu theta`. Needs rows in time order.
    LoadCellFriction,
    /// Each cable's attachment point moved horizontally from the robot
    /// file's (platform frame); eight parameters, metres.
    Attachments,
}

impl EffectKind {
    /// Every effect of the catalogue, in report order.
    pub const ALL: [EffectKind; 15] = [
        EffectKind::Elastic,
        EffectKind::Pulley,
        EffectKind::EncoderScale,
        EffectKind::LoadCell,
        EffectKind::Com,
        EffectKind::CommonGain,
        EffectKind::Segments,
        EffectKind::LocaliserMount,
        EffectKind::PlatformWeight,
        EffectKind::CableWeight,
        EffectKind::EncoderDrift,
        EffectKind::EncoderBacklash,
        EffectKind::LoadCellDrift,
        EffectKind::LoadCellFriction,
        EffectKind::Attachments,
    ];

    /// The name used on the command line and in reports (`elastic`, `encoder-scale`, ...).
    pub fn name(self) -> &'static str {
        match self {
            EffectKind::Elastic => "elastic",
            EffectKind::Pulley => "pulley",
            EffectKind::EncoderScale => "encoder-scale",
            EffectKind::LoadCell => "loadcell",
            EffectKind::Com => "com",
            EffectKind::CommonGain => "encoder-gain",
            EffectKind::Segments => "segments",
            EffectKind::LocaliserMount => "localiser-mount",
            EffectKind::PlatformWeight => "platform-weight",
            EffectKind::CableWeight => "cable-weight",
            EffectKind::EncoderDrift => "encoder-drift",
            EffectKind::EncoderBacklash => "encoder-backlash",
            EffectKind::LoadCellDrift => "loadcell-drift",
            EffectKind::LoadCellFriction => "loadcell-friction",
            EffectKind::Attachments => "attachments",
        }
    }

    /// Parse [`EffectKind::name`].
    pub fn parse(text: &str) -> Result<Self, ParseError> {
        Self::ALL.into_iter().find(|k| k.name() == text.trim()).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|k| k.name()).collect();
            ParseError::UnknownChoice {
                what: "effect",
                given: text.to_string(),
                choices: format!(" (effects: {})", names.join(", ")),
            }
        })
    }

    /// Names of the fitted parameters, in the order of [`EffectKind::parameters`].
    pub fn parameter_names(self) -> &'static [&'static str] {
        match self {
            EffectKind::Elastic => &["compliance_per_mn"],
            EffectKind::Pulley => &["radius_m"],
            EffectKind::EncoderScale => &["gain1", "gain2", "gain3", "gain4"],
            EffectKind::LoadCell => &["bias_n", "gain"],
            EffectKind::Com => &["dx_m", "dy_m"],
            EffectKind::CommonGain => &["gain"],
            EffectKind::Segments => &["inverse_segments_squared"],
            EffectKind::LocaliserMount => &["rx_deg", "ry_deg", "rz_deg"],
            EffectKind::PlatformWeight | EffectKind::CableWeight => &["scale"],
            EffectKind::EncoderDrift => &[
                "drift1_mm_per_row",
                "drift2_mm_per_row",
                "drift3_mm_per_row",
                "drift4_mm_per_row",
            ],
            EffectKind::EncoderBacklash => &["backlash1_mm", "backlash2_mm", "backlash3_mm", "backlash4_mm"],
            EffectKind::LoadCellDrift => &["drift_n_per_row"],
            EffectKind::LoadCellFriction => &["friction"],
            EffectKind::Attachments => &["dx1_m", "dy1_m", "dx2_m", "dy2_m", "dx3_m", "dy3_m", "dx4_m", "dy4_m"],
        }
    }

    /// Number of fitted parameters.
    pub fn parameter_count(self) -> usize {
        self.parameter_names().len()
    }

    /// This effect's parameters in `effects`, in the units of
    /// [`EffectKind::parameter_names`] (compliance 0 for an inextensible cable).
    pub fn parameters(self, effects: &Effects) -> Vec<f64> {
        match self {
            EffectKind::Elastic => vec![effects.axial_compliance_per_mn()],
            EffectKind::Pulley => vec![effects.pulley_radius_m],
            EffectKind::EncoderScale => effects.encoder_gain.to_vec(),
            EffectKind::LoadCell => vec![effects.load_cell_bias_n, effects.load_cell_gain],
            EffectKind::Com => effects.com_shift_m[..2].to_vec(),
            EffectKind::CommonGain => vec![effects.encoder_gain.iter().sum::<f64>() / CABLE_COUNT as f64],
            EffectKind::Segments => vec![effects.inverse_segments_squared()],
            EffectKind::LocaliserMount => effects.localiser_mount_deg.to_vec(),
            EffectKind::PlatformWeight => vec![effects.platform_weight_scale],
            EffectKind::CableWeight => vec![effects.cable_weight_scale],
            EffectKind::EncoderDrift => effects.encoder_drift_m_per_row.map(|d| d * 1e3).to_vec(),
            EffectKind::EncoderBacklash => effects.encoder_backlash_m.map(|b| b * 1e3).to_vec(),
            EffectKind::LoadCellDrift => vec![effects.load_cell_drift_n_per_row],
            EffectKind::LoadCellFriction => vec![effects.load_cell_friction],
            EffectKind::Attachments => effects.attachment_shift_m.iter().flatten().copied().collect(),
        }
    }

    /// This effect's parameters in `effects` in the units of the extended
    /// model's variables: gains and weight scales as errors (`gain - 1`), the
    /// elastic cable as its compliance in 1/MN, the segmented cable as `1/n^2`.
    pub fn variable_values(self, effects: &Effects) -> Vec<f64> {
        let parameters = self.parameters(effects);
        parameters
            .iter()
            .enumerate()
            .map(|(i, p)| if self.is_scale(i) { p - 1.0 } else { *p })
            .collect()
    }

    /// Whether parameter `index` is a scale: reported as the scale (1:
    /// exact), fitted as its error `scale - 1` (encoder and load-cell gains,
    /// weight scales).
    pub fn is_scale(self, index: usize) -> bool {
        match self {
            EffectKind::EncoderScale
            | EffectKind::CommonGain
            | EffectKind::PlatformWeight
            | EffectKind::CableWeight => true,
            EffectKind::LoadCell => index == 1,
            _ => false,
        }
    }

    /// Whether `effects` contains this effect (a parameter away from its
    /// neutral value). Encoder gains count as the common gain when the four
    /// are equal and as per-drum gains otherwise.
    pub fn present_in(self, effects: &Effects) -> bool {
        let gains = effects.encoder_gain;
        let common = gains.iter().all(|g| *g == gains[0]);
        match self {
            EffectKind::EncoderScale => !common,
            EffectKind::CommonGain => common && gains[0] != 1.0,
            _ => self.parameters(effects) != self.parameters(&Effects::default()),
        }
    }

    /// Whether the effect lives in time and motion: its readings depend on
    /// the row or the direction of last motion, which only rows in the
    /// order the robot took them carry ([`crate::model::measurement::ReadingOrder`]).
    pub fn needs_time_order(self) -> bool {
        matches!(
            self,
            EffectKind::EncoderDrift
                | EffectKind::EncoderBacklash
                | EffectKind::LoadCellDrift
                | EffectKind::LoadCellFriction
        )
    }

    /// The effect that contains this one as a special case, if any: the
    /// common encoder gain is the per-drum gains with four equal values; a
    /// centre-of-mass shift is, to within the platform's small tilts and
    /// turns, the four attachments moved together the other way (the anchors
    /// take up their moved ends; `diagnose` keeps the shift unless the data
    /// reject it).
    pub fn nested_in(self) -> Option<EffectKind> {
        match self {
            EffectKind::CommonGain => Some(EffectKind::EncoderScale),
            EffectKind::Com => Some(EffectKind::Attachments),
            _ => None,
        }
    }
}

/// A set of effects of the catalogue (for an extended model with several at once).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct EffectSet(u16);

impl EffectSet {
    /// No effect.
    pub const NONE: EffectSet = EffectSet(0);

    /// The set holding `kind` alone.
    pub fn of(kind: EffectKind) -> Self {
        Self::NONE.with(kind)
    }

    /// This set and `kind`.
    pub fn with(self, kind: EffectKind) -> Self {
        Self(self.0 | 1 << kind as u16)
    }

    /// This set without `kind`.
    pub fn without(self, kind: EffectKind) -> Self {
        Self(self.0 & !(1 << kind as u16))
    }

    /// Whether `kind` is in the set.
    pub fn contains(self, kind: EffectKind) -> bool {
        self.0 & (1 << kind as u16) != 0
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The effects in catalogue order.
    pub fn iter(self) -> impl Iterator<Item = EffectKind> {
        EffectKind::ALL.into_iter().filter(move |k| self.contains(*k))
    }

    /// Number of fitted parameters of all the set's effects.
    pub fn parameter_count(self) -> usize {
        self.iter().map(EffectKind::parameter_count).sum()
    }
}

impl std::fmt::Display for EffectSet {
    /// The names joined by `+` in catalogue order, or `none`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.is_empty() {
            return f.write_str("none");
        }
        let names: Vec<&str> = self.iter().map(EffectKind::name).collect();
        f.write_str(&names.join("+"))
    }
}

impl FromIterator<EffectKind> for EffectSet {
    fn from_iter<I: IntoIterator<Item = EffectKind>>(kinds: I) -> Self {
        kinds.into_iter().fold(Self::NONE, Self::with)
    }
}

impl std::fmt::Display for EffectKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

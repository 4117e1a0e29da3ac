//! Physical effects beyond the closed-form catenary model.
//!
//! sagcal's calibration model ([`crate::model::catenary`],
//! [`crate::model::statics`]) has inextensible cables leaving point anchors,
//! ideal encoders and load cell, and a known centre of mass. [`Effects`]
//! describes what a real robot may add; `sagcal simulate --effect` generates
//! data with them through the discretised simulator
//! ([`crate::sim::effects::measure_with_effects`]) so the calibration's
//! sensitivity to model mismatch can be studied. A robot file's `[effects]`
//! are known inputs of the extended model: the calibration holds them fixed
//! (unless it estimates them), the localisation and `verify` apply them.
//!
//! Each effect is given on the command line as `NAME:PARAM=VALUE[,PARAM=VALUE...]`
//! ([`Effects::apply_spec`]):
//!
//! | effect | parameters |
//! |---|---|
//! | `elastic` | `ea_n` (axial stiffness EA, N, > 0) |
//! | `pulley` | `radius_m` (pulley radius, m, >= 0) |
//! | `encoder-scale` | `gain` (all four encoders) or `gain1` .. `gain4` (> 0) |
//! | `loadcell` | `bias_n` (N), `gain` (> 0) |
//! | `com` | `dx_m`, `dy_m`, `dz_m` (platform frame, m) |
//! | `segments` | `n` (number of straight elements of a finite-element cable, >= 1) |
//! | `localiser-mount` | `rx_deg`, `ry_deg`, `rz_deg` (the localiser's mounting rotation, a rotation vector in the platform frame, degrees) |
//! | `platform-weight` | `scale` (the platform's true weight over the robot file's `platform_weight_n`, > 0) |
//! | `cable-weight` | `scale` (the cables' true weight per metre over the robot file's `cable_weight_n_per_m`, > 0) |
//! | `encoder-drift` | `rate_m` (all four drums) or `rate1_m` .. `rate4_m` (the reading's creep, m per row) |
//! | `encoder-backlash` | `b_m` (all four drums) or `b1_m` .. `b4_m` (the reading's shift when the cable was last paid out, m; minus when reeled in) |
//! | `loadcell-drift` | `rate_n` (the load cell's creep, N per row) |
//! | `loadcell-friction` | `k` (friction `mu theta` of a pulley between the cable and a drum-side load cell, 0 <= k < 1) |
//! | `attachments` | `dx1_m`, `dy1_m` .. `dx4_m`, `dy4_m` (each cable's attachment point moved horizontally from the robot file's, platform frame, m) |
//!
//! The last four live in time and motion ([`crate::model::measurement::ReadingOrder`]):
//! a pose's readings depend on its row and on the direction each cable last
//! moved in ([`Effects::time_and_motion`]).
//!
//! ```
//! use sagcal::model::effect_kind::EffectKind;
//! use sagcal::model::effects::Effects;
//! let mut effects = Effects::default();
//! effects.apply_spec("elastic:ea_n=2e6")?;
//! effects.apply_spec("encoder-scale:gain1=1.002,gain3=0.999")?;
//! // EA = 2 MN is a compliance 1e6 / EA of 0.5 per MN, the parameter diagnose fits.
//! assert_eq!(effects.axial_compliance_per_mn(), 0.5);
//! assert!(EffectKind::Elastic.present_in(&effects) && EffectKind::EncoderScale.present_in(&effects));
//! assert!(!EffectKind::Pulley.present_in(&effects));
//! // `specs` writes what `apply_spec` reads.
//! let mut again = Effects::default();
//! for spec in effects.specs() {
//!     again.apply_spec(&spec)?;
//! }
//! assert_eq!(again, effects);
//! assert!(Effects::default().apply_spec("elastic:ea_n=-1").is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::model::cables::CABLE_COUNT;
use crate::model::measurement::{PoseMeasurement, ReadingOrder};

/// Effects acting on a robot beyond the closed-form model. [`Default`]: none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    /// Axial stiffness `EA` of every cable, newtons (`elastic:ea_n`); `None`: inextensible.
    ///
    /// An elastic cable is Irvine's elastic catenary: an element of unstretched
    /// length `ds` under tension `T` is `ds (1 + T / EA)` long, so the cable's
    /// free span is longer than its paid-out (unstretched) length by about
    /// `L T / EA` and the platform hangs lower than the inextensible model puts it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axial_stiffness_n: Option<f64>,
    /// Pulley radius `r`, metres (`pulley:radius_m`); 0: the cable leaves at the anchor point.
    ///
    /// Pulley wrap geometry: the pulley swivels about the vertical axis through
    /// the anchor, the cable enters the groove at the anchor, wraps over the top
    /// and leaves tangentially; the exit point moves with the cable's direction
    /// (by up to `2 r` from the anchor) and the wrapped arc `r wrap` is paid out
    /// but not part of the free span.
    pub pulley_radius_m: f64,
    /// Encoder scale factor per cable (`encoder-scale:gain` for all four, or `gain1` .. `gain4`); 1: exact.
    ///
    /// A drum radius error: an encoder counting drum revolutions reads
    /// `gain * paid_out` with `gain = r_true / r_nominal`.
    pub encoder_gain: [f64; CABLE_COUNT],
    /// Load-cell bias, newtons (`loadcell:bias_n`): the reading is `bias + gain * |T_ref|`.
    ///
    /// A zero-point error of the load cell on the reference cable.
    pub load_cell_bias_n: f64,
    /// Load-cell gain (`loadcell:gain`), 1: exact.
    ///
    /// A calibration (sensitivity) error of the load cell on the reference cable.
    pub load_cell_gain: f64,
    /// Shift of the centre of mass from the robot's `com_offset_m`, platform frame, metres (`com:dx_m,dy_m,dz_m`).
    ///
    /// A centre of mass offset: the payload's true centre of mass differs from
    /// the nominal one, which tilts the platform and redistributes the tensions.
    pub com_shift_m: [f64; 3],
    /// Number `n` of straight elements of a finite-element cable (`segments:n`); `None`: the smooth cable.
    ///
    /// A cable modelled as `n` straight elements with lumped node weights (a
    /// finite-element discretisation, as in RecurDyn's cables or sagcal's
    /// discretised simulator) spans its geometry with a length that differs
    /// from the smooth catenary's by a term of order `1/n^2` (the midpoint
    /// rule's error, `codegen/cable_model.py::segmented_chain`); the fitted
    /// parameter is `1/n^2`, continuous.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cable_segments: Option<f64>,
    /// The localiser's mounting rotation as a rotation vector `m` in the
    /// platform frame, degrees (`localiser-mount:rx_deg,ry_deg,rz_deg`); 0: aligned.
    ///
    /// A localiser fixed to the platform with its axes turned by `M = Exp(m)`
    /// reports the orientation of its own body, `R M` instead of the
    /// platform's `R`: one rotation shared by every pose, a structured fault
    /// of the orientation readings (`codegen/factors.py::mounted_pose_prior_residual`).
    #[serde(skip_serializing_if = "is_zero3")]
    pub localiser_mount_deg: [f64; 3],
    /// The platform's true weight over the robot file's `platform_weight_n`
    /// (`platform-weight:scale`); 1: as the file says.
    ///
    /// An unmodelled payload (or a tool taken off): the gravity wrench of
    /// paper eq. (9) scales, and with it every tension.
    #[serde(skip_serializing_if = "is_one")]
    pub platform_weight_scale: f64,
    /// The cables' true weight per metre over the robot file's
    /// `cable_weight_n_per_m` (`cable-weight:scale`); 1: as the file says.
    ///
    /// A wrong cable specification (another diameter, a coating): the sag
    /// parameter `lambda = w L / f_h` of the catenary (eq. 2-3) scales.
    #[serde(skip_serializing_if = "is_one")]
    pub cable_weight_scale: f64,
    /// Per drum (robot order), the encoder reading's creep, metres per row
    /// (`encoder-drift:rate_m`): a reading taken at row `k` is off by `k` x
    /// the rate (slip of the rope on its drum, a counter losing counts).
    #[serde(skip_serializing_if = "is_zero4")]
    pub encoder_drift_m_per_row: [f64; CABLE_COUNT],
    /// Per drum, half the dead band between the encoder and the drum, metres
    /// (`encoder-backlash:b_m`): the reading is `+b` off after the cable was
    /// paid out and `-b` off after it was reeled in (gear backlash, an
    /// encoder on the motor's side of the gearbox).
    #[serde(skip_serializing_if = "is_zero4")]
    pub encoder_backlash_m: [f64; CABLE_COUNT],
    /// The load cell's creep, newtons per row (`loadcell-drift:rate_n`): a
    /// zero point that wanders with time (temperature, creep of the gauge).
    #[serde(skip_serializing_if = "is_zero")]
    pub load_cell_drift_n_per_row: f64,
    /// Friction `k = mu theta` of a pulley between the cable and a load cell
    /// on the drum's side (`loadcell-friction:k`).
    ///
    /// By the capstan (Euler-Eytelwein) relation the drum-side tension is
    /// `T exp(-mu theta s)` of the platform-side `T`, `s = +1` after the cable
    /// was paid out (friction holds against the platform) and `-1` after it
    /// was reeled in; to first order the load cell reads `T (1 - k s)`.
    /// Physically `k >= 0`.
    #[serde(skip_serializing_if = "is_zero")]
    pub load_cell_friction: f64,
    /// Per cable (robot order), its attachment point's horizontal move from
    /// the robot file's, `[dx, dy]` in the platform frame, metres
    /// (`attachments:dx1_m,dy1_m,...`): an eyelet drilled or a shackle hung
    /// off the drawing. It moves the cable's end and its moment arm about
    /// the platform (eq. 9-11).
    #[serde(skip_serializing_if = "is_zero42")]
    pub attachment_shift_m: [[f64; 2]; CABLE_COUNT],
}

/// What time and motion add to one pose's readings ([`Effects::time_and_motion`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeAndMotion {
    /// Added to each encoder reading (robot order), metres.
    pub encoder_shift_m: [f64; CABLE_COUNT],
    /// Added to the load cell's reading, newtons.
    pub load_cell_shift_n: f64,
    /// Multiplies the load cell's tension term (`1 - k s`).
    pub load_cell_factor: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn is_zero4(v: &[f64; CABLE_COUNT]) -> bool {
    v.iter().all(|x| *x == 0.0)
}

fn is_zero42(v: &[[f64; 2]; CABLE_COUNT]) -> bool {
    v.iter().flatten().all(|x| *x == 0.0)
}

fn is_one(x: &f64) -> bool {
    *x == 1.0
}

fn is_zero3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| *x == 0.0)
}

impl Default for Effects {
    /// No effect: inextensible cables, point pulleys, exact sensors, the nominal centre of mass.
    fn default() -> Self {
        Self {
            axial_stiffness_n: None,
            pulley_radius_m: 0.0,
            encoder_gain: [1.0; CABLE_COUNT],
            load_cell_bias_n: 0.0,
            load_cell_gain: 1.0,
            com_shift_m: [0.0; 3],
            cable_segments: None,
            localiser_mount_deg: [0.0; 3],
            platform_weight_scale: 1.0,
            cable_weight_scale: 1.0,
            encoder_drift_m_per_row: [0.0; CABLE_COUNT],
            encoder_backlash_m: [0.0; CABLE_COUNT],
            load_cell_drift_n_per_row: 0.0,
            load_cell_friction: 0.0,
            attachment_shift_m: [[0.0; 2]; CABLE_COUNT],
        }
    }
}

impl Effects {
    /// The cables' axial compliance `1e6 / EA` in 1/MN (0: inextensible), the
    /// parameter the extended model fits.
    pub fn axial_compliance_per_mn(&self) -> f64 {
        self.axial_stiffness_n.map_or(0.0, |ea| 1e6 / ea)
    }

    /// `1 / n^2` of a finite-element cable of `n` elements (0: the smooth
    /// cable), the parameter the extended model fits.
    pub fn inverse_segments_squared(&self) -> f64 {
        self.cable_segments.map_or(0.0, |n| 1.0 / (n * n))
    }

    /// True when no effect is present (the closed-form model describes the robot).
    pub fn is_none(&self) -> bool {
        *self == Self::default()
    }

    /// Check values read from a file: the same rules as [`Effects::apply_spec`].
    pub fn validate(&self) -> Result<(), String> {
        if let Some(ea) = self.axial_stiffness_n {
            if !(ea.is_finite() && ea > 0.0) {
                return Err(format!("`axial_stiffness_n` must be a finite EA > 0 N, got {ea}"));
            }
        }
        if !(self.pulley_radius_m.is_finite() && self.pulley_radius_m >= 0.0) {
            return Err(format!(
                "`pulley_radius_m` must be finite and >= 0, got {}",
                self.pulley_radius_m
            ));
        }
        if let Some(g) = self.encoder_gain.iter().find(|g| !(g.is_finite() && **g > 0.0)) {
            return Err(format!("`encoder_gain` must be finite and > 0, got {g}"));
        }
        if !self.load_cell_bias_n.is_finite() {
            return Err(format!(
                "`load_cell_bias_n` must be finite, got {}",
                self.load_cell_bias_n
            ));
        }
        if !(self.load_cell_gain.is_finite() && self.load_cell_gain > 0.0) {
            return Err(format!(
                "`load_cell_gain` must be finite and > 0, got {}",
                self.load_cell_gain
            ));
        }
        if !self.com_shift_m.iter().all(|x| x.is_finite()) {
            return Err(format!("`com_shift_m` must be finite, got {:?}", self.com_shift_m));
        }
        if let Some(n) = self.cable_segments {
            if !(n.is_finite() && n >= 1.0) {
                return Err(format!("`cable_segments` must be a finite number >= 1, got {n}"));
            }
        }
        if !self.localiser_mount_deg.iter().all(|x| x.is_finite()) {
            return Err(format!(
                "`localiser_mount_deg` must be finite, got {:?}",
                self.localiser_mount_deg
            ));
        }
        for (name, scale) in [
            ("platform_weight_scale", self.platform_weight_scale),
            ("cable_weight_scale", self.cable_weight_scale),
        ] {
            if !(scale.is_finite() && scale > 0.0) {
                return Err(format!("`{name}` must be finite and > 0, got {scale}"));
            }
        }
        for (name, values) in [
            ("encoder_drift_m_per_row", self.encoder_drift_m_per_row),
            ("encoder_backlash_m", self.encoder_backlash_m),
        ] {
            if !values.iter().all(|x| x.is_finite()) {
                return Err(format!("`{name}` must be finite, got {values:?}"));
            }
        }
        if !self.load_cell_drift_n_per_row.is_finite() {
            return Err(format!(
                "`load_cell_drift_n_per_row` must be finite, got {}",
                self.load_cell_drift_n_per_row
            ));
        }
        if !self.attachment_shift_m.iter().flatten().all(|x| x.is_finite()) {
            return Err(format!(
                "`attachment_shift_m` must be finite, got {:?}",
                self.attachment_shift_m
            ));
        }
        if !(0.0..1.0).contains(&self.load_cell_friction) {
            return Err(format!(
                "`load_cell_friction` must be >= 0 and < 1, got {}",
                self.load_cell_friction
            ));
        }
        Ok(())
    }

    /// What the time-and-motion effects add to the readings of the pose at
    /// `order` whose load cell reads `reference_cable` (robot order): encoder
    /// `i` gains `rate_i row + b_i s_i`, the load cell reads
    /// `bias + gain (1 - k s_ref) T + rate row` ([`Effects::load_cell_friction`]),
    /// `s` the direction of last motion.
    pub fn time_and_motion(&self, order: &ReadingOrder, reference_cable: usize) -> TimeAndMotion {
        let row = order.row as f64;
        let direction = order.direction.map(f64::from);
        TimeAndMotion {
            encoder_shift_m: std::array::from_fn(|i| {
                self.encoder_drift_m_per_row[i] * row + self.encoder_backlash_m[i] * direction[i]
            }),
            load_cell_shift_n: self.load_cell_drift_n_per_row * row,
            load_cell_factor: 1.0 - self.load_cell_friction * direction[reference_cable.min(CABLE_COUNT - 1)],
        }
    }
}

impl Effects {
    /// `m`'s readings as they would be without the effects of time and
    /// motion ([`Effects::time_and_motion`]): each encoder less its shift, the
    /// load cell's tension term divided by the friction's factor. A pose
    /// without an order is returned as it is.
    pub fn without_time_and_motion(&self, m: &PoseMeasurement, reference_cable: usize) -> PoseMeasurement {
        let Some(order) = m.order else {
            return *m;
        };
        let now = self.time_and_motion(&order, reference_cable);
        let tension_term = m.reference_tension_n - self.load_cell_bias_n - now.load_cell_shift_n;
        PoseMeasurement {
            encoder_lengths_m: std::array::from_fn(|i| m.encoder_lengths_m[i] - now.encoder_shift_m[i]),
            reference_tension_n: self.load_cell_bias_n + tension_term / now.load_cell_factor,
            ..*m
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(specs: &[&str]) -> Result<Effects, crate::error::EffectSpecError> {
        Effects::from_specs(specs)
    }

    #[test]
    fn default_is_none() {
        assert!(Effects::default().is_none());
        assert_eq!(Effects::default().to_string(), "none");
        assert!(!parsed(&["loadcell:bias_n=0.5"]).unwrap().is_none());
    }

    #[test]
    fn toml_round_trip_and_validation() {
        let e = parsed(&[
            "elastic:ea_n=3e6",
            "com:dy_m=0.01",
            "encoder-drift:rate3_m=-1e-4",
            "encoder-backlash:b_m=0.002",
            "loadcell-drift:rate_n=0.4",
            "loadcell-friction:k=0.03",
            "attachments:dx2_m=0.01,dy3_m=-0.005",
        ])
        .unwrap();
        let text = toml::to_string(&e).unwrap();
        assert_eq!(toml::from_str::<Effects>(&text).unwrap(), e);
        // A robot file's `[effects]` with a friction no pulley has is refused by name.
        let seized: Effects = toml::from_str("load_cell_friction = 1.5").unwrap();
        assert!(seized.validate().unwrap_err().contains("load_cell_friction"));
        let shifted: Effects =
            toml::from_str("attachment_shift_m = [[0.01, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]").unwrap();
        assert_eq!(shifted.attachment_shift_m[0], [0.01, 0.0]);
        let partial: Effects = toml::from_str("pulley_radius_m = 0.1").unwrap();
        assert_eq!(partial.pulley_radius_m, 0.1);
        assert_eq!(partial.encoder_gain, [1.0; 4]);
        assert!(toml::from_str::<Effects>("radius = 0.1").is_err());
        let bad = Effects {
            load_cell_gain: 0.0,
            ..Effects::default()
        };
        assert!(bad.validate().unwrap_err().contains("load_cell_gain"));
        assert!(e.validate().is_ok());
    }
}

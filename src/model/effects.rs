//! Physical effects beyond the closed-form catenary model.
//!
//! sagcal's calibration model ([`crate::model::catenary`],
//! [`crate::model::statics`]) has inextensible cables leaving point anchors,
//! ideal encoders and load cell, and a known centre of mass. [`Effects`]
//! describes what a real robot may add; `sagcal simulate --effect` generates
//! data with them through the discretised simulator
//! ([`crate::sim::effects::measure_with_effects`]) so the calibration's
//! sensitivity to model mismatch can be studied. The calibration ignores them.
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
//!
//! The last four live in time and motion ([`crate::model::measurement::ReadingOrder`]):
//! a pose's readings depend on its row and on the direction each cable last
//! moved in ([`Effects::time_and_motion`]).
//!
//! ```
//! use sagcal::model::effect_kind::EffectKind;
//! use sagcal::model::effects::Effects;
//! let mut effects = Effects::default();
//! effects.apply_spec("elastic:ea_n=2e6").map_err(sagcal::Error::InvalidInput)?;
//! effects.apply_spec("encoder-scale:gain1=1.002,gain3=0.999").map_err(sagcal::Error::InvalidInput)?;
//! // EA = 2 MN is a compliance 1e6 / EA of 0.5 per MN, the parameter diagnose fits.
//! assert_eq!(effects.axial_compliance_per_mn(), 0.5);
//! assert!(EffectKind::Elastic.present_in(&effects) && EffectKind::EncoderScale.present_in(&effects));
//! assert!(!EffectKind::Pulley.present_in(&effects));
//! // `specs` writes what `apply_spec` reads.
//! let mut again = Effects::default();
//! for spec in effects.specs() {
//!     again.apply_spec(&spec).map_err(sagcal::Error::InvalidInput)?;
//! }
//! assert_eq!(again, effects);
//! assert!(Effects::default().apply_spec("elastic:ea_n=-1").is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::model::measurement::{PoseMeasurement, ReadingOrder};
use crate::model::robot::CABLE_COUNT;

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
        }
    }
}

/// The effect names accepted by [`Effects::apply_spec`], with their parameters.
pub const EFFECT_NAMES: &str =
    "elastic:ea_n, pulley:radius_m, encoder-scale:gain|gain1..gain4, loadcell:bias_n,gain, com:dx_m,dy_m,dz_m, segments:n, localiser-mount:rx_deg,ry_deg,rz_deg, platform-weight:scale, cable-weight:scale, encoder-drift:rate_m|rate1_m..rate4_m, encoder-backlash:b_m|b1_m..b4_m, loadcell-drift:rate_n, loadcell-friction:k";

/// The parameters [`Effects::apply_spec`] accepts for the effect `name`; `None` for no effect.
fn spec_parameters(name: &str) -> Option<&'static [&'static str]> {
    Some(match name {
        "elastic" => &["ea_n"],
        "pulley" => &["radius_m"],
        "encoder-scale" => &["gain", "gain1", "gain2", "gain3", "gain4"],
        "loadcell" => &["bias_n", "gain"],
        "com" => &["dx_m", "dy_m", "dz_m"],
        "segments" => &["n"],
        "localiser-mount" => &["rx_deg", "ry_deg", "rz_deg"],
        "platform-weight" | "cable-weight" => &["scale"],
        "encoder-drift" => &["rate_m", "rate1_m", "rate2_m", "rate3_m", "rate4_m"],
        "encoder-backlash" => &["b_m", "b1_m", "b2_m", "b3_m", "b4_m"],
        "loadcell-drift" => &["rate_n"],
        "loadcell-friction" => &["k"],
        _ => return None,
    })
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

    /// Apply one `NAME:PARAM=VALUE[,PARAM=VALUE...]` specification, e.g.
    /// `elastic:ea_n=3e6`, `encoder-scale:gain1=1.001,gain3=0.999` or
    /// `com:dx_m=0.02,dz_m=-0.05`. Parameters not given keep their values.
    /// On error `self` is unchanged and the message names the effect and parameter.
    pub fn apply_spec(&mut self, spec: &str) -> Result<(), String> {
        let spec = spec.trim();
        let (name, params) = spec.split_once(':').ok_or_else(|| {
            format!("effect `{spec}`: expected NAME:PARAM=VALUE[,PARAM=VALUE...] (effects: {EFFECT_NAMES})")
        })?;
        let name = name.trim();
        let known =
            spec_parameters(name).ok_or_else(|| format!("unknown effect `{name}` (effects: {EFFECT_NAMES})"))?;
        if params.trim().is_empty() {
            return Err(format!(
                "effect `{name}`: no parameters given (parameters: {})",
                known.join(", ")
            ));
        }
        let mut next = *self;
        for param in params.split(',') {
            let param = param.trim();
            let (key, value) = param
                .split_once('=')
                .ok_or_else(|| format!("effect `{name}`: parameter `{param}` has no `=VALUE`"))?;
            let key = key.trim();
            if !known.contains(&key) {
                return Err(format!(
                    "effect `{name}`: unknown parameter `{key}` (parameters: {})",
                    known.join(", ")
                ));
            }
            let value: f64 = value
                .trim()
                .parse()
                .map_err(|_| format!("effect `{name}`: parameter `{key}`: `{}` is not a number", value.trim()))?;
            if !value.is_finite() {
                return Err(format!(
                    "effect `{name}`: parameter `{key}` must be finite, got {value}"
                ));
            }
            let positive = |what: &str| {
                if value > 0.0 {
                    Ok(value)
                } else {
                    Err(format!(
                        "effect `{name}`: parameter `{key}` ({what}) must be > 0, got {value}"
                    ))
                }
            };
            match (name, key) {
                ("elastic", _) => next.axial_stiffness_n = Some(positive("axial stiffness EA, N")?),
                ("pulley", _) => {
                    if value < 0.0 {
                        return Err(format!(
                            "effect `{name}`: parameter `{key}` (pulley radius, m) must be >= 0, got {value}"
                        ));
                    }
                    next.pulley_radius_m = value;
                }
                ("encoder-scale", "gain") => next.encoder_gain = [positive("encoder gain")?; CABLE_COUNT],
                ("encoder-scale", k) => {
                    let cable: usize = k["gain".len()..].parse().expect("gain1..gain4");
                    next.encoder_gain[cable - 1] = positive("encoder gain")?;
                }
                ("loadcell", "bias_n") => next.load_cell_bias_n = value,
                ("loadcell", _) => next.load_cell_gain = positive("load-cell gain")?,
                ("com", k) => {
                    let axis = ["dx_m", "dy_m", "dz_m"]
                        .iter()
                        .position(|a| *a == k)
                        .expect("known axis");
                    next.com_shift_m[axis] = value;
                }
                ("segments", _) => {
                    if value < 1.0 {
                        return Err(format!(
                            "effect `{name}`: parameter `{key}` (number of cable elements) must be >= 1, got {value}"
                        ));
                    }
                    next.cable_segments = Some(value);
                }
                ("localiser-mount", k) => {
                    let axis = ["rx_deg", "ry_deg", "rz_deg"]
                        .iter()
                        .position(|a| *a == k)
                        .expect("known axis");
                    next.localiser_mount_deg[axis] = value;
                }
                ("platform-weight", _) => next.platform_weight_scale = positive("weight scale")?,
                ("cable-weight", _) => next.cable_weight_scale = positive("weight scale")?,
                ("encoder-drift", "rate_m") => next.encoder_drift_m_per_row = [value; CABLE_COUNT],
                ("encoder-drift", k) => next.encoder_drift_m_per_row[drum(k, "rate")] = value,
                ("encoder-backlash", "b_m") => next.encoder_backlash_m = [value; CABLE_COUNT],
                ("encoder-backlash", k) => next.encoder_backlash_m[drum(k, "b")] = value,
                ("loadcell-drift", _) => next.load_cell_drift_n_per_row = value,
                ("loadcell-friction", _) => next.load_cell_friction = friction(name, key, value)?,
                _ => unreachable!("parameter names are checked above"),
            }
        }
        *self = next;
        Ok(())
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
        if !(0.0..1.0).contains(&self.load_cell_friction) {
            return Err(format!(
                "`load_cell_friction` must be >= 0 and < 1, got {}",
                self.load_cell_friction
            ));
        }
        Ok(())
    }

    /// The effects present, as specifications [`Effects::apply_spec`] accepts (empty: none).
    pub fn specs(&self) -> Vec<String> {
        let none = Self::default();
        let mut specs = Vec::new();
        if let Some(ea) = self.axial_stiffness_n {
            specs.push(format!("elastic:ea_n={ea:e}"));
        }
        if self.pulley_radius_m != none.pulley_radius_m {
            specs.push(format!("pulley:radius_m={}", self.pulley_radius_m));
        }
        if self.encoder_gain != none.encoder_gain {
            let g = self.encoder_gain;
            if g.iter().all(|x| *x == g[0]) {
                specs.push(format!("encoder-scale:gain={}", g[0]));
            } else {
                let parts: Vec<String> = g
                    .iter()
                    .enumerate()
                    .map(|(i, x)| format!("gain{}={x}", i + 1))
                    .collect();
                specs.push(format!("encoder-scale:{}", parts.join(",")));
            }
        }
        if self.load_cell_bias_n != none.load_cell_bias_n || self.load_cell_gain != none.load_cell_gain {
            specs.push(format!(
                "loadcell:bias_n={},gain={}",
                self.load_cell_bias_n, self.load_cell_gain
            ));
        }
        if self.com_shift_m != none.com_shift_m {
            let [x, y, z] = self.com_shift_m;
            specs.push(format!("com:dx_m={x},dy_m={y},dz_m={z}"));
        }
        if let Some(n) = self.cable_segments {
            specs.push(format!("segments:n={n}"));
        }
        if self.localiser_mount_deg != none.localiser_mount_deg {
            let [x, y, z] = self.localiser_mount_deg;
            specs.push(format!("localiser-mount:rx_deg={x},ry_deg={y},rz_deg={z}"));
        }
        if self.platform_weight_scale != 1.0 {
            specs.push(format!("platform-weight:scale={}", self.platform_weight_scale));
        }
        if self.cable_weight_scale != 1.0 {
            specs.push(format!("cable-weight:scale={}", self.cable_weight_scale));
        }
        for (name, key, values) in [
            ("encoder-drift", "rate", self.encoder_drift_m_per_row),
            ("encoder-backlash", "b", self.encoder_backlash_m),
        ] {
            if values.iter().any(|x| *x != 0.0) {
                let parts: Vec<String> = values
                    .iter()
                    .enumerate()
                    .map(|(i, x)| format!("{key}{}_m={x}", i + 1))
                    .collect();
                specs.push(format!("{name}:{}", parts.join(",")));
            }
        }
        if self.load_cell_drift_n_per_row != 0.0 {
            specs.push(format!("loadcell-drift:rate_n={}", self.load_cell_drift_n_per_row));
        }
        if self.load_cell_friction != 0.0 {
            specs.push(format!("loadcell-friction:k={}", self.load_cell_friction));
        }
        specs
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

/// A pulley friction `mu theta` given as `value`: in `[0, 1)`.
fn friction(name: &str, key: &str, value: f64) -> Result<f64, String> {
    if (0.0..1.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!(
            "effect `{name}`: parameter `{key}` (friction mu theta) must be >= 0 and < 1, got {value}"
        ))
    }
}

/// The drum of a per-drum parameter `rate1_m` .. `rate4_m` (0-based).
fn drum(key: &str, prefix: &str) -> usize {
    let digit = key[prefix.len()..].trim_end_matches("_m");
    digit.parse::<usize>().expect("rate1_m..rate4_m, b1_m..b4_m") - 1
}

impl std::fmt::Display for Effects {
    /// `none`, or the specifications joined by spaces.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let specs = self.specs();
        if specs.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&specs.join(" "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(specs: &[&str]) -> Result<Effects, String> {
        let mut effects = Effects::default();
        for spec in specs {
            effects.apply_spec(spec)?;
        }
        Ok(effects)
    }

    #[test]
    fn default_is_none() {
        assert!(Effects::default().is_none());
        assert_eq!(Effects::default().to_string(), "none");
        assert!(!parsed(&["loadcell:bias_n=0.5"]).unwrap().is_none());
    }

    #[test]
    fn parses_every_effect() {
        let e = parsed(&[
            "elastic:ea_n=3e6",
            "pulley:radius_m=0.2",
            "encoder-scale:gain=1.002",
            "encoder-scale:gain1=1.001,gain3=0.999",
            "loadcell:bias_n=3,gain=1.01",
            "com:dx_m=0.02,dz_m=-0.05",
            "segments:n=12",
            "localiser-mount:rx_deg=0.5,rz_deg=-1.5",
            "platform-weight:scale=1.11",
            "cable-weight:scale=0.9",
            "encoder-drift:rate_m=1e-4",
            "encoder-drift:rate2_m=-2e-4",
            "encoder-backlash:b3_m=0.002",
            "loadcell-drift:rate_n=0.3",
            "loadcell-friction:k=0.02",
        ])
        .unwrap();
        assert_eq!(e.axial_stiffness_n, Some(3e6));
        assert_eq!(e.pulley_radius_m, 0.2);
        assert_eq!(e.encoder_gain, [1.001, 1.002, 0.999, 1.002]);
        assert_eq!(e.load_cell_bias_n, 3.0);
        assert_eq!(e.load_cell_gain, 1.01);
        assert_eq!(e.com_shift_m, [0.02, 0.0, -0.05]);
        assert_eq!(e.cable_segments, Some(12.0));
        assert_eq!(e.inverse_segments_squared(), 1.0 / 144.0);
        assert_eq!(e.localiser_mount_deg, [0.5, 0.0, -1.5]);
        assert_eq!((e.platform_weight_scale, e.cable_weight_scale), (1.11, 0.9));
        assert_eq!(e.encoder_drift_m_per_row, [1e-4, -2e-4, 1e-4, 1e-4]);
        assert_eq!(e.encoder_backlash_m, [0.0, 0.0, 0.002, 0.0]);
        assert_eq!((e.load_cell_drift_n_per_row, e.load_cell_friction), (0.3, 0.02));
        // Row 10, cable 3 last paid out, the reference cable 1 reeled in:
        // 10 x 1e-4 + 0.002 on cable 3, 10 x 0.3 N and a factor 1 + 0.02 on the load cell.
        let order = ReadingOrder {
            row: 10,
            direction: [-1, 0, 1, 0],
        };
        let shift = e.time_and_motion(&order, 0);
        assert!((shift.encoder_shift_m[2] - 0.003).abs() < 1e-15 && (shift.encoder_shift_m[1] + 2e-3).abs() < 1e-15);
        assert!((shift.load_cell_shift_n - 3.0).abs() < 1e-12 && (shift.load_cell_factor - 1.02).abs() < 1e-15);
        // The specifications parse back to the same effects.
        let specs = e.specs();
        let again = parsed(&specs.iter().map(String::as_str).collect::<Vec<_>>()).unwrap();
        assert_eq!(again, e);
    }

    #[test]
    fn errors_name_the_effect_and_parameter() {
        let cases = [
            ("stretchy:ea_n=1", &["unknown effect `stretchy`"][..]),
            ("elastic", &["effect `elastic`", "NAME:PARAM=VALUE"]),
            ("elastic:", &["effect `elastic`", "no parameters"]),
            (
                "elastic:ea=3e6",
                &["effect `elastic`", "unknown parameter `ea`", "ea_n"],
            ),
            ("elastic:ea_n", &["effect `elastic`", "`ea_n` has no `=VALUE`"]),
            ("elastic:ea_n=abc", &["`ea_n`", "`abc` is not a number"]),
            ("elastic:ea_n=inf", &["`ea_n` must be finite"]),
            ("elastic:ea_n=NaN", &["`ea_n` must be finite"]),
            ("elastic:ea_n=0", &["effect `elastic`", "`ea_n`", "must be > 0"]),
            ("elastic:ea_n=-1e6", &["`ea_n`", "must be > 0"]),
            ("pulley:radius_m=-0.1", &["effect `pulley`", "`radius_m`", ">= 0"]),
            ("encoder-scale:gain=0", &["effect `encoder-scale`", "`gain`", "> 0"]),
            ("encoder-scale:gain5=1", &["unknown parameter `gain5`"]),
            ("loadcell:gain=-1", &["effect `loadcell`", "`gain`", "> 0"]),
            (
                "loadcell:bias_n=3,offset=1",
                &["effect `loadcell`", "unknown parameter `offset`"],
            ),
            ("com:dx=0.1", &["effect `com`", "unknown parameter `dx`"]),
            ("segments:n=0.5", &["effect `segments`", "`n`", ">= 1"]),
            (
                "platform-weight:scale=0",
                &["effect `platform-weight`", "`scale`", "> 0"],
            ),
            ("cable-weight:scale=-1", &["effect `cable-weight`", "`scale`", "> 0"]),
            (
                "loadcell-friction:k=-0.01",
                &["effect `loadcell-friction`", "`k`", ">= 0"],
            ),
            ("encoder-drift:rate5_m=1", &["unknown parameter `rate5_m`"]),
        ];
        for (spec, needles) in cases {
            let mut effects = Effects::default();
            let message = effects.apply_spec(spec).expect_err(spec);
            for needle in needles {
                assert!(message.contains(needle), "{spec}: `{message}` lacks `{needle}`");
            }
            assert!(effects.is_none(), "{spec}: a failed spec must not change the effects");
        }
    }

    #[test]
    fn pulley_radius_zero_is_allowed_and_later_specs_override() {
        let e = parsed(&["pulley:radius_m=0", "loadcell:gain=2", "loadcell:gain=1.5"]).unwrap();
        assert_eq!(e.pulley_radius_m, 0.0);
        assert_eq!(e.load_cell_gain, 1.5);
    }

    #[test]
    fn toml_round_trip_and_validation() {
        let e = parsed(&["elastic:ea_n=3e6", "com:dy_m=0.01"]).unwrap();
        let text = toml::to_string(&e).unwrap();
        assert_eq!(toml::from_str::<Effects>(&text).unwrap(), e);
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

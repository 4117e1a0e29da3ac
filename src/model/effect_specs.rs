//! The command-line language of [`Effects`]: `NAME:PARAM=VALUE[,PARAM=VALUE...]`
//! ([`Effects::apply_spec`]), and back ([`Effects::specs`], `Display`). The
//! effects and their parameters are listed in [`crate::model::effects`].
//!
//! ```
//! use sagcal::model::effects::Effects;
//! let mut effects = Effects::default();
//! effects.apply_spec("encoder-drift:rate2_m=2e-4")?;
//! assert_eq!(effects.encoder_drift_m_per_row, [0.0, 2e-4, 0.0, 0.0]);
//! assert_eq!(effects.to_string(), "encoder-drift:rate1_m=0,rate2_m=0.0002,rate3_m=0,rate4_m=0");
//! assert!(Effects::default().apply_spec("attachments:dz1_m=0.01").is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

use crate::error::EffectSpecError;
use crate::model::effects::Effects;
use crate::model::robot::CABLE_COUNT;

/// The effect names accepted by [`Effects::apply_spec`], with their parameters.
pub const EFFECT_NAMES: &str =
    "elastic:axial_stiffness_n (or ea_n), pulley:radius_m, encoder-scale:gain|gain1..gain4, loadcell:bias_n,gain, com:dx_m,dy_m,dz_m, segments:n, localiser-mount:rx_deg,ry_deg,rz_deg, platform-weight:scale, cable-weight:scale, encoder-drift:rate_m|rate1_m..rate4_m, encoder-backlash:b_m|b1_m..b4_m, loadcell-drift:rate_n, loadcell-friction:k, attachments:dx1_m,dy1_m..dx4_m,dy4_m";

/// The parameters [`Effects::apply_spec`] accepts for the effect `name`; `None` for no effect.
fn spec_parameters(name: &str) -> Option<&'static [&'static str]> {
    Some(match name {
        // `ea_n`: the name files and scripts written before use.
        "elastic" => &["axial_stiffness_n", "ea_n"],
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
        "attachments" => &["dx1_m", "dy1_m", "dx2_m", "dy2_m", "dx3_m", "dy3_m", "dx4_m", "dy4_m"],
        _ => return None,
    })
}

impl Effects {
    /// Apply one `NAME:PARAM=VALUE[,PARAM=VALUE...]` specification, e.g.
    /// `elastic:axial_stiffness_n=3e6`, `encoder-scale:gain1=1.001,gain3=0.999` or
    /// `com:dx_m=0.02,dz_m=-0.05`. Parameters not given keep their values.
    /// On error `self` is unchanged and the message names the effect and parameter.
    pub fn apply_spec(&mut self, spec: &str) -> Result<(), EffectSpecError> {
        let spec = spec.trim();
        let (name, params) = spec.split_once(':').ok_or_else(|| EffectSpecError::Malformed {
            spec: spec.to_string(),
            effects: EFFECT_NAMES,
        })?;
        let name = name.trim();
        let known = spec_parameters(name).ok_or_else(|| EffectSpecError::UnknownEffect {
            name: name.to_string(),
            effects: EFFECT_NAMES.to_string(),
        })?;
        if params.trim().is_empty() {
            return Err(EffectSpecError::NoParameters {
                name: name.to_string(),
                parameters: known.join(", "),
            });
        }
        let mut next = *self;
        for param in params.split(',') {
            let param = param.trim();
            let (key, value) = param.split_once('=').ok_or_else(|| EffectSpecError::NoValue {
                name: name.to_string(),
                param: param.to_string(),
            })?;
            let key = key.trim();
            if !known.contains(&key) {
                return Err(EffectSpecError::UnknownParameter {
                    name: name.to_string(),
                    key: key.to_string(),
                    parameters: known.join(", "),
                });
            }
            let value: f64 = value.trim().parse().map_err(|_| EffectSpecError::NotANumber {
                name: name.to_string(),
                key: key.to_string(),
                value: value.trim().to_string(),
            })?;
            if !value.is_finite() {
                return Err(EffectSpecError::NotFinite {
                    name: name.to_string(),
                    key: key.to_string(),
                    value,
                });
            }
            set(&mut next, name, key, value)?;
        }
        *self = next;
        Ok(())
    }

    /// The effects of `specs`, each applied in turn to no effect ([`Effects::apply_spec`]).
    pub fn from_specs(specs: &[&str]) -> Result<Effects, EffectSpecError> {
        let mut effects = Effects::default();
        for spec in specs {
            effects.apply_spec(spec)?;
        }
        Ok(effects)
    }

    /// The effects present, as specifications [`Effects::apply_spec`] accepts (empty: none).
    pub fn specs(&self) -> Vec<String> {
        let none = Self::default();
        let mut specs = Vec::new();
        if let Some(ea) = self.axial_stiffness_n {
            specs.push(format!("elastic:axial_stiffness_n={ea:e}"));
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
        if self.attachment_shift_m.iter().flatten().any(|x| *x != 0.0) {
            let parts: Vec<String> = (0..CABLE_COUNT)
                .flat_map(|i| {
                    let [x, y] = self.attachment_shift_m[i];
                    [format!("dx{}_m={x}", i + 1), format!("dy{}_m={y}", i + 1)]
                })
                .collect();
            specs.push(format!("attachments:{}", parts.join(",")));
        }
        specs
    }
}

/// Set parameter `key` of effect `name` to `value` (finite) in `next`; the
/// error names the effect, the parameter and the range it must lie in.
fn set(next: &mut Effects, name: &str, key: &str, value: f64) -> Result<(), EffectSpecError> {
    let out_of_range = |meaning: &'static str, range: &'static str| EffectSpecError::OutOfRange {
        name: name.to_string(),
        key: key.to_string(),
        meaning,
        range,
        value,
    };
    let positive = |meaning: &'static str| {
        if value > 0.0 {
            Ok(value)
        } else {
            Err(out_of_range(meaning, "> 0"))
        }
    };
    match (name, key) {
        ("elastic", _) => next.axial_stiffness_n = Some(positive("axial stiffness EA, N")?),
        ("pulley", _) => {
            if value < 0.0 {
                return Err(out_of_range("pulley radius, m", ">= 0"));
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
                return Err(out_of_range("number of cable elements", ">= 1"));
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
        ("loadcell-friction", _) => {
            if !(0.0..1.0).contains(&value) {
                return Err(out_of_range("friction mu theta", ">= 0 and < 1"));
            }
            next.load_cell_friction = value;
        }
        ("attachments", k) => {
            let cable = drum(k, "dx");
            next.attachment_shift_m[cable][usize::from(k.starts_with("dy"))] = value;
        }
        _ => unreachable!("parameter names are checked above"),
    }
    Ok(())
}

/// The drum (or cable) of a per-drum parameter `rate1_m` .. `rate4_m`,
/// `b1_m` .. or `dx1_m`, `dy1_m` .. (0-based); `prefix` is as long as the
/// name before the digit.
fn drum(key: &str, prefix: &str) -> usize {
    let digit = key[prefix.len()..].trim_end_matches("_m");
    digit
        .parse::<usize>()
        .expect("checked parameter names end in 1..4 and _m")
        - 1
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
    use crate::model::measurement::ReadingOrder;

    fn parsed(specs: &[&str]) -> Result<Effects, EffectSpecError> {
        Effects::from_specs(specs)
    }

    #[test]
    fn the_axial_stiffness_has_the_robot_files_name_and_reads_its_older_spelling() {
        let named = parsed(&["elastic:axial_stiffness_n=3e6"]).unwrap();
        assert_eq!(named.axial_stiffness_n, Some(3e6));
        assert_eq!(parsed(&["elastic:ea_n=3e6"]).unwrap(), named);
        assert_eq!(named.specs(), ["elastic:axial_stiffness_n=3e6"]);
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
            "attachments:dx2_m=0.01,dy4_m=-0.02",
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
        assert_eq!(
            e.attachment_shift_m,
            [[0.0, 0.0], [0.01, 0.0], [0.0, 0.0], [0.0, -0.02]]
        );
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
            let message = effects.apply_spec(spec).expect_err(spec).to_string();
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
}

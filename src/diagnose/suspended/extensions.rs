//! The extensions of the N-cable model that `diagnose` tries, each one
//! parameter the model of [`SuspendedRobot`] (or the sensors' reading of
//! it) can carry, with the value that is the baseline and the values a real
//! robot could have.
//!
//! - `elastic`: every cable's compliance `1/EA` (1/N); 0 is the paper's
//!   inextensible catenary, the elastic one is Irvine's
//!   ([`crate::calib::suspended::factors`]). A real rope has `1/EA > 0`, and
//!   no rope is stiffer than its weight per metre times the specific
//!   modulus of the stiffest rope fibres (UHMWPE and carbon, about
//!   1.4e8 J/kg: 130 GPa / 970 kg/m^3, 230 GPa / 1800 kg/m^3).
//! - `cable-weight`: one scale on every cable's weight per metre (1: the
//!   robot file's), plausible within +-50 %
//!   ([`crate::model::effect_limits::CABLE_WEIGHT_LIMIT`]).
//! - `platform-weight`: a scale on the platform's weight, plausible within
//!   +-50 % ([`crate::model::effect_limits::PLATFORM_WEIGHT_LIMIT`]).
//! - `encoder-scale`: one gain on every encoder (the drums' common radius
//!   error): the model's length is the reading over the gain, plausible
//!   within +-5 % ([`crate::model::effect_limits::ENCODER_GAIN_LIMIT`]).
//! - `loadcell-gain` / `loadcell-bias`: every load cell's gain, plausible
//!   within +-10 %, and its bias as a fraction of the load cells' mean
//!   reading, plausible within +-15 %
//!   ([`crate::model::effect_limits::LOAD_CELL_GAIN_LIMIT`],
//!   [`crate::model::effect_limits::LOAD_CELL_BIAS_LIMIT`]).
//! - `drum-gain-K`: cable K's encoder alone reads its length times a gain
//!   (one drum's radius error, a slipping or mis-wound drum), plausible as
//!   `encoder-scale`; `drum-gain` names every drum's.
//! - `cable-weight-K`: a scale on cable K's weight per metre alone (one
//!   cable of another rope or carrying a hose), plausible as
//!   `cable-weight`.
//!
//! [`suspended_catalogue`] is every global extension that applies and each
//! cable's two, `6 + 2N` at most; [`extensions_named`] reads a list of names.
//!
//! ```
//! use sagcal::diagnose::suspended::SuspendedExtension;
//! use sagcal::model::suspended::SuspendedRobot;
//! let robot = SuspendedRobot::builtin("six")?;
//! let (robot_at, _) = SuspendedExtension::Elastic.apply(&robot, &[], 2e-7);
//! assert!((robot_at.axial_stiffness_n[0] - 5e6).abs() < 1e-3);
//! // The null value is the baseline model itself.
//! let (same, _) = SuspendedExtension::CableWeight.apply(&robot, &[], 1.0);
//! assert_eq!(same.cable_weights_n_per_m, robot.cable_weights_n_per_m);
//! assert!(!SuspendedExtension::Elastic.is_plausible(&robot, &[], -1e-7));
//! // One drum's gain scales its own cable's readings only.
//! let (_, read) = SuspendedExtension::DrumGain(2).apply(&robot, &[], 1.01);
//! assert!(read.is_empty());
//! assert_eq!(SuspendedExtension::DrumGain(2).name(), "drum-gain-3");
//! assert_eq!(sagcal::diagnose::suspended::suspended_catalogue(&robot).len(), 6 + 2 * 6);
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::{Serialize, Serializer};

use crate::model::effect_limits::{
    CABLE_WEIGHT_LIMIT, ENCODER_GAIN_LIMIT, LOAD_CELL_BIAS_LIMIT, LOAD_CELL_GAIN_LIMIT, PLATFORM_WEIGHT_LIMIT,
};
use crate::model::plausibility::STANDARD_GRAVITY_M_S2 as GRAVITY;
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};

/// The highest specific modulus of rope fibres, J/kg (module docs).
pub const MAX_SPECIFIC_MODULUS_J_PER_KG: f64 = 1.4e8;

/// One extension of the N-cable model (module docs); serialised as its
/// [`SuspendedExtension::name`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SuspendedExtension {
    /// Every cable's compliance `1/EA`.
    Elastic,
    /// A scale on every cable's weight per metre.
    CableWeight,
    /// A scale on the platform's weight.
    PlatformWeight,
    /// One gain on every encoder.
    EncoderScale,
    /// One gain on every load cell.
    LoadcellGain,
    /// One bias on every load cell, newtons.
    LoadcellBias,
    /// One drum's gain: the cable's encoder (0-based index) alone.
    DrumGain(usize),
    /// A scale on one cable's (0-based index) weight per metre.
    OneCableWeight(usize),
}

impl Serialize for SuspendedExtension {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.name())
    }
}

/// The per-cable family that names every drum's gain.
const DRUM_GAIN: &str = "drum-gain";
/// The prefix of one cable's weight scale, `cable-weight-K`.
const CABLE_WEIGHT_OF: &str = "cable-weight-";

/// Every global extension, in the report's order.
pub const SUSPENDED_EXTENSIONS: [SuspendedExtension; 6] = [
    SuspendedExtension::Elastic,
    SuspendedExtension::CableWeight,
    SuspendedExtension::PlatformWeight,
    SuspendedExtension::EncoderScale,
    SuspendedExtension::LoadcellGain,
    SuspendedExtension::LoadcellBias,
];

/// The effects of the four-cable catalogue the N-cable model does not carry:
/// a misfit they cause is found by the baseline's test, never named as
/// themselves (an extension of the catalogue can stand in for one).
pub const NOT_MODELLED: &str = "pulley wrap, cable discretisation (segments), a shifted centre of mass, \
the localiser's mounting, moved attachments, per-drum effects other than a gain and per-load-cell effects";

/// The whole catalogue for `robot`, in the report's order: every global
/// extension that applies, then each drum's gain, then each cable's weight.
pub fn suspended_catalogue(robot: &SuspendedRobot) -> Vec<SuspendedExtension> {
    let cables = 0..robot.cable_count();
    let global = SUSPENDED_EXTENSIONS.into_iter().filter(|e| e.applies_to(robot));
    let drums = cables.clone().map(SuspendedExtension::DrumGain);
    global
        .chain(drums)
        .chain(cables.map(SuspendedExtension::OneCableWeight))
        .collect()
}

/// The extensions `names` name for `robot`, in their order: a global one
/// by its name, `drum-gain` for every drum's gain, `drum-gain-K` and
/// `cable-weight-K` for cable K (from 1), each once where first named; an
/// error naming the first name that is none of them, or a cable the robot
/// lacks.
pub fn extensions_named(robot: &SuspendedRobot, names: &[&str]) -> Result<Vec<SuspendedExtension>, String> {
    let mut extensions = Vec::new();
    for name in names {
        let name = name.trim();
        if name == DRUM_GAIN {
            extensions.extend((0..robot.cable_count()).map(SuspendedExtension::DrumGain));
            continue;
        }
        match SuspendedExtension::from_name(name) {
            Some(e) if e.cable().is_none_or(|c| c < robot.cable_count()) => extensions.push(e),
            Some(_) => {
                return Err(format!(
                    "`{name}` names a cable the robot lacks (it has cables 1 to {})",
                    robot.cable_count()
                ))
            }
            None => {
                return Err(format!(
                    "`{name}` is not an extension of the model of 3 to 8 cables (one of {}, {DRUM_GAIN}, \
                     {DRUM_GAIN}-K or {CABLE_WEIGHT_OF}K for cable K)",
                    SUSPENDED_EXTENSIONS.map(SuspendedExtension::name).join(", ")
                ))
            }
        }
    }
    // A name given twice (`drum-gain,drum-gain-3`) is tried once, its
    // first place kept, and counts once in the search's Bonferroni share.
    let mut tried = Vec::with_capacity(extensions.len());
    extensions.retain(|e| match tried.contains(e) {
        true => false,
        false => {
            tried.push(*e);
            true
        }
    });
    Ok(extensions)
}

impl SuspendedExtension {
    /// Its name, as `--candidates` takes it (cables counted from 1).
    pub fn name(self) -> String {
        match self {
            Self::Elastic => "elastic".into(),
            Self::CableWeight => "cable-weight".into(),
            Self::PlatformWeight => "platform-weight".into(),
            Self::EncoderScale => "encoder-scale".into(),
            Self::LoadcellGain => "loadcell-gain".into(),
            Self::LoadcellBias => "loadcell-bias".into(),
            Self::DrumGain(cable) => format!("{DRUM_GAIN}-{}", cable + 1),
            Self::OneCableWeight(cable) => format!("{CABLE_WEIGHT_OF}{}", cable + 1),
        }
    }

    /// The extension named `name` (a per-cable one for any cable from 1).
    pub fn from_name(name: &str) -> Option<Self> {
        let name = name.trim();
        let cable = |prefix: &str| {
            let k: usize = name.strip_prefix(prefix)?.parse().ok()?;
            k.checked_sub(1)
        };
        SUSPENDED_EXTENSIONS
            .into_iter()
            .find(|e| e.name() == name)
            .or_else(|| cable(&format!("{DRUM_GAIN}-")).map(Self::DrumGain))
            .or_else(|| cable(CABLE_WEIGHT_OF).map(Self::OneCableWeight))
    }

    /// The cable a per-cable extension acts on (0-based).
    pub fn cable(self) -> Option<usize> {
        match self {
            Self::DrumGain(cable) | Self::OneCableWeight(cable) => Some(cable),
            _ => None,
        }
    }

    /// Its parameter, with its unit.
    pub fn parameter(self) -> String {
        match self {
            Self::Elastic => "compliance 1/EA (1/N)".into(),
            Self::CableWeight => "cable weight scale".into(),
            Self::PlatformWeight => "platform weight scale".into(),
            Self::EncoderScale => "encoder gain".into(),
            Self::LoadcellGain => "load-cell gain".into(),
            Self::LoadcellBias => "load-cell bias (N)".into(),
            Self::DrumGain(cable) => format!("drum {} gain", cable + 1),
            Self::OneCableWeight(cable) => format!("cable {} weight scale", cable + 1),
        }
    }

    /// `value` of the parameter as the report prints it: the compliance in
    /// 1/N, a bias in newtons, a scale or gain to five decimals.
    pub fn value_text(self, value: f64) -> String {
        match self {
            Self::Elastic => format!("{value:.2e}"),
            Self::LoadcellBias => format!("{value:.1} N"),
            _ => format!("{value:.5}"),
        }
    }

    /// The parameter's value in the baseline model.
    pub fn null_value(self) -> f64 {
        match self {
            Self::Elastic | Self::LoadcellBias => 0.0,
            _ => 1.0,
        }
    }

    /// Whether the extension applies to `robot` (the load-cell ones need a
    /// load cell, the per-cable ones the cable).
    pub fn applies_to(self, robot: &SuspendedRobot) -> bool {
        match self {
            Self::LoadcellGain | Self::LoadcellBias => !robot.load_cells.is_empty(),
            Self::DrumGain(cable) | Self::OneCableWeight(cable) => cable < robot.cable_count(),
            _ => true,
        }
    }

    /// A first step of the parameter's search: a mid-range magnitude.
    pub fn first_step(self, robot: &SuspendedRobot, measurements: &[SuspendedMeasurement]) -> f64 {
        match self {
            // The compliance of a steel rope of the cables' weight at E = 90 GPa.
            Self::Elastic => {
                let area_m2 = heaviest_cable_kg_per_m(robot) / 7850.0;
                if area_m2 > 0.0 {
                    1.0 / (area_m2 * 90e9)
                } else {
                    1.0 / (1e4 * robot.platform_weight_n)
                }
            }
            Self::CableWeight | Self::PlatformWeight | Self::OneCableWeight(_) => 0.05,
            Self::EncoderScale | Self::DrumGain(_) => 1e-3,
            Self::LoadcellGain => 0.02,
            Self::LoadcellBias => 0.05 * mean_load_cell_reading_n(measurements),
        }
    }

    /// The robot and the readings as the model with the parameter at `value` sees them.
    pub fn apply(
        self,
        robot: &SuspendedRobot,
        measurements: &[SuspendedMeasurement],
        value: f64,
    ) -> (SuspendedRobot, Vec<SuspendedMeasurement>) {
        let mut robot = robot.clone();
        let mut measurements = measurements.to_vec();
        match self {
            Self::Elastic => {
                let stiffness = if value == 0.0 { f64::INFINITY } else { 1.0 / value };
                robot.axial_stiffness_n = vec![stiffness; robot.cable_count()];
            }
            Self::CableWeight => robot.cable_weights_n_per_m.iter_mut().for_each(|w| *w *= value),
            Self::PlatformWeight => robot.platform_weight_n *= value,
            Self::EncoderScale => measurements
                .iter_mut()
                .for_each(|m| m.encoder_lengths_m.iter_mut().for_each(|l| *l /= value)),
            Self::LoadcellGain => measurements
                .iter_mut()
                .for_each(|m| m.load_cell_tensions_n.iter_mut().for_each(|t| *t /= value)),
            Self::LoadcellBias => measurements
                .iter_mut()
                .for_each(|m| m.load_cell_tensions_n.iter_mut().for_each(|t| *t -= value)),
            Self::DrumGain(cable) => measurements
                .iter_mut()
                .for_each(|m| m.encoder_lengths_m[cable] /= value),
            Self::OneCableWeight(cable) => robot.cable_weights_n_per_m[cable] *= value,
        }
        (robot, measurements)
    }

    /// The values a real robot could have, in words.
    pub fn plausible_range(self, robot: &SuspendedRobot, measurements: &[SuspendedMeasurement]) -> String {
        match self {
            Self::Elastic => match stiffest_rope_n(robot) {
                Some(ea) => format!("1/EA > 0 and EA <= {ea:.2e} N"),
                None => "1/EA > 0".into(),
            },
            Self::CableWeight | Self::OneCableWeight(_) => scale_range(CABLE_WEIGHT_LIMIT),
            Self::PlatformWeight => scale_range(PLATFORM_WEIGHT_LIMIT),
            Self::EncoderScale | Self::DrumGain(_) => scale_range(ENCODER_GAIN_LIMIT),
            Self::LoadcellGain => scale_range(LOAD_CELL_GAIN_LIMIT),
            Self::LoadcellBias => {
                let limit = LOAD_CELL_BIAS_LIMIT * mean_load_cell_reading_n(measurements);
                format!("-{limit:.1} .. {limit:.1} N")
            }
        }
    }

    /// Whether a real robot could have the parameter at `value` (module docs).
    pub fn is_plausible(self, robot: &SuspendedRobot, measurements: &[SuspendedMeasurement], value: f64) -> bool {
        let within = |limit: f64| (value - 1.0).abs() <= limit;
        match self {
            Self::Elastic => value > 0.0 && stiffest_rope_n(robot).is_none_or(|ea| 1.0 / value <= ea),
            Self::CableWeight | Self::OneCableWeight(_) => within(CABLE_WEIGHT_LIMIT),
            Self::PlatformWeight => within(PLATFORM_WEIGHT_LIMIT),
            Self::EncoderScale | Self::DrumGain(_) => within(ENCODER_GAIN_LIMIT),
            Self::LoadcellGain => within(LOAD_CELL_GAIN_LIMIT),
            Self::LoadcellBias => value.abs() <= LOAD_CELL_BIAS_LIMIT * mean_load_cell_reading_n(measurements),
        }
    }
}

/// `1 - limit .. 1 + limit`.
fn scale_range(limit: f64) -> String {
    format!("{:.2} .. {:.2}", 1.0 - limit, 1.0 + limit)
}

/// The heaviest cable's mass per metre, kg/m.
fn heaviest_cable_kg_per_m(robot: &SuspendedRobot) -> f64 {
    robot.cable_weights_n_per_m.iter().copied().fold(0.0, f64::max) / GRAVITY
}

/// The stiffest rope of the cables' weight (module docs), newtons; `None`
/// for weightless cables.
fn stiffest_rope_n(robot: &SuspendedRobot) -> Option<f64> {
    let mass = heaviest_cable_kg_per_m(robot);
    (mass > 0.0).then_some(mass * MAX_SPECIFIC_MODULUS_J_PER_KG)
}

/// The mean load-cell reading, newtons (0 without readings).
fn mean_load_cell_reading_n(measurements: &[SuspendedMeasurement]) -> f64 {
    let readings: Vec<f64> = measurements
        .iter()
        .flat_map(|m| m.load_cell_tensions_n.iter().copied())
        .collect();
    if readings.is_empty() {
        0.0
    } else {
        readings.iter().sum::<f64>() / readings.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_reads_back_as_its_extension() {
        let robot = SuspendedRobot::builtin("eight").unwrap();
        let catalogue = suspended_catalogue(&robot);
        assert_eq!(catalogue.len(), 6 + 2 * 8);
        for extension in &catalogue {
            assert_eq!(SuspendedExtension::from_name(&extension.name()), Some(*extension));
        }
        assert_eq!(SuspendedExtension::from_name("drum-gain-0"), None);
        assert_eq!(SuspendedExtension::from_name("cable-weight-x"), None);
    }

    #[test]
    fn a_list_of_names_expands_drum_gain_and_refuses_a_cable_the_robot_lacks() {
        let robot = SuspendedRobot::builtin("three").unwrap();
        let names = ["elastic", "drum-gain-2", " drum-gain", "cable-weight-2", "elastic"];
        let named = extensions_named(&robot, &names).unwrap();
        let drums = (0..3).map(SuspendedExtension::DrumGain);
        // Each once, in the place it was first named.
        let expected: Vec<_> = [SuspendedExtension::Elastic, SuspendedExtension::DrumGain(1)]
            .into_iter()
            .chain(drums.filter(|d| *d != SuspendedExtension::DrumGain(1)))
            .chain([SuspendedExtension::OneCableWeight(1)])
            .collect();
        assert_eq!(named, expected);
        let lacking = extensions_named(&robot, &["drum-gain-4"]).unwrap_err();
        assert!(lacking.contains("cables 1 to 3"), "{lacking}");
        let unknown = extensions_named(&robot, &["pulley"]).unwrap_err();
        assert!(unknown.contains("`pulley` is not an extension"), "{unknown}");
    }

    #[test]
    fn one_drum_s_gain_and_one_cable_s_weight_touch_that_cable_only() {
        let robot = SuspendedRobot::builtin("three").unwrap();
        let reading = SuspendedMeasurement {
            line: 1,
            position_m: [0.0; 3],
            roll_deg: 0.0,
            pitch_deg: 0.0,
            yaw_deg: 0.0,
            encoder_lengths_m: vec![10.0, 20.0, 30.0],
            load_cell_tensions_n: vec![100.0],
        };
        let (_, read) = SuspendedExtension::DrumGain(1).apply(&robot, &[reading], 1.25);
        assert_eq!(read[0].encoder_lengths_m, vec![10.0, 16.0, 30.0]);
        let (heavier, _) = SuspendedExtension::OneCableWeight(2).apply(&robot, &[], 2.0);
        let w = &robot.cable_weights_n_per_m;
        assert_eq!(heavier.cable_weights_n_per_m, vec![w[0], w[1], 2.0 * w[2]]);
    }
}

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
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::Serialize;

use crate::model::effect_limits::{
    CABLE_WEIGHT_LIMIT, ENCODER_GAIN_LIMIT, LOAD_CELL_BIAS_LIMIT, LOAD_CELL_GAIN_LIMIT, PLATFORM_WEIGHT_LIMIT,
};
use crate::model::plausibility::STANDARD_GRAVITY_M_S2 as GRAVITY;
use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};

/// The highest specific modulus of rope fibres, J/kg (module docs).
pub const MAX_SPECIFIC_MODULUS_J_PER_KG: f64 = 1.4e8;

/// One extension of the N-cable model (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
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
}

/// Every extension, in the report's order.
pub const SUSPENDED_EXTENSIONS: [SuspendedExtension; 6] = [
    SuspendedExtension::Elastic,
    SuspendedExtension::CableWeight,
    SuspendedExtension::PlatformWeight,
    SuspendedExtension::EncoderScale,
    SuspendedExtension::LoadcellGain,
    SuspendedExtension::LoadcellBias,
];

/// The effects of the four-cable catalogue the N-cable model does not carry:
/// a misfit they cause is found by the baseline's test, never named.
pub const NOT_MODELLED: &str = "pulley wrap, cable discretisation (segments), a shifted centre of mass, \
the localiser's mounting, moved attachments and the per-drum encoder and load-cell effects";

impl SuspendedExtension {
    /// Its name, as `--candidates` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Elastic => "elastic",
            Self::CableWeight => "cable-weight",
            Self::PlatformWeight => "platform-weight",
            Self::EncoderScale => "encoder-scale",
            Self::LoadcellGain => "loadcell-gain",
            Self::LoadcellBias => "loadcell-bias",
        }
    }

    /// The extension named `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        SUSPENDED_EXTENSIONS.into_iter().find(|e| e.name() == name.trim())
    }

    /// Its parameter, with its unit.
    pub fn parameter(self) -> &'static str {
        match self {
            Self::Elastic => "compliance 1/EA (1/N)",
            Self::CableWeight => "cable weight scale",
            Self::PlatformWeight => "platform weight scale",
            Self::EncoderScale => "encoder gain",
            Self::LoadcellGain => "load-cell gain",
            Self::LoadcellBias => "load-cell bias (N)",
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

    /// Whether the extension applies to `robot` (the load-cell ones need a load cell).
    pub fn applies_to(self, robot: &SuspendedRobot) -> bool {
        !matches!(self, Self::LoadcellGain | Self::LoadcellBias) || !robot.load_cells.is_empty()
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
            Self::CableWeight | Self::PlatformWeight => 0.05,
            Self::EncoderScale => 1e-3,
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
            Self::CableWeight => scale_range(CABLE_WEIGHT_LIMIT),
            Self::PlatformWeight => scale_range(PLATFORM_WEIGHT_LIMIT),
            Self::EncoderScale => scale_range(ENCODER_GAIN_LIMIT),
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
            Self::CableWeight => within(CABLE_WEIGHT_LIMIT),
            Self::PlatformWeight => within(PLATFORM_WEIGHT_LIMIT),
            Self::EncoderScale => within(ENCODER_GAIN_LIMIT),
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

//! The robot's sensors and their noise (paper Sec. V-B).
//!
//! Encoders measure cable length plus an unknown offset, the load cell the
//! reference cable's tension at the platform, the localiser the platform pose.
//! Noise is zero-mean Gaussian; the pose noise is a tangent perturbation
//! `pose.retract(xi)`, `xi ~ N(0, diag(sigma_rot^2 I3, sigma_pos^2 I3))`.
//!
//! ```
//! use sagcal::model::sensors::NoisePreset;
//! let paper = NoisePreset::parse("paper")?;
//! // The paper's Sec. V-B: 10 mm encoders, 5 mm / 0.01 rad localiser, a 5 N load cell
//! // on the large robot (334 N) and 1 N on the small one (43 N).
//! let large = paper.sigmas(333.54);
//! assert_eq!((large.encoder_sigma_m, large.position_sigma_m, large.orientation_sigma_rad), (0.010, 0.005, 0.01));
//! assert_eq!((large.load_cell_sigma_n, paper.sigmas(43.2).load_cell_sigma_n), (5.0, 1.0));
//! for preset in [NoisePreset::Paper, NoisePreset::Authors, NoisePreset::None] {
//!     assert_eq!(NoisePreset::parse(&preset.to_string()), Ok(preset));
//! }
//! assert!(NoisePreset::parse("loud").is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::error::ParseError;

/// Standard deviations of the sensors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SensorNoise {
    /// Encoder (relative cable length), metres.
    pub encoder_sigma_m: f64,
    /// Load cell on the reference cable, newtons.
    pub load_cell_sigma_n: f64,
    /// Localiser position, metres per axis.
    pub position_sigma_m: f64,
    /// Localiser orientation, radians per axis.
    pub orientation_sigma_rad: f64,
}

/// The named noise settings of the paper's experiments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NoisePreset {
    /// The paper's text: 10 mm encoders, 5 N load cell (1 N on the small robot), pose 5 mm / 0.01 rad.
    Paper,
    /// What the authors' published program adds: encoders 5/3 mm, load cell 5 N,
    /// pose (5/sqrt 3)/3 mm and (0.5/sqrt 3)/3 degree per axis.
    Authors,
    /// No noise (for exactness tests).
    None,
}

impl NoisePreset {
    /// Parse `paper`, `authors` or `none`.
    pub fn parse(text: &str) -> Result<Self, ParseError> {
        match text {
            "paper" => Ok(NoisePreset::Paper),
            "authors" => Ok(NoisePreset::Authors),
            "none" => Ok(NoisePreset::None),
            other => Err(ParseError::UnknownChoice {
                what: "noise setting",
                given: other.to_string(),
                choices: " (paper, authors, none)".to_string(),
            }),
        }
    }

    /// The sigmas for a robot: the paper uses a 5 N load cell on the large
    /// robot and 1 N on the small one; sagcal takes 1 N for platforms lighter
    /// than 100 N (the small robot weighs 43 N, the large 334 N).
    pub fn sigmas(&self, platform_weight_n: f64) -> SensorNoise {
        let light = platform_weight_n < 100.0;
        match self {
            NoisePreset::Paper => SensorNoise {
                encoder_sigma_m: 0.010,
                load_cell_sigma_n: if light { 1.0 } else { 5.0 },
                position_sigma_m: 0.005,
                orientation_sigma_rad: 0.01,
            },
            NoisePreset::Authors => SensorNoise {
                encoder_sigma_m: 0.005 / 3.0,
                load_cell_sigma_n: if light { 1.0 } else { 5.0 },
                position_sigma_m: 0.005 / 3f64.sqrt() / 3.0,
                orientation_sigma_rad: (0.5f64 / 3f64.sqrt() / 3.0).to_radians(),
            },
            NoisePreset::None => SensorNoise {
                encoder_sigma_m: 0.0,
                load_cell_sigma_n: 0.0,
                position_sigma_m: 0.0,
                orientation_sigma_rad: 0.0,
            },
        }
    }
}

impl std::fmt::Display for NoisePreset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            NoisePreset::Paper => "paper",
            NoisePreset::Authors => "authors",
            NoisePreset::None => "none",
        })
    }
}

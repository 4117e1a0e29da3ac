//! Each sensor's noise as its data show it, where the data are more precise
//! than stated (variance-component estimation, Förstner 1979; Koch,
//! *Parameter Estimation and Hypothesis Testing in Linear Models*, sec. 3.6).
//!
//! One a posteriori variance factor rescales every test alike. When the
//! stated noise overstates the sensors by different factors (the paper's
//! 10 mm encoders stated for 1 mm ones, the load cell as stated), one factor
//! leaves the sensor closest to its stated noise looking far too noisy
//! against the others: every hypothesis that moves its residuals passes its
//! test, and a `none` case is rejected far above the stated false-alarm rate.
//! Each sensor's variance component is its chi-square over its redundancy
//! (its expected chi-square, [`super::residual_tests`]); a sensor's noise
//! is scaled by the square root of its component relative to the largest
//! one (never above the stated noise, never below 1/100 of it), and the
//! common part stays with the variance factor.
//!
//! ```
//! use sagcal::diagnose::{noise_the_data_show, FactorTest};
//! use sagcal::model::sensors::NoisePreset;
//! let test = |kind: &str, chi_square: f64, expected: f64| FactorTest {
//!     kind: kind.into(),
//!     components: 100,
//!     chi_square,
//!     expected,
//!     limit: 0.0,
//!     consistent: true,
//! };
//! let stated = NoisePreset::Paper.sigmas(3000.0);
//! // The encoders and the localiser 0.04 of their stated variance, the load cell as stated.
//! let tests = [
//!     test("catenary_length", 4.0, 100.0),
//!     test("reference_tension", 30.0, 30.0),
//!     test("pose_prior", 3.6, 90.0),
//! ];
//! let shown = noise_the_data_show(&stated, &tests).unwrap();
//! assert!((shown.encoder_sigma_m / stated.encoder_sigma_m - 0.2).abs() < 1e-12);
//! assert_eq!(shown.load_cell_sigma_n, stated.load_cell_sigma_n);
//! assert!((shown.position_sigma_m / stated.position_sigma_m - 0.2).abs() < 1e-12);
//! // All alike: one factor says it, nothing to rescale.
//! let alike = [test("catenary_length", 4.0, 100.0), test("reference_tension", 1.2, 30.0), test("pose_prior", 3.6, 90.0)];
//! assert!(noise_the_data_show(&stated, &alike).is_none());
//! ```

use super::residual_tests::FactorTest;
use crate::model::sensors::SensorNoise;

/// The smallest scale of a sensor's noise against the stated one.
pub const SMALLEST_NOISE_SCALE: f64 = 0.01;

/// Sensors whose variance components differ by less than this factor are
/// alike: one variance factor describes them (a chi-square of 30 components
/// varies by about this much between draws).
const ALIKE_RATIO: f64 = 2.0;

/// The stated noise with each sensor scaled to its variance component
/// relative to the largest one (module docs); `None` when the components are
/// alike or a test is missing.
pub fn noise_the_data_show(stated: &SensorNoise, tests: &[FactorTest]) -> Option<SensorNoise> {
    let component = |kind: &str| {
        tests
            .iter()
            .find(|t| t.kind == kind)
            .filter(|t| t.expected > 0.0 && t.chi_square.is_finite())
            .map(|t| t.chi_square / t.expected)
    };
    let encoder = component("catenary_length")?;
    let load_cell = component("reference_tension")?;
    let localiser = component("pose_prior")?;
    let largest = encoder.max(load_cell).max(localiser);
    let smallest = encoder.min(load_cell).min(localiser);
    if largest.is_nan() || largest <= 0.0 || largest < ALIKE_RATIO * smallest {
        return None;
    }
    let scale = |c: f64| (c / largest).sqrt().clamp(SMALLEST_NOISE_SCALE, 1.0);
    Some(SensorNoise {
        encoder_sigma_m: stated.encoder_sigma_m * scale(encoder),
        load_cell_sigma_n: stated.load_cell_sigma_n * scale(load_cell),
        position_sigma_m: stated.position_sigma_m * scale(localiser),
        orientation_sigma_rad: stated.orientation_sigma_rad * scale(localiser),
    })
}

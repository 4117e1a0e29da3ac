//! What the calibration model gets wrong: `sagcal diagnose`.
//!
//! Given measurements, [`diagnose`]
//!
//! 1. calibrates with the baseline model (the paper's closed-form catenary,
//!    with every sensor as evidence: the localiser's orientation is a prior
//!    unless turned off) and tests the normalised residuals against the
//!    stated sensor noise with a chi-square test per factor type ([`FactorTest`]);
//! 2. relates the residuals to physical drivers of each cable and pose
//!    (tension, tension x length, cable length, sag, elevation, pulley wrap
//!    angle, platform position) by correlation, and says which carry structure
//!    ([`DriverTest`], `|t| > 3.29`, two-sided p < 0.001);
//! 3. searches the hypotheses, each effect of the catalogue ([`EffectKind`](crate::model::effect_kind::EffectKind),
//!    extra parameter variables of the factor graph,
//!    [`crate::calib::effect_factors`]) and "the localiser's orientations are
//!    unreliable" ([`Hypothesis::OrientationFree`], 3 parameters per pose), by
//!    forward selection with likelihood-ratio tests at a stated false-alarm
//!    rate and backward checks (`selection`), so that several effects can be
//!    named at once; each test's power at the effect's smallest physically
//!    plausible magnitude comes from the fit's Fisher information, and a
//!    candidate whose power is below 0.9 is reported as not detectable at
//!    this noise with these poses;
//! 4. keeps only what predicts (`prediction`): each effect the selection
//!    added must lower the held-out residual of the model without it and not
//!    make the anchors worse by their own covariance, else it is taken out;
//! 5. asks whether the final model explains the data (`explanation`): it must
//!    pass every sensor's chi-square test at the false-alarm rate (each
//!    sensor's expectation its redundancy) and hold no stand-in
//!    (`stand_ins`: an estimate beyond what any real robot could have,
//!    [`crate::model::effect_limits`]; an effect whose own sensor stays
//!    inconsistent; freed orientations) and leave no structure: no term
//!    (a reading's residual linear in a driver, the row or the direction of
//!    motion) beyond Rao's score test at the stated rate (`missing_terms`).
//!    The terms missing are proposed by a sparse regression; the causes of
//!    a model that does not explain the data are named only where they are
//!    needed beyond those terms. Hypotheses whose BIC is within 2 of each
//!    other are named together (`X|Y`);
//! 6. reports the verdict (the causes in the order added, joined by `+`;
//!    `none` when nothing is wrong; `unexplained`, or the causes and
//!    `+unexplained`, when the catalogue does not hold what is wrong), the
//!    parameters with 1-sigma, the stand-ins with what they stand in for,
//!    what the final model leaves, and the gain: held-out residual RMS before
//!    and after and, given the truth, anchor and offset errors before and
//!    after.
//!
//! Held-out residual: for each fold the model is re-fitted without the
//! fold's poses; each held-out pose's own variables (pose, reference tension)
//! are then fitted to its measurements with the anchors, offsets and effect
//! parameters held, and its whitened measurement residuals (encoders, load
//! cell, localiser) are collected. `cv_rms` is their root mean square (about 1
//! when the model and the stated noise are right).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::diagnose::{diagnose, DiagnoseOptions};
//! use sagcal::model::effect_kind::EffectKind;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! // Encoders that read 0.3 % long: each reading is gain x length (+ offset).
//! let nominal = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
//! let equilibria = sample_equilibria(&nominal, &Workspace::default_for(&nominal), 20, &mut rng)?;
//! let noise = NoisePreset::Paper.sigmas(nominal.platform_weight_n);
//! let mut data = measure(&nominal, &equilibria, &noise, &mut rng);
//! for (m, e) in data.iter_mut().zip(&equilibria) {
//!     for i in 0..4 {
//!         m.encoder_lengths_m[i] += 0.003 * e.cable_lengths_m[i];
//!     }
//! }
//! let mut options = DiagnoseOptions::new(CalibrationOptions::new(noise));
//! options.candidates = vec![EffectKind::parse("encoder-gain").unwrap()];
//! options.folds = 2;
//! let diagnosis = diagnose(&nominal, &data, None, &options, &mut |_, _, _| {})?;
//! assert_eq!(diagnosis.verdict, "encoder-gain");
//! # Ok::<(), sagcal::Error>(())
//! ```

mod baseline;
mod candidates;
mod drivers;
mod equivalent_fits;
mod explanation;
mod fitted_graph;
mod missing_terms;
mod options;
mod paper_table1;
mod pipeline;
mod prediction;
mod progress;
mod report;
mod residual_tests;
mod search;
mod selection;
mod settings;
mod stand_ins;
pub mod suspended;
mod term_refit;
mod variance_components;
pub mod verify;

pub use candidates::{power_against, CandidateFit, Hypothesis, ParameterValue, DETECTION_POWER, WEIGHT_SCALING};
pub use drivers::{DriverSeries, DriverTest, DRIVERS, DRIVER_T_LIMIT};
pub use explanation::{Ambiguity, Explanation, AMBIGUOUS_BIC};
pub use missing_terms::{CausesGivenTerms, MissingTerm, ALIKE_SHARE, MOST_DESCRIBING};
pub use options::DiagnoseOptions;
pub use pipeline::diagnose;
pub use prediction::NotPredictive;
pub use report::{error_over_sigma, Diagnosis, EffectFit, Gain};
pub use residual_tests::{FactorTest, MEASUREMENT_KINDS};
pub use selection::SelectionStep;
pub use settings::DiagnoseSettings;
pub use stand_ins::{StandIn, STAND_IN_SIGMAS};
pub use variance_components::{noise_the_data_show, SMALLEST_NOISE_SCALE};

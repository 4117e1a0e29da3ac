//! Gross errors: a calibration is never silently wrong.
//!
//! After every solve the fit is tested against the stated noise, in the
//! manner of geodesy's data snooping (Baarda 1968; Förstner 1987) and of
//! bundle adjustment's test-and-remove (Triggs et al. 2000, sec. 10):
//!
//! - **Per reading**, the normalised residual `w_i = e_i / (sigma_i sqrt(r_i))`
//!   with `r_i` the reading's redundancy number
//!   ([`crate::solver::redundancy_numbers`]) is standard normal when the model
//!   holds. The largest `|w|` is compared with the two-sided normal quantile
//!   at `alpha / n` (Bonferroni over the `n` readings tested), so on clean
//!   data any reading is flagged with probability at most `alpha`. A flagged
//!   reading's own error is estimated as `-e_i / r_i` (model minus reading,
//!   divided by the share of an error that shows in its own residual).
//! - **Per sensor type** (encoders, load cell, localiser position, localiser
//!   orientation), the chi-square of its normalised residuals against its
//!   redundancy (the sum of its `r_i`, the expected value): one-sided, so data
//!   more precise than stated (finite-element logs) pass; at `alpha / types`.
//!
//! [`calibrate_checked`] removes the most significant flagged reading,
//! calibrates again from the initial guess (a blunder can have sent the start
//! into a wrong basin), and repeats until nothing is flagged. Every reading
//! left out is reported with its row, sensor, estimated error and `w`. When
//! more readings fail than a few blunders explain, or a sensor type still
//! fails its chi-square, the fit is declared inconsistent: the model or the
//! stated noise is wrong, which is `sagcal diagnose`'s job, not a blunder's.
//! Before calibrating, [`super::mistakes`] looks for the common mistakes that
//! are not single blunders (a sensor logged in the wrong unit, a pose outside
//! the frame).
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::gross_errors::{calibrate_checked, GrossErrorOptions, Verdict};
//! use sagcal::calib::CalibrationOptions;
//! use sagcal::model::measurement::Sensor;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let truth = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(63);
//! let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 15, &mut rng)?;
//! let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
//! let mut data = measure(&truth, &equilibria, &noise, &mut rng);
//! data[4].encoder_lengths_m[2] += 2.0; // the drum of cable 3 slipped 2 m before row 5 was read
//! let options = CalibrationOptions::new(noise);
//! let checked = calibrate_checked(&truth, &data, &options, &GrossErrorOptions::default())?;
//! assert_eq!(checked.verdict, Verdict::Consistent);
//! assert_eq!(checked.excluded.len(), 1, "{:#?}", checked.excluded);
//! let blunder = &checked.excluded[0].test;
//! assert_eq!((blunder.pose, blunder.sensor), (4, Sensor::Encoder(2)));
//! // Its estimated error is the slip, to within a few of the encoders' 10 mm sigma.
//! assert!((blunder.estimated_error - 2.0).abs() < 0.05, "{}", blunder.describe());
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::Serialize;

use std::collections::HashMap;

use super::fit_progress::{search_fit, FitProgress};
use super::mistakes::{self, Mistake};
use super::options::{CalibrationOptions, RobustKernels};
use super::result::CalibrationResult;
use super::screen;
use crate::error::Result;
use crate::graph::RobustKernel;
use crate::model::measurement::{PoseMeasurement, Sensor};
use crate::model::robot::CABLE_COUNT;
use crate::stats::chi_square_critical;

pub use super::options::GrossErrorOptions;
pub use super::snooping::{
    graph_at_solution, residuals_at_fit, row_name, test_fit, used_measurements, ConsistencyTest, ExcludedReading,
    ReadingTest, SensorTypeTest,
};

/// Whether the calibration can be trusted.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "verdict", rename_all = "snake_case")]
pub enum Verdict {
    /// The fit passes every test (after the exclusions listed).
    Consistent,
    /// The fit fails its own tests; the reason names the sensors.
    Inconsistent {
        /// Why, in words.
        reason: String,
    },
}

/// A calibration with its gross-error tests.
#[derive(Debug, Clone)]
pub struct CheckedCalibration {
    /// The final fit (without the excluded readings).
    pub result: CalibrationResult,
    /// The measurements it used, with [`PoseMeasurement::excluded`] set
    /// (rows outside the frame left out: see `rows`).
    pub measurements: Vec<PoseMeasurement>,
    /// `rows[k]`: the row (0-based, in the data given) of `measurements[k]`.
    pub rows: Vec<usize>,
    /// The readings left out, in the order found.
    pub excluded: Vec<ExcludedReading>,
    /// For an inconsistent fit: the readings the search would have left out
    /// before it gave up (the fit uses them all; the mistakes name what they
    /// look like).
    pub set_aside: Vec<ExcludedReading>,
    /// The common mistakes found before or after the fit.
    pub mistakes: Vec<Mistake>,
    /// The tests of the final fit.
    pub test: ConsistencyTest,
    /// The verdict.
    pub verdict: Verdict,
}

/// Calibrate with gross-error detection (module docs): check the data for
/// common mistakes; calibrate and test, which is all for data that pass;
/// otherwise screen them with a robust fit, then calibrate, test,
/// leave the most significant flagged reading out and calibrate again until
/// nothing is flagged, take back what the final fit does not reject, name
/// what the exclusions look like and give the verdict.
///
/// Before any fit, [`super::screen`] refuses sigmas outside a sensor's range,
/// duplicated rows and readings the robot cannot produce, and says why when
/// too few rows are inside the frame; after it, a fit whose parameters the
/// data did not determine ([`super::screen::undetermined`]) is inconsistent.
pub fn calibrate_checked(
    initial: &crate::model::Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    check: &GrossErrorOptions,
) -> Result<CheckedCalibration> {
    calibrate_checked_with_progress(initial, measurements, options, check, &mut |_, _, _| {})
}

/// [`calibrate_checked`], telling `progress(done, total, what)` before each
/// stage of each fit: `done` fits made of the `total` expected so far (one
/// for data that pass, one more per reading the search still flags), `what`
/// the fit and its stage; the last report is `(fits, fits, "done")`. It
/// changes nothing computed.
///
/// ```
/// use rand::SeedableRng;
/// use sagcal::calib::gross_errors::{calibrate_checked_with_progress, GrossErrorOptions};
/// use sagcal::calib::CalibrationOptions;
/// use sagcal::model::sensors::NoisePreset;
/// use sagcal::model::Robot;
/// use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
/// let truth = Robot::builtin("large")?;
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(63);
/// let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 15, &mut rng)?;
/// let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
/// let data = measure(&truth, &equilibria, &noise, &mut rng);
/// let options = CalibrationOptions::new(noise);
/// let mut reports = Vec::new();
/// calibrate_checked_with_progress(&truth, &data, &options, &GrossErrorOptions::default(), &mut |done, total, what| {
///     reports.push((done, total, what.to_string()))
/// })?;
/// // Clean data: one fit, its stages named, then the end.
/// assert_eq!(reports[0], (0, 1, "calibration: rigid".to_string()));
/// assert_eq!(reports.last(), Some(&(1, 1, "done".to_string())));
/// # Ok::<(), sagcal::Error>(())
/// ```
pub fn calibrate_checked_with_progress(
    initial: &crate::model::Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    check: &GrossErrorOptions,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<CheckedCalibration> {
    screen::check_noise(&options.noise, initial)?;
    let mut fits = FitProgress::new(progress);
    let mut checked = checked_fit(initial, measurements, options, check, &mut fits)?;
    fits.finish();
    if let Some(why) = screen::undetermined(&checked.result, screen::robot_size_m(initial)) {
        checked.verdict = match checked.verdict {
            Verdict::Consistent => Verdict::Inconsistent { reason: why },
            Verdict::Inconsistent { reason } => Verdict::Inconsistent {
                reason: format!("{why}; {reason}"),
            },
        };
    }
    Ok(checked)
}

/// [`calibrate_checked`] after its check of the noise, without its check of
/// what the data determined: the data checked for mistakes, one plain fit
/// (all for data that pass), the robust screen, test-and-remove, and the fit
/// with every reading back if the search gave up.
fn checked_fit(
    initial: &crate::model::Robot,
    measurements: &[PoseMeasurement],
    options: &CalibrationOptions,
    check: &GrossErrorOptions,
    fits: &mut FitProgress<'_>,
) -> Result<CheckedCalibration> {
    let found = mistakes::before_calibration(initial, measurements);
    let (mut current, rows) = mistakes::without_rows_outside(measurements, &found);
    let mut state = Exclusions::new(check.max_excluded_fraction, current.len());
    refuse_unit_mistakes(&found)?;
    screen::check_kept_rows(initial, measurements, &current, &rows, &options.noise)?;
    let mut plain = None;
    // Clean data pass at the cost of one fit and its test.
    if let Ok(result) = fits.fit("calibration", initial, &current, options) {
        let test = test_fit(&result, &current, options, check)?;
        if test.consistent() {
            let at_fit = residuals_at_fit(&result, &current, options);
            return Ok(finish(result, current, rows, state, found, test, &at_fit));
        }
        plain = Some(PlainFit {
            result,
            test,
            all: current.clone(),
        });
    }
    // The screen's fit and a fit without what it leaves out, at least.
    fits.expect(2);
    robust_screen(initial, &mut current, options, check, &mut state, fits);
    let search = Search {
        initial,
        options,
        check,
    };
    let checked = test_and_remove(&search, current, &rows, &found, state, plain.as_ref(), fits)?;
    // An inconsistent fit is a model (or noise) error, not blunders: the
    // readings left out go back (kept in `set_aside`, with the mistakes named,
    // as hints), and the fit with every reading is the answer, with its verdict.
    Ok(match plain {
        Some(plain) if checked.verdict != Verdict::Consistent => gave_up(checked, plain, rows, options, check),
        _ => checked,
    })
}

/// What every fit of the search shares: the initial guess, the options and the tests.
#[derive(Clone, Copy)]
struct Search<'a> {
    initial: &'a crate::model::Robot,
    options: &'a CalibrationOptions,
    check: &'a GrossErrorOptions,
}

/// The first fit, with every reading the checks before it kept, and its tests.
struct PlainFit {
    result: CalibrationResult,
    test: ConsistencyTest,
    /// The measurements it used.
    all: Vec<PoseMeasurement>,
}

/// Readings logged in the wrong unit: no reading is to blame and no fit can
/// mend it, the data must be fixed.
fn refuse_unit_mistakes(found: &[Mistake]) -> Result<()> {
    let units: Vec<&str> = found
        .iter()
        .filter(|m| m.is_unit_mistake())
        .map(|m| m.message.as_str())
        .collect();
    if units.is_empty() {
        return Ok(());
    }
    Err(crate::error::CalibrationError::UnitMistakes {
        mistakes: units.iter().map(|m| m.to_string()).collect(),
    }
    .into())
}

/// Test-and-remove (module docs): calibrate, test, leave out an offset step
/// or the most significant flagged reading, and again until nothing is
/// flagged or more are flagged than a few blunders explain; then take back,
/// up to three rounds, what the final fit does not reject.
fn test_and_remove(
    search: &Search,
    mut current: Vec<PoseMeasurement>,
    rows: &[usize],
    found: &[Mistake],
    mut state: Exclusions,
    plain: Option<&PlainFit>,
    fits: &mut FitProgress<'_>,
) -> Result<CheckedCalibration> {
    let Search {
        initial,
        options,
        check,
    } = *search;
    let mut rounds = 0;
    Ok(loop {
        // With every reading back in (the robust screen left nothing out, or
        // all were taken back) the fit is the plain one, already tested.
        let (result, test) = match plain {
            Some(PlainFit { result, test, all }) if *all == current => (result.clone(), test.clone()),
            _ => {
                let result = fits.fit(&search_fit(state.excluded.len()), initial, &current, options)?;
                let test = test_fit(&result, &current, options, check)?;
                (result, test)
            }
        };
        let at_fit = residuals_at_fit(&result, &current, options);
        let room = state.limit.saturating_sub(state.counted());
        // One more fit per reading still to leave out (a reading given back adds one).
        fits.expect(test.flagged.len().min(room));
        if state.stepped == 0 && test.flagged.len() > room {
            if let Some((cable, rows_off)) = mistakes::offset_step(&current, &at_fit, check.false_alarm) {
                state.leave_out_step(&mut current, &at_fit, cable, &rows_off);
                continue;
            }
        }
        match test.flagged.first().copied() {
            // Data snooping assumes a few blunders: more flagged readings than
            // may still be left out reject that assumption, and the loop stops.
            Some(worst) if test.flagged.len() <= room => state.leave_out(&mut current, worst),
            _ if rounds < 3 && take_back(&result, &mut current, options, &test, &mut state) => rounds += 1,
            _ => break finish(result, current, rows.to_vec(), state, found.to_vec(), test, &at_fit),
        }
    })
}

/// The search for gross errors gave up on an inconsistent fit: the plain fit
/// with every reading, its verdict on its own tests (the numbers the report
/// prints beside it) saying so, the readings the search had left out listed
/// as set aside.
fn gave_up(
    checked: CheckedCalibration,
    plain: PlainFit,
    rows: Vec<usize>,
    options: &CalibrationOptions,
    check: &GrossErrorOptions,
) -> CheckedCalibration {
    let PlainFit { result, test, all } = plain;
    let at_fit = residuals_at_fit(&result, &all, options);
    let none = Exclusions::new(check.max_excluded_fraction, all.len());
    let mut reverted = finish(result, all, rows, none, checked.mistakes.clone(), test, &at_fit);
    if let Verdict::Inconsistent { reason } = &mut reverted.verdict {
        if !checked.excluded.is_empty() {
            reason.push_str(&format!(
                ". The search for gross errors gave up after leaving out {}, so the fit reported \
                 leaves none out ({} listed as set aside)",
                match checked.excluded.len() {
                    1 => "1 reading".to_string(),
                    n => format!("{n} readings"),
                },
                if checked.excluded.len() == 1 {
                    "it is"
                } else {
                    "they are"
                }
            ));
        }
    }
    reverted.set_aside = checked.excluded;
    reverted
}

/// The readings left out so far.
struct Exclusions {
    excluded: Vec<ExcludedReading>,
    /// How many of them an offset step left out (not counted against `limit`).
    stepped: usize,
    /// At most this many single readings.
    limit: usize,
    /// The cable whose offset step was left out, if any.
    step_cable: Option<usize>,
}

impl Exclusions {
    /// None left out yet; at most the fraction `max_excluded_fraction` (at
    /// least one) of the `poses`' readings may be.
    fn new(max_excluded_fraction: f64, poses: usize) -> Self {
        let total_readings = poses * (CABLE_COUNT + 1);
        Exclusions {
            excluded: Vec::new(),
            stepped: 0,
            limit: ((max_excluded_fraction * total_readings as f64).floor() as usize).max(1),
            step_cable: None,
        }
    }

    /// Single readings left out (an offset step's rows not counted).
    fn counted(&self) -> usize {
        self.excluded.len() - self.stepped
    }

    fn leave_out(&mut self, current: &mut [PoseMeasurement], test: ReadingTest) {
        current[test.pose].excluded = current[test.pose].excluded.with(test.sensor);
        self.excluded.push(ExcludedReading {
            test,
            explanation: None,
        });
    }

    /// Leave out `cable`'s readings in `rows_off` (an offset step).
    fn leave_out_step(
        &mut self,
        current: &mut [PoseMeasurement],
        at_fit: &HashMap<(usize, Sensor), (f64, f64)>,
        cable: usize,
        rows_off: &[usize],
    ) {
        for &k in rows_off {
            let sensor = Sensor::Encoder(cable);
            let Some(&(e, sigma)) = at_fit.get(&(k, sensor)) else {
                continue;
            };
            if current[k].excluded.contains(sensor) {
                continue;
            }
            self.leave_out(current, unweighed_test(k, current[k].line, sensor, e, sigma));
            self.stepped += 1;
        }
        self.step_cable = Some(cable);
    }
}

/// A reading's test from its residual alone (no redundancy number: at a robust
/// fit, or for a reading the fit did not use), `w = e / sigma`.
fn unweighed_test(pose: usize, line: usize, sensor: Sensor, e: f64, sigma: f64) -> ReadingTest {
    ReadingTest {
        pose,
        line,
        sensor,
        residual: e,
        sigma,
        redundancy: f64::NAN,
        w: e / sigma,
        estimated_error: -e,
    }
}

/// The robust kernel of the screening fit (Cauchy, in sigmas; Triggs et al.
/// 2000 sec. 3): a gross error's pull on the fit falls as `1/|r|`, so a
/// slipped encoder or swapped cables cannot drag the start into a wrong basin.
const SCREEN_KERNEL: RobustKernel = RobustKernel::Cauchy(2.3849);

/// Screen the data with a robust fit: an offset step in one cable's
/// residuals, and every reading beyond the critical `|e / sigma|` (Bonferroni
/// over the readings) when there are no more than `limit`, are left out
/// before the least-squares fit, which the test-and-remove loop then checks
/// (and [`take_back`] gives back what the final fit does not reject).
fn robust_screen(
    initial: &crate::model::Robot,
    current: &mut [PoseMeasurement],
    options: &CalibrationOptions,
    check: &GrossErrorOptions,
    state: &mut Exclusions,
    fits: &mut FitProgress<'_>,
) {
    let kernel = |k: RobustKernel| if k == RobustKernel::None { SCREEN_KERNEL } else { k };
    let robust = CalibrationOptions {
        robust: RobustKernels {
            encoder: kernel(options.robust.encoder),
            load_cell: kernel(options.robust.load_cell),
            pose_prior: kernel(options.robust.pose_prior),
        },
        ..*options
    };
    let Ok(result) = fits.fit("robust screen", initial, current, &robust) else {
        return;
    };
    let at_fit = residuals_at_fit(&result, current, options);
    if let Some((cable, rows_off)) = mistakes::offset_step(current, &at_fit, check.false_alarm) {
        state.leave_out_step(current, &at_fit, cable, &rows_off);
    }
    let critical = chi_square_critical(1, check.false_alarm / at_fit.len().max(1) as f64).sqrt();
    let mut suspects: Vec<ReadingTest> = at_fit
        .iter()
        .filter(|((k, sensor), (e, sigma))| (e / sigma).abs() > critical && !current[*k].excluded.contains(*sensor))
        .map(|(&(k, sensor), &(e, sigma))| unweighed_test(k, current[k].line, sensor, e, sigma))
        .collect();
    suspects.sort_by(|a, b| b.w.abs().total_cmp(&a.w.abs()));
    let suspects = localiser_first(suspects, current, &at_fit);
    if suspects.len() <= state.limit {
        for test in suspects {
            state.leave_out(current, test);
        }
    }
}

/// Where three or more readings of one pose are suspect, one localiser
/// blunder (which moves the pose and so every reading the statics tie to it)
/// is the more parsimonious explanation: that pose's suspects are replaced by
/// its localiser readings. They are set aside, not condemned: the
/// least-squares loop flags the readings that are wrong after all, and
/// [`take_back`] returns the localiser readings the final fit does not reject.
fn localiser_first(
    suspects: Vec<ReadingTest>,
    current: &[PoseMeasurement],
    at_fit: &HashMap<(usize, Sensor), (f64, f64)>,
) -> Vec<ReadingTest> {
    let mut poses: Vec<usize> = suspects.iter().map(|t| t.pose).collect();
    poses.sort_unstable();
    let crowded: Vec<usize> = poses
        .iter()
        .copied()
        .filter(|k| poses.iter().filter(|p| *p == k).count() >= 3)
        .collect();
    let mut out: Vec<ReadingTest> = suspects.into_iter().filter(|t| !crowded.contains(&t.pose)).collect();
    let mut done = Vec::new();
    for k in crowded {
        if done.contains(&k) {
            continue;
        }
        done.push(k);
        let localiser = (0..3).map(Sensor::Position).chain((0..3).map(Sensor::Orientation));
        for sensor in localiser {
            if let Some(&(e, sigma)) = at_fit.get(&(k, sensor)) {
                out.push(unweighed_test(k, current[k].line, sensor, e, sigma));
            }
        }
    }
    out
}

/// Give back every reading set aside by the screen whose residual against
/// the fit without it is within the critical `|w|` of `test`: the screening
/// is a first guess, the final fit decides. The residual of a reading the fit
/// did not use has variance `sigma^2 + var(prediction)` (externally
/// studentised); for a localiser reading the prediction's variance is the
/// fitted pose's own (its marginal covariance), for the others it is taken
/// as 0 (conservative: they stay out). Returns whether any came back.
fn take_back(
    result: &CalibrationResult,
    current: &mut [PoseMeasurement],
    options: &CalibrationOptions,
    test: &ConsistencyTest,
    state: &mut Exclusions,
) -> bool {
    let at_fit = residuals_at_fit(result, current, options);
    let (indices, used) = used_measurements(result, current);
    let built = graph_at_solution(result, &used, options);
    let prediction_variance = |k: usize, sensor: Sensor| -> f64 {
        let (axis, offset) = match sensor {
            Sensor::Orientation(a) => (a, 0),
            Sensor::Position(a) => (a, 3),
            _ => return 0.0,
        };
        let Some(slot) = indices.iter().position(|&i| i == k) else {
            return 0.0;
        };
        match crate::solver::marginal_covariance(&built.graph, &[built.poses[slot].pose]) {
            Ok(crate::solver::Covariance::Full(c)) => c[(offset + axis, offset + axis)].max(0.0),
            _ => 0.0,
        }
    };
    let before = state.excluded.len();
    state.excluded.retain(|x| {
        let key = (x.test.pose, x.test.sensor);
        // Readings the least-squares loop left out (with a redundancy number) stay out.
        let keep_out = x.test.redundancy.is_finite()
            || at_fit.get(&key).is_none_or(|(e, sigma)| {
                let spread = (sigma * sigma + prediction_variance(key.0, key.1)).sqrt();
                (e / spread).abs() > test.critical_w
            });
        if !keep_out {
            current[x.test.pose].excluded = current[x.test.pose].excluded.without(x.test.sensor);
        }
        keep_out
    });
    state.excluded.len() < before
}

/// The checked calibration of the final fit: each left-out reading's error
/// against it, the mistakes that explain them, rows as given, the verdict.
fn finish(
    result: CalibrationResult,
    current: Vec<PoseMeasurement>,
    rows: Vec<usize>,
    mut state: Exclusions,
    mut found: Vec<Mistake>,
    mut test: ConsistencyTest,
    at_fit: &HashMap<(usize, Sensor), (f64, f64)>,
) -> CheckedCalibration {
    // Each left-out reading's error against the final fit, which it did not pull.
    for x in &mut state.excluded {
        if let Some(&(e, sigma)) = at_fit.get(&(x.test.pose, x.test.sensor)) {
            x.test.residual = e;
            x.test.estimated_error = -e;
            if x.test.redundancy.is_nan() {
                x.test.w = e / sigma; // set aside by the screen: its residual against the final fit
            }
        }
    }
    if let Some(cable) = state.step_cable {
        found.extend(mistakes::name_step(cable, &rows, &mut state.excluded));
    }
    found.extend(mistakes::after_calibration(
        &current,
        &rows,
        at_fit,
        &mut state.excluded,
    ));
    // Report rows as given (rows outside the frame were left out before the fit).
    for t in test.flagged.iter_mut().chain(test.largest.as_mut()) {
        t.pose = rows[t.pose];
    }
    for x in &mut state.excluded {
        x.test.pose = rows[x.test.pose];
    }
    let verdict = verdict(&test, state.counted(), state.limit, &found);
    CheckedCalibration {
        result,
        measurements: current,
        rows,
        excluded: state.excluded,
        set_aside: Vec::new(),
        mistakes: found,
        test,
        verdict,
    }
}

/// The verdict on the final fit.
fn verdict(test: &ConsistencyTest, excluded: usize, limit: usize, found: &[Mistake]) -> Verdict {
    let units: Vec<String> = found
        .iter()
        .filter(|m| m.is_unit_mistake())
        .map(|m| m.message.clone())
        .collect();
    if !units.is_empty() {
        // The readings cannot be tested one by one until the column is fixed.
        return Verdict::Inconsistent {
            reason: format!(
                "{}; fix the data (or the robot file) and calibrate again",
                units.join("; ")
            ),
        };
    }
    let mut reasons = Vec::new();
    if !test.flagged.is_empty() {
        let names: Vec<String> = test.flagged.iter().take(3).map(ReadingTest::describe).collect();
        let fail = match excluded {
            0 => format!("{} readings fail the w-test", test.flagged.len()),
            _ => format!(
                "{} readings still fail the w-test after {excluded} were left out (at most {limit} may be)",
                test.flagged.len()
            ),
        };
        reasons.push(format!(
            "{fail}: {}{}",
            names.join("; "),
            if test.flagged.len() > 3 { "; ..." } else { "" }
        ));
    }
    for t in test.sensor_types.iter().filter(|t| !t.consistent) {
        reasons.push(format!(
            "the {} readings fail their chi-square test: {:.1} against an expected {:.1} (p = {:.1e})",
            t.sensor, t.chi_square, t.redundancy, t.p_value
        ));
    }
    if reasons.is_empty() {
        Verdict::Consistent
    } else {
        Verdict::Inconsistent {
            reason: format!(
                "{}. The model or the stated noise does not describe these data: run `sagcal diagnose` to find what it misses",
                reasons.join("; ")
            ),
        }
    }
}

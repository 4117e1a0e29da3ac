//! The job of `sagcal calibrate` and of `sagcal.calibrate` in Python: the
//! settings checked, the calibration with its gross-error tests, its report,
//! and the refusal of a fit that fails its own consistency tests. The front
//! ends format what [`calibrate_job`] returns; the refusal names how to
//! override it as the caller spells it ([`FrontEnd`]).

use super::gross_errors::{calibrate_checked_with_progress, CheckedCalibration, Verdict};
use super::report::{CalibrationReport, CheckedReport, GrossErrorReport};
use super::settings::CalibrationSettings;
use super::CalibrationOptions;
use crate::error::{CalibrationError, Error, FrontEnd, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::DataRow;
use crate::model::Robot;

/// A checked calibration, its report, and whether it is refused.
#[derive(Debug)]
pub struct CalibrationJob {
    /// The calibration options the settings gave.
    pub options: CalibrationOptions,
    /// The calibration with its gross-error tests.
    pub checked: CheckedCalibration,
    /// The report (what `sagcal calibrate --json` prints).
    pub report: CheckedReport,
    /// For a fit that fails its own consistency tests, unless
    /// [`CalibrationSettings::accept_inconsistent`]: the error to give once
    /// the report is shown ([`refusal`]); nothing is to be written.
    pub refusal: Option<Error>,
}

/// Calibrate `nominal` from `measurements` under `settings`, as `sagcal
/// calibrate` does: check the settings ([`CalibrationSettings::options`]),
/// calibrate with the gross-error tests ([`super::gross_errors::calibrate_checked`]), build the
/// report (each pose named by its row and its file line,
/// [`crate::model::DataRow`]) and, for an inconsistent fit not accepted, the refusal.
/// `source` names the measurements in messages (the file as given); an error
/// of the calibration says that no robot file is written.
///
/// ```
/// use rand::SeedableRng;
/// use sagcal::calib::{calibrate_job, CalibrationSettings};
/// use sagcal::error::FrontEnd;
/// use sagcal::model::sensors::NoisePreset;
/// use sagcal::model::Robot;
/// use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
/// let truth = Robot::builtin("large")?;
/// let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
/// let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 12, &mut rng)?;
/// let data = measure(&truth, &equilibria, &NoisePreset::Paper.sigmas(truth.platform_weight_n), &mut rng);
/// let settings = CalibrationSettings::new(NoisePreset::Paper);
/// let job = calibrate_job(&truth, &data, "simulated", &settings, FrontEnd::Cli)?;
/// assert!(job.refusal.is_none());
/// assert_eq!(job.report.report.poses_used, 12);
/// # Ok::<(), sagcal::Error>(())
/// ```
pub fn calibrate_job(
    nominal: &Robot,
    measurements: &[PoseMeasurement],
    source: &str,
    settings: &CalibrationSettings,
    front_end: FrontEnd,
) -> Result<CalibrationJob> {
    calibrate_job_with_progress(nominal, measurements, source, settings, front_end, &mut |_, _, _| {})
}

/// [`calibrate_job`], telling `progress(done, total, what)` before each
/// stage of each fit, as [`calibrate_checked_with_progress`] does (`sagcal
/// calibrate` draws it, `sagcal.calibrate(..., progress=)` passes it on); it
/// changes nothing computed.
pub fn calibrate_job_with_progress(
    nominal: &Robot,
    measurements: &[PoseMeasurement],
    source: &str,
    settings: &CalibrationSettings,
    front_end: FrontEnd,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<CalibrationJob> {
    let (options, check) = settings.options(nominal, front_end)?;
    let checked = calibrate_checked_with_progress(nominal, measurements, &options, &check, progress);
    let checked = checked.map_err(|e| match e {
        Error::Cancelled => e,
        cause => Error::NotWritten {
            source_name: source.to_string(),
            cause: Box::new(cause),
        },
    })?;
    let rows: Vec<DataRow> = checked
        .rows
        .iter()
        .map(|&row| DataRow::at(row, measurements[row].line))
        .collect();
    let report = CheckedReport {
        report: CalibrationReport::new(&checked.result, nominal, options.model, &rows, None),
        gross_errors: GrossErrorReport::new(&checked),
    };
    let refusal = match &checked.verdict {
        Verdict::Inconsistent { reason } if !settings.accept_inconsistent => Some(refusal(source, reason, front_end)),
        _ => None,
    };
    Ok(CalibrationJob {
        options,
        checked,
        report,
        refusal,
    })
}

/// The refusal of a fit of `source` that fails its own consistency tests
/// (`reason` names the sensors), with how `front_end` accepts it anyway.
///
/// ```
/// use sagcal::calib::refusal;
/// use sagcal::error::FrontEnd;
/// let cli = refusal("m.csv", "the load cell fails", FrontEnd::Cli).to_string();
/// assert!(cli.contains("(--accept-inconsistent writes it anyway): the load cell fails"), "{cli}");
/// let python = refusal("measurements", "the load cell fails", FrontEnd::Python).to_string();
/// assert!(python.contains("(accept_inconsistent=True returns it anyway)"), "{python}");
/// ```
pub fn refusal(source: &str, reason: &str, front_end: FrontEnd) -> Error {
    let accept = front_end.switch("accept_inconsistent");
    let anyway = match front_end {
        FrontEnd::Cli => "writes it anyway",
        FrontEnd::Python => "returns it anyway",
    };
    CalibrationError::Refused {
        source_name: source.to_string(),
        accept,
        anyway,
        reason: reason.to_string(),
    }
    .into()
}

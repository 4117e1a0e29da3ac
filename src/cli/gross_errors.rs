//! The gross-error section of `sagcal calibrate`'s report (table and JSON).

use serde::Serialize;

use sagcal::calib::gross_errors::{CheckedCalibration, ConsistencyTest, ExcludedReading, Verdict};
use sagcal::calib::mistakes::Mistake;

use super::output::Table;

/// What the gross-error tests found and did.
#[derive(Debug, Clone, Serialize)]
pub struct GrossErrorReport {
    /// `consistent`, or `inconsistent` with its reason.
    pub verdict: Verdict,
    /// Readings left out, each with its row, sensor, estimated error, `w` and explanation.
    pub excluded_readings: Vec<ExcludedReading>,
    /// For an inconsistent fit: the readings the search had left out before
    /// it gave up (the fit reported uses them; omitted when empty).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub set_aside_readings: Vec<ExcludedReading>,
    /// Common mistakes recognised (units, swapped cables, re-homing, poses outside the frame).
    pub mistakes: Vec<Mistake>,
    /// The tests of the final fit.
    pub tests: ConsistencyTest,
}

impl GrossErrorReport {
    /// The report of a checked calibration.
    pub fn new(checked: &CheckedCalibration) -> Self {
        Self {
            verdict: checked.verdict.clone(),
            excluded_readings: checked.excluded.clone(),
            set_aside_readings: checked.set_aside.clone(),
            mistakes: checked.mistakes.clone(),
            tests: checked.test.clone(),
        }
    }
}

/// The section in words and tables.
pub fn render(report: &GrossErrorReport) -> String {
    let t = &report.tests;
    let mut out = format!(
        "\ngross errors (data snooping: |w| > {:.2} flags a reading, {} readings tested):\n",
        t.critical_w, t.readings
    );
    let mut types = Table::new(["sensor", "readings", "chi-square", "expected", "p-value", "consistent"]);
    for s in &t.sensor_types {
        types.row([
            s.sensor.clone(),
            s.readings.to_string(),
            format!("{:.1}", s.chi_square),
            format!("{:.1}", s.redundancy),
            format!("{:.2e}", s.p_value),
            if s.consistent { "yes" } else { "NO" }.to_string(),
        ]);
    }
    out += &types.to_string();
    if let Some(largest) = &t.largest {
        out += &format!("largest |w|: {}\n", largest.describe());
    }
    if report.excluded_readings.is_empty() && !report.set_aside_readings.is_empty() {
        out += &format!(
            "no reading left out of the fit reported: the search for gross errors gave up after leaving out {}:\n",
            report.set_aside_readings.len()
        );
        for x in &report.set_aside_readings {
            out += &format!("  set aside: {}\n", x.test.describe());
        }
    } else if report.excluded_readings.is_empty() {
        out += "no reading left out\n";
    } else {
        out += &format!(
            "{} readings left out as gross errors:\n",
            report.excluded_readings.len()
        );
        for x in &report.excluded_readings {
            out += &format!("  {}\n", x.test.describe());
        }
    }
    for m in &report.mistakes {
        out += &format!("MISTAKE: {}\n", m.message);
    }
    match &report.verdict {
        Verdict::Consistent => out += "verdict: consistent with the stated noise\n",
        Verdict::Inconsistent { reason } => out += &format!("verdict: INCONSISTENT: {reason}\n"),
    }
    out
}

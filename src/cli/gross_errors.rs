//! The gross-error section of `sagcal calibrate`'s report in words and tables.

use sagcal::calib::gross_errors::Verdict;
use sagcal::calib::report::GrossErrorReport;

use super::output::{counted, Table};

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
            "{} left out as gross errors:\n",
            counted(report.excluded_readings.len(), "reading", "readings")
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

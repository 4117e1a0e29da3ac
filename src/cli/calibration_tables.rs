//! The tables and the figure of a calibration report, for robots of four
//! cables and of 3 to 8: anchors and offsets, unobservable directions,
//! residuals per factor type, the solver's stages, and the anchor plot.

use sagcal::calib::{FactorStatistics, ParameterUncertainty, StageSummary};
use sagcal::plot::{anchor_plot_svg, AnchorPlot, AnchorPlotEntry};

use super::output::Table;

/// A 1-sigma with three decimals, `n/a` where there is none.
pub(super) fn sigma(value: Option<f64>) -> String {
    value.map_or_else(|| "n/a".to_string(), |s| format!("{s:.3}"))
}

/// The anchors (position, 1-sigma, change from nominal) and the offsets
/// (value, 1-sigma) of a calibration, one table each.
pub(super) fn parameter_tables(
    anchors_m: &[[f64; 3]],
    anchor_sigma_m: Option<&[[f64; 3]]>,
    anchor_change_m: &[[f64; 3]],
    length_offsets_m: &[f64],
    offset_sigma_m: Option<&[f64]>,
) -> String {
    let mut anchors = Table::new([
        "anchor",
        "x m",
        "y m",
        "z m",
        "1-sigma x,y,z m",
        "change from nominal m",
    ]);
    for (i, a) in anchors_m.iter().enumerate() {
        let s = anchor_sigma_m.map(|s| s[i]);
        let d = anchor_change_m[i];
        anchors.row([
            format!("{}", i + 1),
            format!("{:.3}", a[0]),
            format!("{:.3}", a[1]),
            format!("{:.3}", a[2]),
            s.map_or("n/a".into(), |s| format!("{:.3} {:.3} {:.3}", s[0], s[1], s[2])),
            format!("{:+.3} {:+.3} {:+.3}", d[0], d[1], d[2]),
        ]);
    }
    let mut out = anchors.to_string();
    out += "\n";
    let mut offsets = Table::new(["cable", "length offset m", "1-sigma m"]);
    for (i, o) in length_offsets_m.iter().enumerate() {
        offsets.row([
            format!("{}", i + 1),
            format!("{o:.4}"),
            sigma(offset_sigma_m.map(|s| s[i])),
        ]);
    }
    out += &offsets.to_string();
    out
}

/// The directions the poses leave unobservable (if any), the normalised
/// residuals per factor type and the solver's stages.
pub(super) fn fit_tables(
    uncertainty: &ParameterUncertainty,
    factor_statistics: &[FactorStatistics],
    stages: &[StageSummary],
) -> String {
    let mut out = String::new();
    if let ParameterUncertainty::RankDeficient { directions } = uncertainty {
        out += "\nNOT OBSERVABLE from these poses (add poses spread over the workspace):\n";
        for d in directions {
            let parts: Vec<String> = d
                .components
                .iter()
                .take(6)
                .map(|(name, c, w)| format!("{w:+.2} {name}[{}]", ["x", "y", "z"].get(*c).unwrap_or(&"?")))
                .collect();
            out += &format!("  direction: {}\n", parts.join(" "));
        }
    }
    out += "\nnormalised residuals r/sigma per factor type (rms ~ 1 when the stated noise is right):\n";
    let mut stats = Table::new(["factor", "count", "rms", "max |r/sigma|"]);
    for s in factor_statistics {
        stats.row([
            s.kind.clone(),
            s.factors.to_string(),
            format!("{:.3}", s.rms),
            format!("{:.2}", s.max_abs),
        ]);
    }
    out += &stats.to_string();
    out += "\nsolver:\n";
    let mut table = Table::new(["stage", "iterations", "initial cost", "final cost", "termination"]);
    for s in stages {
        table.row([
            s.name.clone(),
            s.summary.iterations.to_string(),
            format!("{:.4e}", s.summary.initial_cost),
            format!("{:.4e}", s.summary.final_cost),
            s.summary.termination.to_string(),
        ]);
    }
    out += &table.to_string();
    out
}

/// The anchor plot (SVG) of calibrated anchors `estimates_m` against the
/// `nominal_m` they started from, with the error ellipses of `uncertainty`
/// and the truth where known.
pub(super) fn calibrated_anchor_plot(
    title: String,
    caption: &str,
    nominal_m: &[[f64; 3]],
    estimates_m: &[[f64; 3]],
    uncertainty: &ParameterUncertainty,
    truth_m: Option<&[[f64; 3]]>,
    positions: &[[f64; 3]],
) -> String {
    let covariances = match uncertainty {
        ParameterUncertainty::Full {
            anchor_covariance_m2, ..
        } => Some(anchor_covariance_m2.clone()),
        ParameterUncertainty::RankDeficient { .. } => None,
    };
    let plot = AnchorPlot {
        title,
        caption: caption.to_string(),
        anchors: (0..estimates_m.len())
            .map(|i| AnchorPlotEntry {
                label: format!("anchor {}", i + 1),
                nominal_m: nominal_m[i],
                initial_m: Some(nominal_m[i]),
                estimate_m: estimates_m[i],
                covariance_m2: covariances.as_ref().map(|c| c[i]),
                truth_m: truth_m.map(|t| t[i]),
            })
            .collect(),
        platform_positions_m: positions.to_vec(),
    };
    anchor_plot_svg(&plot)
}

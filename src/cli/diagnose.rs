//! `sagcal diagnose`: what the calibration model gets wrong, and what an extension gains.

use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use sagcal::diagnose::{diagnose, DiagnoseOptions, Diagnosis};
use sagcal::io::measurements::{read_measurements, ReadOptions};
use sagcal::model::effects::EffectKind;
use sagcal::model::Robot;
use sagcal::plot::residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};

use super::output::{print_json, Table};
use super::DiagnoseArgs;

pub fn run(args: &DiagnoseArgs) -> sagcal::Result<()> {
    let nominal = Robot::from_file(&args.robot)?;
    let truth = args.truth.as_deref().map(Robot::from_file).transpose()?;
    let data = read_measurements(
        &args.data,
        &ReadOptions {
            reference_cable: nominal.reference_cable,
            keep_rounded: false,
        },
    )?;
    let mut options = DiagnoseOptions::new(args.solver.options(&nominal)?);
    options.folds = args.folds;
    options.min_bic_drop = args.min_bic_drop;
    if let Some(list) = &args.candidates {
        options.candidates = list
            .split(',')
            .map(EffectKind::parse)
            .collect::<Result<_, _>>()
            .map_err(|e| sagcal::Error::InvalidInput(format!("--candidates: {e}")))?;
    }
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{msg:40} [{bar:30}] {pos}/{len} fits, {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let diagnosis = diagnose(
        &nominal,
        &data.poses,
        truth.as_ref(),
        &options,
        &mut |done, total, what| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            bar.set_message(what.to_string());
        },
    )?;
    bar.finish_and_clear();
    // Files only after everything succeeded, each atomically.
    let plot_path = match &args.plots {
        Some(dir) => Some(write_plots(dir, &diagnosis, &args.data)?),
        None => None,
    };
    if args.json {
        print_json(&diagnosis)
    } else {
        print!("{}", render(&diagnosis, &options));
        if let Some(path) = plot_path {
            println!("plot written to {}", path.display());
        }
        Ok(())
    }
}

fn file_name(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect::<String>()
        .split('_')
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join("_")
}

fn write_plots(dir: &Path, diagnosis: &Diagnosis, data: &Path) -> sagcal::Result<std::path::PathBuf> {
    std::fs::create_dir_all(dir).map_err(|e| {
        sagcal::Error::InvalidInput(format!("--plots {}: cannot create the folder: {e}", dir.display()))
    })?;
    let s = &diagnosis.series;
    let path = dir.join(format!("{}_vs_{}.svg", s.residual, file_name(&s.driver)));
    let plot = ResidualPlot {
        title: format!(
            "sagcal diagnose `{}`: {} residual vs {} (verdict: {})",
            diagnosis.robot, s.residual, s.driver, diagnosis.verdict
        ),
        driver_label: s.driver.clone(),
        residual_label: format!("{} residual / sigma", s.residual),
        before: ResidualSeries {
            label: "baseline model".into(),
            points: s.before.clone(),
        },
        after: s.after.as_ref().map(|points| ResidualSeries {
            label: format!("with {}", diagnosis.verdict),
            points: points.clone(),
        }),
        caption: format!(
            "{}; held-out residual RMS {:.3} -> {:.3} ({})",
            data.display(),
            diagnosis.gain.residual_rms_before,
            diagnosis.gain.residual_rms_after,
            diagnosis.reason
        ),
    };
    sagcal::plot::write_svg(&path, &residual_plot_svg(&plot))?;
    Ok(path)
}

fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "-".into(), |v| format!("{v:.digits$}"))
}

/// The `count` strongest residual-driver correlations as a table.
fn driver_table(tests: &[sagcal::diagnose::DriverTest], count: usize) -> String {
    let mut table = Table::new(["residual", "driver", "points", "correlation", "t", "structure"]);
    for t in tests.iter().take(count) {
        table.row([
            t.residual.clone(),
            t.driver.clone(),
            t.points.to_string(),
            format!("{:+.3}", t.correlation),
            format!("{:+.1}", t.t_statistic),
            if t.significant {
                "yes (p < 0.001)".into()
            } else {
                "no".to_string()
            },
        ]);
    }
    table.to_string()
}

/// The human-readable diagnosis.
pub fn render(d: &Diagnosis, options: &DiagnoseOptions) -> String {
    let mut out = format!(
        "sagcal diagnose: robot `{}`, {} poses, {} measurement components, {}-fold cross-validation\n\n",
        d.robot, d.poses_used, d.measurement_components, options.folds
    );
    out += &format!(
        "1. baseline model against the stated noise: chi-square {:.1} for {} degrees of freedom ({})\n",
        d.baseline_chi_square,
        d.baseline_dof,
        if d.baseline_consistent {
            "consistent"
        } else {
            "INCONSISTENT at 99.9 %"
        }
    );
    let mut tests = Table::new([
        "factor",
        "components",
        "chi-square",
        "expected",
        "99.9 % limit",
        "verdict",
    ]);
    for t in &d.factor_tests {
        tests.row([
            t.kind.clone(),
            t.components.to_string(),
            format!("{:.1}", t.chi_square),
            format!("{:.1}", t.expected),
            format!("{:.1}", t.limit),
            if t.consistent {
                "consistent".into()
            } else {
                "too large".to_string()
            },
        ]);
    }
    out += &tests.to_string();
    if d.variance_factor != 1.0 {
        out += &format!(
            "   the data are more precise than the stated noise: the information criteria use the a posteriori variance factor {:.4} (residual scale x{:.3})\n",
            d.variance_factor,
            d.variance_factor.sqrt()
        );
    }
    out += "\n2. residual structure (baseline): correlation with physical drivers, strongest first\n";
    out += &driver_table(&d.drivers, 8);
    out += &format!(
        "\n3. candidate extensions (baseline: BIC {:.1}, held-out residual RMS {:.3})\n",
        d.baseline_bic, d.baseline_cv_rms
    );
    let mut candidates = Table::new([
        "effect",
        "parameters (1-sigma)",
        "delta BIC",
        "held-out RMS",
        "anchor MAE m",
    ]);
    for c in &d.candidates {
        let params = if c.params.is_empty() {
            format!("failed: {}", c.error.clone().unwrap_or_default())
        } else {
            c.params
                .iter()
                .map(|p| format!("{} {:.4e} ({:.1e})", p.name, p.value, p.sigma))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let params = match &c.inadmissible {
            Some(why) => format!("{params} [impossible: {why}]"),
            None => params,
        };
        candidates.row([
            c.effect.clone(),
            params,
            format!("{:+.1}", c.delta_bic),
            format!("{:.3}", c.cv_rms),
            opt(c.anchor_mae_m, 4),
        ]);
    }
    out += &candidates.to_string();
    out += &format!("\n4. verdict: {}\n   {}\n", d.verdict, d.reason);
    let g = &d.gain;
    out += &format!(
        "   gain: held-out residual RMS {:.3} -> {:.3}",
        g.residual_rms_before, g.residual_rms_after
    );
    if g.anchor_mae_before_m.is_some() {
        out += &format!(
            "; against the truth: anchor MAE {} -> {} m (mean Euclidean {} -> {} m), offset MAE {} -> {} m",
            opt(g.anchor_mae_before_m, 4),
            opt(g.anchor_mae_after_m, 4),
            opt(g.anchor_mean_euclidean_before_m, 4),
            opt(g.anchor_mean_euclidean_after_m, 4),
            opt(g.offset_mae_before_m, 4),
            opt(g.offset_mae_after_m, 4)
        );
    }
    out += "\n";
    if !d.drivers_after.is_empty() {
        out += &format!("\n   residual structure left with {} (strongest first):\n", d.verdict);
        out += &driver_table(&d.drivers_after, 5);
    }
    out
}

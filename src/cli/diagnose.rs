//! `sagcal diagnose`: what the calibration model gets wrong, and what an extension gains;
//! the run on a four-cable robot (flags: [`DiagnoseArgs`]).

use std::path::Path;

use sagcal::diagnose::{diagnose, DiagnoseOptions, DiagnoseSettings, Diagnosis};
use sagcal::error::FrontEnd;
use sagcal::io::measurements::{read_measurements, MeasurementFormat, ReadOptions};
use sagcal::io::OutputSet;
use sagcal::model::effect_kind::EffectKind;
use sagcal::model::Robot;
use sagcal::plot::residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};

use super::diagnose_args::DiagnoseArgs;
use super::output::{counted, opt, print_json, progress_bar, Table};
use super::robot_kind::{read_robot, AnyRobot};

/// Diagnose the data against the nominal robot, write the requested files, print the report (or JSON).
/// A robot of 3 to 8 cables goes to [`super::diagnose_suspended::run`].
pub fn run(args: &DiagnoseArgs) -> sagcal::Result<()> {
    let nominal = match read_robot(&args.robot)? {
        AnyRobot::Four(robot) => *robot,
        AnyRobot::Suspended(robot) => return super::diagnose_suspended::run(args, &robot),
    };
    let truth = args.truth.as_deref().map(Robot::from_file).transpose()?;
    let data = read_measurements(
        &args.data,
        &ReadOptions {
            reference_cable: nominal.reference_cable,
            keep_rounded: false,
        },
    )?;
    let settings = DiagnoseSettings {
        solver: args.solver.settings(),
        candidates: args
            .candidates
            .as_ref()
            .map(|list| list.split(',').map(str::to_string).collect()),
        orientation_hypothesis: !args.no_orientation_hypothesis,
        folds: args.folds,
        false_alarm: args.false_alarm,
        rows_in_time_order: data.format == MeasurementFormat::Sagcal,
    };
    let options = settings.options(&nominal, FrontEnd::Cli)?;
    let bar = progress_bar(1, "{msg:40} [{bar:30}] {pos}/{len} fits, {elapsed}");
    let diagnosis = diagnose(
        &nominal,
        &data.poses,
        truth.as_ref(),
        &options,
        &mut |done, total, what| bar.report(done, total, what),
    )?;
    bar.finish_and_clear();
    // Files only after everything succeeded: all of them or none, none over an input.
    let mut outputs = OutputSet::new();
    outputs.input("--robot", &args.robot).input("--data", &args.data);
    if let Some(truth) = &args.truth {
        outputs.input("--truth", truth);
    }
    let plot_path = match &args.plots {
        Some(dir) => Some(add_plots(
            &mut outputs,
            dir,
            args.plot_format.extension(),
            &diagnosis,
            &args.data,
        )?),
        None => None,
    };
    if let Some(out) = &args.out {
        outputs.file("--out", out, extended_robot_text(&diagnosis)?);
    }
    outputs.write()?;
    if args.json {
        print_json(&diagnosis)
    } else {
        print!("{}", render(&diagnosis, &options));
        if let Some(path) = plot_path {
            println!("plot written to {}", path.display());
        }
        if let Some(out) = &args.out {
            println!("robot with the selected model written to {}", out.display());
        }
        Ok(())
    }
}

/// The selected model's robot (TOML), with a header naming the verdict.
fn extended_robot_text(diagnosis: &Diagnosis) -> sagcal::Result<String> {
    let text = diagnosis.robot_after.to_file_contents().to_toml()?;
    let header = format!(
        "# Calibrated by sagcal diagnose: anchors, encoder length offsets and the final model ({}; verdict {}).\n",
        diagnosis.explanation.final_model, diagnosis.verdict
    );
    Ok(format!("{header}{text}"))
}

/// `text` as a file name: ASCII letters (lower-cased) and digits, each run of anything else one `_`, none at the ends.
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

/// Add to `outputs` the folder `dir` and the residual plot against the
/// winning driver (before and after) in it as `extension` (`svg` or `png`); its path.
fn add_plots(
    outputs: &mut OutputSet,
    dir: &Path,
    extension: &str,
    diagnosis: &Diagnosis,
    data: &Path,
) -> sagcal::Result<std::path::PathBuf> {
    let s = &diagnosis.series;
    let path = dir.join(format!("{}_vs_{}.{extension}", s.residual, file_name(&s.driver)));
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
            label: format!("with {}", diagnosis.explanation.final_model),
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
    let bytes = sagcal::plot::figure_bytes(&path, &residual_plot_svg(&plot))?;
    outputs.folder("--plots", dir).file("--plots", &path, bytes);
    Ok(path)
}

/// The human-readable diagnosis: the four steps of the search.
pub fn render(d: &Diagnosis, options: &DiagnoseOptions) -> String {
    let mut out = format!(
        "sagcal diagnose: robot `{}`, {} poses, {} measurement components, {}-fold cross-validation, orientation prior {}\n\n",
        d.robot, d.poses_used, d.measurement_components, options.folds, d.orientation_prior
    );
    out += &render_gross_errors(d);
    out += &render_residual_tests(d);
    out += "\n2. residual structure (baseline): correlation with physical drivers, strongest first\n";
    if !d.rows_in_time_order {
        out += "   the rows are not in the order the poses were taken (a RecurDyn log or an authors' folder): \
                no drift over the rows or direction of motion is tested, and the effects of time and motion \
                (encoder-drift, encoder-backlash, loadcell-drift, loadcell-friction) are not hypotheses\n";
    }
    if d.first_row_left_out {
        out += "   the first row's encoders and load cell take no part in any fit: the direction of the motion \
                that led there is unknown, and backlash and pulley friction depend on it\n";
    }
    out += &driver_table(&d.drivers, 8);
    out += &format!(
        "\n3. forward selection at a false-alarm rate of {:.0e} (baseline: held-out residual RMS {:.3})\n",
        d.false_alarm, d.baseline_cv_rms
    );
    out += &render_candidates(d);
    out += &render_verdict(d);
    out
}

/// Step 0: readings left out as gross errors, and mistakes named.
fn render_gross_errors(d: &Diagnosis) -> String {
    let mut out = String::from("0. gross errors (the tests of `sagcal calibrate`): ");
    if d.excluded_readings.is_empty() && d.mistakes.is_empty() {
        return out + "no reading left out\n\n";
    }
    out += &format!(
        "{} left out\n",
        counted(d.excluded_readings.len(), "reading", "readings")
    );
    for x in &d.excluded_readings {
        out += &format!("   {}\n", x.test.describe());
    }
    for m in &d.mistakes {
        out += &format!("   MISTAKE: {}\n", m.message);
    }
    out + "\n"
}

/// Step 1: the chi-square test per factor type.
fn render_residual_tests(d: &Diagnosis) -> String {
    let mut out = format!(
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
    if let Some(n) = &d.noise_shown {
        out += &format!(
            "   the sensors are more precise than stated, each by its own factor: the table and every test use the noise \
             their data show (encoder {:.3} mm, load cell {:.3} N, localiser {:.3} mm and {:.5} rad)\n",
            n.encoder_sigma_m * 1e3,
            n.load_cell_sigma_n,
            n.position_sigma_m * 1e3,
            n.orientation_sigma_rad
        );
    }
    if d.variance_factor != 1.0 {
        out += &format!(
            "   the data are more precise than the stated noise: the tests use the a posteriori variance factor {:.4} (residual scale x{:.3})\n",
            d.variance_factor,
            d.variance_factor.sqrt()
        );
    }
    out
}

/// The width of the hypotheses' parameter lists, wrapped onto lines of their
/// own: with the other columns the table stays within about 140 columns.
const PARAMETERS_WIDTH: usize = 48;

/// Step 3: every hypothesis tested, step by step.
fn render_candidates(d: &Diagnosis) -> String {
    let mut table = Table::new([
        "step",
        "hypothesis",
        "extends",
        "LR",
        "dof",
        "p-value",
        "needs <",
        "power",
        "anchor MAE m",
        "parameters (1-sigma)",
    ])
    .wrap_last(PARAMETERS_WIDTH);
    for c in &d.candidates {
        let params = if let Some(error) = &c.error {
            format!("failed: {error}")
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
        table.row([
            c.step.to_string(),
            format!("{}{}", c.effect, if c.significant { " *" } else { "" }),
            c.extends.clone(),
            format!("{:.1}", c.lr_statistic),
            c.added_parameters.to_string(),
            format!("{:.2e}", c.p_value),
            format!("{:.1e}", c.p_threshold),
            opt(c.power, 2),
            opt(c.anchor_mae_m, 4),
            params,
        ]);
    }
    let mut out = table.to_string();
    out += "   (* significant; power: of the test at the effect's smallest plausible magnitude for this robot)\n";
    out
}

/// For the elastic effect's fitted compliance (1/MN), the axial stiffness
/// it gives in the robot file's name and unit: ` (axial_stiffness_n 3.1e6)`.
fn stiffness_note(parameter: &str, value: f64) -> String {
    let compliance = EffectKind::Elastic.parameter_names()[0];
    if parameter == compliance && value > 0.0 {
        format!(" (axial_stiffness_n {:.2e})", 1e6 / value)
    } else {
        String::new()
    }
}

/// Step 4: the verdict, the final model's effects, what it leaves, the gain
/// and the structure left.
fn render_verdict(d: &Diagnosis) -> String {
    let mut out = format!("\n4. verdict: {}\n   {}\n", d.verdict, d.reason);
    for e in &d.effects {
        let params: Vec<String> = e
            .params
            .iter()
            .map(|p| {
                format!(
                    "{} {:.5e} +- {:.1e}{}",
                    p.name,
                    p.value,
                    p.sigma,
                    stiffness_note(&p.name, p.value)
                )
            })
            .collect();
        let stand_in = d.explanation.stand_ins.iter().any(|s| s.hypothesis == e.effect);
        let proxy = d.explanation.explained_away.contains(&e.effect);
        out += &format!(
            "   {}{}: {}\n",
            e.effect,
            match (stand_in, proxy) {
                (true, _) => " (stand-in)",
                (false, true) => " (proxy: not needed beyond the proposed terms)",
                _ => "",
            },
            params.join(", ")
        );
    }
    for s in &d.explanation.stand_ins {
        out += &format!("   stand-in: {}\n", s.sentence());
    }
    for a in &d.explanation.ambiguous {
        out += &format!(
            "   ambiguous: {} and {} explain the data about equally (BIC {:.1} apart, below {}): one of the two\n",
            a.cause,
            a.rival,
            a.bic_margin,
            sagcal::diagnose::AMBIGUOUS_BIC
        );
    }
    let failing = d.explanation.final_tests.iter().filter(|t| !t.consistent).count();
    out += &format!(
        "   final model {}: chi-square {:.1} for {} degrees of freedom; {} of {} sensor tests pass at {:.1e} each{}\n",
        d.explanation.final_model,
        d.explanation.final_chi_square,
        d.explanation.final_dof,
        d.explanation.final_tests.len() - failing,
        d.explanation.final_tests.len(),
        d.false_alarm / d.explanation.final_tests.len().max(1) as f64,
        if d.explanation.explained {
            ": explained"
        } else {
            ": NOT explained by the catalogue"
        }
    );
    for fit in &d.equivalent_fits {
        out += &format!("   {fit}\n");
    }
    out += &render_missing_terms(d);
    if !d.undetectable.is_empty() {
        out += &format!(
            "   not detectable at this noise with these poses (power < 0.9 at the smallest plausible magnitude): {}\n",
            d.undetectable.join(", ")
        );
    }
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
        out += &format!(
            "\n   residual structure left with {} (strongest first):\n",
            d.explanation.final_model
        );
        out += &driver_table(&d.drivers_after, 5);
    }
    out
}

/// The terms the final model (or, past a stand-in, the baseline) misses by
/// the score test, and the terms proposed to explain them.
fn render_missing_terms(d: &Diagnosis) -> String {
    let e = &d.explanation;
    if e.missing_terms.is_empty() {
        return format!(
            "   no term missing: no reading's residual follows a driver (score test, |z| below {:.2})\n",
            e.structure_limit_t
        );
    }
    let mut out = format!(
        "   terms missing from {} (score test, |z| above {:.2}): {} of them; the strongest: {}\n",
        e.terms_missing_from,
        e.structure_limit_t,
        e.missing_terms.len(),
        e.missing_terms[0].formula()
    );
    for term in &e.proposed_terms {
        out += &format!(
            "   proposed term (fitted with the others proposed): {}\n",
            term.formula()
        );
    }
    out
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

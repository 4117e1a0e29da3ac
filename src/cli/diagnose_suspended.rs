//! `sagcal diagnose` on a robot of 3 to 8 cables
//! ([`sagcal::diagnose::suspended`]): the baseline's test, each extension's
//! fit, likelihood ratio and held-out score, and the verdict.

use sagcal::calib::suspended::suspended_options;
use sagcal::diagnose::suspended::{
    diagnose_suspended, extensions_named, suspended_catalogue, SuspendedDiagnoseSettings, SuspendedDiagnosis,
    SuspendedExtension,
};
use sagcal::error::FrontEnd;
use sagcal::io::suspended_measurements::read_suspended_measurements;
use sagcal::model::suspended::SuspendedRobot;

use super::diagnose_args::DiagnoseArgs;
use super::output::{print_json, progress_bar, wrapped, Table};
use super::robot_kind::refuse_four_cable_flags;

/// The report's width, characters.
const WIDTH: usize = 100;

/// Diagnose `args.data` against `nominal`, print the report (or JSON).
pub(super) fn run(args: &DiagnoseArgs, nominal: &SuspendedRobot) -> sagcal::Result<()> {
    refuse_four_cable_flags(
        &[
            (args.truth.is_some(), "--truth"),
            (args.plots.is_some(), "--plots"),
            (args.out.is_some(), "--out"),
            (args.no_orientation_hypothesis, "--no-orientation-hypothesis"),
        ],
        nominal,
        "its diagnosis reports the extensions' fits and scores only",
    )?;
    let settings = SuspendedDiagnoseSettings {
        extensions: extensions(args.candidates.as_deref(), nominal)?,
        folds: args.folds,
        false_alarm: args.false_alarm,
    };
    let options = suspended_options(&args.solver.settings(), nominal, FrontEnd::Cli)?;
    let data = read_suspended_measurements(&args.data, nominal)?;
    let bar = progress_bar(1, "{msg} [{bar:30}] {pos}/{len} fits, {elapsed}");
    let diagnosis = diagnose_suspended(nominal, &data, &settings, &options, &|done, total| {
        bar.report(done, total, "fitting the extensions")
    });
    bar.finish_and_clear();
    let diagnosis = diagnosis?;
    if args.json {
        return print_json(&diagnosis);
    }
    print!("{}", render(&diagnosis));
    Ok(())
}

/// The extensions `--candidates` names (the whole catalogue without it).
fn extensions(candidates: Option<&str>, robot: &SuspendedRobot) -> sagcal::Result<Vec<SuspendedExtension>> {
    let Some(list) = candidates else {
        return Ok(suspended_catalogue(robot));
    };
    let names: Vec<&str> = list.split(',').collect();
    extensions_named(robot, &names).map_err(|e| sagcal::Error::InvalidInput(format!("--candidates: {e}")))
}

/// The report as text.
fn render(d: &SuspendedDiagnosis) -> String {
    let b = &d.baseline;
    let mut text = String::new();
    let head = [
        format!(
            "diagnosis of robot `{}` ({} cables) from {} poses, {}-fold cross-validation, false-alarm rate {}",
            d.robot, d.cables, d.poses, d.settings.folds, d.settings.false_alarm
        ),
        format!(
            "baseline: chi-square {:.1} for {} degrees of freedom (limit {:.1}): {}; held-out chi-square {:.1}",
            b.chi_square,
            b.degrees_of_freedom,
            b.limit,
            if b.passes { "passes" } else { "fails" },
            b.held_out_chi_square
        ),
    ];
    for paragraph in head {
        text += &wrapped(&paragraph, WIDTH).join("\n");
        text += "\n\n";
    }
    let mut table = Table::new([
        "extension",
        "fitted",
        "1-sigma",
        "LR",
        "held-out gain",
        "plausible",
        "extended model",
    ]);
    for f in &d.extensions {
        let (fitted, sigma, lr, gain) = match &f.failure {
            Some(_) => ("failed".into(), String::new(), String::new(), String::new()),
            None => (
                f.extension.value_text(f.value),
                f.extension.value_text(f.sigma),
                format!("{:.1}{}", f.likelihood_ratio, if f.significant { " *" } else { "" }),
                format!("{:+.1}", f.held_out_gain),
            ),
        };
        let plausible = if f.plausible { "yes" } else { "no" };
        let passes = if f.passes { "passes" } else { "fails" };
        table.row([
            f.extension.name(),
            fitted,
            sigma,
            lr,
            gain,
            plausible.into(),
            passes.into(),
        ]);
    }
    text += &table.to_string();
    let mut notes = vec![
        "fitted: for elastic the compliance 1/EA (1/N), for cable-weight, cable-weight-K and platform-weight a \
         scale on the robot file's weight, for encoder-scale, drum-gain-K and loadcell-gain a gain, for \
         loadcell-bias newtons"
            .to_string(),
        format!(
            "LR: the likelihood ratio chi2(baseline) - chi2(extension); * above {:.2}, the 1-dof quantile at \
             the search's false-alarm rate shared over {} extensions",
            d.likelihood_ratio_limit,
            d.extensions.len()
        ),
        "held-out gain: the baseline's held-out chi-square less the extension's (positive: it predicts \
         unseen poses better)"
            .to_string(),
    ];
    for f in d.extensions.iter().filter(|f| f.failure.is_some()) {
        notes.push(format!(
            "{}: {}",
            f.extension.name(),
            f.failure.as_deref().unwrap_or_default()
        ));
    }
    notes.push(String::new());
    notes.push(d.conclusion.clone());
    notes.push(format!(
        "not in the model of {} cables, so never named: {}",
        d.cables, d.not_modelled
    ));
    for note in notes {
        text += &wrapped(&note, WIDTH).join("\n");
        text += "\n";
    }
    text
}

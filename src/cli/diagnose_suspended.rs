//! `sagcal diagnose` on a robot of 3 to 8 cables
//! ([`sagcal::diagnose::suspended`]): the baseline's test, each extension's
//! fit, likelihood ratio and held-out score, and the verdict.

use sagcal::calib::suspended::suspended_options;
use sagcal::diagnose::suspended::{
    diagnose_suspended, errors_against_truth, extensions_named, suspended_catalogue, ResidualStructure,
    SuspendedDiagnoseSettings, SuspendedDiagnosis, SuspendedExtension, TruthError,
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
    let truth = args.truth.as_deref().map(SuspendedRobot::from_file).transpose()?;
    let bar = progress_bar(1, "{msg} [{bar:30}] {pos}/{len} fits, {elapsed}");
    let diagnosis = diagnose_suspended(nominal, &data, &settings, &options, &|done, total| {
        bar.report(done, total, "fitting the extensions")
    });
    let diagnosis = match (diagnosis, &truth) {
        (Ok(mut diagnosis), Some(truth)) => {
            let models = diagnosis.fitted_models();
            bar.report(0, 1, &format!("calibrating {} models against the truth", models.len()));
            errors_against_truth(nominal, &data, &models, truth, &options).map(|errors| {
                diagnosis.against_truth = errors;
                diagnosis
            })
        }
        (diagnosis, _) => diagnosis,
    };
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
        structure_line("baseline", &d.baseline_structure),
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
    if let Some(named) = &d.named_structure {
        notes.push(structure_line(&named.extension.name(), named));
    }
    notes.push(d.conclusion.clone());
    notes.push(format!(
        "not in the model of {} cables, so never named: {}",
        d.cables, d.not_modelled
    ));
    for note in notes {
        text += &wrapped(&note, WIDTH).join("\n");
        text += "\n";
    }
    if !d.against_truth.is_empty() {
        text += "\n";
        text += &truth_table(&d.against_truth);
    }
    text
}

/// Each model's anchors and offsets against the truth, in millimetres.
fn truth_table(errors: &[TruthError]) -> String {
    let mut table = Table::new([
        "against the truth",
        "anchor MAE mm",
        "mean anchor distance mm",
        "max anchor distance mm",
        "offset MAE mm",
    ]);
    let mm = |m: f64| format!("{:.2}", 1e3 * m);
    for e in errors {
        table.row([
            e.model.clone(),
            mm(e.anchor_mae_m),
            mm(e.anchor_mean_distance_m),
            mm(e.anchor_max_distance_m),
            mm(e.offset_mae_m),
        ]);
    }
    let mut text = table.to_string();
    for e in errors.iter().filter(|e| e.failure.is_some()) {
        text += &format!("{}: {}\n", e.model, e.failure.as_deref().unwrap_or_default());
    }
    text += "each model calibrated on every pose, its parameter at the fitted value above\n";
    text
}

/// The score tests of one model's residuals in a line.
fn structure_line(model: &str, s: &ResidualStructure) -> String {
    let strongest = s.strongest.as_ref().map_or("none testable".into(), |t| t.describe());
    format!(
        "residual tests of the {model} model: {} terms; limit |z| {:.2} (the false-alarm rate shared over them); \
         {} beyond; strongest: {strongest}",
        s.tested,
        s.limit,
        s.beyond.len()
    )
}

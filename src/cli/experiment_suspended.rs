//! `sagcal experiment table2` on a robot of 3 to 8 cables
//! ([`sagcal::experiments::suspended_trials`]): per pose count, the trials'
//! anchor and offset errors from a guess `--anchor-perturbation-m` off,
//! beside the Cramer-Rao bound of the same poses.

use sagcal::experiments::suspended_trials::{suspended_trials, SuspendedTrialsOptions, SuspendedTrialsSummary};
use sagcal::model::suspended::SuspendedRobot;

use super::output::{print_json, progress_bar, Table};
use super::robot_kind::refuse_four_cable_flags;
use super::table2_args::Table2Args;

/// Run the trials of every pose count of `args` on `truth` and print the table (or JSON).
pub(super) fn run(args: &Table2Args, truth: &SuspendedRobot) -> sagcal::Result<()> {
    refuse_four_cable_options(args, truth)?;
    let guess_m = args.anchor_perturbation_m.unwrap_or(10.0);
    let total = args.poses.len() * args.trials;
    let bar = progress_bar(total as u64, "{msg} [{bar:30}] {pos}/{len} trials, {elapsed}");
    let mut summaries = Vec::with_capacity(args.poses.len());
    for (k, &poses) in args.poses.iter().enumerate() {
        let options = SuspendedTrialsOptions {
            poses,
            trials: args.trials,
            noise: args.noise,
            guess_m,
            seed: args.seed,
        };
        let label = format!("{poses} poses");
        summaries.push(suspended_trials(truth, &options, &mut |done, _| {
            bar.report(k * args.trials + done, total, &label)
        })?);
    }
    bar.finish_and_clear();
    if args.json {
        return print_json(&summaries);
    }
    print!("{}", render(truth, args, guess_m, &summaries));
    Ok(())
}

/// The flags of the four-cable protocol that these trials do not have.
fn refuse_four_cable_options(args: &Table2Args, truth: &SuspendedRobot) -> sagcal::Result<()> {
    let given = [
        (args.data.is_some(), "--data"),
        (args.model != sagcal::calib::CableModel::Catenary, "--model"),
        (args.offset_perturbation_m.is_some(), "--offset-perturbation-m"),
        (args.basin_radius_m.is_some(), "--basin-radius-m"),
        (args.estimate.is_some(), "--estimate"),
        (args.apply_gross_errors, "--apply-gross-errors"),
        (args.select != "random", "--select"),
    ];
    refuse_four_cable_flags(&given, truth, "its trials draw their poses in the robot's workspace, start every offset at 0 and calibrate with catenaries and the localiser's orientation")
}

/// The table.
fn render(truth: &SuspendedRobot, args: &Table2Args, guess_m: f64, summaries: &[SuspendedTrialsSummary]) -> String {
    let mut out = format!(
        "Table II protocol on `{}` ({} cables, load cells on {}): poses drawn in its workspace, {} noise, seed {}, every anchor of the guess {guess_m} m off, offsets from 0\n",
        truth.name,
        truth.cable_count(),
        truth.load_cells_phrase(),
        args.noise,
        args.seed
    );
    let mut table = Table::new([
        "poses",
        "converged",
        "anchor RMS m",
        "CRB anchor RMS m",
        "ratio",
        "offset RMS m",
        "CRB offset RMS m",
    ]);
    for s in summaries {
        table.row([
            s.options.poses.to_string(),
            format!("{}/{}", s.converged, s.options.trials),
            format!("{:.4}", s.anchor_rms_error_m),
            format!("{:.4}", s.anchor_rms_bound_m),
            format!("{:.2}", s.anchor_rms_error_m / s.anchor_rms_bound_m),
            format!("{:.4}", s.offset_rms_error_m),
            format!("{:.4}", s.offset_rms_bound_m),
        ]);
    }
    out += &table.to_string();
    out += "(RMS over anchors and converged trials of the Euclidean error, against the root of the mean trace of the Cramer-Rao bound at the truth for the same poses: an efficient estimator has ratio 1)\n";
    for s in summaries {
        for failure in &s.failures {
            out += &format!("{} poses, {failure}\n", s.options.poses);
        }
        if s.unbounded > 0 {
            out += &format!(
                "{} poses: {} trials had a singular Fisher information (no bound)\n",
                s.options.poses, s.unbounded
            );
        }
    }
    out
}

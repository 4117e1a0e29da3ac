//! `sagcal experiment hidden-effects --robots three,six,eight`: the sweep
//! of robots of 3 to 8 cables ([`sagcal::experiments::suspended_sweep`]),
//! scored by the calibration's own verdict (`sagcal diagnose` names
//! causes), one table per robot and noise reading.

use sagcal::calib::gross_errors::GrossErrorOptions;
use sagcal::experiments::hidden_effects::Catalogue;
use sagcal::experiments::suspended_sweep::{suspended_effect_sweep, SuspendedSweep, SuspendedSweepOptions};
use sagcal::model::suspended::SuspendedRobot;
use sagcal::sim::closed_form::Closure;
use sagcal::Error;

use super::hidden_args::HiddenEffectsArgs;
use super::output::{print_json, progress_bar, Table};

/// Run the sweep on the built-in robots `names` (each of 3 to 8 cables).
pub(super) fn run(args: &HiddenEffectsArgs, names: &[&str]) -> sagcal::Result<()> {
    refuse_four_cable_flags(args)?;
    let robots: Vec<SuspendedRobot> = names
        .iter()
        .map(|name| SuspendedRobot::builtin(name))
        .collect::<sagcal::Result<_>>()?;
    let false_alarm = GrossErrorOptions::default().false_alarm;
    eprintln!(
        "sagcal experiment hidden-effects: seed {}, {} cases per effect, {} poses, {} segments, robots {}",
        args.seed,
        args.seeds,
        args.poses,
        args.segments,
        names.join(", ")
    );
    let mut sweeps = Vec::new();
    for robot in &robots {
        for &noise in &args.noise {
            let options = SuspendedSweepOptions {
                poses: args.poses,
                seeds: args.seeds,
                seed: args.seed,
                segments: args.segments,
                noise,
                false_alarm,
            };
            let bar = progress_bar(1, "{msg} [{bar:40}] {pos}/{len} cases, {elapsed} (eta {eta})");
            let what = format!("{} cables, {noise} noise", robot.cable_count());
            let sweep = suspended_effect_sweep(robot, &options, &|done, total| bar.report(done, total, &what));
            bar.finish_and_clear();
            sweeps.push(sweep?);
        }
    }
    if args.json {
        return print_json(&sweeps);
    }
    for sweep in &sweeps {
        print_sweep(sweep);
    }
    Ok(())
}

/// The four-cable sweep's flags that this sweep has no use for, refused.
fn refuse_four_cable_flags(args: &HiddenEffectsArgs) -> sagcal::Result<()> {
    let refused = if args.catalogue != Catalogue::Full {
        Some("--catalogue: robots of 3 to 8 cables have no diagnosis; their cases are scored by the calibration's verdict")
    } else if !matches!(args.closure, Closure::Mixed { .. }) {
        Some("--closure: the sweep of 3 to 8 cables closes its poses as Table II's trials do (a yaw within +-5 degrees held)")
    } else {
        None
    };
    match refused {
        Some(why) => Err(Error::InvalidInput(why.into())),
        None => Ok(()),
    }
}

/// One robot's and noise reading's table, with how to read it.
fn print_sweep(sweep: &SuspendedSweep) {
    let o = &sweep.options;
    println!(
        "robot `{}` ({} cables), {} noise, {} poses, {} cases per effect, seed {} (case k of effect e: seed {} + 1000 e + k), {} segments",
        sweep.robot, sweep.cables, o.noise, o.poses, o.seeds, o.seed, o.seed, o.segments
    );
    let mut table = Table::new([
        "effect",
        "refused",
        "passed, biased",
        "passed",
        "failed",
        "median worst anchor error m",
    ]);
    for row in &sweep.rows {
        table.row([
            row.effect.clone(),
            format!("{}/{}", row.refused, row.cases),
            format!("{}/{}", row.passed_biased, row.cases),
            format!("{}/{}", row.passed, row.cases),
            format!("{}/{}", row.failed, row.cases),
            format!("{:.3}", row.median_worst_anchor_error_m),
        ]);
    }
    print!("{table}");
    println!("ranges drawn from:");
    for row in &sweep.rows {
        println!("  {:<16} {}", row.effect, row.range);
    }
    println!(
        "refused: the fit's chi-square test at 99.9 % finds the model inconsistent (for `none`, a false alarm); \
         passed, biased: the fit passes with an anchor coordinate beyond {:.2} of its 1-sigma (the two-sided \
         Bonferroni 99.9 % bound over {} coordinates)\n",
        sweep.bias_bound_sigmas,
        3 * sweep.cables
    );
    for case in sweep.cases.iter().filter(|c| c.failure.is_some()) {
        println!(
            "failed: {} seed {}: {}",
            case.effect,
            case.seed,
            case.failure.as_deref().unwrap_or_default()
        );
    }
}

//! `sagcal experiment hidden-effects`: hide effects (none, one, or a pair) in
//! simulated data and score `sagcal diagnose`; the flags
//! ([`HiddenEffectsArgs`]) and the run.

use std::collections::BTreeMap;

use rayon::prelude::*;
use sagcal::experiments::hidden_effects::{
    effect_ranges, identifiability, mean_reference_tension_n, run_sweep, smallest_effects, EffectRange, HiddenCase,
    HiddenEffectOptions, Identifiability, SweepCases, UnmeasurableCase, PAIRS,
};
use sagcal::model::effect_kind::EffectKind;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::suspended::SuspendedRobot;
use sagcal::model::Robot;
use sagcal::sim::closed_form::Closure;
use serde::Serialize;

use super::hidden_args::HiddenEffectsArgs;
use super::hidden_suspended;
use super::output::{counted, print_json, progress_bar, Table};

/// A case is detectable when the diagnosis' test has at least this power at the true magnitude.
const DETECTABLE_POWER: f64 = 0.9;

/// Per robot, noise reading and hidden set: the score.
#[derive(Debug, Clone, Serialize)]
struct EffectScore {
    robot: String,
    noise: NoisePreset,
    hidden: String,
    cases: usize,
    right: usize,
    /// Cases whose tests have power >= 0.9 at the true magnitudes.
    detectable: usize,
    /// Right verdicts among them.
    right_detectable: usize,
    /// Mean power of the low-power cases (NaN if none).
    low_power_mean: f64,
    /// Verdict -> count.
    verdicts: BTreeMap<String, usize>,
    anchor_mae_before_m: f64,
    anchor_mae_after_m: f64,
    /// Detectable cases whose anchor error the verdict's model at least halved.
    halved: usize,
    /// Diagnoses of detectable cases with a hidden effect left out of the catalogue.
    left_out_detectable: usize,
    /// Honest verdicts among them.
    left_out_honest: usize,
}

/// The score of one robot under one noise reading.
#[derive(Debug, Clone, Serialize)]
struct Summary {
    robot: String,
    noise: NoisePreset,
    /// Right set among the detectable single-effect cases.
    single_right_rate: f64,
    /// Right set among the detectable pair cases.
    pair_right_rate: f64,
    /// `none` cases given another verdict.
    none_false_rejection_rate: f64,
    /// Detectable cases (single and pairs) whose anchor error was at least halved.
    halved_rate: f64,
    /// Honest verdicts among the diagnoses of detectable cases with a hidden
    /// effect left out of the catalogue (NaN without `--catalogue leave-one-out`).
    left_out_honest_rate: f64,
    /// Mean chi-square per degree of freedom of the unseen poses, localised
    /// with the baseline's robot, over every case.
    held_out_before: f64,
    /// The same with the final model's robot.
    held_out_after: f64,
    /// Cases whose verdict names a cause.
    declared: usize,
    /// Those whose final model does not lower the unseen poses' mean
    /// chi-square per degree of freedom: a declared cause that does not predict.
    declared_not_predicting: usize,
}

#[derive(Debug, Clone, Serialize)]
struct Report {
    seed: u64,
    closure: Closure,
    seeds: usize,
    poses: usize,
    noises: Vec<NoisePreset>,
    ranges: BTreeMap<String, Vec<EffectRange>>,
    scores: Vec<EffectScore>,
    summaries: Vec<Summary>,
    smallest: Vec<Identifiability>,
    cases: Vec<HiddenCase>,
    /// Cases whose simulated readings sagcal refuses as input: not diagnosed, not scored.
    unmeasurable: Vec<UnmeasurableCase>,
}

/// The mean of the finite values; NaN without any.
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.iter().sum::<f64>() / v.len() as f64
}

/// Run the sweep, score it and print the report (or JSON).
pub fn run(args: &HiddenEffectsArgs) -> sagcal::Result<()> {
    // Every option checked before any case is drawn.
    if args.seeds == 0 {
        return Err(sagcal::Error::InvalidInput("--seeds must be at least 1".into()));
    }
    let options = HiddenEffectOptions {
        poses: args.poses,
        noise: args.noise[0],
        segments: args.segments,
        closure: args.closure,
        catalogue: args.catalogue,
        ..HiddenEffectOptions::default()
    };
    options.validate()?;
    let mut names: Vec<&str> = Vec::new();
    for name in args.robots.split(',').map(str::trim) {
        if names.contains(&name) {
            return Err(sagcal::Error::InvalidInput(format!("--robots names `{name}` twice")));
        }
        names.push(name);
    }
    let suspended = |name: &&str| Robot::builtin(name).is_err() && SuspendedRobot::builtin(name).is_ok();
    if names.iter().all(suspended) {
        return hidden_suspended::run(args, &names);
    }
    if let Some(name) = names.iter().find(|n| suspended(n)) {
        return Err(sagcal::Error::InvalidInput(format!(
            "--robots: `{name}` has {} cables: sweep robots of 3 to 8 cables in a run of their own",
            SuspendedRobot::builtin(name)?.cable_count()
        )));
    }
    let robots: Vec<Robot> = names
        .iter()
        .map(|name| Robot::builtin(name))
        .collect::<sagcal::Result<_>>()
        .map_err(|e| match e {
            sagcal::Error::InvalidInput(m) => sagcal::Error::InvalidInput(format!("--robots: {m}")),
            other => other,
        })?;
    let SweepCases {
        diagnosed: cases,
        unmeasurable,
    } = sweep(args, &robots, &options)?;
    let smallest = smallest_identifiability(args, &robots, &options)?;
    let scores = scores(&robots, &args.noise, &cases);
    let report = Report {
        seed: args.seed,
        closure: args.closure,
        seeds: args.seeds,
        poses: args.poses,
        noises: args.noise.clone(),
        ranges: robots.iter().map(|r| (r.name.clone(), effect_ranges(r))).collect(),
        summaries: summaries(&robots, &args.noise, &scores, &cases),
        scores,
        smallest,
        cases,
        unmeasurable,
    };
    if args.json {
        return print_json(&report);
    }
    print_report(args, &report);
    Ok(())
}

/// The hidden sets of a sweep: none, each effect, each pair.
fn hidden_sets() -> Vec<String> {
    let mut sets = vec!["none".to_string()];
    sets.extend(EffectKind::ALL.map(|k| k.name().to_string()));
    sets.extend(PAIRS.map(|p| {
        let mut names = [p[0].name(), p[1].name()];
        names.sort();
        names.join("+")
    }));
    sets
}

/// Run every case with a progress bar.
fn sweep(args: &HiddenEffectsArgs, robots: &[Robot], options: &HiddenEffectOptions) -> sagcal::Result<SweepCases> {
    let total = robots.len() * args.noise.len() * hidden_sets().len() * args.seeds;
    eprintln!(
        "sagcal experiment hidden-effects: seed {}, {} closure, {} x {} hidden sets (none, {} effects, {} pairs) x {} x {} noise, {} poses",
        args.seed,
        args.closure,
        counted(args.seeds, "seed", "seeds"),
        hidden_sets().len(),
        EffectKind::ALL.len(),
        PAIRS.len(),
        counted(robots.len(), "robot", "robots"),
        noise_names(&args.noise),
        args.poses
    );
    let bar = progress_bar(
        total as u64,
        "hidden effects [{bar:40}] {pos}/{len} cases, {elapsed} (eta {eta})",
    );
    let cases = run_sweep(robots, &args.noise, args.seeds, args.seed, options, &|| bar.inc(1))?;
    bar.finish_and_clear();
    Ok(cases)
}

/// The identifiability of each robot's smallest effects (independent
/// studies, in parallel), with a progress bar: seconds after the sweep.
fn smallest_identifiability(
    args: &HiddenEffectsArgs,
    robots: &[Robot],
    options: &HiddenEffectOptions,
) -> sagcal::Result<Vec<Identifiability>> {
    let bar = progress_bar(robots.len() as u64, "{msg} [{bar:40}] {pos}/{len}, {elapsed}");
    bar.set_message("identifiability of the smallest effects: mean tension per robot");
    let mut studies = Vec::new();
    for robot in robots {
        let mean_tension = match mean_reference_tension_n(robot, args.poses, args.seed) {
            Ok(tension) => tension,
            Err(e) => {
                bar.finish_and_clear();
                return Err(e);
            }
        };
        studies.extend(smallest_effects(robot, mean_tension).into_iter().map(|s| (robot, s)));
        bar.inc(1);
    }
    bar.report(0, studies.len(), "identifiability of the smallest effects: studies");
    let smallest = studies
        .par_iter()
        .map(|(robot, (kind, effects))| {
            let study = identifiability(robot, *kind, effects, args.poses, args.seed, options);
            bar.inc(1);
            study
        })
        .collect::<sagcal::Result<Vec<_>>>();
    bar.finish_and_clear();
    smallest
}

/// The score of every robot, noise reading and hidden set.
fn scores(robots: &[Robot], noises: &[NoisePreset], cases: &[HiddenCase]) -> Vec<EffectScore> {
    let mut scores = Vec::new();
    for robot in robots {
        for noise in noises {
            for hidden in hidden_sets() {
                let group: Vec<&HiddenCase> = cases
                    .iter()
                    .filter(|c| c.robot == robot.name && c.noise == *noise && c.hidden == hidden)
                    .collect();
                scores.push(score(&robot.name, *noise, &hidden, &group));
            }
        }
    }
    scores
}

/// The score of one group of cases.
fn score(robot: &str, noise: NoisePreset, hidden: &str, group: &[&HiddenCase]) -> EffectScore {
    let detectable = |c: &&&HiddenCase| c.hidden != "none" && c.power.is_some_and(|p| p >= DETECTABLE_POWER);
    let mut verdicts = BTreeMap::new();
    for c in group {
        *verdicts.entry(c.verdict.clone()).or_insert(0) += 1;
    }
    EffectScore {
        robot: robot.to_string(),
        noise,
        hidden: hidden.to_string(),
        cases: group.len(),
        right: group.iter().filter(|c| c.correct).count(),
        detectable: group.iter().filter(detectable).count(),
        right_detectable: group.iter().filter(detectable).filter(|c| c.correct).count(),
        low_power_mean: mean(group.iter().filter_map(|c| c.power).filter(|p| *p < DETECTABLE_POWER)),
        verdicts,
        anchor_mae_before_m: mean(group.iter().map(|c| c.anchor_mae_before_m)),
        anchor_mae_after_m: mean(group.iter().map(|c| c.anchor_mae_after_m)),
        halved: group
            .iter()
            .filter(detectable)
            .filter(|c| c.anchor_mae_after_m <= 0.5 * c.anchor_mae_before_m)
            .count(),
        left_out_detectable: group.iter().filter(detectable).map(|c| c.left_out.len()).sum(),
        left_out_honest: group
            .iter()
            .filter(detectable)
            .map(|c| c.left_out.iter().filter(|x| x.honest).count())
            .sum(),
    }
}

/// Per robot and noise reading: the scores of the sweep (detection, false alarms, anchors, honesty, unseen poses).
fn summaries(robots: &[Robot], noises: &[NoisePreset], scores: &[EffectScore], cases: &[HiddenCase]) -> Vec<Summary> {
    let rate = |num: usize, den: usize| if den == 0 { f64::NAN } else { num as f64 / den as f64 };
    let mut out = Vec::new();
    for robot in robots {
        for noise in noises {
            let group: Vec<&EffectScore> = scores
                .iter()
                .filter(|s| s.robot == robot.name && s.noise == *noise)
                .collect();
            let sum = |pick: &dyn Fn(&EffectScore) -> bool, value: &dyn Fn(&EffectScore) -> usize| -> usize {
                group.iter().filter(|s| pick(s)).map(|s| value(s)).sum()
            };
            let single = |s: &EffectScore| s.hidden != "none" && !s.hidden.contains('+');
            let pair = |s: &EffectScore| s.hidden.contains('+');
            let none = |s: &EffectScore| s.hidden == "none";
            let effect = |s: &EffectScore| s.hidden != "none";
            let own: Vec<&HiddenCase> = cases
                .iter()
                .filter(|c| c.robot == robot.name && c.noise == *noise)
                .collect();
            let mean = |value: &dyn Fn(&HiddenCase) -> f64| {
                let values: Vec<f64> = own.iter().map(|c| value(c)).filter(|v| v.is_finite()).collect();
                values.iter().sum::<f64>() / values.len().max(1) as f64
            };
            let declared: Vec<&&HiddenCase> = own
                .iter()
                .filter(|c| c.verdict.split('+').any(|t| t != "none" && t != "unexplained"))
                .collect();
            out.push(Summary {
                robot: robot.name.clone(),
                noise: *noise,
                single_right_rate: rate(sum(&single, &|s| s.right_detectable), sum(&single, &|s| s.detectable)),
                pair_right_rate: rate(sum(&pair, &|s| s.right_detectable), sum(&pair, &|s| s.detectable)),
                none_false_rejection_rate: 1.0 - rate(sum(&none, &|s| s.right), sum(&none, &|s| s.cases)),
                halved_rate: rate(sum(&effect, &|s| s.halved), sum(&effect, &|s| s.detectable)),
                left_out_honest_rate: rate(
                    sum(&effect, &|s| s.left_out_honest),
                    sum(&effect, &|s| s.left_out_detectable),
                ),
                held_out_before: mean(&|c| c.held_out.chi_square_per_dof_before),
                held_out_after: mean(&|c| c.held_out.chi_square_per_dof_after),
                declared: declared.len(),
                declared_not_predicting: declared
                    .iter()
                    .filter(|c| {
                        c.held_out
                            .chi_square_per_dof_after
                            .total_cmp(&c.held_out.chi_square_per_dof_before)
                            .is_gt()
                    })
                    .count(),
            });
        }
    }
    out
}

/// The noise readings of a sweep, as a person reads them: `paper and authors`.
fn noise_names(noises: &[NoisePreset]) -> String {
    let names: Vec<String> = noises.iter().map(NoisePreset::to_string).collect();
    names.join(" and ")
}

/// `--noise`'s value that runs `noises` again: `both` for paper and authors.
fn noise_flag(noises: &[NoisePreset]) -> String {
    if noises == [NoisePreset::Paper, NoisePreset::Authors] {
        "both".to_string()
    } else {
        noise_names(noises)
    }
}

/// The readable report.
fn print_report(args: &HiddenEffectsArgs, report: &Report) {
    println!(
        "sagcal experiment hidden-effects --seeds {} --seed {} --poses {} --noise {} --closure {}\n",
        args.seeds,
        args.seed,
        args.poses,
        noise_flag(&report.noises),
        args.closure.name()
    );
    for (robot, ranges) in &report.ranges {
        println!("magnitudes drawn for `{robot}` (true anchors off the nominal ones, offsets of metres):");
        let mut t = Table::new(["effect", "range", "why"]);
        for r in ranges {
            t.row([r.effect.clone(), r.range.clone(), r.justification.clone()]);
        }
        println!("{t}");
    }
    print_scores(&report.scores);
    print_summaries(&report.summaries);
    print_dishonest(&report.cases);
    print_unmeasurable(&report.unmeasurable);
    print_smallest(&report.smallest);
}

/// With the hidden effect left out of the catalogue: the detectable cases
/// whose verdict was not honest, each with the full catalogue's verdict.
fn print_dishonest(cases: &[HiddenCase]) {
    let mut t = Table::new([
        "robot",
        "noise",
        "hidden",
        "seed",
        "left out",
        "verdict",
        "full catalogue's verdict",
    ]);
    let mut count = 0;
    for c in cases.iter().filter(|c| c.power.is_some_and(|p| p >= DETECTABLE_POWER)) {
        for x in c.left_out.iter().filter(|x| !x.honest) {
            count += 1;
            t.row([
                c.robot.clone(),
                c.noise.to_string(),
                c.hidden.clone(),
                c.seed.to_string(),
                x.left_out.clone(),
                x.verdict.clone(),
                c.verdict.clone(),
            ]);
        }
    }
    if count > 0 {
        println!("{count} verdict(s) not honest with the hidden effect left out (detectable cases):");
        println!("{t}");
    }
}

/// The cases left out because sagcal refuses their simulated readings.
fn print_unmeasurable(cases: &[UnmeasurableCase]) {
    if cases.is_empty() {
        return;
    }
    println!(
        "{} case(s) not diagnosed and not scored above: their simulated readings are refused as input, as an operator's file would be (the truth's effects leave the reference cable nearly slack at a pose):",
        cases.len()
    );
    let mut t = Table::new(["robot", "noise", "hidden", "seed", "refused reading"]);
    for c in cases {
        t.row([
            c.robot.clone(),
            c.noise.to_string(),
            c.hidden.clone(),
            c.seed.to_string(),
            c.reason.clone(),
        ]);
    }
    println!("{t}");
}

/// Per robot, noise reading and hidden set: verdicts, detectability and anchor errors.
fn print_scores(scores: &[EffectScore]) {
    let mut t = Table::new([
        "robot",
        "noise",
        "hidden",
        "right",
        "detectable (power >= 0.9)",
        "right of detectable",
        "low-power mean power",
        "verdicts",
        "anchor MAE baseline m",
        "verdict's m",
    ]);
    for s in scores {
        let verdicts: Vec<String> = s.verdicts.iter().map(|(k, v)| format!("{k} {v}")).collect();
        t.row([
            s.robot.clone(),
            s.noise.to_string(),
            s.hidden.clone(),
            format!("{}/{}", s.right, s.cases),
            s.detectable.to_string(),
            format!("{}/{}", s.right_detectable, s.detectable),
            if s.low_power_mean.is_finite() {
                format!("{:.2}", s.low_power_mean)
            } else {
                "-".into()
            },
            verdicts.join(", "),
            format!("{:.4}", s.anchor_mae_before_m),
            format!("{:.4}", s.anchor_mae_after_m),
        ]);
    }
    println!("{t}");
}

/// Per robot and noise reading: the rates of right verdicts, false rejections and halved errors.
fn print_summaries(summaries: &[Summary]) {
    let mut t = Table::new([
        "robot",
        "noise",
        "right set, detectable single effects",
        "right set, detectable pairs",
        "`none` wrongly rejected",
        "anchor error at least halved",
        "honest with the hidden effect left out",
        "unseen poses: chi2/dof baseline -> final",
        "causes declared / not predicting unseen poses",
    ]);
    let pct = |x: f64| {
        if x.is_finite() {
            format!("{:.1} %", 100.0 * x)
        } else {
            "-".into()
        }
    };
    for s in summaries {
        t.row([
            s.robot.clone(),
            s.noise.to_string(),
            pct(s.single_right_rate),
            pct(s.pair_right_rate),
            pct(s.none_false_rejection_rate),
            pct(s.halved_rate),
            pct(s.left_out_honest_rate),
            format!("{:.2} -> {:.2}", s.held_out_before, s.held_out_after),
            format!("{} / {}", s.declared, s.declared_not_predicting),
        ]);
    }
    println!("{t}");
}

/// The smallest magnitude of each range on noise-free data.
fn print_smallest(smallest: &[Identifiability]) {
    println!("the smallest magnitude of each range, noise-free data: the baseline's anchor bias over its 1-sigma:");
    let mut t = Table::new([
        "robot",
        "effect",
        "magnitude",
        "baseline anchor bias m",
        "bias / 1-sigma",
    ]);
    for p in smallest {
        t.row([
            p.robot.clone(),
            p.effect.clone(),
            format!("{:.4e}", p.value),
            format!("{:.4}", p.baseline_anchor_bias_m),
            format!("{:.2}", p.baseline_bias_over_sigma),
        ]);
    }
    println!("{t}");
}

//! `sagcal experiment hidden-effects`: hide effects in simulated data and score `sagcal diagnose`.

use std::collections::BTreeMap;

use indicatif::{ProgressBar, ProgressStyle};
use sagcal::experiments::hidden_effects::{
    effect_ranges, identifiability, mean_reference_tension_n, mid_range_effects, run_sweep, smallest_effects,
    EffectRange, HiddenCase, HiddenEffectOptions, Identifiability,
};
use sagcal::model::effects::EffectKind;
use sagcal::model::Robot;
use serde::Serialize;

use super::output::{print_json, Table};
use super::HiddenEffectsArgs;

/// Per robot and hidden effect: the score.
#[derive(Debug, Clone, Serialize)]
struct EffectScore {
    robot: String,
    hidden: String,
    cases: usize,
    right: usize,
    /// Verdict -> count.
    verdicts: BTreeMap<String, usize>,
    anchor_mae_before_m: f64,
    anchor_mae_extended_m: Option<f64>,
    anchor_mae_after_m: f64,
    min_error_over_sigma: f64,
    anchor_mae_known_geometry_m: Option<f64>,
    scored: bool,
}

#[derive(Debug, Clone, Serialize)]
struct Report {
    seed: u64,
    seeds: usize,
    poses: usize,
    noise: String,
    ranges: BTreeMap<String, Vec<EffectRange>>,
    scores: Vec<EffectScore>,
    detection_rate: f64,
    none_false_rejection_rate: f64,
    anchor_ratio_extended_over_baseline: f64,
    identifiability: Vec<Identifiability>,
    smallest: Vec<Identifiability>,
    cases: Vec<HiddenCase>,
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

pub fn run(args: &HiddenEffectsArgs) -> sagcal::Result<()> {
    let robots: Vec<Robot> = args
        .robots
        .split(',')
        .map(|name| Robot::builtin(name.trim()))
        .collect::<sagcal::Result<_>>()?;
    if args.seeds == 0 {
        return Err(sagcal::Error::InvalidInput("--seeds must be at least 1".into()));
    }
    let options = HiddenEffectOptions {
        poses: args.poses,
        noise: args.noise,
        segments: args.segments,
        ..HiddenEffectOptions::default()
    };
    let total = robots.len() * (1 + EffectKind::ALL.len()) * args.seeds;
    eprintln!(
        "sagcal experiment hidden-effects: seed {}, {} seeds x {} effects (and none) x {} robot(s), {} poses, {:?} noise",
        args.seed,
        args.seeds,
        EffectKind::ALL.len(),
        robots.len(),
        args.poses,
        args.noise
    );
    let bar = ProgressBar::new(total as u64);
    bar.set_style(
        ProgressStyle::with_template("hidden effects [{bar:40}] {pos}/{len} cases, {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let cases = run_sweep(&robots, args.seeds, args.seed, &options, &|| bar.inc(1))?;
    bar.finish_and_clear();
    // Identifiability at mid-range magnitudes: an effect whose parameter the
    // Fisher information cannot separate from the other unknowns at 3 sigma is
    // left out of the detection score on that robot (with this evidence).
    let mut identifiability_rows = Vec::new();
    let mut unscored: Vec<(String, String)> = Vec::new();
    for robot in &robots {
        let mean_tension = mean_reference_tension_n(robot, args.poses, args.seed)?;
        for (kind, effects) in mid_range_effects(robot, mean_tension) {
            let id = identifiability(robot, kind, &effects, args.poses, args.seed, &options)?;
            if kind == EffectKind::Pulley || id.sigma > id.value.abs() / 3.0 {
                unscored.push((robot.name.clone(), kind.name().to_string()));
            }
            identifiability_rows.push(id);
        }
    }
    let mut smallest = Vec::new();
    for robot in &robots {
        let mean_tension = mean_reference_tension_n(robot, args.poses, args.seed)?;
        for (kind, effects) in smallest_effects(robot, mean_tension) {
            smallest.push(identifiability(robot, kind, &effects, args.poses, args.seed, &options)?);
        }
    }
    let mut scores = Vec::new();
    for robot in &robots {
        for hidden in std::iter::once("none").chain(EffectKind::ALL.map(|k| k.name())) {
            let group: Vec<&HiddenCase> = cases
                .iter()
                .filter(|c| c.robot == robot.name && c.hidden == hidden)
                .collect();
            let mut verdicts = BTreeMap::new();
            for c in &group {
                *verdicts.entry(c.verdict.clone()).or_insert(0) += 1;
            }
            scores.push(EffectScore {
                robot: robot.name.clone(),
                hidden: hidden.to_string(),
                cases: group.len(),
                right: group.iter().filter(|c| c.correct).count(),
                verdicts,
                anchor_mae_before_m: mean(group.iter().map(|c| c.anchor_mae_before_m)),
                anchor_mae_extended_m: (hidden != "none")
                    .then(|| mean(group.iter().filter_map(|c| c.anchor_mae_extended_m))),
                anchor_mae_after_m: mean(group.iter().map(|c| c.anchor_mae_after_m)),
                min_error_over_sigma: group
                    .iter()
                    .map(|c| c.baseline_error_over_sigma)
                    .fold(f64::INFINITY, f64::min),
                anchor_mae_known_geometry_m: (hidden == "pulley")
                    .then(|| mean(group.iter().filter_map(|c| c.anchor_mae_known_geometry_m))),
                scored: !unscored.contains(&(robot.name.clone(), hidden.to_string())),
            });
        }
    }
    let detected: Vec<&EffectScore> = scores.iter().filter(|s| s.scored && s.hidden != "none").collect();
    let detection_rate = detected.iter().map(|s| s.right).sum::<usize>() as f64
        / detected.iter().map(|s| s.cases).sum::<usize>().max(1) as f64;
    let nones: Vec<&EffectScore> = scores.iter().filter(|s| s.hidden == "none").collect();
    let none_false_rejection_rate = 1.0
        - nones.iter().map(|s| s.right).sum::<usize>() as f64
            / nones.iter().map(|s| s.cases).sum::<usize>().max(1) as f64;
    let anchor_ratio_extended_over_baseline = detected
        .iter()
        .filter_map(|s| s.anchor_mae_extended_m.map(|e| e / s.anchor_mae_before_m))
        .fold(0.0, f64::max);
    let report = Report {
        seed: args.seed,
        seeds: args.seeds,
        poses: args.poses,
        noise: format!("{:?}", args.noise).to_lowercase(),
        ranges: robots.iter().map(|r| (r.name.clone(), effect_ranges(r))).collect(),
        scores,
        detection_rate,
        none_false_rejection_rate,
        anchor_ratio_extended_over_baseline,
        identifiability: identifiability_rows,
        smallest,
        cases,
    };
    if args.json {
        return print_json(&report);
    }
    println!(
        "sagcal experiment hidden-effects --seeds {} --seed {} --poses {} --noise {}\n",
        args.seeds, args.seed, args.poses, report.noise
    );
    for (robot, ranges) in &report.ranges {
        println!("magnitudes drawn for `{robot}`:");
        let mut t = Table::new(["effect", "range", "why"]);
        for r in ranges {
            t.row([r.effect.clone(), r.range.clone(), r.justification.clone()]);
        }
        println!("{t}");
    }
    let mut t = Table::new([
        "robot",
        "hidden",
        "right verdict",
        "verdicts",
        "anchor MAE baseline m",
        "extended m",
        "verdict's m",
        "min error/sigma",
        "radius known m",
    ]);
    for s in &report.scores {
        let verdicts: Vec<String> = s.verdicts.iter().map(|(k, v)| format!("{k} {v}")).collect();
        t.row([
            s.robot.clone(),
            if s.scored {
                s.hidden.clone()
            } else {
                format!("{} (not scored)", s.hidden)
            },
            format!("{}/{}", s.right, s.cases),
            verdicts.join(", "),
            format!("{:.4}", s.anchor_mae_before_m),
            s.anchor_mae_extended_m.map_or("-".into(), |v| format!("{v:.4}")),
            format!("{:.4}", s.anchor_mae_after_m),
            format!("{:.2}", s.min_error_over_sigma),
            s.anchor_mae_known_geometry_m.map_or("-".into(), |v| format!("{v:.4}")),
        ]);
    }
    println!("{t}");
    println!(
        "right verdict with an effect hidden (unidentifiable effects not scored): {:.1} %; `none` wrongly rejected: {:.1} %; worst extended/baseline anchor MAE: {:.3}\n",
        100.0 * report.detection_rate,
        100.0 * report.none_false_rejection_rate,
        report.anchor_ratio_extended_over_baseline
    );
    println!(
        "identifiability at mid-range magnitudes (Fisher information at the true equilibria, {} poses; an effect is not scored where sigma free > value / 3, the pulley never):",
        args.poses
    );
    let mut t = Table::new([
        "robot",
        "effect",
        "value (m or N)",
        "sigma free",
        "sigma alone",
        "correlation with anchors",
        "mimicking anchor shift m",
        "baseline anchor bias m",
        "baseline chi-square / dof",
    ]);
    for p in &report.identifiability {
        t.row([
            p.robot.clone(),
            p.effect.clone(),
            format!("{:.3}", p.value),
            format!("{:.4}", p.sigma),
            format!("{:.5}", p.sigma_alone),
            format!("{:.5}", p.correlation_with_anchors),
            format!("{:.3}", p.mimicking_shift_mean_m),
            format!("{:.3}", p.baseline_anchor_bias_m),
            format!("{:.2} / {}", p.baseline_chi_square, p.baseline_dof),
        ]);
    }
    println!("{t}");
    println!("the smallest magnitude of each scored range, noise-free data: the baseline's anchor bias over its 1-sigma (must exceed 1):");
    let mut t = Table::new([
        "robot",
        "effect",
        "magnitude",
        "baseline anchor bias m",
        "bias / 1-sigma",
    ]);
    for p in &report.smallest {
        t.row([
            p.robot.clone(),
            p.effect.clone(),
            format!("{:.4e}", p.value),
            format!("{:.4}", p.baseline_anchor_bias_m),
            format!("{:.2}", p.baseline_bias_over_sigma),
        ]);
    }
    println!("{t}");
    Ok(())
}

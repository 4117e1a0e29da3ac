//! `sagcal simulate`'s flags ([`SimulateArgs`]) and the words it prints
//! about them, for four cables (`simulate.rs`) and for 3 to 8
//! (`simulate_suspended.rs`).

use std::path::PathBuf;

use sagcal::model::sensors::NoisePreset;
use sagcal::sim::closed_form::{Closure, Workspace};

#[derive(Debug, clap::Args)]
pub(super) struct SimulateArgs {
    /// The true robot (TOML): anchors and length offsets of the simulation
    /// (four cables, or 3 to 8 with the closed-form model).
    #[arg(long)]
    pub(super) robot: PathBuf,
    /// Number of static poses.
    #[arg(long)]
    pub(super) poses: usize,
    /// Random seed (the same seed gives the same file).
    #[arg(long, default_value_t = 1)]
    pub(super) seed: u64,
    /// Sensor noise: paper, authors or none.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    pub(super) noise: sagcal::model::sensors::NoisePreset,
    /// Output measurement file (CSV).
    #[arg(long)]
    pub(super) out: PathBuf,
    /// Also write the truth (robot TOML with offsets, and `[effects]` with `--effect`) here.
    #[arg(long)]
    pub(super) truth: Option<PathBuf>,
    /// A physical effect the closed-form model lacks, `NAME:PARAM=VALUE[,PARAM=VALUE...]`
    /// (repeatable). The data then come from the discretised simulator.
    #[arg(long = "effect", value_name = "SPEC", long_help = effect_help())]
    pub(super) effects: Vec<String>,
    /// Segments per cable of the discretised simulator (only used with effects).
    #[arg(long, default_value_t = 100)]
    pub(super) segments: usize,
    /// How each pose closes its family of equilibria: level (the most level member),
    /// yaw (a random yaw within +-1 degree) or mixed (about half each).
    #[arg(long, default_value = "level", value_parser = sagcal::sim::closed_form::Closure::parse)]
    pub(super) closure: sagcal::sim::closed_form::Closure,
}

/// `simulate --effect`'s long help: every effect with its parameters.
fn effect_help() -> String {
    format!(
        "A physical effect the closed-form model lacks, `NAME:PARAM=VALUE[,PARAM=VALUE...]` \
         (repeatable): {}. The data then come from the discretised simulator.",
        sagcal::model::effect_specs::EFFECT_NAMES
    )
}

/// `, closure yaw (+-1 deg)` for a closure other than level (whose files and
/// messages stay as they were), else nothing.
pub(super) fn closure_note(closure: Closure) -> String {
    if closure == Closure::Level {
        String::new()
    } else {
        format!(", closure {closure}")
    }
}

/// The model the data come from, as a measurement file's first comment says it.
pub(super) fn model_phrase(with_effects: bool, segments: usize) -> String {
    if with_effects {
        format!("discretised elastic-chain model, {segments} segments per cable, commanded to closed-form equilibria")
    } else {
        "closed-form catenary model".to_string()
    }
}

/// `without noise` or `with paper noise`.
pub(super) fn noise_phrase(noise: NoisePreset) -> String {
    match noise {
        NoisePreset::None => "without noise".to_string(),
        noise => format!("with {noise} noise"),
    }
}

/// `workspace BOX: cable lengths A .. B m, tensions C .. D N`, the ranges
/// the drawn poses gave.
pub(super) fn ranges_line(
    workspace: &Workspace,
    lengths_m: impl Iterator<Item = f64>,
    tensions_n: impl Iterator<Item = f64>,
) -> String {
    let range = |values: &mut dyn Iterator<Item = f64>| {
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
    };
    let (length_min, length_max) = range(&mut { lengths_m });
    let (tension_min, tension_max) = range(&mut { tensions_n });
    format!(
        "workspace {workspace}: cable lengths {length_min:.1} .. {length_max:.1} m, tensions {tension_min:.1} .. {tension_max:.1} N"
    )
}

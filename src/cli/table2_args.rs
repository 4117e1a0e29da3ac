//! The flags of `sagcal experiment table2` ([`Table2Args`]), for robots of
//! four cables and of 3 to 8.

use std::path::PathBuf;

use super::parse::{parse_pose_counts, parse_source};

#[derive(Debug, clap::Args)]
pub(super) struct Table2Args {
    /// The true robot (TOML).
    #[arg(long)]
    pub(super) robot: PathBuf,
    /// The log whose poses are sampled (RecurDyn or sagcal CSV, or the authors' dataset folder);
    /// a robot of 3 to 8 cables draws its poses in its workspace instead.
    #[arg(long)]
    pub(super) data: Option<PathBuf>,
    /// Pose counts, comma separated.
    #[arg(long, default_value = "9,18,35", value_parser = parse_pose_counts)]
    pub(super) poses: std::vec::Vec<usize>,
    /// Trials per pose count.
    #[arg(long, default_value_t = 100)]
    pub(super) trials: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub(super) seed: u64,
    /// Cable model of the calibration: catenary or rigid.
    #[arg(long, default_value = "catenary", value_parser = sagcal::calib::CableModel::parse)]
    pub(super) model: sagcal::calib::CableModel,
    /// Noise reading: paper (the paper's text) or authors (the authors' program).
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    pub(super) noise: sagcal::model::sensors::NoisePreset,
    /// `log`: the log's own lengths and tensions; `model`: the model's equilibria at the logged poses.
    #[arg(long, default_value = "log", value_parser = parse_source)]
    pub(super) source: sagcal::experiments::table2::Source,
    /// Anchor perturbation of the initial guess, m (default 10, 1 for light four-cable robots).
    #[arg(long)]
    pub(super) anchor_perturbation_m: Option<f64>,
    /// Offset perturbation of the initial guess, m (default 80, 10 for light robots).
    #[arg(long)]
    pub(super) offset_perturbation_m: Option<f64>,
    /// Right-basin radius: every anchor within it, m (default 0.3 x the anchor perturbation; unlimited for rigid).
    #[arg(long)]
    pub(super) basin_radius_m: Option<f64>,
    /// The localiser's orientation as a prior: `auto` (used unless a chi-square test finds it
    /// inconsistent with the statics), `on` or `off` (the statics decide).
    #[arg(long, default_value = "auto", value_parser = sagcal::calib::OrientationPrior::parse)]
    pub(super) orientation_prior: sagcal::calib::OrientationPrior,
    /// Effects estimated with the anchors (comma separated, e.g. a `diagnose`
    /// verdict such as `encoder-gain,segments`); default: none.
    #[arg(long)]
    pub(super) estimate: Option<String>,
    /// Leave out the readings the gross-error tests flag, as `calibrate` does
    /// (default: every trial is tested and the flags counted, the fit uses every reading).
    #[arg(long)]
    pub(super) apply_gross_errors: bool,
    /// How each trial's poses are chosen from the pool: random (the paper), planned
    /// (`sagcal plan` over the pool) or sequential (plan half, calibrate, re-plan the rest at the estimate).
    #[arg(long, default_value = "random", value_parser = ["random", "planned", "sequential"])]
    pub(super) select: String,
    /// The plan's criterion (with --select planned|sequential): a or d.
    #[arg(long, default_value = "a", value_parser = sagcal::plan::Criterion::parse)]
    pub(super) plan_criterion: sagcal::plan::Criterion,
    /// The planner's nominal anchors are this far from the truth, each in a random direction, m.
    #[arg(long, default_value_t = 0.0)]
    pub(super) plan_anchor_error_m: f64,
    /// Print JSON.
    #[arg(long)]
    pub(super) json: bool,
}

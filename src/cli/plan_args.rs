//! The flags of `sagcal plan` ([`PlanArgs`]), shared by the four-cable run
//! and the run of 3 to 8 cables.

use std::path::PathBuf;

use sagcal::model::robot::Workspace;

#[derive(Debug, clap::Args)]
pub(super) struct PlanArgs {
    /// The nominal robot (TOML): the plan is computed at its anchors.
    #[arg(long)]
    pub(super) robot: PathBuf,
    /// Poses to choose.
    #[arg(long)]
    pub(super) poses: usize,
    /// Sensor noise the bound assumes: paper or authors.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    pub(super) noise: sagcal::model::sensors::NoisePreset,
    /// The box candidates are drawn in, `x0,x1,y0,y1,z0,z1` metres (default: the
    /// robot file's `[workspace]`, else the frame below the anchors with a 10 % margin).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_workspace)]
    pub(super) workspace: Option<sagcal::model::robot::Workspace>,
    /// Candidate poses from a file (sagcal CSV or RecurDyn log, e.g. poses already logged) instead of drawing them.
    #[arg(long)]
    pub(super) from: Option<PathBuf>,
    /// Candidates to draw (without `--from`; each a level equilibrium, ~30 ms of CPU).
    #[arg(long, default_value_t = 1000)]
    pub(super) candidates: usize,
    /// Random seed of the candidates and of the random sets compared with.
    #[arg(long, default_value_t = 1)]
    pub(super) seed: u64,
    /// Design criterion: a (trace of the anchors' covariance) or d (log-determinant of the information).
    #[arg(long, default_value = "a", value_parser = sagcal::plan::Criterion::parse)]
    pub(super) criterion: sagcal::plan::Criterion,
    /// The localiser's orientation as a prior in the bound: `on`, or `off`/`auto`
    /// (the statics alone decide the orientation; the bound reads `auto` as `off`).
    #[arg(long, default_value = "off", value_parser = sagcal::calib::OrientationPrior::parse)]
    pub(super) orientation_prior: sagcal::calib::OrientationPrior,
    /// Write the plan (visiting order) as a sagcal measurement CSV (atomically).
    #[arg(long)]
    pub(super) out: Option<PathBuf>,
    /// Write the figure (PNG if the name ends in `.png`, SVG otherwise): frame, anchors, candidates,
    /// path, error ellipses plan vs random.
    #[arg(long)]
    pub(super) plot: Option<PathBuf>,
    /// Print JSON instead of the tables.
    #[arg(long)]
    pub(super) json: bool,
}

/// `x0,x1,y0,y1,z0,z1` in metres (see `sagcal::experiments::pose_plan::parse_workspace`).
pub fn parse_workspace(text: &str) -> Result<Workspace, sagcal::error::ParseError> {
    sagcal::experiments::pose_plan::parse_workspace(text)
}

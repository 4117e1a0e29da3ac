//! The flags of `sagcal diagnose` ([`DiagnoseArgs`], [`PlotFormat`]), for
//! robots of four cables and of 3 to 8.

use std::path::PathBuf;

use clap::ValueEnum;
use sagcal::diagnose::suspended::{SuspendedExtension, SUSPENDED_EXTENSIONS};
use sagcal::model::effect_kind::EffectKind;

use super::solver_args::SolverArgs;

#[derive(Debug, clap::Args)]
pub(super) struct DiagnoseArgs {
    /// Nominal robot description (TOML): the initial guess; its `[effects]` are known inputs.
    #[arg(long)]
    pub(super) robot: PathBuf,
    /// Measurements: sagcal CSV, a RecurDyn log, or the authors' dataset folder.
    #[arg(long)]
    pub(super) data: PathBuf,
    /// The true robot (TOML, e.g. from `sagcal simulate --truth`): report anchor and offset errors.
    #[arg(long)]
    pub(super) truth: Option<PathBuf>,
    /// Write the plot of the residual against the winning driver (before and after) into this folder.
    #[arg(long)]
    pub(super) plots: Option<PathBuf>,
    /// Format of the `--plots` figures: svg or png.
    #[arg(long, value_enum, default_value = "svg")]
    pub(super) plot_format: PlotFormat,
    /// Candidate effects, comma separated (default: the whole catalogue).
    #[arg(long, long_help = candidates_help())]
    pub(super) candidates: Option<String>,
    /// Leave out the hypothesis "the localiser's orientations are unreliable".
    #[arg(long)]
    pub(super) no_orientation_hypothesis: bool,
    /// Folds of the cross-validation over poses.
    #[arg(long, default_value_t = 5)]
    pub(super) folds: usize,
    /// False-alarm rate of the whole search: the probability of declaring an
    /// effect on data the baseline model describes.
    #[arg(long, default_value_t = 1e-3)]
    pub(super) false_alarm: f64,
    /// Write the selected model's calibrated robot (anchors, offsets, effects) here (TOML).
    #[arg(long)]
    pub(super) out: Option<PathBuf>,
    /// Print the diagnosis as JSON.
    #[arg(long)]
    pub(super) json: bool,
    #[command(flatten)]
    pub(super) solver: SolverArgs,
}

/// The file format of figures written into a folder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(super) enum PlotFormat {
    /// Scalable vector graphics (the figure as drawn).
    Svg,
    /// The same figure rendered to a PNG image (2x pixel density, bundled font).
    Png,
}

impl PlotFormat {
    /// The file-name extension.
    pub(super) fn extension(self) -> &'static str {
        match self {
            PlotFormat::Svg => "svg",
            PlotFormat::Png => "png",
        }
    }
}

/// `--candidates`' long help: the catalogue, from the library's list of effects.
fn candidates_help() -> String {
    let names = |in_time_order: bool| -> String {
        let kinds = EffectKind::ALL
            .into_iter()
            .filter(|k| k.needs_time_order() == in_time_order);
        kinds.map(EffectKind::name).collect::<Vec<_>>().join(", ")
    };
    format!(
        "Candidate effects, comma separated (default: the whole catalogue: {}, and, for rows in the order \
         taken (a sagcal file), {}; for a robot of 3 to 8 cables: {}, drum-gain-K and cable-weight-K for each \
         cable K; drum-gain names every drum's).",
        names(false),
        names(true),
        SUSPENDED_EXTENSIONS.map(SuspendedExtension::name).join(", ")
    )
}

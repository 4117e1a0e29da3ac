//! Command-line parsing and dispatch. Every command returns a `Result`; errors
//! are printed once, to stderr, with exit code 1 (2 for usage errors).

mod calibrate;
mod demo;
mod diagnose;
mod experiment;
mod gross_errors;
mod hidden;
mod localize;
mod localize_experiment;
mod output;
mod plan;
mod simulate;
mod verify;

use std::path::PathBuf;

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};

/// Self-calibration of suspended cable-driven parallel robots with sagging cables.
#[derive(Debug, Parser)]
#[command(name = "sagcal", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Simulate the built-in large robot, calibrate it from a perturbed guess, plot the anchors (the default).
    Demo(DemoArgs),
    /// Estimate anchors and encoder length offsets from measurements.
    Calibrate(CalibrateArgs),
    /// Write simulated measurements of a robot (sagcal's CSV format).
    Simulate(SimulateArgs),
    /// Check the kineto-static model against measured data (the paper's Table I).
    Verify(VerifyArgs),
    /// Find what the model gets wrong: test residuals, fit the catalogue of effects, report the gain.
    Diagnose(DiagnoseArgs),
    /// Localise the calibrated robot: pose and tensions from its cable readings.
    Localize(LocalizeArgs),
    /// Choose the calibration poses that make the anchors observable (optimal design on the Cramer-Rao bound).
    Plan(PlanArgs),
    /// Reproduce the paper's experiments.
    #[command(subcommand)]
    Experiment(ExperimentCommand),
    /// Print a shell completion script (e.g. `sagcal completions bash > ~/.local/share/bash-completion/completions/sagcal`).
    Completions(CompletionsArgs),
}

#[derive(Debug, clap::Args)]
struct CompletionsArgs {
    /// The shell: bash, zsh, fish (also elvish, powershell).
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

#[derive(Debug, Subcommand)]
enum ExperimentCommand {
    /// The paper's Table II calibration protocol with the Cramer-Rao bound.
    Table2(Table2Args),
    /// Hide effects in simulated data and score `sagcal diagnose`.
    HiddenEffects(HiddenEffectsArgs),
    /// Calibrate by the Table II protocol, then localise the held-out poses.
    Localize(LocalizeExperimentArgs),
}

#[derive(Debug, clap::Args)]
struct LocalizeExperimentArgs {
    /// The robot the data were logged on (truth: its anchors, zero offsets).
    #[arg(long)]
    robot: PathBuf,
    /// A RecurDyn log or sagcal measurement file: the pool of poses.
    #[arg(long)]
    data: PathBuf,
    /// Calibration poses per trial; the rest of the pool is localised.
    #[arg(long, default_value_t = 35)]
    poses: usize,
    /// Trials per case.
    #[arg(long, default_value_t = 50)]
    trials: usize,
    /// Base random seed (printed; each trial's streams derive from it).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Noise: paper, authors, or both.
    #[arg(long, default_value = "both", value_parser = parse_noises)]
    noise: std::vec::Vec<sagcal::model::sensors::NoisePreset>,
    /// Data: log, model, or both (`model`: the closed-form equilibria at the logged poses).
    #[arg(long, default_value = "both", value_parser = parse_sources)]
    source: std::vec::Vec<sagcal::experiments::table2::Source>,
    /// Print JSON instead of the table.
    #[arg(long)]
    json: bool,
}

fn parse_sources(text: &str) -> Result<Vec<sagcal::experiments::table2::Source>, String> {
    match text {
        "both" => Ok(vec![
            sagcal::experiments::table2::Source::Log,
            sagcal::experiments::table2::Source::Model,
        ]),
        other => parse_source(other).map(|s| vec![s]),
    }
}

#[derive(Debug, clap::Args)]
struct HiddenEffectsArgs {
    /// Cases per effect (and with none) per robot.
    #[arg(long, default_value_t = 20)]
    seeds: usize,
    /// Base random seed (each case's seed is derived from it and printed in the JSON).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Built-in robots, comma separated.
    #[arg(long, default_value = "large,small")]
    robots: String,
    /// Static poses per case.
    #[arg(long, default_value_t = 35)]
    poses: usize,
    /// Sensor noise of the data and the calibration: paper, authors, or both.
    #[arg(long, default_value = "both", value_parser = parse_noises)]
    noise: std::vec::Vec<sagcal::model::sensors::NoisePreset>,
    /// Segments per cable of the discretised simulator.
    #[arg(long, default_value_t = 50)]
    segments: usize,
    /// How each pose closes its family of equilibria: level (the most level member),
    /// yaw (a random yaw within +-1 degree) or mixed (about half each).
    #[arg(long, default_value = "mixed", value_parser = sagcal::sim::closed_form::Closure::parse)]
    closure: sagcal::sim::closed_form::Closure,
    /// The diagnosis' catalogue: full, or leave-one-out (each case is also
    /// diagnosed with each hidden effect left out of the catalogue, and the
    /// verdict scored for honesty: `unexplained`, and no wrong cause named).
    #[arg(long, default_value = "full", value_parser = sagcal::experiments::hidden_effects::Catalogue::parse)]
    catalogue: sagcal::experiments::hidden_effects::Catalogue,
    /// Print JSON (with every case).
    #[arg(long)]
    json: bool,
}

/// `paper`, `authors` or `both`.
/// `simulate --effect`'s long help: every effect with its parameters.
fn effect_help() -> String {
    format!(
        "A physical effect the closed-form model lacks, `NAME:PARAM=VALUE[,PARAM=VALUE...]` \
         (repeatable): {}. The data then come from the discretised simulator.",
        sagcal::model::effect_specs::EFFECT_NAMES
    )
}

fn parse_noises(text: &str) -> Result<Vec<sagcal::model::sensors::NoisePreset>, String> {
    use sagcal::model::sensors::NoisePreset;
    match text {
        "both" => Ok(vec![NoisePreset::Paper, NoisePreset::Authors]),
        other => NoisePreset::parse(other)
            .map(|n| vec![n])
            .map_err(|e| format!("{e}, or `both` (paper and authors)")),
    }
}

fn parse_pose_counts(text: &str) -> Result<Vec<usize>, String> {
    text.split(',')
        .map(|p| {
            p.trim()
                .parse::<usize>()
                .map_err(|_| format!("`{p}` is not a pose count"))
        })
        .collect()
}

fn parse_source(text: &str) -> Result<sagcal::experiments::table2::Source, String> {
    match text {
        "log" => Ok(sagcal::experiments::table2::Source::Log),
        "model" => Ok(sagcal::experiments::table2::Source::Model),
        other => Err(format!("unknown source `{other}` (log, model)")),
    }
}

#[derive(Debug, clap::Args)]
struct Table2Args {
    /// The true robot (TOML).
    #[arg(long)]
    robot: PathBuf,
    /// The log whose poses are sampled (RecurDyn or sagcal CSV, or the authors' dataset folder).
    #[arg(long)]
    data: PathBuf,
    /// Pose counts, comma separated.
    #[arg(long, default_value = "9,18,35", value_parser = parse_pose_counts)]
    poses: std::vec::Vec<usize>,
    /// Trials per pose count.
    #[arg(long, default_value_t = 100)]
    trials: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Cable model of the calibration: catenary or rigid.
    #[arg(long, default_value = "catenary", value_parser = sagcal::calib::CableModel::parse)]
    model: sagcal::calib::CableModel,
    /// Noise reading: paper (the paper's text) or authors (the authors' program).
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    noise: sagcal::model::sensors::NoisePreset,
    /// `log`: the log's own lengths and tensions; `model`: the model's equilibria at the logged poses.
    #[arg(long, default_value = "log", value_parser = parse_source)]
    source: sagcal::experiments::table2::Source,
    /// Anchor perturbation of the initial guess, m (default 10, 1 for light robots).
    #[arg(long)]
    anchor_perturbation_m: Option<f64>,
    /// Offset perturbation of the initial guess, m (default 80, 10 for light robots).
    #[arg(long)]
    offset_perturbation_m: Option<f64>,
    /// Right-basin radius: every anchor within it, m (default 0.3 x the anchor perturbation; unlimited for rigid).
    #[arg(long)]
    basin_radius_m: Option<f64>,
    /// The localiser's orientation as a prior: `auto` (used unless a chi-square test finds it
    /// inconsistent with the statics), `on` or `off` (the statics decide).
    #[arg(long, default_value = "auto", value_parser = sagcal::calib::OrientationPrior::parse)]
    orientation_prior: sagcal::calib::OrientationPrior,
    /// Effects estimated with the anchors (comma separated, e.g. a `diagnose`
    /// verdict such as `encoder-gain,segments`); default: none.
    #[arg(long)]
    estimate: Option<String>,
    /// Leave out the readings the gross-error tests flag, as `calibrate` does
    /// (default: every trial is tested and the flags counted, the fit uses every reading).
    #[arg(long)]
    apply_gross_errors: bool,
    /// How each trial's poses are chosen from the pool: random (the paper), planned
    /// (`sagcal plan` over the pool) or sequential (plan half, calibrate, re-plan the rest at the estimate).
    #[arg(long, default_value = "random", value_parser = ["random", "planned", "sequential"])]
    select: String,
    /// The plan's criterion (with --select planned|sequential): a or d.
    #[arg(long, default_value = "a", value_parser = sagcal::plan::Criterion::parse)]
    plan_criterion: sagcal::plan::Criterion,
    /// The planner's nominal anchors are this far from the truth, each in a random direction, m.
    #[arg(long, default_value_t = 0.0)]
    plan_anchor_error_m: f64,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Options of the calibration solver shared by the commands that calibrate.
#[derive(Debug, Clone, clap::Args)]
struct SolverArgs {
    /// Cable model: `catenary` (heavy cable, the default) or `rigid` (massless straight cable).
    #[arg(long, default_value = "catenary", value_parser = sagcal::calib::CableModel::parse)]
    model: sagcal::calib::CableModel,
    /// Sensor noise used as factor weights: `paper` (10 mm, 5 N / 1 N, 5 mm, 0.01 rad) or `authors`.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    noise: sagcal::model::sensors::NoisePreset,
    /// Override the encoder sigma, metres.
    #[arg(long)]
    encoder_sigma_m: Option<f64>,
    /// Override the load-cell sigma, newtons.
    #[arg(long)]
    load_cell_sigma_n: Option<f64>,
    /// Override the localiser position sigma, metres.
    #[arg(long)]
    position_sigma_m: Option<f64>,
    /// The localiser's orientation as a prior: `auto` (used unless a chi-square test finds it
    /// inconsistent with the fitted statics), `on` or `off` (the statics decide).
    #[arg(long, default_value = "auto", value_parser = sagcal::calib::OrientationPrior::parse)]
    orientation_prior: sagcal::calib::OrientationPrior,
    /// Robust kernel on the encoder factors: none, huber[:k], cauchy[:c].
    #[arg(long, default_value = "none", value_parser = sagcal::graph::RobustKernel::parse)]
    robust_encoder: sagcal::graph::RobustKernel,
    /// Robust kernel on the load-cell factors.
    #[arg(long, default_value = "none", value_parser = sagcal::graph::RobustKernel::parse)]
    robust_load_cell: sagcal::graph::RobustKernel,
    /// Robust kernel on the pose priors.
    #[arg(long, default_value = "none", value_parser = sagcal::graph::RobustKernel::parse)]
    robust_pose: sagcal::graph::RobustKernel,
}

impl SolverArgs {
    /// The library's solver settings these flags give.
    fn settings(&self) -> sagcal::calib::SolverSettings {
        sagcal::calib::SolverSettings {
            model: self.model,
            noise: self.noise,
            encoder_sigma_m: self.encoder_sigma_m,
            load_cell_sigma_n: self.load_cell_sigma_n,
            position_sigma_m: self.position_sigma_m,
            orientation_prior: self.orientation_prior,
            robust: sagcal::calib::RobustKernels {
                encoder: self.robust_encoder,
                load_cell: self.robust_load_cell,
                pose_prior: self.robust_pose,
            },
        }
    }
}

#[derive(Debug, clap::Args)]
struct CalibrateArgs {
    /// Nominal robot description (TOML): the initial guess of anchors and offsets.
    #[arg(long)]
    robot: PathBuf,
    /// Measurements: sagcal CSV (see docs/measurements.md), a RecurDyn log, or the authors' dataset folder
    /// (`pos_i_cpp_test.csv`, `R_i_cpp_test.csv`, `lc_meas_cpp_test.csv`, `forces_cpp_test.csv`).
    #[arg(long)]
    data: PathBuf,
    /// Write the calibrated robot (TOML) here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write a plot of nominal and calibrated anchors with error ellipses here (PNG if the name ends in `.png`, SVG otherwise).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Write the calibrated robot even when the fit fails its own consistency
    /// tests (the verdict is recorded in the file's header comment).
    #[arg(long)]
    accept_inconsistent: bool,
    /// False-alarm rate of the gross-error tests (per reading, over all
    /// readings; per sensor type, over the types).
    #[arg(long, default_value_t = 1e-3)]
    false_alarm: f64,
    #[command(flatten)]
    solver: SolverArgs,
}

#[derive(Debug, clap::Args)]
struct DiagnoseArgs {
    /// Nominal robot description (TOML): the initial guess; its `[effects]` are known inputs.
    #[arg(long)]
    robot: PathBuf,
    /// Measurements: sagcal CSV, a RecurDyn log, or the authors' dataset folder.
    #[arg(long)]
    data: PathBuf,
    /// The true robot (TOML, e.g. from `sagcal simulate --truth`): report anchor and offset errors.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// Write the plot of the residual against the winning driver (before and after) into this folder.
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Format of the `--plots` figures: svg or png.
    #[arg(long, value_enum, default_value = "svg")]
    plot_format: PlotFormat,
    /// Candidate effects, comma separated (default: the whole catalogue: elastic, pulley, encoder-scale, loadcell,
    /// com, encoder-gain, segments, localiser-mount, platform-weight, cable-weight, and, for rows in the order
    /// taken (a sagcal file), encoder-drift, encoder-backlash, loadcell-drift, loadcell-friction).
    #[arg(long)]
    candidates: Option<String>,
    /// Leave out the hypothesis "the localiser's orientations are unreliable".
    #[arg(long)]
    no_orientation_hypothesis: bool,
    /// Folds of the cross-validation over poses.
    #[arg(long, default_value_t = 5)]
    folds: usize,
    /// False-alarm rate of the whole search: the probability of declaring an
    /// effect on data the baseline model describes.
    #[arg(long, default_value_t = 1e-3)]
    false_alarm: f64,
    /// Write the selected model's calibrated robot (anchors, offsets, effects) here (TOML).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the diagnosis as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    solver: SolverArgs,
}

#[derive(Debug, clap::Args)]
struct SimulateArgs {
    /// The true robot (TOML): anchors and length offsets of the simulation.
    #[arg(long)]
    robot: PathBuf,
    /// Number of static poses.
    #[arg(long)]
    poses: usize,
    /// Random seed (the same seed gives the same file).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Sensor noise: paper, authors or none.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    noise: sagcal::model::sensors::NoisePreset,
    /// Output measurement file (CSV).
    #[arg(long)]
    out: PathBuf,
    /// Also write the truth (robot TOML with offsets, and `[effects]` with `--effect`) here.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// A physical effect the closed-form model lacks, `NAME:PARAM=VALUE[,PARAM=VALUE...]`
    /// (repeatable). The data then come from the discretised simulator.
    #[arg(long = "effect", value_name = "SPEC", long_help = effect_help())]
    effects: Vec<String>,
    /// Segments per cable of the discretised simulator (only used with effects).
    #[arg(long, default_value_t = 100)]
    segments: usize,
    /// How each pose closes its family of equilibria: level (the most level member),
    /// yaw (a random yaw within +-1 degree) or mixed (about half each).
    #[arg(long, default_value = "level", value_parser = sagcal::sim::closed_form::Closure::parse)]
    closure: sagcal::sim::closed_form::Closure,
}

#[derive(Debug, Clone, clap::Args)]
struct DemoArgs {
    /// Random seed of the simulation and of the perturbed initial guess.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Number of static poses.
    #[arg(long, default_value_t = 35)]
    poses: usize,
    /// Folder for the demo's files (data.csv, truth.toml, calibrated.toml, anchors.svg).
    #[arg(long, default_value = "sagcal-demo")]
    out_dir: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// The file format of figures written into a folder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum PlotFormat {
    /// Scalable vector graphics (the figure as drawn).
    Svg,
    /// The same figure rendered to a PNG image (2x pixel density, bundled font).
    Png,
}

impl PlotFormat {
    /// The file-name extension.
    fn extension(self) -> &'static str {
        match self {
            PlotFormat::Svg => "svg",
            PlotFormat::Png => "png",
        }
    }
}

/// Which measurement closes the statics in `verify`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ClosureArg {
    /// Position + the reference cable's load-cell tension (default).
    ReferenceTension,
    /// Position + the four measured cable lengths (least squares).
    CableLengths,
}

#[derive(Debug, clap::Args)]
struct VerifyArgs {
    /// Robot description (TOML), e.g. robots/large.toml.
    #[arg(long)]
    robot: PathBuf,
    /// Measurement log: RecurDyn CSV, sagcal CSV or the authors' dataset folder.
    #[arg(long)]
    data: PathBuf,
    /// The measurement that closes the one-parameter family of equilibria.
    #[arg(long, value_enum, default_value = "reference-tension")]
    close_with: ClosureArg,
    /// Keep rows whose pose was transcribed rounded to 0.01 m (rejected by default).
    #[arg(long)]
    keep_rounded: bool,
    /// Print the full report as JSON instead of tables.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct LocalizeArgs {
    /// The calibrated robot (TOML): anchors, length offsets, `[effects]`.
    #[arg(long)]
    robot: PathBuf,
    /// Readings: `l1_m,l2_m,l3_m,l4_m[,f_ref_n]`, a sagcal measurement file, a RecurDyn log or
    /// the authors' dataset folder.
    #[arg(long)]
    data: PathBuf,
    /// Use the input's localiser pose as a prior (by default it is only compared with).
    #[arg(long)]
    pose_prior: bool,
    /// Sensor sigmas of the readings: paper or authors.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    noise: sagcal::model::sensors::NoisePreset,
    /// False-alarm rate of each row's chi-square consistency test.
    #[arg(long, default_value_t = 1e-3)]
    false_alarm: f64,
    /// Leave the robot file's recorded calibration covariance out of the sigmas.
    #[arg(long)]
    no_calibration_uncertainty: bool,
    /// Skip the multistart search for every equilibrium of each row (about
    /// 1000 starts per row): for long trajectories, each row warm-started
    /// from the previous one.
    #[arg(long)]
    fast: bool,
    /// Write the poses as CSV (atomically).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Draw the localised poses with their 1-sigma ellipses (top and side
    /// views), beside the input's poses when it has them (PNG if the name ends in `.png`, SVG otherwise).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print JSON instead of the table.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct PlanArgs {
    /// The nominal robot (TOML): the plan is computed at its anchors.
    #[arg(long)]
    robot: PathBuf,
    /// Poses to choose.
    #[arg(long)]
    poses: usize,
    /// Sensor noise the bound assumes: paper or authors.
    #[arg(long, default_value = "paper", value_parser = sagcal::model::sensors::NoisePreset::parse)]
    noise: sagcal::model::sensors::NoisePreset,
    /// The box candidates are drawn in, `x0,x1,y0,y1,z0,z1` metres (default: the
    /// robot file's `[workspace]`, else the frame below the anchors with a 10 % margin).
    #[arg(long, allow_hyphen_values = true, value_parser = plan::parse_workspace)]
    workspace: Option<sagcal::model::robot::Workspace>,
    /// Candidate poses from a file (sagcal CSV or RecurDyn log, e.g. poses already logged) instead of drawing them.
    #[arg(long)]
    from: Option<PathBuf>,
    /// Candidates to draw (without `--from`; each a level equilibrium, ~30 ms of CPU).
    #[arg(long, default_value_t = 1000)]
    candidates: usize,
    /// Random seed of the candidates and of the random sets compared with.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Design criterion: a (trace of the anchors' covariance) or d (log-determinant of the information).
    #[arg(long, default_value = "a", value_parser = sagcal::plan::Criterion::parse)]
    criterion: sagcal::plan::Criterion,
    /// The localiser's orientation as a prior in the bound: `on`, or `off`/`auto`
    /// (the statics alone decide the orientation, as `cramer_rao_bound` reads `auto`).
    #[arg(long, default_value = "off", value_parser = sagcal::calib::OrientationPrior::parse)]
    orientation_prior: sagcal::calib::OrientationPrior,
    /// Write the plan (visiting order) as a sagcal measurement CSV (atomically).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the figure (PNG if the name ends in `.png`, SVG otherwise): frame, anchors, candidates,
    /// path, error ellipses plan vs random.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print JSON instead of the tables.
    #[arg(long)]
    json: bool,
}

/// Parse the command line, run the command, return the process exit code.
pub fn run() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    if let Err(message) = sagcal::simd::check_switch() {
        eprintln!("error: {message}");
        return 2;
    }
    let result = match cli.command {
        None => demo::run(&DemoArgs {
            seed: 1,
            poses: 35,
            out_dir: PathBuf::from("sagcal-demo"),
            json: false,
        }),
        Some(Command::Demo(args)) => demo::run(&args),
        Some(Command::Calibrate(args)) => calibrate::run(&args),
        Some(Command::Simulate(args)) => simulate::run(&args),
        Some(Command::Verify(args)) => verify::run(&args),
        Some(Command::Diagnose(args)) => diagnose::run(&args),
        Some(Command::Localize(args)) => localize::run(&args),
        Some(Command::Plan(args)) => plan::run(&args),
        Some(Command::Experiment(ExperimentCommand::Table2(args))) => experiment::run(&args),
        Some(Command::Experiment(ExperimentCommand::HiddenEffects(args))) => hidden::run(&args),
        Some(Command::Experiment(ExperimentCommand::Localize(args))) => localize_experiment::run_experiment(&args),
        Some(Command::Completions(args)) => {
            clap_complete::generate(args.shell, &mut Cli::command(), "sagcal", &mut std::io::stdout());
            Ok(())
        }
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e}");
            1
        }
    }
}

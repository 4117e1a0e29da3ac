//! `sagcal simulate`: measurements of a robot from the closed-form model, or,
//! with `--effect` (or a robot file with `[effects]`), from the discretised
//! simulator with those effects acting; its flags ([`SimulateArgs`]) and the
//! run.

use std::path::PathBuf;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::error::FrontEnd;
use sagcal::io::measurements::measurements_text;
use sagcal::io::OutputSet;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::statics::Equilibrium;
use sagcal::model::{PoseMeasurement, Robot};
use sagcal::sim::closed_form::{measure, sample_equilibria_with, Closure, Workspace};
use sagcal::sim::effects::{measure_with_effects, simulation_truth};

use super::output::counted;

#[derive(Debug, clap::Args)]
pub(super) struct SimulateArgs {
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

/// `simulate --effect`'s long help: every effect with its parameters.
fn effect_help() -> String {
    format!(
        "A physical effect the closed-form model lacks, `NAME:PARAM=VALUE[,PARAM=VALUE...]` \
         (repeatable): {}. The data then come from the discretised simulator.",
        sagcal::model::effect_specs::EFFECT_NAMES
    )
}

/// Simulate measurements of the robot, write them (and the truth), report what was drawn.
pub fn run(args: &SimulateArgs) -> sagcal::Result<()> {
    let (truth, from_file) = load_truth(args)?;
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let workspace = Workspace::default_for(&truth);
    let equilibria = sample_equilibria_with(&truth, &workspace, args.poses, args.closure, &mut rng)?;
    let data = measure_poses(args, &truth, from_file, &equilibria, &mut rng)?;
    // Both files or neither (no truth file beside a refused data file), none over the robot file.
    let mut outputs = OutputSet::new();
    outputs.input("--robot", &args.robot);
    let text = measurements_text(&args.out, &comments(args, &truth, &workspace), &data)?;
    outputs.file("--out", &args.out, text);
    if let Some(path) = &args.truth {
        outputs.file("--truth", path, truth_text(args, &truth)?);
    }
    outputs.write()?;
    print_ranges(&workspace, &equilibria);
    println!(
        "seed {}: {} of robot `{}` {}{} written to {}",
        args.seed,
        counted(args.poses, "pose", "poses"),
        truth.name,
        match args.noise {
            NoisePreset::None => "without noise".to_string(),
            noise => format!("with {noise} noise"),
        },
        closure_note(args.closure),
        args.out.display()
    );
    Ok(())
}

/// The true robot with its effects (the robot file's `[effects]`, if any, then
/// every `--effect` in order) and whether the file brought effects; checks
/// `--poses` and, with effects, `--segments`.
fn load_truth(args: &SimulateArgs) -> sagcal::Result<(Robot, bool)> {
    let robot = Robot::from_file(&args.robot)?;
    // The robot file's `[effects]` (if any), then every `--effect` in order.
    let from_file = !robot.effects.is_none();
    let truth = simulation_truth(&robot, args.poses, &args.effects, args.segments, FrontEnd::Cli)?;
    Ok((truth, from_file))
}

/// Noisy measurements at the equilibria: from the closed-form model, or, with
/// effects, from the discretised simulator (announced on stdout).
fn measure_poses(
    args: &SimulateArgs,
    truth: &Robot,
    from_file: bool,
    equilibria: &[Equilibrium],
    rng: &mut ChaCha8Rng,
) -> sagcal::Result<Vec<PoseMeasurement>> {
    let effects = truth.effects;
    let noise = args.noise.sigmas(truth.platform_weight_n);
    if effects.is_none() {
        return Ok(measure(truth, equilibria, &noise, rng));
    }
    println!(
        "effects{}: {effects}; seed {}; discretised simulator, {} segments per cable",
        if from_file {
            " (robot file's [effects] included)"
        } else {
            ""
        },
        args.seed,
        args.segments
    );
    measure_with_effects(truth, &effects, equilibria, &noise, args.segments, rng)
}

/// The measurement file's comment lines: generator, robot, seed, noise, workspace and effects.
fn comments(args: &SimulateArgs, truth: &Robot, workspace: &Workspace) -> Vec<String> {
    let effects = truth.effects;
    let model = if effects.is_none() {
        "closed-form catenary model".to_string()
    } else {
        format!(
            "discretised elastic-chain model, {} segments per cable, commanded to closed-form equilibria",
            args.segments
        )
    };
    let mut comments = vec![
        format!("simulated by sagcal {} ({model})", env!("CARGO_PKG_VERSION")),
        format!(
            "robot {} ({}), {} poses, seed {}, noise {}{}",
            truth.name,
            args.robot.display(),
            args.poses,
            args.seed,
            args.noise,
            closure_note(args.closure)
        ),
        format!("workspace {workspace}"),
    ];
    if !effects.is_none() {
        comments.push(format!("effects {effects}"));
    }
    comments
}

/// The truth: robot TOML with offsets and effects, under a comment naming the simulation.
fn truth_text(args: &SimulateArgs, truth: &Robot) -> sagcal::Result<String> {
    let effects = truth.effects;
    let effects_note = if effects.is_none() {
        String::new()
    } else {
        format!(", effects {effects} ({} segments)", args.segments)
    };
    Ok(format!(
        "# The truth of a sagcal simulation: seed {}, {} poses, noise {}{}{effects_note}.\n{}",
        args.seed,
        args.poses,
        args.noise,
        closure_note(args.closure),
        truth.to_file_contents().to_toml()?
    ))
}

/// `, closure yaw (+-1 deg)` for a closure other than level (whose files and
/// messages stay as they were), else nothing.
fn closure_note(closure: Closure) -> String {
    if closure == Closure::Level {
        String::new()
    } else {
        format!(", closure {closure}")
    }
}

/// The workspace and the ranges of cable lengths and tensions it gave.
fn print_ranges(workspace: &Workspace, equilibria: &[Equilibrium]) {
    let range = |values: &mut dyn Iterator<Item = f64>| {
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
    };
    let (length_min, length_max) = range(&mut equilibria.iter().flat_map(|eq| eq.cable_lengths_m));
    let (tension_min, tension_max) = range(
        &mut equilibria
            .iter()
            .flat_map(|eq| eq.tensions.iter().map(|t| t.magnitude_n())),
    );
    println!(
        "workspace {workspace}: cable lengths {length_min:.1} .. {length_max:.1} m, tensions {tension_min:.1} .. {tension_max:.1} N"
    );
}

//! `sagcal simulate`: measurements of a robot from the closed-form model, or,
//! with `--effect` (or a robot file with `[effects]`), from the discretised
//! simulator with those effects acting: the run.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::error::FrontEnd;
use sagcal::io::measurements::measurements_text;
use sagcal::io::OutputSet;
use sagcal::model::statics::Equilibrium;
use sagcal::model::{PoseMeasurement, Robot};
use sagcal::sim::closed_form::{measure, sample_equilibria_with, Workspace};
use sagcal::sim::effects::{measure_with_effects, simulation_truth};

use super::output::counted;
use super::robot_kind::{read_robot, AnyRobot};
use super::simulate_args::{closure_note, model_phrase, noise_phrase, ranges_line, SimulateArgs};

/// Simulate measurements of the robot, write them (and the truth), report what was drawn.
///
/// A robot file the four-cable model does not take (another number of
/// cables, per-cable weights, several load cells) goes to the model of 3 to
/// 8 cables.
pub fn run(args: &SimulateArgs) -> sagcal::Result<()> {
    if let AnyRobot::Suspended(robot) = read_robot(&args.robot)? {
        return super::simulate_suspended::run(args, &robot);
    }
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
        noise_phrase(args.noise),
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
    let model = model_phrase(!effects.is_none(), args.segments);
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

/// The workspace and the ranges of cable lengths and tensions it gave.
fn print_ranges(workspace: &Workspace, equilibria: &[Equilibrium]) {
    println!(
        "{}",
        ranges_line(
            workspace,
            equilibria.iter().flat_map(|eq| eq.cable_lengths_m),
            equilibria
                .iter()
                .flat_map(|eq| eq.tensions.iter().map(|t| t.magnitude_n())),
        )
    );
}

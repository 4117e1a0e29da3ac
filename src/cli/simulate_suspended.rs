//! `sagcal simulate` on a robot of 3 to 8 cables: the closed-form model
//! ([`sagcal::sim::suspended`]), or with `--effect` or elastic cables the
//! discretised simulator with those effects acting ([`sagcal::sim::suspended_effects`]),
//! written in the N-cable measurement file
//! ([`sagcal::io::suspended_measurements`]).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::error::FrontEnd;
use sagcal::io::suspended_measurements::suspended_measurements_text;
use sagcal::io::OutputSet;
use sagcal::model::effects::Effects;
use sagcal::model::suspended::{SuspendedEquilibrium, SuspendedMeasurement, SuspendedRobot};
use sagcal::sim::closed_form::Workspace;
use sagcal::sim::suspended::sample_suspended;
use sagcal::sim::suspended_effects::{effects_from_specs, simulate_readings};
use sagcal::Error;

use super::output::counted;
use super::simulate_args::{closure_note, model_phrase, noise_phrase, ranges_line, SimulateArgs};

/// Simulate `robot` as `args` ask, write the measurements and report what was drawn.
pub(super) fn run(args: &SimulateArgs, robot: &SuspendedRobot) -> sagcal::Result<()> {
    refuse_four_cable_options(args, robot)?;
    let workspace = robot
        .workspace
        .unwrap_or_else(|| Workspace::around_anchor_points(&robot.anchors_m));
    let effects = effects_from_specs(&args.effects, FrontEnd::Cli)?;
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let equilibria = sample_suspended(robot, &workspace, args.poses, args.closure, &mut rng)?;
    let rows = measure(args, robot, &effects, &equilibria, &mut rng)?;
    let model = model_phrase(!effects.is_none() || robot.is_elastic(), args.segments);
    let mut comments = vec![
        format!(
            "simulated by sagcal {} ({model}, {} cables)",
            env!("CARGO_PKG_VERSION"),
            robot.cable_count()
        ),
        format!(
            "robot {} ({}), {} poses, seed {}, noise {}{}",
            robot.name,
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
    let mut outputs = OutputSet::new();
    outputs.input("--robot", &args.robot);
    outputs.file(
        "--out",
        &args.out,
        suspended_measurements_text(&args.out, robot, &comments, &rows)?,
    );
    outputs.write()?;
    print_ranges(&workspace, &equilibria);
    println!(
        "seed {}: {} of robot `{}` ({} cables, load cells on {}) {}{} written to {}",
        args.seed,
        counted(args.poses, "pose", "poses"),
        robot.name,
        robot.cable_count(),
        robot.load_cells_phrase(),
        noise_phrase(args.noise),
        closure_note(args.closure),
        args.out.display()
    );
    Ok(())
}

/// The options only the four-cable model has, refused with the reason.
fn refuse_four_cable_options(args: &SimulateArgs, robot: &SuspendedRobot) -> sagcal::Result<()> {
    if args.truth.is_some() {
        return Err(Error::InvalidInput(format!(
            "robot `{}` ({} cables): --truth: the robot file is the truth of a simulation of 3 to 8 cables \
             (nothing is drawn for it; the effects are the --effect flags)",
            robot.name,
            robot.cable_count()
        )));
    }
    Ok(())
}

/// The readings at `equilibria` (announcing the discretised simulator's
/// settings on stdout when effects act, as for four cables).
fn measure(
    args: &SimulateArgs,
    robot: &SuspendedRobot,
    effects: &Effects,
    equilibria: &[SuspendedEquilibrium],
    rng: &mut ChaCha8Rng,
) -> sagcal::Result<Vec<SuspendedMeasurement>> {
    if !effects.is_none() {
        println!(
            "effects: {effects}; seed {}; discretised simulator, {} segments per cable",
            args.seed, args.segments
        );
    } else if robot.is_elastic() {
        println!(
            "elastic cables (the robot file's axial_stiffness_n); seed {}; discretised simulator, {} segments per cable",
            args.seed, args.segments
        );
    }
    let noise = args.noise.sigmas(robot.platform_weight_n);
    simulate_readings(robot, effects, equilibria, &noise, args.segments, rng)
}
/// The workspace and the ranges of cable lengths and tensions it gave.
fn print_ranges(workspace: &Workspace, equilibria: &[SuspendedEquilibrium]) {
    println!(
        "{}",
        ranges_line(
            workspace,
            equilibria.iter().flat_map(|eq| eq.cable_lengths_m.iter().copied()),
            equilibria
                .iter()
                .flat_map(|eq| eq.tensions.iter().map(|t| t.magnitude_n())),
        )
    );
}

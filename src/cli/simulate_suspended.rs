//! `sagcal simulate` on a robot of 3 to 8 cables: the closed-form model
//! ([`sagcal::sim::suspended`]), written in the N-cable measurement file
//! ([`sagcal::io::suspended_measurements`]).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::io::suspended_measurements::suspended_measurements_text;
use sagcal::io::OutputSet;
use sagcal::model::suspended::{SuspendedEquilibrium, SuspendedRobot};
use sagcal::sim::closed_form::Workspace;
use sagcal::sim::suspended::{measure_suspended, sample_suspended};
use sagcal::Error;

use super::output::counted;
use super::simulate_args::{closure_note, noise_phrase, ranges_line, SimulateArgs};

/// Simulate `robot` as `args` ask, write the measurements and report what was drawn.
pub(super) fn run(args: &SimulateArgs, robot: &SuspendedRobot) -> sagcal::Result<()> {
    refuse_four_cable_options(args, robot)?;
    let workspace = robot
        .workspace
        .unwrap_or_else(|| Workspace::around_anchor_points(&robot.anchors_m));
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let equilibria = sample_suspended(robot, &workspace, args.poses, args.closure, &mut rng)?;
    let noise = args.noise.sigmas(robot.platform_weight_n);
    let rows = measure_suspended(robot, &equilibria, &noise, &mut rng);
    let comments = vec![
        format!(
            "simulated by sagcal {} (closed-form catenary model, {} cables)",
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
    let refused = if !args.effects.is_empty() {
        Some("--effect: the model of 3 to 8 cables has none of the effects of the catalogue")
    } else if args.truth.is_some() {
        Some("--truth: the robot file is the truth of a simulation of 3 to 8 cables (nothing is drawn for it)")
    } else {
        None
    };
    match refused {
        Some(why) => Err(Error::InvalidInput(format!(
            "robot `{}` ({} cables): {why}",
            robot.name,
            robot.cable_count()
        ))),
        None => Ok(()),
    }
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

//! `sagcal simulate`: measurements of a robot from the closed-form model.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::io::measurements::write_measurements;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

use super::SimulateArgs;

pub fn run(args: &SimulateArgs) -> sagcal::Result<()> {
    let truth = Robot::from_file(&args.robot)?;
    if args.poses == 0 {
        return Err(sagcal::Error::InvalidInput("--poses must be at least 1".into()));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let workspace = Workspace::default_for(&truth);
    let equilibria = sample_equilibria(&truth, &workspace, args.poses, &mut rng)?;
    let noise = args.noise.sigmas(truth.platform_weight_n);
    let data = measure(&truth, &equilibria, &noise, &mut rng);
    let comments = vec![
        format!(
            "simulated by sagcal {} (closed-form catenary model)",
            env!("CARGO_PKG_VERSION")
        ),
        format!(
            "robot {} ({}), {} poses, seed {}, noise {}",
            truth.name,
            args.robot.display(),
            args.poses,
            args.seed,
            args.noise
        ),
        format!("workspace {:?} .. {:?} m", workspace.min_m, workspace.max_m),
    ];
    if let Some(path) = &args.truth {
        let text = format!(
            "# The truth of a sagcal simulation: seed {}, {} poses, noise {}.\n{}",
            args.seed,
            args.poses,
            args.noise,
            truth.to_file_contents().to_toml()?
        );
        sagcal::io::write_atomically(path, text.as_bytes())?;
    }
    write_measurements(&args.out, &comments, &data)?;
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
        "workspace {:?} .. {:?} m: cable lengths {length_min:.1} .. {length_max:.1} m, tensions {tension_min:.1} .. {tension_max:.1} N",
        workspace.min_m, workspace.max_m
    );
    println!(
        "seed {}: {} poses of robot `{}` with {} noise written to {}",
        args.seed,
        args.poses,
        truth.name,
        args.noise,
        args.out.display()
    );
    Ok(())
}

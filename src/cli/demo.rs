//! `sagcal demo` (and `sagcal` with no arguments): the main job on built-in
//! data; its flags ([`DemoArgs`]) and the run.
//!
//! The truth is the built-in large robot with random encoder offsets; the
//! calibration starts, as in the paper, from anchors moved 10 m and offsets
//! moved 80 m; 35 static poses with the paper's noise.

use std::path::PathBuf;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sagcal::calib::gross_errors::Verdict;
use sagcal::calib::report::CalibrationReport;
use sagcal::calib::{anchor_rms_bound_m, calibrate, cramer_rao_bound, CalibrationOptions, CalibrationResult};
use sagcal::io::measurements::measurements_text;
use sagcal::io::OutputSet;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::{PoseMeasurement, Robot};
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

use super::calibrate::{plot_svg, render, robot_text};
use super::output::print_json;

#[derive(Debug, Clone, clap::Args)]
pub(super) struct DemoArgs {
    /// Random seed of the simulation and of the perturbed initial guess.
    #[arg(long, default_value_t = 1)]
    pub(super) seed: u64,
    /// Number of static poses.
    #[arg(long, default_value_t = 35)]
    pub(super) poses: usize,
    /// Folder for the demo's files (data.csv, truth.toml, guess.toml, calibrated.toml, anchors.svg).
    #[arg(long, default_value = "sagcal-demo")]
    pub(super) out_dir: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub(super) json: bool,
}

pub fn run(args: &DemoArgs) -> sagcal::Result<()> {
    if args.poses < sagcal::calib::MIN_POSES {
        return Err(sagcal::Error::InvalidInput(format!(
            "--poses must be at least {}",
            sagcal::calib::MIN_POSES
        )));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut truth = Robot::builtin("large")?;
    for offset in &mut truth.length_offsets_m {
        *offset = rng.random_range(-5.0..5.0);
    }
    let mut guess = truth.clone();
    guess.name = "large (nominal guess)".into();
    for i in 0..4 {
        let direction = loop {
            let v = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if v.norm() > 0.1 && v.norm() <= 1.0 {
                break v.normalize();
            }
        };
        guess.anchors_m[i] += 10.0 * direction;
        guess.length_offsets_m[i] = truth.length_offsets_m[i] + if rng.random_bool(0.5) { 80.0 } else { -80.0 };
    }
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), args.poses, &mut rng)?;
    let data = measure(&truth, &equilibria, &noise, &mut rng);
    let options = CalibrationOptions::new(noise);
    let started = std::time::Instant::now();
    let result = calibrate(&guess, &data, &options)?;
    let elapsed_ms = started.elapsed().as_secs_f64() * 1e3;
    let bound = cramer_rao_bound(&truth, &equilibria, &options.as_used_by(&result))?;
    let report = CalibrationReport::new(&result, &guess, options.model, &[], Some(&truth));

    let data_path = write_files(args, &data, &truth, &guess, &result)?;
    if args.json {
        return print_json(&report);
    }
    println!(
        "sagcal demo (seed {}): the built-in large robot, {} simulated static poses with the paper's noise;\ncalibration from anchors moved 10 m and offsets moved 80 m (the paper's protocol).\n",
        args.seed, args.poses
    );
    print!("{}", render(&report, &options));
    if let (Some(e), Some(bound)) = (&report.error_against_truth, anchor_rms_bound_m(&bound)) {
        let rms_bound = (bound.iter().map(|b| b * b).sum::<f64>() / bound.len() as f64).sqrt();
        let rms_error = (0..4)
            .map(|i| (result.robot.anchors_m[i] - truth.anchors_m[i]).norm_squared())
            .sum::<f64>()
            / 4.0;
        println!(
            "Cramer-Rao bound at the truth: {:.3} m RMS per anchor; achieved {:.3} m RMS ({:.3} m mean Euclidean)",
            rms_bound,
            rms_error.sqrt(),
            e.anchor_mean_euclidean_m
        );
    }
    println!("solve time {elapsed_ms:.0} ms");
    println!(
        "files: {} (measurements), truth.toml, guess.toml, calibrated.toml, anchors.svg (plot) in {}",
        data_path.display(),
        args.out_dir.display()
    );
    println!(
        "next: sagcal calibrate --robot {} --data {}",
        args.out_dir.join("guess.toml").display(),
        data_path.display()
    );
    Ok(())
}

/// The demo's folder and its five files, all of them or none; the data file's path.
fn write_files(
    args: &DemoArgs,
    data: &[PoseMeasurement],
    truth: &Robot,
    guess: &Robot,
    result: &CalibrationResult,
) -> sagcal::Result<PathBuf> {
    let data_path = args.out_dir.join("data.csv");
    let comments = vec![format!(
        "sagcal demo: built-in large robot, {} poses, seed {}, paper noise",
        args.poses, args.seed
    )];
    let positions: Vec<[f64; 3]> = data.iter().map(|p| p.position_m).collect();
    let caption = format!("sagcal demo --seed {} --poses {}", args.seed, args.poses);
    let mut outputs = OutputSet::new();
    outputs.folder("--out-dir", &args.out_dir).file(
        "--out-dir",
        &data_path,
        measurements_text(&data_path, &comments, data)?,
    );
    let (truth_header, guess_header) = robot_headers(args);
    for (name, text) in [
        (
            "truth.toml",
            format!("{truth_header}{}", truth.to_file_contents().to_toml()?),
        ),
        (
            "guess.toml",
            format!("{guess_header}{}", guess.to_file_contents().to_toml()?),
        ),
        ("calibrated.toml", robot_text(&result.robot, &Verdict::Consistent)?),
    ] {
        outputs.file("--out-dir", &args.out_dir.join(name), text);
    }
    outputs.file(
        "--out-dir",
        &args.out_dir.join("anchors.svg"),
        plot_svg(guess, Some(truth), result, &positions, &caption),
    );
    outputs.write()?;
    Ok(data_path)
}

/// The header comments of `truth.toml` and `guess.toml`: what each file is
/// (neither was estimated from measurements; `calibrated.toml` was).
fn robot_headers(args: &DemoArgs) -> (String, String) {
    (
        format!(
            "# The truth of sagcal demo (seed {}, {} poses): the simulated robot's true parameters; data.csv was simulated from it.\n",
            args.seed, args.poses
        ),
        format!(
            "# The initial guess of sagcal demo (seed {}): the nominal robot the calibration starts from, the truth's anchors moved 10 m and its encoder length offsets moved 80 m.\n",
            args.seed
        ),
    )
}

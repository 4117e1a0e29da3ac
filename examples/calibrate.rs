//! Calibrate the built-in large robot from simulated measurements.
//!
//! ```text
//! cargo run --release --example calibrate [-- FIGURE.png|FIGURE.svg]
//! ```
//!
//! The truth is the built-in `large` robot (the paper's 250 m x 220 m
//! platform) with encoder offsets of a few metres; the calibration starts,
//! as in the paper's Table II, from anchors moved 10 m and offsets moved
//! 80 m, and reads 35 static poses with the paper's sensor noise. It prints
//! each anchor's error against the truth beside its 3D sigma
//! (`sqrt(trace)` of the covariance), and, with an argument, writes the anchor figure (PNG or SVG).

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sagcal::calib::{calibrate, CalibrationOptions, ParameterUncertainty};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::plot::{anchor_plot_svg, write_figure, AnchorPlot, AnchorPlotEntry};
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

fn main() -> sagcal::Result<()> {
    let seed = 1;
    println!("seed {seed}");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);

    // The truth, and the operator's guess: every anchor 10 m off, every offset 80 m off.
    let mut truth = Robot::builtin("large")?;
    for offset in &mut truth.length_offsets_m {
        *offset = rng.random_range(-5.0..5.0);
    }
    let mut guess = truth.clone();
    for i in 0..4 {
        let direction = Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 0.5).normalize();
        guess.anchors_m[i] += 10.0 * direction;
        guess.length_offsets_m[i] += 80.0;
    }

    // 35 static poses: the robot's sensors read them with the paper's noise.
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 35, &mut rng)?;
    let measurements = measure(&truth, &equilibria, &noise, &mut rng);

    let result = calibrate(&guess, &measurements, &CalibrationOptions::new(noise))?;

    let covariance = match &result.uncertainty {
        ParameterUncertainty::Full {
            anchor_covariance_m2, ..
        } => Some(anchor_covariance_m2.clone()),
        ParameterUncertainty::RankDeficient { .. } => None,
    };
    println!("anchor   guess error m   calibrated error m   sigma m (3D, from the covariance)");
    for i in 0..4 {
        let sigma = covariance
            .as_ref()
            .map_or(f64::NAN, |c| (c[i][0][0] + c[i][1][1] + c[i][2][2]).sqrt());
        println!(
            "{:>6}   {:>13.3}   {:>18.3}   {:>9.3}",
            i + 1,
            (guess.anchors_m[i] - truth.anchors_m[i]).norm(),
            (result.robot.anchors_m[i] - truth.anchors_m[i]).norm(),
            sigma
        );
    }
    println!("cable   offset error m");
    for i in 0..4 {
        println!(
            "{:>5}   {:>14.4}",
            i + 1,
            result.robot.length_offsets_m[i] - truth.length_offsets_m[i]
        );
    }

    if let Some(path) = std::env::args().nth(1) {
        let plot = AnchorPlot {
            title: format!("sagcal: calibrated anchors of `{}` (35 poses)", truth.name),
            caption: format!(
                "cargo run --example calibrate (seed {seed}): anchors 10 m and offsets 80 m off at the start"
            ),
            anchors: (0..4)
                .map(|i| AnchorPlotEntry {
                    label: format!("anchor {}", i + 1),
                    nominal_m: guess.anchors_m[i].into(),
                    initial_m: Some(guess.anchors_m[i].into()),
                    estimate_m: result.robot.anchors_m[i].into(),
                    covariance_m2: covariance.as_ref().map(|c| c[i]),
                    truth_m: Some(truth.anchors_m[i].into()),
                })
                .collect(),
            platform_positions_m: measurements.iter().map(|m| m.position_m).collect(),
        };
        write_figure(std::path::Path::new(&path), &anchor_plot_svg(&plot))?;
        println!("figure written to {path}");
    }
    Ok(())
}

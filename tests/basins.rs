//! Every trial lands in the right basin: seeded Table II trials of the
//! authors' own small robot (`robots/small-authors.toml`), whose nearly
//! vertical cables and narrow column of poses make the initialisation's
//! rigid stage ambiguous (module docs of `sagcal::calib`, "Basins").
//!
//! The trials at 10 m / 80 m off are ones the single-start initialisation
//! lost (seed 3 of `sagcal experiment table2 --robot robots/small-authors.toml
//! --data <sagcal simulate --poses 57 --seed 1 --noise none> --poses 8
//! --anchor-perturbation-m 10 --offset-perturbation-m 80`): trials 78 and 86
//! ended 40 m and 17 m from the truth (the rigid stage had put one anchor far
//! along its valley and the guess was 10 m off), 73 in a wrong basin of the
//! fit with the orientation prior that the chi-square test blamed on the
//! localiser, 26 and 54 with no start at which the poses had an equilibrium.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::calib::{CableModel, OrientationPrior};
use sagcal::experiments::table2::{pose_pool, run_trial, PoolPose, Protocol, Source};
use sagcal::model::effect_kind::EffectSet;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

/// The robot and the pool of `sagcal simulate --robot robots/small-authors.toml --poses 57 --seed 1 --noise none`.
fn small_authors() -> (Robot, Vec<PoolPose>) {
    let truth = Robot::from_file(std::path::Path::new("robots/small-authors.toml")).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 57, &mut rng).unwrap();
    let log = measure(
        &truth,
        &equilibria,
        &NoisePreset::None.sigmas(truth.platform_weight_n),
        &mut rng,
    );
    let pool = pose_pool(&truth, &log, Source::Log).unwrap();
    (truth, pool)
}

fn protocol(noise: NoisePreset, anchor_m: f64, offset_m: f64) -> Protocol {
    Protocol {
        noise,
        model: CableModel::Catenary,
        anchor_perturbation_m: anchor_m,
        offset_perturbation_m: offset_m,
        basin_radius_m: 0.3 * anchor_m,
        orientation_prior: OrientationPrior::Auto,
        estimate: EffectSet::NONE,
        apply_gross_errors: false,
    }
}

#[test]
fn seeded_trials_of_the_authors_small_robot_land_in_the_right_basin() {
    let (truth, pool) = small_authors();
    // (noise, anchor / offset perturbation, seed, trials)
    let cases: [(NoisePreset, f64, f64, u64, &[usize]); 3] = [
        (NoisePreset::Paper, 10.0, 80.0, 3, &[26, 54, 73, 78, 86]),
        (NoisePreset::Paper, 1.0, 10.0, 1, &[0, 1, 2, 3]),
        (NoisePreset::Authors, 1.0, 10.0, 1, &[0, 1, 2, 3]),
    ];
    let mut lost = Vec::new();
    for (noise, anchor_m, offset_m, seed, trials) in cases {
        let protocol = protocol(noise, anchor_m, offset_m);
        for &trial in trials {
            let r = run_trial(&truth, &pool, 8, trial, seed, &protocol);
            if !r.converged {
                lost.push(format!(
                    "{noise} noise, {anchor_m} m off, seed {seed}, trial {trial}: {}",
                    r.failure.unwrap_or_default()
                ));
            }
        }
    }
    assert!(lost.is_empty(), "trials in a wrong basin:\n{}", lost.join("\n"));
}

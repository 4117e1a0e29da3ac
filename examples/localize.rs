//! Localise the calibrated robot from its cable readings alone.
//!
//! ```text
//! cargo run --release --example localize
//! ```
//!
//! After calibration the four encoder readings (and the load cell) fix the
//! platform's pose through the statics (the paper's Sec. VI outlook): eight
//! unknowns, the pose and the reference cable's `(f_h, f_v)`, against the
//! four catenary lengths and the four attachment heights. The example reads
//! 10 simulated poses of the built-in `large` robot with the paper's noise,
//! localises each, warm-started from the previous one, and compares the
//! position with the truth and with the 1-sigma the reading noise gives.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::localize::{Localizer, Readings};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

fn main() -> sagcal::Result<()> {
    let seed = 3;
    println!("seed {seed}");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // The calibrated robot: here the built-in one, encoder offsets included.
    let mut robot = Robot::builtin("large")?;
    robot.length_offsets_m = [1.5, -0.7, 2.2, 0.4];
    let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
    let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 10, &mut rng)?;
    let measurements = measure(&robot, &equilibria, &noise, &mut rng);

    let localizer = Localizer::new(&robot, &noise)?;
    let mut previous = None;
    println!("pose   error m   1-sigma m (x, y, z)        tensions N (cables 1..4)           consistent");
    for (k, (m, truth)) in measurements.iter().zip(&equilibria).enumerate() {
        let readings = Readings {
            encoder_lengths_m: m.encoder_lengths_m,
            load_cell_n: Some(m.reference_tension_n),
            localiser_pose: None,
        };
        let found = localizer.localize(&readings, previous.as_ref())?;
        let s = found.position_sigma_m;
        let t = found.tension_magnitudes_n();
        println!(
            "{:>4} {:>9.3}   {:.3}, {:.3}, {:.3}   {:>7.1} {:>7.1} {:>7.1} {:>7.1}   {}",
            k + 1,
            (found.pose.position_m - truth.pose.position_m).norm(),
            s.x,
            s.y,
            s.z,
            t[0],
            t[1],
            t[2],
            t[3],
            found.consistent
        );
        previous = Some(found.pose);
    }
    Ok(())
}

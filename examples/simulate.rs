//! Simulate a robot's measurements and write them as a sagcal measurement file.
//!
//! ```text
//! cargo run --example simulate [-- OUT.csv]
//! ```
//!
//! Samples 20 static equilibria of the built-in `large` robot in its default
//! workspace (the platform hangs where the four catenary cables and gravity
//! balance, paper eq. 1-11), reads them with the paper's sensor noise and
//! writes the file `sagcal calibrate --data` reads (default: a file in the
//! system's temporary folder). The same seed gives the same file.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::io::measurements::{read_measurements, write_measurements, ReadOptions};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

fn main() -> sagcal::Result<()> {
    let seed = 7;
    let robot = Robot::builtin("large")?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 20, &mut rng)?;
    let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
    let measurements = measure(&robot, &equilibria, &noise, &mut rng);

    let out = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("sagcal-example-simulate.csv"));
    let comment = format!(
        "simulated by examples/simulate.rs: robot `{}`, seed {seed}, paper noise",
        robot.name
    );
    write_measurements(&out, &[comment], &measurements)?;
    println!("seed {seed}: {} poses written to {}", measurements.len(), out.display());

    // The equilibria: where the platform hangs and what the reference cable pulls.
    println!("pose      x m      y m      z m   reference tension N");
    for (k, e) in equilibria.iter().enumerate().take(5) {
        let p = e.pose.position_m;
        let t = e.tensions[robot.reference_cable];
        println!(
            "{:>4} {:>8.2} {:>8.2} {:>8.2} {:>21.1}",
            k + 1,
            p.x,
            p.y,
            p.z,
            t.magnitude_n()
        );
    }
    // Written with full precision: reading back gives the same numbers.
    let back = read_measurements(&out, &ReadOptions::default())?;
    assert_eq!(back.poses[0].encoder_lengths_m, measurements[0].encoder_lengths_m);
    Ok(())
}

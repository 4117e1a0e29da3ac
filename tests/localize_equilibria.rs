//! The multistart search for every equilibrium of a row
//! (`Localizer::equilibria`): it finds the simulated equilibrium, every
//! solution it returns satisfies the equations, and the stable one chosen by
//! `localize` is among them.

use std::path::Path;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::localize::{model_at_pose, tilt_deg, Localizer, Readings};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::statics::Equilibrium;
use sagcal::model::{Robot, CABLE_COUNT};
use sagcal::sim::closed_form::{sample_equilibria, Workspace};

fn robot(name: &str) -> Robot {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("robots/{name}.toml"));
    let mut robot = Robot::from_file(&path).unwrap();
    robot.length_offsets_m = [0.5, -0.25, 1.0, 0.0];
    robot
}

fn equilibria(robot: &Robot, count: usize, seed: u64) -> Vec<Equilibrium> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    sample_equilibria(robot, &Workspace::default_for(robot), count, &mut rng).unwrap()
}

#[test]
fn the_multistart_finds_the_simulated_equilibrium_and_only_solutions() {
    for name in ["large", "small"] {
        let robot = robot(name);
        let localizer = Localizer::new(&robot, &NoisePreset::Paper.sigmas(robot.platform_weight_n)).unwrap();
        for eq in equilibria(&robot, 4, 5) {
            let readings = Readings {
                encoder_lengths_m: std::array::from_fn(|i| eq.cable_lengths_m[i] + robot.length_offsets_m[i]),
                load_cell_n: None,
                localiser_pose: None,
            };
            let all = localizer.equilibria(&readings, None).unwrap();
            let summary: Vec<String> = all
                .iter()
                .map(|l| {
                    format!(
                        "[{:.3} {:.3} {:.3}] tilt {:.1} deg stable {}",
                        l.pose.position_m.x,
                        l.pose.position_m.y,
                        l.pose.position_m.z,
                        tilt_deg(&l.pose),
                        l.stable
                    )
                })
                .collect();
            eprintln!("{name}: {} equilibria: {summary:#?}", all.len());
            let truth = all
                .iter()
                .find(|l| (l.pose.position_m - eq.pose.position_m).norm() < 1e-8)
                .unwrap_or_else(|| panic!("{name}: the simulated equilibrium is not among {summary:#?}"));
            assert!(truth.stable, "{name}: the simulated equilibrium must be stable");
            for l in &all {
                let t = l.tensions[robot.reference_cable];
                let model = model_at_pose(
                    localizer.slots(),
                    &l.pose,
                    &nalgebra::Vector2::new(t.horizontal_n, t.vertical_n),
                )
                .unwrap();
                let encoders = localizer.slots().to_slots(&readings.encoder_lengths_m);
                assert!((model.encoders_m - encoders).amax() < 1e-8, "{name}: not a solution");
                assert!(model.heights_m.amax() < 1e-8, "{name}: heights off");
            }
            let chosen = localizer.localize(&readings, None).unwrap();
            assert!(all
                .iter()
                .any(|l| (l.pose.position_m - chosen.pose.position_m).norm() < 1e-8));
            let _ = CABLE_COUNT;
        }
    }
}

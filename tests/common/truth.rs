//! A truth off a nominal robot, shared by the diagnosis tests: every anchor
//! coordinate moved within +-0.3 m and every encoder offset drawn within
//! +-3 m (the nominal robot file is only a guess), then `poses` static poses
//! of that truth, all from one seeded random stream that the caller goes on
//! drawing its noise from.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sagcal::model::statics::Equilibrium;
use sagcal::model::{Robot, CABLE_COUNT};
use sagcal::sim::closed_form::{sample_equilibria, Workspace};

/// The nominal built-in robot `name`, a truth drawn off it (then changed by
/// `change`), `poses` equilibria of the truth, and the random stream after them.
pub fn truth_off_nominal(
    name: &str,
    seed: u64,
    poses: usize,
    change: impl Fn(&mut Robot),
) -> (Robot, Robot, Vec<Equilibrium>, ChaCha8Rng) {
    let nominal = Robot::builtin(name).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut truth = nominal.clone();
    for i in 0..CABLE_COUNT {
        truth.anchors_m[i] += Vector3::from_fn(|_, _| rng.random_range(-0.3..0.3));
        truth.length_offsets_m[i] = rng.random_range(-3.0..3.0);
    }
    change(&mut truth);
    let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), poses, &mut rng).unwrap();
    (nominal, truth, equilibria, rng)
}

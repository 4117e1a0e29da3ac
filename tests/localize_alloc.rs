//! The localiser's hot path allocates nothing: a warm start that converges
//! to a stable equilibrium (`sagcal::localize`, issue 16). Counted by a
//! global allocator, per thread (this binary holds this one test only).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::localize::{Localizer, Readings};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{sample_equilibria, Workspace};

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

struct Counting;

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn a_warm_start_allocates_nothing() {
    let robot = Robot::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/large.toml")).unwrap();
    let localizer = Localizer::new(&robot, &NoisePreset::Paper.sigmas(robot.platform_weight_n)).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let eqs = sample_equilibria(&robot, &Workspace::default_for(&robot), 5, &mut rng).unwrap();
    for eq in &eqs {
        let readings = Readings {
            encoder_lengths_m: eq.cable_lengths_m,
            load_cell_n: Some(eq.tensions[robot.reference_cable].magnitude_n()),
            localiser_pose: None,
        };
        let start = eq
            .pose
            .retract(&nalgebra::Vector6::new(0.001, 0.0, -0.002, 0.02, -0.01, 0.03));
        let before = ALLOCATIONS.with(Cell::get);
        let found = localizer.localize(&readings, Some(&start)).unwrap();
        let allocations = ALLOCATIONS.with(Cell::get) - before;
        assert!(found.stable && (found.pose.position_m - eq.pose.position_m).norm() < 1e-9);
        assert_eq!(
            allocations, 0,
            "{allocations} allocations in a warm-started localisation"
        );
    }
}

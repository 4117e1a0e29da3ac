//! The yaw closure of the static equilibria (issue 14, point 6): the member of
//! the one-parameter family at a position with a given yaw, and the sampler
//! that takes some or all poses with it instead of the most level member.

use nalgebra::{SVector, Vector3};
use rand::{Rng, RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sagcal::error::Error;
use sagcal::model::statics::{self, Equilibrium, StaticsOptions};
use sagcal::model::Robot;
use sagcal::sim::closed_form::{sample_equilibria, sample_equilibria_with, Closure, Workspace};

/// Check `eq` against the model's own equations: the attachment heights
/// (eq. 15), the force and moment balance (eq. 8) and positive tensions.
fn assert_static_equilibrium(robot: &Robot, eq: &Equilibrium) {
    let heights = statics::attachment_height_residuals(robot, &eq.pose, &eq.tensions);
    let worst = heights.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    assert!(worst < 1e-9, "attachment height residuals {heights:?}");
    let forces = SVector::<f64, 8>::from_fn(|k, _| {
        let t = eq.tensions[k / 2];
        if k % 2 == 0 {
            t.horizontal_n
        } else {
            t.vertical_n
        }
    });
    let wrench = statics::structure_matrix(robot, &eq.pose) * forces - statics::gravity_wrench(robot, &eq.pose);
    assert!(
        wrench.norm() < 1e-9 * robot.platform_weight_n,
        "unbalanced wrench {wrench}"
    );
    for (i, t) in eq.tensions.iter().enumerate() {
        assert!(t.horizontal_n > 0.0, "cable {} pushes: {t:?}", i + 1);
    }
}

#[test]
fn the_yaw_closure_reaches_its_yaw_and_is_a_static_equilibrium() {
    let options = StaticsOptions::default();
    for (name, position, yaw_deg) in [
        ("large", Vector3::new(13.6, 6.0, 10.6), 0.8),
        ("large", Vector3::new(-20.5, -19.7, 19.9), -1.2),
        ("small", Vector3::new(0.9, 0.2, 8.4), -9.0),
        ("small", Vector3::new(-1.4, -0.5, 13.6), 5.5),
    ] {
        let robot = Robot::builtin(name).unwrap();
        let target = f64::to_radians(yaw_deg);
        let eq = statics::solve_with_yaw(&robot, position, target, &options).unwrap();
        let level = statics::solve_level(&robot, position, &options).unwrap();
        println!(
            "{name} at {:?}: yaw {:.12} deg (level member {:.3} deg), rotation {:.3} deg, reference tension {:.3} N",
            position.as_slice(),
            eq.pose.yaw_rad().to_degrees(),
            level.pose.yaw_rad().to_degrees(),
            eq.pose.rotation.angle().to_degrees(),
            eq.tensions[robot.reference_cable].magnitude_n()
        );
        assert!(
            (eq.pose.yaw_rad() - target).abs() < 1e-9,
            "{name}: yaw {} rad, target {target} rad",
            eq.pose.yaw_rad()
        );
        assert_eq!(eq.pose.position_m, position);
        assert_static_equilibrium(&robot, &eq);
        // The same member, closed by its load-cell reading instead: the family is one curve.
        let magnitude = eq.tensions[robot.reference_cable].magnitude_n();
        let again =
            statics::solve_with_reference_tension(&robot, position, magnitude, Some(eq.pose.rotation), &options)
                .unwrap();
        assert!(again.pose.angle_to_deg(&eq.pose) < 1e-6);
        // Not the level member: the closure chose another point of the family.
        assert!((level.pose.yaw_rad() - target).abs() > f64::to_radians(0.2));
    }
}

#[test]
fn an_unreachable_yaw_is_an_error_naming_the_range() {
    let options = StaticsOptions::default();
    let robot = Robot::builtin("large").unwrap();
    let position = Vector3::new(13.6, 6.0, 10.6);
    for yaw_deg in [30.0, -5.0, 179.0] {
        match statics::solve_with_yaw(&robot, position, f64::to_radians(yaw_deg), &options) {
            Err(Error::NoEquilibrium(message)) => {
                println!("{message}");
                assert!(message.contains("spans yaw"), "{message}");
                assert!(message.contains(&format!("{yaw_deg:.3} deg")), "{message}");
            }
            other => panic!("yaw {yaw_deg} deg: expected NoEquilibrium, got {other:?}"),
        }
    }
    assert!(matches!(
        statics::solve_with_yaw(&robot, position, f64::NAN, &options),
        Err(Error::InvalidInput(_))
    ));
}

/// The sampler as it was before the closures, written out here so that the
/// level closure is checked against it and not against itself.
fn sample_level_as_before(robot: &Robot, workspace: &Workspace, count: usize, rng: &mut impl Rng) -> Vec<Equilibrium> {
    let options = StaticsOptions::default();
    let mut poses = Vec::new();
    while poses.len() < count {
        let position = Vector3::from_fn(|i, _| rng.random_range(workspace.min_m[i]..=workspace.max_m[i]));
        let Ok(level) = statics::solve_level(robot, position, &options) else {
            continue;
        };
        let magnitude = level.tensions[robot.reference_cable].magnitude_n() * rng.random_range(0.98..=1.02);
        if let Ok(eq) =
            statics::solve_with_reference_tension(robot, position, magnitude, Some(level.pose.rotation), &options)
        {
            poses.push(eq);
        }
    }
    poses
}

#[test]
fn the_level_closure_samples_exactly_as_before() {
    for name in ["large", "small"] {
        let robot = Robot::builtin(name).unwrap();
        let workspace = Workspace::default_for(&robot);
        let mut before_rng = ChaCha8Rng::seed_from_u64(11);
        let mut plain_rng = ChaCha8Rng::seed_from_u64(11);
        let mut level_rng = ChaCha8Rng::seed_from_u64(11);
        let before = sample_level_as_before(&robot, &workspace, 8, &mut before_rng);
        let plain = sample_equilibria(&robot, &workspace, 8, &mut plain_rng).unwrap();
        let level = sample_equilibria_with(&robot, &workspace, 8, Closure::Level, &mut level_rng).unwrap();
        // `Equilibrium: PartialEq` compares every f64 exactly: bit-identical poses and tensions.
        assert_eq!(before, plain, "{name}");
        assert_eq!(before, level, "{name}");
        // ... and the same random numbers consumed.
        let next = before_rng.next_u64();
        assert_eq!(next, plain_rng.next_u64());
        assert_eq!(next, level_rng.next_u64());
    }
}

#[test]
fn yaw_and_mixed_closures_leave_the_level_member() {
    let options = StaticsOptions::default();
    let robot = Robot::builtin("large").unwrap();
    let workspace = Workspace::default_for(&robot);
    let max_yaw_deg = 1.0;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let yaw = sample_equilibria_with(&robot, &workspace, 6, Closure::Yaw { max_yaw_deg }, &mut rng).unwrap();
    for eq in &yaw {
        assert!(eq.pose.yaw_rad().abs() <= f64::to_radians(max_yaw_deg) + 1e-9);
        assert_static_equilibrium(&robot, eq);
    }
    let closure = Closure::parse("mixed").unwrap();
    assert_eq!(
        closure,
        Closure::Mixed {
            yaw_fraction: 0.5,
            max_yaw_deg
        }
    );
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mixed = sample_equilibria_with(&robot, &workspace, 16, closure, &mut rng).unwrap();
    let offsets_deg: Vec<f64> = mixed
        .iter()
        .map(|eq| {
            assert_static_equilibrium(&robot, eq);
            let level = statics::solve_level(&robot, eq.pose.position_m, &options).unwrap();
            (eq.pose.yaw_rad() - level.pose.yaw_rad()).to_degrees().abs()
        })
        .collect();
    println!("mixed sample, |yaw - level member's yaw| deg: {offsets_deg:.3?}");
    let far = offsets_deg.iter().filter(|d| **d > 1.0).count();
    // Level poses stay within the 2 % tension jitter of their level member.
    let near = offsets_deg.iter().filter(|d| **d < 0.1).count();
    assert!(
        far >= 2,
        "{far} of 16 poses more than 1 degree of yaw off the level member"
    );
    assert!(near >= 2, "{near} of 16 poses within 0.1 degree of the level member");
}

#[test]
fn closures_parse_and_reject_bad_settings() {
    assert_eq!(Closure::parse("level").unwrap(), Closure::Level);
    assert!(matches!(Closure::parse("yaw").unwrap(), Closure::Yaw { .. }));
    assert!(Closure::parse("tilt")
        .unwrap_err()
        .to_string()
        .contains("level, yaw or mixed"));
    let robot = Robot::builtin("small").unwrap();
    let workspace = Workspace::default_for(&robot);
    let bad = Closure::Mixed {
        yaw_fraction: 1.5,
        max_yaw_deg: 1.0,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    assert!(matches!(
        sample_equilibria_with(&robot, &workspace, 2, bad, &mut rng),
        Err(Error::InvalidInput(_))
    ));
    // A zero bound is the family's zero-yaw member.
    let zero = Closure::Yaw { max_yaw_deg: 0.0 };
    let poses = sample_equilibria_with(&robot, &workspace, 2, zero, &mut rng).unwrap();
    assert!(poses.iter().all(|eq| eq.pose.yaw_rad().abs() < 1e-9));
}

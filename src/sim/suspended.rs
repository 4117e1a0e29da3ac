//! Simulated measurements of a robot of `N` cables from the closed-form
//! catenary model ([`sample_suspended`], [`measure_suspended`]).
//!
//! Positions are drawn uniformly in the workspace; at each, the equilibrium
//! that the closure picks ([`crate::model::suspended::solve_at`]): the most
//! level member ([`Closure::Level`]), or the member at a yaw drawn
//! uniformly in `+-max_yaw_deg` ([`Closure::Yaw`]; four cables or more),
//! or either per pose ([`Closure::Mixed`]). A position without an
//! equilibrium with every cable taut, whose equilibrium has a cable that
//! sags below the platform before it rises to its anchor, or whose
//! equilibrium is unstable (a negative stiffness at fixed cable lengths,
//! which no robot can hold), is redrawn. The sensors read as on four cables ([`SensorSampler`]): the
//! localiser's pose perturbed on its tangent space, each encoder its
//! cable's catenary length plus the cable's offset plus noise, each load
//! cell its cable's tension at the attachment plus noise.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::suspended::SuspendedRobot;
//! use sagcal::sim::closed_form::Closure;
//! use sagcal::sim::suspended::{measure_suspended, sample_suspended};
//! let robot = SuspendedRobot::builtin("six")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
//! let workspace = robot.workspace.unwrap();
//! let poses = sample_suspended(&robot, &workspace, 3, Closure::Level, &mut rng)?;
//! let noise = NoisePreset::None.sigmas(robot.platform_weight_n);
//! let rows = measure_suspended(&robot, &poses, &noise, &mut rng)?;
//! // Without noise an encoder reads its catenary's length (and a zero offset).
//! assert_eq!(rows[0].encoder_lengths_m, poses[0].cable_lengths_m);
//! assert_eq!(rows[0].load_cell_tensions_n[0], poses[0].tensions[0].magnitude_n());
//! # Ok::<(), sagcal::Error>(())
//! ```

use rand::Rng;

use super::closed_form::{draw_poses, Closure, SensorSampler, Workspace, FIRST_DRAWS};
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;
use crate::model::sensors::SensorNoise;
use crate::model::suspended::{
    check_suspended, smallest_stiffness, solve_at, stiffness, Closure as Member, EquilibriumOptions,
    SuspendedEquilibrium, SuspendedMeasurement, SuspendedRobot,
};

/// Draw `count` stable equilibria of `robot` in `workspace`, each closed by
/// `closure` (module docs); an error after [`FIRST_DRAWS`] draws without any
/// equilibrium, or `100 count + 1000` in all, says how many failed.
pub fn sample_suspended<R: Rng>(
    robot: &SuspendedRobot,
    workspace: &Workspace,
    count: usize,
    closure: Closure,
    rng: &mut R,
) -> Result<Vec<SuspendedEquilibrium>> {
    closure.validate()?;
    if robot.cable_count() < 4 && closure != Closure::Level {
        return Err(Error::InvalidInput(format!(
            "robot `{}`: the {closure} closure holds a yaw, but three cables fix the platform's orientation at each \
             position: use the level closure",
            robot.name
        )));
    }
    let boxed = SuspendedRobot {
        workspace: Some(*workspace),
        ..robot.clone()
    };
    check_suspended(&boxed).map_err(|e| Error::InvalidInput(format!("robot `{}`: {e}", robot.name)))?;
    let options = EquilibriumOptions::default();
    let failure = "no stable equilibrium with every cable taut and rising from the platform";
    let admissible = |eq: &SuspendedEquilibrium| rises(eq) && is_stable(robot, eq);
    let draw = |position, max_yaw_deg: Option<f64>, rng: &mut R| {
        let member = match max_yaw_deg {
            None => Member::Level,
            Some(max) => Member::Yaw {
                yaw_rad: rng.random_range(-max..=max).to_radians(),
            },
        };
        solve_at(robot, position, member, &options).ok().filter(admissible)
    };
    draw_poses(&robot.name, workspace, count, closure, FIRST_DRAWS, failure, rng, draw).map(|(poses, _)| poses)
}

/// Every cable rises from its attachment (a positive vertical tension
/// there): a cable that first sags below the platform and climbs back is an
/// equilibrium too, but one hundreds of metres longer than its span where
/// its horizontal tension nears zero, which no winch is commanded to pay
/// out.
fn rises(eq: &SuspendedEquilibrium) -> bool {
    eq.tensions.iter().all(|t| t.vertical_n > 0.0)
}

/// Stable: the stiffness at fixed cable lengths positive definite (where
/// the cables weigh nothing, their lengths do not fix the forces and the
/// test does not apply).
fn is_stable(robot: &SuspendedRobot, eq: &SuspendedEquilibrium) -> bool {
    stiffness(robot, eq).is_none_or(|k| smallest_stiffness(&k) > 0.0)
}

/// What the robot's sensors read at these equilibria (module docs), in the
/// order of the draws: per pose the localiser, the encoders in cable order,
/// then the load cells in the robot's order. The closed-form model's cables
/// are inextensible: a robot with elastic cables (a finite
/// `axial_stiffness_n`) is refused, its readings are the discretised
/// simulator's ([`super::suspended_effects::simulate_readings`]).
pub fn measure_suspended(
    robot: &SuspendedRobot,
    equilibria: &[SuspendedEquilibrium],
    noise: &SensorNoise,
    rng: &mut impl Rng,
) -> Result<Vec<SuspendedMeasurement>> {
    if robot.is_elastic() {
        return Err(Error::InvalidInput(format!(
            "robot `{}` has elastic cables: the closed-form model's are inextensible; \
             simulate it with the discretised simulator (sim::suspended_effects::simulate_readings)",
            robot.name
        )));
    }
    let sensors = SensorSampler::new(noise);
    Ok(equilibria
        .iter()
        .map(|eq| {
            let lengths = eq
                .cable_lengths_m
                .iter()
                .zip(&robot.length_offsets_m)
                .map(|(l, o)| l + o);
            let tensions = robot.load_cells.iter().map(|&cable| eq.tensions[cable].magnitude_n());
            read_suspended_row(&sensors, &eq.pose, lengths, tensions, rng)
        })
        .collect())
}

/// One row of readings with their noise drawn in the file's order: the
/// localiser at `pose`, each encoder's noise-free reading of `encoders_m`
/// in cable order, then each load cell's of `load_cells_n` in the robot's order.
pub(crate) fn read_suspended_row(
    sensors: &SensorSampler,
    pose: &PlatformPose,
    encoders_m: impl Iterator<Item = f64>,
    load_cells_n: impl Iterator<Item = f64>,
    rng: &mut impl Rng,
) -> SuspendedMeasurement {
    let pose = sensors.localiser(pose, rng);
    let (roll_deg, pitch_deg, yaw_deg) = pose.roll_pitch_yaw_deg();
    let encoder_lengths_m = encoders_m.map(|length| sensors.encoder(length, rng)).collect();
    let load_cell_tensions_n = load_cells_n.map(|tension| sensors.load_cell(tension, rng)).collect();
    SuspendedMeasurement {
        line: 0,
        position_m: pose.position_m.into(),
        roll_deg,
        pitch_deg,
        yaw_deg,
        encoder_lengths_m,
        load_cell_tensions_n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Every drawn pose lies in the box, hangs in equilibrium (the six
    /// equations, each cable's end at its attachment) and is stable, for
    /// three, six and eight cables and each closure they take.
    #[test]
    fn drawn_poses_are_stable_equilibria_in_the_box() {
        for (name, closure) in [
            ("three", Closure::Level),
            ("six", Closure::Level),
            ("eight", Closure::Level),
            ("eight", Closure::parse("yaw").unwrap()),
        ] {
            let robot = SuspendedRobot::builtin(name).unwrap();
            let workspace = robot.workspace.unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            let poses = sample_suspended(&robot, &workspace, 6, closure, &mut rng).unwrap();
            for eq in &poses {
                let p = eq.pose.position_m;
                assert!((0..3).all(|i| workspace.min_m[i] <= p[i] && p[i] <= workspace.max_m[i]));
                let wrench = robot.wrench_residual(&eq.pose, &eq.tensions);
                assert!(wrench.amax() < 1e-8 * robot.platform_weight_n, "{name}: {wrench}");
                assert!(robot
                    .height_residuals(&eq.pose, &eq.tensions)
                    .iter()
                    .all(|h| h.abs() < 1e-9));
                assert!(is_stable(&robot, eq) && rises(eq));
                for (length, span) in eq
                    .cable_lengths_m
                    .iter()
                    .zip(robot.anchors_m.iter().map(|a| (a - p).norm()))
                {
                    assert!(*length < 1.1 * span, "{name}: a {length} m cable over {span} m");
                }
            }
        }
    }

    /// Noise-free readings with length offsets are what the calibration's
    /// per-cable factors expect at the truth: with the localiser's pose and
    /// the equilibrium's forces, every cable's length and height residual
    /// (`generated::suspended_cable_residual`) vanishes, and each load cell
    /// reads its cable's tension.
    #[test]
    fn noise_free_readings_satisfy_the_per_cable_factors_at_the_truth() {
        use nalgebra::Vector2;
        let mut robot = SuspendedRobot::builtin("six").unwrap();
        robot.length_offsets_m = vec![0.5, -1.25, 2.0, 0.0, -0.75, 3.5];
        robot.load_cells = vec![1, 4];
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let poses = sample_suspended(&robot, &robot.workspace.unwrap(), 5, Closure::Level, &mut rng).unwrap();
        let none = crate::model::sensors::NoisePreset::None.sigmas(robot.platform_weight_n);
        let rows = measure_suspended(&robot, &poses, &none, &mut rng).unwrap();
        for (row, eq) in rows.iter().zip(&poses) {
            let pose = crate::model::pose::PlatformPose::from_roll_pitch_yaw_deg(
                row.position_m.into(),
                row.roll_deg,
                row.pitch_deg,
                row.yaw_deg,
            );
            for i in 0..6 {
                let residual = crate::generated::suspended_cable_residual(
                    &pose.position_m,
                    &pose.rotation_xyzw(),
                    &Vector2::new(eq.tensions[i].horizontal_n, eq.tensions[i].vertical_n),
                    &robot.anchors_m[i],
                    &robot.attachments_m[i],
                    robot.cable_weights_n_per_m[i],
                    robot.length_offsets_m[i],
                    row.encoder_lengths_m[i],
                    1e-15,
                    None,
                    None,
                    None,
                    None,
                );
                assert!(residual.amax() < 1e-9, "cable {i}: {residual}");
            }
            for (reading, &cable) in row.load_cell_tensions_n.iter().zip(&robot.load_cells) {
                assert_eq!(*reading, eq.tensions[cable].magnitude_n());
            }
        }
    }

    /// Three cables refuse a held yaw; an empty box far from the anchors is refused.
    #[test]
    fn impossible_requests_are_refused() {
        let three = SuspendedRobot::builtin("three").unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let yaw = sample_suspended(
            &three,
            &three.workspace.unwrap(),
            2,
            Closure::parse("yaw").unwrap(),
            &mut rng,
        );
        assert!(
            matches!(&yaw, Err(Error::InvalidInput(m)) if m.contains("three cables")),
            "{yaw:?}"
        );
        let far = Workspace {
            min_m: [100.0, 100.0, 1.0],
            max_m: [101.0, 101.0, 2.0],
        };
        let outside = sample_suspended(&three, &far, 2, Closure::Level, &mut rng);
        assert!(
            matches!(&outside, Err(Error::InvalidInput(m)) if m.contains("footprint")),
            "{outside:?}"
        );
    }
}

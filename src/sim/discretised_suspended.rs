//! The discretised simulator of [`super::discretised`] for robots of 3 to 8
//! cables: every cable a lumped elastic chain over its own swivelling
//! pulley, each with its own weight per metre, axial stiffness `EA` and
//! pulley radius.
//!
//! The equations are the four-cable simulator's, written once for any
//! number of cables `N` (its `Problem`): per cable the chain's closure at
//! its pulley's exit point (3) and its paid-out length (1), and the
//! platform's force and moment balance (6), in the pose (6), each cable's
//! force on the platform (3) and its free length (1): `6 + 4 N` equations
//! in as many unknowns, solved by the same damped Newton with its
//! Levenberg-Marquardt fallback and Newton homotopy. With four cables the
//! code is the four-cable simulator's and so are its results, to the bit.
//!
//! Like the four-cable simulator it shares no formula with the closed-form
//! catenary model ([`crate::model::suspended`]): comparing them checks both,
//! and the chain converges to the catenary as `O(1/n^2)` in its segment
//! count `n` (the midpoint rule).
//!
//! ```
//! use sagcal::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedRobot};
//! use sagcal::sim::discretised_suspended::{closed_form_forces, solve_forward_suspended, SuspendedDiscretisedOptions};
//! let robot = SuspendedRobot::builtin("six")?;
//! let centre = robot.workspace.unwrap().centre();
//! let eq = solve_at(&robot, centre, Closure::Level, &EquilibriumOptions::default())?;
//! // The catenary's lengths paid out on 100-element chains: the platform settles within a millimetre.
//! let options = SuspendedDiscretisedOptions::inextensible(robot.cable_count(), 100);
//! let guess = closed_form_forces(&robot, &eq);
//! let chain = solve_forward_suspended(&robot, &options, &eq.cable_lengths_m, &eq.pose, Some(&guess))?;
//! assert!((chain.pose.position_m - eq.pose.position_m).norm() < 1e-3);
//! assert!(chain.max_residual_n < 1e-6 * robot.platform_weight_n);
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::f64::consts::PI;

use nalgebra::{Const, DimMin, Vector3};

use super::discretised::{
    assemble_cables, check_lengths, newton_from_starts, residual_of, unknowns, CableSpec, DiscretisedCable,
    EquilibriumResidual, Problem, MAX_SEGMENTS,
};
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;
use crate::model::suspended::{SuspendedEquilibrium, SuspendedRobot};

/// Settings of the discretised model of a robot of `N` cables, one entry
/// per cable in the robot's order where a setting is per cable.
#[derive(Debug, Clone, PartialEq)]
pub struct SuspendedDiscretisedOptions {
    /// Straight segments per cable, `n >= 1`.
    pub segments: usize,
    /// Each cable's axial stiffness `EA`, newtons; `f64::INFINITY`: inextensible.
    pub axial_stiffness_n: Vec<f64>,
    /// Each cable's pulley radius `r`, metres (0: the cable leaves at its anchor point).
    pub pulley_radius_m: Vec<f64>,
    /// Centre of mass in the platform frame replacing the robot's, metres.
    pub com_offset_m: Option<Vector3<f64>>,
    /// Newton iterations per attempt.
    pub max_iterations: usize,
}

impl SuspendedDiscretisedOptions {
    /// `cables` inextensible chains of `segments` segments over point
    /// pulleys, the robot's centre of mass, 100 Newton iterations.
    pub fn inextensible(cables: usize, segments: usize) -> Self {
        Self {
            segments,
            axial_stiffness_n: vec![f64::INFINITY; cables],
            pulley_radius_m: vec![0.0; cables],
            com_offset_m: None,
            max_iterations: 100,
        }
    }

    /// Every setting valid for `robot`, or a message naming the first that is not.
    fn check(&self, robot: &SuspendedRobot) -> Result<()> {
        let cables = robot.cable_count();
        let invalid = |message: String| {
            Err(Error::InvalidInput(format!(
                "discretised robot `{}`: {message}",
                robot.name
            )))
        };
        if !(1..=MAX_SEGMENTS).contains(&self.segments) {
            return invalid(format!(
                "segments must be between 1 and {MAX_SEGMENTS}, got {}",
                self.segments
            ));
        }
        if self.axial_stiffness_n.len() != cables || self.pulley_radius_m.len() != cables {
            return invalid(format!(
                "{} axial stiffnesses and {} pulley radii for {cables} cables",
                self.axial_stiffness_n.len(),
                self.pulley_radius_m.len()
            ));
        }
        if let Some((i, ea)) = self
            .axial_stiffness_n
            .iter()
            .enumerate()
            .find(|(_, ea)| ea.is_nan() || **ea <= 0.0)
        {
            return invalid(format!(
                "cable {}: axial stiffness EA must be > 0 N (infinite: inextensible), got {ea}",
                i + 1
            ));
        }
        if let Some((i, r)) = self
            .pulley_radius_m
            .iter()
            .enumerate()
            .find(|(_, r)| !(r.is_finite() && **r >= 0.0))
        {
            return invalid(format!("cable {}: pulley radius must be >= 0 m, got {r}", i + 1));
        }
        if self.com_offset_m.is_some_and(|c| !c.iter().all(|x| x.is_finite())) {
            return invalid("the centre of mass override is not finite".into());
        }
        Ok(())
    }
}

/// A static equilibrium of the discretised robot of `N` cables.
#[derive(Debug, Clone, PartialEq)]
pub struct SuspendedDiscretisedEquilibrium {
    /// Platform pose.
    pub pose: PlatformPose,
    /// The cables' chains, in cable order.
    pub cables: Vec<DiscretisedCable>,
    /// The paid-out (unstretched) lengths that were solved for, metres.
    pub paid_out_lengths_m: Vec<f64>,
    /// Newton iterations used (all attempts).
    pub iterations: usize,
    /// Worst force (N) or moment (N m) residual of the independent check at the solution.
    pub max_residual_n: f64,
    /// The independent check at the solution, every residual.
    pub residual: EquilibriumResidual,
}

/// The force each cable of a closed-form equilibrium exerts on the platform
/// (world frame, newtons): `f_h` horizontally towards its anchor, `f_v` up;
/// a start for [`solve_forward_suspended`].
pub fn closed_form_forces(robot: &SuspendedRobot, equilibrium: &SuspendedEquilibrium) -> Vec<Vector3<f64>> {
    let rotation = equilibrium.pose.rotation_matrix();
    robot
        .anchors_m
        .iter()
        .zip(&robot.attachments_m)
        .zip(&equilibrium.tensions)
        .map(|((anchor, attachment), tension)| {
            let towards = anchor - (equilibrium.pose.position_m + rotation * attachment);
            let horizontal = Vector3::new(towards.x, towards.y, 0.0);
            let direction = horizontal.try_normalize(0.0).unwrap_or_else(Vector3::x);
            direction * tension.horizontal_n + Vector3::z() * tension.vertical_n
        })
        .collect()
}

/// Forward statics of the discretised robot of `N` cables: the paid-out
/// (unstretched) lengths -> the static equilibrium near `guess_pose`,
/// starting from `guess_forces_n` (each cable's force on the platform, as
/// [`closed_form_forces`] gives) if given, then from each cable solved
/// alone, then from straight cables, as [`super::discretised::solve_forward`]
/// does. Fails with [`Error::NoEquilibrium`] if none converges and with
/// [`Error::InvalidInput`] on bad input; never panics or returns NaN.
pub fn solve_forward_suspended(
    robot: &SuspendedRobot,
    options: &SuspendedDiscretisedOptions,
    paid_out_lengths_m: &[f64],
    guess_pose: &PlatformPose,
    guess_forces_n: Option<&[Vector3<f64>]>,
) -> Result<SuspendedDiscretisedEquilibrium> {
    options.check(robot)?;
    let cables = robot.cable_count();
    if paid_out_lengths_m.len() != cables || guess_forces_n.is_some_and(|f| f.len() != cables) {
        return Err(Error::InvalidInput(format!(
            "discretised robot `{}`: {} paid-out lengths (and a guess of {} forces) for {cables} cables",
            robot.name,
            paid_out_lengths_m.len(),
            guess_forces_n.map_or(cables, <[_]>::len)
        )));
    }
    check_lengths(paid_out_lengths_m)?;
    let finite_guess = guess_pose
        .position_m
        .iter()
        .chain(guess_pose.rotation.coords.iter())
        .all(|x| x.is_finite())
        && guess_forces_n.is_none_or(|f| f.iter().all(|v| v.iter().all(|x| x.is_finite())));
    if !finite_guess {
        return Err(Error::InvalidInput(format!(
            "discretised robot `{}`: the initial pose or forces are not finite",
            robot.name
        )));
    }
    let inputs = Inputs {
        robot,
        options,
        paid_out: paid_out_lengths_m,
        guess_pose,
        guess_forces: guess_forces_n,
    };
    match cables {
        3 => solve::<3, { unknowns(3) }>(&inputs),
        4 => solve::<4, { unknowns(4) }>(&inputs),
        5 => solve::<5, { unknowns(5) }>(&inputs),
        6 => solve::<6, { unknowns(6) }>(&inputs),
        7 => solve::<7, { unknowns(7) }>(&inputs),
        8 => solve::<8, { unknowns(8) }>(&inputs),
        n => Err(Error::InvalidInput(format!(
            "discretised robot `{}`: {n} cables; the simulator takes 3 to 8",
            robot.name
        ))),
    }
}

/// The checked inputs of one forward solve.
struct Inputs<'a> {
    robot: &'a SuspendedRobot,
    options: &'a SuspendedDiscretisedOptions,
    paid_out: &'a [f64],
    guess_pose: &'a PlatformPose,
    guess_forces: Option<&'a [Vector3<f64>]>,
}

/// [`solve_forward_suspended`] for `C` cables and `U = 6 + 4 C` unknowns.
fn solve<const C: usize, const U: usize>(inputs: &Inputs) -> Result<SuspendedDiscretisedEquilibrium>
where
    Const<U>: DimMin<Const<U>, Output = Const<U>>,
{
    let (robot, options) = (inputs.robot, inputs.options);
    let specs: [CableSpec; C] = std::array::from_fn(|i| CableSpec {
        anchor: robot.anchors_m[i],
        radius: options.pulley_radius_m[i],
        paid_out: inputs.paid_out[i],
        weight_per_m: robot.cable_weights_n_per_m[i],
        segments: options.segments,
        compliance: 1.0 / options.axial_stiffness_n[i],
    });
    let attachments = std::array::from_fn(|i| robot.attachments_m[i]);
    let com = options.com_offset_m.unwrap_or(robot.com_offset_m);
    let problem = Problem::<C, U>::new(specs, attachments, com, robot.platform_weight_n);
    // Free lengths start at the paid-out length minus a quarter turn of wrap.
    let lengths = std::array::from_fn(|i| {
        let wrapped = 0.5 * PI * specs[i].radius;
        if specs[i].paid_out > 2.0 * wrapped {
            specs[i].paid_out - wrapped
        } else {
            specs[i].paid_out
        }
    });
    let forces = inputs.guess_forces.map(|f| std::array::from_fn(|i| f[i]));
    let (solution, iterations) =
        newton_from_starts(&problem, options.max_iterations, inputs.guess_pose, forces, lengths);
    let state = solution.ok_or_else(|| {
        Error::NoEquilibrium(format!(
            "discretised robot `{}` ({C} cables, {} segments): Newton did not converge from the pose at {:?} for \
             paid-out lengths {:?} m",
            robot.name,
            options.segments,
            inputs.guess_pose.position_m.as_slice(),
            inputs.paid_out
        ))
    })?;
    let cables = assemble_cables(&problem, &state)?;
    let residual = residual_of(&problem, &state.pose, &cables);
    if !(residual.max_n().is_finite() && residual.max_m().is_finite()) {
        return Err(Error::NoEquilibrium(format!(
            "discretised robot `{}`: non-finite residual at the solution",
            robot.name
        )));
    }
    Ok(SuspendedDiscretisedEquilibrium {
        pose: state.pose,
        cables,
        paid_out_lengths_m: inputs.paid_out.to_vec(),
        iterations,
        max_residual_n: residual.max_n(),
        residual,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::suspended::{solve_at, Closure, EquilibriumOptions};
    use crate::model::Robot;
    use crate::sim::closed_form::Workspace;
    use crate::sim::discretised::{solve_forward, DiscretisedOptions, InitialGuess};

    /// The level equilibrium at the workspace's centre moved by `offset_m`.
    fn level(robot: &SuspendedRobot, offset_m: Vector3<f64>) -> SuspendedEquilibrium {
        let workspace = robot
            .workspace
            .unwrap_or_else(|| Workspace::around_anchor_points(&robot.anchors_m));
        let centre = workspace.centre() + offset_m;
        solve_at(robot, centre, Closure::Level, &EquilibriumOptions::default()).unwrap()
    }

    #[test]
    fn four_cables_are_the_four_cable_simulator_to_the_bit() {
        let four = Robot::builtin("large").unwrap();
        let robot = SuspendedRobot::from_robot(&four);
        let eq = level(&robot, Vector3::new(3.0, -2.0, 1.0));
        let paid_out: [f64; 4] = std::array::from_fn(|i| eq.cable_lengths_m[i]);
        let four_options = DiscretisedOptions {
            segments: 30,
            axial_stiffness_n: 4e6,
            pulley_radius_m: 0.15,
            ..DiscretisedOptions::default()
        };
        let expected = solve_forward(&four, &four_options, &paid_out, &InitialGuess::from_pose(eq.pose)).unwrap();
        let options = SuspendedDiscretisedOptions {
            axial_stiffness_n: vec![4e6; 4],
            pulley_radius_m: vec![0.15; 4],
            ..SuspendedDiscretisedOptions::inextensible(4, 30)
        };
        let got = solve_forward_suspended(&robot, &options, &paid_out, &eq.pose, None).unwrap();
        assert_eq!(got.pose, expected.pose);
        assert_eq!(got.cables, expected.cables.to_vec());
        assert_eq!(got.iterations, expected.iterations);
        assert_eq!(got.max_residual_n, expected.max_residual_n);
    }

    #[test]
    fn chains_converge_to_the_catenary_as_one_over_n_squared() {
        for name in ["three", "six", "eight"] {
            let robot = SuspendedRobot::builtin(name).unwrap();
            let eq = level(&robot, Vector3::new(1.5, -1.0, 0.5));
            let guess = closed_form_forces(&robot, &eq);
            let error = |segments: usize| {
                let options = SuspendedDiscretisedOptions::inextensible(robot.cable_count(), segments);
                let chain =
                    solve_forward_suspended(&robot, &options, &eq.cable_lengths_m, &eq.pose, Some(&guess)).unwrap();
                assert!(
                    chain.max_residual_n < 1e-6 * robot.platform_weight_n,
                    "{name}: {}",
                    chain.max_residual_n
                );
                assert!(chain.residual.max_m() < 1e-8, "{name}: {:?}", chain.residual);
                // The chain's force on the platform against the catenary's, cable by cable.
                let force = guess
                    .iter()
                    .zip(&chain.cables)
                    .map(|(f, c)| (f - c.platform_force_n).norm())
                    .fold(0.0, f64::max);
                ((chain.pose.position_m - eq.pose.position_m).norm(), force)
            };
            let (coarse, fine) = (error(25), error(50));
            let ratio = coarse.0 / fine.0;
            assert!(
                (3.5..4.5).contains(&ratio),
                "{name}: position errors {coarse:?} -> {fine:?}, ratio {ratio}"
            );
            assert!(
                fine.0 < 5e-3 && fine.1 < 1e-2 * robot.platform_weight_n,
                "{name}: {fine:?}"
            );
        }
    }

    #[test]
    fn a_stretchier_cable_pays_out_more_free_span_and_lowers_the_platform() {
        let robot = SuspendedRobot::builtin("six").unwrap();
        let eq = level(&robot, Vector3::zeros());
        let guess = closed_form_forces(&robot, &eq);
        let rigid = SuspendedDiscretisedOptions::inextensible(6, 40);
        let base = solve_forward_suspended(&robot, &rigid, &eq.cable_lengths_m, &eq.pose, Some(&guess)).unwrap();
        let mut one_elastic = rigid.clone();
        one_elastic.axial_stiffness_n[2] = 1e5;
        let soft = solve_forward_suspended(&robot, &one_elastic, &eq.cable_lengths_m, &eq.pose, Some(&guess)).unwrap();
        assert!(soft.residual.max_m() < 1e-8 && soft.max_residual_n < 1e-6 * robot.platform_weight_n);
        // Cable 3's chain is longer than its unstretched length by about L T / EA (Hooke's law, the mean tension).
        let chain = &soft.cables[2];
        let stretched: f64 = chain.nodes_m.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let mean_tension = chain.segment_tensions_n.iter().sum::<f64>() / chain.segment_tensions_n.len() as f64;
        let expected = chain.free_length_m * mean_tension / 1e5;
        assert!(((stretched - chain.free_length_m) - expected).abs() < 1e-9 * chain.free_length_m);
        assert!(expected > 1e-3, "a visible stretch: {expected} m");
        // The other cables stay inextensible, and the platform hangs lower.
        for (i, c) in soft.cables.iter().enumerate().filter(|(i, _)| *i != 2) {
            let length: f64 = c.nodes_m.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
            assert!((length - c.free_length_m).abs() < 1e-9, "cable {}", i + 1);
        }
        assert!(soft.pose.position_m.z < base.pose.position_m.z);
    }

    #[test]
    fn bad_settings_are_named() {
        let robot = SuspendedRobot::builtin("three").unwrap();
        let eq = level(&robot, Vector3::zeros());
        let mut options = SuspendedDiscretisedOptions::inextensible(3, 10);
        options.pulley_radius_m[1] = -0.1;
        let error = solve_forward_suspended(&robot, &options, &eq.cable_lengths_m, &eq.pose, None).unwrap_err();
        assert!(
            error.to_string().contains("cable 2: pulley radius must be >= 0 m"),
            "{error}"
        );
        let options = SuspendedDiscretisedOptions::inextensible(4, 10);
        let error = solve_forward_suspended(&robot, &options, &eq.cable_lengths_m, &eq.pose, None).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("4 axial stiffnesses and 4 pulley radii for 3 cables"),
            "{error}"
        );
        let options = SuspendedDiscretisedOptions::inextensible(3, 10);
        let error = solve_forward_suspended(&robot, &options, &[10.0, f64::NAN, 10.0], &eq.pose, None).unwrap_err();
        assert!(error.to_string().contains("cable 2: paid-out length"), "{error}");
    }
}

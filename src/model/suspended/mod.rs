//! The statics of a platform hung from any number `N >= 3` of sagging
//! cables: the paper's equilibrium (Sec. III-C, eq. 5-8) with `N` columns
//! pairs instead of four, and which of the `2N` end-force components to
//! solve for.
//!
//! Cable `i` pulls the platform with `-s_i f_h,i + z f_v,i` at `r_i = R b_i`
//! (`s_i` the horizontal unit vector from anchor `i` towards its
//! attachment), so the six equations of equilibrium read (paper eq. 8)
//! ```text
//! J^T f = w,   J^T = [ ... [ -s_i ; -r_i x s_i ]  [ z ; r_i x z ] ... ]  (6 x 2N),
//!              w = [ z ; (R b_com) x z ] m_e g.
//! ```
//! Six components are *dependent*: given the other `2N - 6` (the free
//! ones), they follow from the 6 x 6 solve `J_dep^T f_dep = w - J_free^T f_free`
//! (the paper's eq. 11 with the reference cable free, for `N = 4`). Three
//! cables' `(f_h, f_v)` make the dependent set, the three whose 6 x 6 block
//! is best conditioned at the pose ([`SuspendedRobot::dependent_cables`]):
//! among the `C(N, 3)` triples, the one with the largest smallest singular value of
//! the block with its moment rows divided by the platform's attachment
//! radius (so that forces and moments weigh alike). A triple whose block is
//! near singular (three cables pulling in one vertical plane, or through one
//! line) is never chosen while a better one exists. For `N = 3` there is
//! one triple and no free component, and its block is singular at every
//! equilibrium: gravity loads none of the rows `F_x`, `F_y`, `M_z` and the
//! vertical forces enter none of them, so the horizontal tensions solve a
//! homogeneous system that has a non-zero solution only where the block is
//! singular (the cables' horizontal lines meeting in one point). The
//! balance serves where some forces are known (a load cell's cable free);
//! the equilibrium solver ([`solve_at`]) takes the horizontal tensions as
//! its unknowns instead, each cable's vertical one from its catenary.
//! Whether an equilibrium is stable: [`stiffness`] at fixed cable lengths;
//! the equilibrium that given cable lengths hold: [`equilibrium_at_lengths`].
//!
//! Each cable must also reach its attachment: the catenary from anchor `i`
//! with `(f_h,i, f_v,i)` ends at the attachment's height (paper eq. 15,
//! [`SuspendedRobot::height_residuals`]), one equation per cable, with the
//! cable's own weight per metre; [`solve_at`] finds the equilibrium at a
//! position that a [`Closure`] picks among the `N - 3`-parameter family.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::model::pose::PlatformPose;
//! use sagcal::model::suspended::SuspendedRobot;
//! use sagcal::model::Robot;
//! // The large robot as N cables: its own statics, the reference cable free.
//! let robot = Robot::builtin("large")?;
//! let suspended = SuspendedRobot::from_robot(&robot);
//! let pose = PlatformPose::from_position(Vector3::new(10.0, -5.0, 20.0));
//! let dependent = suspended.dependent_cables(&pose);
//! assert_eq!(dependent.len(), 3);
//! let free: Vec<usize> = (0..4).filter(|i| !dependent.contains(i)).collect();
//! let tensions = suspended.balance(&pose, &dependent, &[(free[0], 300.0, 150.0)])?;
//! // The six equations of equilibrium hold.
//! assert!(suspended.wrench_residual(&pose, &tensions).amax() < 1e-9);
//! # Ok::<(), sagcal::Error>(())
//! ```

mod closure_steps;
mod equilibrium;
mod fixed_lengths;
mod measurement;
mod plausible;
mod robot;
mod stiffness;
mod tension_distribution;
#[cfg(test)]
mod test_ring;

pub use equilibrium::{
    solve_at, vertical_for_height, Closure, EquilibriumOptions, SuspendedEquilibrium, FORCE_WEIGHT, YAW_WEIGHT,
};
pub use fixed_lengths::equilibrium_at_lengths;
pub use measurement::SuspendedMeasurement;
pub use plausible::check_suspended;
pub use robot::{SuspendedRobot, MIN_CABLES, MIN_RECIPROCAL_CONDITION};
pub use stiffness::{smallest_stiffness, stiffness};

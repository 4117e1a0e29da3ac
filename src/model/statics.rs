//! Kineto-statics of the suspended 4-cable robot (paper Sec. III-C, eq. 5-11).
//!
//! Equilibrium of the platform under its weight and four catenary cables
//! (paper eq. 5-8): with `r_i = R b_i` and `s_i` the horizontal unit vector
//! from anchor `i` towards its attachment, cable `i` pulls the platform with
//! `-s_i f_h,i + z f_v,i`, and
//! ```text
//! sum_i [ -s_i ; -r_i x s_i ] f_h,i + [ z ; r_i x z ] f_v,i = [ z ; (R b_com) x z ] m_e g
//! ```
//! Given the reference cable's `(f_h, f_v)`, eq. (11) gives the other six
//! components ([`cable_tensions`]). Each cable must then also *reach* its
//! attachment: the catenary hanging from anchor `i` with those tensions ends at
//! the attachment height (eq. 15, [`attachment_height_residuals`]).
//!
//! At a fixed position the unknowns are the orientation (3) and the reference
//! tension (2) against 4 height equations: a one-parameter family. One more
//! measurement closes it:
//! * (a) [`solve_with_reference_tension`]: the load cell's tension magnitude (eq. 16);
//! * (b) [`solve_with_cable_lengths`]: the four cable lengths (least squares);
//! * (c) [`solve_forward`]: cable lengths only, position unknown too (localisation);
//! * or, for simulation, the platform's orientation: the most level member
//!   ([`solve_level`]) or the member of a given yaw ([`solve_with_yaw`]).
//!
//! This module holds the equations; `solve` the solvers. Both are
//! hand-written and share no code with `generated/`: the tests compare the two.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::model::statics::{solve_forward, solve_level, StaticsOptions};
//! use sagcal::model::Robot;
//! let robot = Robot::builtin("large")?;
//! let options = StaticsOptions::default();
//! // Problem (a): the most level equilibrium at a position, and its tensions.
//! let eq = solve_level(&robot, Vector3::new(10.0, 5.0, 20.0), &options)?;
//! // The cables' vertical pulls carry the platform's weight (force balance along z).
//! let lift: f64 = eq.tensions.iter().map(|t| t.vertical_n).sum();
//! assert!((lift - robot.platform_weight_n).abs() < 1e-6);
//! assert!(eq.max_height_residual_m() < 1e-9);
//! // Problem (c): the four cable lengths give the pose back.
//! let back = solve_forward(&robot, &eq.cable_lengths_m, None, &options)?;
//! assert!((back.pose.position_m - eq.pose.position_m).norm() < 1e-6);
//! # Ok::<(), sagcal::Error>(())
//! ```

mod equations;
mod solve;

pub use equations::{
    attachment_height_residuals, cable_geometry, cable_tensions, catenaries, gravity_wrench, structure_matrix,
    CableGeometry, CableTension, Equilibrium, StaticsOptions,
};
pub use solve::{
    feasible_start, reference_tension_magnitude_guess, scan_family, solve_forward, solve_level,
    solve_with_cable_lengths, solve_with_reference_tension, solve_with_yaw, unsolved_at, YAW_TOLERANCE_RAD,
};

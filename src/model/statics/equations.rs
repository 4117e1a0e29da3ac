//! The kineto-static equations of one pose (module docs of [`super`]): the
//! cables' spans and directions, the structure matrix and the gravity
//! wrench, the tensions that balance it, the catenaries and the attachment
//! heights they give, and what an equilibrium holds.
use nalgebra::{Matrix6, SMatrix, Vector3, Vector6};

use crate::error::{Error, Result};
use crate::model::catenary::Catenary;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};

/// Tension of one cable at its platform attachment, paper eq. (7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CableTension {
    /// Horizontal component `f_h` (towards the anchor), newtons; > 0 for a taut cable.
    pub horizontal_n: f64,
    /// Vertical component `f_v` (upward pull on the platform), newtons.
    pub vertical_n: f64,
}

impl CableTension {
    /// Tension magnitude `sqrt(f_h^2 + f_v^2)`, newtons.
    pub fn magnitude_n(&self) -> f64 {
        self.horizontal_n.hypot(self.vertical_n)
    }

    /// Whether the cable pulls (`f_h > 0`; false for NaN): a catenary needs a taut cable.
    pub fn is_taut(&self) -> bool {
        self.horizontal_n > 0.0
    }
}

/// Where cable `i` runs for a given platform pose (paper Sec. III-A).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CableGeometry {
    /// Attachment point in the world frame, `p + R b_i`, metres.
    pub attachment_world_m: Vector3<f64>,
    /// Horizontal unit vector `s_c,i` from the anchor towards the attachment.
    pub horizontal_direction: Vector3<f64>,
    /// Horizontal span `L_i = |b_xy - a_xy|`, metres.
    pub span_m: f64,
    /// Height of the anchor above the attachment, metres.
    pub height_difference_m: f64,
}

/// The geometry of the four cables at `pose`.
pub fn cable_geometry(robot: &Robot, pose: &PlatformPose) -> [CableGeometry; CABLE_COUNT] {
    let rotation = pose.rotation_matrix();
    std::array::from_fn(|i| {
        let attachment_world_m = pose.position_m + rotation * robot.attachments_m[i];
        let mut horizontal = attachment_world_m - robot.anchors_m[i];
        horizontal.z = 0.0;
        let span_m = horizontal.norm();
        CableGeometry {
            attachment_world_m,
            horizontal_direction: horizontal / span_m,
            span_m,
            height_difference_m: robot.anchors_m[i].z - attachment_world_m.z,
        }
    })
}

/// The transposed structure matrix `J^T` (6 x 8, paper eq. 8): columns `(f_h,i, f_v,i)` per cable.
pub fn structure_matrix(robot: &Robot, pose: &PlatformPose) -> SMatrix<f64, 6, 8> {
    let geometry = cable_geometry(robot, pose);
    let rotation = pose.rotation_matrix();
    let z = Vector3::z();
    let mut jt = SMatrix::<f64, 6, 8>::zeros();
    for (i, cable) in geometry.iter().enumerate() {
        let r = rotation * robot.attachments_m[i];
        let s = cable.horizontal_direction;
        // Entry by entry, not through iterator adaptors (whose cost depended
        // on the compiler's inlining: 3.5x more instructions in one build).
        let (h_moment, v_moment) = (-r.cross(&s), r.cross(&z));
        let h_column = Vector6::new(-s.x, -s.y, -s.z, h_moment.x, h_moment.y, h_moment.z);
        let v_column = Vector6::new(z.x, z.y, z.z, v_moment.x, v_moment.y, v_moment.z);
        jt.set_column(2 * i, &h_column);
        jt.set_column(2 * i + 1, &v_column);
    }
    jt
}

/// The gravity wrench the cables must carry, `[z; (R b_com) x z] m_e g` (paper eq. 6).
pub fn gravity_wrench(robot: &Robot, pose: &PlatformPose) -> Vector6<f64> {
    let z = Vector3::z();
    let moment = (pose.rotation_matrix() * robot.com_offset_m).cross(&z);
    Vector6::new(z.x, z.y, z.z, moment.x, moment.y, moment.z) * robot.platform_weight_n
}

/// All four cable tensions from the reference cable's, paper eq. (11):
/// `f_res = (J_res^T)^-1 (w - J_ref^T f_ref)`.
///
/// Fails when `J_res^T` is singular (the other three cables cannot balance the platform).
pub fn cable_tensions(
    robot: &Robot,
    pose: &PlatformPose,
    reference: CableTension,
) -> Result<[CableTension; CABLE_COUNT]> {
    crate::steps::tick();
    let jt = structure_matrix(robot, pose);
    let wrench = gravity_wrench(robot, pose);
    let r = robot.reference_cable;
    let others: Vec<usize> = (0..CABLE_COUNT).filter(|&i| i != r).collect();
    let mut j_res = Matrix6::<f64>::zeros();
    for (k, &i) in others.iter().enumerate() {
        j_res.set_column(2 * k, &jt.column(2 * i));
        j_res.set_column(2 * k + 1, &jt.column(2 * i + 1));
    }
    let rhs = wrench - jt.column(2 * r) * reference.horizontal_n - jt.column(2 * r + 1) * reference.vertical_n;
    let lu = j_res.lu();
    let solution = lu
        .solve(&rhs)
        .filter(|x| x.iter().all(|v| v.is_finite()))
        .ok_or_else(|| {
            Error::NoEquilibrium(format!(
                "the structure matrix of the non-reference cables is singular at position {:?}",
                pose.position_m.as_slice()
            ))
        })?;
    let mut tensions = [reference; CABLE_COUNT];
    for (k, &i) in others.iter().enumerate() {
        tensions[i] = CableTension {
            horizontal_n: solution[2 * k],
            vertical_n: solution[2 * k + 1],
        };
    }
    Ok(tensions)
}

/// The catenary of every cable for a pose and its tensions.
pub fn catenaries(
    robot: &Robot,
    pose: &PlatformPose,
    tensions: &[CableTension; CABLE_COUNT],
) -> [Catenary; CABLE_COUNT] {
    let geometry = cable_geometry(robot, pose);
    std::array::from_fn(|i| Catenary {
        span_m: geometry[i].span_m,
        horizontal_tension_n: tensions[i].horizontal_n,
        vertical_tension_n: tensions[i].vertical_n,
        cable_weight_n_per_m: robot.cable_weight_n_per_m,
    })
}

/// Attachment-height residuals (paper eq. 15): attachment height minus the
/// catenary's height at the attachment, metres. Zero at equilibrium.
pub fn attachment_height_residuals(
    robot: &Robot,
    pose: &PlatformPose,
    tensions: &[CableTension; CABLE_COUNT],
) -> [f64; CABLE_COUNT] {
    let geometry = cable_geometry(robot, pose);
    let cables = catenaries(robot, pose, tensions);
    std::array::from_fn(|i| cables[i].drop_m() - geometry[i].height_difference_m)
}

/// A static equilibrium of the robot.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// Platform pose.
    pub pose: PlatformPose,
    /// Tensions at the attachments, in cable order.
    pub tensions: [CableTension; CABLE_COUNT],
    /// Catenary (true) cable lengths, metres.
    pub cable_lengths_m: [f64; CABLE_COUNT],
    /// Remaining attachment-height residuals, metres (~1e-12 at a solved equilibrium).
    pub height_residuals_m: [f64; CABLE_COUNT],
    /// Newton / Levenberg-Marquardt iterations used.
    pub iterations: usize,
}

impl Equilibrium {
    pub(super) fn evaluate(
        robot: &Robot,
        pose: PlatformPose,
        reference: CableTension,
        iterations: usize,
    ) -> Result<Self> {
        let tensions = cable_tensions(robot, &pose, reference)?;
        let cables = catenaries(robot, &pose, &tensions);
        Ok(Self {
            pose,
            tensions,
            cable_lengths_m: std::array::from_fn(|i| cables[i].length_m()),
            height_residuals_m: attachment_height_residuals(robot, &pose, &tensions),
            iterations,
        })
    }

    /// Largest attachment-height residual, metres (NaN if any residual is NaN).
    pub fn max_height_residual_m(&self) -> f64 {
        self.height_residuals_m.iter().fold(0.0, |m: f64, r| {
            if r.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(r.abs())
            }
        })
    }
}

/// Options of the kineto-static solvers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticsOptions {
    /// Maximum number of Levenberg-Marquardt iterations.
    pub max_iterations: usize,
    /// Largest attachment-height residual accepted as equilibrium, metres.
    pub height_tolerance_m: f64,
    /// Standard deviation of a cable-length measurement in (b) and (c), metres.
    pub length_sigma_m: f64,
}

impl Default for StaticsOptions {
    /// 100 iterations, 1e-9 m height tolerance, 1 mm cable-length sigma.
    fn default() -> Self {
        Self {
            max_iterations: 100,
            height_tolerance_m: 1e-9,
            length_sigma_m: 1e-3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::statics::{solve_forward, solve_with_cable_lengths, solve_with_reference_tension};

    fn large() -> Robot {
        Robot::builtin("large").unwrap()
    }

    #[test]
    fn equilibrium_balances_forces_and_moments() {
        let robot = large();
        let eq = solve_with_reference_tension(
            &robot,
            Vector3::new(10.0, -5.0, 12.0),
            700.0,
            None,
            &StaticsOptions::default(),
        )
        .unwrap();
        let mut f = nalgebra::SVector::<f64, 8>::zeros();
        for i in 0..CABLE_COUNT {
            f[2 * i] = eq.tensions[i].horizontal_n;
            f[2 * i + 1] = eq.tensions[i].vertical_n;
        }
        let imbalance = structure_matrix(&robot, &eq.pose) * f - gravity_wrench(&robot, &eq.pose);
        assert!(imbalance.norm() < 1e-9, "wrench imbalance {imbalance}");
        assert!((eq.tensions[0].magnitude_n() - 700.0).abs() < 1e-9);
        assert!(eq.max_height_residual_m() < 1e-9);
    }

    #[test]
    fn the_three_closures_agree() {
        let robot = large();
        let options = StaticsOptions::default();
        let position = Vector3::new(-8.0, 6.0, 15.0);
        let a = solve_with_reference_tension(&robot, position, 650.0, None, &options).unwrap();
        let b = solve_with_cable_lengths(&robot, position, &a.cable_lengths_m, &options).unwrap();
        assert!(
            a.pose.angle_to_deg(&b.pose) < 1e-6,
            "{} deg",
            a.pose.angle_to_deg(&b.pose)
        );
        assert!((b.tensions[0].magnitude_n() - 650.0).abs() < 1e-4);
        let c = solve_forward(&robot, &a.cable_lengths_m, None, &options).unwrap();
        assert!((c.pose.position_m - position).norm() < 1e-6, "{}", c.pose.position_m);
        assert!(a.pose.angle_to_deg(&c.pose) < 1e-5);
        assert!((c.tensions[0].magnitude_n() - 650.0).abs() < 1e-3);
    }

    #[test]
    fn a_slack_reference_cable_has_no_equilibrium() {
        let robot = large();
        // 5 N cannot hold anything: the other cables would have to push.
        let err = solve_with_reference_tension(
            &robot,
            Vector3::new(0.0, 0.0, 10.0),
            5.0,
            None,
            &StaticsOptions::default(),
        )
        .unwrap_err();
        assert!(matches!(err, Error::NoEquilibrium(_)), "{err}");
    }
}

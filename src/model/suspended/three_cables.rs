//! The equilibrium of a platform on three cables at a given position
//! ([`solve_three`]), where the general solver's dependent block is
//! singular at every solution.
//!
//! Gravity loads none of the rows `F_x`, `F_y`, `M_z` of `J^T f = w` and the
//! vertical forces enter none of them (paper eq. 8: the `f_v` columns are
//! `[z; r_i x z]`), so the horizontal tensions solve the homogeneous
//! `H f_h = 0` (3 x 3). A taut equilibrium needs `H` singular: the
//! orientation must make the three cables' horizontal lines of action meet
//! in one point, and `f_h` is then a multiple `k` of `H`'s null vector. The
//! unknowns are the orientation (3) and that scale, as the horizontal
//! tension `k` of one cable (the one whose two partners' `F_x`, `F_y`
//! columns are best conditioned); the other two follow from the `F_x`, `F_y`
//! rows, the vertical tensions from the rows `F_z`, `M_x`, `M_y`, and the
//! equations are the three attachment heights (eq. 15) and the `M_z` row,
//! divided by the platform's weight (a lever arm, metres, like the
//! heights). Four equations in four unknowns: Newton with central
//! differences and a halving line search, from the best taut point of a
//! grid of orientations within 30 degrees of level.

use nalgebra::{Matrix2, Matrix3, Matrix4, UnitQuaternion, Vector2, Vector3, Vector4};

use super::robot::SuspendedRobot;
use crate::model::pose::PlatformPose;
use crate::model::statics::CableTension;

/// The three-cable problem at one position.
pub(super) struct ThreeCables<'a> {
    robot: &'a SuspendedRobot,
    position_m: Vector3<f64>,
    /// The cable whose horizontal tension is the scale unknown.
    scale_cable: usize,
}

impl<'a> ThreeCables<'a> {
    /// The problem at `position_m`, the scale cable chosen at the level pose.
    pub(super) fn new(robot: &'a SuspendedRobot, position_m: Vector3<f64>) -> Self {
        let jt = robot.structure_matrix(&PlatformPose::from_position(position_m));
        let conditioning = |cable: usize| {
            let others: Vec<usize> = (0..3).filter(|&i| i != cable).collect();
            let block = Matrix2::new(
                jt[(0, 2 * others[0])],
                jt[(0, 2 * others[1])],
                jt[(1, 2 * others[0])],
                jt[(1, 2 * others[1])],
            );
            block.determinant().abs()
        };
        let scale_cable = (0..3)
            .max_by(|&a, &b| conditioning(a).total_cmp(&conditioning(b)))
            .unwrap_or(0);
        Self {
            robot,
            position_m,
            scale_cable,
        }
    }

    /// The pose of the unknowns `x = [roll, pitch, yaw, k / m_e g]`.
    pub(super) fn pose(&self, x: &Vector4<f64>) -> PlatformPose {
        PlatformPose::new(self.position_m, UnitQuaternion::from_euler_angles(x[0], x[1], x[2]))
    }

    /// The three cables' forces at `x` and the `M_z` row's residual, newton-metres.
    pub(super) fn forces(&self, x: &Vector4<f64>) -> Option<(Vec<CableTension>, f64)> {
        let pose = self.pose(x);
        let jt = self.robot.structure_matrix(&pose);
        let wrench = self.robot.gravity_wrench(&pose);
        let s = self.scale_cable;
        let others: Vec<usize> = (0..3).filter(|&i| i != s).collect();
        let k = x[3] * self.robot.platform_weight_n;
        // F_x, F_y: the two partners' horizontal tensions.
        let block = Matrix2::new(
            jt[(0, 2 * others[0])],
            jt[(0, 2 * others[1])],
            jt[(1, 2 * others[0])],
            jt[(1, 2 * others[1])],
        );
        let partners = block
            .lu()
            .solve(&Vector2::new(-jt[(0, 2 * s)] * k, -jt[(1, 2 * s)] * k))?;
        let mut horizontal = [0.0; 3];
        horizontal[s] = k;
        horizontal[others[0]] = partners[0];
        horizontal[others[1]] = partners[1];
        let yaw_moment: f64 = (0..3).map(|i| jt[(5, 2 * i)] * horizontal[i]).sum::<f64>() - wrench[5];
        // F_z, M_x, M_y: the vertical tensions.
        let rows = [2, 3, 4];
        let vertical_block = Matrix3::from_fn(|r, c| jt[(rows[r], 2 * c + 1)]);
        let rhs = Vector3::from_fn(|r, _| {
            wrench[rows[r]] - (0..3).map(|i| jt[(rows[r], 2 * i)] * horizontal[i]).sum::<f64>()
        });
        let vertical = vertical_block.lu().solve(&rhs)?;
        let tensions = (0..3)
            .map(|i| CableTension {
                horizontal_n: horizontal[i],
                vertical_n: vertical[i],
            })
            .collect();
        Some((tensions, yaw_moment))
    }

    /// The equations at `x`: three heights and the `M_z` residual over the
    /// platform's weight (metres); `None` where a cable is slack.
    pub(super) fn equations(&self, x: &Vector4<f64>) -> Option<Vector4<f64>> {
        let (tensions, yaw_moment) = self.forces(x)?;
        if !tensions.iter().all(CableTension::is_taut) {
            return None;
        }
        let heights = self.robot.height_residuals(&self.pose(x), &tensions);
        let e = Vector4::new(
            heights[0],
            heights[1],
            heights[2],
            yaw_moment / self.robot.platform_weight_n,
        );
        e.iter().all(|v| v.is_finite()).then_some(e)
    }

    /// Newton on the four equations from the best taut point of a grid
    /// (every 5 degrees to 30 of roll, pitch and yaw, and horizontal
    /// tensions from a tenth to ten times the platform's weight): the
    /// equilibrium nearest level, not one turned half round; the unknowns where every equation is within `tolerance_m`,
    /// with the iterations used.
    pub(super) fn solve(&self, tolerance_m: f64, max_iterations: usize) -> Option<(Vector4<f64>, usize)> {
        let (mut x, mut e) = self.start()?;
        for iteration in 0..max_iterations {
            if e.amax() <= tolerance_m {
                return Some((x, iteration));
            }
            let mut jacobian = Matrix4::zeros();
            for j in 0..4 {
                let step = 1e-7 * x[j].abs().max(1e-2);
                let (mut up, mut down) = (x, x);
                up[j] += step;
                down[j] -= step;
                jacobian.set_column(j, &((self.equations(&up)? - self.equations(&down)?) / (2.0 * step)));
            }
            let dx = jacobian.lu().solve(&(-e))?;
            let mut scale = 1.0;
            loop {
                let trial = x + dx * scale;
                if let Some(trial_e) = self.equations(&trial) {
                    if trial_e.amax() < e.amax() * (1.0 - 0.5 * scale) || trial_e.amax() <= tolerance_m {
                        (x, e) = (trial, trial_e);
                        break;
                    }
                }
                scale *= 0.5;
                if scale < 1e-12 {
                    return None;
                }
            }
        }
        (e.amax() <= tolerance_m).then_some((x, max_iterations))
    }

    fn start(&self) -> Option<(Vector4<f64>, Vector4<f64>)> {
        let tilts: Vec<f64> = (-6..=6).map(|k| (5.0 * k as f64).to_radians()).collect();
        let yaws = tilts.clone();
        let scales: Vec<f64> = (-4..=4).map(|k| 10f64.powf(k as f64 / 4.0)).collect();
        let mut best: Option<(Vector4<f64>, Vector4<f64>)> = None;
        for &roll in &tilts {
            for &pitch in &tilts {
                for &yaw in &yaws {
                    for &k in &scales {
                        let x = Vector4::new(roll, pitch, yaw, k);
                        if let Some(e) = self.equations(&x) {
                            if best.as_ref().is_none_or(|(_, b)| e.norm() < b.norm()) {
                                best = Some((x, e));
                            }
                        }
                    }
                }
            }
        }
        best
    }
}

//! A platform hung from `N >= 3` cables ([`SuspendedRobot`]): the structure
//! matrix and gravity wrench of the paper's eq. (6)-(8) for `N` cables, the
//! dependent set of three cables ([`SuspendedRobot::dependent_cables`]), the
//! balance that gives their forces from the free ones, and each cable's
//! attachment height (eq. 15) with its own weight.

use nalgebra::{DMatrix, Matrix6, Vector3, Vector6};

use crate::error::{Error, Result};
use crate::model::catenary::Catenary;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, Workspace};
use crate::model::statics::CableTension;

/// The fewest cables that can hold a platform in all six directions.
pub const MIN_CABLES: usize = 3;

/// The smallest ratio of the dependent block's extreme singular values
/// (scaled, module docs) that [`SuspendedRobot::balance`] solves with: below
/// it the forces would carry fewer than six significant digits of a double.
pub const MIN_RECIPROCAL_CONDITION: f64 = 1e-10;

/// A platform hung from `N >= 3` cables, each with its anchor, its
/// attachment and its own weight per metre.
#[derive(Debug, Clone, PartialEq)]
pub struct SuspendedRobot {
    /// Anchors `p_a,i` (pulley exit points), world frame, metres.
    pub anchors_m: Vec<Vector3<f64>>,
    /// Attachment points `p_b,i`, platform frame, metres.
    pub attachments_m: Vec<Vector3<f64>>,
    /// Each cable's weight per metre `g_c,i = rho_c,i g`, newtons per metre.
    pub cable_weights_n_per_m: Vec<f64>,
    /// Each cable's axial stiffness `EA_i`, newtons; `f64::INFINITY` for an
    /// inextensible cable (Irvine's elastic catenary otherwise:
    /// [`SuspendedRobot::axial_compliance_per_mn`]).
    pub axial_stiffness_n: Vec<f64>,
    /// Centre of mass `b_com` in the platform frame, metres.
    pub com_offset_m: Vector3<f64>,
    /// Platform weight `m_e g`, newtons.
    pub platform_weight_n: f64,
    /// Human-readable name.
    pub name: String,
    /// The cables with a load cell at their attachment, 0-based, ascending.
    pub load_cells: Vec<usize>,
    /// Encoder length offsets `l_i^0`, metres, one per cable.
    pub length_offsets_m: Vec<f64>,
    /// The box of platform positions the robot works in, if its file gives one.
    pub workspace: Option<Workspace>,
}

/// Where one cable runs at a pose: its attachment in the world, the
/// horizontal unit vector from its anchor towards it, the horizontal span
/// and the anchor's height above it (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Run {
    pub(super) attachment_world_m: Vector3<f64>,
    pub(super) horizontal_direction: Vector3<f64>,
    pub(super) span_m: f64,
    pub(super) height_difference_m: f64,
}

impl SuspendedRobot {
    /// A robot of `anchors_m.len()` cables, named `suspended`, with a load
    /// cell on its first cable, zero length offsets and no workspace of its
    /// own; fails unless every list has one entry per cable, there are at
    /// least [`MIN_CABLES`], and every number is finite with positive weights.
    pub fn new(
        anchors_m: Vec<Vector3<f64>>,
        attachments_m: Vec<Vector3<f64>>,
        cable_weights_n_per_m: Vec<f64>,
        com_offset_m: Vector3<f64>,
        platform_weight_n: f64,
    ) -> Result<Self> {
        let n = anchors_m.len();
        if n < MIN_CABLES {
            return Err(Error::InvalidInput(format!(
                "{n} cables cannot hold a platform in all six directions: at least {MIN_CABLES} are needed"
            )));
        }
        if attachments_m.len() != n || cable_weights_n_per_m.len() != n {
            return Err(Error::InvalidInput(format!(
                "{n} anchors but {} attachments and {} cable weights: one each per cable",
                attachments_m.len(),
                cable_weights_n_per_m.len()
            )));
        }
        let finite = anchors_m
            .iter()
            .chain(&attachments_m)
            .all(|p| p.iter().all(|v| v.is_finite()))
            && com_offset_m.iter().all(|v| v.is_finite());
        let positive_weight = platform_weight_n > 0.0 && platform_weight_n.is_finite();
        let cables_weigh = cable_weights_n_per_m.iter().all(|w| *w >= 0.0 && w.is_finite());
        if !finite || !positive_weight || !cables_weigh {
            return Err(Error::InvalidInput(
                "every anchor, attachment and the centre of mass finite, the platform's weight > 0 and each cable's >= 0"
                    .into(),
            ));
        }
        Ok(Self {
            length_offsets_m: vec![0.0; n],
            axial_stiffness_n: vec![f64::INFINITY; n],
            anchors_m,
            attachments_m,
            cable_weights_n_per_m,
            com_offset_m,
            platform_weight_n,
            name: "suspended".into(),
            load_cells: vec![0],
            workspace: None,
        })
    }

    /// The four-cable robot as a suspended robot (its effects and its
    /// calibration's covariance aside), the load cell on its reference cable.
    pub fn from_robot(robot: &Robot) -> Self {
        Self {
            anchors_m: robot.anchors_m.to_vec(),
            attachments_m: robot.attachments_m.to_vec(),
            cable_weights_n_per_m: vec![robot.cable_weight_n_per_m; robot.anchors_m.len()],
            axial_stiffness_n: vec![f64::INFINITY; robot.anchors_m.len()],
            com_offset_m: robot.com_offset_m,
            platform_weight_n: robot.platform_weight_n,
            name: robot.name.clone(),
            load_cells: vec![robot.reference_cable],
            length_offsets_m: robot.length_offsets_m.to_vec(),
            workspace: robot.workspace,
        }
    }

    /// The robot without its last cable, named `name` (the six- and
    /// eight-cable robots as five and seven, for tests and benches): every
    /// per-cable list one shorter, a load cell on that cable dropped. Fails
    /// where that leaves fewer than [`MIN_CABLES`] cables or no load cell.
    pub fn without_last_cable(&self, name: &str) -> Result<Self> {
        let last = self.cable_count() - 1;
        let mut robot = self.clone();
        robot.anchors_m.pop();
        robot.attachments_m.pop();
        robot.cable_weights_n_per_m.pop();
        robot.axial_stiffness_n.pop();
        robot.length_offsets_m.pop();
        robot.load_cells.retain(|&c| c != last);
        robot.name = name.into();
        if robot.cable_count() < MIN_CABLES || robot.load_cells.is_empty() {
            return Err(Error::InvalidInput(format!(
                "robot `{}` without cable {}: {} cables and {} load cells cannot be calibrated",
                self.name,
                last + 1,
                robot.cable_count(),
                robot.load_cells.len()
            )));
        }
        Ok(robot)
    }

    /// The cables with a load cell as a reader says them: `cable 1, cable 5`.
    pub fn load_cells_phrase(&self) -> String {
        let cables: Vec<String> = self.load_cells.iter().map(|c| format!("cable {}", c + 1)).collect();
        cables.join(", ")
    }

    /// Number of cables `N`.
    pub fn cable_count(&self) -> usize {
        self.anchors_m.len()
    }

    /// Cable `cable`'s axial compliance `1e6 / EA` in 1/MN, the argument of
    /// the elastic cable's residual; 0 for an inextensible cable.
    pub fn axial_compliance_per_mn(&self, cable: usize) -> f64 {
        1e6 / self.axial_stiffness_n[cable]
    }

    /// Whether any cable stretches (a finite axial stiffness).
    pub fn is_elastic(&self) -> bool {
        self.axial_stiffness_n.iter().any(|ea| ea.is_finite())
    }

    /// The force components left free at each pose, `2N - 6`.
    pub fn free_components(&self) -> usize {
        2 * self.cable_count() - 6
    }

    /// The largest distance of an attachment from the platform's origin,
    /// metres (at least a millimetre): the lever arm that makes moments
    /// comparable with forces.
    pub fn attachment_radius_m(&self) -> f64 {
        self.attachments_m.iter().map(|b| b.norm()).fold(1e-3, f64::max)
    }

    pub(super) fn runs(&self, pose: &PlatformPose) -> Vec<Run> {
        let rotation = pose.rotation_matrix();
        (0..self.cable_count())
            .map(|i| {
                let attachment_world_m = pose.position_m + rotation * self.attachments_m[i];
                let mut horizontal = attachment_world_m - self.anchors_m[i];
                horizontal.z = 0.0;
                let span_m = horizontal.norm();
                Run {
                    attachment_world_m,
                    horizontal_direction: horizontal / span_m,
                    span_m,
                    height_difference_m: self.anchors_m[i].z - attachment_world_m.z,
                }
            })
            .collect()
    }

    /// The transposed structure matrix `J^T` (6 x 2N, paper eq. 8): columns
    /// `(f_h,i, f_v,i)` per cable.
    pub fn structure_matrix(&self, pose: &PlatformPose) -> DMatrix<f64> {
        let rotation = pose.rotation_matrix();
        let z = Vector3::z();
        let mut jt = DMatrix::zeros(6, 2 * self.cable_count());
        for (i, run) in self.runs(pose).iter().enumerate() {
            let r = rotation * self.attachments_m[i];
            let s = run.horizontal_direction;
            let (h_moment, v_moment) = (-r.cross(&s), r.cross(&z));
            jt.set_column(
                2 * i,
                &Vector6::new(-s.x, -s.y, -s.z, h_moment.x, h_moment.y, h_moment.z),
            );
            jt.set_column(
                2 * i + 1,
                &Vector6::new(z.x, z.y, z.z, v_moment.x, v_moment.y, v_moment.z),
            );
        }
        jt
    }

    /// The gravity wrench the cables carry, `[z; (R b_com) x z] m_e g` (paper eq. 6).
    pub fn gravity_wrench(&self, pose: &PlatformPose) -> Vector6<f64> {
        let moment = (pose.rotation_matrix() * self.com_offset_m).cross(&Vector3::z());
        Vector6::new(0.0, 0.0, 1.0, moment.x, moment.y, moment.z) * self.platform_weight_n
    }

    /// The 6 x 6 block of `cables`' columns, moment rows divided by
    /// [`Self::attachment_radius_m`].
    fn scaled_block(&self, jt: &DMatrix<f64>, cables: &[usize; 3]) -> Matrix6<f64> {
        let radius = self.attachment_radius_m();
        let mut block = Matrix6::zeros();
        for (k, &i) in cables.iter().enumerate() {
            for c in 0..2 {
                let mut column: Vector6<f64> = jt.fixed_view::<6, 1>(0, 2 * i + c).into_owned();
                column.fixed_rows_mut::<3>(3).unscale_mut(radius);
                block.set_column(2 * k + c, &column);
            }
        }
        block
    }

    /// The three cables whose forces are solved for at `pose`: the triple
    /// whose scaled 6 x 6 block has the largest smallest singular value
    /// (module docs), in increasing order; the first such triple on a tie.
    pub fn dependent_cables(&self, pose: &PlatformPose) -> [usize; 3] {
        let jt = self.structure_matrix(pose);
        let n = self.cable_count();
        let mut best = ([0, 1, 2], f64::NEG_INFINITY);
        for a in 0..n {
            for b in a + 1..n {
                for c in b + 1..n {
                    let smallest = smallest_singular_value(&self.scaled_block(&jt, &[a, b, c]));
                    if smallest > best.1 {
                        best = ([a, b, c], smallest);
                    }
                }
            }
        }
        best.0
    }

    /// Every cable's end forces at `pose` from the free components `free`
    /// (`(cable, f_h, f_v)` for each cable not in `dependent`, in any
    /// order): the dependent three from `J_dep^T f_dep = w - J_free^T f_free`.
    /// Fails when a cable is named twice or missing, or the dependent block
    /// is singular.
    pub fn balance(
        &self,
        pose: &PlatformPose,
        dependent: &[usize; 3],
        free: &[(usize, f64, f64)],
    ) -> Result<Vec<CableTension>> {
        let n = self.cable_count();
        let mut tensions: Vec<Option<CableTension>> = vec![None; n];
        for &(i, horizontal_n, vertical_n) in free {
            if i >= n || dependent.contains(&i) || tensions[i].is_some() {
                return Err(Error::InvalidInput(format!(
                    "cable {} cannot be free: the free cables are the {} not in the dependent set {:?}, each once",
                    i + 1,
                    n - 3,
                    dependent.map(|d| d + 1)
                )));
            }
            tensions[i] = Some(CableTension {
                horizontal_n,
                vertical_n,
            });
        }
        if free.len() + 3 != n {
            return Err(Error::InvalidInput(format!(
                "{} free cables given for {n} cables and 3 dependent",
                free.len()
            )));
        }
        let jt = self.structure_matrix(pose);
        let mut rhs = self.gravity_wrench(pose);
        for &(i, h, v) in free {
            rhs -= jt.column(2 * i) * h + jt.column(2 * i + 1) * v;
        }
        let mut block = Matrix6::zeros();
        for (k, &i) in dependent.iter().enumerate() {
            block.set_column(2 * k, &jt.column(2 * i));
            block.set_column(2 * k + 1, &jt.column(2 * i + 1));
        }
        let scaled = self.scaled_block(&jt, dependent).singular_values();
        let solution = (scaled.min() > MIN_RECIPROCAL_CONDITION * scaled.max())
            .then(|| block.lu().solve(&rhs))
            .flatten()
            .filter(|x| x.iter().all(|v| v.is_finite()))
            .ok_or_else(|| {
                Error::NoEquilibrium(format!(
                    "cables {:?} cannot balance the platform at position {:?}: their structure matrix is singular",
                    dependent.map(|d| d + 1),
                    pose.position_m.as_slice()
                ))
            })?;
        for (k, &i) in dependent.iter().enumerate() {
            tensions[i] = Some(CableTension {
                horizontal_n: solution[2 * k],
                vertical_n: solution[2 * k + 1],
            });
        }
        Ok(tensions
            .into_iter()
            .map(|t| t.expect("every cable is free or dependent"))
            .collect())
    }

    /// `J^T f - w`: what the forces `tensions` leave unbalanced (newtons and
    /// newton-metres; zero at equilibrium).
    pub fn wrench_residual(&self, pose: &PlatformPose, tensions: &[CableTension]) -> Vector6<f64> {
        let jt = self.structure_matrix(pose);
        let mut sum = -self.gravity_wrench(pose);
        for (i, t) in tensions.iter().enumerate() {
            sum += jt.column(2 * i) * t.horizontal_n + jt.column(2 * i + 1) * t.vertical_n;
        }
        sum
    }

    /// Each cable's catenary at `pose` under `tensions`, with its own weight.
    pub fn catenaries(&self, pose: &PlatformPose, tensions: &[CableTension]) -> Vec<Catenary> {
        self.runs(pose)
            .iter()
            .zip(tensions)
            .zip(&self.cable_weights_n_per_m)
            .map(|((run, t), &weight)| Catenary {
                span_m: run.span_m,
                horizontal_tension_n: t.horizontal_n,
                vertical_tension_n: t.vertical_n,
                cable_weight_n_per_m: weight,
            })
            .collect()
    }

    /// Attachment-height residuals (paper eq. 15), one per cable: the
    /// catenary's drop from its anchor minus the anchor's height above the
    /// attachment, metres; zero when every cable reaches its attachment.
    pub fn height_residuals(&self, pose: &PlatformPose, tensions: &[CableTension]) -> Vec<f64> {
        self.runs(pose)
            .iter()
            .zip(self.catenaries(pose, tensions))
            .map(|(run, cable)| cable.drop_m() - run.height_difference_m)
            .collect()
    }
}

/// The smallest singular value of a 6 x 6 matrix (0 for a singular one).
fn smallest_singular_value(block: &Matrix6<f64>) -> f64 {
    block.singular_values().min()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::statics::{cable_tensions, solve_level, StaticsOptions};
    use nalgebra::UnitQuaternion;

    /// `n` anchors on a circle of radius 20 m at 15 m height, attachments on
    /// a 0.5 m circle (turned by a third of the spacing), 2 kg/m... of rope.
    fn ring(n: usize) -> SuspendedRobot {
        let angle = |k: usize, turn: f64| 2.0 * std::f64::consts::PI * (k as f64 + turn) / n as f64;
        SuspendedRobot::new(
            (0..n)
                .map(|k| Vector3::new(20.0 * angle(k, 0.0).cos(), 20.0 * angle(k, 0.0).sin(), 15.0))
                .collect(),
            (0..n)
                .map(|k| Vector3::new(0.5 * angle(k, 0.3).cos(), 0.5 * angle(k, 0.3).sin(), 0.2))
                .collect(),
            vec![0.5; n],
            Vector3::new(0.0, 0.0, -0.1),
            500.0,
        )
        .unwrap()
    }

    fn tilted(position: Vector3<f64>) -> PlatformPose {
        PlatformPose {
            position_m: position,
            rotation: UnitQuaternion::from_euler_angles(0.05, -0.03, 0.2),
        }
    }

    /// For the four-cable robot with the reference cable free, the balance
    /// is the paper's eq. (11) of `model::statics::cable_tensions`.
    #[test]
    fn four_cables_with_the_reference_free_are_the_papers_eq_11() {
        let robot = Robot::builtin("large").unwrap();
        let suspended = SuspendedRobot::from_robot(&robot);
        let eq = solve_level(&robot, Vector3::new(12.0, -8.0, 18.0), &StaticsOptions::default()).unwrap();
        let r = robot.reference_cable;
        let dependent: Vec<usize> = (0..4).filter(|&i| i != r).collect();
        let reference = eq.tensions[r];
        let tensions = suspended
            .balance(
                &eq.pose,
                &[dependent[0], dependent[1], dependent[2]],
                &[(r, reference.horizontal_n, reference.vertical_n)],
            )
            .unwrap();
        let paper = cable_tensions(&robot, &eq.pose, reference).unwrap();
        for (t, p) in tensions.iter().zip(&paper) {
            assert!(
                (t.horizontal_n - p.horizontal_n).abs() < 1e-9 * p.magnitude_n(),
                "{t:?} {p:?}"
            );
            assert!(
                (t.vertical_n - p.vertical_n).abs() < 1e-9 * p.magnitude_n(),
                "{t:?} {p:?}"
            );
        }
        // The equilibrium solve's heights hold in the general code too.
        let heights = suspended.height_residuals(&eq.pose, &tensions);
        assert!(heights.iter().all(|h| h.abs() < 1e-8), "{heights:?}");
    }

    /// For 3 to 8 cables and any free components, the six equations hold
    /// whichever triple is dependent, and the chosen triple is the best
    /// conditioned of all.
    #[test]
    fn the_balance_holds_for_three_to_eight_cables() {
        for n in 3..=8 {
            let robot = ring(n);
            assert_eq!(robot.free_components(), 2 * n - 6);
            let pose = tilted(Vector3::new(1.5, -2.0, 4.0));
            let chosen = robot.dependent_cables(&pose);
            let jt = robot.structure_matrix(&pose);
            let conditioning = |d: &[usize; 3]| smallest_singular_value(&robot.scaled_block(&jt, d));
            for a in 0..n {
                for b in a + 1..n {
                    for c in b + 1..n {
                        assert!(conditioning(&chosen) >= conditioning(&[a, b, c]));
                        let free: Vec<(usize, f64, f64)> = (0..n)
                            .filter(|i| ![a, b, c].contains(i))
                            .map(|i| (i, 80.0 + 7.0 * i as f64, 40.0 - 3.0 * i as f64))
                            .collect();
                        let tensions = robot.balance(&pose, &[a, b, c], &free).unwrap();
                        let residual = robot.wrench_residual(&pose, &tensions);
                        assert!(
                            residual.amax() < 1e-9 * robot.platform_weight_n,
                            "{n} cables, {a}{b}{c}: {residual}"
                        );
                        for &(i, h, v) in &free {
                            assert_eq!((tensions[i].horizontal_n, tensions[i].vertical_n), (h, v));
                        }
                    }
                }
            }
        }
    }

    /// Three cables pulling in one vertical plane through the platform's
    /// centre cannot hold a moment about that plane's normal: that triple is
    /// never chosen, and balancing with it is refused, not a NaN.
    #[test]
    fn a_singular_triple_is_avoided_and_refused() {
        let mut robot = ring(6);
        // Cables 1, 2 and 3 (0-based 0..3) anchored on the x axis, attached on it.
        for (k, x) in [(0, -20.0), (1, 20.0), (2, 30.0)] {
            robot.anchors_m[k] = Vector3::new(x, 0.0, 15.0);
            robot.attachments_m[k] = Vector3::new(0.5 * x.signum(), 0.0, 0.2);
        }
        let pose = PlatformPose::from_position(Vector3::new(0.0, 0.0, 4.0));
        assert_ne!(robot.dependent_cables(&pose), [0, 1, 2]);
        let free: Vec<(usize, f64, f64)> = (3..6).map(|i| (i, 50.0, 30.0)).collect();
        let refused = robot.balance(&pose, &[0, 1, 2], &free);
        assert!(matches!(refused, Err(Error::NoEquilibrium(_))), "{refused:?}");
    }

    /// The height residual of each cable is its own catenary's: a heavier
    /// cable (its own weight per metre) sags more at the same forces.
    #[test]
    fn each_cable_sags_by_its_own_weight() {
        let mut robot = ring(4);
        let pose = PlatformPose::from_position(Vector3::new(0.0, 0.0, 4.0));
        let tensions = vec![
            CableTension {
                horizontal_n: 200.0,
                vertical_n: 125.0,
            };
            4
        ];
        let light = robot.height_residuals(&pose, &tensions);
        robot.cable_weights_n_per_m[2] = 5.0;
        let heavy = robot.height_residuals(&pose, &tensions);
        assert_eq!((light[0], light[1], light[3]), (heavy[0], heavy[1], heavy[3]));
        // The anchor's height above the attachment, paper eq. (1) at x = span in
        // the cosh form: (f_h / g_c) (cosh(A + g_c span / f_h) - cosh A), sinh A = f_v / f_h;
        // the residual grows by the difference of the two drops.
        let span = (robot.anchors_m[2] - robot.attachments_m[2] - pose.position_m)
            .xy()
            .norm();
        let drop = |w: f64| {
            let a = (125.0f64 / 200.0).asinh();
            (200.0 / w) * ((a + w * span / 200.0).cosh() - a.cosh())
        };
        let expected = drop(5.0) - drop(0.5);
        assert!(
            ((heavy[2] - light[2]) - expected).abs() < 1e-9 * expected.abs().max(1.0),
            "{} vs {expected}",
            heavy[2] - light[2]
        );
    }

    #[test]
    fn too_few_cables_or_mismatched_lists_are_refused() {
        let two = SuspendedRobot::new(
            vec![Vector3::zeros(); 2],
            vec![Vector3::zeros(); 2],
            vec![1.0; 2],
            Vector3::zeros(),
            1.0,
        );
        assert!(two.unwrap_err().to_string().contains("at least 3"));
        let mismatched = SuspendedRobot::new(
            vec![Vector3::zeros(); 4],
            vec![Vector3::zeros(); 3],
            vec![1.0; 4],
            Vector3::zeros(),
            1.0,
        );
        assert!(mismatched.unwrap_err().to_string().contains("3 attachments"));
    }

    /// Dropping the last cable shortens every per-cable list and its load
    /// cell; three cables, or the only load cell, cannot be dropped.
    #[test]
    fn the_last_cable_is_dropped_with_everything_it_carries() {
        let mut six = ring(6);
        six.axial_stiffness_n[5] = 3e6;
        six.load_cells = vec![0, 5];
        let five = six.without_last_cable("five").unwrap();
        assert_eq!(five.cable_count(), 5);
        let lengths = [
            five.attachments_m.len(),
            five.cable_weights_n_per_m.len(),
            five.axial_stiffness_n.len(),
            five.length_offsets_m.len(),
        ];
        assert_eq!(
            (lengths, five.load_cells.clone(), five.is_elastic()),
            ([5; 4], vec![0], false)
        );
        assert!(ring(3).without_last_cable("two").is_err());
        six.load_cells = vec![5];
        let message = six.without_last_cable("five").unwrap_err().to_string();
        assert!(message.contains("0 load cells"), "{message}");
    }
}

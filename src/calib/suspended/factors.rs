//! The factors of a calibration of `N` cables: thin wrappers that gather the
//! variables, call the SymForce-generated residual and copy its Jacobian
//! blocks. Each cable of each pose carries its own end forces `(f_h, f_v)`
//! as a variable; the equilibrium factor balances them against gravity.
//!
//! - [`CatenaryCableFactor`]: one cable's length (paper eq. 14) or
//!   attachment height (eq. 15);
//! - [`StraightCableFactor`]: one massless cable's length row (the rigid stage);
//! - [`EquilibriumFactor`]: the six equations of equilibrium (eq. 5-8), the
//!   cables' wrenches minus the weight's;
//! - [`CableLoadCellFactor`]: a load cell on one cable (eq. 16).
//!
//! ```
//! use nalgebra::{DMatrix, DVector, Vector3};
//! use sagcal::calib::suspended::factors::{
//!     CableConstants, CableRow, CableVariables, CatenaryCableFactor, EquilibriumFactor,
//! };
//! use sagcal::graph::{Factor, RobustKernel, Values, VariableValue};
//! use sagcal::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedRobot};
//! let robot = SuspendedRobot::builtin("three")?;
//! let eq = solve_at(&robot, Vector3::new(1.0, -0.5, 2.0), Closure::Level, &EquilibriumOptions::default())?;
//! let vector = |v: &[f64]| VariableValue::Vector(DVector::from_column_slice(v));
//! let mut values = Values::new();
//! let pose = values.insert("pose", VariableValue::Pose(eq.pose));
//! let forces: Vec<_> =
//!     eq.tensions.iter().map(|t| values.insert("forces", vector(&[t.horizontal_n, t.vertical_n]))).collect();
//! let anchors: Vec<_> = robot.anchors_m.iter().map(|a| values.insert("anchor", vector(a.as_slice()))).collect();
//! let offset = values.insert("offset", vector(&[0.2]));
//! // At an equilibrium every cable reaches its attachment with the length its encoder reads ...
//! let variables = CableVariables { pose, forces: forces[1], anchor: anchors[1], length_offset: offset };
//! let constants = CableConstants::of(&robot, 1);
//! for (row, sigma_m) in [(CableRow::Length, 0.01), (CableRow::Height, 1e-4)] {
//!     let cable =
//!         CatenaryCableFactor::new(variables, constants, eq.cable_lengths_m[1] + 0.2, row, sigma_m, RobustKernel::None);
//!     assert!(cable.evaluate(&values, None).unwrap()[0].abs() < 1e-9);
//! }
//! // ... and the cables hold the platform's weight: six equations, one block per variable.
//! let statics = EquilibriumFactor::new(
//!     pose, &forces, &anchors, &robot.attachments_m, robot.com_offset_m, robot.platform_weight_n, 1e-3, 1.0,
//! );
//! let mut blocks: Vec<DMatrix<f64>> =
//!     [6, 2, 2, 2, 3, 3, 3].iter().map(|&d| DMatrix::zeros(6, d)).collect();
//! let wrench = statics.evaluate(&values, Some(&mut blocks)).unwrap();
//! assert!(wrench.amax() < 1e-6 * robot.platform_weight_n);
//! // d F_z / d f_v of a cable is 1: it pulls straight up.
//! assert_eq!(blocks[1][(2, 1)], 1.0);
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{DMatrix, DVector, SMatrix, Vector2, Vector3};

use crate::calib::factors::{pose_arguments, EPSILON};
use crate::generated;
use crate::graph::{evaluate_through_into, Factor, Noise, RobustKernel, Values, VariableId};
use crate::model::suspended::SuspendedRobot;

/// The methods every factor of this file shares: its variables, its
/// residual evaluated through `evaluate_into` and its noise; each fills
/// every entry of every block it is given.
macro_rules! factor_basics {
    () => {
        fn variables(&self) -> &[VariableId] {
            &self.variables
        }
        fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
            evaluate_through_into(self, values, jacobians)
        }
        fn noise(&self) -> &Noise {
            &self.noise
        }
        fn writes_every_jacobian_entry(&self) -> bool {
            true
        }
    };
}

/// The variables of one cable at one pose, in the order of the Jacobian
/// blocks of [`CatenaryCableFactor`]: `[pose, forces, anchor, offset]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CableVariables {
    /// The platform's pose.
    pub pose: VariableId,
    /// The cable's `(f_h, f_v)` at its attachment at this pose, newtons.
    pub forces: VariableId,
    /// The cable's anchor, world frame, metres.
    pub anchor: VariableId,
    /// The cable's encoder length offset, metres.
    pub length_offset: VariableId,
}

/// What one cable is: its attachment on the platform, its weight and its stretch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CableConstants {
    /// Attachment, platform frame, metres.
    pub attachment_m: Vector3<f64>,
    /// Weight per metre, N/m.
    pub weight_n_per_m: f64,
    /// Axial compliance `1e6 / EA`, 1/MN; 0 for an inextensible cable.
    pub axial_compliance_per_mn: f64,
}

impl CableConstants {
    /// Cable `cable` (0-based) of `robot`.
    pub fn of(robot: &SuspendedRobot, cable: usize) -> Self {
        Self {
            attachment_m: robot.attachments_m[cable],
            weight_n_per_m: robot.cable_weights_n_per_m[cable],
            axial_compliance_per_mn: robot.axial_compliance_per_mn(cable),
        }
    }
}

/// Which row of one cable's eq. (14)-(15) a [`CatenaryCableFactor`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CableRow {
    /// `l_C + l0 - z_enc` (eq. 14), metres, the encoder's sigma.
    Length,
    /// `(p + R b)_z - a_z + drop` (eq. 15), metres, the height constraint's sigma.
    Height,
}

/// Paper eq. (14) or (15) for one cable with its own forces (one row of
/// `generated::suspended_cable_residual`, or of
/// `generated::suspended_elastic_cable_residual` for an elastic cable): its statistics are the
/// encoders' (`catenary_length`) or the constraint's (`attachment_height`),
/// as the four-cable graph reports them.
pub struct CatenaryCableFactor {
    variables: [VariableId; 4],
    cable: CableConstants,
    encoder_length_m: f64,
    row: CableRow,
    noise: Noise,
}

impl CatenaryCableFactor {
    /// The `row` of `cable` reading `encoder_length_m`, with standard deviation `sigma_m`.
    pub fn new(
        variables: CableVariables,
        cable: CableConstants,
        encoder_length_m: f64,
        row: CableRow,
        sigma_m: f64,
        kernel: RobustKernel,
    ) -> Self {
        Self {
            variables: [
                variables.pose,
                variables.forces,
                variables.anchor,
                variables.length_offset,
            ],
            cable,
            encoder_length_m,
            row,
            noise: Noise::isotropic(1, sigma_m, kernel),
        }
    }
}

/// A vector variable as a fixed-size vector.
fn fixed<const D: usize>(values: &Values, id: VariableId) -> SMatrix<f64, D, 1> {
    SMatrix::<f64, D, 1>::from_column_slice(values.vector(id).as_slice())
}

impl Factor for CatenaryCableFactor {
    factor_basics!();
    fn residual_dim(&self) -> usize {
        1
    }
    fn kind(&self) -> &'static str {
        match self.row {
            CableRow::Length => "catenary_length",
            CableRow::Height => "attachment_height",
        }
    }
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        let (position, rotation) = pose_arguments(values, self.variables[0]);
        let forces: Vector2<f64> = fixed(values, self.variables[1]);
        let anchor: Vector3<f64> = fixed(values, self.variables[2]);
        let offset = values.vector(self.variables[3])[0];
        let (mut j_pose, mut j_forces, mut j_anchor, mut j_offset) = (
            SMatrix::<f64, 2, 6>::zeros(),
            SMatrix::<f64, 2, 2>::zeros(),
            SMatrix::<f64, 2, 3>::zeros(),
            SMatrix::<f64, 2, 1>::zeros(),
        );
        let want = jacobians.is_some();
        let c = &self.cable;
        // An inextensible cable keeps the shorter code of eq. (14)-(15).
        let r = if c.axial_compliance_per_mn == 0.0 {
            generated::suspended_cable_residual(
                &position,
                &rotation,
                &forces,
                &anchor,
                &c.attachment_m,
                c.weight_n_per_m,
                offset,
                self.encoder_length_m,
                EPSILON,
                want.then_some(&mut j_pose),
                want.then_some(&mut j_forces),
                want.then_some(&mut j_anchor),
                want.then_some(&mut j_offset),
            )
        } else {
            generated::suspended_elastic_cable_residual(
                &position,
                &rotation,
                &forces,
                &anchor,
                &c.attachment_m,
                c.weight_n_per_m,
                c.axial_compliance_per_mn,
                offset,
                self.encoder_length_m,
                EPSILON,
                want.then_some(&mut j_pose),
                want.then_some(&mut j_forces),
                want.then_some(&mut j_anchor),
                want.then_some(&mut j_offset),
                None,
            )
        };
        let k = match self.row {
            CableRow::Length => 0,
            CableRow::Height => 1,
        };
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j_pose.row(k));
            blocks[1].copy_from(&j_forces.row(k));
            blocks[2].copy_from(&j_anchor.row(k));
            blocks[3].copy_from(&j_offset.row(k));
        }
        residual[0] = r[k];
        r[k].is_finite()
    }
}

/// One massless cable's length, `||a - (p + R b)|| + l0 - z_enc` (the
/// `g_c -> 0` limit of eq. 14): the rigid stage. Blocks `[pose, anchor, offset]`.
pub struct StraightCableFactor {
    variables: [VariableId; 3],
    attachment_m: Vector3<f64>,
    encoder_length_m: f64,
    noise: Noise,
}

impl StraightCableFactor {
    /// The factor of the cable with `anchor` and `length_offset` at `pose`, reading `encoder_length_m`.
    pub fn new(
        [pose, anchor, length_offset]: [VariableId; 3],
        attachment_m: Vector3<f64>,
        encoder_length_m: f64,
        encoder_sigma_m: f64,
        kernel: RobustKernel,
    ) -> Self {
        Self {
            variables: [pose, anchor, length_offset],
            attachment_m,
            encoder_length_m,
            noise: Noise::isotropic(1, encoder_sigma_m, kernel),
        }
    }
}

impl Factor for StraightCableFactor {
    factor_basics!();
    fn residual_dim(&self) -> usize {
        1
    }
    fn kind(&self) -> &'static str {
        "straight_cable"
    }
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        let (position, rotation) = pose_arguments(values, self.variables[0]);
        let anchor: Vector3<f64> = fixed(values, self.variables[1]);
        let offset = values.vector(self.variables[2])[0];
        let (mut j_pose, mut j_anchor, mut j_offset) = (
            SMatrix::<f64, 1, 6>::zeros(),
            SMatrix::<f64, 1, 3>::zeros(),
            SMatrix::<f64, 1, 1>::zeros(),
        );
        let want = jacobians.is_some();
        let r = generated::straight_cable_residual(
            &position,
            &rotation,
            &anchor,
            &self.attachment_m,
            offset,
            self.encoder_length_m,
            EPSILON,
            want.then_some(&mut j_pose),
            want.then_some(&mut j_anchor),
            want.then_some(&mut j_offset),
        );
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j_pose);
            blocks[1].copy_from(&j_anchor);
            blocks[2].copy_from(&j_offset);
        }
        residual[0] = r[0];
        r[0].is_finite()
    }
}

/// The six equations of equilibrium of one pose (paper eq. 5-8):
/// `sum_i [F_i; r_i x F_i] - [z; (R b_com) x z] m_e g` (newtons, then
/// newton-metres about the platform origin). Blocks `[pose, forces 1..N,
/// anchors 1..N]`. A model equation: its sigmas are tight.
pub struct EquilibriumFactor {
    variables: Vec<VariableId>,
    attachments_m: Vec<Vector3<f64>>,
    com_offset_m: Vector3<f64>,
    platform_weight_n: f64,
    noise: Noise,
}

impl EquilibriumFactor {
    /// The equilibrium of the pose `pose` held by cables with `forces` and
    /// `anchors` (one each per cable, cable order), with sigma
    /// `force_sigma_n` on the force rows and `force_sigma_n * lever_m` on
    /// the moment rows.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        pose: VariableId,
        forces: &[VariableId],
        anchors: &[VariableId],
        attachments_m: &[Vector3<f64>],
        com_offset_m: Vector3<f64>,
        platform_weight_n: f64,
        force_sigma_n: f64,
        lever_m: f64,
    ) -> Self {
        let mut variables = Vec::with_capacity(1 + 2 * forces.len());
        variables.push(pose);
        variables.extend_from_slice(forces);
        variables.extend_from_slice(anchors);
        let sigmas = DVector::from_fn(6, |row, _| {
            if row < 3 {
                force_sigma_n
            } else {
                force_sigma_n * lever_m
            }
        });
        Self {
            variables,
            attachments_m: attachments_m.to_vec(),
            com_offset_m,
            platform_weight_n,
            noise: Noise::new(sigmas, RobustKernel::None),
        }
    }

    fn cable_count(&self) -> usize {
        self.attachments_m.len()
    }
}

impl Factor for EquilibriumFactor {
    factor_basics!();
    fn residual_dim(&self) -> usize {
        6
    }
    fn kind(&self) -> &'static str {
        "equilibrium"
    }
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], mut jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        let n = self.cable_count();
        let (position, rotation) = pose_arguments(values, self.variables[0]);
        let want = jacobians.is_some();
        let mut j_gravity = SMatrix::<f64, 6, 3>::zeros();
        let mut total = -generated::platform_weight_wrench(
            &rotation,
            &self.com_offset_m,
            self.platform_weight_n,
            want.then_some(&mut j_gravity),
        );
        let mut j_pose_total = SMatrix::<f64, 6, 6>::zeros();
        j_pose_total.fixed_columns_mut::<3>(0).copy_from(&(-j_gravity));
        for i in 0..n {
            let forces: Vector2<f64> = fixed(values, self.variables[1 + i]);
            let anchor: Vector3<f64> = fixed(values, self.variables[1 + n + i]);
            let (mut j_pose, mut j_forces, mut j_anchor) = (
                SMatrix::<f64, 6, 6>::zeros(),
                SMatrix::<f64, 6, 2>::zeros(),
                SMatrix::<f64, 6, 3>::zeros(),
            );
            total += generated::cable_wrench(
                &position,
                &rotation,
                &forces,
                &anchor,
                &self.attachments_m[i],
                EPSILON,
                want.then_some(&mut j_pose),
                want.then_some(&mut j_forces),
                want.then_some(&mut j_anchor),
            );
            if let Some(blocks) = jacobians.as_deref_mut() {
                j_pose_total += j_pose;
                blocks[1 + i].copy_from(&j_forces);
                blocks[1 + n + i].copy_from(&j_anchor);
            }
        }
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j_pose_total);
        }
        residual.copy_from_slice(total.as_slice());
        total.iter().all(|v| v.is_finite())
    }
}

/// A load cell at one cable's attachment (paper eq. 16):
/// `||(f_h, f_v)|| - f_m`, newtons. Block `[forces]`.
pub struct CableLoadCellFactor {
    variables: [VariableId; 1],
    measured_tension_n: f64,
    noise: Noise,
}

impl CableLoadCellFactor {
    /// The load cell on the cable with `forces`, reading `measured_tension_n`.
    pub fn new(forces: VariableId, measured_tension_n: f64, sigma_n: f64, kernel: RobustKernel) -> Self {
        Self {
            variables: [forces],
            measured_tension_n,
            noise: Noise::isotropic(1, sigma_n, kernel),
        }
    }
}

impl Factor for CableLoadCellFactor {
    factor_basics!();
    fn residual_dim(&self) -> usize {
        1
    }
    fn kind(&self) -> &'static str {
        "load_cell"
    }
    fn evaluate_into(&self, values: &Values, residual: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        let forces: Vector2<f64> = fixed(values, self.variables[0]);
        let mut j = SMatrix::<f64, 1, 2>::zeros();
        let want = jacobians.is_some();
        let r = generated::load_cell_residual(
            &forces,
            0.0,
            0.0,
            self.measured_tension_n,
            EPSILON,
            want.then_some(&mut j),
            None,
            None,
        );
        if let Some(blocks) = jacobians {
            blocks[0].copy_from(&j);
        }
        residual[0] = r[0];
        r[0].is_finite()
    }
}

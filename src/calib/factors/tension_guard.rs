//! The positivity guard of a pose's tensions (eq. 11), and where it takes
//! them from: the pose's shared catenary call or a call of its own.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector4};

use super::catenary_call::CatenaryCall;
use super::slots::{
    gather_anchors, pose_arguments, rows_to_cables, tension_argument, variable_list, CalibrationVariables,
    PoseVariables, SlotOrder, EPSILON,
};
use crate::generated;
use crate::graph::{evaluate_through_into, Factor, Noise, Values, VariableId};
use crate::model::robot::CABLE_COUNT;

/// Where a tension guard takes the tensions of eq. (11) from.
pub enum TensionSource {
    /// Rows 8..16 of the pose's shared catenary call (the paper's model).
    Shared(CatenaryCall),
    /// Its own call of [`generated::cable_tensions_from_reference`] (the extended model).
    Own {
        /// Robot constants in slot order.
        slots: Arc<SlotOrder>,
        /// Anchors and offsets.
        globals: CalibrationVariables,
        /// The pose's variables.
        pose: PoseVariables,
    },
}

impl TensionSource {
    fn pose(&self) -> (&PoseVariables, &CalibrationVariables, &SlotOrder) {
        match self {
            TensionSource::Shared(call) => (&call.pose, &call.globals, &call.slots),
            TensionSource::Own { slots, globals, pose } => (pose, globals, slots),
        }
    }

    /// The tensions (slot order), `[f_h0, f_v0, ..., f_h3, f_v3]`.
    fn tensions(&self, values: &Values) -> SVector<f64, 8> {
        match self {
            TensionSource::Shared(call) => call.read(values, false, |out| out.rows.fixed_rows::<8>(8).into_owned()),
            TensionSource::Own { .. } => self.own_tensions(values, None),
        }
    }

    /// The Jacobian of [`TensionSource::tensions`] (8 x 20, columns
    /// `[pose 6, tension 2, anchors 12]`).
    fn tension_jacobian(&self, values: &Values) -> SMatrix<f64, 8, 20> {
        let mut jacobian = SMatrix::<f64, 8, 20>::zeros();
        match self {
            TensionSource::Shared(call) => call.read(values, true, |out| {
                jacobian
                    .fixed_columns_mut::<6>(0)
                    .copy_from(&out.pose.fixed_rows::<8>(8));
                jacobian
                    .fixed_columns_mut::<2>(6)
                    .copy_from(&out.tension.fixed_rows::<8>(8));
                jacobian
                    .fixed_columns_mut::<12>(8)
                    .copy_from(&out.anchors.fixed_rows::<8>(8));
            }),
            TensionSource::Own { .. } => {
                self.own_tensions(values, Some(&mut jacobian));
            }
        }
        jacobian
    }

    /// [`generated::cable_tensions_from_reference`] for a guard without a
    /// shared call, with its Jacobian into `jacobian` if given.
    fn own_tensions(&self, values: &Values, jacobian: Option<&mut SMatrix<f64, 8, 20>>) -> SVector<f64, 8> {
        let (s, globals, pose) = match self {
            TensionSource::Own { slots, globals, pose } => (&**slots, globals, pose),
            TensionSource::Shared(call) => (&*call.slots, &call.globals, &call.pose),
        };
        let (position, rotation) = pose_arguments(values, pose.pose);
        let tension = tension_argument(values, pose.reference_tension);
        let anchors = gather_anchors(values, s, globals);
        let mut j_pose = SMatrix::<f64, 8, 6>::zeros();
        let mut j_tension = SMatrix::<f64, 8, 2>::zeros();
        let mut j_anchors = SMatrix::<f64, 8, 12>::zeros();
        let want = jacobian.is_some();
        let tensions = generated::cable_tensions_from_reference(
            &position,
            &rotation,
            &tension,
            &anchors,
            &s.attachments_m,
            &s.com_offset_m,
            s.platform_weight_n,
            EPSILON,
            want.then_some(&mut j_pose),
            want.then_some(&mut j_tension),
            want.then_some(&mut j_anchors),
        );
        if let Some(jacobian) = jacobian {
            jacobian.fixed_columns_mut::<6>(0).copy_from(&j_pose);
            jacobian.fixed_columns_mut::<2>(6).copy_from(&j_tension);
            jacobian.fixed_columns_mut::<12>(8).copy_from(&j_anchors);
        }
        tensions
    }
}

/// Positivity guard: `min(0, f_h,i - f_min)` for every cable of one pose,
/// with the tensions of eq. (11). Zero (inactive) while all cables are taut;
/// it only shapes the path of the solver. Undefined (`None`) once a cable
/// would push, so the solver never steps into a slack configuration.
pub struct TensionGuardFactor {
    variables: Vec<VariableId>,
    source: TensionSource,
    minimum_horizontal_tension_n: f64,
    noise: Noise,
}

impl TensionGuardFactor {
    /// A guard keeping every `f_h` from `source` above `minimum_horizontal_tension_n`, stiffness `sigma_n`.
    pub fn new(source: TensionSource, minimum_horizontal_tension_n: f64, sigma_n: f64) -> Self {
        let (pose, globals, _) = source.pose();
        Self {
            variables: variable_list(pose, globals, true, false),
            source,
            minimum_horizontal_tension_n,
            noise: Noise::gaussian(DVector::from_element(CABLE_COUNT, sigma_n)),
        }
    }
}

impl Factor for TensionGuardFactor {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        CABLE_COUNT
    }
    fn evaluate(&self, values: &Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        evaluate_through_into(self, values, jacobians)
    }
    fn evaluate_into(&self, values: &Values, out: &mut [f64], jacobians: Option<&mut [DMatrix<f64>]>) -> bool {
        // Values first: the Jacobian is needed only where a row is active
        // (rarely: the guard is zero while every cable is taut).
        let tensions = self.source.tensions(values);
        let (_, _, s) = self.source.pose();
        let mut residual = Vector4::zeros();
        let mut active = [false; CABLE_COUNT];
        for slot in 0..CABLE_COUNT {
            let f_h = tensions[2 * slot];
            if !(f_h.is_finite() && f_h > 0.0) {
                return false;
            }
            if f_h < self.minimum_horizontal_tension_n {
                residual[slot] = f_h - self.minimum_horizontal_tension_n;
                active[slot] = true;
            }
        }
        for (slot, &cable) in s.cables.iter().enumerate() {
            out[cable] = residual[slot];
        }
        let Some(blocks) = jacobians else {
            return true;
        };
        for block in blocks.iter_mut() {
            block.as_mut_slice().fill(0.0);
        }
        if !active.contains(&true) {
            return true;
        }
        let jacobian = self.source.tension_jacobian(values);
        for slot in (0..CABLE_COUNT).filter(|&k| active[k]) {
            let row = 2 * slot;
            for c in 0..6 {
                blocks[0][(slot, c)] = jacobian[(row, c)];
            }
            for c in 0..2 {
                blocks[1][(slot, c)] = jacobian[(row, 6 + c)];
            }
            for (anchor_slot, &cable) in s.cables.iter().enumerate() {
                for c in 0..3 {
                    blocks[2 + cable][(slot, c)] = jacobian[(row, 8 + 3 * anchor_slot + c)];
                }
            }
        }
        rows_to_cables(s, blocks);
        true
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "tension_guard"
    }
    /// Every block is zeroed first, then its active rows written.
    fn writes_every_jacobian_entry(&self) -> bool {
        true
    }
}

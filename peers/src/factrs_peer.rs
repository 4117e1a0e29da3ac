//! The factrs peer (issue 5): the benchmark problem of [`sagcal::experiments::benchmark`]
//! solved by factrs 0.3 (<https://github.com/rpl-cmu/factrs>), whose
//! Jacobians come from forward-mode dual numbers (`num_dual::DualVec`)
//! instead of sagcal's SymForce-generated analytic derivatives.
//!
//! # The residuals
//!
//! Every residual is written once, generic over factrs's `T: Numeric` (`f64`
//! for values, `DualVector<N>` for Jacobians), re-implementing
//! `codegen/cable_model.py` and `codegen/factors.py` term by term: rotation
//! matrix of the `[x, y, z, w]` quaternion (SymForce's formula), spans and
//! horizontal directions with `sqrt(dx^2 + dy^2 + epsilon)`, eq. (11) as the
//! two block-triangular 3x3 Cramer solves with the safe determinant
//! `det + sign_no_zero(det) epsilon`, the stable catenary
//! `L sinhc(lambda/2) cosh|sinh(asinh(u) + lambda/2)` with the shifted
//! `sinhc`, the pose prior's `[Log(R_prior^-1 R); p - p_prior]` with
//! sagcal's `rotation_log` (`v 4 atan(n / (1 + |w|)) / n`, `n = sqrt(v.v +
//! epsilon)`, quaternion flipped to `w >= 0`), and `|(f_h, f_v)|_epsilon -
//! f_m`. `epsilon` is sagcal's `10 f64::EPSILON`; `sign_no_zero` is taken on
//! the real part (zero derivative, as in the generated code's `signum`). No
//! sagcal residual code is called. Rows are in the robot's cable order, as
//! in sagcal's factors.
//!
//! # The graph
//!
//! Same factors (per pose: pose prior 6 rows, catenary length 4, attachment
//! height 4, reference tension 1; no tension guard, no robust kernels, plain
//! L2), same sigmas (from `problem.options`), same initial values
//! (`problem.initial`, `initial_poses`, `initial_tensions`), same cost
//! `sum 1/2 |r / sigma|^2` (factrs's `L2::loss(d2) = d2 / 2` of the whitened
//! residual, so `reported_final_cost` needs no conversion).
//!
//! What differs in the *variables*, because a factrs factor takes at most six
//! variables (`Residual1`..`Residual6`, `FactorBuilder::new1`..`new6`) and
//! sagcal's catenary factor reads ten:
//! - the four anchors are one `VectorVar<12>` (robot cable order, `[a1 x, y,
//!   z, a2 x, ...]`) and the four length offsets one `VectorVar4`. Both are
//!   Euclidean, so the unknowns, their retraction and the scalar sparsity
//!   pattern of the Jacobian are exactly sagcal's (every length factor reads
//!   all four anchors and offsets anyway); only the block grouping differs.
//! - the platform pose is `SO3` x `VectorVar3` (two variables). factrs's
//!   default (right) `oplus` is `(R Exp(dtheta), p + dp)`, exactly sagcal's
//!   retraction (`src/model/pose.rs`), so even the tangent convention and the
//!   Jacobian columns `[dtheta, dp, f_h, f_v, anchors, offsets]` coincide
//!   with sagcal's (the tests compare them entry by entry).
//!   factrs's `SO3::exp` below `|dtheta| = 1e-3` is the series `(dtheta/2,
//!   1 - |dtheta|^2/8)`, unit only to `|dtheta|^4/128`, and factrs never
//!   renormalises; the solution's quaternions are normalised when handed back
//!   (a change of < 1e-14).
//!
//! # Solver settings (`BenchmarkProblem::stopping()` -> factrs)
//!
//! | sagcal `LmParams` | factrs |
//! | --- | --- |
//! | `max_iterations` 100 | `BaseOptParams::max_iterations` 100 (`OptError::MaxIterations` carries the values; taken as the result) |
//! | `relative_cost_tolerance` 1e-10 (accepted step lowers the cost by less than 1e-10 of itself) | `error_tol_relative` 1e-10: factrs stops when `(E_old - E_new) / E_old <= 1e-10` after an accepted step, the same test |
//! | `gradient_tolerance` 1e-10 | not expressible (factrs has no gradient test) |
//! | `relative_step_tolerance` 1e-12 | not expressible (no step test) |
//! | `max_damping` 1e16 | `lambda_max` 1e16; beyond it factrs returns `OptError::FailedToStep` (sagcal: "damping exhausted", a converged stop); the values of the last accepted step are returned |
//! | `initial_damping` 1e-4 | not settable: factrs starts at `lambda = 1e-10` (private field) |
//! | - | `error_tol_absolute` 0 (factrs's default 1e-6 would stop on an absolute decrease sagcal does not test), `error_tol` 0 |
//!
//! The LM algorithm itself stays factrs's: damping `lambda diag(J^T J)`
//! (`diagonal_damping`, sagcal clamps the diagonal to [1e-6, 1e32]), a step
//! is accepted when the linear model decreases and the gain ratio exceeds
//! `min_model_fidelity` = 1e-3 (sagcal: > 0), `lambda` / 10 after an accepted
//! step and x 10 after a rejected one (sagcal: Nielsen's rule). factrs's
//! default sparse Cholesky (faer `Llt`, symbolic factorisation cached).
//!
//! Iterations are factrs's own iteration index (one linearisation each,
//! reported through an `OptObserver`), plus one when factrs gives up with
//! `FailedToStep` (it linearised once more before failing, as sagcal's count
//! includes its damping-exhausted iteration). The observer also keeps a copy
//! of the latest accepted values (factrs drops them on `FailedToStep`); that
//! copy is inside the timed region.
//!
//! # Verification (`cargo test --release --manifest-path peers/Cargo.toml factrs_peer`)
//!
//! At the initial values of `BenchmarkProblem::new(35, 7)` the f64
//! instantiation of every residual equals sagcal's factor residual to a few
//! ulps of the terms it is a difference of (the length residual, ~0.05 m,
//! is a difference of ~170 m numbers: 1.9e-12 of the residual, 6e-16 of the
//! length), and factrs's whitened dual-number Jacobians equal sagcal's
//! whitened analytic ones to < 2e-14 of their largest entry. factrs's final
//! cost equals sagcal's cost at factrs's solution and sagcal's own minimum to
//! ~1e-12 (35 and 1000 poses).
//!
//! Single-threaded: factrs's `rayon` feature is off (default features), so
//! its faer 0.23 is built without rayon (see `Cargo.lock`: faer 0.23.2 has
//! no rayon dependency) and `faer::get_global_parallelism()` is `Par::Seq`;
//! factrs itself has no threads.

use std::cell::{Cell, RefCell};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::rc::Rc;
use std::time::Instant;

use factrs::containers::{FactorBuilder, Graph, Values};
use factrs::linalg::{Const, ForwardProp, Numeric, Vector, Vector4, VectorX};
use factrs::noise::GaussianNoise;
use factrs::optimizers::{BaseOptParams, LevenMarquardt, LevenParams, OptError, OptObserver, Optimizer};
use factrs::residuals::{Residual1, Residual2, Residual4, Residual5};
use factrs::variables::{VectorVar, VectorVar2, VectorVar3, VectorVar4, SO3};

use sagcal::experiments::benchmark::BenchmarkProblem;
use sagcal::calib::{CableModel, OrientationPrior};
use sagcal::graph::RobustKernel;
use sagcal::io::measurements::PoseMeasurement;
use sagcal::model::pose::PlatformPose;
use sagcal::model::robot::{Robot, CABLE_COUNT};
use sagcal::solver::LmParams;

use crate::common::{PeerRun, Solution};

/// The `epsilon` of sagcal's generated code (`sagcal::calib::factors::EPSILON`).
const EPSILON: f64 = 10.0 * f64::EPSILON;

/// The four anchors as one variable, robot cable order.
type Anchors = VectorVar<12>;

/// Keys: `Q(k)` rotation and `P(k)` position of pose `k`, `F(k)` its
/// reference tension `[f_h, f_v]`, `A(0)` the anchors, `L(0)` the offsets.
mod sym {
    use super::Anchors;
    use factrs::assign_symbols;
    use factrs::variables::{VectorVar2, VectorVar3, VectorVar4, SO3};
    assign_symbols!(Q: SO3; P: VectorVar3; F: VectorVar2; A: Anchors; L: VectorVar4);
}
use sym::{A, F, L, P, Q};

// ------------------------------------------------------------------------
// The model, generic over factrs's numeric type.
// ------------------------------------------------------------------------

/// Robot constants in slot order (slot 0 = the reference cable).
#[derive(Debug, Clone)]
struct Platform {
    /// `cables[slot]` = the robot's cable in that slot.
    cables: [usize; CABLE_COUNT],
    /// Attachments, platform frame, slot order.
    attachments_m: [[f64; 3]; CABLE_COUNT],
    com_offset_m: [f64; 3],
    platform_weight_n: f64,
    cable_weight_n_per_m: f64,
}

impl Platform {
    fn new(robot: &Robot) -> Self {
        let mut cables = [robot.reference_cable; CABLE_COUNT];
        let mut slot = 1;
        for cable in 0..CABLE_COUNT {
            if cable != robot.reference_cable {
                cables[slot] = cable;
                slot += 1;
            }
        }
        let v = |x: &nalgebra::Vector3<f64>| [x[0], x[1], x[2]];
        Self {
            cables,
            attachments_m: std::array::from_fn(|s| v(&robot.attachments_m[cables[s]])),
            com_offset_m: v(&robot.com_offset_m),
            platform_weight_n: robot.platform_weight_n,
            cable_weight_n_per_m: robot.cable_weight_n_per_m,
        }
    }
}

/// `sign_no_zero(x)` of SymForce (`x.signum()` in the generated code), on the real part.
fn sign<T: Numeric>(x: T) -> f64 {
    if x.is_sign_negative() {
        -1.0
    } else {
        1.0
    }
}

/// `x + sign_no_zero(x) epsilon`: never zero.
fn safe_divisor<T: Numeric>(x: T) -> T {
    x + sign(x) * EPSILON
}

fn dot<T: Numeric>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross<T: Numeric>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `R` of the quaternion `[x, y, z, w]` (SymForce's `Rot3.to_rotation_matrix`).
fn rotation_matrix<T: Numeric>(q: &Vector4<T>) -> [[T; 3]; 3] {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    let one = T::from(1.0);
    [
        [
            one - (y * y + z * z) * 2.0,
            (x * y - z * w) * 2.0,
            (x * z + y * w) * 2.0,
        ],
        [
            (x * y + z * w) * 2.0,
            one - (x * x + z * z) * 2.0,
            (y * z - x * w) * 2.0,
        ],
        [
            (x * z - y * w) * 2.0,
            (y * z + x * w) * 2.0,
            one - (x * x + y * y) * 2.0,
        ],
    ]
}

/// `R b` for a constant `b`.
fn rotate<T: Numeric>(r: &[[T; 3]; 3], b: &[f64; 3]) -> [T; 3] {
    std::array::from_fn(|i| r[i][0] * b[0] + r[i][1] * b[1] + r[i][2] * b[2])
}

/// `A x = rhs` for `A = [c0 c1 c2]` by Cramer's rule with a safe determinant (`cable_model.solve3`).
fn solve3<T: Numeric>(c0: &[T; 3], c1: &[T; 3], c2: &[T; 3], rhs: &[T; 3]) -> [T; 3] {
    let c12 = cross(c1, c2);
    let det = safe_divisor(dot(c0, &c12));
    let x0 = dot(rhs, &c12);
    let x1 = dot(c0, &cross(rhs, c2));
    let x2 = dot(c0, &cross(c1, rhs));
    [x0 / det, x1 / det, x2 / det]
}

/// World attachments, spans and `(f_h, f_v)` of the four cables, slot order
/// (`factors._catenaries`: eq. 2 and eq. 5-11 via
/// `cable_model.cable_tensions_from_reference`).
struct Cables<T> {
    /// `R b_j`; the world attachment is `p + R b_j`.
    arms: [[T; 3]; CABLE_COUNT],
    position_z: T,
    spans: [T; CABLE_COUNT],
    tensions: [[T; 2]; CABLE_COUNT],
}

fn cables<T: Numeric>(
    platform: &Platform,
    rotation_xyzw: &Vector4<T>,
    position: &[T; 3],
    reference: [T; 2],
    anchors: &[[T; 3]; CABLE_COUNT],
) -> Cables<T> {
    let rot = rotation_matrix(rotation_xyzw);
    let arms: [[T; 3]; CABLE_COUNT] = std::array::from_fn(|j| rotate(&rot, &platform.attachments_m[j]));
    let mut spans = [T::from(0.0); CABLE_COUNT];
    // Horizontal unit vectors s_j (x, y) from the anchor towards the attachment.
    let mut dirs = [[T::from(0.0); 2]; CABLE_COUNT];
    for j in 0..CABLE_COUNT {
        // (R b - a) + p: the generated code's order of the sums (the spans are
        // ~170 m on the large robot, so an ulp here is visible in the residuals).
        let dx = arms[j][0] - anchors[j][0] + position[0];
        let dy = arms[j][1] - anchors[j][1] + position[1];
        let span = (dx * dx + dy * dy + EPSILON).sqrt();
        spans[j] = span;
        dirs[j] = [dx / span, dy / span];
    }
    let zero = T::from(0.0);
    let one = T::from(1.0);
    let c = rotate(&rot, &platform.com_offset_m);
    let weight = platform.platform_weight_n;
    // Rows [Fx, Fy, Mz] of the f_h column of eq. (8).
    let horizontal_column = |j: usize| -> [T; 3] {
        let (r, s) = (&arms[j], &dirs[j]);
        [-s[0], -s[1], -(r[0] * s[1] - r[1] * s[0])]
    };
    // Rows [Fz, Mx, My] of the f_v column.
    let vertical_column = |j: usize| -> [T; 3] { [one, arms[j][1], -arms[j][0]] };
    // Rows [Fz, Mx, My] of the f_h column.
    let horizontal_in_vertical_rows = |j: usize| -> [T; 3] {
        let (r, s) = (&arms[j], &dirs[j]);
        [zero, r[2] * s[1], -(r[2] * s[0])]
    };
    let [f_h_ref, f_v_ref] = reference;
    // Step 1: rows [Fx, Fy, Mz] (the wrench has none there).
    let h0 = horizontal_column(0);
    let rhs_h = [-(h0[0] * f_h_ref), -(h0[1] * f_h_ref), -(h0[2] * f_h_ref)];
    let f_h = solve3(
        &horizontal_column(1),
        &horizontal_column(2),
        &horizontal_column(3),
        &rhs_h,
    );
    // Step 2: rows [Fz, Mx, My], wrench W [1, c_y, -c_x].
    let mut rhs_v = [T::from(weight), c[1] * weight, -(c[0] * weight)];
    let hv0 = horizontal_in_vertical_rows(0);
    let v0 = vertical_column(0);
    for i in 0..3 {
        rhs_v[i] -= hv0[i] * f_h_ref + v0[i] * f_v_ref;
    }
    for (k, &f) in f_h.iter().enumerate() {
        let hv = horizontal_in_vertical_rows(k + 1);
        for i in 0..3 {
            rhs_v[i] -= hv[i] * f;
        }
    }
    let f_v = solve3(&vertical_column(1), &vertical_column(2), &vertical_column(3), &rhs_v);
    Cables {
        arms,
        position_z: position[2],
        spans,
        tensions: [[f_h_ref, f_v_ref], [f_h[0], f_v[0]], [f_h[1], f_v[1]], [f_h[2], f_v[2]]],
    }
}

/// Length and drop `a_z - z(L)` of a catenary (`cable_model.catenary_length`
/// / `catenary_drop`, eq. 1-4 in the stable product form).
///
/// The operations are ordered as in the generated code (`1/f_h` once, then
/// products), which keeps the f64 values within an ulp or so of sagcal's.
fn catenary<T: Numeric>(span: T, f_h: T, f_v: T, cable_weight_n_per_m: f64) -> (T, T) {
    let inverse_f_h = T::from(1.0) / f_h;
    let half_lambda = span * inverse_f_h * (0.5 * cable_weight_n_per_m);
    let y = safe_divisor(half_lambda);
    let sinhc = T::from(1.0) / y * y.sinh();
    let a = half_lambda + (inverse_f_h * f_v).asinh();
    (span * (a.cosh() * sinhc), span * (a.sinh() * sinhc))
}

/// The anchors of `anchors_robot` (`[a1 x, y, z, a2 x, ...]`) in slot order.
fn anchors_in_slots<T: Numeric>(platform: &Platform, anchors_robot: &Vector<12, T>) -> [[T; 3]; CABLE_COUNT] {
    std::array::from_fn(|s| {
        let c = platform.cables[s];
        [anchors_robot[3 * c], anchors_robot[3 * c + 1], anchors_robot[3 * c + 2]]
    })
}

// ------------------------------------------------------------------------
// factrs residuals.
// ------------------------------------------------------------------------

/// Catenary length (eq. 14): `l_C,i + l0_i - z_enc,i`, robot cable order.
#[derive(Debug, Clone)]
struct CatenaryLength {
    platform: Platform,
    /// Robot cable order.
    encoder_lengths_m: [f64; CABLE_COUNT],
}

#[factrs::mark]
impl Residual5 for CatenaryLength {
    type Differ = ForwardProp<<Self as Residual5>::DimIn>;
    type V1 = SO3;
    type V2 = VectorVar3;
    type V3 = VectorVar2;
    type V4 = Anchors;
    type V5 = VectorVar4;
    type DimIn = Const<24>;
    type DimOut = Const<4>;

    fn residual5<T: Numeric>(
        &self,
        rotation: SO3<T>,
        position: VectorVar3<T>,
        reference: VectorVar2<T>,
        anchors: VectorVar<12, T>,
        offsets: VectorVar4<T>,
    ) -> VectorX<T> {
        let pl = &self.platform;
        let p = [position.0[0], position.0[1], position.0[2]];
        let a = anchors_in_slots(pl, &anchors.0);
        let c = cables(pl, &rotation.xyzw, &p, [reference.0[0], reference.0[1]], &a);
        let mut out = VectorX::zeros(CABLE_COUNT);
        for s in 0..CABLE_COUNT {
            let cable = pl.cables[s];
            let (length, _) = catenary(c.spans[s], c.tensions[s][0], c.tensions[s][1], pl.cable_weight_n_per_m);
            out[cable] = length - self.encoder_lengths_m[cable] + offsets.0[cable];
        }
        out
    }
}

/// Attachment height (eq. 15): `(p + R b_i)_z - a_i,z + drop_i`, robot cable order.
#[derive(Debug, Clone)]
struct AttachmentHeight {
    platform: Platform,
}

#[factrs::mark]
impl Residual4 for AttachmentHeight {
    type Differ = ForwardProp<<Self as Residual4>::DimIn>;
    type V1 = SO3;
    type V2 = VectorVar3;
    type V3 = VectorVar2;
    type V4 = Anchors;
    type DimIn = Const<20>;
    type DimOut = Const<4>;

    fn residual4<T: Numeric>(
        &self,
        rotation: SO3<T>,
        position: VectorVar3<T>,
        reference: VectorVar2<T>,
        anchors: VectorVar<12, T>,
    ) -> VectorX<T> {
        let pl = &self.platform;
        let p = [position.0[0], position.0[1], position.0[2]];
        let a = anchors_in_slots(pl, &anchors.0);
        let c = cables(pl, &rotation.xyzw, &p, [reference.0[0], reference.0[1]], &a);
        let mut out = VectorX::zeros(CABLE_COUNT);
        for s in 0..CABLE_COUNT {
            let (_, drop) = catenary(c.spans[s], c.tensions[s][0], c.tensions[s][1], pl.cable_weight_n_per_m);
            out[pl.cables[s]] = drop + c.arms[s][2] - a[s][2] + c.position_z;
        }
        out
    }
}

/// Load cell (eq. 16): `|(f_h, f_v)| - f_m`.
#[derive(Debug, Clone)]
struct ReferenceTension {
    measured_tension_n: f64,
}

#[factrs::mark]
impl Residual1 for ReferenceTension {
    type Differ = ForwardProp<<Self as Residual1>::DimIn>;
    type V1 = VectorVar2;
    type DimIn = Const<2>;
    type DimOut = Const<1>;

    fn residual1<T: Numeric>(&self, reference: VectorVar2<T>) -> VectorX<T> {
        let (f_h, f_v) = (reference.0[0], reference.0[1]);
        VectorX::from_element(1, (f_h * f_h + f_v * f_v + EPSILON).sqrt() - self.measured_tension_n)
    }
}

/// Pose prior: `[Log(R_prior^-1 R); p - p_prior]` with sagcal's `rotation_log`.
#[derive(Debug, Clone)]
struct PosePrior {
    prior_rotation_xyzw: [f64; 4],
    prior_position_m: [f64; 3],
}

#[factrs::mark]
impl Residual2 for PosePrior {
    type Differ = ForwardProp<<Self as Residual2>::DimIn>;
    type V1 = SO3;
    type V2 = VectorVar3;
    type DimIn = Const<6>;
    type DimOut = Const<6>;

    fn residual2<T: Numeric>(&self, rotation: SO3<T>, position: VectorVar3<T>) -> VectorX<T> {
        let [px, py, pz, pw] = self.prior_rotation_xyzw;
        let q = &rotation.xyzw;
        let (qx, qy, qz, qw) = (q[0], q[1], q[2], q[3]);
        // conj(prior) * q (Hamilton product).
        let x = qx * pw - qw * px - qz * py + qy * pz;
        let y = qy * pw + qz * px - qw * py - qx * pz;
        let z = qz * pw - qy * px + qx * py - qw * pz;
        let w = qw * pw + qx * px + qy * py + qz * pz;
        // rotation_log: the same rotation with w >= 0, n = sqrt(v.v + epsilon).
        let sign = sign(w);
        let n = (x * x + y * y + z * z + EPSILON).sqrt();
        let scale = (n / (w * sign + 1.0)).atan() * (sign * 4.0) / n;
        let mut out = VectorX::zeros(6);
        out[0] = x * scale;
        out[1] = y * scale;
        out[2] = z * scale;
        for i in 0..3 {
            out[3 + i] = position.0[i] - self.prior_position_m[i];
        }
        out
    }
}

/// The four residuals of one pose.
struct PoseResiduals {
    prior: PosePrior,
    length: CatenaryLength,
    height: AttachmentHeight,
    tension: ReferenceTension,
}

fn pose_residuals(platform: &Platform, m: &PoseMeasurement) -> PoseResiduals {
    let prior = PlatformPose::from_roll_pitch_yaw_deg(m.position_m.into(), m.roll_deg, m.pitch_deg, m.yaw_deg);
    let q = prior.rotation_xyzw();
    PoseResiduals {
        prior: PosePrior {
            prior_rotation_xyzw: [q[0], q[1], q[2], q[3]],
            prior_position_m: m.position_m,
        },
        length: CatenaryLength {
            platform: platform.clone(),
            encoder_lengths_m: m.encoder_lengths_m,
        },
        height: AttachmentHeight {
            platform: platform.clone(),
        },
        tension: ReferenceTension {
            measured_tension_n: m.reference_tension_n,
        },
    }
}

// ------------------------------------------------------------------------
// The problem and the solve.
// ------------------------------------------------------------------------

/// Refuse problems this peer does not model (an extended model, robust kernels,
/// no orientation prior): the peer must see the benchmark's graph exactly.
fn check_supported(problem: &BenchmarkProblem) -> Result<(), String> {
    let o = &problem.options;
    if !problem.initial.effects.is_none() || !o.free_effects.is_empty() {
        return Err("factrs peer: the extended (effects) model is not implemented".into());
    }
    if o.model != CableModel::Catenary || o.orientation_prior != OrientationPrior::On {
        return Err("factrs peer: only the catenary model with the orientation prior is implemented".into());
    }
    if [o.robust.encoder, o.robust.load_cell, o.robust.pose_prior]
        .iter()
        .any(|k| *k != RobustKernel::None)
    {
        return Err("factrs peer: robust kernels are not implemented".into());
    }
    Ok(())
}

/// The factrs graph and initial values of the benchmark problem.
fn build(problem: &BenchmarkProblem) -> Result<(Graph, Values), String> {
    check_supported(problem)?;
    let robot = &problem.initial;
    let noise = &problem.options.noise;
    let platform = Platform::new(robot);
    let mut values = Values::new();
    let anchors: Vec<f64> = robot.anchors_m.iter().flat_map(|a| [a[0], a[1], a[2]]).collect();
    values.insert(A(0), VectorVar(Vector::<12>::from_column_slice(&anchors)));
    let o = &robot.length_offsets_m;
    values.insert(L(0), VectorVar4::new(o[0], o[1], o[2], o[3]));
    let mut graph = Graph::with_capacity(4 * problem.measurements.len());
    let (rot, pos) = (noise.orientation_sigma_rad, noise.position_sigma_m);
    for (k, m) in problem.measurements.iter().enumerate() {
        let k32 = u32::try_from(k).map_err(|_| "too many poses".to_string())?;
        let pose = &problem.initial_poses[k];
        let q = pose.rotation_xyzw();
        values.insert(Q(k32), SO3::from_xyzw(q[0], q[1], q[2], q[3]));
        let p = pose.position_m;
        values.insert(P(k32), VectorVar3::new(p[0], p[1], p[2]));
        let t = &problem.initial_tensions[k];
        values.insert(F(k32), VectorVar2::new(t.horizontal_n, t.vertical_n));
        let r = pose_residuals(&platform, m);
        graph.add_factor(
            FactorBuilder::<6>::new2(r.prior, Q(k32), P(k32))
                .noise(GaussianNoise::<6>::from_diag_sigmas(rot, rot, rot, pos, pos, pos))
                .build(),
        );
        graph.add_factor(
            FactorBuilder::<4>::new5(r.length, Q(k32), P(k32), F(k32), A(0), L(0))
                .noise(GaussianNoise::<4>::from_scalar_sigma(noise.encoder_sigma_m))
                .build(),
        );
        graph.add_factor(
            FactorBuilder::<4>::new4(r.height, Q(k32), P(k32), F(k32), A(0))
                .noise(GaussianNoise::<4>::from_scalar_sigma(problem.options.height_sigma_m))
                .build(),
        );
        graph.add_factor(
            FactorBuilder::<1>::new1(r.tension, F(k32))
                .noise(GaussianNoise::<1>::from_scalar_sigma(noise.load_cell_sigma_n))
                .build(),
        );
    }
    Ok((graph, values))
}

/// factrs's parameters for sagcal's stopping rule (see the module docs).
fn params(problem_stopping: &sagcal::solver::LmParams) -> LevenParams {
    LevenParams {
        lambda_max: problem_stopping.max_damping,
        base: BaseOptParams {
            max_iterations: problem_stopping.max_iterations,
            error_tol_relative: problem_stopping.relative_cost_tolerance,
            error_tol_absolute: 0.0,
            error_tol: 0.0,
        },
        ..LevenParams::default()
    }
}

/// Counts factrs's iterations and keeps the latest accepted values.
struct Progress {
    iterations: Rc<Cell<usize>>,
    latest: Rc<RefCell<Option<Values>>>,
}

impl OptObserver for Progress {
    fn on_step(&self, values: &Values, time: i64) {
        self.iterations.set(time.max(0) as usize);
        *self.latest.borrow_mut() = Some(values.clone());
    }
}

/// Why factrs stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stop {
    /// `Ok`: relative (or absolute) cost decrease below tolerance.
    Converged,
    /// `OptError::MaxIterations`.
    MaxIterations,
    /// `OptError::FailedToStep`: `lambda` exceeded `lambda_max`.
    FailedToStep,
}

/// A run with factrs's termination and cost at the start.
#[cfg_attr(not(test), allow(dead_code))]
struct Detailed {
    run: PeerRun,
    stop: Stop,
    initial_cost: f64,
    /// factrs's final values.
    values: Values,
}

/// The solution in sagcal's variables; `normalize`: the quaternions made
/// unit (factrs's may be off by ~1e-15, see the module docs).
fn solution_from(values: &Values, poses: usize, normalize: bool) -> Result<Solution, String> {
    let missing = |what: &str| format!("factrs peer: {what} missing from the solution");
    let a: &Anchors = values.get(A(0)).ok_or_else(|| missing("anchors"))?;
    let o: &VectorVar4 = values.get(L(0)).ok_or_else(|| missing("offsets"))?;
    let mut solution = Solution {
        anchors_m: std::array::from_fn(|i| [a.0[3 * i], a.0[3 * i + 1], a.0[3 * i + 2]]),
        length_offsets_m: std::array::from_fn(|i| o.0[i]),
        poses: Vec::with_capacity(poses),
        reference_tensions_n: Vec::with_capacity(poses),
    };
    for k in 0..poses as u32 {
        let q: &SO3 = values.get(Q(k)).ok_or_else(|| missing("a rotation"))?;
        let p: &VectorVar3 = values.get(P(k)).ok_or_else(|| missing("a position"))?;
        let f: &VectorVar2 = values.get(F(k)).ok_or_else(|| missing("a tension"))?;
        let quaternion = nalgebra::Quaternion::new(q.xyzw[3], q.xyzw[0], q.xyzw[1], q.xyzw[2]);
        let rotation = if normalize {
            nalgebra::UnitQuaternion::from_quaternion(quaternion)
        } else {
            nalgebra::UnitQuaternion::new_unchecked(quaternion)
        };
        solution.poses.push(PlatformPose::new(
            nalgebra::Vector3::new(p.0[0], p.0[1], p.0[2]),
            rotation,
        ));
        solution.reference_tensions_n.push([f.0[0], f.0[1]]);
    }
    Ok(solution)
}

fn solve_detailed(problem: &BenchmarkProblem, max_iterations: usize) -> Result<Detailed, String> {
    let setup_start = Instant::now();
    let (graph, values) = build(problem)?;
    let mut optimizer = LevenMarquardt::new(
        params(&LmParams {
            max_iterations,
            ..BenchmarkProblem::stopping()
        }),
        graph,
    );
    let iterations = Rc::new(Cell::new(0));
    let latest = Rc::new(RefCell::new(None));
    optimizer.add_observer(Progress {
        iterations: iterations.clone(),
        latest: latest.clone(),
    });
    let setup_seconds = setup_start.elapsed().as_secs_f64();

    let initial_cost = optimizer.graph().error(&values);
    let initial_values = values.clone();

    let solve_start = Instant::now();
    let result = catch_unwind(AssertUnwindSafe(|| optimizer.optimize(values)));
    let solve_seconds = solve_start.elapsed().as_secs_f64();

    let result = result.map_err(|e| {
        let what = e
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| e.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        format!("factrs panicked: {what}")
    })?;
    let mut linearisations = iterations.get();
    let (values, stop) = match result {
        Ok(values) => (values, Stop::Converged),
        Err(OptError::MaxIterations(values)) => (values, Stop::MaxIterations),
        Err(OptError::FailedToStep) => {
            linearisations += 1;
            let values = latest.borrow_mut().take().unwrap_or(initial_values);
            (values, Stop::FailedToStep)
        }
        Err(OptError::InvalidSystem) => return Err("factrs: invalid system".into()),
    };
    // factrs's own cost at its solution: sum 1/2 |r / sigma|^2 already (L2 loss = d2 / 2).
    let reported_final_cost = optimizer.graph().error(&values);
    let solution = solution_from(&values, problem.measurements.len(), true)?;
    Ok(Detailed {
        run: PeerRun {
            reported_final_cost,
            iterations: linearisations,
            solve_seconds,
            setup_seconds,
            solution,
        },
        stop,
        initial_cost,
        values,
    })
}

/// Solve the benchmark problem with factrs's Levenberg-Marquardt (see the module docs).
/// `max_iterations`: the linearisation budget (see `apex::solve`).
pub fn solve(problem: &BenchmarkProblem, max_iterations: usize) -> Result<PeerRun, String> {
    solve_detailed(problem, max_iterations).map(|d| d.run)
}

#[cfg(test)]
mod tests {
    use super::*;
    use factrs::containers::Key;
    use factrs::residuals::Residual;
    use sagcal::calib::CalibrationGraph;
    use sagcal::graph::{linearize_factor, VariableValue};

    fn set_solution(built: &mut CalibrationGraph, s: &Solution) {
        let values = &mut built.graph.values;
        for i in 0..CABLE_COUNT {
            values.set(
                built.globals.anchors[i],
                VariableValue::Vector(nalgebra::DVector::from_column_slice(&s.anchors_m[i])),
            );
            values.set(
                built.globals.length_offsets[i],
                VariableValue::Vector(nalgebra::DVector::from_element(1, s.length_offsets_m[i])),
            );
        }
        for (k, vars) in built.poses.iter().enumerate() {
            values.set(vars.pose, VariableValue::Pose(s.poses[k]));
            values.set(
                vars.reference_tension,
                VariableValue::Vector(nalgebra::DVector::from_column_slice(&s.reference_tensions_n[k])),
            );
        }
    }

    fn relative(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
    }

    /// (1) The generic residuals at `f64` equal sagcal's factor residuals at
    /// the initial values, and factrs's dual-number Jacobians (whitened)
    /// equal sagcal's analytic ones (same column order, see the module docs).
    ///
    /// Two relative measures: against the residual itself (meaningless for the
    /// height and tension factors, which the warm start zeroes: |r| < 5e-12
    /// m, 1.2e-13 N) and against the size of the terms it is a difference of
    /// (the encoder reading for a length, up to ~190 m on this robot;
    /// `max(|drop|, |a_z|, |p_z|)` for a height; `f_m` for the load cell;
    /// `|r|` for the prior). Two f64 evaluations of the same formula in a
    /// different operation order differ by a few ulps of those terms.
    #[test]
    fn residuals_and_jacobians_match_sagcal() {
        let problem = BenchmarkProblem::new(35, 7).unwrap();
        let built = problem.graph();
        let (graph, values) = build(&problem).unwrap();
        assert_eq!(graph.len(), built.graph.factors.len());
        let platform = Platform::new(&problem.initial);
        let kinds = [
            "pose_prior",
            "catenary_length",
            "attachment_height",
            "reference_tension",
        ];
        // Per kind: max |r|, max |dr| / |r|_inf, max |dr| / term scale,
        // max |whitened dr| (sigmas), max |dJ| / |J|_max (whitened Jacobians).
        let mut worst = [[0.0f64; 5]; 4];
        for (k, m) in problem.measurements.iter().enumerate() {
            let k32 = k as u32;
            let r = pose_residuals(&platform, m);
            let keys_pose: [Key; 2] = [Q(k32).into(), P(k32).into()];
            let keys_length: [Key; 5] = [Q(k32).into(), P(k32).into(), F(k32).into(), A(0).into(), L(0).into()];
            let keys_height: [Key; 4] = [Q(k32).into(), P(k32).into(), F(k32).into(), A(0).into()];
            let keys_tension: [Key; 1] = [F(k32).into()];
            let mine = [
                Residual::residual(&r.prior, &values, &keys_pose),
                Residual::residual(&r.length, &values, &keys_length),
                Residual::residual(&r.height, &values, &keys_height),
                Residual::residual(&r.tension, &values, &keys_tension),
            ];
            // The size of the height terms: drop, anchor height, platform height.
            let height_terms = {
                let q: &SO3 = values.get(Q(k32)).unwrap();
                let p: &VectorVar3 = values.get(P(k32)).unwrap();
                let f: &VectorVar2 = values.get(F(k32)).unwrap();
                let a: &Anchors = values.get(A(0)).unwrap();
                let anchors = anchors_in_slots(&platform, &a.0);
                let c = cables(
                    &platform,
                    &q.xyzw,
                    &[p.0[0], p.0[1], p.0[2]],
                    [f.0[0], f.0[1]],
                    &anchors,
                );
                (0..CABLE_COUNT)
                    .map(|s| {
                        let (_, drop) = catenary(
                            c.spans[s],
                            c.tensions[s][0],
                            c.tensions[s][1],
                            platform.cable_weight_n_per_m,
                        );
                        drop.abs().max(anchors[s][2].abs()).max(p.0[2].abs())
                    })
                    .fold(0.0f64, f64::max)
            };
            for (kind_index, kind) in kinds.iter().enumerate() {
                let index = 4 * k + kind_index;
                let factor = built.graph.factors[index].as_ref();
                assert_eq!(factor.kind(), *kind);
                let theirs = factor.evaluate(&built.graph.values, None).unwrap();
                let ours = &mine[kind_index];
                assert_eq!(ours.len(), theirs.len());
                let r_scale = theirs.amax();
                let diff = (ours - &theirs).amax();
                let term_scale = match kind_index {
                    0 => r_scale,
                    1 => m.encoder_lengths_m.iter().fold(0.0f64, |x, y| x.max(y.abs())),
                    2 => height_terms,
                    _ => m.reference_tension_n,
                };

                // factrs's linearisation (whitened, b = -r / sigma, A = J / sigma) vs sagcal's.
                let linear = graph.at(index).linearize(&values);
                let lin = linearize_factor(factor, &built.graph.values).unwrap();
                let whitened_diff = (0..lin.residual.len())
                    .map(|row| (-linear.b[row] - lin.residual[row]).abs())
                    .fold(0.0f64, f64::max);
                let ours_j = linear.a.mat();
                let cols: usize = lin.jacobians.iter().map(|j| j.ncols()).sum();
                assert_eq!(ours_j.ncols(), cols, "{kind}");
                assert_eq!(ours_j.nrows(), lin.residual.len(), "{kind}");
                let mut col = 0;
                let (mut j_diff, mut j_scale) = (0.0f64, 0.0f64);
                for block in &lin.jacobians {
                    for c in 0..block.ncols() {
                        for row in 0..block.nrows() {
                            j_diff = j_diff.max((ours_j[(row, col)] - block[(row, c)]).abs());
                            j_scale = j_scale.max(block[(row, c)].abs());
                        }
                        col += 1;
                    }
                }
                let w = &mut worst[kind_index];
                w[0] = w[0].max(r_scale);
                w[1] = w[1].max(diff / r_scale.max(f64::MIN_POSITIVE));
                w[2] = w[2].max(diff / term_scale);
                w[3] = w[3].max(whitened_diff);
                w[4] = w[4].max(j_diff / j_scale);
            }
        }
        for (kind_index, kind) in kinds.iter().enumerate() {
            let [r_max, rel_r, rel_terms, sigmas, jac] = worst[kind_index];
            eprintln!(
                "{kind:18}: max |r| {r_max:.2e}; max |dr| / |r| {rel_r:.2e}, / terms {rel_terms:.2e}, \
                 whitened {sigmas:.2e} sigma; Jacobians max |dJ| / |J|_max {jac:.2e}"
            );
        }
        for (kind_index, kind) in kinds.iter().enumerate() {
            let [_, rel_r, rel_terms, sigmas, jac] = worst[kind_index];
            assert!(
                rel_terms < 1e-14,
                "{kind}: residuals differ by {rel_terms:e} of their terms"
            );
            assert!(sigmas < 1e-8, "{kind}: whitened residuals differ by {sigmas:e}");
            assert!(jac < 1e-12, "{kind}: Jacobians differ by {jac:e} relative");
            // Meaningful where the residuals are not ~0 at the initial values.
            // The length residual (~0.05 m) is a difference of ~170 m numbers:
            // 1e-12 of it is 0.3 ulp of the length; 2.8 ulp are observed.
            match kind_index {
                0 => assert!(rel_r < 1e-12, "{kind}: residuals differ by {rel_r:e} relative"),
                1 => assert!(rel_r < 5e-12, "{kind}: residuals differ by {rel_r:e} relative"),
                _ => {}
            }
        }
    }

    fn compare(poses: usize, seed: u64) {
        let problem = BenchmarkProblem::new(poses, seed).unwrap();
        let detailed = solve_detailed(&problem, BenchmarkProblem::stopping().max_iterations).unwrap();
        let run = &detailed.run;

        // (2) factrs's reported cost equals sagcal's cost at factrs's solution.
        let mut at_factrs = problem.graph();
        let initial_sagcal = at_factrs.graph.cost(&at_factrs.graph.values).unwrap();
        set_solution(&mut at_factrs, &run.solution);
        let sagcal_cost_at_factrs = at_factrs.graph.cost(&at_factrs.graph.values).unwrap();
        // The same with factrs's quaternions as they are (not renormalised).
        let raw = solution_from(&detailed.values, poses, false).unwrap();
        let norm_error = raw
            .poses
            .iter()
            .map(|p| (p.rotation.quaternion().norm() - 1.0).abs())
            .fold(0.0f64, f64::max);
        set_solution(&mut at_factrs, &raw);
        let sagcal_cost_at_raw = at_factrs.graph.cost(&at_factrs.graph.values).unwrap();

        // (3) sagcal's own solve.
        let mut own = problem.graph();
        let start = Instant::now();
        let summary = sagcal::solver::optimize(&mut own.graph, &BenchmarkProblem::stopping()).unwrap();
        let sagcal_seconds = start.elapsed().as_secs_f64();

        eprintln!(
            "{poses} poses, seed {seed}: initial cost factrs {:.12e} / sagcal {initial_sagcal:.12e} (rel {:.1e})",
            detailed.initial_cost,
            relative(detailed.initial_cost, initial_sagcal)
        );
        eprintln!(
            "  factrs: final {:.12e}, {} iterations, stop {:?}, solve {:.3} s, setup {:.3} s",
            run.reported_final_cost, run.iterations, detailed.stop, run.solve_seconds, run.setup_seconds
        );
        eprintln!(
            "  sagcal cost at factrs's solution {sagcal_cost_at_factrs:.12e} (rel {:.1e}); \
             with factrs's raw quaternions (max ||q| - 1| {norm_error:.1e}) {sagcal_cost_at_raw:.12e} (rel {:.1e})",
            relative(run.reported_final_cost, sagcal_cost_at_factrs),
            relative(run.reported_final_cost, sagcal_cost_at_raw)
        );
        eprintln!(
            "  sagcal: final {:.12e}, {} iterations, {}, {sagcal_seconds:.3} s; factrs vs sagcal rel {:.1e}",
            summary.final_cost,
            summary.iterations,
            summary.termination,
            relative(run.reported_final_cost, summary.final_cost)
        );
        assert!(relative(detailed.initial_cost, initial_sagcal) < 1e-12);
        // Rounding noise of the two residual implementations (a few ulps of the
        // ~170 m lengths and drops, see the residual test): ~1e-12 relative.
        assert!(relative(run.reported_final_cost, sagcal_cost_at_factrs) < 5e-12);
        assert!(relative(run.reported_final_cost, summary.final_cost) < 1e-9);
    }

    /// (2) and (3) on 35 poses.
    #[test]
    fn solves_to_sagcal_minimum_35() {
        compare(35, 7);
    }

    /// The same on 1000 poses (~1 s).
    #[test]
    fn solves_to_sagcal_minimum_1000() {
        compare(1000, 7);
    }
}

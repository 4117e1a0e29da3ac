//! An independent high-fidelity static simulator: every cable a discretised
//! elastic chain running over a swivelling pulley.
//!
//! This module shares no formula with [`crate::model::catenary`] or
//! [`crate::model::statics`] (it only borrows their data types), so comparing
//! the two checks both.
//!
//! # Cable: a lumped elastic chain
//!
//! A cable's free span (pulley exit point to platform attachment) of unstretched
//! length `L_free` is cut into `n` straight segments of unstretched length
//! `l0 = L_free / n`. Each segment's weight `g_c l0` (`g_c` =
//! [`Robot::cable_weight_n_per_m`]) is lumped half on each of its end nodes:
//! interior nodes carry `g_c l0`, the half at the platform attachment (node 0)
//! loads the platform, the half at the pulley exit (node `n`) is carried by the
//! pulley. A segment of tension `T` has stretched length `l0 (1 + T / EA)`
//! (`EA = f64::INFINITY`: inextensible).
//!
//! **Discrete shooting.** Let `F` be the force the cable exerts on the platform
//! at its attachment (world frame, pointing up towards the anchor). Node 0's
//! balance gives the tension vector of segment 0 (the pull of segment 0 on node
//! 0), `T_0 = F + (g_c l0 / 2) z`, and every interior node `k` gives
//! `T_k = T_{k-1} + g_c l0 z`, so
//! ```text
//! T_k   = F + g_c l0 (k + 1/2) z                       k = 0 .. n-1
//! x_k+1 = x_k + l0 (T_k / |T_k| + T_k / EA)            x_0 = platform attachment
//! ```
//! exactly, with no integration error for the lumped chain. The pulley holds
//! node `n` with `T_n = T_{n-1} + (g_c l0 / 2) z = F + g_c L_free z`, the
//! tension at the exit. (`T_k` is the continuous cable's tension at the
//! segment's mid-length, so the chain is the midpoint rule applied to the
//! elastic catenary: it converges to it as `O(1/n^2)`.) A segment always points
//! along its tension: a chain cannot push, and the linear spring law is used
//! at any strain.
//!
//! # Pulley wrap geometry
//!
//! The pulley (radius `r`) swivels about the vertical axis through the anchor
//! `a` ([`Robot::anchors_m`]). The cable comes up from the winch along that
//! axis, enters the groove at `a`, wraps over the top and leaves tangentially at
//! the exit point `e` towards the platform. The pulley plane is the vertical
//! plane through the axis containing `u = -T_n,h / |T_n,h|` (the horizontal
//! direction from the anchor towards the free span; `T_n,h` is the horizontal
//! part of `T_n`); the centre is `a + r u`.
//!
//! The free span leaves the groove along `T_n`, the direction of the groove's
//! pull on node `n` (which balances the top segment's pull and node `n`'s half
//! weight). The top segment itself points along `T_{n-1}`, tilted from `T_n`
//! by `O(g_c l0 / |T|)`; tying the tangent to `T_n` keeps the exit point
//! second-order accurate in `1/n` (tying it to `T_{n-1}` would make it first
//! order). Both share the horizontal direction `u`.
//!
//! In plane coordinates (`xi` along `u`, `zeta` up, origin at `a`) the groove is
//! the circle of centre `(r, 0)`; the entry point `a` is at polar angle `pi`
//! (tangent straight up) and the cable runs clockwise, so at angle `phi` its
//! direction is `(sin phi, -cos phi)`. The free span leaves along
//! `-T_n / |T_n| = (h, -c)` with `h = |T_n,h| / |T_n| >= 0`, `c = T_n,z / |T_n|`,
//! hence `sin phi_e = h`, `cos phi_e = -c` and
//! ```text
//! e     = a + r [ (1 + c) u + h z ]
//! wrap  = pi - phi_e = pi - atan2(|T_n,h|, T_n,z)      in [0, pi]
//! ```
//! (a horizontal cable leaves at the top with a quarter turn of wrap, a
//! vertical one at `a + 2 r u` with a half turn). `1 + c` is evaluated as
//! `h^2 / (1 - c)` when `c < 0`, and `atan2` is finite for every non-zero
//! `T_n`, so a nearly horizontal or nearly vertical cable gives no NaN. A cable
//! within 1e-12 rad of vertical has no defined pulley plane: `u` then falls
//! back to the horizontal direction from the anchor to the attachment.
//! With `r = 0` the exit point is the anchor and the wrap is zero.
//!
//! The drum's paid-out length (unstretched, past the entry point) is the free
//! length plus the unstretched length on the groove, which is under the exit
//! tension: `paid_out = L_free + r wrap / (1 + |T_n| / EA)` (the weight of the
//! wrapped arc is carried by the pulley).
//!
//! # Robot equilibrium
//!
//! Unknowns: the platform pose (6, the tangent of [`PlatformPose::retract`]),
//! each cable's platform force `F_i` (3 x 4) and free length `L_free,i` (4).
//! Equations: each chain ends at its pulley exit point (3 x 4), each paid-out
//! length (4), and the platform's force and moment balance under its weight
//! `m_e g` at the centre of mass and the four `F_i` at the attachments (6).
//! The 22 x 22 system is solved by damped Newton with an analytic Jacobian,
//! row- and column-scaled, with a backtracking line search and a
//! Levenberg-Marquardt fallback, to machine precision; if that fails from every
//! start ([`solve_forward`]), a Newton homotopy `r(x) = (1 - t) r(x0)` follows
//! the solution from the start (`t = 0`) to the equilibrium (`t = 1`).
//!
//! With `n = 1` every cable is a straight rod (with half its weight at each
//! end). Fed the catenary's lengths, four nearly concurrent rods generally
//! cannot take up the cables' different sag excesses without a rod pushing or
//! the platform turning on its side, and the solver then reports
//! [`Error::NoEquilibrium`]; from `n = 2` on the sag is represented.
//!
//! [`equilibrium_residual_n`] re-checks a solution from the node positions
//! alone (spring law of every segment, node weights, platform wrench, pulley
//! tangency) without the shooting recursion. Recomputing a tension from a
//! stretch limits it to about `EA eps |x| / l0` newtons (`|x|` the size of the
//! node coordinates), its round-off floor.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::model::Catenary;
//! use sagcal::sim::discretised::{pulley_exit, solve_cable};
//! // One heavy cable between its attachment (origin) and an anchor 60 m away, 20 m up:
//! // the 200-element chain's pull on the attachment matches the catenary's (f_h, f_v)
//! // to O(1/n^2).
//! let cable = Catenary { span_m: 60.0, horizontal_tension_n: 300.0, vertical_tension_n: 150.0, cable_weight_n_per_m: 0.71 };
//! let anchor = Vector3::new(cable.span_m, 0.0, cable.drop_m());
//! let chain = solve_cable(&Vector3::zeros(), &anchor, cable.length_m(), 0.71, 200, f64::INFINITY)?;
//! assert!((chain.platform_force_n - Vector3::new(300.0, 0.0, 150.0)).norm() < 1e-3 * 300.0);
//! // A horizontal cable leaves its pulley at the top, a quarter turn of the groove past the entry.
//! let exit = pulley_exit(&Vector3::zeros(), 0.2, &Vector3::new(-500.0, 0.0, 0.0)).unwrap();
//! assert!((exit.exit_point_m - Vector3::new(0.2, 0.0, 0.2)).norm() < 1e-12);
//! assert!((exit.wrap_angle_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::f64::consts::PI;

use nalgebra::{Const, DMatrix, DVector, DimMin, Matrix3, RowVector3, SMatrix, SVector, Vector3, Vector6};

use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::Equilibrium;

/// Largest number of segments per cable accepted.
pub const MAX_SEGMENTS: usize = 1_000_000;

/// Unknowns of the four-cable robot: the pose (6) and each cable's force (3) and free length (1).
const UNKNOWNS: usize = unknowns(CABLE_COUNT);
#[cfg(test)]
type VectorN = SVector<f64, UNKNOWNS>;

/// Unknowns of a robot of `cables` cables ([`Problem`]).
pub(crate) const fn unknowns(cables: usize) -> usize {
    6 + 4 * cables
}

/// A cable within this angle (rad) of vertical has no defined pulley plane.
const VERTICAL_CABLE_RAD: f64 = 1e-12;
/// Scaled residual at which Newton stops.
const CONVERGED: f64 = 1e-15;
/// Scaled residual accepted as an equilibrium when Newton stagnates at round-off.
const ACCEPTED: f64 = 1e-10;

/// Settings of the discretised model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscretisedOptions {
    /// Straight segments per cable, `n >= 1`.
    pub segments: usize,
    /// Axial stiffness `EA` of every cable, newtons; `f64::INFINITY` for an inextensible cable.
    pub axial_stiffness_n: f64,
    /// Pulley radius `r`, metres (0: the cable leaves at the anchor point).
    pub pulley_radius_m: f64,
    /// Centre of mass in the platform frame replacing [`Robot::com_offset_m`], metres.
    pub com_offset_m: Option<Vector3<f64>>,
    /// Newton iterations per attempt.
    pub max_iterations: usize,
}

impl Default for DiscretisedOptions {
    /// 100 inextensible segments, no pulley radius, the robot's centre of mass, 100 iterations.
    fn default() -> Self {
        Self {
            segments: 100,
            axial_stiffness_n: f64::INFINITY,
            pulley_radius_m: 0.0,
            com_offset_m: None,
            max_iterations: 100,
        }
    }
}

/// Where the forward solver starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialGuess {
    /// Platform pose guess.
    pub pose: PlatformPose,
    /// Guess of each cable's force on the platform (world frame, newtons); `None`: computed from the pose.
    pub platform_forces_n: Option<[Vector3<f64>; CABLE_COUNT]>,
}

impl InitialGuess {
    /// Start at `pose`; the cable forces are found by solving each cable between the fixed ends.
    pub fn from_pose(pose: PlatformPose) -> Self {
        Self {
            pose,
            platform_forces_n: None,
        }
    }

    /// Start at a closed-form equilibrium: its pose and its tensions
    /// (`f_h` horizontally towards the anchor, `f_v` up) as the platform forces.
    pub fn from_closed_form(robot: &Robot, equilibrium: &Equilibrium) -> Self {
        let rotation = equilibrium.pose.rotation_matrix();
        let forces = std::array::from_fn(|i| {
            let attachment = equilibrium.pose.position_m + rotation * robot.attachments_m[i];
            let towards_anchor = horizontal_unit(&(robot.anchors_m[i] - attachment)).unwrap_or_else(Vector3::x);
            towards_anchor * equilibrium.tensions[i].horizontal_n + Vector3::z() * equilibrium.tensions[i].vertical_n
        });
        Self {
            pose: equilibrium.pose,
            platform_forces_n: Some(forces),
        }
    }
}

/// Where a cable leaves its pulley.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulleyExit {
    /// Exit point `e` (where the free span begins), world frame, metres.
    pub exit_point_m: Vector3<f64>,
    /// Pulley centre `a + r u`, world frame, metres.
    pub centre_m: Vector3<f64>,
    /// Angle of groove the cable wraps, entry to exit, radians in `[0, pi]`.
    pub wrap_angle_rad: f64,
}

/// One cable of a discretised equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscretisedCable {
    /// Chain nodes, world frame, metres: `n + 1` of them, from the platform attachment (0) to the pulley exit (`n`).
    pub nodes_m: Vec<Vector3<f64>>,
    /// Tension magnitude of each of the `n` segments, newtons (platform end first).
    pub segment_tensions_n: Vec<f64>,
    /// Force the cable exerts on the platform at its attachment, world frame, newtons.
    pub platform_force_n: Vector3<f64>,
    /// Tension vector at the pulley exit, `F + g_c L_free z`: the pull of the pulley on the free span, newtons.
    pub exit_tension_n: Vector3<f64>,
    /// Unstretched length of the free span (exit point to attachment), metres.
    pub free_length_m: f64,
    /// Groove angle wrapped by the cable, radians.
    pub wrap_angle_rad: f64,
    /// Pulley exit point, world frame, metres.
    pub exit_point_m: Vector3<f64>,
}

/// A static equilibrium of the discretised robot.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscretisedEquilibrium {
    /// Platform pose.
    pub pose: PlatformPose,
    /// The four cables, in cable order.
    pub cables: [DiscretisedCable; CABLE_COUNT],
    /// The paid-out (unstretched) lengths that were solved for, metres.
    pub paid_out_lengths_m: [f64; CABLE_COUNT],
    /// Newton iterations used (all attempts).
    pub iterations: usize,
    /// Worst force (N) or moment (N m) residual of [`equilibrium_residual_n`] at the solution.
    pub max_residual_n: f64,
}

/// Residuals of an equilibrium recomputed from its node positions ([`equilibrium_residual_n`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumResidual {
    /// Worst force imbalance at an interior chain node, newtons.
    pub node_force_n: f64,
    /// Platform force imbalance, newtons.
    pub platform_force_n: f64,
    /// Platform moment imbalance about the platform origin, newton metres.
    pub platform_moment_n_m: f64,
    /// Worst component of a pulley's pull on its exit node normal to the groove tangent, newtons.
    pub pulley_force_n: f64,
    /// Worst distance between a chain's last node and its pulley's exit point, metres.
    pub closure_m: f64,
    /// Worst distance of an exit point from its groove circle, metres.
    pub groove_m: f64,
    /// Worst mismatch of a segment's length against its tension (inextensible: against `l0`), metres.
    pub segment_length_m: f64,
    /// Worst paid-out length mismatch (free length + wrapped length - paid out), metres.
    pub paid_out_m: f64,
}

impl EquilibriumResidual {
    /// Worst force (N) or moment (N m) residual (NaN if any is NaN).
    pub fn max_n(&self) -> f64 {
        [
            self.node_force_n,
            self.platform_force_n,
            self.platform_moment_n_m,
            self.pulley_force_n,
        ]
        .into_iter()
        .fold(0.0, nan_max)
    }

    /// Worst geometric residual, metres (NaN if any is NaN).
    pub fn max_m(&self) -> f64 {
        [self.closure_m, self.groove_m, self.segment_length_m, self.paid_out_m]
            .into_iter()
            .fold(0.0, nan_max)
    }
}

fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b.abs())
    }
}

fn horizontal_unit(v: &Vector3<f64>) -> Option<Vector3<f64>> {
    let h = Vector3::new(v.x, v.y, 0.0);
    let norm = h.norm();
    (norm > 0.0 && norm.is_finite()).then(|| h / norm)
}

/// Pulley exit point and wrap angle for a cable whose tension at the exit is
/// `exit_tension_n` (pointing from the free span up into the pulley), see the
/// module docs. `None` for a zero or non-finite tension or radius. A cable
/// within 1e-12 rad of vertical swivels the pulley towards +x.
pub fn pulley_exit(anchor_m: &Vector3<f64>, pulley_radius_m: f64, exit_tension_n: &Vector3<f64>) -> Option<PulleyExit> {
    if !(pulley_radius_m.is_finite() && pulley_radius_m >= 0.0 && anchor_m.iter().all(|x| x.is_finite())) {
        return None;
    }
    pulley_geometry(anchor_m, pulley_radius_m, exit_tension_n, &Vector3::x()).map(|g| g.exit)
}

struct PulleyGeometry {
    exit: PulleyExit,
    /// d exit_point / d T_n
    d_exit: Matrix3<f64>,
    /// d wrap / d T_n
    d_wrap: RowVector3<f64>,
}

fn pulley_geometry(
    anchor: &Vector3<f64>,
    radius: f64,
    tension: &Vector3<f64>,
    fallback_direction: &Vector3<f64>,
) -> Option<PulleyGeometry> {
    let tau = tension.norm();
    if !(tau > 0.0 && tau.is_finite()) {
        return None;
    }
    let horizontal = Vector3::new(tension.x, tension.y, 0.0);
    let eta = horizontal.norm();
    let wrap = PI - eta.atan2(tension.z);
    if radius == 0.0 {
        return Some(PulleyGeometry {
            exit: PulleyExit {
                exit_point_m: *anchor,
                centre_m: *anchor,
                wrap_angle_rad: 0.0,
            },
            d_exit: Matrix3::zeros(),
            d_wrap: RowVector3::zeros(),
        });
    }
    let t = tension / tau;
    let h = eta / tau;
    let c = t.z;
    let one_plus_c = if c >= 0.0 { 1.0 + c } else { h * h / (1.0 - c) };
    let vertical = eta <= VERTICAL_CABLE_RAD * tau;
    let (u, h_hat) = if vertical {
        let u = horizontal_unit(fallback_direction).unwrap_or_else(Vector3::x);
        (u, -u)
    } else {
        let h_hat = horizontal / eta;
        (-h_hat, h_hat)
    };
    let z = Vector3::z();
    let exit_point = anchor + (u * one_plus_c + z * h) * radius;
    // d(1 + c)/dT = (z - c t)/tau; dh/dT = (h_hat - h t)/tau; du/dT = -(P_h - h_hat h_hat^T)/eta.
    let d_a = ((z - t * c) / tau).transpose();
    let d_h = ((h_hat - t * h) / tau).transpose();
    let mut d_exit = u * d_a + z * d_h;
    if !vertical {
        let mut projector = Matrix3::zeros();
        projector[(0, 0)] = 1.0;
        projector[(1, 1)] = 1.0;
        d_exit -= (projector - h_hat * h_hat.transpose()) * (one_plus_c / eta);
    }
    d_exit *= radius;
    // wrap = pi - atan2(eta, T_z): d wrap = -(T_z d eta - eta d T_z) / tau^2.
    let d_wrap = -((h_hat * tension.z - z * eta) / (tau * tau)).transpose();
    Some(PulleyGeometry {
        exit: PulleyExit {
            exit_point_m: exit_point,
            centre_m: anchor + u * radius,
            wrap_angle_rad: wrap,
        },
        d_exit,
        d_wrap,
    })
}

/// The sum of one chain's segment vectors (chain end minus chain start) and its derivatives.
struct Shot {
    span: Vector3<f64>,
    d_force: Matrix3<f64>,
    d_length: Vector3<f64>,
}

/// Discrete shooting (module docs) from the platform force `force` for a free length `length`.
fn shoot(force: &Vector3<f64>, length: f64, weight_per_m: f64, segments: usize, compliance: f64) -> Option<Shot> {
    let n = segments as f64;
    let l0 = length / n;
    let node_weight = weight_per_m * l0;
    let mut directions = Vector3::zeros();
    let mut tensions = Vector3::zeros();
    let mut projector_sum = Matrix3::zeros();
    let mut weighted_column = Vector3::zeros();
    for k in 0..segments {
        let level = k as f64 + 0.5;
        let tension = force + Vector3::new(0.0, 0.0, node_weight * level);
        let tau = tension.norm();
        if !(tau > 0.0 && tau.is_finite()) {
            return None;
        }
        let t = tension / tau;
        directions += t;
        tensions += tension;
        // (I - t t^T) / tau, symmetric.
        let inv = 1.0 / tau;
        let p = Matrix3::new(
            (1.0 - t.x * t.x) * inv,
            -t.x * t.y * inv,
            -t.x * t.z * inv,
            -t.y * t.x * inv,
            (1.0 - t.y * t.y) * inv,
            -t.y * t.z * inv,
            -t.z * t.x * inv,
            -t.z * t.y * inv,
            (1.0 - t.z * t.z) * inv,
        );
        projector_sum += p;
        weighted_column += p.column(2) * level;
    }
    let span = (directions + tensions * compliance) * l0;
    let d_force = (projector_sum + Matrix3::identity() * (n * compliance)) * l0;
    // d T_k / dL = g_c (k + 1/2) / n z;  sum_k (k + 1/2) = n^2 / 2.
    let d_length =
        span / length + (weighted_column + Vector3::z() * (compliance * 0.5 * n * n)) * (l0 * weight_per_m / n);
    if !(span.iter().all(|x| x.is_finite()) && d_force.iter().all(|x| x.is_finite())) {
        return None;
    }
    Some(Shot {
        span,
        d_force,
        d_length,
    })
}

/// One cable's physical constants and boundary conditions.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CableSpec {
    /// Anchor (pulley entry), world frame, metres.
    pub(crate) anchor: Vector3<f64>,
    /// Pulley radius, metres.
    pub(crate) radius: f64,
    /// Paid-out (unstretched) length, metres.
    pub(crate) paid_out: f64,
    /// Weight per metre, N/m.
    pub(crate) weight_per_m: f64,
    /// Straight segments of the chain.
    pub(crate) segments: usize,
    /// `1 / EA`, 1/N (0: inextensible).
    pub(crate) compliance: f64,
}

/// One cable's residuals (closure, paid-out length) and their derivatives.
struct CableBlock {
    closure: Vector3<f64>,
    length_residual: f64,
    d_closure_force: Matrix3<f64>,
    d_closure_length: Vector3<f64>,
    d_paid_force: RowVector3<f64>,
    d_paid_length: f64,
}

fn cable_block(spec: &CableSpec, start: &Vector3<f64>, force: &Vector3<f64>, length: f64) -> Option<CableBlock> {
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let shot = shoot(force, length, spec.weight_per_m, spec.segments, spec.compliance)?;
    let exit_tension = force + Vector3::z() * (spec.weight_per_m * length);
    let fallback = start - spec.anchor;
    let pulley = pulley_geometry(&spec.anchor, spec.radius, &exit_tension, &fallback)?;
    let closure = start + shot.span - pulley.exit.exit_point_m;
    let d_closure_force = shot.d_force - pulley.d_exit;
    let d_closure_length = shot.d_length - pulley.d_exit.column(2) * spec.weight_per_m;
    // Unstretched length on the groove: r wrap / (1 + |T_n| / EA).
    let tau = exit_tension.norm();
    let stretch = 1.0 + tau * spec.compliance;
    let wrapped = spec.radius * pulley.exit.wrap_angle_rad / stretch;
    let d_wrapped =
        (pulley.d_wrap * spec.radius - (exit_tension / tau).transpose() * (wrapped * spec.compliance)) / stretch;
    let d_wrapped = if spec.radius == 0.0 {
        RowVector3::zeros()
    } else {
        d_wrapped
    };
    Some(CableBlock {
        closure,
        length_residual: length + wrapped - spec.paid_out,
        d_closure_force,
        d_closure_length,
        d_paid_force: d_wrapped,
        d_paid_length: 1.0 + d_wrapped[2] * spec.weight_per_m,
    })
}

/// The whole robot's equilibrium equations for `C` cables and `U =
/// unknowns(C)` unknowns. Rows: each chain's closure (`3 C`), the platform's
/// force and moment balance (6), each paid-out length (`C`); columns: the
/// pose's tangent (6), each cable's platform force (`3 C`), each free length
/// (`C`). One generic code for every cable count: the four-cable robot's
/// equations are the instance `C = 4`.
#[derive(Clone, Copy)]
pub(crate) struct Problem<const C: usize, const U: usize> {
    pub(crate) cables: [CableSpec; C],
    pub(crate) attachments: [Vector3<f64>; C],
    pub(crate) com: Vector3<f64>,
    pub(crate) platform_weight: f64,
    length_scale: f64,
    force_scale: f64,
    moment_scale: f64,
    /// Subtracted from the residual: `(1 - t) r(x0)` on a Newton-homotopy path, else zero.
    offset: SVector<f64, U>,
}

/// The unknowns of a [`Problem`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct State<const C: usize> {
    pub(crate) pose: PlatformPose,
    pub(crate) forces: [Vector3<f64>; C],
    pub(crate) lengths: [f64; C],
}

impl<const C: usize, const U: usize> Problem<C, U>
where
    Const<U>: DimMin<Const<U>, Output = Const<U>>,
{
    /// The equations of `cables` (anchors, weights, paid-out lengths, ...)
    /// attached at `attachments` to a platform of weight `platform_weight`
    /// (N) with its centre of mass at `com` (platform frame, metres).
    pub(crate) fn new(
        cables: [CableSpec; C],
        attachments: [Vector3<f64>; C],
        com: Vector3<f64>,
        platform_weight: f64,
    ) -> Self {
        assert_eq!(U, unknowns(C), "a problem of {C} cables has {} unknowns", unknowns(C));
        let total_length: f64 = cables.iter().map(|c| c.paid_out).sum();
        let length_scale = (total_length / C as f64).max(1e-3);
        // The platform's weight and an upper bound of the cables' (their heaviest weight per metre).
        let heaviest = cables.iter().map(|c| c.weight_per_m).fold(0.0, f64::max);
        let force_scale = platform_weight + heaviest * total_length;
        let arm = attachments
            .iter()
            .chain(std::iter::once(&com))
            .map(|b| b.norm())
            .fold(0.0, f64::max)
            .max(1e-3);
        Problem {
            cables,
            attachments,
            com,
            platform_weight,
            length_scale,
            force_scale,
            moment_scale: force_scale * arm,
            offset: SVector::zeros(),
        }
    }

    fn evaluate(&self, state: &State<C>) -> Option<(SVector<f64, U>, SMatrix<f64, U, U>)> {
        crate::steps::tick();
        let mut r = SVector::<f64, U>::zeros();
        let mut j = SMatrix::<f64, U, U>::zeros();
        let (force_row, moment_row, length_row) = (3 * C, 3 * C + 3, 3 * C + 6);
        let rotation = *state.pose.rotation_matrix().matrix();
        let p = state.pose.position_m;
        let gravity = Vector3::new(0.0, 0.0, -self.platform_weight);
        let mut force_sum = gravity;
        let com_arm = rotation * self.com;
        let mut moment_sum = com_arm.cross(&gravity);
        // d(moment)/d(dtheta) of the weight: [g]x [R c]x R.
        let mut d_moment_rotation = gravity.cross_matrix() * com_arm.cross_matrix() * rotation;
        for i in 0..C {
            let arm = rotation * self.attachments[i];
            let start = p + arm;
            let force = state.forces[i];
            let block = cable_block(&self.cables[i], &start, &force, state.lengths[i])?;
            let (row, fcol, lcol) = (3 * i, 6 + 3 * i, 6 + 3 * C + i);
            r.fixed_rows_mut::<3>(row).copy_from(&block.closure);
            // d start / d dtheta = -[R b]x R; d start / d dp = I.
            j.fixed_view_mut::<3, 3>(row, 0)
                .copy_from(&(-arm.cross_matrix() * rotation));
            j.fixed_view_mut::<3, 3>(row, 3).copy_from(&Matrix3::identity());
            j.fixed_view_mut::<3, 3>(row, fcol).copy_from(&block.d_closure_force);
            j.fixed_view_mut::<3, 1>(row, lcol).copy_from(&block.d_closure_length);
            let lrow = length_row + i;
            r[lrow] = block.length_residual;
            j.fixed_view_mut::<1, 3>(lrow, fcol).copy_from(&block.d_paid_force);
            j[(lrow, lcol)] = block.d_paid_length;
            force_sum += force;
            moment_sum += arm.cross(&force);
            j.fixed_view_mut::<3, 3>(force_row, fcol)
                .copy_from(&Matrix3::identity());
            j.fixed_view_mut::<3, 3>(moment_row, fcol)
                .copy_from(&arm.cross_matrix());
            d_moment_rotation += force.cross_matrix() * arm.cross_matrix() * rotation;
        }
        r.fixed_rows_mut::<3>(force_row).copy_from(&force_sum);
        r.fixed_rows_mut::<3>(moment_row).copy_from(&moment_sum);
        j.fixed_view_mut::<3, 3>(moment_row, 0).copy_from(&d_moment_rotation);
        r -= self.offset;
        if !(r.iter().all(|x| x.is_finite()) && j.iter().all(|x| x.is_finite())) {
            return None;
        }
        Some((r, j))
    }

    fn residual_scales(&self) -> SVector<f64, U> {
        SVector::from_fn(|k, _| {
            if k < 3 * C {
                1.0 / self.length_scale
            } else if k < 3 * C + 3 {
                1.0 / self.force_scale
            } else if k < 3 * C + 6 {
                1.0 / self.moment_scale
            } else {
                1.0 / self.length_scale
            }
        })
    }

    fn unknown_scales(&self) -> SVector<f64, U> {
        SVector::from_fn(|k, _| match k {
            0..3 => 1.0,
            3..6 => self.length_scale,
            _ if k < 6 + 3 * C => self.force_scale,
            _ => self.length_scale,
        })
    }

    fn merit(&self, r: &SVector<f64, U>) -> f64 {
        r.component_mul(&self.residual_scales()).norm()
    }

    fn step(state: &State<C>, delta: &SVector<f64, U>) -> State<C> {
        let tangent = Vector6::from_fn(|k, _| delta[k]);
        State {
            pose: state.pose.retract(&tangent),
            forces: std::array::from_fn(|i| state.forces[i] + delta.fixed_rows::<3>(6 + 3 * i)),
            lengths: std::array::from_fn(|i| state.lengths[i] + delta[6 + 3 * C + i]),
        }
    }

    /// Damped Newton from `state`; `Ok` when the scaled residual reaches round-off.
    fn newton(&self, state: State<C>, max_iterations: usize) -> std::result::Result<(State<C>, usize), usize> {
        let row_scale = self.residual_scales();
        let col_scale = self.unknown_scales();
        let Some((mut r, mut j)) = self.evaluate(&state) else {
            return Err(0);
        };
        let mut state = state;
        let mut merit = self.merit(&r);
        for iteration in 1..=max_iterations {
            if merit <= CONVERGED {
                return Ok((state, iteration - 1));
            }
            // Scaled system (D_r J D_x) (D_x^-1 delta) = -D_r r.
            let scaled_j = SMatrix::<f64, U, U>::from_fn(|a, b| j[(a, b)] * row_scale[a] * col_scale[b]);
            let scaled_r = r.component_mul(&row_scale);
            let newton_step = scaled_j
                .lu()
                .solve(&(-scaled_r))
                .filter(|s| s.iter().all(|x| x.is_finite()));
            let mut accepted = None;
            // A full Newton step this small leaves an error of its square: converged.
            let mut converged = false;
            if let Some(scaled_step) = newton_step {
                let size = scaled_step.amax();
                let delta = scaled_step.component_mul(&col_scale);
                // Limit a step to a rotation of ~0.5 rad and length changes of half a length.
                let mut alpha: f64 = 1.0;
                let rotation = delta.fixed_rows::<3>(0).norm();
                if rotation > 0.5 {
                    alpha = alpha.min(0.5 / rotation);
                }
                for i in 0..C {
                    let dl = delta[6 + 3 * C + i].abs();
                    if dl > 0.5 * state.lengths[i] {
                        alpha = alpha.min(0.5 * state.lengths[i] / dl);
                    }
                }
                for _ in 0..40 {
                    let trial = Self::step(&state, &(delta * alpha));
                    if let Some((rt, jt)) = self.evaluate(&trial) {
                        let mt = self.merit(&rt);
                        if mt < (1.0 - 1e-4 * alpha) * merit || (size < 1e-13 && mt <= merit) {
                            converged = alpha == 1.0 && size < 1e-9 && mt < ACCEPTED;
                            accepted = Some((trial, rt, jt, mt));
                            break;
                        }
                    }
                    alpha *= 0.5;
                }
                if accepted.is_none() && size < 1e-12 && merit < ACCEPTED {
                    return Ok((state, iteration));
                }
            }
            if accepted.is_none() {
                accepted = self.levenberg_marquardt_step(&state, &scaled_j, &r, merit);
            }
            let Some((trial, rt, jt, mt)) = accepted else {
                return if merit < ACCEPTED {
                    Ok((state, iteration))
                } else {
                    Err(iteration)
                };
            };
            state = trial;
            r = rt;
            j = jt;
            merit = mt;
            if converged {
                return Ok((state, iteration));
            }
        }
        if merit < ACCEPTED {
            Ok((state, max_iterations))
        } else {
            Err(max_iterations)
        }
    }

    /// Newton homotopy `r(x) = (1 - t) r(x0)`, `t` from 0 to 1 with adaptive steps,
    /// for starts from which damped Newton alone fails.
    fn continuation(&self, start: State<C>, max_iterations: usize) -> std::result::Result<(State<C>, usize), usize> {
        let Some((r0, _)) = self.evaluate(&start) else {
            return Err(0);
        };
        let (mut state, mut t, mut dt, mut iterations) = (start, 0.0_f64, 0.125_f64, 0);
        while t < 1.0 {
            let next = (t + dt).min(1.0);
            let stage = Problem {
                offset: r0 * (1.0 - next),
                ..*self
            };
            match stage.newton(state, max_iterations.min(40)) {
                Ok((solution, used)) => {
                    iterations += used;
                    state = solution;
                    t = next;
                    dt = (dt * 2.0).min(0.5);
                }
                Err(used) => {
                    iterations += used;
                    dt *= 0.25;
                    if dt < 1e-4 {
                        return Err(iterations);
                    }
                }
            }
        }
        Ok((state, iterations))
    }

    /// Damped least-squares steps of growing damping, for when Newton's direction fails.
    #[allow(clippy::type_complexity)]
    fn levenberg_marquardt_step(
        &self,
        state: &State<C>,
        scaled_j: &SMatrix<f64, U, U>,
        r: &SVector<f64, U>,
        merit: f64,
    ) -> Option<(State<C>, SVector<f64, U>, SMatrix<f64, U, U>, f64)> {
        let row_scale = self.residual_scales();
        let col_scale = self.unknown_scales();
        let scaled_r = r.component_mul(&row_scale);
        let normal = scaled_j.transpose() * scaled_j;
        let gradient = scaled_j.transpose() * scaled_r;
        let base = normal.diagonal().amax().max(1e-300);
        let mut damping = 1e-8;
        while damping < 1e8 {
            let mut damped = normal;
            for k in 0..U {
                damped[(k, k)] += damping * base;
            }
            if let Some(step) = damped.cholesky().map(|c| -c.solve(&gradient)) {
                let trial = Self::step(state, &step.component_mul(&col_scale));
                if let Some((rt, jt)) = self.evaluate(&trial) {
                    let mt = self.merit(&rt);
                    if mt < merit {
                        return Some((trial, rt, jt, mt));
                    }
                }
            }
            damping *= 10.0;
        }
        None
    }
}

fn check_options(options: &DiscretisedOptions) -> Result<()> {
    if options.segments == 0 || options.segments > MAX_SEGMENTS {
        return Err(Error::InvalidInput(format!(
            "discretised cable: segments must be between 1 and {MAX_SEGMENTS}, got {}",
            options.segments
        )));
    }
    if options.axial_stiffness_n.is_nan() || options.axial_stiffness_n <= 0.0 {
        return Err(Error::InvalidInput(format!(
            "discretised cable: axial stiffness EA must be > 0 N (infinite: inextensible), got {}",
            options.axial_stiffness_n
        )));
    }
    if !(options.pulley_radius_m.is_finite() && options.pulley_radius_m >= 0.0) {
        return Err(Error::InvalidInput(format!(
            "discretised cable: pulley radius must be >= 0 m, got {}",
            options.pulley_radius_m
        )));
    }
    if let Some(com) = options.com_offset_m {
        if !com.iter().all(|x| x.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "discretised robot: centre of mass override is not finite: {:?}",
                com.as_slice()
            )));
        }
    }
    Ok(())
}

fn check_robot(robot: &Robot) -> Result<()> {
    let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
    if !(robot.anchors_m.iter().all(finite) && robot.attachments_m.iter().all(finite) && finite(&robot.com_offset_m)) {
        return Err(Error::InvalidInput("discretised robot: non-finite geometry".into()));
    }
    if !(robot.platform_weight_n.is_finite() && robot.platform_weight_n > 0.0) {
        return Err(Error::InvalidInput(format!(
            "discretised robot: platform weight must be > 0 N, got {}",
            robot.platform_weight_n
        )));
    }
    if !(robot.cable_weight_n_per_m.is_finite() && robot.cable_weight_n_per_m >= 0.0) {
        return Err(Error::InvalidInput(format!(
            "discretised robot: cable weight must be >= 0 N/m, got {}",
            robot.cable_weight_n_per_m
        )));
    }
    Ok(())
}

pub(crate) fn check_lengths(lengths: &[f64]) -> Result<()> {
    if let Some((i, l)) = lengths.iter().enumerate().find(|(_, l)| !(l.is_finite() && **l > 0.0)) {
        return Err(Error::InvalidInput(format!(
            "cable {}: paid-out length must be a positive number of metres, got {l}",
            i + 1
        )));
    }
    Ok(())
}

fn problem(
    robot: &Robot,
    options: &DiscretisedOptions,
    paid_out: &[f64; CABLE_COUNT],
) -> Problem<CABLE_COUNT, UNKNOWNS> {
    let compliance = 1.0 / options.axial_stiffness_n;
    let cables = std::array::from_fn(|i| CableSpec {
        anchor: robot.anchors_m[i],
        radius: options.pulley_radius_m,
        paid_out: paid_out[i],
        weight_per_m: robot.cable_weight_n_per_m,
        segments: options.segments,
        compliance,
    });
    let com = options.com_offset_m.unwrap_or(robot.com_offset_m);
    Problem::new(cables, robot.attachments_m, com, robot.platform_weight_n)
}

/// Newton for one cable between a fixed start point and its pulley: unknowns the
/// platform force and the free length, equations the closure and the paid-out length.
fn solve_single(
    spec: &CableSpec,
    start: &Vector3<f64>,
    force: Vector3<f64>,
    length: f64,
    max_iterations: usize,
) -> Option<(Vector3<f64>, f64, usize)> {
    let length_scale = spec.paid_out.max((spec.anchor - start).norm()).max(1e-3);
    let force_scale = force.norm().max(spec.weight_per_m * spec.paid_out).max(1e-6);
    let evaluate = |f: &Vector3<f64>, l: f64| -> Option<(nalgebra::Vector4<f64>, nalgebra::Matrix4<f64>)> {
        let block = cable_block(spec, start, f, l)?;
        let mut r = nalgebra::Vector4::zeros();
        let mut j = nalgebra::Matrix4::zeros();
        r.fixed_rows_mut::<3>(0).copy_from(&(block.closure / length_scale));
        r[3] = block.length_residual / length_scale;
        j.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(block.d_closure_force * (force_scale / length_scale)));
        j.fixed_view_mut::<3, 1>(0, 3).copy_from(&block.d_closure_length);
        j.fixed_view_mut::<1, 3>(3, 0)
            .copy_from(&(block.d_paid_force * (force_scale / length_scale)));
        j[(3, 3)] = block.d_paid_length;
        (r.iter().all(|x| x.is_finite()) && j.iter().all(|x| x.is_finite())).then_some((r, j))
    };
    let (mut f, mut l) = (force, length);
    let (mut r, mut j) = evaluate(&f, l)?;
    let mut merit = r.norm();
    for iteration in 1..=max_iterations {
        if merit <= CONVERGED {
            return Some((f, l, iteration - 1));
        }
        let step = j.lu().solve(&(-r)).filter(|s| s.iter().all(|x| x.is_finite()));
        let mut accepted = false;
        if let Some(step) = step {
            let df = Vector3::new(step[0], step[1], step[2]) * force_scale;
            let mut alpha: f64 = 1.0;
            if step[3].abs() > 0.5 * l / length_scale {
                alpha = 0.5 * l / length_scale / step[3].abs();
            }
            for _ in 0..60 {
                let (ft, lt) = (f + df * alpha, l + step[3] * length_scale * alpha);
                if let Some((rt, jt)) = evaluate(&ft, lt) {
                    let mt = rt.norm();
                    if mt < (1.0 - 1e-4 * alpha) * merit || (step.amax() < 1e-13 && mt <= merit) {
                        (f, l, r, j, merit, accepted) = (ft, lt, rt, jt, mt, true);
                        break;
                    }
                }
                alpha *= 0.5;
            }
        }
        if !accepted {
            return (merit < ACCEPTED).then_some((f, l, iteration));
        }
    }
    (merit < ACCEPTED).then_some((f, l, max_iterations))
}

/// A first guess of the force a cable of unstretched length `length` hanging
/// from `top` pulls `bottom` with: Peyrot and Goulois's starting point for
/// cable statics (a parabola whose sag matches the excess length), or along the
/// chord for a light or taut cable.
fn cable_force_guess(
    bottom: &Vector3<f64>,
    top: &Vector3<f64>,
    length: f64,
    weight_per_m: f64,
    compliance: f64,
) -> Vector3<f64> {
    let chord = top - bottom;
    let distance = chord.norm();
    let span = Vector3::new(chord.x, chord.y, 0.0).norm();
    let height = chord.z;
    let taut_tension = if compliance > 0.0 && distance > length {
        (distance / length - 1.0) / compliance
    } else {
        0.0
    };
    let along_chord = |tension: f64| chord / distance.max(1e-12) * tension;
    if weight_per_m == 0.0 || span < 1e-9 * length.max(distance) {
        let tension = taut_tension.max(1.0);
        return along_chord(tension) + Vector3::z() * (0.5 * weight_per_m * length);
    }
    let lambda: f64 = if length * length <= span * span + height * height {
        0.2
    } else {
        (3.0 * ((length * length - height * height) / (span * span) - 1.0)).sqrt()
    };
    let horizontal = (weight_per_m * span / (2.0 * lambda)).max(taut_tension * span / distance);
    let vertical_bottom = 0.5 * weight_per_m * (height / lambda.tanh() - length);
    let towards_top = Vector3::new(chord.x, chord.y, 0.0) / span;
    towards_top * horizontal + Vector3::z() * vertical_bottom
}

/// One cable hanging between two fixed points: `start_m` (a support the cable
/// pulls with the returned [`DiscretisedCable::platform_force_n`]) and `end_m`
/// (no pulley), unstretched length `unstretched_length_m`, weight
/// `cable_weight_n_per_m`, `segments` segments of stiffness `axial_stiffness_n`.
pub fn solve_cable(
    start_m: &Vector3<f64>,
    end_m: &Vector3<f64>,
    unstretched_length_m: f64,
    cable_weight_n_per_m: f64,
    segments: usize,
    axial_stiffness_n: f64,
) -> Result<DiscretisedCable> {
    let options = DiscretisedOptions {
        segments,
        axial_stiffness_n,
        ..DiscretisedOptions::default()
    };
    check_options(&options)?;
    if !(start_m.iter().chain(end_m.iter()).all(|x| x.is_finite())) {
        return Err(Error::InvalidInput(
            "discretised cable: end points must be finite".into(),
        ));
    }
    check_lengths(&[unstretched_length_m; CABLE_COUNT])?;
    if !(cable_weight_n_per_m.is_finite() && cable_weight_n_per_m >= 0.0) {
        return Err(Error::InvalidInput(format!(
            "discretised cable: weight must be >= 0 N/m, got {cable_weight_n_per_m}"
        )));
    }
    let spec = CableSpec {
        anchor: *end_m,
        radius: 0.0,
        paid_out: unstretched_length_m,
        weight_per_m: cable_weight_n_per_m,
        segments,
        compliance: 1.0 / axial_stiffness_n,
    };
    let guess = cable_force_guess(
        start_m,
        end_m,
        unstretched_length_m,
        cable_weight_n_per_m,
        spec.compliance,
    );
    let (force, length, _) = solve_single(&spec, start_m, guess, unstretched_length_m, 200).ok_or_else(|| {
        Error::NoEquilibrium(format!(
            "discretised cable of {unstretched_length_m} m between {:?} and {:?}: Newton did not converge",
            start_m.as_slice(),
            end_m.as_slice()
        ))
    })?;
    assemble_cable(&spec, start_m, &force, length)
        .ok_or_else(|| Error::NoEquilibrium("discretised cable: degenerate chain".into()))
}

/// The nodes and tensions of a solved chain.
fn assemble_cable(
    spec: &CableSpec,
    start: &Vector3<f64>,
    force: &Vector3<f64>,
    length: f64,
) -> Option<DiscretisedCable> {
    let n = spec.segments;
    let l0 = length / n as f64;
    let node_weight = spec.weight_per_m * l0;
    let mut nodes = Vec::with_capacity(n + 1);
    let mut segment_tensions = Vec::with_capacity(n);
    let mut offset = Vector3::zeros();
    nodes.push(*start);
    for k in 0..n {
        let tension = force + Vector3::new(0.0, 0.0, node_weight * (k as f64 + 0.5));
        let tau = tension.norm();
        offset += (tension / tau + tension * spec.compliance) * l0;
        nodes.push(start + offset);
        segment_tensions.push(tau);
    }
    let exit_tension = force + Vector3::z() * (spec.weight_per_m * length);
    let pulley = pulley_geometry(&spec.anchor, spec.radius, &exit_tension, &(start - spec.anchor))?;
    nodes
        .iter()
        .all(|x| x.iter().all(|v| v.is_finite()))
        .then_some(DiscretisedCable {
            nodes_m: nodes,
            segment_tensions_n: segment_tensions,
            platform_force_n: *force,
            exit_tension_n: exit_tension,
            free_length_m: length,
            wrap_angle_rad: pulley.exit.wrap_angle_rad,
            exit_point_m: pulley.exit.exit_point_m,
        })
}

/// Straight-cable statics at `pose`: tensions along the chords to the anchors
/// balancing the platform's wrench in the least-squares sense, plus half of each cable's weight.
fn straight_forces<const C: usize, const U: usize>(problem: &Problem<C, U>, pose: &PlatformPose) -> [Vector3<f64>; C] {
    let rotation = pose.rotation_matrix();
    let mut structure = DMatrix::<f64>::zeros(6, C);
    let mut chords = [Vector3::zeros(); C];
    for i in 0..C {
        let arm = rotation * problem.attachments[i];
        let chord = (problem.cables[i].anchor - pose.position_m - arm).normalize();
        chords[i] = chord;
        let column = arm.cross(&chord);
        for k in 0..3 {
            structure[(k, i)] = chord[k];
            structure[(k + 3, i)] = column[k];
        }
    }
    let com_arm = rotation * problem.com;
    let weight = Vector3::new(0.0, 0.0, problem.platform_weight);
    let moment = com_arm.cross(&weight);
    let wrench = Vector6::new(weight.x, weight.y, weight.z, moment.x, moment.y, moment.z);
    let share = problem.platform_weight / C as f64;
    let tensions = least_squares_tensions(&structure, &wrench).unwrap_or_else(|| DVector::from_element(C, share));
    std::array::from_fn(|i| {
        let tension = if tensions[i].is_finite() && tensions[i] > 0.0 {
            tensions[i]
        } else {
            share
        };
        chords[i] * tension + Vector3::z() * (0.5 * problem.cables[i].weight_per_m * problem.cables[i].paid_out)
    })
}

/// The least-squares (minimum-norm) solution of `structure t = wrench` by
/// the SVD. Four cables take the fixed-size 6 x 4 SVD the four-cable
/// simulator has always used (its starts, and so its results, unchanged to
/// the bit); other counts the dynamic one.
fn least_squares_tensions(structure: &DMatrix<f64>, wrench: &Vector6<f64>) -> Option<DVector<f64>> {
    if structure.ncols() == CABLE_COUNT {
        let fixed = SMatrix::<f64, 6, CABLE_COUNT>::from_column_slice(structure.as_slice());
        let solved = fixed.svd(true, true).solve(wrench, 1e-12).ok()?;
        return Some(DVector::from_column_slice(solved.as_slice()));
    }
    let solved = structure.clone().svd(true, true).solve(wrench, 1e-12).ok()?;
    Some(DVector::from_column_slice(solved.as_slice()))
}

/// Forward statics of the discretised robot: the four paid-out (unstretched)
/// lengths -> the static equilibrium near `guess`.
///
/// Starts, in order, from the guess's cable forces (if given), forces from
/// solving each cable alone between the guessed pose's attachment and its
/// pulley, and the straight-cable statics; damped Newton from each, then a
/// Newton homotopy (`r(x) = (1 - t) r(x0)`, `t`: 0 -> 1) from each. Fails with
/// [`Error::NoEquilibrium`] if none converges and with [`Error::InvalidInput`]
/// on bad input; never panics or returns NaN.
pub fn solve_forward(
    robot: &Robot,
    options: &DiscretisedOptions,
    paid_out_lengths_m: &[f64; CABLE_COUNT],
    guess: &InitialGuess,
) -> Result<DiscretisedEquilibrium> {
    check_options(options)?;
    check_robot(robot)?;
    check_lengths(paid_out_lengths_m)?;
    check_guess(guess)?;
    let problem = problem(robot, options, paid_out_lengths_m);
    // Free lengths start at the paid-out length minus a quarter turn of wrap.
    let lengths: [f64; CABLE_COUNT] = std::array::from_fn(|i| {
        let wrapped = 0.5 * PI * options.pulley_radius_m;
        if paid_out_lengths_m[i] > 2.0 * wrapped {
            paid_out_lengths_m[i] - wrapped
        } else {
            paid_out_lengths_m[i]
        }
    });
    let (solution, iterations) = newton_from_starts(
        &problem,
        options.max_iterations,
        &guess.pose,
        guess.platform_forces_n,
        lengths,
    );
    let state = solution.ok_or_else(|| {
        Error::NoEquilibrium(format!(
            "discretised robot ({} segments, EA {} N, pulley radius {} m): Newton did not converge from the pose at {:?} for paid-out lengths {:?} m",
            options.segments,
            options.axial_stiffness_n,
            options.pulley_radius_m,
            guess.pose.position_m.as_slice(),
            paid_out_lengths_m
        ))
    })?;
    let mut equilibrium = DiscretisedEquilibrium {
        pose: state.pose,
        cables: assemble_cables(&problem, &state)?
            .try_into()
            .map_err(|_| Error::NoEquilibrium("discretised robot: cable count".into()))?,
        paid_out_lengths_m: *paid_out_lengths_m,
        iterations,
        max_residual_n: 0.0,
    };
    let residual = residual_of(&problem, &equilibrium.pose, &equilibrium.cables);
    equilibrium.max_residual_n = residual.max_n();
    if !(equilibrium.max_residual_n.is_finite() && residual.max_m().is_finite()) {
        return Err(Error::NoEquilibrium(
            "discretised robot: non-finite residual at the solution".into(),
        ));
    }
    Ok(equilibrium)
}

/// The initial guess must be finite.
fn check_guess(guess: &InitialGuess) -> Result<()> {
    let pose_finite =
        guess.pose.position_m.iter().all(|x| x.is_finite()) && guess.pose.rotation.coords.iter().all(|x| x.is_finite());
    if !pose_finite {
        return Err(Error::InvalidInput(
            "discretised robot: initial pose is not finite".into(),
        ));
    }
    if let Some(forces) = &guess.platform_forces_n {
        if !forces.iter().all(|f| f.iter().all(|x| x.is_finite())) {
            return Err(Error::InvalidInput(
                "discretised robot: initial cable forces are not finite".into(),
            ));
        }
    }
    Ok(())
}

/// Damped Newton from each start in turn, then the Newton homotopy from
/// each (see [`solve_forward`]); the solution, if any, and the iterations
/// spent. Starts are computed only when the previous ones fail: the guess's
/// forces, then each cable solved alone between the guessed attachment and
/// its pulley (forces and free lengths), then the straight-cable statics.
pub(crate) fn newton_from_starts<const C: usize, const U: usize>(
    problem: &Problem<C, U>,
    max_iterations: usize,
    guess_pose: &PlatformPose,
    guess_forces: Option<[Vector3<f64>; C]>,
    lengths: [f64; C],
) -> (Option<State<C>>, usize)
where
    Const<U>: DimMin<Const<U>, Output = Const<U>>,
{
    let mut iterations = 0;
    let state = |(forces, lengths): ([Vector3<f64>; C], [f64; C])| State {
        pose: *guess_pose,
        forces,
        lengths,
    };
    let rotation = guess_pose.rotation_matrix();
    let single_cables = |iterations: &mut usize| {
        let mut forces = [Vector3::zeros(); C];
        let mut free_lengths = lengths;
        for i in 0..C {
            let start = guess_pose.position_m + rotation * problem.attachments[i];
            let spec = &problem.cables[i];
            let f0 = cable_force_guess(&start, &spec.anchor, lengths[i], spec.weight_per_m, spec.compliance);
            let (f, l, used) = solve_single(spec, &start, f0, lengths[i], max_iterations)?;
            *iterations += used;
            forces[i] = f;
            free_lengths[i] = l;
        }
        Some((forces, free_lengths))
    };
    let mut tried = Vec::new();
    // Damped Newton from each start in turn ...
    for strategy in 0..3 {
        let start = match strategy {
            0 => guess_forces.map(|forces| (forces, lengths)),
            1 => single_cables(&mut iterations),
            _ => Some((straight_forces(problem, guess_pose), lengths)),
        };
        let Some(start) = start else { continue };
        tried.push(start);
        match problem.newton(state(start), max_iterations) {
            Ok((found, used)) => return (Some(found), iterations + used),
            Err(used) => iterations += used,
        }
    }
    // ... then the Newton homotopy from each.
    for start in tried {
        match problem.continuation(state(start), max_iterations) {
            Ok((found, used)) => return (Some(found), iterations + used),
            Err(used) => iterations += used,
        }
    }
    (None, iterations)
}

/// The chains of a solved state, node by node, in cable order.
pub(crate) fn assemble_cables<const C: usize, const U: usize>(
    problem: &Problem<C, U>,
    state: &State<C>,
) -> Result<Vec<DiscretisedCable>> {
    let rotation = state.pose.rotation_matrix();
    (0..C)
        .map(|i| {
            let start = state.pose.position_m + rotation * problem.attachments[i];
            assemble_cable(&problem.cables[i], &start, &state.forces[i], state.lengths[i])
                .ok_or_else(|| Error::NoEquilibrium("discretised robot: degenerate chain at the solution".into()))
        })
        .collect()
}

/// An independent check of an equilibrium from its node positions.
///
/// Each segment's tension is recomputed from its length by the spring law
/// `T = EA (|x_k+1 - x_k| / l0 - 1)` (inextensible cables: the reported
/// [`DiscretisedCable::segment_tensions_n`], with the length error reported in
/// [`EquilibriumResidual::segment_length_m`]) and acts along the segment.
/// Checked: every interior node (`T_k d_k - T_k-1 d_k-1 - g_c l0 z = 0`), the
/// platform (weight at the centre of mass, each cable's pull `T_0 d_0 - g_c l0 / 2 z`
/// at its attachment), every exit node (the pulley's pull `T_n-1 d_n-1 + g_c l0 / 2 z`
/// must lie in the pulley plane and along the groove's tangent, with the pulley
/// centre found from the exit point) and the paid-out lengths.
pub fn equilibrium_residual_n(
    robot: &Robot,
    options: &DiscretisedOptions,
    equilibrium: &DiscretisedEquilibrium,
) -> EquilibriumResidual {
    residual_of(
        &problem(robot, options, &equilibrium.paid_out_lengths_m),
        &equilibrium.pose,
        &equilibrium.cables,
    )
}

/// [`equilibrium_residual_n`] of `cables` at `pose` for the equations of
/// `problem` (its cables' anchors, weights, stiffnesses, pulleys and
/// paid-out lengths, the platform's attachments, weight and centre of mass).
pub(crate) fn residual_of<const C: usize, const U: usize>(
    problem: &Problem<C, U>,
    pose: &PlatformPose,
    cables: &[DiscretisedCable],
) -> EquilibriumResidual {
    let rotation = pose.rotation_matrix();
    let origin = pose.position_m;
    let platform_weight = Vector3::new(0.0, 0.0, -problem.platform_weight);
    let mut force_sum = platform_weight;
    let mut moment_sum = (rotation * problem.com).cross(&platform_weight);
    let mut result = EquilibriumResidual {
        node_force_n: 0.0,
        platform_force_n: 0.0,
        platform_moment_n_m: 0.0,
        pulley_force_n: 0.0,
        closure_m: 0.0,
        groove_m: 0.0,
        segment_length_m: 0.0,
        paid_out_m: 0.0,
    };
    if cables.len() != C {
        return EquilibriumResidual {
            node_force_n: f64::NAN,
            ..result
        };
    }
    let worst = |slot: &mut f64, value: f64| *slot = nan_max(*slot, value);
    for (i, cable) in cables.iter().enumerate() {
        let spec = &problem.cables[i];
        let compliance = spec.compliance;
        let elastic = compliance > 0.0;
        let n = cable.nodes_m.len().saturating_sub(1);
        if n == 0 || cable.segment_tensions_n.len() != n {
            return EquilibriumResidual {
                node_force_n: f64::NAN,
                ..result
            };
        }
        let l0 = cable.free_length_m / n as f64;
        let node_weight = spec.weight_per_m * l0;
        // Segment tension vectors from the positions.
        let segment = |k: usize| -> Vector3<f64> {
            let chord = cable.nodes_m[k + 1] - cable.nodes_m[k];
            let length = chord.norm();
            let tension = if elastic {
                (length / l0 - 1.0) / compliance
            } else {
                cable.segment_tensions_n[k]
            };
            chord / length * tension
        };
        let mut previous = segment(0);
        for k in 0..n {
            let length = (cable.nodes_m[k + 1] - cable.nodes_m[k]).norm();
            let expected = if elastic {
                l0 * (1.0 + cable.segment_tensions_n[k] * compliance)
            } else {
                l0
            };
            worst(&mut result.segment_length_m, length - expected);
            if k > 0 {
                let current = segment(k);
                worst(
                    &mut result.node_force_n,
                    (current - previous - Vector3::z() * node_weight).norm(),
                );
                previous = current;
            }
        }
        // Platform end.
        let pull = segment(0) - Vector3::z() * (0.5 * node_weight);
        force_sum += pull;
        moment_sum += (cable.nodes_m[0] - origin).cross(&pull);
        let attachment = origin + rotation * problem.attachments[i];
        worst(&mut result.closure_m, (cable.nodes_m[0] - attachment).norm());
        // Pulley end.
        let exit = cable.exit_point_m;
        let anchor = spec.anchor;
        worst(&mut result.closure_m, (cable.nodes_m[n] - exit).norm());
        let pulley_pull = segment(n - 1) + Vector3::z() * (0.5 * node_weight);
        let wrapped_length = pulley_end(&mut result, cable, &anchor, spec.radius, compliance, &pulley_pull);
        worst(
            &mut result.paid_out_m,
            cable.free_length_m + wrapped_length - spec.paid_out,
        );
    }
    result.platform_force_n = nan_max(0.0, force_sum.norm());
    result.platform_moment_n_m = nan_max(0.0, moment_sum.norm());
    result
}

/// The pulley end of `cable` in [`equilibrium_residual_n`]: the exit point on
/// the groove, the pulley's pull `pulley_pull` in the pulley plane and along
/// the groove's tangent (worst values into `result`); returns the wrapped
/// length `r wrap / (1 + T c)` (zero without a pulley).
fn pulley_end(
    result: &mut EquilibriumResidual,
    cable: &DiscretisedCable,
    anchor: &Vector3<f64>,
    radius: f64,
    compliance: f64,
    pulley_pull: &Vector3<f64>,
) -> f64 {
    let worst = |slot: &mut f64, value: f64| *slot = nan_max(*slot, value);
    let exit = cable.exit_point_m;
    if radius > 0.0 {
        let from_anchor = exit - anchor;
        let u = horizontal_unit(&from_anchor)
            .or_else(|| horizontal_unit(&(cable.nodes_m[0] - anchor)))
            .unwrap_or_else(Vector3::x);
        let centre = anchor + u * radius;
        let radial = exit - centre;
        worst(&mut result.groove_m, radial.norm() - radius);
        let normal = u.cross(&Vector3::z());
        let radial_unit = radial / radial.norm();
        worst(&mut result.pulley_force_n, pulley_pull.dot(&radial_unit));
        worst(&mut result.pulley_force_n, pulley_pull.dot(&normal));
        // Polar angle of the exit point in the pulley plane; the wrap runs from pi down to it.
        let wrap = PI - radial.z.atan2(radial.dot(&u));
        radius * wrap / (1.0 + pulley_pull.norm() * compliance)
    } else {
        worst(&mut result.groove_m, (exit - anchor).norm());
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn numeric_jacobian(f: impl Fn(&Vector3<f64>) -> Vector3<f64>, x: &Vector3<f64>, h: Vector3<f64>) -> Matrix3<f64> {
        let mut j = Matrix3::zeros();
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = h[k];
            j.set_column(k, &((f(&(x + e)) - f(&(x - e))) / (2.0 * h[k])));
        }
        j
    }

    #[test]
    fn pulley_jacobians_match_central_differences() {
        let anchor = Vector3::new(1.0, -2.0, 30.0);
        for tension in [
            Vector3::new(-300.0, 120.0, 250.0),
            Vector3::new(40.0, -500.0, -60.0),
            Vector3::new(-0.01, 0.02, 800.0),
        ] {
            let g = pulley_geometry(&anchor, 0.4, &tension, &Vector3::x()).unwrap();
            // Horizontal steps small against the horizontal part, which sets the pulley plane.
            let eta = tension.x.hypot(tension.y);
            let h = Vector3::new(1e-6 * eta, 1e-6 * eta, 1e-6 * tension.z.abs().max(eta));
            let numeric = numeric_jacobian(
                |t| {
                    pulley_geometry(&anchor, 0.4, t, &Vector3::x())
                        .unwrap()
                        .exit
                        .exit_point_m
                },
                &tension,
                h,
            );
            assert!(
                (numeric - g.d_exit).norm() < 1e-7 * g.d_exit.norm().max(1e-3),
                "{numeric} {}",
                g.d_exit
            );
            let wrap = |t: &Vector3<f64>| {
                Vector3::repeat(
                    pulley_geometry(&anchor, 0.4, t, &Vector3::x())
                        .unwrap()
                        .exit
                        .wrap_angle_rad,
                )
            };
            let numeric = numeric_jacobian(wrap, &tension, h).row(0).into_owned();
            assert!(
                (numeric - g.d_wrap).norm() < 1e-7 * g.d_wrap.norm(),
                "{numeric} {}",
                g.d_wrap
            );
        }
    }

    #[test]
    fn cable_block_jacobians_match_central_differences() {
        for (radius, compliance) in [(0.0, 0.0), (0.3, 1e-5), (0.5, 0.0)] {
            let spec = CableSpec {
                anchor: Vector3::new(-125.0, -110.0, 48.0),
                radius,
                paid_out: 170.0,
                weight_per_m: 0.71,
                segments: 37,
                compliance,
            };
            let start = Vector3::new(3.0, 2.0, 10.0);
            let force = Vector3::new(-400.0, -350.0, 150.0);
            let length = 168.0;
            let b = cable_block(&spec, &start, &force, length).unwrap();
            let closure = |f: &Vector3<f64>| cable_block(&spec, &start, f, length).unwrap().closure;
            let numeric = numeric_jacobian(closure, &force, Vector3::repeat(1e-3));
            assert!((numeric - b.d_closure_force).norm() < 1e-7 * b.d_closure_force.norm());
            let paid =
                |f: &Vector3<f64>| Vector3::repeat(cable_block(&spec, &start, f, length).unwrap().length_residual);
            let numeric = numeric_jacobian(paid, &force, Vector3::repeat(1e-3))
                .row(0)
                .into_owned();
            assert!((numeric - b.d_paid_force).norm() <= 1e-7 * b.d_paid_force.norm().max(1e-9));
            let h = 1e-4;
            let plus = cable_block(&spec, &start, &force, length + h).unwrap();
            let minus = cable_block(&spec, &start, &force, length - h).unwrap();
            let numeric = (plus.closure - minus.closure) / (2.0 * h);
            assert!((numeric - b.d_closure_length).norm() < 1e-7 * b.d_closure_length.norm());
            let numeric = (plus.length_residual - minus.length_residual) / (2.0 * h);
            assert!((numeric - b.d_paid_length).abs() < 1e-8);
        }
    }

    #[test]
    fn robot_jacobian_matches_central_differences() {
        let robot = Robot::builtin("large").unwrap();
        let options = DiscretisedOptions {
            segments: 20,
            axial_stiffness_n: 2e5,
            pulley_radius_m: 0.3,
            com_offset_m: Some(Vector3::new(0.05, 0.0, -0.1)),
            max_iterations: 10,
        };
        let problem = problem(&robot, &options, &[170.0, 171.0, 169.0, 172.0]);
        let state = State {
            pose: PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(2.0, -3.0, 12.0), 3.0, -2.0, 10.0),
            forces: [
                Vector3::new(-400.0, -350.0, 150.0),
                Vector3::new(420.0, -340.0, 140.0),
                Vector3::new(380.0, 360.0, 160.0),
                Vector3::new(-390.0, 330.0, 155.0),
            ],
            lengths: [168.0, 169.0, 167.5, 170.0],
        };
        let (_, j) = problem.evaluate(&state).unwrap();
        let scales = problem.unknown_scales();
        for k in 0..UNKNOWNS {
            let h = 1e-6 * scales[k];
            let mut e = VectorN::zeros();
            e[k] = h;
            let (rp, _) = problem.evaluate(&Problem::step(&state, &e)).unwrap();
            let (rm, _) = problem.evaluate(&Problem::step(&state, &(-e))).unwrap();
            let numeric = (rp - rm) / (2.0 * h);
            let column = j.column(k);
            assert!(
                (numeric - column).norm() <= 1e-6 * column.norm().max(1e-6),
                "column {k}: {} vs {}",
                numeric.transpose(),
                column.transpose()
            );
        }
    }
}

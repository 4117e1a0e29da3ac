//! The generated residuals (`generated/`, from `codegen/`) against independent computations.
//!
//! * Every Jacobian of every generated function against central finite
//!   differences (5-point stencil), the pose perturbed through
//!   [`PlatformPose::retract`] and the other arguments additively, at random
//!   points of two regimes: the large robot (`robots/large.toml`) and the
//!   small robot (`robots/small.toml`). `extended_cable` is evaluated for the
//!   four cables of a point (spans and tensions from `cable_geometry` there)
//!   with compliance in [0, 2] 1/MN and pulley radius in [0, 0.3] m: both
//!   exactly 0 at a quarter of the points, one of them 0 at two other quarters.
//! * The values against hand-written Rust: eq. (11) against a 6x6 LU solve of
//!   the full statics `J^T f = w`, the catenary length and drop against
//!   [`Catenary`], the straight cable, the load cell and the pose prior;
//!   `extended_cable` against [`Catenary`] without effects, Irvine's first
//!   order elastic catenary, the spring `l (1 - k T)` of a massless cable and
//!   a massless cable's pulley exit in closed form.
//! * The massless limit `g_c = 0`.

use nalgebra::{DMatrix, DVector, Matrix3x4, SMatrix, SVector, UnitQuaternion, Vector2, Vector3, Vector4, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sagcal::generated;
use sagcal::model::{Catenary, PlatformPose, Robot};

#[path = "common/generated_calls.rs"]
mod calls;

use calls::{dynamic, extended_blocks, Point, M};

/// SymForce's default epsilon (`sym::kDefaultEpsilon`).
const EPSILON: f64 = 10.0 * f64::EPSILON;
/// Random points per regime.
const SAMPLES: usize = 120;
/// `max |analytic - fd| <= TOLERANCE * max(1, max |fd|)` per Jacobian block.
const TOLERANCE: f64 = 1e-6;

/// Sampling ranges of one regime.
struct Regime {
    name: &'static str,
    robot: Robot,
    x_m: f64,
    y_m: f64,
    z_m: (f64, f64),
    max_angle_deg: f64,
    horizontal_tension_n: (f64, f64),
    vertical_tension_n: (f64, f64),
    /// Random displacement of each anchor coordinate, metres.
    anchor_jitter_m: f64,
}

fn large() -> Regime {
    Regime {
        name: "large",
        robot: Robot::builtin("large").unwrap(),
        x_m: 30.0,
        y_m: 30.0,
        z_m: (0.0, 25.0),
        max_angle_deg: 5.0,
        horizontal_tension_n: (400.0, 1000.0),
        vertical_tension_n: (30.0, 200.0),
        anchor_jitter_m: 1.0,
    }
}

fn small() -> Regime {
    Regime {
        name: "small",
        robot: Robot::builtin("small").unwrap(),
        x_m: 3.0,
        y_m: 1.0,
        z_m: (3.0, 18.0),
        max_angle_deg: 5.0,
        horizontal_tension_n: (10.0, 30.0),
        vertical_tension_n: (2.0, 15.0),
        anchor_jitter_m: 0.1,
    }
}

/// The robot's cable indices in slot order: the reference cable first, then the others.
fn slot_order(robot: &Robot) -> [usize; 4] {
    let mut order = [robot.reference_cable; 4];
    let mut next = 1;
    for cable in 0..4 {
        if cable != robot.reference_cable {
            order[next] = cable;
            next += 1;
        }
    }
    order
}

fn random_rotation(rng: &mut ChaCha8Rng, max_angle_deg: f64) -> UnitQuaternion<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let angle = rng.random_range(0.0..max_angle_deg).to_radians();
    UnitQuaternion::from_scaled_axis(axis.normalize() * angle)
}

fn random_point(regime: &Regime, rng: &mut ChaCha8Rng) -> Point {
    let robot = &regime.robot;
    let order = slot_order(robot);
    let jitter = regime.anchor_jitter_m;
    let anchors_m = Matrix3x4::from_columns(&order.map(|c| {
        robot.anchors_m[c]
            + Vector3::new(
                rng.random_range(-jitter..jitter),
                rng.random_range(-jitter..jitter),
                rng.random_range(-jitter..jitter),
            )
    }));
    let attachments_m = Matrix3x4::from_columns(&order.map(|c| robot.attachments_m[c]));
    let position = Vector3::new(
        rng.random_range(-regime.x_m..regime.x_m),
        rng.random_range(-regime.y_m..regime.y_m),
        rng.random_range(regime.z_m.0..regime.z_m.1),
    );
    let pose = PlatformPose::new(position, random_rotation(rng, regime.max_angle_deg));
    let prior_tangent = Vector6::new(
        rng.random_range(-0.05..0.05),
        rng.random_range(-0.05..0.05),
        rng.random_range(-0.05..0.05),
        rng.random_range(-0.1..0.1),
        rng.random_range(-0.1..0.1),
        rng.random_range(-0.1..0.1),
    );
    let reference_tension_n = Vector2::new(
        rng.random_range(regime.horizontal_tension_n.0..regime.horizontal_tension_n.1),
        rng.random_range(regime.vertical_tension_n.0..regime.vertical_tension_n.1),
    );
    Point {
        pose,
        reference_tension_n,
        anchors_m,
        attachments_m,
        com_offset_m: robot.com_offset_m,
        platform_weight_n: robot.platform_weight_n,
        cable_weight_n_per_m: robot.cable_weight_n_per_m,
        length_offsets_m: Vector4::from_fn(|_, _| rng.random_range(-2.0..2.0)),
        encoder_lengths_m: Vector4::from_fn(|_, _| rng.random_range(5.0..200.0)),
        prior: pose.retract(&prior_tangent),
        measured_tension_n: reference_tension_n.norm() + rng.random_range(-5.0..5.0),
        // Filled by `with_effects` (its own generator, so that the points above do not change).
        cable_spans_m: Vector4::zeros(),
        cable_horizontal_tensions_n: Vector4::zeros(),
        cable_vertical_tensions_n: Vector4::zeros(),
        axial_compliance_per_mn: 0.0,
        pulley_radius_m: 0.0,
        inverse_segments_squared: 0.0,
        load_cell_bias_n: 0.0,
        load_cell_gain_error: 0.0,
        localiser_mount_rad: Vector3::zeros(),
    }
}

/// `point` with the arguments of the extended model's functions: the cables' spans and
/// tensions from `cable_geometry` at the point, and effect parameters drawn by `rng`:
/// compliance in [0, 2] 1/MN, pulley radius in [0, 0.3] m, where `index % 4` selects
/// both 0 (the inextensible catenary from the anchor point), compliance 0, radius 0 or
/// neither, load-cell bias in [-5, 5] N and gain error in [-0.05, 0.05].
fn with_effects(mut point: Point, index: usize, rng: &mut ChaCha8Rng) -> Point {
    let geometry = geometry(&point).0;
    for j in 0..4 {
        point.cable_spans_m[j] = geometry[4 * j];
        point.cable_horizontal_tensions_n[j] = geometry[4 * j + 1];
        point.cable_vertical_tensions_n[j] = geometry[4 * j + 2];
    }
    let compliance = rng.random_range(0.0..=2.0);
    let radius = rng.random_range(0.0..=0.3);
    point.axial_compliance_per_mn = if index % 4 < 2 { 0.0 } else { compliance };
    point.pulley_radius_m = if index % 2 == 0 { 0.0 } else { radius };
    point.load_cell_bias_n = rng.random_range(-5.0..5.0);
    point.load_cell_gain_error = rng.random_range(-0.05..0.05);
    // A chain of 5 to 50 elements on every third point, the smooth cable elsewhere
    // (drawn last, so that the draws above do not change).
    let elements: f64 = rng.random_range(5.0..50.0);
    point.inverse_segments_squared = if index % 3 == 1 {
        1.0 / (elements * elements)
    } else {
        0.0
    };
    // A mount of up to 5 degrees per axis, zero on every fifth point (drawn last).
    let mount = Vector3::from_fn(|_, _| rng.random_range(-5f64..5.0).to_radians());
    point.localiser_mount_rad = if index % 5 == 0 { Vector3::zeros() } else { mount };
    point
}

/// The differentiated argument blocks.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Block {
    Pose,
    ReferenceTension,
    Anchors,
    /// The attachments in the platform frame (`cable_geometry`'s `attachments_m`).
    Attachments,
    LengthOffsets,
    ComOffset,
    /// The four cables' spans (`extended_cable`'s `span_m`, one column per slot).
    Span,
    /// The four cables' `f_h` (`extended_cable`'s `horizontal_tension_n`).
    HorizontalTension,
    /// The four cables' `f_v` (`extended_cable`'s `vertical_tension_n`).
    VerticalTension,
    AxialCompliance,
    PulleyRadius,
    /// `1/n^2` of the segmented cable.
    InverseSegmentsSquared,
    LoadCellBias,
    LoadCellGain,
    /// The localiser's mounting rotation vector (`mounted_pose_prior_residual`).
    LocaliserMount,
    /// The platform's weight (`cable_geometry`'s `platform_weight_n`).
    PlatformWeight,
    /// The cables' weight per metre (`extended_cable`'s `cable_weight_n_per_m`).
    CableWeight,
}

impl Block {
    fn dimension(self) -> usize {
        match self {
            Block::Pose => 6,
            Block::ReferenceTension => 2,
            Block::Anchors | Block::Attachments => 12,
            Block::LengthOffsets => 4,
            Block::ComOffset | Block::LocaliserMount => 3,
            Block::Span | Block::HorizontalTension | Block::VerticalTension => 4,
            Block::AxialCompliance
            | Block::PulleyRadius
            | Block::InverseSegmentsSquared
            | Block::LoadCellBias
            | Block::LoadCellGain
            | Block::PlatformWeight
            | Block::CableWeight => 1,
        }
    }

    /// Finite-difference step of tangent coordinate `k` at `point`.
    fn step(self, k: usize, point: &Point) -> f64 {
        match self {
            Block::Pose if k < 3 => 1e-4,
            Block::Pose => 1e-3,
            Block::ReferenceTension => 1e-4 * point.reference_tension_n[k].abs().max(1.0),
            Block::Anchors | Block::LengthOffsets => 1e-3,
            Block::Attachments => 1e-4,
            Block::ComOffset => 1e-4,
            Block::Span => 1e-4 * point.cable_spans_m[k].abs().max(1.0),
            Block::HorizontalTension => 1e-4 * point.cable_horizontal_tensions_n[k].abs().max(1.0),
            Block::VerticalTension => 1e-4 * point.cable_vertical_tensions_n[k].abs().max(1.0),
            Block::AxialCompliance | Block::LoadCellBias => 1e-3,
            Block::PulleyRadius | Block::LoadCellGain => 1e-4,
            Block::InverseSegmentsSquared => 1e-4,
            Block::LocaliserMount => 1e-4,
            Block::PlatformWeight => 1e-4 * point.platform_weight_n.abs().max(1.0),
            Block::CableWeight => 1e-4 * point.cable_weight_n_per_m.abs().max(1e-2),
        }
    }

    /// `point` moved by `t` along tangent coordinate `k` of this block.
    fn perturb(self, point: &Point, k: usize, t: f64) -> Point {
        let mut moved = point.clone();
        match self {
            Block::Pose => {
                let mut tangent = Vector6::zeros();
                tangent[k] = t;
                moved.pose = point.pose.retract(&tangent);
            }
            Block::ReferenceTension => moved.reference_tension_n[k] += t,
            Block::Anchors => moved.anchors_m[(k % 3, k / 3)] += t,
            Block::Attachments => moved.attachments_m[(k % 3, k / 3)] += t,
            Block::LengthOffsets => moved.length_offsets_m[k] += t,
            Block::ComOffset => moved.com_offset_m[k] += t,
            Block::Span => moved.cable_spans_m[k] += t,
            Block::HorizontalTension => moved.cable_horizontal_tensions_n[k] += t,
            Block::VerticalTension => moved.cable_vertical_tensions_n[k] += t,
            Block::AxialCompliance => moved.axial_compliance_per_mn += t,
            Block::PulleyRadius => moved.pulley_radius_m += t,
            Block::InverseSegmentsSquared => moved.inverse_segments_squared += t,
            Block::LoadCellBias => moved.load_cell_bias_n += t,
            Block::LoadCellGain => moved.load_cell_gain_error += t,
            Block::LocaliserMount => moved.localiser_mount_rad[k] += t,
            Block::PlatformWeight => moved.platform_weight_n += t,
            Block::CableWeight => moved.cable_weight_n_per_m += t,
        }
        moved
    }
}

/// Value and Jacobians (in the order of `blocks`) of one generated function.
type Evaluation = (DVector<f64>, Vec<DMatrix<f64>>);

struct Function {
    name: &'static str,
    blocks: &'static [Block],
    evaluate: fn(&Point) -> Evaluation,
}

/// Every Jacobian starts as NaN: the generated code must overwrite every entry.
fn nan<const R: usize, const C: usize>() -> M<R, C> {
    SMatrix::from_element(f64::NAN)
}

fn column<const R: usize>(value: SVector<f64, R>) -> DVector<f64> {
    DVector::from_column_slice(value.as_slice())
}

fn tensions(p: &Point) -> Evaluation {
    let mut j = (nan(), nan(), nan());
    let value = calls::tensions(p, Some(&mut j));
    (column(value), vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)])
}

fn catenary_length(p: &Point) -> Evaluation {
    let mut j = (nan(), nan(), nan(), nan());
    let value = calls::catenary_length(p, Some(&mut j));
    (
        column(value),
        vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2), dynamic(&j.3)],
    )
}

fn catenary_cable(p: &Point) -> Evaluation {
    let mut j = (nan(), nan(), nan(), nan());
    let value = calls::catenary_cable(p, Some(&mut j));
    (
        column(value),
        vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2), dynamic(&j.3)],
    )
}

fn attachment_height(p: &Point) -> Evaluation {
    let mut j = (nan(), nan(), nan());
    let value = calls::attachment_height(p, Some(&mut j));
    (column(value), vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)])
}

fn reference_tension(p: &Point) -> Evaluation {
    let mut j = nan();
    let value = calls::reference_tension(p, Some(&mut j));
    (column(value), vec![dynamic(&j)])
}

fn pose_prior(p: &Point) -> Evaluation {
    let mut j = nan();
    let value = calls::pose_prior(p, Some(&mut j));
    (column(value), vec![dynamic(&j)])
}

fn mounted_pose_prior(p: &Point) -> Evaluation {
    let mut j = (nan(), nan());
    let value = calls::mounted_pose_prior(p, Some(&mut j));
    (column(value), vec![dynamic(&j.0), dynamic(&j.1)])
}

fn rigid_length(p: &Point) -> Evaluation {
    let mut j = (nan(), nan(), nan());
    let value = calls::rigid_length(p, Some(&mut j));
    (column(value), vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)])
}

fn geometry(p: &Point) -> Evaluation {
    let mut j = (nan(), nan(), nan(), nan(), nan(), nan());
    let value = calls::geometry(p, Some(&mut j));
    (column(value), calls::geometry_blocks(&j))
}

/// `extended_cable` of the four slots stacked: `[paid_out_0, drop_0, paid_out_1, ...]` (8).
///
/// The per-cable blocks (span, `f_h`, `f_v`) are block diagonal, 8x4, from the 2x1 Jacobians of
/// each slot; the compliance and radius are shared, 8x1.
fn extended(p: &Point) -> Evaluation {
    let mut j = [(); 4].map(|_| (nan(), nan(), nan(), nan(), nan(), nan(), nan()));
    let value = calls::extended(p, Some(&mut j));
    (column(value), extended_blocks(&j))
}

fn load_cell(p: &Point) -> Evaluation {
    let mut j = (nan(), nan(), nan());
    let value = calls::load_cell(p, Some(&mut j));
    (column(value), vec![dynamic(&j.0), dynamic(&j.1), dynamic(&j.2)])
}

const FUNCTIONS: [Function; 11] = [
    Function {
        name: "cable_tensions_from_reference",
        blocks: &[Block::Pose, Block::ReferenceTension, Block::Anchors],
        evaluate: tensions,
    },
    Function {
        name: "catenary_length_residual",
        blocks: &[
            Block::Pose,
            Block::ReferenceTension,
            Block::Anchors,
            Block::LengthOffsets,
        ],
        evaluate: catenary_length,
    },
    Function {
        name: "attachment_height_residual",
        blocks: &[Block::Pose, Block::ReferenceTension, Block::Anchors],
        evaluate: attachment_height,
    },
    Function {
        name: "catenary_cable_residuals",
        blocks: &[
            Block::Pose,
            Block::ReferenceTension,
            Block::Anchors,
            Block::LengthOffsets,
        ],
        evaluate: catenary_cable,
    },
    Function {
        name: "reference_tension_residual",
        blocks: &[Block::ReferenceTension],
        evaluate: reference_tension,
    },
    Function {
        name: "pose_prior_residual",
        blocks: &[Block::Pose],
        evaluate: pose_prior,
    },
    Function {
        name: "mounted_pose_prior_residual",
        blocks: &[Block::Pose, Block::LocaliserMount],
        evaluate: mounted_pose_prior,
    },
    Function {
        name: "rigid_length_residual",
        blocks: &[Block::Pose, Block::Anchors, Block::LengthOffsets],
        evaluate: rigid_length,
    },
    Function {
        name: "cable_geometry",
        blocks: &[
            Block::Pose,
            Block::ReferenceTension,
            Block::Anchors,
            Block::Attachments,
            Block::ComOffset,
            Block::PlatformWeight,
        ],
        evaluate: geometry,
    },
    Function {
        name: "extended_cable",
        blocks: &[
            Block::Span,
            Block::HorizontalTension,
            Block::VerticalTension,
            Block::AxialCompliance,
            Block::PulleyRadius,
            Block::InverseSegmentsSquared,
            Block::CableWeight,
        ],
        evaluate: extended,
    },
    Function {
        name: "load_cell_residual",
        blocks: &[Block::ReferenceTension, Block::LoadCellBias, Block::LoadCellGain],
        evaluate: load_cell,
    },
];

/// Central 5-point finite-difference Jacobian of `function` with respect to `block`.
///
/// Each column is evaluated with the steps `h, h/10, h/100, h/1000` (`h` from
/// [`Block::step`]) and the estimate of the two consecutive steps that agree best
/// is kept: large steps suffer from truncation where the tensions of eq. (11) are
/// sensitive to the pose, small ones from rounding.
fn finite_difference(function: &Function, block: Block, point: &Point) -> DMatrix<f64> {
    let rows = (function.evaluate)(point).0.len();
    let mut jacobian = DMatrix::zeros(rows, block.dimension());
    for k in 0..block.dimension() {
        let at = |t: f64| (function.evaluate)(&block.perturb(point, k, t)).0;
        let estimates: Vec<DVector<f64>> = (0..4)
            .map(|i| {
                let h = block.step(k, point) / 10f64.powi(i);
                (at(-2.0 * h) - at(2.0 * h) + (at(h) - at(-h)) * 8.0) / (12.0 * h)
            })
            .collect();
        let best = (0..3)
            .min_by(|&a, &b| {
                let spread = |i: usize| (&estimates[i] - &estimates[i + 1]).amax();
                spread(a).total_cmp(&spread(b))
            })
            .unwrap();
        jacobian.set_column(k, &estimates[best + 1]);
    }
    jacobian
}

/// Worst case of one Jacobian block over the points of a regime.
#[derive(Default, Clone, Copy)]
struct Worst {
    error: f64,
    scale: f64,
    ratio: f64,
    sample: usize,
}

/// `max |analytic - fd| / max(1, max |fd|)` of every block of every function over `points`.
fn worst_jacobian_errors(points: &[Point]) -> Vec<(&'static str, Block, Worst)> {
    let mut worst = Vec::new();
    for function in &FUNCTIONS {
        for (b, &block) in function.blocks.iter().enumerate() {
            let mut w = Worst::default();
            for (sample, point) in points.iter().enumerate() {
                let analytic = &(function.evaluate)(point).1[b];
                assert!(
                    analytic.iter().all(|x| x.is_finite()),
                    "{} d/d{block:?}: non-finite entry at sample {sample}",
                    function.name
                );
                let fd = finite_difference(function, block, point);
                assert!(
                    fd.iter().all(|x| x.is_finite()),
                    "{} d/d{block:?}: non-finite finite difference at sample {sample}",
                    function.name
                );
                let error = (analytic - &fd).amax();
                let scale = fd.amax().max(1.0);
                // A NaN anywhere counts as the worst possible agreement.
                let ratio = if error.is_nan() { f64::INFINITY } else { error / scale };
                if ratio > w.ratio || sample == 0 {
                    w = Worst {
                        error,
                        scale,
                        ratio,
                        sample,
                    };
                }
            }
            worst.push((function.name, block, w));
        }
    }
    worst
}

/// Random points of a regime whose cables all pull (eq. 11 gives every `f_h` at least 5 % of the
/// regime's smallest reference `f_h`, and every `f_v > 0`).
///
/// Random reference tensions and rotations are mostly not an equilibrium of the large robot:
/// the moment about the vertical (eq. 8, row `Mz`) has arms of a few centimetres, so eq. (11)
/// often gives a slack or pushing cable there, where the catenary is meaningless.
fn physical_points(regime: &Regime, seed: u64, count: usize) -> Vec<Point> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut effects_rng = ChaCha8Rng::seed_from_u64(seed ^ 0x0eff_ec75);
    let mut points = Vec::with_capacity(count);
    let mut rejected = 0;
    while points.len() < count {
        let point = random_point(regime, &mut rng);
        let tensions = independent_tensions(&point);
        if tensions
            .iter()
            .all(|&(h, v)| h > 0.05 * regime.horizontal_tension_n.0 && v > 0.0)
        {
            let index = points.len();
            points.push(with_effects(point, index, &mut effects_rng));
        } else {
            rejected += 1;
            assert!(rejected < 50 * count, "{}: no physical points", regime.name);
        }
    }
    println!(
        "{}: {count} points ({rejected} rejected with a slack or pushing cable)",
        regime.name
    );
    points
}

fn check_jacobians(regime: &Regime, seed: u64) {
    let points = physical_points(regime, seed, SAMPLES);
    let worst = worst_jacobian_errors(&points);
    println!(
        "{}: worst max|analytic - fd| per Jacobian block over {} points",
        regime.name,
        points.len()
    );
    let mut failures = Vec::new();
    for (name, block, w) in &worst {
        println!(
            "  {name:<30} {:<18} error {:.3e}  scale {:.3e}  ratio {:.3e}  (sample {})",
            format!("{block:?}"),
            w.error,
            w.scale,
            w.ratio,
            w.sample
        );
        if w.ratio > TOLERANCE {
            failures.push(format!("{name} d/d{block:?}: ratio {:.3e}", w.ratio));
        }
    }
    assert!(failures.is_empty(), "{}: {failures:?}", regime.name);
}

#[test]
fn jacobians_match_finite_differences_large_robot() {
    check_jacobians(&large(), 0x5a6c_a101);
}

#[test]
fn jacobians_match_finite_differences_small_robot() {
    check_jacobians(&small(), 0x5a6c_a202);
}

#[test]
fn jacobians_match_finite_differences_massless_cable() {
    for (regime, seed) in [(large(), 11), (small(), 12)] {
        let mut points = physical_points(&regime, seed, 20);
        for point in &mut points {
            point.cable_weight_n_per_m = 0.0;
        }
        for (name, block, w) in worst_jacobian_errors(&points) {
            // The derivative in the cable weight itself at g_c = 0 sits on the
            // guarded branch of the sag terms (central differences straddle a
            // negative weight); the model only uses it times the robot's
            // weight per metre (the cable-weight effect scales it), which is 0 here.
            if block == Block::CableWeight {
                continue;
            }
            println!("  g_c = 0 {}: {name} d/d{block:?} ratio {:.3e}", regime.name, w.ratio);
            assert!(
                w.ratio <= TOLERANCE,
                "{name} d/d{block:?} at g_c = 0: ratio {:.3e}",
                w.ratio
            );
        }
    }
}

/// `catenary_cable_residuals` is the three functions it replaces in the
/// solver, stacked: its rows 0..4, 4..8 and 8..16 and their Jacobians equal
/// `catenary_length_residual`, `attachment_height_residual` and
/// `cable_tensions_from_reference` (the offsets' block of the height and
/// tension rows zero) to 1e-12 of each block's largest entry: the same
/// expressions, only shared.
#[test]
fn catenary_cable_rows_are_the_length_height_and_tension_functions() {
    let mut worst: f64 = 0.0;
    for (regime, seed) in [(large(), 21), (small(), 22)] {
        for p in physical_points(&regime, seed, 30) {
            let (rows, blocks) = catenary_cable(&p);
            let (length, length_blocks) = catenary_length(&p);
            let (height, height_blocks) = attachment_height(&p);
            let (tensions, tension_blocks) = tensions(&p);
            let parts = [
                (0, length, length_blocks),
                (4, height, height_blocks),
                (8, tensions, tension_blocks),
            ];
            for (first, value, part_blocks) in parts {
                let n = value.len();
                let scale = value.amax().max(1.0);
                let difference = (rows.rows(first, n) - &value).amax() / scale;
                worst = worst.max(difference);
                assert!(
                    difference <= 1e-12,
                    "{}: rows {first}.. differ by {difference:.1e}",
                    regime.name
                );
                for (k, block) in blocks.iter().enumerate() {
                    let expected = part_blocks
                        .get(k)
                        .cloned()
                        .unwrap_or_else(|| DMatrix::zeros(n, block.ncols()));
                    let scale = expected.amax().max(1.0);
                    let difference = (block.rows(first, n) - &expected).amax() / scale;
                    worst = worst.max(difference);
                    assert!(
                        difference <= 1e-12,
                        "{}: rows {first}.. block {k} differ by {difference:.1e}",
                        regime.name
                    );
                }
            }
        }
    }
    println!("catenary_cable_residuals against the three functions: worst relative difference {worst:.1e}");
}

// -------------------------------------------------------------------------------------------------
// Values against independent hand-written computations
// -------------------------------------------------------------------------------------------------

/// Geometry of slot `j`: world attachment, moment arm `R b`, horizontal span and unit direction.
fn cable_geometry(p: &Point, j: usize) -> (Vector3<f64>, Vector3<f64>, f64, Vector3<f64>) {
    let arm = p.pose.rotation * p.attachments_m.column(j).into_owned();
    let attachment = p.pose.position_m + arm;
    let delta = attachment - p.anchors_m.column(j);
    let span = delta.x.hypot(delta.y);
    (attachment, arm, span, Vector3::new(delta.x / span, delta.y / span, 0.0))
}

/// Eq. (11) by a 6x6 LU solve of the full statics `J^T f = w` (eq. 5, 6, 8), in slot order.
fn independent_tensions(p: &Point) -> [(f64, f64); 4] {
    let z = Vector3::z();
    let mut structure = SMatrix::<f64, 6, 8>::zeros();
    for j in 0..4 {
        let (_, arm, _, s) = cable_geometry(p, j);
        let mut column_h = nalgebra::Vector6::zeros();
        column_h.fixed_rows_mut::<3>(0).copy_from(&-s);
        column_h.fixed_rows_mut::<3>(3).copy_from(&-arm.cross(&s));
        let mut column_v = nalgebra::Vector6::zeros();
        column_v.fixed_rows_mut::<3>(0).copy_from(&z);
        column_v.fixed_rows_mut::<3>(3).copy_from(&arm.cross(&z));
        structure.set_column(2 * j, &column_h);
        structure.set_column(2 * j + 1, &column_v);
    }
    let com = p.pose.rotation * p.com_offset_m;
    let mut wrench = nalgebra::Vector6::zeros();
    wrench.fixed_rows_mut::<3>(0).copy_from(&(z * p.platform_weight_n));
    wrench
        .fixed_rows_mut::<3>(3)
        .copy_from(&(com.cross(&z) * p.platform_weight_n));
    let rhs = wrench - structure.column(0) * p.reference_tension_n[0] - structure.column(1) * p.reference_tension_n[1];
    let rest = structure.fixed_columns::<6>(2).into_owned();
    let solution = rest.lu().solve(&rhs).expect("J_res^T is invertible");
    [
        (p.reference_tension_n[0], p.reference_tension_n[1]),
        (solution[0], solution[1]),
        (solution[2], solution[3]),
        (solution[4], solution[5]),
    ]
}

fn relative_error(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1.0)
}

#[test]
fn values_match_independent_computations() {
    for (regime, seed) in [(large(), 21), (small(), 22)] {
        let mut worst = [0.0_f64; 6];
        for p in physical_points(&regime, seed, 100) {
            let expected = independent_tensions(&p);
            let tensions = tensions(&p).0;
            let catenary = catenary_length(&p).0;
            let height = attachment_height(&p).0;
            let rigid = rigid_length(&p).0;
            for (j, &(f_h, f_v)) in expected.iter().enumerate() {
                worst[0] = worst[0].max(relative_error(tensions[2 * j], f_h));
                worst[0] = worst[0].max(relative_error(tensions[2 * j + 1], f_v));
                let (attachment, _, span, _) = cable_geometry(&p, j);
                let cable = Catenary {
                    span_m: span,
                    horizontal_tension_n: f_h,
                    vertical_tension_n: f_v,
                    cable_weight_n_per_m: p.cable_weight_n_per_m,
                };
                let length = catenary[j] - p.length_offsets_m[j] + p.encoder_lengths_m[j];
                worst[1] = worst[1].max(relative_error(length, cable.length_m()));
                let drop = height[j] - attachment.z + p.anchors_m[(2, j)];
                worst[2] = worst[2].max(relative_error(drop, cable.drop_m()));
                let straight = (p.anchors_m.column(j) - attachment).norm();
                let rigid_length = rigid[j] - p.length_offsets_m[j] + p.encoder_lengths_m[j];
                worst[3] = worst[3].max(relative_error(rigid_length, straight));
            }
            let load_cell = reference_tension(&p).0[0];
            let expected_load_cell = p.reference_tension_n.norm() - p.measured_tension_n;
            worst[4] = worst[4].max((load_cell - expected_load_cell).abs());
            let prior = pose_prior(&p).0;
            let expected_prior = p.prior.local_coordinates(&p.pose);
            worst[5] = worst[5].max((prior - expected_prior).amax());
        }
        println!(
            "{}: tensions {:.1e}, catenary length {:.1e}, drop {:.1e}, rigid {:.1e}, load cell {:.1e}, prior {:.1e}",
            regime.name, worst[0], worst[1], worst[2], worst[3], worst[4], worst[5]
        );
        assert!(
            worst[0] < 1e-9,
            "eq. (11) tensions differ from the 6x6 LU solve: {:e}",
            worst[0]
        );
        assert!(
            worst[1] < 1e-11,
            "catenary length differs from Catenary::length_m: {:e}",
            worst[1]
        );
        assert!(worst[2] < 1e-11, "drop differs from Catenary::drop_m: {:e}", worst[2]);
        assert!(
            worst[3] < 1e-12,
            "rigid length differs from the distance: {:e}",
            worst[3]
        );
        assert!(worst[4] < 1e-12, "load-cell residual differs: {:e}", worst[4]);
        assert!(
            worst[5] < 1e-12,
            "pose prior differs from local_coordinates: {:e}",
            worst[5]
        );
    }
}

/// `extended_cable` of slot `j` of `p` with the given effect parameters, `(paid_out, drop)`.
fn extended_cable_at(p: &Point, j: usize, compliance_per_mn: f64, radius_m: f64) -> (f64, f64) {
    chain_at(p, j, compliance_per_mn, radius_m, 0.0)
}

/// `extended_cable` of slot `j` with `1/n^2` too.
fn chain_at(p: &Point, j: usize, compliance_per_mn: f64, radius_m: f64, inverse_segments_squared: f64) -> (f64, f64) {
    let cable = generated::extended_cable(
        p.cable_spans_m[j],
        p.cable_horizontal_tensions_n[j],
        p.cable_vertical_tensions_n[j],
        p.cable_weight_n_per_m,
        compliance_per_mn,
        radius_m,
        inverse_segments_squared,
        EPSILON,
        None,
        None,
        None,
        None,
        None,
        None,
        None,
    );
    (cable[0], cable[1])
}

fn catenary_of_slot(p: &Point, j: usize) -> Catenary {
    Catenary {
        span_m: p.cable_spans_m[j],
        horizontal_tension_n: p.cable_horizontal_tensions_n[j],
        vertical_tension_n: p.cable_vertical_tensions_n[j],
        cable_weight_n_per_m: p.cable_weight_n_per_m,
    }
}

#[test]
fn new_functions_match_independent_computations() {
    // cable_geometry against the 6x6 LU solve and the hand-written geometry, load_cell_residual
    // against b + (1 + g) T - f_m.
    for (regime, seed) in [(large(), 81), (small(), 82)] {
        let (mut tension, mut geometry_error, mut load_cell_error) = (0.0_f64, 0.0_f64, 0.0_f64);
        for p in physical_points(&regime, seed, 100) {
            let value = geometry(&p).0;
            for (j, &(f_h, f_v)) in independent_tensions(&p).iter().enumerate() {
                let (attachment, _, span, _) = cable_geometry(&p, j);
                tension = tension.max(relative_error(value[4 * j + 1], f_h));
                tension = tension.max(relative_error(value[4 * j + 2], f_v));
                geometry_error = geometry_error.max(relative_error(value[4 * j], span));
                let height = p.anchors_m[(2, j)] - attachment.z;
                geometry_error = geometry_error.max(relative_error(value[4 * j + 3], height));
            }
            let expected = p.load_cell_bias_n + (1.0 + p.load_cell_gain_error) * p.reference_tension_n.norm()
                - p.measured_tension_n;
            load_cell_error = load_cell_error.max((load_cell(&p).0[0] - expected).abs());
        }
        println!(
            "{}: cable_geometry tensions {tension:.1e}, span/height {geometry_error:.1e}, load cell {load_cell_error:.1e}",
            regime.name
        );
        assert!(
            tension < 1e-9,
            "cable_geometry tensions differ from the LU solve: {tension:e}"
        );
        assert!(
            geometry_error < 1e-12,
            "cable_geometry span/height differ: {geometry_error:e}"
        );
        assert!(
            load_cell_error < 1e-12,
            "load_cell_residual differs: {load_cell_error:e}"
        );
    }
}

#[test]
fn extended_cable_closed_forms() {
    for (regime, seed) in [(large(), 91), (small(), 92)] {
        let mut worst = [0.0_f64; 4];
        for p in physical_points(&regime, seed, 100) {
            for j in 0..4 {
                let catenary = catenary_of_slot(&p, j);
                // No effect: exactly eq. (4) and the drop of eq. (1)-(3), as `Catenary` computes them.
                let (paid_out, drop) = extended_cable_at(&p, j, 0.0, 0.0);
                worst[0] = worst[0].max((paid_out - catenary.length_m()).abs() / catenary.length_m());
                worst[0] = worst[0].max((drop - catenary.drop_m()).abs() / catenary.drop_m().abs());

                // Elastic, point anchor: Irvine to first order from the inextensible catenary,
                // L0 = l (1 - k T_top), drop - k g_c l^2 / 2.
                let k = 1e-6 * p.axial_compliance_per_mn;
                let l = catenary.length_m();
                let top = catenary
                    .horizontal_tension_n
                    .hypot(catenary.anchor_vertical_tension_n());
                let (paid_out, drop) = extended_cable_at(&p, j, p.axial_compliance_per_mn, 0.0);
                worst[1] = worst[1].max((paid_out - l * (1.0 - k * top)).abs() / l);
                let expected_drop = catenary.drop_m() - k * p.cable_weight_n_per_m * l * l / 2.0;
                worst[1] = worst[1].max((drop - expected_drop).abs() / expected_drop.abs());

                // Massless cable, point anchor: the spring l / (1 + k T) to first order,
                // l = span sqrt(1 + u^2), T = sqrt(f_h^2 + f_v^2); the drop stays span u.
                let mut massless = p.clone();
                massless.cable_weight_n_per_m = 0.0;
                let (span, f_h, f_v) = (
                    catenary.span_m,
                    catenary.horizontal_tension_n,
                    catenary.vertical_tension_n,
                );
                let u = f_v / f_h;
                let l = span * (1.0 + u * u).sqrt();
                let t = (f_h * f_h + f_v * f_v).sqrt();
                for compliance in [0.0, 0.5, 2.0, p.axial_compliance_per_mn] {
                    let (paid_out, drop) = extended_cable_at(&massless, j, compliance, 0.0);
                    let expected = l * (1.0 - t * 1e-6 * compliance);
                    worst[2] = worst[2].max((paid_out - expected).abs() / expected);
                    worst[2] = worst[2].max((drop - span * u).abs() / (span * u));
                }

                // Massless cable on a pulley: the top tension does not depend on the free length,
                // so the exit point is exact: span' = L - r (1 + f_v / T), rise r f_h / T, wrap
                // pi/2 + atan(u), paid_out = span' sqrt(1 + u^2) (1 - k T) + r wrap / (1 + k T).
                for radius in [0.05, 0.3, p.pulley_radius_m] {
                    let compliance = p.axial_compliance_per_mn;
                    let k = 1e-6 * compliance;
                    let free_span = span - radius * (1.0 + f_v / t);
                    let wrap = std::f64::consts::FRAC_PI_2 + u.atan();
                    let expected = free_span * (1.0 + u * u).sqrt() * (1.0 - k * t) + radius * wrap / (1.0 + k * t);
                    let expected_drop = free_span * u - radius * f_h / t;
                    let (paid_out, drop) = extended_cable_at(&massless, j, compliance, radius);
                    worst[3] = worst[3].max((paid_out - expected).abs() / expected);
                    worst[3] = worst[3].max((drop - expected_drop).abs() / expected_drop.abs());
                }

                // Sanity of the sign: a stretching cable needs less unstretched length.
                if p.axial_compliance_per_mn > 0.0 {
                    let stretched = extended_cable_at(&p, j, p.axial_compliance_per_mn, 0.0).0;
                    assert!(
                        stretched < catenary.length_m(),
                        "slot {j}: {stretched} >= {}",
                        catenary.length_m()
                    );
                }
            }
        }
        println!(
            "{}: extended_cable vs Catenary {:.1e}, elastic {:.1e}, massless spring {:.1e}, massless pulley {:.1e}",
            regime.name, worst[0], worst[1], worst[2], worst[3]
        );
        assert!(
            worst[0] < 1e-12,
            "extended_cable(k = 0, r = 0) differs from Catenary: {:e}",
            worst[0]
        );
        assert!(
            worst[1] < 1e-12,
            "elastic catenary differs from l (1 - k T_top): {:e}",
            worst[1]
        );
        assert!(
            worst[2] < 1e-12,
            "massless elastic cable differs from l (1 - k T): {:e}",
            worst[2]
        );
        assert!(worst[3] < 1e-12, "massless cable on a pulley differs: {:e}", worst[3]);
    }
}

/// The span and rise of a chain of `n` straight elements of total length
/// `length` with lumped node weights (half at the ends), end forces `f_h`,
/// `f_v` at the attachment: element `k` carries `V = f_v + g_c (k + 1/2) h`.
fn chain_span_and_rise(length: f64, f_h: f64, f_v: f64, weight: f64, n: usize) -> (f64, f64) {
    let h = length / n as f64;
    (0..n).fold((0.0, 0.0), |(x, z), k| {
        let v = f_v + weight * (k as f64 + 0.5) * h;
        let t = f_h.hypot(v);
        (x + h * f_h / t, z + h * v / t)
    })
}

#[test]
fn segmented_chain_matches_the_chain_summed_element_by_element() {
    for (regime, seed) in [(large(), 93), (small(), 94)] {
        let mut worst_ratio = 0.0_f64;
        let mut worst_massless = 0.0_f64;
        let (mut checked, mut skipped) = (0, 0);
        for p in physical_points(&regime, seed, 40) {
            for j in 0..4 {
                let catenary = catenary_of_slot(&p, j);
                let (f_h, f_v) = (catenary.horizontal_tension_n, catenary.vertical_tension_n);
                let smooth = chain_at(&p, j, 0.0, 0.0, 0.0);
                // The expansion in 1/n^2 holds while an element's weight is small
                // against the tension: g_c h / f_h < 0.1 at n = 10 (every
                // realistic cable here; the random points also hold loops
                // hundreds of times longer than their span).
                if p.cable_weight_n_per_m * smooth.0 / 10.0 / f_h > 0.1 {
                    skipped += 1;
                    continue;
                }
                checked += 1;
                for n in [10usize, 20, 40] {
                    // The chain that spans the same horizontal distance, by the secant method on its length.
                    let span = |length: f64| chain_span_and_rise(length, f_h, f_v, p.cable_weight_n_per_m, n).0;
                    let (mut a, mut b) = (smooth.0, smooth.0 * 1.001);
                    for _ in 0..50 {
                        let (fa, fb) = (span(a) - catenary.span_m, span(b) - catenary.span_m);
                        if (fb - fa).abs() < 1e-300 || fb == 0.0 {
                            break;
                        }
                        let next = b - fb * (b - a) / (fb - fa);
                        (a, b) = (b, next);
                    }
                    let rise = chain_span_and_rise(b, f_h, f_v, p.cable_weight_n_per_m, n).1;
                    let (exact_length, exact_drop) = (b - smooth.0, rise - smooth.1);
                    let model = chain_at(&p, j, 0.0, 0.0, 1.0 / (n * n) as f64);
                    let (model_length, model_drop) = (model.0 - smooth.0, model.1 - smooth.1);
                    // First order in 1/n^2: what is left is of order 1/n^4, a small part of the correction.
                    let left = (model_length - exact_length).abs().max((model_drop - exact_drop).abs());
                    let size = exact_length.abs().max(exact_drop.abs());
                    if size > 1e-12 {
                        worst_ratio = worst_ratio.max(left / size * (n * n) as f64 / 100.0);
                    }
                    let mut massless = p.clone();
                    massless.cable_weight_n_per_m = 0.0;
                    let straight = chain_at(&massless, j, 0.0, 0.0, 0.0);
                    let chained = chain_at(&massless, j, 0.0, 0.0, 1.0 / (n * n) as f64);
                    worst_massless = worst_massless
                        .max((chained.0 - straight.0).abs())
                        .max((chained.1 - straight.1).abs());
                }
            }
        }
        println!(
            "{}: segmented chain ({checked} cables, {skipped} beyond the expansion), error left x n^2 / 100 over the correction {worst_ratio:.2e}; massless change {worst_massless:.1e} m",
            regime.name
        );
        assert!(checked > 100, "{}: only {checked} cables checked", regime.name);
        // The error left falls like 1/n^2 relative to the correction: scaled to n = 10 it is below 5 %.
        assert!(worst_ratio < 0.05, "{}: {worst_ratio}", regime.name);
        assert!(
            worst_massless == 0.0,
            "{}: a massless chain is straight: {worst_massless}",
            regime.name
        );
    }
}

#[test]
fn tensions_satisfy_the_statics() {
    // J^T f = w with the generated tensions, residual relative to the weight.
    for (regime, seed) in [(large(), 31), (small(), 32)] {
        for p in physical_points(&regime, seed, 50) {
            let f = tensions(&p).0;
            let z = Vector3::z();
            let mut force = Vector3::zeros();
            let mut moment = Vector3::zeros();
            for j in 0..4 {
                let (_, arm, _, s) = cable_geometry(&p, j);
                let cable_force = -s * f[2 * j] + z * f[2 * j + 1];
                force += cable_force;
                moment += arm.cross(&cable_force);
            }
            let weight = p.platform_weight_n;
            let com = p.pose.rotation * p.com_offset_m;
            assert!((force - z * weight).amax() < 1e-9 * weight, "force balance {force}");
            assert!(
                (moment - com.cross(&z) * weight).amax() < 1e-9 * weight,
                "moment balance {moment}"
            );
        }
    }
}

#[test]
fn massless_cable_is_straight() {
    // g_c = 0 exactly: sinhc(0) must be 1 (no 0/0), length = L sqrt(1 + u^2), drop = L u.
    for (regime, seed) in [(large(), 41), (small(), 42)] {
        for mut p in physical_points(&regime, seed, 50) {
            p.cable_weight_n_per_m = 0.0;
            let f = tensions(&p).0;
            let catenary = catenary_length(&p).0;
            let height = attachment_height(&p).0;
            for j in 0..4 {
                let (attachment, _, span, _) = cable_geometry(&p, j);
                let u = f[2 * j + 1] / f[2 * j];
                let length = catenary[j] - p.length_offsets_m[j] + p.encoder_lengths_m[j];
                assert!(length.is_finite() && height[j].is_finite());
                assert!(relative_error(length, span * (1.0 + u * u).sqrt()) < 1e-13, "{length}");
                let drop = height[j] - attachment.z + p.anchors_m[(2, j)];
                assert!(relative_error(drop, span * u) < 1e-13, "{drop} vs {}", span * u);
            }
        }
    }
}

#[test]
fn massless_catenary_equals_rigid_cable_at_a_symmetric_equilibrium() {
    // Platform centred below symmetric anchors, level, centre of mass on the vertical axis:
    // every cable is straight with tension t along it and 4 t_z = W; eq. (11) must give the
    // same for the three other cables, and then the catenary residual (g_c = 0) equals the
    // rigid one and the attachment heights agree.
    for robot in [Robot::builtin("large").unwrap(), Robot::builtin("small").unwrap()] {
        let order = slot_order(&robot);
        for z in [2.0, 10.0, 20.0] {
            let pose = PlatformPose::from_position(Vector3::new(0.0, 0.0, z));
            let anchors_m = Matrix3x4::from_columns(&order.map(|c| robot.anchors_m[c]));
            let attachments_m = Matrix3x4::from_columns(&order.map(|c| robot.attachments_m[c]));
            let cable = anchors_m.column(0) - (pose.position_m + attachments_m.column(0));
            let tension = robot.platform_weight_n / 4.0 / (cable.z / cable.norm());
            let direction = cable / cable.norm();
            let p = Point {
                pose,
                reference_tension_n: Vector2::new(tension * direction.xy().norm(), tension * direction.z),
                anchors_m,
                attachments_m,
                com_offset_m: robot.com_offset_m,
                platform_weight_n: robot.platform_weight_n,
                cable_weight_n_per_m: 0.0,
                length_offsets_m: Vector4::new(0.1, -0.2, 0.3, -0.4),
                encoder_lengths_m: Vector4::new(100.0, 110.0, 120.0, 130.0),
                prior: pose,
                measured_tension_n: tension,
                cable_spans_m: Vector4::zeros(),
                cable_horizontal_tensions_n: Vector4::zeros(),
                cable_vertical_tensions_n: Vector4::zeros(),
                axial_compliance_per_mn: 0.0,
                pulley_radius_m: 0.0,
                inverse_segments_squared: 0.0,
                load_cell_bias_n: 0.0,
                load_cell_gain_error: 0.0,
                localiser_mount_rad: Vector3::zeros(),
            };
            let f = tensions(&p).0;
            for j in 1..4 {
                assert!(relative_error(f[2 * j], f[0]) < 1e-12, "{}: {f}", robot.name);
                assert!(relative_error(f[2 * j + 1], f[1]) < 1e-12, "{}: {f}", robot.name);
            }
            let catenary = catenary_length(&p).0;
            let rigid = rigid_length(&p).0;
            let height = attachment_height(&p).0;
            for j in 0..4 {
                assert!(
                    (catenary[j] - rigid[j]).abs() < 1e-11,
                    "{}: {catenary} vs {rigid}",
                    robot.name
                );
                assert!(height[j].abs() < 1e-11, "{}: height residual {height}", robot.name);
            }
            assert!(reference_tension(&p).0[0].abs() < 1e-12);
        }
    }
}

#[test]
fn catenary_residual_of_a_heavy_cable_is_longer_than_rigid() {
    // Sanity of the sign conventions: with the same tensions, sag makes the cable longer.
    let regime = large();
    for p in physical_points(&regime, 51, 20) {
        let catenary = catenary_length(&p).0;
        let f = tensions(&p).0;
        for j in 0..4 {
            let (_, _, span, _) = cable_geometry(&p, j);
            let u = f[2 * j + 1] / f[2 * j];
            let massless = span * (1.0 + u * u).sqrt();
            let length = catenary[j] - p.length_offsets_m[j] + p.encoder_lengths_m[j];
            assert!(length > massless, "slot {j}: {length} <= {massless}");
        }
    }
}

#[test]
fn outputs_do_not_depend_on_the_requested_jacobians() {
    let p = physical_points(&large(), 61, 1).remove(0);
    let without = calls::catenary_length(&p, None);
    assert_eq!(DVector::from_column_slice(without.as_slice()), catenary_length(&p).0);
}

#[test]
fn pose_prior_is_well_behaved_at_and_near_the_prior() {
    // A calibration starts with every pose at its measurement: the logarithm at the identity
    // (clamped with epsilon in SymForce's Rot3) must give a zero residual and an identity Jacobian.
    let mut p = physical_points(&small(), 71, 1).remove(0);
    p.prior = p.pose;
    let (value, jacobians) = pose_prior(&p);
    assert!(value.amax() < 1e-15, "{value}");
    assert!(
        (&jacobians[0] - DMatrix::<f64>::identity(6, 6)).amax() < 1e-7,
        "{}",
        jacobians[0]
    );
    for angle in [1e-9, 1e-7, 1e-5, 1e-3] {
        p.prior = p
            .pose
            .retract(&Vector6::new(angle, -0.5 * angle, 0.3 * angle, 1e-3, 0.0, -1e-3));
        let value = pose_prior(&p).0;
        let expected = DVector::from_column_slice(p.prior.local_coordinates(&p.pose).as_slice());
        println!(
            "angle {angle:e}: relative error of the rotation part {:.1e}",
            (&value - &expected).rows(0, 3).amax() / angle
        );
        assert!(
            (&value - &expected).amax() < 1e-12 * angle.max(1e-3),
            "angle {angle}: {value} vs {expected}"
        );
    }
}

/// The mounted pose prior against nalgebra: zero for a localiser that reads
/// `R Exp(m)`, the plain prior at `m = 0`, and `Log(Exp(m) R_prior^-1 R)` otherwise.
#[test]
fn mounted_pose_prior_matches_the_rotation_algebra() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    for regime in [large(), small()] {
        for _ in 0..20 {
            let mut p = random_point(&regime, &mut rng);
            let mount = Vector3::from_fn(|_, _| rng.random_range(-0.08..0.08));
            let exp_m = UnitQuaternion::from_scaled_axis(mount);
            p.localiser_mount_rad = Vector3::zeros();
            let plain = calls::pose_prior(&p, None);
            let zero_mount = calls::mounted_pose_prior(&p, None);
            assert!((plain - zero_mount).amax() < 1e-15, "m = 0: {plain} vs {zero_mount}");
            p.localiser_mount_rad = mount;
            let general = calls::mounted_pose_prior(&p, None);
            let expected = (exp_m * p.prior.rotation.inverse() * p.pose.rotation).scaled_axis();
            assert!(
                (general.fixed_rows::<3>(0) - expected).amax() < 1e-12,
                "{general} vs {expected}"
            );
            p.prior = PlatformPose::new(p.pose.position_m, p.pose.rotation * exp_m);
            let reading = calls::mounted_pose_prior(&p, None);
            assert!(
                reading.amax() < 1e-12,
                "a mounted reading of the pose itself: {reading}"
            );
        }
    }
}

/// The per-cable factors of a robot of any number of cables
/// (`suspended_cable_residual`, `cable_wrench`, `straight_cable_residual`,
/// and gravity's `platform_weight_wrench`) against the model they
/// derive from (`model::suspended`): at equilibria of the eight-cable robot
/// each cable's residuals vanish with encoders reading its catenary length,
/// the cables' wrenches are the model's structure matrix times the forces
/// and balance gravity; their Jacobians are those of central differences.
#[test]
fn per_cable_factors_agree_with_the_n_cable_model() {
    use sagcal::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedRobot};
    let robot = SuspendedRobot::builtin("eight").unwrap();
    let weight = robot.platform_weight_n;
    let mut worst: f64 = 0.0;
    for position in [
        Vector3::new(1.0, -0.5, 2.0),
        Vector3::new(-3.5, 2.0, 1.5),
        Vector3::new(4.0, 2.5, 3.2),
    ] {
        let eq = solve_at(&robot, position, Closure::Level, &EquilibriumOptions::default()).unwrap();
        let (p, q) = (eq.pose.position_m, eq.pose.rotation_xyzw());
        let forces = DVector::from_iterator(16, eq.tensions.iter().flat_map(|t| [t.horizontal_n, t.vertical_n]));
        let mut total = Vector6::zeros();
        for i in 0..8 {
            let tension = Vector2::new(eq.tensions[i].horizontal_n, eq.tensions[i].vertical_n);
            let (anchor, attachment) = (robot.anchors_m[i], robot.attachments_m[i]);
            let g_c = robot.cable_weights_n_per_m[i];
            let (offset, reading) = (0.25, eq.cable_lengths_m[i] + 0.25);
            let residual = |pose: &PlatformPose, tension: &Vector2<f64>, anchor: &Vector3<f64>, offset: f64| {
                generated::suspended_cable_residual(
                    &pose.position_m,
                    &pose.rotation_xyzw(),
                    tension,
                    anchor,
                    &attachment,
                    g_c,
                    offset,
                    reading,
                    EPSILON,
                    None,
                    None,
                    None,
                    None,
                )
            };
            let wrench = |pose: &PlatformPose, tension: &Vector2<f64>, anchor: &Vector3<f64>| {
                generated::cable_wrench(
                    &pose.position_m,
                    &pose.rotation_xyzw(),
                    tension,
                    anchor,
                    &attachment,
                    EPSILON,
                    None,
                    None,
                    None,
                )
            };
            assert!(residual(&eq.pose, &tension, &anchor, offset).amax() < 1e-9, "cable {i}");
            total += wrench(&eq.pose, &tension, &anchor);
            // Analytic Jacobians against central differences.
            let (mut r_pose, mut r_tension, mut r_anchor, mut r_offset) = (
                SMatrix::<f64, 2, 6>::zeros(),
                SMatrix::<f64, 2, 2>::zeros(),
                SMatrix::<f64, 2, 3>::zeros(),
                SMatrix::<f64, 2, 1>::zeros(),
            );
            generated::suspended_cable_residual(
                &p,
                &q,
                &tension,
                &anchor,
                &attachment,
                g_c,
                offset,
                reading,
                EPSILON,
                Some(&mut r_pose),
                Some(&mut r_tension),
                Some(&mut r_anchor),
                Some(&mut r_offset),
            );
            let (mut w_pose, mut w_tension, mut w_anchor) = (
                SMatrix::<f64, 6, 6>::zeros(),
                SMatrix::<f64, 6, 2>::zeros(),
                SMatrix::<f64, 6, 3>::zeros(),
            );
            generated::cable_wrench(
                &p,
                &q,
                &tension,
                &anchor,
                &attachment,
                EPSILON,
                Some(&mut w_pose),
                Some(&mut w_tension),
                Some(&mut w_anchor),
            );
            let relative = |analytic: f64, numeric: f64, scale: f64| (analytic - numeric).abs() / scale.max(1e-12);
            for k in 0..6 {
                let h = 1e-6;
                let step = |t: f64| eq.pose.retract(&Vector6::from_fn(|j, _| if j == k { t } else { 0.0 }));
                let dr = (residual(&step(h), &tension, &anchor, offset)
                    - residual(&step(-h), &tension, &anchor, offset))
                    / (2.0 * h);
                let dw = (wrench(&step(h), &tension, &anchor) - wrench(&step(-h), &tension, &anchor)) / (2.0 * h);
                for row in 0..2 {
                    worst = worst.max(relative(r_pose[(row, k)], dr[row], r_pose.amax()));
                }
                for row in 0..6 {
                    worst = worst.max(relative(w_pose[(row, k)], dw[row], w_pose.amax()));
                }
            }
            for k in 0..2 {
                let h = 1e-3;
                let moved = |t: f64| tension + Vector2::from_fn(|j, _| if j == k { t } else { 0.0 });
                let dr = (residual(&eq.pose, &moved(h), &anchor, offset)
                    - residual(&eq.pose, &moved(-h), &anchor, offset))
                    / (2.0 * h);
                let dw = (wrench(&eq.pose, &moved(h), &anchor) - wrench(&eq.pose, &moved(-h), &anchor)) / (2.0 * h);
                for row in 0..2 {
                    worst = worst.max(relative(r_tension[(row, k)], dr[row], r_tension.amax()));
                }
                for row in 0..6 {
                    worst = worst.max(relative(w_tension[(row, k)], dw[row], w_tension.amax()));
                }
            }
            for k in 0..3 {
                let h = 1e-6;
                let moved = |t: f64| anchor + Vector3::from_fn(|j, _| if j == k { t } else { 0.0 });
                let dr = (residual(&eq.pose, &tension, &moved(h), offset)
                    - residual(&eq.pose, &tension, &moved(-h), offset))
                    / (2.0 * h);
                let dw = (wrench(&eq.pose, &tension, &moved(h)) - wrench(&eq.pose, &tension, &moved(-h))) / (2.0 * h);
                for row in 0..2 {
                    worst = worst.max(relative(r_anchor[(row, k)], dr[row], r_anchor.amax()));
                }
                for row in 0..6 {
                    worst = worst.max(relative(w_anchor[(row, k)], dw[row], w_anchor.amax()));
                }
            }
            assert_eq!(r_offset, SMatrix::<f64, 2, 1>::new(1.0, 0.0));
            // The straight cable: the chord plus the offset, and its Jacobians.
            let straight = |pose: &PlatformPose, anchor: &Vector3<f64>| {
                generated::straight_cable_residual(
                    &pose.position_m,
                    &pose.rotation_xyzw(),
                    anchor,
                    &attachment,
                    offset,
                    reading,
                    EPSILON,
                    None,
                    None,
                    None,
                )[0]
            };
            let chord = (anchor - (eq.pose.position_m + eq.pose.rotation_matrix() * attachment)).norm();
            assert!((straight(&eq.pose, &anchor) - (chord + offset - reading)).abs() < 1e-12);
            let (mut s_pose, mut s_anchor, mut s_offset) = (
                SMatrix::<f64, 1, 6>::zeros(),
                SMatrix::<f64, 1, 3>::zeros(),
                SMatrix::<f64, 1, 1>::zeros(),
            );
            generated::straight_cable_residual(
                &p,
                &q,
                &anchor,
                &attachment,
                offset,
                reading,
                EPSILON,
                Some(&mut s_pose),
                Some(&mut s_anchor),
                Some(&mut s_offset),
            );
            assert_eq!(s_offset[0], 1.0);
            for k in 0..6 {
                let h = 1e-6;
                let step = |t: f64| eq.pose.retract(&Vector6::from_fn(|j, _| if j == k { t } else { 0.0 }));
                let numeric = (straight(&step(h), &anchor) - straight(&step(-h), &anchor)) / (2.0 * h);
                worst = worst.max(relative(s_pose[k], numeric, s_pose.amax()));
            }
            for k in 0..3 {
                let h = 1e-6;
                let moved = |t: f64| anchor + Vector3::from_fn(|j, _| if j == k { t } else { 0.0 });
                let numeric = (straight(&eq.pose, &moved(h)) - straight(&eq.pose, &moved(-h))) / (2.0 * h);
                worst = worst.max(relative(s_anchor[k], numeric, s_anchor.amax()));
            }
        }
        let model = robot.structure_matrix(&eq.pose) * &forces;
        for row in 0..6 {
            assert!(
                (total[row] - model[row]).abs() < 1e-9 * weight,
                "row {row}: {} vs {}",
                total[row],
                model[row]
            );
        }
        let unbalanced = total - robot.gravity_wrench(&eq.pose);
        assert!(unbalanced.amax() < 1e-8 * weight, "{unbalanced}");
        // Gravity's wrench: the model's, and its orientation columns, with
        // the centre of mass off the origin (the eight-cable robot's is on it).
        let mut shifted = robot.clone();
        shifted.com_offset_m = Vector3::new(0.12, -0.07, -0.3);
        let gravity = |pose: &PlatformPose, jacobian: Option<&mut SMatrix<f64, 6, 3>>| {
            generated::platform_weight_wrench(&pose.rotation_xyzw(), &shifted.com_offset_m, weight, jacobian)
        };
        let mut g_rotation = SMatrix::<f64, 6, 3>::zeros();
        let g = gravity(&eq.pose, Some(&mut g_rotation));
        assert!((g - shifted.gravity_wrench(&eq.pose)).amax() < 1e-12 * weight, "{g}");
        assert!(g_rotation.amax() > 0.01 * weight, "{g_rotation}");
        for k in 0..3 {
            let h = 1e-6;
            let step = |t: f64| eq.pose.retract(&Vector6::from_fn(|j, _| if j == k { t } else { 0.0 }));
            let dg = (gravity(&step(h), None) - gravity(&step(-h), None)) / (2.0 * h);
            for row in 0..6 {
                let relative = (g_rotation[(row, k)] - dg[row]).abs() / g_rotation.amax().max(1e-12);
                worst = worst.max(relative);
            }
        }
    }
    println!("worst relative Jacobian error {worst:.2e}");
    assert!(worst < TOLERANCE, "{worst}");
}

/// The elastic cable of a robot of any number of cables
/// (`suspended_elastic_cable_residual`) against closed forms: with no
/// compliance it is the inextensible `suspended_cable_residual`; with one,
/// the drum pays out `l (1 - T_top / EA)` and the attachment hangs
/// `g_c l^2 / (2 EA)` lower (Irvine, first order); a weightless cable is
/// Hooke's spring `l / (1 + T / EA)` to within `l (T / EA)^2`; the
/// Jacobians are central differences'.
#[test]
fn the_elastic_cable_stretches_as_irvine_and_hooke_say() {
    use sagcal::model::suspended::{solve_at, Closure, EquilibriumOptions, SuspendedRobot};
    type Blocks = (
        SMatrix<f64, 2, 6>,
        SMatrix<f64, 2, 2>,
        SMatrix<f64, 2, 3>,
        SVector<f64, 2>,
        SVector<f64, 2>,
    );
    let mut worst: f64 = 0.0;
    for weight_n_per_m in [2.5506, 0.0] {
        let mut robot = SuspendedRobot::builtin("eight").unwrap();
        robot.cable_weights_n_per_m = vec![weight_n_per_m; 8];
        let eq = solve_at(
            &robot,
            Vector3::new(1.0, -0.5, 2.0),
            Closure::Level,
            &EquilibriumOptions::default(),
        )
        .unwrap();
        for i in 0..8 {
            let (attachment, l) = (robot.attachments_m[i], eq.cable_lengths_m[i]);
            let (offset, reading) = (0.25, l + 0.25);
            let elastic =
                |pose: &PlatformPose, f: &Vector2<f64>, anchor: &Vector3<f64>, c: f64, b: Option<&mut Blocks>| {
                    let (jp, jf, ja, jo, jc) = match b {
                        Some((p, f, a, o, c)) => (Some(p), Some(f), Some(a), Some(o), Some(c)),
                        None => (None, None, None, None, None),
                    };
                    generated::suspended_elastic_cable_residual(
                        &pose.position_m,
                        &pose.rotation_xyzw(),
                        f,
                        anchor,
                        &attachment,
                        weight_n_per_m,
                        c,
                        offset,
                        reading,
                        EPSILON,
                        jp,
                        jf,
                        ja,
                        jo,
                        jc,
                    )
                };
            let f = Vector2::new(eq.tensions[i].horizontal_n, eq.tensions[i].vertical_n);
            let anchor = robot.anchors_m[i];
            let inextensible = generated::suspended_cable_residual(
                &eq.pose.position_m,
                &eq.pose.rotation_xyzw(),
                &f,
                &anchor,
                &attachment,
                weight_n_per_m,
                offset,
                reading,
                EPSILON,
                None,
                None,
                None,
                None,
            );
            assert_eq!(elastic(&eq.pose, &f, &anchor, 0.0, None), inextensible, "cable {i}");
            // EA = 0.5 MN: a compliance of 2 per MN.
            let (compliance, k) = (2.0, 2e-6);
            let r = elastic(&eq.pose, &f, &anchor, compliance, None);
            let top = (f.x.powi(2) + (f.y + weight_n_per_m * l).powi(2)).sqrt();
            let stretch = l * k * top;
            assert!(stretch > 1e-3, "cable {i}: a stretch of {stretch} m tests nothing");
            assert!(
                (r[0] - (inextensible[0] - stretch)).abs() < 1e-9,
                "cable {i}: {} vs {}",
                r[0],
                stretch
            );
            let sag = k * weight_n_per_m * l * l / 2.0;
            assert!(
                (r[1] - (inextensible[1] - sag)).abs() < 1e-12,
                "cable {i}: {} vs {sag}",
                r[1]
            );
            if weight_n_per_m == 0.0 {
                let hooke = l / (1.0 + k * top) + offset - reading;
                assert!(
                    (r[0] - hooke).abs() < 1.01 * l * (k * top).powi(2),
                    "cable {i}: {} vs {hooke}",
                    r[0]
                );
            }
            let mut b: Blocks = Default::default();
            elastic(&eq.pose, &f, &anchor, compliance, Some(&mut b));
            assert_eq!(b.3, SVector::<f64, 2>::new(1.0, 0.0));
            let relative = |analytic: f64, numeric: f64, scale: f64| (analytic - numeric).abs() / scale.max(1e-12);
            let central = |g: &dyn Fn(f64) -> SVector<f64, 2>, h: f64| (g(h) - g(-h)) / (2.0 * h);
            for k in 0..6 {
                let step = |t: f64| eq.pose.retract(&Vector6::from_fn(|j, _| if j == k { t } else { 0.0 }));
                let d = central(&|t| elastic(&step(t), &f, &anchor, compliance, None), 1e-6);
                for row in 0..2 {
                    worst = worst.max(relative(b.0[(row, k)], d[row], b.0.amax()));
                }
            }
            for k in 0..2 {
                let moved = |t: f64| f + Vector2::from_fn(|j, _| if j == k { t } else { 0.0 });
                let d = central(&|t| elastic(&eq.pose, &moved(t), &anchor, compliance, None), 1e-3);
                for row in 0..2 {
                    worst = worst.max(relative(b.1[(row, k)], d[row], b.1.amax()));
                }
            }
            for k in 0..3 {
                let moved = |t: f64| anchor + Vector3::from_fn(|j, _| if j == k { t } else { 0.0 });
                let d = central(&|t| elastic(&eq.pose, &f, &moved(t), compliance, None), 1e-6);
                for row in 0..2 {
                    worst = worst.max(relative(b.2[(row, k)], d[row], b.2.amax()));
                }
            }
            let d = central(&|t| elastic(&eq.pose, &f, &anchor, compliance + t, None), 1e-4);
            for row in 0..2 {
                worst = worst.max(relative(b.4[row], d[row], b.4.amax()));
            }
            // The tension moves the length row only through the stretch: l k dT_top/df.
            assert!(b.1[(0, 0)].abs() > 1e-7, "cable {i}: {}", b.1);
        }
    }
    assert!(worst < TOLERANCE, "worst relative Jacobian error {worst:e}");
}

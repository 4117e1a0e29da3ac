//! The discretised-chain simulator (`sim::discretised`) against independent references:
//! the closed-form catenary statics, Irvine's elastic catenary, the tangent
//! construction of a pulley, and its own node-by-node force balance.

use std::f64::consts::PI;

use nalgebra::{UnitQuaternion, Vector3};
use sagcal::model::statics::{self, Equilibrium, StaticsOptions};
use sagcal::model::{PlatformPose, Robot};
use sagcal::sim::discretised::{
    self, equilibrium_residual_n, pulley_exit, solve_cable, solve_forward, DiscretisedEquilibrium, DiscretisedOptions,
    InitialGuess,
};
use sagcal::Error;

fn large() -> Robot {
    Robot::builtin("large").unwrap()
}

fn closed_form(robot: &Robot, position: [f64; 3]) -> Equilibrium {
    statics::solve_level(robot, Vector3::from(position), &StaticsOptions::default()).unwrap()
}

fn options(segments: usize, axial_stiffness_n: f64, pulley_radius_m: f64) -> DiscretisedOptions {
    DiscretisedOptions {
        segments,
        axial_stiffness_n,
        pulley_radius_m,
        ..DiscretisedOptions::default()
    }
}

fn solve(robot: &Robot, options: &DiscretisedOptions, cf: &Equilibrium) -> DiscretisedEquilibrium {
    solve_forward(
        robot,
        options,
        &cf.cable_lengths_m,
        &InitialGuess::from_closed_form(robot, cf),
    )
    .unwrap_or_else(|e| panic!("{options:?}: {e}"))
}

/// The closed-form tension of cable `i` as a force on the platform (world frame).
fn closed_form_force(robot: &Robot, cf: &Equilibrium, i: usize) -> Vector3<f64> {
    let attachment = cf.pose.position_m + cf.pose.rotation * robot.attachments_m[i];
    let mut horizontal = robot.anchors_m[i] - attachment;
    horizontal.z = 0.0;
    horizontal.normalize() * cf.tensions[i].horizontal_n + Vector3::z() * cf.tensions[i].vertical_n
}

/// Worst relative difference of the platform forces and the pulley-end tensions against the closed form.
fn tension_error(robot: &Robot, cf: &Equilibrium, forces: &[Vector3<f64>; 4], exits: &[Vector3<f64>; 4]) -> f64 {
    let mut error = 0.0_f64;
    for i in 0..4 {
        let reference = closed_form_force(robot, cf, i);
        error = error.max((forces[i] - reference).norm() / reference.norm());
        // The pulley end carries the whole cable weight: F + g_c L z.
        let top = reference + Vector3::z() * robot.cable_weight_n_per_m * cf.cable_lengths_m[i];
        error = error.max((exits[i] - top).norm() / top.norm());
    }
    error
}

fn forces(eq: &DiscretisedEquilibrium) -> ([Vector3<f64>; 4], [Vector3<f64>; 4]) {
    (
        std::array::from_fn(|i| eq.cables[i].platform_force_n),
        std::array::from_fn(|i| eq.cables[i].exit_tension_n),
    )
}

#[test]
fn inextensible_chain_converges_to_the_closed_form_catenary_as_one_over_n_squared() {
    let robot = large();
    let positions = [[0.0, 0.0, 15.0], [25.0, -20.0, 5.0], [-20.0, 25.0, 25.0]];
    let references: Vec<Equilibrium> = positions.iter().map(|p| closed_form(&robot, *p)).collect();
    let segments: Vec<usize> = (2..=10).map(|k| 1 << k).collect();
    let mut solutions = Vec::new();
    println!("large robot, EA = inf, r = 0, worst of 3 positions:");
    println!("     n   position error m   orientation error deg   tension error (relative)");
    let mut rows = Vec::new();
    for &n in &segments {
        let (mut position_error, mut angle_error, mut worst_tension) = (0.0_f64, 0.0_f64, 0.0_f64);
        let mut at_n = Vec::new();
        for cf in &references {
            let eq = solve(&robot, &options(n, f64::INFINITY, 0.0), cf);
            position_error = position_error.max((eq.pose.position_m - cf.pose.position_m).norm());
            angle_error = angle_error.max(eq.pose.angle_to_deg(&cf.pose));
            let (f, e) = forces(&eq);
            worst_tension = worst_tension.max(tension_error(&robot, cf, &f, &e));
            at_n.push(eq);
        }
        println!("{n:>6}   {position_error:>16.3e}   {angle_error:>21.3e}   {worst_tension:>24.3e}");
        rows.push((position_error, angle_error, worst_tension));
        solutions.push(at_n);
    }
    for k in 1..rows.len() {
        let ratios = [
            rows[k - 1].0 / rows[k].0,
            rows[k - 1].1 / rows[k].1,
            rows[k - 1].2 / rows[k].2,
        ];
        println!(
            "n {:>5} -> {:>5}: error ratios {:.3?}",
            segments[k - 1],
            segments[k],
            ratios
        );
        for ratio in ratios {
            assert!(
                (3.9..=4.1).contains(&ratio),
                "doubling n must divide the error by 4: {ratios:?}"
            );
        }
    }
    let (position_error, angle_error, worst_tension) = rows[rows.len() - 1];
    assert!(position_error < 1e-6, "n = 1024: position error {position_error:.3e} m");
    assert!(angle_error < 1e-6, "n = 1024: orientation error {angle_error:.3e} deg");
    assert!(worst_tension < 5e-7, "n = 1024: tension error {worst_tension:.3e}");
    // Richardson extrapolation of n = 512 and 1024 removes the 1/n^2 term: the
    // limit of the chain is the closed-form catenary to round-off.
    let (coarse, fine) = (&solutions[solutions.len() - 2], &solutions[solutions.len() - 1]);
    for (k, cf) in references.iter().enumerate() {
        let (a, b) = (&coarse[k], &fine[k]);
        let extrapolate = |x: Vector3<f64>, y: Vector3<f64>| (y * 4.0 - x) / 3.0;
        let position_error = (extrapolate(a.pose.position_m, b.pose.position_m) - cf.pose.position_m).norm();
        let (fa, ea) = forces(a);
        let (fb, eb) = forces(b);
        let f: [Vector3<f64>; 4] = std::array::from_fn(|i| extrapolate(fa[i], fb[i]));
        let e: [Vector3<f64>; 4] = std::array::from_fn(|i| extrapolate(ea[i], eb[i]));
        let worst_tension = tension_error(&robot, cf, &f, &e);
        println!(
            "Richardson limit (n = 512, 1024) at {:?}: position error {position_error:.2e} m, tension error {worst_tension:.2e}",
            positions[k]
        );
        assert!(position_error < 1e-9 && worst_tension < 1e-9);
    }
}

/// The floor of a residual recomputed from node positions by the spring law:
/// a position rounded to eps |x| changes a segment's stretch by eps |x| / l0.
fn spring_law_floor_n(eq: &DiscretisedEquilibrium, options: &DiscretisedOptions) -> f64 {
    let largest = eq
        .cables
        .iter()
        .flat_map(|c| c.nodes_m.iter())
        .map(|x| x.norm())
        .fold(0.0, f64::max);
    let shortest = eq.cables.iter().map(|c| c.free_length_m).fold(f64::INFINITY, f64::min) / options.segments as f64;
    let stiffness = if options.axial_stiffness_n.is_finite() {
        options.axial_stiffness_n
    } else {
        0.0
    };
    f64::EPSILON * largest * stiffness / shortest
}

#[test]
fn equilibrium_residuals_are_at_machine_precision() {
    for name in ["large", "small"] {
        let robot = Robot::builtin(name).unwrap();
        let position = if name == "large" {
            [10.0, -8.0, 12.0]
        } else {
            [0.5, 0.3, 12.0]
        };
        let cf = closed_form(&robot, position);
        for stiffness in [f64::INFINITY, 1e6, 1e5] {
            for segments in [10, 100] {
                let mut o = options(segments, stiffness, 0.3);
                o.com_offset_m = Some(robot.com_offset_m + Vector3::new(0.05, -0.03, 0.0));
                let eq = solve(&robot, &o, &cf);
                let r = equilibrium_residual_n(&robot, &o, &eq);
                let floor = spring_law_floor_n(&eq, &o);
                println!(
                    "{name:>5} EA {stiffness:>7.0e} N, n {segments:>3}: worst force/moment residual {:.2e} N = {:.1e} x platform weight (spring-law round-off floor {floor:.1e} N); worst geometric residual {:.1e} m; {} iterations",
                    r.max_n(),
                    r.max_n() / robot.platform_weight_n,
                    r.max_m(),
                    eq.iterations
                );
                assert_eq!(eq.max_residual_n, r.max_n());
                assert!(r.max_n() < 1e-9 * robot.platform_weight_n + 10.0 * floor, "{r:?}");
                if stiffness != 1e6 {
                    assert!(r.max_n() < 1e-9 * robot.platform_weight_n, "{r:?}");
                }
                assert!(r.max_m() < 1e-11, "{r:?}");
                // The check is not blind: move one node by 1 mm.
                let mut moved = eq.clone();
                moved.cables[2].nodes_m[segments / 2].x += 1e-3;
                assert!(equilibrium_residual_n(&robot, &o, &moved).max_n() > 1e-4);
            }
        }
    }
}

/// Irvine's elastic catenary (Irvine, *Cable Structures*, 1981, sec. 2.2),
/// with the Lagrangian coordinate `s` (unstretched arc length) running from the
/// lower support, which the cable pulls with `H` horizontally and `V`
/// vertically (up): the tension there is `(H, V + w s)` and
/// ```text
/// x(s) = H s / EA + H / w [asinh((V + w s) / H) - asinh(V / H)]
/// z(s) = (V s + w s^2 / 2) / EA + H / w [sqrt(1 + ((V + w s) / H)^2) - sqrt(1 + (V / H)^2)]
/// ```
fn irvine(h: f64, v: f64, w: f64, stiffness: f64, s: f64) -> (f64, f64) {
    let compliance = 1.0 / stiffness;
    let x = h * s * compliance + h / w * (((v + w * s) / h).asinh() - (v / h).asinh());
    let z = (v * s + 0.5 * w * s * s) * compliance
        + h / w * ((1.0 + ((v + w * s) / h).powi(2)).sqrt() - (1.0 + (v / h).powi(2)).sqrt());
    (x, z)
}

#[test]
fn single_elastic_cable_converges_to_irvines_elastic_catenary() {
    let (w, length) = (0.71, 170.0);
    let start = Vector3::new(3.0, -4.0, 10.0);
    let direction = Vector3::new(0.6, -0.8, 0.0);
    // (H, V, EA): taut, dipping below its lower support (V < 0), inextensible.
    for (h, v, stiffness) in [(500.0, 150.0, 1e5), (120.0, -40.0, 2e5), (300.0, 90.0, f64::INFINITY)] {
        let point = |s: f64| {
            let (x, z) = irvine(h, v, w, stiffness, s);
            start + direction * x + Vector3::z() * z
        };
        let end = point(length);
        let force = direction * h + Vector3::z() * v;
        let top = force + Vector3::z() * (w * length);
        let mut previous: Option<(f64, f64)> = None;
        println!("Irvine H {h} N, V {v} N, EA {stiffness:e} N:");
        for segments in [16, 32, 64, 128, 256, 512, 1024] {
            let cable = solve_cable(&start, &end, length, w, segments, stiffness).unwrap();
            let force_error = ((cable.platform_force_n - force).norm() / force.norm())
                .max((cable.exit_tension_n - top).norm() / top.norm());
            // Node n/2 sits at s = L/2, node n/4 at s = L/4.
            let shape_error = [2, 4]
                .iter()
                .map(|&k| (cable.nodes_m[segments / k] - point(length / k as f64)).norm())
                .fold(0.0, f64::max);
            println!("  n {segments:>5}: force error {force_error:.3e} (relative), shape error {shape_error:.3e} m");
            assert!((cable.nodes_m[segments] - end).norm() < 1e-9);
            if let Some((f, x)) = previous {
                assert!(
                    (3.9..=4.1).contains(&(f / force_error)),
                    "force error ratio {}",
                    f / force_error
                );
                assert!(
                    (3.9..=4.1).contains(&(x / shape_error)),
                    "shape error ratio {}",
                    x / shape_error
                );
            }
            previous = Some((force_error, shape_error));
        }
        let (force_error, shape_error) = previous.unwrap();
        assert!(
            force_error < 1e-6 && shape_error < 1e-4,
            "{force_error:.3e} {shape_error:.3e}"
        );
    }
}

/// The exit point and wrap angle drawn by hand: in the pulley plane (`xi` along
/// the horizontal direction `u` from the anchor to the point `p`, `zeta` up) the
/// groove is the circle of centre `(r, 0)`; a straight free span is the tangent
/// from `p` touching the circle beyond the top, at polar angle `beta + gamma`:
/// `beta` is the direction of `p` seen from the centre and `cos gamma = r / |p - c|`.
/// The cable wraps from the entry point (polar angle pi) down to it.
fn tangent_construction(anchor: &Vector3<f64>, radius: f64, point: &Vector3<f64>) -> (Vector3<f64>, f64) {
    let mut u = point - anchor;
    u.z = 0.0;
    let xi = u.norm();
    let u = u / xi;
    let (dx, dz) = (xi - radius, point.z - anchor.z);
    let angle = dz.atan2(dx) + (radius / dx.hypot(dz)).acos();
    let exit = anchor + u * (radius + radius * angle.cos()) + Vector3::z() * (radius * angle.sin());
    (exit, PI - angle)
}

#[test]
fn pulley_exit_point_is_the_tangent_from_the_free_span() {
    let anchor = Vector3::new(-125.0, -110.0, 48.0);
    for radius in [0.05, 0.3, 0.5] {
        for psi_deg in [0.0, 37.0, 135.0, 260.0] {
            let u = Vector3::new(f64::to_radians(psi_deg).cos(), f64::to_radians(psi_deg).sin(), 0.0);
            // Steep, nearly horizontal (either side), nearly vertical, and a point above the pulley.
            for (xi, zeta) in [
                (60.0, -45.0),
                (170.0, -1e-7),
                (170.0, 1e-7),
                (2.0 * radius + 1e-6, -40.0),
                (2.0 * radius + 1e-3, -40.0),
                (20.0, 6.0),
            ] {
                let point = anchor + u * xi + Vector3::z() * zeta;
                let (exit, wrap) = tangent_construction(&anchor, radius, &point);
                let computed = pulley_exit(&anchor, radius, &(exit - point)).unwrap();
                // A nearly vertical span (1e-6 m off vertical over 40 m) fixes the
                // pulley plane only to ~1e-8 rad: its direction comes from a
                // horizontal difference of coordinates of ~100 m.
                let tolerance = if xi < 2.0 * radius + 0.01 {
                    1e-8
                } else {
                    1e-12 * anchor.norm()
                };
                assert!(
                    (computed.exit_point_m - exit).norm() < tolerance,
                    "r {radius} psi {psi_deg} ({xi}, {zeta}): {:?} vs {:?}",
                    computed.exit_point_m.as_slice(),
                    exit.as_slice()
                );
                assert!(
                    (computed.wrap_angle_rad - wrap).abs() < 1e-9,
                    "{} vs {wrap}",
                    computed.wrap_angle_rad
                );
                let radial = computed.exit_point_m - computed.centre_m;
                assert!((radial.norm() - radius).abs() < 1e-12);
                let span = (point - computed.exit_point_m).normalize();
                assert!(
                    radial.dot(&span).abs() < 1e-9 * radius,
                    "not tangent: {}",
                    radial.dot(&span)
                );
            }
        }
        // A cable hanging exactly vertically: no NaN, half a turn of wrap, exit 2 r from the anchor.
        let vertical = pulley_exit(&anchor, radius, &Vector3::new(0.0, 0.0, 300.0)).unwrap();
        assert!(vertical.exit_point_m.iter().all(|x| x.is_finite()));
        assert!((vertical.wrap_angle_rad - PI).abs() < 1e-15);
        assert!(((vertical.exit_point_m - anchor).norm() - 2.0 * radius).abs() < 1e-12);
        // A horizontal cable leaves at the top after a quarter turn.
        let horizontal = pulley_exit(&anchor, radius, &Vector3::new(-300.0, 0.0, 0.0)).unwrap();
        assert!((horizontal.exit_point_m - (anchor + Vector3::new(radius, 0.0, radius))).norm() < 1e-13);
        assert!((horizontal.wrap_angle_rad - PI / 2.0).abs() < 1e-15);
    }
    assert!(pulley_exit(&anchor, 0.3, &Vector3::zeros()).is_none());
    assert!(pulley_exit(&anchor, 0.3, &Vector3::new(f64::NAN, 0.0, 1.0)).is_none());
    assert!(pulley_exit(&anchor, -0.3, &Vector3::z()).is_none());
    let point = pulley_exit(&anchor, 0.0, &Vector3::new(-3.0, 1.0, 2.0)).unwrap();
    assert!(point.exit_point_m == anchor && point.wrap_angle_rad == 0.0);
}

#[test]
fn massless_cables_leave_their_pulleys_along_the_tangent() {
    let mut robot = large();
    robot.cable_weight_n_per_m = 0.0;
    let cf = closed_form(&robot, [12.0, -9.0, 14.0]);
    let stiffness = 1e6;
    for radius in [0.1, 0.5] {
        for segments in [1, 7] {
            let eq = solve(&robot, &options(segments, stiffness, radius), &cf);
            for (i, cable) in eq.cables.iter().enumerate() {
                let attachment = cable.nodes_m[0];
                let (exit, wrap) = tangent_construction(&robot.anchors_m[i], radius, &attachment);
                assert!(
                    (cable.exit_point_m - exit).norm() < 1e-10,
                    "{:?} vs {:?}",
                    cable.exit_point_m,
                    exit
                );
                assert!((cable.wrap_angle_rad - wrap).abs() < 1e-12);
                // A massless chain is straight.
                let chord = (exit - attachment).normalize();
                for node in &cable.nodes_m {
                    let offset = node - attachment;
                    assert!((offset - chord * offset.dot(&chord)).norm() < 1e-10);
                }
                // Paid out = (free span + wrapped arc) shrunk back by the stretch.
                let tension = cable.platform_force_n.norm();
                let paid = ((exit - attachment).norm() + radius * wrap) / (1.0 + tension / stiffness);
                assert!(
                    (paid - cf.cable_lengths_m[i]).abs() < 1e-9,
                    "{paid} vs {}",
                    cf.cable_lengths_m[i]
                );
            }
            println!(
                "massless, r {radius} m, n {segments}: wraps {:.4?} rad",
                eq.cables.iter().map(|c| c.wrap_angle_rad).collect::<Vec<_>>()
            );
        }
    }
}

#[test]
fn equilibrium_tends_to_the_point_pulley_one_as_the_radius_vanishes() {
    let robot = large();
    let cf = closed_form(&robot, [10.0, -8.0, 12.0]);
    let point_pulley = solve(&robot, &options(64, f64::INFINITY, 0.0), &cf);
    let mut previous: Option<f64> = None;
    for radius in [0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 1e-6] {
        let eq = solve(&robot, &options(64, f64::INFINITY, radius), &cf);
        let error = (eq.pose.position_m - point_pulley.pose.position_m).norm();
        let angle = eq.pose.angle_to_deg(&point_pulley.pose);
        let exit_offset = (0..4)
            .map(|i| (eq.cables[i].exit_point_m - robot.anchors_m[i]).norm())
            .fold(0.0, f64::max);
        println!(
            "r {radius:>7} m: pose {error:.3e} m, {angle:.3e} deg from the r = 0 equilibrium; exit points within {exit_offset:.3e} m of the anchors"
        );
        assert!(exit_offset <= 2.0 * radius);
        if let Some(p) = previous.filter(|_| radius > 1e-3) {
            assert!(
                (1.8..=2.2).contains(&(p / error)),
                "halving r must halve the error: {}",
                p / error
            );
        }
        previous = Some(error);
        if radius < 1e-3 {
            assert!(error < 1e-4 && angle < 1e-4, "{error} {angle}");
        }
    }
}

#[test]
fn converges_from_the_closed_form_start_over_the_required_range() {
    let mut count = 0;
    for name in ["large", "small"] {
        let robot = Robot::builtin(name).unwrap();
        let positions: [[f64; 3]; 2] = if name == "large" {
            [[0.0, 0.0, 15.0], [-25.0, 20.0, 3.0]]
        } else {
            [[0.0, 0.0, 10.0], [1.5, -0.6, 16.0]]
        };
        for position in positions {
            let cf = closed_form(&robot, position);
            for segments in [2, 10, 100, 2000] {
                for stiffness in [f64::INFINITY, 1e5] {
                    for radius in [0.0, 0.5] {
                        for com_shift in [0.0, 0.1] {
                            let mut o = options(segments, stiffness, radius);
                            o.com_offset_m = Some(robot.com_offset_m + Vector3::new(com_shift, 0.0, 0.0));
                            let eq = solve(&robot, &o, &cf);
                            let r = equilibrium_residual_n(&robot, &o, &eq);
                            let floor = spring_law_floor_n(&eq, &o);
                            assert!(r.max_n() < 1e-9 * robot.platform_weight_n + 10.0 * floor, "{r:?}");
                            assert!(r.max_m() < 1e-10, "{r:?}");
                            count += 1;
                        }
                    }
                }
            }
        }
    }
    println!("{count} equilibria solved");
}

#[test]
fn one_segment_per_cable_is_a_rod_and_may_have_no_taut_equilibrium() {
    let robot = large();
    // At the centre the four rods find an equilibrium ...
    let cf = closed_form(&robot, [0.0, 0.0, 15.0]);
    let eq = solve(&robot, &options(1, f64::INFINITY, 0.0), &cf);
    println!(
        "n = 1 at the centre: {:.3} m from the catenary pose",
        (eq.pose.position_m - cf.pose.position_m).norm()
    );
    // ... off centre four straight rods cannot take up the catenaries'
    // different sag excesses: a clear error, never a panic or NaN.
    let cf = closed_form(&robot, [-30.0, -12.0, 14.0]);
    let guess = InitialGuess::from_closed_form(&robot, &cf);
    match solve_forward(&robot, &options(1, f64::INFINITY, 0.0), &cf.cable_lengths_m, &guess) {
        Err(Error::NoEquilibrium(message)) => println!("n = 1 off centre: {message}"),
        Ok(eq) => assert!(eq.max_residual_n.is_finite() && eq.pose.position_m.iter().all(|x| x.is_finite())),
        Err(other) => panic!("unexpected error {other}"),
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let robot = large();
    let cf = closed_form(&robot, [0.0, 0.0, 15.0]);
    let guess = InitialGuess::from_closed_form(&robot, &cf);
    let good = options(20, 1e6, 0.2);
    let lengths = cf.cable_lengths_m;
    let invalid = |o: &DiscretisedOptions, l: &[f64; 4], g: &InitialGuess| {
        matches!(solve_forward(&robot, o, l, g), Err(Error::InvalidInput(_)))
    };
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut l = lengths;
        l[2] = bad;
        assert!(invalid(&good, &l, &guess), "length {bad}");
    }
    assert!(invalid(&options(0, 1e6, 0.2), &lengths, &guess));
    assert!(invalid(
        &options(discretised::MAX_SEGMENTS + 1, 1e6, 0.2),
        &lengths,
        &guess
    ));
    for bad in [0.0, -1e6, f64::NAN] {
        assert!(invalid(&options(20, bad, 0.2), &lengths, &guess), "EA {bad}");
    }
    for bad in [-0.1, f64::NAN, f64::INFINITY] {
        assert!(invalid(&options(20, 1e6, bad), &lengths, &guess), "radius {bad}");
    }
    let mut nan_com = good;
    nan_com.com_offset_m = Some(Vector3::new(0.0, f64::NAN, 0.0));
    assert!(invalid(&nan_com, &lengths, &guess));
    let nan_pose = InitialGuess::from_pose(PlatformPose::new(
        Vector3::new(f64::NAN, 0.0, 1.0),
        UnitQuaternion::identity(),
    ));
    assert!(invalid(&good, &lengths, &nan_pose));
    let mut nan_forces = guess;
    nan_forces.platform_forces_n.as_mut().unwrap()[1].z = f64::NAN;
    assert!(invalid(&good, &lengths, &nan_forces));
    let mut nan_robot = robot.clone();
    nan_robot.anchors_m[3].y = f64::NAN;
    assert!(matches!(
        solve_forward(&nan_robot, &good, &lengths, &guess),
        Err(Error::InvalidInput(_))
    ));
    // Inextensible cables far too short to reach the platform: no equilibrium, reported as such.
    // (Elastic ones would stretch: the linear spring law holds at any strain.)
    assert!(matches!(
        solve_forward(&robot, &options(20, f64::INFINITY, 0.2), &[5.0; 4], &guess),
        Err(Error::NoEquilibrium(_))
    ));
    // The single-cable solver too.
    let (a, b) = (Vector3::zeros(), Vector3::new(100.0, 0.0, 30.0));
    let invalid_cable = |start: &Vector3<f64>, end: &Vector3<f64>, length: f64, w: f64, n: usize| {
        matches!(solve_cable(start, end, length, w, n, 1e6), Err(Error::InvalidInput(_)))
    };
    assert!(invalid_cable(&a, &b, -1.0, 0.7, 10));
    assert!(invalid_cable(&a, &b, f64::NAN, 0.7, 10));
    assert!(invalid_cable(&a, &b, 120.0, 0.7, 0));
    assert!(invalid_cable(&a, &b, 120.0, f64::NAN, 10));
    assert!(invalid_cable(&a, &Vector3::new(f64::NAN, 0.0, 0.0), 120.0, 0.7, 10));
    // An inextensible cable shorter than the distance between its ends cannot hang there ...
    assert!(matches!(
        solve_cable(&a, &b, 90.0, 0.7, 10, f64::INFINITY),
        Err(Error::NoEquilibrium(_))
    ));
    // ... an elastic one stretches.
    let stretched = solve_cable(&a, &b, 100.0, 0.7, 10, 1e6).unwrap();
    assert!(stretched.segment_tensions_n.iter().all(|t| t.is_finite() && *t > 1e3));
}

#[test]
fn one_equilibrium_is_fast() {
    let robot = large();
    let cf = closed_form(&robot, [10.0, -8.0, 12.0]);
    let guess = InitialGuess::from_closed_form(&robot, &cf);
    for segments in [100, 1000] {
        let o = options(segments, 1e6, 0.3);
        let repeats = 20;
        let start = std::time::Instant::now();
        for _ in 0..repeats {
            solve_forward(&robot, &o, &cf.cable_lengths_m, &guess).unwrap();
        }
        let each = start.elapsed().as_secs_f64() / repeats as f64;
        println!(
            "n = {segments}: {:.3} ms per equilibrium (EA 1e6 N, r 0.3 m, closed-form start, this build profile)",
            each * 1e3
        );
        assert!(each < 0.05);
    }
}

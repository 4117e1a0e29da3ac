//! The static equilibrium closed by one more measurement (module docs of
//! [`super`]): (a) the load cell, (b) the four cable lengths, (c) lengths only
//! with the position unknown; each by a small dense Levenberg-Marquardt over
//! one pose's unknowns.

use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3, Vector6};

use super::equations::{
    attachment_height_residuals, cable_geometry, cable_tensions, catenaries, CableTension, Equilibrium, StaticsOptions,
};
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};

/// A small dense Levenberg-Marquardt with central-difference Jacobians, for
/// the 4-8 unknowns of one pose. `residual` returns `None` where the model is
/// undefined (a slack cable): such a trial step is rejected like a bad one.
fn dense_least_squares(
    start: DVector<f64>,
    steps: &DVector<f64>,
    max_iterations: usize,
    residual: impl Fn(&DVector<f64>) -> Option<DVector<f64>>,
) -> Option<(DVector<f64>, usize)> {
    let mut x = start;
    let mut r = residual(&x)?;
    let mut cost = r.norm_squared();
    let mut damping = 1e-6;
    for iteration in 1..=max_iterations {
        let n = x.len();
        let mut jacobian = DMatrix::<f64>::zeros(r.len(), n);
        for j in 0..n {
            let mut plus = x.clone();
            let mut minus = x.clone();
            plus[j] += steps[j];
            minus[j] -= steps[j];
            let (rp, rm) = (residual(&plus)?, residual(&minus)?);
            jacobian.set_column(j, &((rp - rm) / (2.0 * steps[j])));
        }
        let hessian = jacobian.transpose() * &jacobian;
        let gradient = jacobian.transpose() * &r;
        let mut accepted = false;
        for _ in 0..30 {
            let mut damped = hessian.clone();
            for k in 0..n {
                damped[(k, k)] += damping * hessian[(k, k)].max(1e-12);
            }
            let Some(step) = damped.cholesky().map(|c| -c.solve(&gradient)) else {
                damping *= 10.0;
                continue;
            };
            let trial = &x + &step;
            match residual(&trial) {
                Some(rt) if rt.norm_squared() < cost => {
                    let small_step = step.iter().zip(steps.iter()).all(|(d, h)| d.abs() < 1e-6 * h);
                    x = trial;
                    r = rt;
                    cost = r.norm_squared();
                    damping = (damping / 10.0).max(1e-12);
                    accepted = true;
                    if small_step || cost < 1e-30 {
                        return Some((x, iteration));
                    }
                    break;
                }
                _ => damping *= 10.0,
            }
        }
        if !accepted {
            return Some((x, iteration));
        }
    }
    Some((x, max_iterations))
}

fn rotated(base: &UnitQuaternion<f64>, x: &DVector<f64>) -> UnitQuaternion<f64> {
    base * UnitQuaternion::from_scaled_axis(Vector3::new(x[0], x[1], x[2]))
}

fn check_equilibrium(equilibrium: Equilibrium, options: &StaticsOptions, what: &str) -> Result<Equilibrium> {
    if let Some((i, t)) = equilibrium.tensions.iter().enumerate().find(|(_, t)| !t.is_taut()) {
        return Err(Error::NoEquilibrium(format!(
            "{what}: cable {} would have to push (horizontal tension {:.3} N)",
            i + 1,
            t.horizontal_n
        )));
    }
    let residual = equilibrium.max_height_residual_m();
    if residual.is_nan() || residual > options.height_tolerance_m {
        return Err(Error::NoEquilibrium(format!(
            "{what}: no orientation lets all four catenaries reach the platform (attachment height residual {:.3e} m after {} iterations)",
            equilibrium.max_height_residual_m(),
            equilibrium.iterations
        )));
    }
    Ok(equilibrium)
}

/// A reference-cable tension of magnitude `magnitude_n` whose direction
/// follows the chord to the anchor, flattened by the sag (`u ~ dz/L - lambda/2`).
fn reference_tension_guess(robot: &Robot, pose: &PlatformPose, magnitude_n: f64) -> f64 {
    let geometry = cable_geometry(robot, pose)[robot.reference_cable];
    let half_lambda = 0.5 * robot.cable_weight_n_per_m * geometry.span_m / magnitude_n;
    (geometry.height_difference_m / geometry.span_m - half_lambda).atan()
}

/// The state at `pose` with a reference tension of magnitude
/// `reference_tension_n` along its sag-corrected chord (as the search of
/// [`solve_with_reference_tension`] starts), not solved: the attachment
/// heights are generally not met (`height_residuals_m` says by how much). A
/// start for a model that extends the closed form. An error where the
/// tensions of eq. (11) cannot be formed at this pose.
pub fn unsolved_at(robot: &Robot, pose: PlatformPose, reference_tension_n: f64) -> Result<Equilibrium> {
    if !(reference_tension_n.is_finite() && reference_tension_n > 0.0) {
        return Err(Error::InvalidInput(format!(
            "reference-cable tension must be positive, got {reference_tension_n} N"
        )));
    }
    let phi = reference_tension_guess(robot, &pose, reference_tension_n);
    let reference = CableTension {
        horizontal_n: reference_tension_n * phi.cos(),
        vertical_n: reference_tension_n * phi.sin(),
    };
    Equilibrium::evaluate(robot, pose, reference, 0)
}

/// Problem (a): position and the load cell's reference-tension magnitude
/// (paper eq. 16) -> orientation, all four tensions, catenary lengths.
///
/// The reference tension is parametrised as `f_m (cos phi, sin phi)`, so the
/// unknowns `(orientation, phi)` meet the four attachment-height equations
/// exactly (a square Newton system). `initial_rotation` defaults to level.
pub fn solve_with_reference_tension(
    robot: &Robot,
    position_m: Vector3<f64>,
    reference_tension_n: f64,
    initial_rotation: Option<UnitQuaternion<f64>>,
    options: &StaticsOptions,
) -> Result<Equilibrium> {
    if !(reference_tension_n.is_finite() && reference_tension_n > 0.0) {
        return Err(Error::InvalidInput(format!(
            "reference-cable tension must be positive, got {reference_tension_n} N"
        )));
    }
    let base = initial_rotation.unwrap_or_else(UnitQuaternion::identity);
    let base_pose = PlatformPose::new(position_m, base);
    let phi0 = reference_tension_guess(robot, &base_pose, reference_tension_n);
    let reference = |phi: f64| CableTension {
        horizontal_n: reference_tension_n * phi.cos(),
        vertical_n: reference_tension_n * phi.sin(),
    };
    let residual = |x: &DVector<f64>| -> Option<DVector<f64>> {
        let pose = PlatformPose::new(position_m, rotated(&base, x));
        let tensions = cable_tensions(robot, &pose, reference(x[3])).ok()?;
        if !tensions.iter().all(CableTension::is_taut) {
            return None;
        }
        Some(DVector::from_row_slice(&attachment_height_residuals(
            robot, &pose, &tensions,
        )))
    };
    let steps = DVector::from_row_slice(&[1e-7, 1e-7, 1e-7, 1e-7]);
    let mut best: Option<Equilibrium> = None;
    // Start at the sag-corrected chord angle; if eq. (11) yields a slack cable
    // there, widen the search over the reference cable's angle.
    for offset_deg in [0.0, 5.0, -5.0, 10.0, -10.0, 20.0, -20.0] {
        let start = DVector::from_row_slice(&[0.0, 0.0, 0.0, phi0 + f64::to_radians(offset_deg)]);
        let Some((x, iterations)) = dense_least_squares(start, &steps, options.max_iterations, residual) else {
            continue;
        };
        let pose = PlatformPose::new(position_m, rotated(&base, &x));
        let equilibrium = Equilibrium::evaluate(robot, pose, reference(x[3]), iterations)?;
        if equilibrium.max_height_residual_m() <= options.height_tolerance_m {
            return check_equilibrium(equilibrium, options, "position + reference tension");
        }
        if best
            .as_ref()
            .is_none_or(|b| equilibrium.max_height_residual_m() < b.max_height_residual_m())
        {
            best = Some(equilibrium);
        }
    }
    match best {
        Some(equilibrium) => check_equilibrium(equilibrium, options, "position + reference tension"),
        None => Err(Error::NoEquilibrium(format!(
            "position {:?} with reference tension {reference_tension_n} N: every start gives a slack cable",
            position_m.as_slice()
        ))),
    }
}

/// The most level equilibrium at `position_m`: the member of the
/// one-parameter family whose orientation is closest to the nominal one
/// (smallest rotation angle: tilt and yaw together; at the centre of the
/// workspace the family is a pure yaw twist, so tilt alone would not choose).
/// This is how a robot that commands its cable lengths for a level, unrotated
/// platform hangs; the search runs over the reference-tension magnitude (a
/// grid from 0.5 to 2 times the straight-cable guess, then golden-section
/// refinement).
pub fn solve_level(robot: &Robot, position_m: Vector3<f64>, options: &StaticsOptions) -> Result<Equilibrium> {
    let guess = reference_tension_magnitude_guess(robot, position_m);
    let tilt = |eq: &Equilibrium| eq.pose.rotation.angle();
    let evaluate = |magnitude: f64| solve_with_reference_tension(robot, position_m, magnitude, None, options).ok();
    let mut best: Option<(f64, f64)> = None;
    let step = 0.05;
    let mut factor = 0.5;
    while factor <= 2.0 + 1e-9 {
        if let Some(eq) = evaluate(guess * factor) {
            let t = tilt(&eq);
            if best.is_none_or(|(_, bt)| t < bt) {
                best = Some((factor, t));
            }
        }
        factor += step;
    }
    let (center, _) = best.ok_or_else(|| {
        Error::NoEquilibrium(format!(
            "position {:?}: no positive-tension equilibrium for reference tensions between {:.1} and {:.1} N",
            position_m.as_slice(),
            0.5 * guess,
            2.0 * guess
        ))
    })?;
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (center - step, center + step);
    let cost = |f: f64| evaluate(guess * f).map_or(f64::INFINITY, |eq| tilt(&eq));
    let (mut x1, mut x2) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
    let (mut c1, mut c2) = (cost(x1), cost(x2));
    for _ in 0..40 {
        if c1 <= c2 {
            hi = x2;
            x2 = x1;
            c2 = c1;
            x1 = hi - phi * (hi - lo);
            c1 = cost(x1);
        } else {
            lo = x1;
            x1 = x2;
            c1 = c2;
            x2 = lo + phi * (hi - lo);
            c2 = cost(x2);
        }
    }
    let best_factor = if c1 <= c2 { x1 } else { x2 };
    let candidates = [best_factor, center];
    candidates
        .iter()
        .filter_map(|&f| evaluate(guess * f))
        .min_by(|a, b| tilt(a).total_cmp(&tilt(b)))
        .ok_or_else(|| Error::NoEquilibrium(format!("position {:?}: level search failed", position_m.as_slice())))
}

/// The grid of the family scans, as multiples of
/// [`reference_tension_magnitude_guess`]: 0.5, 0.55, .., 2 (as in [`solve_level`]).
const FAMILY_GRID: std::ops::RangeInclusive<usize> = 0..=30;
/// The grid point at 1 x the guess, where a family scan starts.
const FAMILY_GRID_GUESS: usize = 10;

fn family_factor(index: usize) -> f64 {
    0.5 + 0.05 * index as f64
}

/// Adjacent scanned members further apart than this (rotation angle, radians)
/// lie on different branches: no yaw bracket between them.
const FAMILY_BRANCH_JUMP_RAD: f64 = 0.2;
/// How close the yaw closure brings the yaw to its target, radians.
pub const YAW_TOLERANCE_RAD: f64 = 1e-10;

/// `a - b` wrapped into `(-pi, pi]`.
fn angle_difference_rad(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

/// The one-parameter family at `position_m` on the grid of reference-tension
/// magnitudes `0.5 .. 2 x` [`reference_tension_magnitude_guess`], in
/// increasing magnitude: `(magnitude_n, equilibrium)` for every grid point
/// with a positive-tension equilibrium. The scan follows the family by
/// continuation: it starts at the guess from a level platform and walks up,
/// then down, each solve started from the previous member's orientation (a
/// level start far from level can land on another branch, e.g. the platform
/// turned by ~180 degrees).
pub fn scan_family(robot: &Robot, position_m: Vector3<f64>, options: &StaticsOptions) -> Vec<(f64, Equilibrium)> {
    let guess = reference_tension_magnitude_guess(robot, position_m);
    let solve = |index: usize, start: Option<UnitQuaternion<f64>>| {
        let magnitude = guess * family_factor(index);
        solve_with_reference_tension(robot, position_m, magnitude, start, options)
            .ok()
            .map(|eq| (magnitude, eq))
    };
    let centre = solve(FAMILY_GRID_GUESS, None);
    let centre_rotation = centre.as_ref().map(|(_, eq)| eq.pose.rotation);
    let walk = |indices: &mut dyn Iterator<Item = usize>| {
        let mut start = centre_rotation;
        let mut members = Vec::new();
        for index in indices {
            if let Some(member) = solve(index, start) {
                start = Some(member.1.pose.rotation);
                members.push(member);
            }
        }
        members
    };
    let up = walk(&mut (FAMILY_GRID_GUESS + 1..=*FAMILY_GRID.end()));
    let mut members = walk(&mut (*FAMILY_GRID.start()..FAMILY_GRID_GUESS).rev());
    members.reverse();
    members.extend(centre);
    members.extend(up);
    members
}

/// The yaw closure: the static equilibrium at `position_m` whose yaw
/// ([`PlatformPose::yaw_rad`]: `R = Rz(yaw) Ry(pitch) Rx(roll)`, the rotation
/// about the world z axis) is `yaw_rad`, to [`YAW_TOLERANCE_RAD`].
///
/// With one reference cable, the six equilibrium equations (paper eq. 5-8)
/// give the other cables' tensions (eq. 11) and the four catenaries must reach
/// their attachments (eq. 15): orientation (3) and reference tension (2)
/// against four height equations leave one free parameter at a fixed
/// position. The load cell (eq. 16, [`solve_with_reference_tension`]) or the
/// most level member ([`solve_level`]) close it; here the yaw does, as a
/// platform settles wherever its statics put it. The family is scanned over
/// the reference-tension magnitude ([`scan_family`]); a bracket where
/// `yaw - yaw_rad` changes sign between adjacent members of one branch (the
/// most level one if there are several) is then refined by the Illinois variant of
/// regula falsi, every evaluation an exact (a)-solve.
///
/// Fails with [`Error::NoEquilibrium`] where the family does not reach the
/// yaw, naming the yaw range it spans at `position_m`.
pub fn solve_with_yaw(
    robot: &Robot,
    position_m: Vector3<f64>,
    yaw_rad: f64,
    options: &StaticsOptions,
) -> Result<Equilibrium> {
    if !yaw_rad.is_finite() {
        return Err(Error::InvalidInput(format!(
            "yaw must be a finite angle, got {yaw_rad} rad"
        )));
    }
    let members = scan_family(robot, position_m, options);
    let offset = |eq: &Equilibrium| angle_difference_rad(eq.pose.yaw_rad(), yaw_rad);
    if let Some((_, eq)) = members.iter().find(|(_, eq)| offset(eq).abs() <= YAW_TOLERANCE_RAD) {
        return Ok(eq.clone());
    }
    let bracket = members
        .windows(2)
        .filter(|pair| {
            let (a, b) = (offset(&pair[0].1), offset(&pair[1].1));
            // Through zero, not through the +-pi of the wrapped offset, and on one branch.
            a.signum() != b.signum()
                && (a - b).abs() < std::f64::consts::PI
                && pair[0].1.pose.rotation.angle_to(&pair[1].1.pose.rotation) < FAMILY_BRANCH_JUMP_RAD
        })
        .min_by(|a, b| {
            let tilt =
                |pair: &[(f64, Equilibrium)]| pair[0].1.pose.rotation.angle().max(pair[1].1.pose.rotation.angle());
            tilt(a).total_cmp(&tilt(b))
        });
    let Some(pair) = bracket else {
        return Err(unreachable_yaw(robot, position_m, yaw_rad, &members));
    };
    let evaluate = |magnitude: f64, start: &Equilibrium| {
        solve_with_reference_tension(robot, position_m, magnitude, Some(start.pose.rotation), options).ok()
    };
    refine_yaw(&pair[0], &pair[1], &offset, &evaluate).ok_or_else(|| {
        Error::NoEquilibrium(format!(
            "position {:?}: the yaw search for {:.4} deg did not converge between reference tensions {:.3} and {:.3} N",
            position_m.as_slice(),
            yaw_rad.to_degrees(),
            pair[0].0,
            pair[1].0
        ))
    })
}

/// The error of a yaw the family at `position_m` does not reach.
fn unreachable_yaw(robot: &Robot, position_m: Vector3<f64>, yaw_rad: f64, members: &[(f64, Equilibrium)]) -> Error {
    let guess = reference_tension_magnitude_guess(robot, position_m);
    let (low, high) = (
        family_factor(*FAMILY_GRID.start()) * guess,
        family_factor(*FAMILY_GRID.end()) * guess,
    );
    if members.is_empty() {
        return Error::NoEquilibrium(format!(
            "position {:?}: no positive-tension equilibrium for reference tensions between {low:.1} and {high:.1} N",
            position_m.as_slice()
        ));
    }
    let (min, max) = members
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, eq)| {
            let yaw = eq.pose.yaw_rad();
            (lo.min(yaw), hi.max(yaw))
        });
    Error::NoEquilibrium(format!(
        "position {:?}: no equilibrium with yaw {:.3} deg; the family spans yaw {:.3} .. {:.3} deg for reference tensions between {low:.1} and {high:.1} N",
        position_m.as_slice(),
        yaw_rad.to_degrees(),
        min.to_degrees(),
        max.to_degrees()
    ))
}

/// Regula falsi (Illinois) on the reference-tension magnitude between two
/// members whose yaw offsets have opposite signs, until the offset is below
/// [`YAW_TOLERANCE_RAD`]; bisection where an evaluation fails. Each trial is
/// solved from the orientation of the nearer bracket end.
fn refine_yaw(
    low: &(f64, Equilibrium),
    high: &(f64, Equilibrium),
    offset: &dyn Fn(&Equilibrium) -> f64,
    evaluate: &dyn Fn(f64, &Equilibrium) -> Option<Equilibrium>,
) -> Option<Equilibrium> {
    let (mut a, mut b) = (low.clone(), high.clone());
    let (mut fa, mut fb) = (offset(&a.1), offset(&b.1));
    let mut kept = 0i8;
    for _ in 0..100 {
        let secant = b.0 - fb * (b.0 - a.0) / (fb - fa);
        let middle = 0.5 * (a.0 + b.0);
        let start = |x: f64| if (x - a.0).abs() < (b.0 - x).abs() { &a.1 } else { &b.1 };
        let inside = secant.is_finite() && secant > a.0.min(b.0) && secant < a.0.max(b.0);
        let trial = inside.then(|| evaluate(secant, start(secant))).flatten();
        let (x, eq) = match trial {
            Some(eq) => (secant, eq),
            None => (middle, evaluate(middle, start(middle))?),
        };
        let fx = offset(&eq);
        if fx.abs() <= YAW_TOLERANCE_RAD {
            return Some(eq);
        }
        if (b.0 - a.0).abs() <= 1e-14 * x.abs() {
            return None;
        }
        if fx.signum() == fa.signum() {
            (a, fa) = ((x, eq), fx);
            // b kept twice in a row: halve its offset (Illinois) so the secant moves b too.
            if kept == 1 {
                fb *= 0.5;
            }
            kept = 1;
        } else {
            (b, fb) = ((x, eq), fx);
            if kept == -1 {
                fa *= 0.5;
            }
            kept = -1;
        }
    }
    None
}

/// A rough reference-tension magnitude for a position, newtons: the straight-cable
/// force balance `sum t_i e_i = m_e g z` solved in the least-norm sense.
pub fn reference_tension_magnitude_guess(robot: &Robot, position_m: Vector3<f64>) -> f64 {
    let pose = PlatformPose::from_position(position_m);
    let geometry = cable_geometry(robot, &pose);
    let mut directions = nalgebra::Matrix3x4::<f64>::zeros();
    for (i, cable) in geometry.iter().enumerate() {
        directions.set_column(i, &(robot.anchors_m[i] - cable.attachment_world_m).normalize());
    }
    let weight = Vector3::new(0.0, 0.0, robot.platform_weight_n);
    let tensions = directions.pseudo_inverse(1e-12).map(|p| p * weight).ok();
    let guess = tensions.map(|t| t[robot.reference_cable]).unwrap_or(0.0);
    // Cable weight hangs on the platform too: add half of the reference cable's.
    let cable_weight = 0.5 * robot.cable_weight_n_per_m * (robot.anchors_m[robot.reference_cable] - position_m).norm();
    if guess.is_finite() && guess > 0.0 {
        guess + cable_weight
    } else {
        robot.platform_weight_n / CABLE_COUNT as f64 + cable_weight
    }
}

/// Problem (b): position and the four (true, offset-free) cable lengths ->
/// orientation and tensions.
///
/// The equilibria at a fixed position form a one-parameter family, which (a)
/// parametrises by the reference-tension magnitude `f_m`. (b) walks along that
/// family: Gauss-Newton on the single unknown `f_m`, minimising the squared
/// length errors, every evaluation an exact (a)-solve. The attachment heights
/// (eq. 15) therefore hold exactly while the lengths are fitted in the
/// least-squares sense.
pub fn solve_with_cable_lengths(
    robot: &Robot,
    position_m: Vector3<f64>,
    cable_lengths_m: &[f64; CABLE_COUNT],
    options: &StaticsOptions,
) -> Result<Equilibrium> {
    validate_lengths(cable_lengths_m)?;
    let (mut magnitude, mut current) = feasible_start(robot, position_m, None, options)?;
    let length_errors = |eq: &Equilibrium| -> [f64; CABLE_COUNT] {
        std::array::from_fn(|i| eq.cable_lengths_m[i] - cable_lengths_m[i])
    };
    let sum_sq = |r: &[f64; CABLE_COUNT]| r.iter().map(|x| x * x).sum::<f64>();
    let mut iterations = current.iterations;
    for _ in 0..options.max_iterations {
        let h = 1e-6 * magnitude;
        let plus =
            solve_with_reference_tension(robot, position_m, magnitude + h, Some(current.pose.rotation), options)?;
        let minus =
            solve_with_reference_tension(robot, position_m, magnitude - h, Some(current.pose.rotation), options)?;
        let r = length_errors(&current);
        let slope: [f64; CABLE_COUNT] =
            std::array::from_fn(|i| (plus.cable_lengths_m[i] - minus.cable_lengths_m[i]) / (2.0 * h));
        let jtj: f64 = slope.iter().map(|d| d * d).sum();
        let jtr: f64 = slope.iter().zip(r.iter()).map(|(d, e)| d * e).sum();
        let mut step = -jtr / jtj;
        let cost = sum_sq(&r);
        let mut accepted = None;
        // Halve the step until the cost does not increase and the family still exists.
        for _ in 0..40 {
            let trial = magnitude + step;
            if trial > 0.0 {
                if let Ok(eq) =
                    solve_with_reference_tension(robot, position_m, trial, Some(current.pose.rotation), options)
                {
                    if sum_sq(&length_errors(&eq)) <= cost {
                        accepted = Some((trial, eq));
                        break;
                    }
                }
            }
            step *= 0.5;
        }
        let Some((trial, eq)) = accepted else { break };
        iterations += eq.iterations;
        magnitude = trial;
        current = eq;
        if step.abs() <= 1e-12 * magnitude {
            break;
        }
    }
    current.iterations = iterations;
    Ok(current)
}

/// A point of the one-parameter family at `position_m`: the straight-cable
/// guess of the reference tension, or, where the family does not extend that
/// far (a slack cable), the nearest of a ladder of magnitudes around it.
pub fn feasible_start(
    robot: &Robot,
    position_m: Vector3<f64>,
    initial_rotation: Option<UnitQuaternion<f64>>,
    options: &StaticsOptions,
) -> Result<(f64, Equilibrium)> {
    let guess = reference_tension_magnitude_guess(robot, position_m);
    let mut first_error = None;
    for factor in [1.0, 1.2, 0.85, 1.5, 0.7, 2.0, 0.5, 3.0] {
        match solve_with_reference_tension(robot, position_m, guess * factor, initial_rotation, options) {
            Ok(eq) => return Ok((guess * factor, eq)),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.unwrap_or_else(|| Error::NoEquilibrium("no start for the statics".into())))
}

fn validate_lengths(cable_lengths_m: &[f64; CABLE_COUNT]) -> Result<()> {
    if let Some((i, l)) = cable_lengths_m
        .iter()
        .enumerate()
        .find(|(_, l)| !(l.is_finite() && **l > 0.0))
    {
        return Err(Error::InvalidInput(format!(
            "cable {} length must be a positive number of metres, got {l}",
            i + 1
        )));
    }
    Ok(())
}

/// Problem (c), the forward kineto-statics (localisation): the four cable
/// lengths -> pose and tensions. Eight equations (4 heights, 4 lengths) in
/// eight unknowns (pose, reference tension). Without `initial_guess` the
/// start is the straight-cable trilateration of the lengths.
pub fn solve_forward(
    robot: &Robot,
    cable_lengths_m: &[f64; CABLE_COUNT],
    initial_guess: Option<PlatformPose>,
    options: &StaticsOptions,
) -> Result<Equilibrium> {
    validate_lengths(cable_lengths_m)?;
    let start_position = match initial_guess {
        Some(pose) => pose.position_m,
        None => trilaterate(robot, cable_lengths_m),
    };
    let (_, start) = feasible_start(robot, start_position, initial_guess.map(|p| p.rotation), options)?;
    let reference = start.tensions[robot.reference_cable];
    let base = start.pose;
    let residual = |x: &DVector<f64>| -> Option<DVector<f64>> {
        let pose = base.retract(&Vector6::new(x[0], x[1], x[2], x[3], x[4], x[5]));
        let tensions = cable_tensions(
            robot,
            &pose,
            CableTension {
                horizontal_n: x[6],
                vertical_n: x[7],
            },
        )
        .ok()?;
        if !tensions.iter().all(CableTension::is_taut) {
            return None;
        }
        let heights = attachment_height_residuals(robot, &pose, &tensions);
        let cables = catenaries(robot, &pose, &tensions);
        let mut r = DVector::zeros(2 * CABLE_COUNT);
        for i in 0..CABLE_COUNT {
            r[i] = heights[i];
            r[CABLE_COUNT + i] = cables[i].length_m() - cable_lengths_m[i];
        }
        Some(r)
    };
    let mut x0 = DVector::zeros(8);
    x0[6] = reference.horizontal_n;
    x0[7] = reference.vertical_n;
    let tension_step = 1e-6 * reference.horizontal_n;
    let steps = DVector::from_row_slice(&[1e-7, 1e-7, 1e-7, 1e-6, 1e-6, 1e-6, tension_step, tension_step]);
    let (x, iterations) = dense_least_squares(x0, &steps, options.max_iterations, residual)
        .ok_or_else(|| Error::NoEquilibrium("forward kineto-statics: the start has a slack cable".into()))?;
    let pose = base.retract(&Vector6::new(x[0], x[1], x[2], x[3], x[4], x[5]));
    let equilibrium = Equilibrium::evaluate(
        robot,
        pose,
        CableTension {
            horizontal_n: x[6],
            vertical_n: x[7],
        },
        iterations + start.iterations,
    )?;
    let length_error = (0..CABLE_COUNT)
        .map(|i| (equilibrium.cable_lengths_m[i] - cable_lengths_m[i]).abs())
        .fold(0.0, f64::max);
    if length_error > 1e-6 {
        return Err(Error::NoEquilibrium(format!(
            "forward kineto-statics: no pose reproduces the cable lengths (worst length error {length_error:.3e} m)"
        )));
    }
    check_equilibrium(equilibrium, options, "forward kineto-statics")
}

/// Position whose straight-line distances to the anchors best match the
/// lengths (attachments taken at a level platform), by Gauss-Newton from
/// below the anchors' centroid.
fn trilaterate(robot: &Robot, cable_lengths_m: &[f64; CABLE_COUNT]) -> Vector3<f64> {
    let centroid = robot.anchors_m.iter().sum::<Vector3<f64>>() / CABLE_COUNT as f64;
    let mean_length = cable_lengths_m.iter().sum::<f64>() / CABLE_COUNT as f64;
    let mut start = centroid;
    start.z -= 0.5 * mean_length;
    let residual = |x: &DVector<f64>| -> Option<DVector<f64>> {
        let p = Vector3::new(x[0], x[1], x[2]);
        Some(DVector::from_iterator(
            CABLE_COUNT,
            (0..CABLE_COUNT).map(|i| (robot.anchors_m[i] - p - robot.attachments_m[i]).norm() - cable_lengths_m[i]),
        ))
    };
    let x0 = DVector::from_row_slice(start.as_slice());
    let steps = DVector::from_element(3, 1e-6);
    dense_least_squares(x0, &steps, 100, residual)
        .map(|(x, _)| Vector3::new(x[0], x[1], x[2]))
        .unwrap_or(start)
}

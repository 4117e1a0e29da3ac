//! A start for the anchors that does not depend on the guess
//! ([`anchors_by_trilateration`]): the second start of
//! [`super::calibrate_suspended`] where the first ends in a minimum that
//! fails its test.
//!
//! With the platform's pose taken from the localiser, each cable's anchor
//! and offset are four unknowns of that cable alone: straight cables read
//! `l_j = |a - w_j| + l0` at the attachment's world position `w_j = p_j +
//! R_j b` of pose `j` (trilateration with an unknown range offset, the
//! catenary's excess over its chord, a few centimetres, ignored as in the
//! paper's initialisation, eq. 17-18). Each cable's least squares is
//! solved by Levenberg-Marquardt from many starts: the guess's anchor and
//! [`STARTS`] points spread over the hemisphere above the poses' centroid
//! at the median reading's distance (a suspended robot's anchors are above
//! its platform), the lowest sum of squares kept. Four unknowns a cable
//! make the search cheap (a few thousand evaluations of nine residuals) and
//! global enough that a guess ten metres off, which can lead the joint
//! straight-cable fit into another basin, does not decide it.
//!
//! ```
//! use sagcal::calib::suspended::anchors_by_trilateration;
//! use sagcal::model::suspended::{SuspendedMeasurement, SuspendedRobot};
//! let robot = SuspendedRobot::builtin("three")?;
//! // Straight readings of the true anchors at a few level poses, offsets 0.25 m.
//! let rows: Vec<SuspendedMeasurement> = [[0.5, 0.2, 3.0], [-1.0, 0.8, 5.0], [1.5, -1.0, 4.0], [0.0, -2.0, 6.0], [-2.0, -0.5, 2.5]]
//!     .iter()
//!     .map(|p| SuspendedMeasurement {
//!         line: 0,
//!         position_m: *p,
//!         roll_deg: 0.0,
//!         pitch_deg: 0.0,
//!         yaw_deg: 0.0,
//!         encoder_lengths_m: (0..3)
//!             .map(|i| (robot.anchors_m[i] - (nalgebra::Vector3::from(*p) + robot.attachments_m[i])).norm() + 0.25)
//!             .collect(),
//!         load_cell_tensions_n: vec![100.0],
//!     })
//!     .collect();
//! let mut guess = robot.clone();
//! guess.anchors_m.iter_mut().for_each(|a| *a += nalgebra::Vector3::new(10.0, -10.0, 3.0));
//! let found = anchors_by_trilateration(&guess, &rows);
//! for (a, truth) in found.iter().zip(&robot.anchors_m) {
//!     assert!((a - truth).norm() < 1e-6, "{a} against {truth}");
//! }
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::{Matrix4, Vector3, Vector4};

use crate::model::suspended::{SuspendedMeasurement, SuspendedRobot};

/// Starts spread over the upper hemisphere, besides the guess's anchor.
pub const STARTS: usize = 48;

/// Levenberg-Marquardt iterations per start.
const ITERATIONS: usize = 60;

/// Each cable's anchor from straight-cable trilateration of `measurements`
/// at the localiser's poses, started from `guess`'s anchors and from
/// [`STARTS`] points above the poses (module docs); in cable order.
pub fn anchors_by_trilateration(guess: &SuspendedRobot, measurements: &[SuspendedMeasurement]) -> Vec<Vector3<f64>> {
    let poses: Vec<_> = measurements.iter().map(SuspendedMeasurement::localiser_pose).collect();
    let centroid = poses.iter().map(|p| p.position_m).sum::<Vector3<f64>>() / poses.len().max(1) as f64;
    (0..guess.cable_count())
        .map(|i| {
            let points: Vec<Vector3<f64>> = poses
                .iter()
                .map(|p| p.position_m + p.rotation * guess.attachments_m[i])
                .collect();
            let readings: Vec<f64> = measurements.iter().map(|m| m.encoder_lengths_m[i]).collect();
            let mut sorted = readings.clone();
            sorted.sort_by(f64::total_cmp);
            let reach = sorted.get(sorted.len() / 2).copied().unwrap_or(1.0);
            let starts = std::iter::once(guess.anchors_m[i]).chain(hemisphere(STARTS).map(|d| centroid + d * reach));
            starts
                .map(|start| fit_cable(&points, &readings, start))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(guess.anchors_m[i], |(anchor, _)| anchor)
        })
        .collect()
}

/// `count` unit vectors spread evenly over the upper hemisphere (a
/// Fibonacci lattice: heights evenly spaced, azimuths by the golden angle).
fn hemisphere(count: usize) -> impl Iterator<Item = Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count).map(move |k| {
        let z = (k as f64 + 0.5) / count as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * k as f64;
        Vector3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

/// The anchor and offset of one straight cable fitted to `readings` at the
/// attachment `points` from `start` (the offset from the readings' mean
/// excess there) by Levenberg-Marquardt; the anchor and the sum of squares.
fn fit_cable(points: &[Vector3<f64>], readings: &[f64], start: Vector3<f64>) -> (Vector3<f64>, f64) {
    let cost = |a: &Vector3<f64>, offset: f64| -> f64 {
        points
            .iter()
            .zip(readings)
            .map(|(w, l)| ((a - w).norm() + offset - l).powi(2))
            .sum()
    };
    let n = points.len().max(1) as f64;
    let mut anchor = start;
    let mut offset = points
        .iter()
        .zip(readings)
        .map(|(w, l)| l - (start - w).norm())
        .sum::<f64>()
        / n;
    let mut current = cost(&anchor, offset);
    let mut damping = 1e-3;
    for _ in 0..ITERATIONS {
        let (mut normal, mut gradient) = (Matrix4::<f64>::zeros(), Vector4::<f64>::zeros());
        for (w, l) in points.iter().zip(readings) {
            let d = anchor - w;
            let range = d.norm().max(1e-12);
            let row = Vector4::new(d.x / range, d.y / range, d.z / range, 1.0);
            let residual = range + offset - l;
            normal += row * row.transpose();
            gradient += row * residual;
        }
        let mut improved = false;
        while damping < 1e12 {
            let damped = normal + Matrix4::from_diagonal(&normal.diagonal()) * damping;
            let Some(step) = damped.lu().solve(&(-gradient)) else {
                damping *= 10.0;
                continue;
            };
            let (a, o) = (anchor + step.xyz(), offset + step.w);
            let next = cost(&a, o);
            if next < current {
                (anchor, offset, current) = (a, o, next);
                damping = (damping * 0.1).max(1e-12);
                improved = true;
                break;
            }
            damping *= 10.0;
        }
        if !improved || current < 1e-24 {
            break;
        }
    }
    (anchor, current)
}

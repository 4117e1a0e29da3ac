//! Where the solver starts (module docs of [`crate::calib`]): the rigid
//! stage's start, the per-pose warm-up on the statics, and the length offsets
//! in closed form.

use super::graph::{build_graph, measured_pose, CalibrationGraph, MIN_POSES};
use super::options::{CableModel, CalibrationOptions};
use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::pose::PlatformPose;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::statics::{self, CableTension, Equilibrium, StaticsOptions};

/// Eq. (17)-(18): `f_v = m_e g / 4`, `f_h = f_v / tan(alpha)`, alpha the angle
/// between the reference cable's chord and the horizontal. Only a fallback.
fn paper_initial_tension(robot: &Robot, pose: &PlatformPose) -> CableTension {
    let geometry = statics::cable_geometry(robot, pose)[robot.reference_cable];
    let vertical = robot.platform_weight_n / CABLE_COUNT as f64;
    let alpha = geometry.height_difference_m.atan2(geometry.span_m).max(1e-3);
    CableTension {
        horizontal_n: vertical / alpha.tan(),
        vertical_n: vertical,
    }
}

/// Step (2) of the initialisation for a given robot: every pose's static
/// equilibrium at its measured position and load-cell tension (the poses and
/// reference tensions `(f_h, f_v)` to start the catenary graph from). Poses
/// without an equilibrium start from the measured pose and eq. (17)-(18);
/// their indices are the third element.
pub fn warm_start(
    robot: &Robot,
    measurements: &[PoseMeasurement],
) -> (Vec<PlatformPose>, Vec<CableTension>, Vec<usize>) {
    let warm = warm_up(robot, measurements);
    (warm.poses, warm.tensions, warm.failures)
}

/// The per-pose warm-up: a start for every pose.
struct WarmUp {
    poses: Vec<PlatformPose>,
    tensions: Vec<CableTension>,
    /// Poses without an equilibrium (their start is the measured pose and eq. 17-18).
    failures: Vec<usize>,
    equilibria: Vec<Option<Equilibrium>>,
}

/// Per-pose warm-up: the static equilibrium at each measured position and
/// load-cell tension for `robot`'s current anchors (or, where that tension has
/// none, the nearest tension that has one). Poses without any start from the
/// measured pose and eq. (17)-(18) and are listed as failures.
fn warm_up(robot: &Robot, measurements: &[PoseMeasurement]) -> WarmUp {
    let options = StaticsOptions::default();
    let mut warm = WarmUp {
        poses: Vec::with_capacity(measurements.len()),
        tensions: Vec::with_capacity(measurements.len()),
        failures: Vec::new(),
        equilibria: Vec::with_capacity(measurements.len()),
    };
    for (k, m) in measurements.iter().enumerate() {
        let measured = measured_pose(m);
        let solved = statics::solve_with_reference_tension(
            robot,
            measured.position_m,
            m.reference_tension_n,
            Some(measured.rotation),
            &options,
        )
        .or_else(|_| {
            statics::feasible_start(robot, measured.position_m, Some(measured.rotation), &options).map(|(_, eq)| eq)
        });
        match solved {
            Ok(eq) => {
                warm.poses.push(eq.pose);
                warm.tensions.push(eq.tensions[robot.reference_cable]);
                warm.equilibria.push(Some(eq));
            }
            Err(_) => {
                warm.failures.push(k);
                warm.poses.push(measured);
                warm.tensions.push(paper_initial_tension(robot, &measured));
                warm.equilibria.push(None);
            }
        }
    }
    warm
}

/// Closed-form length offsets for fixed geometry: the offsets enter the
/// encoder factors linearly, so the least-squares value is the mean of
/// `encoder - catenary length` over the poses.
fn offsets_in_closed_form(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    equilibria: &[Option<Equilibrium>],
) -> [f64; CABLE_COUNT] {
    std::array::from_fn(|i| {
        let differences: Vec<f64> = measurements
            .iter()
            .zip(equilibria)
            .filter_map(|(m, eq)| eq.as_ref().map(|eq| m.encoder_lengths_m[i] - eq.cable_lengths_m[i]))
            .collect();
        if differences.is_empty() {
            robot.length_offsets_m[i]
        } else {
            differences.iter().sum::<f64>() / differences.len() as f64
        }
    })
}

/// Closed-form offsets for the straight-cable model: mean of `encoder - chord`.
fn rigid_offsets_in_closed_form(
    robot: &Robot,
    measurements: &[PoseMeasurement],
    poses: &[PlatformPose],
) -> [f64; CABLE_COUNT] {
    std::array::from_fn(|i| {
        measurements
            .iter()
            .zip(poses)
            .map(|(m, p)| {
                let attachment = p.position_m + p.rotation_matrix() * robot.attachments_m[i];
                m.encoder_lengths_m[i] - (robot.anchors_m[i] - attachment).norm()
            })
            .sum::<f64>()
            / measurements.len() as f64
    })
}

/// The rigid stage's start: `initial` with the straight-cable offsets in
/// closed form, the measured poses, and eq. (17)-(18)'s reference tensions
/// (held fixed by the rigid model).
pub(super) fn rigid_start(
    initial: &Robot,
    measurements: &[PoseMeasurement],
) -> (Robot, Vec<PlatformPose>, Vec<CableTension>) {
    let measured: Vec<PlatformPose> = measurements.iter().map(measured_pose).collect();
    let placeholder: Vec<CableTension> = measured.iter().map(|p| paper_initial_tension(initial, p)).collect();
    let mut start = initial.clone();
    start.length_offsets_m = rigid_offsets_in_closed_form(initial, measurements, &measured);
    (start, measured, placeholder)
}

/// The options of the relaxed-statics stage: the attachment-height sigma
/// raised to the encoder sigma (see [`super::pipeline::calibrate_once`]).
pub(super) fn relaxed_statics(options: &CalibrationOptions) -> CalibrationOptions {
    CalibrationOptions {
        height_sigma_m: options.height_sigma_m.max(options.noise.encoder_sigma_m),
        ..*options
    }
}

/// A warmed-up start of the catenary stages.
#[derive(Debug, Clone)]
pub(super) struct CatenaryStart {
    /// Anchors of the candidate, offsets in closed form.
    pub robot: Robot,
    /// Per measurement: the warmed-up pose and reference tension.
    pub poses: Vec<PlatformPose>,
    /// Per measurement: the warmed-up reference tension.
    pub tensions: Vec<CableTension>,
    /// The measurements with an equilibrium at the candidate's anchors.
    pub feasible: Vec<usize>,
}

impl CatenaryStart {
    /// The feasible poses' measurements, poses and reference tensions.
    pub fn feasible_subset(
        &self,
        measurements: &[PoseMeasurement],
    ) -> (Vec<PoseMeasurement>, Vec<PlatformPose>, Vec<CableTension>) {
        (
            self.feasible.iter().map(|&k| measurements[k]).collect(),
            self.feasible.iter().map(|&k| self.poses[k]).collect(),
            self.feasible.iter().map(|&k| self.tensions[k]).collect(),
        )
    }
}

/// The warmed-up `candidates` (the initial guess, a rigid-cable calibration
/// from it, or anchors mixed from both: [`mixed_anchors`]), best first: the
/// two halves [`warm_candidates`] and [`rank_starts`].
pub(super) fn catenary_starts(
    candidates: impl IntoIterator<Item = Robot>,
    measurements: &[PoseMeasurement],
    relaxed_options: &CalibrationOptions,
) -> Vec<CatenaryStart> {
    let warmed = warm_candidates(candidates, measurements);
    rank_starts(&warmed, measurements, relaxed_options)
        .into_iter()
        .cloned()
        .collect()
}

/// Every candidate warmed up (per-pose statics, closed-form offsets), in the
/// order given; candidates with fewer than [`MIN_POSES`] feasible poses are
/// dropped. Independent of the calibration options (the statics and the
/// offsets see only the robot and the readings), so one warm-up serves the
/// calibrations with and without the orientation prior.
pub(super) fn warm_candidates(
    candidates: impl IntoIterator<Item = Robot>,
    measurements: &[PoseMeasurement],
) -> Vec<CatenaryStart> {
    let mut warmed = Vec::new();
    for candidate in candidates {
        let warm = warm_up(&candidate, measurements);
        let mut start = candidate;
        start.length_offsets_m = offsets_in_closed_form(&start, measurements, &warm.equilibria);
        let feasible: Vec<usize> = (0..measurements.len())
            .filter(|k| warm.equilibria[*k].is_some())
            .collect();
        if feasible.len() < MIN_POSES {
            continue;
        }
        warmed.push(CatenaryStart {
            robot: start,
            poses: warm.poses,
            tensions: warm.tensions,
            feasible,
        });
    }
    warmed
}

/// The warmed-up starts ([`warm_candidates`]) best first, each scored by its
/// relaxed catenary cost per feasible pose under `relaxed_options` (a start
/// with fewer feasible poses is penalised); a start whose cost cannot be
/// evaluated, or whose anchors repeat a better-placed one, is dropped. The
/// score only orders them: a start's cost says little about the basin it lies
/// in (see [`super::pipeline::calibrate_once`]), so every start is solved and the
/// lowest final cost wins.
pub(super) fn rank_starts<'a>(
    warmed: &'a [CatenaryStart],
    measurements: &[PoseMeasurement],
    relaxed_options: &CalibrationOptions,
) -> Vec<&'a CatenaryStart> {
    let mut scored: Vec<(f64, &CatenaryStart)> = Vec::new();
    for start in warmed {
        let (chosen, poses, tensions) = start.feasible_subset(measurements);
        let graph = build_graph(
            &start.robot,
            &chosen,
            &poses,
            &tensions,
            CableModel::Catenary,
            relaxed_options,
        );
        // Compare per pose, so that a start with more feasible poses is not penalised.
        let Some(cost) = graph.graph.cost(&graph.graph.values) else {
            continue;
        };
        let feasible = start.feasible.len();
        let score = cost / feasible as f64 * (1.0 + (measurements.len() - feasible) as f64);
        // The same anchors twice (a rigid stage that did not move) would only be solved twice.
        let duplicate = scored.iter().any(|(_, other)| {
            (0..CABLE_COUNT).all(|i| (other.robot.anchors_m[i] - start.robot.anchors_m[i]).norm() < 1e-6)
        });
        if duplicate {
            continue;
        }
        scored.push((score, start));
    }
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    scored.into_iter().map(|(_, start)| start).collect()
}

/// Every mix of `initial`'s and `rigid`'s anchors other than the two
/// themselves: cable `i`'s anchor from `rigid` where bit `i` of the mask is
/// set. The rigid stage is, cable by cable, an independent fit of one anchor
/// and one offset to that cable's lengths (the poses are held by their
/// priors), so a wrong rigid minimum for one cable does not spoil the others:
/// keeping the initial anchor for that cable alone is a start no better and
/// no worse than the guess was for it.
pub(super) fn mixed_anchors(initial: &Robot, rigid: &Robot) -> Vec<Robot> {
    let full = (1usize << CABLE_COUNT) - 1;
    (1..full)
        .map(|mask| {
            let mut mixed = initial.clone();
            for i in 0..CABLE_COUNT {
                if mask & (1 << i) != 0 {
                    mixed.anchors_m[i] = rigid.anchors_m[i];
                }
            }
            mixed
        })
        .collect()
}

/// The start of the final stage: every measurement, the feasible ones at the
/// relaxed stage's solution, those that sat out warmed up again at its
/// anchors `relaxed_robot`, and those still without an equilibrium excluded.
pub(super) struct FinalStart {
    /// The measurements in the final stage.
    pub measurements: Vec<PoseMeasurement>,
    /// Their start poses.
    pub poses: Vec<PlatformPose>,
    /// Their start reference tensions.
    pub tensions: Vec<CableTension>,
    /// Indices of the measurements left out.
    pub excluded: Vec<usize>,
}

/// The final stage's start after the relaxed stage (see [`FinalStart`]);
/// an error if fewer than [`MIN_POSES`] poses remain.
pub(super) fn final_start(
    relaxed: &CalibrationGraph,
    relaxed_robot: &Robot,
    measurements: &[PoseMeasurement],
    feasible: &[usize],
) -> Result<FinalStart> {
    // Only the poses that sat out are warmed up again (each pose's statics
    // is its own problem): `sat_out[j]` is the measurement of `rewarmed[j]`.
    let sat_out: Vec<usize> = (0..measurements.len()).filter(|k| !feasible.contains(k)).collect();
    let rewarmed = warm_up(
        relaxed_robot,
        &sat_out.iter().map(|&k| measurements[k]).collect::<Vec<_>>(),
    );
    let mut start = FinalStart {
        measurements: Vec::new(),
        poses: Vec::new(),
        tensions: Vec::new(),
        excluded: Vec::new(),
    };
    for (k, measurement) in measurements.iter().enumerate() {
        if let Some(slot) = feasible.iter().position(|&f| f == k) {
            let vars = relaxed.poses[slot];
            let t = relaxed.graph.values.vector(vars.reference_tension);
            start.poses.push(*relaxed.graph.values.pose(vars.pose));
            start.tensions.push(CableTension {
                horizontal_n: t[0],
                vertical_n: t[1],
            });
        } else {
            let j = sat_out.partition_point(|&s| s < k);
            if rewarmed.failures.contains(&j) {
                start.excluded.push(k);
                continue;
            }
            start.poses.push(rewarmed.poses[j]);
            start.tensions.push(rewarmed.tensions[j]);
        }
        start.measurements.push(*measurement);
    }
    if start.measurements.len() < MIN_POSES {
        return Err(Error::NoEquilibrium(format!(
            "only {} of {} poses have a positive-tension equilibrium at the calibrated anchors",
            start.measurements.len(),
            measurements.len()
        )));
    }
    Ok(start)
}

//! The localiser of a calibrated robot (module docs of [`super`]): the
//! readings of one row, the options, the pose found with its tensions,
//! uncertainty and consistency test, and the warm and cold starts tried.

use nalgebra::{Matrix6, SMatrix, UnitQuaternion, Vector2, Vector3, Vector6};

use super::equations::{self, SlotRobot, MEASUREMENT_ROWS, PARAMETERS};
use super::frame::Frame;
use super::newton::{self, Observation, Solution};
use super::stiffness;
use crate::error::{Error, Result};
use crate::model::pose::PlatformPose;
use crate::model::robot::{ParameterCovariance, Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::model::statics::{self, CableTension, StaticsOptions};
use crate::stats;

/// One row of readings of the calibrated robot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Readings {
    /// Encoder readings of cables 1..4 (cable length + calibrated offset), metres.
    pub encoder_lengths_m: [f64; CABLE_COUNT],
    /// The load cell on the reference cable, newtons, if read.
    pub load_cell_n: Option<f64>,
    /// The localiser's pose as it reads it (its mounting rotation included),
    /// used as a prior only when [`LocalizeOptions::pose_prior`] is set.
    pub localiser_pose: Option<PlatformPose>,
}

/// Options of [`Localizer`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalizeOptions {
    /// Use the localiser pose as a prior (with the localiser's sigmas); by
    /// default it is never an input.
    pub pose_prior: bool,
    /// False-alarm rate of the chi-square consistency test.
    pub false_alarm: f64,
    /// Gauss-Newton iterations per start.
    pub max_iterations: usize,
    /// Largest attachment-height residual (eq. 15) accepted, metres.
    pub height_tolerance_m: f64,
    /// Propagate the robot's recorded calibration covariance
    /// ([`Robot::calibration_covariance_m2`]) into the pose uncertainty.
    pub calibration_uncertainty: bool,
}

impl Default for LocalizeOptions {
    /// No prior, false alarms 1e-3, 50 iterations, 1e-9 m, the calibration's
    /// uncertainty propagated.
    fn default() -> Self {
        Self {
            pose_prior: false,
            false_alarm: 1e-3,
            max_iterations: 50,
            height_tolerance_m: 1e-9,
            calibration_uncertainty: true,
        }
    }
}

/// The localised equilibrium of one row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Localized {
    /// Platform pose.
    pub pose: PlatformPose,
    /// Tensions at the attachments, robot cable order.
    pub tensions: [CableTension; CABLE_COUNT],
    /// Covariance of the pose tangent `[dtheta (rad), dp (m)]` from the
    /// reading noise, `(J^T W J)^-1` with the model equations tight.
    pub covariance: Matrix6<f64>,
    /// Covariance of the pose tangent from the calibration's own uncertainty
    /// (the robot's recorded anchor/offset covariance carried through the
    /// equilibrium, `S Sigma_theta S^T`); `None` when the robot records none.
    pub calibration_covariance: Option<Matrix6<f64>>,
    /// 1-sigma of the position per world axis, metres, from both sources
    /// (`covariance + calibration_covariance`).
    pub position_sigma_m: Vector3<f64>,
    /// 1-sigma of the position per world axis from the reading noise only, metres.
    pub reading_position_sigma_m: Vector3<f64>,
    /// Chi-square of the whitened readings at the solution.
    pub chi_square: f64,
    /// Its degrees of freedom: readings minus 4 (0 with the encoders only).
    pub degrees_of_freedom: usize,
    /// Whether the chi-square passes at [`LocalizeOptions::false_alarm`]
    /// (always true with 0 degrees of freedom).
    pub consistent: bool,
    /// Whether the equilibrium is stable at fixed cable lengths.
    pub stable: bool,
    /// Smallest eigenvalue of the stiffness's symmetric part ([`stiffness`]).
    pub smallest_stiffness: f64,
    /// Gauss-Newton iterations, all starts together.
    pub iterations: usize,
}

impl Localized {
    /// Tension magnitudes, robot cable order, newtons.
    pub fn tension_magnitudes_n(&self) -> [f64; CABLE_COUNT] {
        std::array::from_fn(|i| self.tensions[i].magnitude_n())
    }
}

/// The localiser of one calibrated robot, built once and used for every row.
#[derive(Debug, Clone)]
pub struct Localizer {
    robot: Robot,
    /// The robot with the `[effects]` centre of mass, for the stiffness.
    shifted: Robot,
    slots: SlotRobot,
    noise: SensorNoise,
    pub(super) options: LocalizeOptions,
    /// The localiser's mounting rotation `M` (`[effects]`): it reads `R M`.
    mount: UnitQuaternion<f64>,
    critical: [f64; MEASUREMENT_ROWS],
    /// The calibration covariance in slot order ([`PARAMETERS`]), if used.
    calibration: Option<SMatrix<f64, PARAMETERS, PARAMETERS>>,
    /// Where the platform can hang ([`Frame`]).
    frame: Frame,
}

/// The robot-order covariance (anchors of cables 1..4, then offsets) in
/// slot order.
fn to_slot_order(slots: &SlotRobot, covariance: &ParameterCovariance) -> SMatrix<f64, PARAMETERS, PARAMETERS> {
    let index = |k: usize| {
        if k < 12 {
            3 * slots.cables[k / 3] + k % 3
        } else {
            12 + slots.cables[k - 12]
        }
    };
    SMatrix::from_fn(|r, c| covariance[(index(r), index(c))])
}

impl Localizer {
    /// A localiser of `robot` (its anchors, offsets and `[effects]`) whose
    /// readings have the sigmas of `noise`, with default options.
    pub fn new(robot: &Robot, noise: &SensorNoise) -> Result<Self> {
        Self::with_options(robot, noise, LocalizeOptions::default())
    }

    /// As [`Localizer::new`] with `options`. Fails when a sigma the readings
    /// need (encoder, load cell; localiser with a prior) is not positive.
    pub fn with_options(robot: &Robot, noise: &SensorNoise, options: LocalizeOptions) -> Result<Self> {
        let positive = |v: f64, what: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidInput(format!("{what} sigma must be positive, got {v}")))
            }
        };
        positive(noise.encoder_sigma_m, "encoder")?;
        positive(noise.load_cell_sigma_n, "load-cell")?;
        if options.pose_prior {
            positive(noise.position_sigma_m, "localiser position")?;
            positive(noise.orientation_sigma_rad, "localiser orientation")?;
        }
        if !(options.false_alarm > 0.0 && options.false_alarm < 1.0) {
            return Err(Error::InvalidInput(format!(
                "false-alarm rate must be in (0, 1), got {}",
                options.false_alarm
            )));
        }
        let mut shifted = crate::model::robot::with_true_attachments(robot, &robot.effects);
        shifted.com_offset_m += Vector3::from(robot.effects.com_shift_m);
        let mount =
            UnitQuaternion::from_scaled_axis(Vector3::from(robot.effects.localiser_mount_deg).map(f64::to_radians));
        let slots = SlotRobot::new(robot);
        let calibration = robot
            .calibration_covariance_m2
            .filter(|_| options.calibration_uncertainty)
            .map(|c| to_slot_order(&slots, &c));
        Ok(Self {
            robot: robot.clone(),
            frame: Frame::of(robot),
            shifted,
            calibration,
            slots,
            noise: *noise,
            options,
            mount,
            critical: std::array::from_fn(|k| {
                if k == 0 {
                    0.0
                } else {
                    stats::chi_square_critical(k, options.false_alarm)
                }
            }),
        })
    }

    /// The robot in slot order (for evaluating the equations, e.g. in tests).
    pub fn slots(&self) -> &SlotRobot {
        &self.slots
    }

    /// The options.
    pub fn options(&self) -> &LocalizeOptions {
        &self.options
    }

    /// The region the robot's platform can hang in.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Whether a solved row lies in the robot's frame ([`Frame::check`]):
    /// the pose can then warm-start the next row.
    pub fn frame_allows(&self, found: &Localized) -> bool {
        self.frame
            .check(&self.robot, &found.pose, &found.tensions, &found.position_sigma_m)
            .is_none()
    }

    /// Why a solved row is not a trusted localisation, in the words `sagcal
    /// localize` prints, or `None` for a good row: a pose outside the robot's
    /// frame or with a cable lying on the floor ([`Frame::check`]), an
    /// unstable equilibrium, or readings that fail their chi-square test.
    pub fn flag(&self, found: &Localized) -> Option<String> {
        if let Some(why) = self
            .frame
            .check(&self.robot, &found.pose, &found.tensions, &found.position_sigma_m)
        {
            return Some(why);
        }
        match (found.consistent, found.stable) {
            (_, false) => {
                Some("unstable equilibrium (the stiffness at fixed cable lengths is not positive definite)".into())
            }
            (false, _) => Some(format!(
                "inconsistent: chi-square {:.2} with {} degree(s) of freedom",
                found.chi_square, found.degrees_of_freedom
            )),
            _ => None,
        }
    }

    /// The platform pose a localiser reading implies: `R_read M^-1` (the
    /// `[effects]` mounting rotation removed), the same position.
    pub fn platform_pose_of_reading(&self, reading: &PlatformPose) -> PlatformPose {
        PlatformPose::new(reading.position_m, reading.rotation * self.mount.inverse())
    }

    pub(super) fn observation(&self, readings: &Readings) -> Result<Observation> {
        if let Some((i, l)) = readings
            .encoder_lengths_m
            .iter()
            .enumerate()
            .find(|(_, l)| !l.is_finite())
        {
            return Err(Error::InvalidInput(format!(
                "encoder of cable {} must be a finite number of metres, got {l}",
                i + 1
            )));
        }
        if let Some(f) = readings.load_cell_n.filter(|f| !(f.is_finite() && *f > 0.0)) {
            return Err(Error::InvalidInput(format!(
                "load cell must be a positive number of newtons, got {f}"
            )));
        }
        let prior = if self.options.pose_prior {
            let reading = readings.localiser_pose.ok_or_else(|| {
                Error::InvalidInput("a pose prior was asked for but the row has no localiser pose".into())
            })?;
            let pose = self.platform_pose_of_reading(&reading);
            if !pose
                .position_m
                .iter()
                .chain(pose.rotation.coords.iter())
                .all(|v| v.is_finite())
            {
                return Err(Error::InvalidInput("the localiser pose is not finite".into()));
            }
            Some((pose, self.noise.position_sigma_m, self.noise.orientation_sigma_rad))
        } else {
            None
        };
        Ok(Observation {
            encoders_m: self.slots.to_slots(&readings.encoder_lengths_m),
            encoder_sigma_m: self.noise.encoder_sigma_m,
            load_cell: readings.load_cell_n.map(|f| (f, self.noise.load_cell_sigma_n)),
            prior,
        })
    }

    /// The equilibrium of one row (module docs): from `warm_start` (the
    /// previous row's pose) if given, else from the prior or a cold start
    /// (trilateration of the lengths, then a statics start there). The
    /// stable solution nearest the warm start (or prior) is returned.
    ///
    /// Errors: [`Error::InvalidInput`] for a reading that is not a finite
    /// number (or a load cell that is not positive), [`Error::NoEquilibrium`]
    /// when no start converges to a stable equilibrium (a cable that would go
    /// slack, lengths no pose reaches, a reading outside the workspace).
    pub fn localize(&self, readings: &Readings, warm_start: Option<&PlatformPose>) -> Result<Localized> {
        let observation = self.observation(readings)?;
        let reference = warm_start.copied().or(observation.prior.map(|p| p.0));
        let mut iterations = 0;
        // Fast path: the warm start converges to a stable equilibrium.
        if let Some(start) = warm_start {
            if let Some(found) = self.try_start(&observation, *start, None, &mut iterations) {
                if found.stable {
                    return Ok(Localized { iterations, ..found });
                }
            }
        }
        let mut best: Option<Localized> = None;
        let mut unstable = 0;
        let level = self.level_start(readings);
        for kind in [ColdStart::Prior, ColdStart::Level, ColdStart::Statics] {
            let Some((pose, tension)) = self.cold_start(kind, &observation, &level) else {
                continue;
            };
            let Some(found) = self.try_start(&observation, pose, tension, &mut iterations) else {
                continue;
            };
            if !found.stable {
                unstable += 1;
                continue;
            }
            let distance = |l: &Localized| reference.map_or(0.0, |r| pose_distance(&l.pose, &r));
            if best.as_ref().is_none_or(|b| distance(&found) < distance(b) - 1e-9) {
                best = Some(found);
            }
            // Without a reference pose the first stable equilibrium is taken;
            // one found from the prior is the one nearest the prior.
            if reference.is_none() || kind == ColdStart::Prior {
                break;
            }
        }
        best.map(|b| Localized { iterations, ..b }).ok_or_else(|| {
            Error::NoEquilibrium(if unstable > 0 {
                format!("the readings are explained only by unstable equilibria ({unstable} found): none is stable at fixed cable lengths")
            } else {
                format!(
                    "no pose with taut cables reproduces the encoder readings {:?} m (a cable too short or too long to reach, or outside the workspace)",
                    readings.encoder_lengths_m
                )
            })
        })
    }

    /// The level platform at the straight-cable trilateration of the
    /// lengths (offsets and encoder scale removed).
    pub(super) fn level_start(&self, readings: &Readings) -> PlatformPose {
        let true_lengths: [f64; CABLE_COUNT] = std::array::from_fn(|i| {
            (readings.encoder_lengths_m[i] - self.robot.length_offsets_m[i]) / self.robot.effects.encoder_gain[i]
        });
        PlatformPose::from_position(trilaterate(&self.robot, &true_lengths))
    }

    /// A start after the warm one (`None` where it does not exist); the
    /// statics start (an exact closed-form equilibrium at the trilaterated
    /// position, `model::statics::feasible_start`) is the costly one, taken last.
    pub(super) fn cold_start(
        &self,
        kind: ColdStart,
        observation: &Observation,
        level: &PlatformPose,
    ) -> Option<(PlatformPose, Option<Vector2<f64>>)> {
        match kind {
            ColdStart::Prior => observation.prior.map(|(pose, _, _)| (pose, None)),
            ColdStart::Level => Some((*level, None)),
            ColdStart::Statics => {
                let (_, eq) =
                    statics::feasible_start(&self.robot, level.position_m, None, &StaticsOptions::default()).ok()?;
                let t = eq.tensions[self.robot.reference_cable];
                Some((eq.pose, Some(Vector2::new(t.horizontal_n, t.vertical_n))))
            }
        }
    }

    /// A reference tension for a start pose: the straight-cable magnitude
    /// along the sag-corrected chord (`u ~ dz/L - lambda/2`).
    fn chord_tension(&self, pose: &PlatformPose) -> Vector2<f64> {
        let magnitude = statics::reference_tension_magnitude_guess(&self.robot, pose.position_m);
        let geometry = statics::cable_geometry(&self.robot, pose)[self.robot.reference_cable];
        let half_lambda = 0.5 * self.robot.cable_weight_n_per_m * geometry.span_m / magnitude;
        let angle = (geometry.height_difference_m / geometry.span_m - half_lambda).atan();
        Vector2::new(magnitude * angle.cos(), magnitude * angle.sin())
    }

    pub(super) fn try_start(
        &self,
        observation: &Observation,
        pose: PlatformPose,
        reference: Option<Vector2<f64>>,
        iterations: &mut usize,
    ) -> Option<Localized> {
        let reference =
            reference.unwrap_or_else(|| newton::fit_reference_tension(&self.slots, &pose, self.chord_tension(&pose)));
        let solution = newton::solve(
            &self.slots,
            observation,
            pose,
            reference,
            self.options.max_iterations,
            self.options.height_tolerance_m,
        )?;
        *iterations += solution.iterations;
        solution.converged.then(|| self.summarise(observation, &solution))
    }

    fn summarise(&self, observation: &Observation, solution: &Solution) -> Localized {
        let k = stiffness::stiffness(&self.shifted, &self.slots, &solution.pose, &solution.model);
        let smallest = stiffness::smallest_stiffness(&k);
        let covariance: Matrix6<f64> = solution.covariance.fixed_view::<6, 6>(0, 0).into_owned();
        let calibration_covariance = self.calibration.and_then(|sigma| {
            let reference = solution.model.tensions_n[0];
            let partials = equations::parameter_partials(&self.slots, &solution.pose, &reference)?;
            let s = newton::parameter_sensitivity(&self.slots, observation, solution, &partials);
            Some(s * sigma * s.transpose())
        });
        let position_sigma = |c: &Matrix6<f64>| Vector3::from_fn(|a, _| c[(3 + a, 3 + a)].max(0.0).sqrt());
        let total = covariance + calibration_covariance.unwrap_or_else(Matrix6::zeros);
        let chi_square = solution.whitened.norm_squared();
        let degrees_of_freedom = observation.rows() - 4;
        let mut tensions = [CableTension {
            horizontal_n: 0.0,
            vertical_n: 0.0,
        }; CABLE_COUNT];
        for (slot, &cable) in self.slots.cables.iter().enumerate() {
            tensions[cable] = CableTension {
                horizontal_n: solution.model.tensions_n[slot][0],
                vertical_n: solution.model.tensions_n[slot][1],
            };
        }
        Localized {
            pose: solution.pose,
            tensions,
            covariance,
            calibration_covariance,
            position_sigma_m: position_sigma(&total),
            reading_position_sigma_m: position_sigma(&covariance),
            chi_square,
            degrees_of_freedom,
            consistent: degrees_of_freedom == 0 || chi_square <= self.critical[degrees_of_freedom],
            stable: smallest > 0.0,
            smallest_stiffness: smallest,
            iterations: solution.iterations,
        }
    }
}

/// The starts tried after the warm one, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum ColdStart {
    /// The localiser prior (with `--pose-prior`).
    Prior,
    /// The level platform at the trilaterated position.
    Level,
    /// A closed-form equilibrium at the trilaterated position.
    Statics,
}

/// Distance between poses for choosing among equilibria: position (m) plus
/// rotation angle (rad) times 1 m.
pub(super) fn pose_distance(a: &PlatformPose, b: &PlatformPose) -> f64 {
    let xi: Vector6<f64> = a.local_coordinates(b);
    xi.norm()
}

/// Position whose straight-line distances to the anchors best match the
/// lengths (attachments at a level platform): Gauss-Newton from below the
/// anchors' centroid, fixed-size.
pub fn trilaterate(robot: &Robot, cable_lengths_m: &[f64; CABLE_COUNT]) -> Vector3<f64> {
    let centroid = robot.anchors_m.iter().sum::<Vector3<f64>>() / CABLE_COUNT as f64;
    let mean_length = cable_lengths_m.iter().sum::<f64>() / CABLE_COUNT as f64;
    let mut p = centroid - Vector3::new(0.0, 0.0, 0.5 * mean_length.abs());
    for _ in 0..50 {
        let mut j = nalgebra::Matrix4x3::<f64>::zeros();
        let mut r = nalgebra::Vector4::<f64>::zeros();
        for i in 0..CABLE_COUNT {
            let d = p + robot.attachments_m[i] - robot.anchors_m[i];
            let n = d.norm();
            r[i] = n - cable_lengths_m[i];
            j.set_row(i, &(d / n).transpose());
        }
        let Some(step) = (j.transpose() * j).try_inverse().map(|m| -(m * j.transpose() * r)) else {
            break;
        };
        if !step.iter().all(|v| v.is_finite()) {
            break;
        }
        p += step;
        if step.norm() < 1e-10 {
            break;
        }
    }
    p
}

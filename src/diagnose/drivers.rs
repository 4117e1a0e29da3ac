//! Step 2: the residuals against the physical drivers of each cable and pose
//! (tension, tension x length, cable length, sag, elevation, pulley wrap
//! angle, platform position), by correlation. Where the rows are in the
//! order they were taken, two drivers of time and motion join them: the row
//! (a drift over time: an encoder or load cell creeping) and, per cable, the
//! direction of its last motion (+1 paid out, -1 reeled in since the
//! previous row: pulley friction at a load cell, backlash, hysteresis).

use nalgebra::Vector3;
use serde::Serialize;

use super::fitted_graph::rebuild;
use crate::calib::{CalibrationOptions, CalibrationResult};
use crate::error::Result;
use crate::model::effect_kind::EffectKind;
use crate::model::measurement::{PoseMeasurement, ReadingSet, Sensor};
use crate::model::robot::CABLE_COUNT;
use crate::model::statics;
use crate::stats::correlation;

/// Two-sided p < 0.001 for a correlation's t statistic (normal approximation).
pub const DRIVER_T_LIMIT: f64 = 3.29;

/// Correlation of one residual with one physical driver over the poses (and cables).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriverTest {
    /// The residual (`encoder`, `load_cell`, `position_x|y|z`), normalised by its sigma.
    pub residual: String,
    /// The driver (see [`DRIVERS`]).
    pub driver: String,
    /// Number of points.
    pub points: usize,
    /// Pearson correlation.
    pub correlation: f64,
    /// `r sqrt((n - 2) / (1 - r^2))`.
    pub t_statistic: f64,
    /// `|t| > 3.29`: the residual carries structure along this driver.
    pub significant: bool,
}

/// Normalised residuals against one driver, before and after the extension (for plots).
#[derive(Debug, Clone, PartialEq)]
pub struct DriverSeries {
    /// Residual name.
    pub residual: String,
    /// Driver name with unit.
    pub driver: String,
    /// `(driver, residual / sigma)` with the baseline model.
    pub before: Vec<(f64, f64)>,
    /// The same with the verdict's model (`None` for `none`).
    pub after: Option<Vec<(f64, f64)>>,
}

/// Per pose of a fitted model: the drivers and normalised residuals.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PoseSample {
    /// Per cable: driver values in the order of [`DRIVERS`].
    cable_drivers: [[f64; CABLE_DRIVER_COUNT]; CABLE_COUNT],
    /// Platform position, metres.
    position_m: Vector3<f64>,
    /// Measured load-cell tension, newtons.
    measured_tension_n: f64,
    /// Encoder residual / sigma, per cable.
    encoder: [f64; CABLE_COUNT],
    /// Load-cell residual / sigma.
    load_cell: f64,
    /// Localiser position residual / sigma.
    position: [f64; 3],
    /// The row, counted from 1 in the order the poses were taken.
    row: f64,
    /// The cable the load cell reads (robot cable order).
    pub reference_cable: usize,
    /// Per cable: +1 when its encoder reading grew since the previous row
    /// (paid out), -1 when it shrank (reeled in), NaN for the first row.
    direction: [f64; CABLE_COUNT],
}

const CABLE_DRIVER_COUNT: usize = 7;

/// The per-cable drivers, with units.
pub const DRIVERS: [&str; CABLE_DRIVER_COUNT] = [
    "tension at the pulley (N)",
    "tension x length (kN m)",
    "cable length (m)",
    "mid-span sag (m)",
    "elevation (deg)",
    "pulley wrap angle (deg)",
    "platform height (m)",
];

/// The pose driver of the load cell's own reading.
pub const MEASURED_TENSION: &str = "measured tension (N)";
/// The driver of time: the row in the order taken.
pub const ROW_DRIVER: &str = "row (order taken)";
/// The driver of motion, per cable.
pub const DIRECTION_DRIVER: &str = "direction of last motion (+1 out, -1 in)";

/// The driver and residual that show `effect` best.
pub(super) fn winning_driver(effect: EffectKind) -> (&'static str, &'static str) {
    match effect {
        EffectKind::Elastic => ("encoder", DRIVERS[1]),
        EffectKind::Pulley => ("encoder", DRIVERS[5]),
        EffectKind::EncoderScale => ("encoder", DRIVERS[2]),
        EffectKind::LoadCell => ("load_cell", MEASURED_TENSION),
        EffectKind::Com => ("encoder", DRIVERS[0]),
        EffectKind::CommonGain => ("encoder", DRIVERS[2]),
        EffectKind::Segments => ("encoder", DRIVERS[3]),
        // A mount turns the orientation readings only; its trace in the other
        // residuals is the statics' answer to the tilt, strongest in the tension.
        EffectKind::LocaliserMount => ("encoder", DRIVERS[0]),
        // Both change the sag, which grows with the cable's length.
        EffectKind::PlatformWeight | EffectKind::CableWeight => ("encoder", DRIVERS[3]),
        EffectKind::EncoderDrift => ("encoder", ROW_DRIVER),
        EffectKind::EncoderBacklash => ("encoder", DIRECTION_DRIVER),
        EffectKind::LoadCellDrift => ("load_cell", ROW_DRIVER),
        EffectKind::LoadCellFriction => ("load_cell", DIRECTION_DRIVER),
        // A moved attachment shifts the platform's balance, as a centre of mass does.
        EffectKind::Attachments => ("encoder", DRIVERS[0]),
    }
}

/// Drivers and normalised residuals of every pose of a fitted model
/// (`options` as it was fitted with); a reading left out as a gross error
/// ([`PoseMeasurement::excluded`]) is NaN and takes no part in the tests.
pub(super) fn samples(
    result: &CalibrationResult,
    used: &[PoseMeasurement],
    options: &CalibrationOptions,
) -> Result<Vec<PoseSample>> {
    let unmasked: Vec<PoseMeasurement> = used
        .iter()
        .map(|m| PoseMeasurement {
            excluded: ReadingSet::NONE,
            ..*m
        })
        .collect();
    let built = rebuild(result, &unmasked, options);
    let graph = &built.graph;
    let normalised = |kind: &str| -> Vec<Vec<f64>> {
        graph
            .factors
            .iter()
            .filter(|f| f.kind() == kind)
            .map(|f| {
                let r = f
                    .evaluate(&graph.values, None)
                    .unwrap_or_else(|| nalgebra::DVector::from_element(f.residual_dim(), f64::NAN));
                r.iter().zip(f.sigmas().iter()).map(|(r, s)| r / s).collect()
            })
            .collect()
    };
    let encoders = normalised("catenary_length");
    let cells = normalised("reference_tension");
    let priors = normalised("pose_prior");
    let robot = &result.robot;
    let references = result.reference_tensions();
    (0..used.len())
        .map(|k| {
            let pose = &result.poses[k];
            let tensions = statics::cable_tensions(robot, pose, references[k])?;
            let cables = statics::catenaries(robot, pose, &tensions);
            let geometry = statics::cable_geometry(robot, pose);
            let cable_drivers = std::array::from_fn(|i| {
                let c = &cables[i];
                let length = c.length_m();
                let top_vertical = c.anchor_vertical_tension_n();
                let top = c.horizontal_tension_n.hypot(top_vertical);
                let sag = robot.cable_weight_n_per_m * c.span_m * c.span_m / (8.0 * c.horizontal_tension_n);
                [
                    top,
                    top * length / 1e3,
                    length,
                    sag,
                    geometry[i].height_difference_m.atan2(geometry[i].span_m).to_degrees(),
                    (std::f64::consts::FRAC_PI_2 + (top_vertical / c.horizontal_tension_n).atan()).to_degrees(),
                    pose.position_m.z,
                ]
            });
            let prior = &priors[k];
            let position_rows = prior.len() - 3;
            let out = used[k].excluded;
            let unless = |sensor: Sensor, value: f64| if out.contains(sensor) { f64::NAN } else { value };
            // The pose's place in the order taken, where the rows carry it
            // (a pose the baseline left out keeps the rows after it in place);
            // else its place among the poses used.
            let (row, direction) = match used[k].order {
                Some(order) => (
                    order.row as f64,
                    order.direction.map(|d| if d == 0 { f64::NAN } else { f64::from(d) }),
                ),
                None => (
                    (k + 1) as f64,
                    std::array::from_fn(|i| match k {
                        0 => f64::NAN,
                        _ => (used[k].encoder_lengths_m[i] - used[k - 1].encoder_lengths_m[i]).signum(),
                    }),
                ),
            };
            Ok(PoseSample {
                reference_cable: robot.reference_cable,
                row,
                direction,
                cable_drivers,
                position_m: pose.position_m,
                measured_tension_n: used[k].reference_tension_n,
                encoder: std::array::from_fn(|i| unless(Sensor::Encoder(i), encoders[k][i])),
                load_cell: unless(Sensor::LoadCell, cells[k][0]),
                position: std::array::from_fn(|i| unless(Sensor::Position(i), prior[position_rows + i])),
            })
        })
        .collect()
}

/// The value of `driver` at one pose: for `cable` (a per-cable driver), or
/// for the pose (a pose driver, or the mean of a per-cable driver over the
/// cables when `cable` is `None`).
pub(super) fn driver_value(s: &PoseSample, driver: &str, cable: Option<usize>) -> Option<f64> {
    let pose_driver = match driver {
        MEASURED_TENSION => Some(s.measured_tension_n),
        "platform x (m)" => Some(s.position_m.x),
        "platform y (m)" => Some(s.position_m.y),
        ROW_DRIVER => Some(s.row),
        _ => None,
    };
    let cable_driver = |i: usize| -> Option<f64> {
        if driver == DIRECTION_DRIVER {
            return Some(s.direction[i]);
        }
        DRIVERS.iter().position(|d| *d == driver).map(|d| s.cable_drivers[i][d])
    };
    pose_driver.or_else(|| match cable {
        Some(i) => cable_driver(i),
        None => {
            let values: Option<Vec<f64>> = (0..CABLE_COUNT).map(cable_driver).collect();
            values.map(|v| v.iter().sum::<f64>() / CABLE_COUNT as f64)
        }
    })
}

/// The normalised residual of one reading at one pose: `encoder` of
/// `cable`, or `load_cell`, `position_x|y|z` (NaN when left out).
pub(super) fn residual_value(s: &PoseSample, residual: &str, cable: usize) -> f64 {
    match residual {
        "encoder" => s.encoder[cable],
        "load_cell" => s.load_cell,
        "position_x" => s.position[0],
        "position_y" => s.position[1],
        _ => s.position[2],
    }
}

/// The residuals of [`driver_tests`].
pub(super) const RESIDUALS: [&str; 5] = ["encoder", "load_cell", "position_x", "position_y", "position_z"];

/// The drivers of [`driver_tests`]: the row and the direction of motion only
/// where `time_order`.
pub(super) fn drivers_tested(time_order: bool) -> Vec<&'static str> {
    let mut drivers: Vec<&str> = DRIVERS.to_vec();
    drivers.extend([MEASURED_TENSION, "platform x (m)", "platform y (m)"]);
    if time_order {
        drivers.extend([ROW_DRIVER, DIRECTION_DRIVER]);
    }
    drivers
}

/// `(driver, residual)` points of one residual against one driver.
pub(super) fn series_of(samples: &[PoseSample], residual: &str, driver: &str) -> Vec<(f64, f64)> {
    let mut points = Vec::new();
    for s in samples {
        if residual == "encoder" {
            for i in 0..CABLE_COUNT {
                if let Some(x) = driver_value(s, driver, Some(i)) {
                    if x.is_finite() && s.encoder[i].is_finite() {
                        points.push((x, s.encoder[i]));
                    }
                }
            }
        } else {
            let y = residual_value(s, residual, 0);
            if let Some(x) = driver_value(s, driver, None) {
                if x.is_finite() && y.is_finite() {
                    points.push((x, y));
                }
            }
        }
    }
    points
}

/// Every residual against every driver, strongest correlation first; the
/// row and the direction of motion only where `time_order` (the rows are in
/// the order the poses were taken).
pub(super) fn driver_tests(samples: &[PoseSample], time_order: bool) -> Vec<DriverTest> {
    let drivers = drivers_tested(time_order);
    let mut tests = Vec::new();
    for residual in RESIDUALS {
        for driver in &drivers {
            let points = series_of(samples, residual, driver);
            let (r, t) = correlation(&points);
            if r.is_finite() {
                tests.push(DriverTest {
                    residual: residual.to_string(),
                    driver: driver.to_string(),
                    points: points.len(),
                    correlation: r,
                    t_statistic: t,
                    significant: t.abs() > DRIVER_T_LIMIT,
                });
            }
        }
    }
    tests.sort_by(|a, b| b.t_statistic.abs().total_cmp(&a.t_statistic.abs()));
    tests
}

/// The driver most correlated with `residual`.
pub(super) fn strongest_driver<'a>(drivers: &'a [DriverTest], residual: &str) -> &'a str {
    drivers
        .iter()
        .find(|d| d.residual == residual)
        .map_or(DRIVERS[0], |d| d.driver.as_str())
}

/// The residual against the driver that shows the verdict's effect best,
/// before and after it (`after`: the verdict's fit and its samples), or
/// against the strongest driver for `none`.
pub(super) fn driver_series(
    drivers: &[DriverTest],
    before: &[PoseSample],
    after: Option<(EffectKind, &[PoseSample])>,
) -> DriverSeries {
    match after {
        Some((kind, after_samples)) => {
            let (residual, driver) = winning_driver(kind);
            let driver = if kind == EffectKind::Com {
                strongest_driver(drivers, "encoder")
            } else {
                driver
            };
            DriverSeries {
                residual: residual.to_string(),
                driver: driver.to_string(),
                before: series_of(before, residual, driver),
                after: Some(series_of(after_samples, residual, driver)),
            }
        }
        None => {
            let strongest = drivers.first();
            let residual = strongest.map_or("encoder", |d| d.residual.as_str());
            let driver = strongest.map_or(DRIVERS[0], |d| d.driver.as_str());
            DriverSeries {
                residual: residual.to_string(),
                driver: driver.to_string(),
                before: series_of(before, residual, driver),
                after: None,
            }
        }
    }
}

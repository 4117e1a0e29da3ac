//! Checks a calibration makes before and after its fit that no fit can make
//! for it ([`super::gross_errors::calibrate_checked`] runs them):
//!
//! - **the stated noise** ([`check_noise`]): every sigma within a range a
//!   sensor of the robot can have. A length sigma above the robot's size
//!   (its farthest anchors' distance) says the readings cannot tell any two
//!   poses apart, so the data could not move the guess; one below a
//!   micrometre (a load cell's below a millionth of the platform's weight,
//!   an orientation's below a microradian) is finer than any such sensor
//!   resolves, and its whitened residuals overflow the solver's cost;
//! - **duplicated rows** ([`check_rows`]): two rows whose eleven readings all
//!   agree within 1 % of their sigma are one pose logged twice. Two visits'
//!   independent readings differ by `N(0, 2 sigma^2)` each, so one agrees that
//!   closely with probability `0.01 / sqrt(pi) = 5.6e-3` and all eleven with
//!   about `2e-25` per pair of rows (below `1e-16` for 20 000 rows). A
//!   duplicate counts one pose twice and shrinks every 1-sigma by `sqrt 2`;
//! - **impossible readings** ([`check_rows`]): an encoder reading farther
//!   from its cable's median reading than twice the longest anchor-to-pose
//!   distance (both carry the same unknown offset, and no cable holding the
//!   platform is twice as long as its straight line); a load-cell reading
//!   more than 100 times off the file's median ratio to the straight-cable
//!   statics at the guess (a guess inside the frame gives each pose's tension
//!   to within a factor of a few; the unit check allows 3); an Euler angle
//!   outside the range of `R = Rz(yaw) Ry(pitch) Rx(roll)` (roll and yaw
//!   -180..180, pitch -90..90 degrees);
//! - **rows left out before the fit** ([`too_few_rows`]): why, counted per
//!   reason, with the first rows named and a unit hint;
//! - **parameters the data did not determine** ([`undetermined`]): an
//!   unobservable direction, or a 1-sigma larger than the robot itself.
//!
//! ```
//! use rand::SeedableRng;
//! use sagcal::calib::screen::{check_noise, check_rows};
//! use sagcal::model::sensors::NoisePreset;
//! use sagcal::model::Robot;
//! use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};
//! let robot = Robot::builtin("large")?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
//! let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 8, &mut rng)?;
//! let mut noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
//! let mut data = measure(&robot, &equilibria, &noise, &mut rng);
//! check_noise(&noise, &robot)?;
//! let rows: Vec<usize> = (0..data.len()).collect();
//! check_rows(&robot, &data, &rows, &noise)?;
//! // Row 6 logged again as row 8: both named.
//! data[7] = data[5];
//! let message = check_rows(&robot, &data, &rows, &noise).unwrap_err().to_string();
//! assert!(message.contains("rows 6 and 8 hold the same readings"), "{message}");
//! // An encoder sigma of 1 km for a robot 330 m across.
//! noise.encoder_sigma_m = 1e3;
//! let message = check_noise(&noise, &robot).unwrap_err().to_string();
//! assert!(message.contains("encoder sigma"), "{message}");
//! # Ok::<(), sagcal::Error>(())
//! ```

use nalgebra::Vector3;

use super::result::{CalibrationResult, ParameterUncertainty};
use super::snooping::row_name;
use crate::error::{Error, Result};
use crate::model::measurement::PoseMeasurement;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::model::sensors::SensorNoise;
use crate::model::statics::reference_tension_magnitude_guess;

/// The finest length sigma accepted, metres: no cable encoder or localiser
/// resolves a micrometre over a frame of metres.
pub const MIN_LENGTH_SIGMA_M: f64 = 1e-6;
/// The finest load-cell sigma accepted, as a fraction of the platform's
/// weight (the best load cells resolve about 1e-5 of their full scale).
pub const MIN_LOAD_CELL_SIGMA_FRACTION: f64 = 1e-6;
/// The finest orientation sigma accepted, radians (0.2 arcsecond).
pub const MIN_ORIENTATION_SIGMA_RAD: f64 = 1e-6;
/// Two rows whose every reading agrees within this fraction of its sigma are
/// one pose logged twice (module docs: about 2e-25 per pair by chance).
pub const DUPLICATE_FRACTION: f64 = 0.01;
/// A load-cell reading this many times off the file's median ratio to the
/// statics at the guess is impossible (module docs).
pub const LOAD_CELL_FACTOR: f64 = 100.0;
/// At most this many rows are named in a message.
const NAMED: usize = 3;

/// The robot's size: the largest distance between two of its anchors, metres.
pub fn robot_size_m(robot: &Robot) -> f64 {
    let a = &robot.anchors_m;
    (0..CABLE_COUNT)
        .flat_map(|i| (i + 1..CABLE_COUNT).map(move |j| (a[i] - a[j]).norm()))
        .fold(0.0, f64::max)
}

/// Refuse sigmas outside the range a sensor of `robot` can have (module
/// docs): [`Error::InvalidInput`] naming the sigma, its value, the range
/// and the reason.
pub fn check_noise(noise: &SensorNoise, robot: &Robot) -> Result<()> {
    let size = robot_size_m(robot);
    let weight = robot.platform_weight_n;
    let checks = [
        (
            "encoder sigma",
            noise.encoder_sigma_m,
            MIN_LENGTH_SIGMA_M,
            size,
            "m",
            "the robot's size",
        ),
        (
            "localiser position sigma",
            noise.position_sigma_m,
            MIN_LENGTH_SIGMA_M,
            size,
            "m",
            "the robot's size",
        ),
        (
            "load-cell sigma",
            noise.load_cell_sigma_n,
            MIN_LOAD_CELL_SIGMA_FRACTION * weight,
            weight,
            "N",
            "the platform's weight",
        ),
        (
            "localiser orientation sigma",
            noise.orientation_sigma_rad,
            MIN_ORIENTATION_SIGMA_RAD,
            std::f64::consts::PI,
            "rad",
            "half a turn",
        ),
    ];
    for (name, value, low, high, unit, what) in checks {
        if !(value.is_finite() && value > 0.0) {
            return Err(Error::InvalidInput(format!(
                "the {name} must be a positive number, got {value}: it weights the readings"
            )));
        }
        if value > high {
            return Err(Error::InvalidInput(format!(
                "the {name} {value:e} {unit} is larger than {what} ({high:.4} {unit}): readings that uncertain cannot tell \
                 any two poses apart, so the data could not move the initial guess; state the sensor's real noise"
            )));
        }
        if value < low {
            return Err(Error::InvalidInput(format!(
                "the {name} {value:e} {unit} is below {low:e} {unit}: no such sensor resolves that, and the model's own \
                 approximations would read as gross errors; state the sensor's real noise"
            )));
        }
    }
    Ok(())
}

/// Refuse rows that no fit can use (module docs): duplicated rows, encoder
/// and load-cell readings the robot cannot produce, angles outside the
/// Euler ranges. The error names the rows (1-based, with their lines) and
/// the field. `measurements` are the rows inside the robot's frame.
/// `rows[k]` is the row (0-based, in the data given) of `measurements[k]`.
pub fn check_rows(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    rows: &[usize],
    noise: &SensorNoise,
) -> Result<()> {
    check_angles(measurements, rows)?;
    check_encoders(initial, measurements, rows)?;
    check_load_cell(initial, measurements, rows)?;
    check_duplicates(measurements, rows, noise)
}

/// A reading as it reads best: plain, or in scientific notation when very
/// large or small (a value of 1e300 is not 301 digits).
fn value_text(value: f64) -> String {
    if value != 0.0 && !(1e-4..1e6).contains(&value.abs()) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// The checks of the rows kept for the fit: `kept[k]` is row `rows[k]` of
/// `measurements`, the others were left out outside the robot's frame. Fewer
/// than [`super::MIN_POSES`] kept is [`too_few_rows`]'s error; otherwise
/// [`super::validate_measurements`], then [`check_rows`].
pub fn check_kept_rows(
    initial: &Robot,
    measurements: &[PoseMeasurement],
    kept: &[PoseMeasurement],
    rows: &[usize],
    noise: &SensorNoise,
) -> Result<()> {
    if kept.len() < super::MIN_POSES && kept.len() < measurements.len() {
        let outside: Vec<usize> = (0..measurements.len()).filter(|k| !rows.contains(k)).collect();
        return Err(too_few_rows(initial, measurements, &outside, super::MIN_POSES));
    }
    // Too few poses, or all at one place, first: they say more than a duplicate.
    super::validate_measurements(kept)?;
    check_rows(initial, kept, rows, noise)
}

/// The rows named, at most [`NAMED`], and how many more.
fn named(rows: &[String]) -> String {
    let more = rows.len().saturating_sub(NAMED);
    let mut text = rows.iter().take(NAMED).cloned().collect::<Vec<_>>().join("; ");
    if more > 0 {
        text += &format!("; and {more} more");
    }
    text
}

fn check_angles(measurements: &[PoseMeasurement], rows: &[usize]) -> Result<()> {
    let mut bad = Vec::new();
    for (k, m) in measurements.iter().enumerate() {
        for (field, value, limit) in [
            ("roll_deg", m.roll_deg, 180.0),
            ("pitch_deg", m.pitch_deg, 90.0),
            ("yaw_deg", m.yaw_deg, 180.0),
        ] {
            if value.abs() > limit {
                bad.push(format!(
                    "{}, field `{field}`: {} deg is outside -{limit}..{limit}",
                    row_name(rows[k], m.line),
                    value_text(value)
                ));
            }
        }
    }
    if bad.is_empty() {
        return Ok(());
    }
    Err(Error::InvalidInput(format!(
        "{}: the localiser's angles of R = Rz(yaw) Ry(pitch) Rx(roll) lie in -180..180 (roll, yaw) and -90..90 (pitch) \
         degrees; an angle beyond wrapped or was mistyped, and would make the localiser's orientations look \
         inconsistent for every pose: fix the row",
        named(&bad)
    )))
}

fn median(mut values: Vec<f64>) -> Option<f64> {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    Some(values[values.len() / 2])
}

fn check_encoders(initial: &Robot, measurements: &[PoseMeasurement], rows: &[usize]) -> Result<()> {
    let mut bad = Vec::new();
    let mut bound_text = String::new();
    for i in 0..CABLE_COUNT {
        let reach = initial.attachments_m[i].norm();
        let longest = measurements
            .iter()
            .map(|m| (initial.anchors_m[i] - Vector3::from(m.position_m)).norm() + reach)
            .fold(0.0, f64::max);
        let bound = 2.0 * longest;
        let Some(centre) = median(measurements.iter().map(|m| m.encoder_lengths_m[i]).collect()) else {
            continue;
        };
        for (k, m) in measurements.iter().enumerate() {
            let value = m.encoder_lengths_m[i];
            if (value - centre).abs() > bound {
                if bound_text.is_empty() {
                    bound_text = format!(
                        "cable {}'s readings lie within {bound:.3} m of their median {centre:.3} m",
                        i + 1
                    );
                }
                bad.push(format!(
                    "{}, field `l{}_m`: {} m is {:.3e} m from the cable's median reading",
                    row_name(rows[k], m.line),
                    i + 1,
                    value_text(value),
                    (value - centre).abs()
                ));
            }
        }
    }
    if bad.is_empty() {
        return Ok(());
    }
    Err(Error::InvalidInput(format!(
        "{}: impossible for this robot: two readings of one encoder share its offset, so they differ by less than \
         the cable's longest length, and no cable holding the platform is twice as long as the longest straight \
         line from its anchor to a pose ({bound_text}); fix or delete the row",
        named(&bad)
    )))
}

fn check_load_cell(initial: &Robot, measurements: &[PoseMeasurement], rows: &[usize]) -> Result<()> {
    let ratios: Vec<f64> = measurements
        .iter()
        .map(|m| m.reference_tension_n / reference_tension_magnitude_guess(initial, Vector3::from(m.position_m)))
        .collect();
    let Some(centre) = median(ratios.clone()) else {
        return Ok(());
    };
    if centre <= 0.0 {
        return Ok(());
    }
    let bad: Vec<String> = measurements
        .iter()
        .zip(&ratios)
        .enumerate()
        .filter(|(_, (_, r))| r.is_finite() && (**r / centre > LOAD_CELL_FACTOR || centre / **r > LOAD_CELL_FACTOR))
        .map(|(k, (m, r))| {
            format!(
                "{}, field `f_ref_n`: {} N is {:.3e} times what the other rows' readings give at that pose",
                row_name(rows[k], m.line),
                value_text(m.reference_tension_n),
                r / centre
            )
        })
        .collect();
    if bad.is_empty() {
        return Ok(());
    }
    Err(Error::InvalidInput(format!(
        "{}: impossible for this robot: the straight-cable statics at the initial guess give each pose's reference \
         tension to within a factor of a few, and this is more than {LOAD_CELL_FACTOR} times off the file's median \
         ratio to them; fix or delete the row",
        named(&bad)
    )))
}

/// The 11 readings of a row, in file column order.
fn readings(m: &PoseMeasurement) -> [f64; 11] {
    let [x, y, z] = m.position_m;
    let [l1, l2, l3, l4] = m.encoder_lengths_m;
    [
        x,
        y,
        z,
        m.roll_deg,
        m.pitch_deg,
        m.yaw_deg,
        l1,
        l2,
        l3,
        l4,
        m.reference_tension_n,
    ]
}

/// The sigma of each of a row's 11 readings, in file column order.
fn sigmas(noise: &SensorNoise) -> [f64; 11] {
    let p = noise.position_sigma_m;
    let o = noise.orientation_sigma_rad.to_degrees();
    let e = noise.encoder_sigma_m;
    [p, p, p, o, o, o, e, e, e, e, noise.load_cell_sigma_n]
}

/// The pairs of rows (0-based, earlier first) whose every reading agrees
/// within [`DUPLICATE_FRACTION`] of its sigma, in row order.
pub fn duplicate_rows(measurements: &[PoseMeasurement], noise: &SensorNoise) -> Vec<(usize, usize)> {
    let tolerance = sigmas(noise).map(|s| DUPLICATE_FRACTION * s);
    // Sorted by x, only rows within x's tolerance of each other are compared.
    let mut order: Vec<usize> = (0..measurements.len()).collect();
    order.sort_by(|&a, &b| measurements[a].position_m[0].total_cmp(&measurements[b].position_m[0]));
    let mut pairs = Vec::new();
    for (n, &a) in order.iter().enumerate() {
        let va = readings(&measurements[a]);
        for &b in &order[n + 1..] {
            let vb = readings(&measurements[b]);
            if vb[0] - va[0] > tolerance[0] {
                break;
            }
            if (0..11).all(|c| (va[c] - vb[c]).abs() <= tolerance[c]) {
                pairs.push((a.min(b), a.max(b)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

fn check_duplicates(measurements: &[PoseMeasurement], rows: &[usize], noise: &SensorNoise) -> Result<()> {
    let pairs = duplicate_rows(measurements, noise);
    if pairs.is_empty() {
        return Ok(());
    }
    let (a, b) = pairs[0];
    let (ma, mb) = (&measurements[a], &measurements[b]);
    let first = if ma.line > 0 && mb.line > 0 {
        format!(
            "rows {} and {} (lines {} and {})",
            rows[a] + 1,
            rows[b] + 1,
            ma.line,
            mb.line
        )
    } else {
        format!("rows {} and {}", rows[a] + 1, rows[b] + 1)
    };
    let others: Vec<String> = pairs[1..]
        .iter()
        .map(|&(a, b)| format!("rows {} and {}", rows[a] + 1, rows[b] + 1))
        .collect();
    Err(Error::InvalidInput(format!(
        "{first} hold the same readings: all 11 agree within {:.0} % of their noise sigma, which two visits' \
         independent readings do with probability about 2e-25: one pose logged twice, which would count it twice \
         and make the calibration over-confident; delete one of them{}",
        DUPLICATE_FRACTION * 100.0,
        if others.is_empty() {
            String::new()
        } else {
            format!(" ({} such pairs in all; also {})", pairs.len(), named(&others))
        }
    )))
}

/// The error when fewer than `min_poses` of `measurements` are inside the
/// robot's frame: how many rows were left out for what reason, the first
/// rows named, and, when the positions lie about 1000 (100) times as far from
/// the anchors' centre as the robot is large, that they look like mm (cm).
pub fn too_few_rows(initial: &Robot, measurements: &[PoseMeasurement], outside: &[usize], min_poses: usize) -> Error {
    let kept = measurements.len() - outside.len();
    let names: Vec<String> = outside.iter().map(|&k| row_name(k, measurements[k].line)).collect();
    // Would the positions, divided by 1000 (100), be inside the frame? Then
    // they were logged in mm (cm), if they are spread like a calibration's.
    let min = initial
        .anchors_m
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |m, a| m.inf(a));
    let max = initial
        .anchors_m
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |m, a| m.sup(a));
    // Converted poses must still spread over a hundredth of the robot (a
    // calibration's spread over tens of per cent of it): dividing any far-off
    // positions by 1000 would put them near the origin, inside most frames.
    let size = robot_size_m(initial);
    let points: Vec<Vector3<f64>> = outside
        .iter()
        .map(|&k| Vector3::from(measurements[k].position_m))
        .collect();
    let mean = points.iter().sum::<Vector3<f64>>() / points.len().max(1) as f64;
    let spread_m = (points.iter().map(|p| (p - mean).norm_squared()).sum::<f64>() / points.len().max(1) as f64).sqrt();
    let inside_if = |scale: f64| {
        outside
            .iter()
            .filter(|&&k| {
                let p = Vector3::from(measurements[k].position_m) / scale;
                p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z < min.z
            })
            .count()
    };
    let units: Vec<&str> = [(1e3, "mm"), (1e2, "cm")]
        .iter()
        .filter(|&&(scale, _)| 2 * inside_if(scale) > outside.len() && spread_m / scale >= 0.01 * size)
        .map(|&(_, unit)| unit)
        .collect();
    let hint = if units.is_empty() {
        String::new()
    } else {
        format!(
            " the positions look like {}, not m: converted to metres, most of these rows are inside the frame \
             (convert the data, encoder readings included, to metres)",
            units.join(" or ")
        )
    };
    Error::InvalidInput(format!(
        "{} of {} rows are left out because the localiser's position is outside the robot's frame ({}), leaving {kept}: \
         at least {min_poses} are needed to calibrate;{hint}",
        outside.len(),
        measurements.len(),
        named(&names)
    ))
}

/// Why the data did not determine the calibrated parameters, if they did
/// not: an unobservable direction, or an anchor or offset whose 1-sigma is
/// larger than the robot itself (`size_m`, [`robot_size_m`] of the guess):
/// the data could put it anywhere in the frame.
pub fn undetermined(result: &CalibrationResult, size_m: f64) -> Option<String> {
    match &result.uncertainty {
        ParameterUncertainty::RankDeficient { directions } => Some(format!(
            "the data do not determine the anchors and offsets: {} directions of parameter space are not observable from these \
             poses with the stated noise, and the data cannot move the initial guess along them",
            directions.len()
        )),
        ParameterUncertainty::Full {
            anchor_sigma_m,
            offset_sigma_m,
            ..
        } => {
            let worst_anchor = anchor_sigma_m
                .iter()
                .enumerate()
                .map(|(i, s)| (i, s.iter().copied().fold(0.0, f64::max)))
                .max_by(|a, b| a.1.total_cmp(&b.1));
            let worst_offset = offset_sigma_m
                .iter()
                .copied()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(&b.1));
            let too_large = |s: f64| s.is_nan() || s > size_m;
            if let Some((i, s)) = worst_anchor.filter(|(_, s)| too_large(*s)) {
                return Some(format!(
                    "the data did not determine the anchors: anchor {}'s 1-sigma is {s:.3e} m, larger than the robot \
                     itself ({size_m:.3} m between its farthest anchors); the stated noise is too large or the poses too few",
                    i + 1
                ));
            }
            if let Some((i, s)) = worst_offset.filter(|(_, s)| too_large(*s)) {
                return Some(format!(
                    "the data did not determine the offsets: cable {}'s offset 1-sigma is {s:.3e} m, larger than the \
                     robot itself ({size_m:.3} m between its farthest anchors); the stated noise is too large or the poses too few",
                    i + 1
                ));
            }
            None
        }
    }
}

#[cfg(test)]
mod tests;

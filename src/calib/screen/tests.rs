//! Unit tests of the checks before and after a fit.

use super::*;
use crate::model::sensors::NoisePreset;

/// Rows on a grid under the large robot's anchors: encoders the straight
/// distances, the load cell the straight-cable statics, angles small.
fn rows(robot: &Robot) -> Vec<PoseMeasurement> {
    let mut out = Vec::new();
    for (n, (x, y)) in [
        (-40.0, -30.0),
        (0.0, 0.0),
        (35.0, 20.0),
        (-20.0, 40.0),
        (50.0, -45.0),
        (10.0, 60.0),
    ]
    .into_iter()
    .enumerate()
    {
        let p = Vector3::new(x, y, 5.0 + n as f64);
        out.push(PoseMeasurement {
            line: n + 2,
            position_m: p.into(),
            roll_deg: 0.3 * n as f64,
            pitch_deg: -0.2 * n as f64,
            yaw_deg: 0.1,
            encoder_lengths_m: std::array::from_fn(|i| (robot.anchors_m[i] - p).norm()),
            reference_tension_n: reference_tension_magnitude_guess(robot, p),
            excluded: Default::default(),
            order: None,
        });
    }
    out
}

fn setup() -> (Robot, Vec<PoseMeasurement>, Vec<usize>, SensorNoise) {
    let robot = Robot::builtin("large").unwrap();
    let data = rows(&robot);
    let index = (0..data.len()).collect();
    let noise = NoisePreset::Paper.sigmas(robot.platform_weight_n);
    (robot, data, index, noise)
}

#[test]
fn clean_rows_pass() {
    let (robot, data, index, noise) = setup();
    check_noise(&noise, &robot).unwrap();
    check_rows(&robot, &data, &index, &noise).unwrap();
}

#[test]
fn duplicates_exact_and_near_are_found_and_revisits_are_not() {
    let (robot, mut data, _, noise) = setup();
    // Row 2 again, every reading within a tenth of a per cent of its sigma.
    let mut again = data[1];
    again.line = 8;
    again.position_m[0] += 1e-3 * noise.position_sigma_m;
    again.reference_tension_n += 1e-3 * noise.load_cell_sigma_n;
    data.push(again);
    assert_eq!(duplicate_rows(&data, &noise), vec![(1, 6)]);
    let index: Vec<usize> = (0..data.len()).collect();
    let message = check_rows(&robot, &data, &index, &noise).unwrap_err().to_string();
    assert!(
        message.contains("rows 2 and 7 (lines 3 and 8) hold the same readings"),
        "{message}"
    );
    // A revisit of the same pose: its readings differ by about a sigma (here one encoder by half of it).
    data[6].encoder_lengths_m[2] += 0.5 * noise.encoder_sigma_m;
    assert!(duplicate_rows(&data, &noise).is_empty());
}

#[test]
fn noise_outside_its_range_is_refused() {
    let (robot, _, _, noise) = setup();
    let size = robot_size_m(&robot);
    assert!((size - 333.0).abs() < 0.1, "{size}");
    for (change, needle) in [
        (
            (|n: &mut SensorNoise| n.encoder_sigma_m = 1e300) as fn(&mut SensorNoise),
            "encoder sigma 1e300 m is larger than the robot's size",
        ),
        (
            |n| n.position_sigma_m = 400.0,
            "localiser position sigma 4e2 m is larger",
        ),
        (
            |n| n.load_cell_sigma_n = 1e4,
            "load-cell sigma 1e4 N is larger than the platform's weight",
        ),
        (
            |n| n.orientation_sigma_rad = 4.0,
            "orientation sigma 4e0 rad is larger than half a turn",
        ),
        (|n| n.encoder_sigma_m = 1e-300, "encoder sigma 1e-300 m is below 1e-6 m"),
        (
            |n| n.load_cell_sigma_n = 0.0,
            "load-cell sigma must be a positive number, got 0",
        ),
        (
            |n| n.position_sigma_m = f64::NAN,
            "position sigma must be a positive number, got NaN",
        ),
    ] {
        let mut n = noise;
        change(&mut n);
        let message = check_noise(&n, &robot).unwrap_err().to_string();
        assert!(message.contains(needle), "{message}");
    }
}

#[test]
fn impossible_readings_are_named_with_row_line_and_field() {
    let (robot, data, index, noise) = setup();
    for (k, edit, needle) in [
        (
            3,
            (|m: &mut PoseMeasurement| m.encoder_lengths_m[0] = 1e6) as fn(&mut PoseMeasurement),
            "row 4 (line 5), field `l1_m`: 1e6 m",
        ),
        (
            0,
            |m| m.encoder_lengths_m[3] = -900.0,
            "row 1 (line 2), field `l4_m`: -900 m",
        ),
        (
            5,
            |m| m.reference_tension_n = 1e300,
            "row 6 (line 7), field `f_ref_n`: 1e300 N",
        ),
        (
            2,
            |m| m.reference_tension_n = 1e-3,
            "row 3 (line 4), field `f_ref_n`: 0.001 N",
        ),
        (
            1,
            |m| m.roll_deg = 400.0,
            "row 2 (line 3), field `roll_deg`: 400 deg is outside -180..180",
        ),
        (
            4,
            |m| m.pitch_deg = -95.0,
            "row 5 (line 6), field `pitch_deg`: -95 deg is outside -90..90",
        ),
    ] {
        let mut bad = data.clone();
        edit(&mut bad[k]);
        let message = check_rows(&robot, &bad, &index, &noise).unwrap_err().to_string();
        assert!(message.contains(needle), "{message}");
    }
    // An encoder 5 m off is a blunder for the fit to find, not impossible.
    let mut slipped = data.clone();
    slipped[2].encoder_lengths_m[1] += 5.0;
    check_rows(&robot, &slipped, &index, &noise).unwrap();
}

#[test]
fn rows_left_out_say_why_and_hint_at_the_unit() {
    let (robot, data, _, _) = setup();
    let mm: Vec<PoseMeasurement> = data
        .iter()
        .map(|m| PoseMeasurement {
            position_m: m.position_m.map(|v| v * 1000.0),
            ..*m
        })
        .collect();
    let all: Vec<usize> = (0..mm.len()).collect();
    let message = too_few_rows(&robot, &mm, &all, 4).to_string();
    assert!(message.contains("6 of 6 rows are left out"), "{message}");
    assert!(
        message.contains("row 1 (line 2); row 2 (line 3); row 3 (line 4); and 3 more"),
        "{message}"
    );
    assert!(message.contains("the positions look like mm, not m"), "{message}");
    let cm: Vec<PoseMeasurement> = data
        .iter()
        .map(|m| PoseMeasurement {
            position_m: m.position_m.map(|v| v * 100.0),
            ..*m
        })
        .collect();
    // Divided by 1000 they are inside the frame too (a tenth of the way out): both are named.
    let message = too_few_rows(&robot, &cm, &all, 4).to_string();
    assert!(message.contains("the positions look like mm or cm, not m"), "{message}");
    // Positions 1 km off in x are no unit.
    let far: Vec<PoseMeasurement> = data
        .iter()
        .map(|m| PoseMeasurement {
            position_m: [m.position_m[0] + 1e3, m.position_m[1], m.position_m[2]],
            ..*m
        })
        .collect();
    let message = too_few_rows(&robot, &far, &all, 4).to_string();
    assert!(!message.contains("look like"), "{message}");
}

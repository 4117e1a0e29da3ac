//! Progress of the long jobs: the library tells its callback `(done, total,
//! what)` with counts that never fall within a stage and end at the total,
//! and the callback changes no number; the command writes its progress to
//! stderr only, so that stdout (tables, JSON) is the same on a terminal and
//! in a pipe.

#[cfg(target_os = "linux")]
use std::path::Path;
#[cfg(target_os = "linux")]
use std::process::{Command, Stdio};

use rand::SeedableRng;
use sagcal::calib::gross_errors::{calibrate_checked, calibrate_checked_with_progress, GrossErrorOptions};
use sagcal::calib::CalibrationOptions;
use sagcal::experiments::pose_plan::{plan_calibration, CandidateSource, PlanSettings};
use sagcal::localize::{Localizer, Readings};
use sagcal::model::sensors::NoisePreset;
use sagcal::model::Robot;
use sagcal::sim::closed_form::{measure, sample_equilibria, Workspace};

#[path = "common/cli.rs"]
mod cli;
use cli::robot;

/// Every report is `done <= total`; within a stage (`what` unchanged) `done`
/// never falls; the last report is `(total, total, "done")`.
fn check_reports(reports: &[(usize, usize, String)]) {
    assert!(!reports.is_empty(), "no report");
    for (done, total, what) in reports {
        assert!(done <= total, "{done} of {total}: {what}");
    }
    for pair in reports.windows(2) {
        if pair[0].2 == pair[1].2 {
            assert!(pair[1].0 >= pair[0].0, "{:?} then {:?}", pair[0], pair[1]);
        }
    }
    let (done, total, what) = reports.last().unwrap();
    assert_eq!((done, what.as_str()), (total, "done"));
}

#[test]
fn the_plan_reports_drawing_and_choosing_and_plans_the_same() {
    let robot = Robot::builtin("small").unwrap();
    let settings = PlanSettings {
        candidates: CandidateSource::Drawn {
            workspace: None,
            count: 100,
        },
        seed: 3,
        ..PlanSettings::new(9)
    };
    let mut reports = Vec::new();
    let planned = plan_calibration(&robot, &settings, &mut |step| reports.push(step.counts())).unwrap();
    check_reports(&reports);
    let drawn: Vec<(usize, usize)> = reports
        .iter()
        .filter(|r| r.2.starts_with("drawing 100 candidate poses"))
        .map(|r| (r.0, r.1))
        .collect();
    assert_eq!(drawn.first(), Some(&(0, 100)));
    assert_eq!(drawn.last(), Some(&(100, 100)));
    assert!(drawn.windows(2).all(|w| w[0].0 < w[1].0), "{drawn:?}");
    let greedy: Vec<(usize, usize)> = reports
        .iter()
        .filter(|r| r.2 == "choosing the poses one by one")
        .map(|r| (r.0, r.1))
        .collect();
    assert_eq!(greedy, (0..=9).map(|k| (k, 9)).collect::<Vec<_>>());
    // Each exchange pass runs from 0 to 9 poses tried.
    let passes = reports.iter().filter(|r| r.2.starts_with("exchanging poses")).count();
    assert_eq!(passes, 10 * planned.plan.design.passes);
    let quiet = plan_calibration(&robot, &settings, &mut |_| {}).unwrap();
    let json = |p: &sagcal::experiments::pose_plan::PlannedCalibration| serde_json::to_string(&p.report).unwrap();
    assert_eq!(json(&planned), json(&quiet));
}

#[test]
fn the_checked_calibration_counts_its_fits_and_calibrates_the_same() {
    let truth = Robot::builtin("large").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(63);
    let equilibria = sample_equilibria(&truth, &Workspace::default_for(&truth), 15, &mut rng).unwrap();
    let noise = NoisePreset::Paper.sigmas(truth.platform_weight_n);
    let mut data = measure(&truth, &equilibria, &noise, &mut rng);
    data[4].encoder_lengths_m[2] += 2.0; // a slipped drum: the search for gross errors runs
    let options = CalibrationOptions::new(noise);
    let check = GrossErrorOptions::default();
    let mut reports = Vec::new();
    let checked = calibrate_checked_with_progress(&truth, &data, &options, &check, &mut |done, total, what| {
        reports.push((done, total, what.to_string()))
    })
    .unwrap();
    check_reports(&reports);
    assert_eq!(reports[0], (0, 1, "calibration: rigid".to_string()));
    // Fits are counted in order: `done` never falls over the whole run.
    assert!(reports.windows(2).all(|w| w[1].0 >= w[0].0));
    let fits = reports.last().unwrap().0;
    assert!(fits >= 2, "{reports:?}");
    assert!(
        reports.iter().any(|r| r.2.starts_with("gross-error search")),
        "{reports:?}"
    );
    let quiet = calibrate_checked(&truth, &data, &options, &check).unwrap();
    assert_eq!(format!("{:?}", checked.result), format!("{:?}", quiet.result));
    assert_eq!(format!("{:?}", checked.excluded), format!("{:?}", quiet.excluded));
}

#[test]
fn localisation_reports_every_row() {
    let robot = Robot::builtin("large").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let equilibria = sample_equilibria(&robot, &Workspace::default_for(&robot), 7, &mut rng).unwrap();
    let rows: Vec<Readings> = equilibria
        .iter()
        .map(|eq| Readings {
            encoder_lengths_m: eq.cable_lengths_m,
            load_cell_n: None,
            localiser_pose: None,
        })
        .collect();
    let localizer = Localizer::new(&robot, &NoisePreset::Paper.sigmas(robot.platform_weight_n)).unwrap();
    let mut reports = Vec::new();
    let solved = localizer
        .localize_sequence_with_progress(&rows, true, &mut || false, &mut |done, total, what| {
            reports.push((done, total, what.to_string()))
        })
        .unwrap();
    check_reports(&reports);
    let counts: Vec<(usize, usize)> = reports.iter().map(|r| (r.0, r.1)).collect();
    assert_eq!(counts, (0..=7).map(|k| (k, 7)).collect::<Vec<_>>());
    let quiet = localizer.localize_sequence(&rows, true, &mut || false).unwrap();
    assert_eq!(format!("{solved:?}"), format!("{quiet:?}"));
}

/// `sagcal ARGS` in `dir` with stdout piped and stderr a pseudo-terminal
/// (`TERM=xterm`, so that the bar is drawn): (stdout, what the terminal got).
#[cfg(target_os = "linux")]
fn on_a_terminal(dir: &Path, args: &[&str]) -> (Vec<u8>, String) {
    use std::io::Read;
    use std::os::fd::{FromRawFd, OwnedFd};

    let (mut master, mut slave) = (-1, -1);
    // SAFETY: openpty writes two new descriptors into the integers given; the
    // name, termios and window size may be null.
    let opened = unsafe {
        libc::openpty(
            &mut master,
            &mut slave,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
        )
    };
    assert_eq!(opened, 0, "openpty: {}", std::io::Error::last_os_error());
    // SAFETY: both descriptors were just opened and are owned here alone.
    let (master, slave) = unsafe { (OwnedFd::from_raw_fd(master), OwnedFd::from_raw_fd(slave)) };
    let child = Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .env("TERM", "xterm")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::from(slave))
        .spawn()
        .expect("sagcal runs");
    // The terminal is read while the command runs (a full one would block it);
    // reading ends with an error (EIO) once the command has closed it.
    let reader = std::thread::spawn(move || {
        let mut terminal = std::fs::File::from(master);
        let (mut seen, mut buffer) = (Vec::new(), [0u8; 4096]);
        while let Ok(n) = terminal.read(&mut buffer) {
            if n == 0 {
                break;
            }
            seen.extend_from_slice(&buffer[..n]);
        }
        String::from_utf8_lossy(&seen).to_string()
    });
    let out = child.wait_with_output().expect("sagcal ends");
    assert!(out.status.success(), "{:?}", out.status);
    (out.stdout, reader.join().unwrap())
}

#[cfg(target_os = "linux")]
#[test]
fn plan_writes_its_progress_to_stderr_only() {
    let dir = tempfile::tempdir().unwrap();
    let small = robot("small");
    let args = [
        "plan",
        "--robot",
        small.as_str(),
        "--poses",
        "6",
        "--candidates",
        "100",
        "--seed",
        "2",
        "--json",
    ];
    let (on_terminal, terminal) = on_a_terminal(dir.path(), &args);
    assert!(
        terminal.contains("drawing 100 candidate poses") && terminal.contains("/100"),
        "no progress on the terminal: {terminal}"
    );
    let started = std::time::Instant::now();
    let piped = cli::sagcal(dir.path(), &args);
    let seconds = started.elapsed().as_secs_f64();
    assert!(piped.status.success());
    // stdout is the JSON alone, the same with and without a terminal.
    assert_eq!(on_terminal, piped.stdout);
    let report: serde_json::Value = serde_json::from_slice(&piped.stdout).unwrap();
    assert_eq!(report["poses"], 6);
    // Not on a terminal, a run shorter than 10 s writes nothing but its first line.
    let stderr = String::from_utf8_lossy(&piped.stderr);
    assert!(stderr.starts_with("sagcal plan: seed 2, 6 poses"), "{stderr}");
    if seconds < 9.0 {
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
}

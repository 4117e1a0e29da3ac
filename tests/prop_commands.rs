//! Whole commands under random robots, workspaces, data and options
//! (property-based, proptest): every run of the `sagcal` binary must
//!
//! - end without a panic (exit 0, 1 or 2, never 101 or a signal);
//! - do a bounded amount of work: the binary's step count (`sagcal::steps`,
//!   printed with `SAGCAL_REPORT_STEPS`) stays under a budget that is a
//!   formula of the command's sizes, so a hang is caught by a count, not a clock;
//! - on a non-zero exit, say why on stderr and leave no output file;
//! - leave its input files byte for byte as they were;
//! - on exit 0, give an answer that passes its own consistency test: the
//!   files it wrote load again, the numbers are finite, `calibrate`'s verdict
//!   is "consistent", every `localize` row called ok is inside the robot's
//!   frame, `verify` verified at least one row.
//!
//! Robots are drawn anywhere: realistic frames of any size, anchors at random
//! (coincident, collinear, below the platform), weights from 0 to absurd,
//! random reference cables, offsets, workspaces (inverted, far away, huge) and
//! effects. Data are simulated from valid robots and then damaged (one absurd
//! reading, duplicated rows, a unit change, quoted numbers, a huge angle).
//!
//! `SAGCAL_PROPERTY_CASES` sets the number of cases (default 40, about a
//! minute here); `SAGCAL_PROPERTY_SEED` the seed (printed); `SAGCAL_BIN` runs
//! another binary (e.g. the release build for long runs); with
//! `SAGCAL_PROPERTY_COLLECT=DIR` every failing case is written to DIR and the
//! run goes on (a search for faults rather than a test); with
//! `SAGCAL_PROPERTY_ONLY=N` only case N of the seed is run (to reproduce a
//! collected case: the cases are drawn the same, the others are not run).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

/// Cases of one `make test` run.
const DEFAULT_CASES: u32 = 40;

/// A run that takes longer than this is stopped and reported; the property
/// itself bounds the work by the step count, this only keeps a hang from
/// hanging the test suite.
const SAFETY_TIMEOUT: Duration = Duration::from_secs(600);

/// The binary under test.
fn binary() -> PathBuf {
    std::env::var_os("SAGCAL_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_sagcal")))
}

// ---------------------------------------------------------------------------
// Random robots

/// A robot file's contents, drawn at random (some of them invalid on purpose).
#[derive(Debug, Clone)]
struct RobotSpec {
    anchors: [[f64; 3]; 4],
    attachments: [[f64; 3]; 4],
    platform_weight_n: f64,
    cable_weight_n_per_m: f64,
    com_offset_m: [f64; 3],
    reference_cable: usize,
    length_offsets_m: Option<[f64; 4]>,
    workspace: Option<([f64; 3], [f64; 3])>,
    pulley_radius_m: Option<f64>,
}

impl RobotSpec {
    fn toml(&self) -> String {
        let v = |a: &[f64]| {
            format!(
                "[{}]",
                a.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", ")
            )
        };
        let mut text = format!(
            "name = \"random\"\nreference_cable = {}\nplatform_weight_n = {:?}\ncable_weight_n_per_m = {:?}\ncom_offset_m = {}\n",
            self.reference_cable,
            self.platform_weight_n,
            self.cable_weight_n_per_m,
            v(&self.com_offset_m)
        );
        if let Some(offsets) = &self.length_offsets_m {
            text += &format!("length_offsets_m = {}\n", v(offsets));
        }
        for i in 0..4 {
            text += &format!(
                "\n[[cables]]\nanchor_m = {}\nattachment_m = {}\n",
                v(&self.anchors[i]),
                v(&self.attachments[i])
            );
        }
        if let Some((min, max)) = &self.workspace {
            text += &format!("\n[workspace]\nmin_m = {}\nmax_m = {}\n", v(min), v(max));
        }
        if let Some(radius) = self.pulley_radius_m {
            text += &format!("\n[effects]\npulley_radius_m = {radius:?}\n");
        }
        text
    }
}

/// How a robot's `[workspace]` is drawn.
#[derive(Debug, Clone)]
enum WorkspaceDraw {
    None,
    /// Centred under the anchors: `fx`, `fy` of their horizontal half-extents,
    /// heights `z0` .. `z1` as fractions of the lowest anchor's height.
    UnderAnchors {
        fx: f64,
        fy: f64,
        z0: f64,
        z1: f64,
    },
    /// Anywhere.
    Box([f64; 3], [f64; 3]),
}

impl WorkspaceDraw {
    fn resolve(&self, anchors: &[[f64; 3]; 4]) -> Option<([f64; 3], [f64; 3])> {
        match *self {
            WorkspaceDraw::None => None,
            WorkspaceDraw::Box(min, max) => Some((min, max)),
            WorkspaceDraw::UnderAnchors { fx, fy, z0, z1 } => {
                let lo = |k: usize| anchors.iter().map(|a| a[k]).fold(f64::INFINITY, f64::min);
                let hi = |k: usize| anchors.iter().map(|a| a[k]).fold(f64::NEG_INFINITY, f64::max);
                let (cx, cy) = ((lo(0) + hi(0)) / 2.0, (lo(1) + hi(1)) / 2.0);
                let (hx, hy) = ((hi(0) - lo(0)) / 2.0, (hi(1) - lo(1)) / 2.0);
                let top = lo(2);
                Some((
                    [cx - fx * hx, cy - fy * hy, z0 * top],
                    [cx + fx * hx, cy + fy * hy, z1 * top],
                ))
            }
        }
    }
}

/// Log-uniform in `[low, high]`.
fn log_uniform(low: f64, high: f64) -> impl Strategy<Value = f64> {
    (low.ln()..high.ln()).prop_map(f64::exp)
}

/// Anchors: a realistic rectangle of any size, points anywhere, or a degenerate layout.
fn anchors() -> impl Strategy<Value = [[f64; 3]; 4]> {
    let rectangle = (
        log_uniform(1.0, 300.0),
        log_uniform(1.0, 300.0),
        log_uniform(1.0, 100.0),
        0.0..0.15f64,
    )
        .prop_flat_map(|(hx, hy, h, jitter)| {
            proptest::collection::vec(-1.0..1.0f64, 12).prop_map(move |e| {
                let corner = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
                std::array::from_fn(|i| {
                    [
                        corner[i].0 * hx * (1.0 + jitter * e[3 * i]),
                        corner[i].1 * hy * (1.0 + jitter * e[3 * i + 1]),
                        h * (1.0 + jitter * e[3 * i + 2]),
                    ]
                })
            })
        });
    let anywhere = proptest::collection::vec(-200.0..200.0f64, 12)
        .prop_map(|c| std::array::from_fn(|i| [c[3 * i], c[3 * i + 1], c[3 * i + 2]]));
    let collinear = (log_uniform(1.0, 100.0), log_uniform(1.0, 50.0))
        .prop_map(|(s, h)| std::array::from_fn(|i| [s * (i as f64 - 1.5), 0.3 * s * (i as f64 - 1.5), h]));
    let below = (log_uniform(1.0, 100.0), -50.0..0.0f64).prop_map(|(s, z)| {
        let corner = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        std::array::from_fn(|i| [corner[i].0 * s, corner[i].1 * s, if i == 0 { z } else { s / 2.0 }])
    });
    prop_oneof![6 => rectangle, 2 => anywhere, 1 => collinear, 1 => below]
}

fn robot() -> impl Strategy<Value = RobotSpec> {
    let attachments = prop_oneof![
        3 => log_uniform(0.01, 1.0).prop_map(|a| {
            let corner = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            std::array::from_fn(|i| [corner[i].0 * a, corner[i].1 * a, -0.01])
        }),
        1 => proptest::collection::vec(-1.0..1.0f64, 12)
            .prop_map(|c| std::array::from_fn(|i| [c[3 * i], c[3 * i + 1], c[3 * i + 2]])),
    ];
    let platform_weight = prop_oneof![6 => log_uniform(1.0, 1e4), 1 => log_uniform(1e-300, 1e12)];
    let cable_weight = prop_oneof![
        5 => log_uniform(1e-3, 10.0),
        1 => Just(0.0),
        1 => log_uniform(1e-12, 1e-3),
        1 => log_uniform(10.0, 1e7),
    ];
    let offsets = proptest::option::of(proptest::array::uniform4(-100.0..100.0f64));
    // No box, a box under the anchors (fractions of their footprint and height), or a box anywhere.
    let workspace = prop_oneof![
        2 => Just(WorkspaceDraw::None),
        2 => (0.02..0.6f64, 0.02..0.6f64, 0.0..0.5f64, 0.05..0.7f64)
            .prop_map(|(fx, fy, z0, dz)| WorkspaceDraw::UnderAnchors { fx, fy, z0, z1: (z0 + dz).min(0.95) }),
        1 => (proptest::array::uniform3(-200.0..200.0f64), proptest::array::uniform3(-1.0..100.0f64))
            .prop_map(|(min, size)| WorkspaceDraw::Box(min, std::array::from_fn(|k| min[k] + size[k]))),
    ];
    let pulley = proptest::option::weighted(0.15, log_uniform(1e-3, 1e6));
    (
        anchors(),
        attachments,
        platform_weight,
        cable_weight,
        proptest::array::uniform3(-0.3..0.3f64),
        prop_oneof![10 => 1usize..=4, 1 => 0usize..=6],
        offsets,
        workspace,
        pulley,
    )
        .prop_map(
            |(anchors, attachments, platform, cable, com, reference, offsets, workspace, pulley)| RobotSpec {
                anchors,
                attachments,
                platform_weight_n: platform,
                cable_weight_n_per_m: cable,
                com_offset_m: com,
                reference_cable: reference,
                length_offsets_m: offsets,
                workspace: workspace.resolve(&anchors),
                pulley_radius_m: pulley,
            },
        )
}

// ---------------------------------------------------------------------------
// Data: simulated once per run from the built-in robots, then damaged per case

/// Measurement files simulated once per test run: `(robot file text, csv text)`.
struct Pool {
    _dir: tempfile::TempDir,
    /// Data of the large robot (35 poses, authors' noise), its truth, and its calibrated robot.
    large: (String, String),
    /// Data of the small robot (20 poses, paper noise) and its truth.
    small: (String, String),
}

fn pool() -> &'static Pool {
    static POOL: OnceLock<Pool> = OnceLock::new();
    POOL.get_or_init(|| {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let make = |name: &str, poses: &str, noise: &str, seed: &str| {
            let robot = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("robots/{name}.toml"));
            let out = dir.path().join(format!("{name}.csv"));
            let truth = dir.path().join(format!("{name}-truth.toml"));
            let status = Command::new(binary())
                .args(["simulate", "--robot"])
                .arg(&robot)
                .args(["--poses", poses, "--noise", noise, "--seed", seed, "--out"])
                .arg(&out)
                .arg("--truth")
                .arg(&truth)
                .output()
                .expect("the binary runs");
            assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
            (
                std::fs::read_to_string(&truth).unwrap(),
                std::fs::read_to_string(&out).unwrap(),
            )
        };
        Pool {
            large: make("large", "35", "authors", "5"),
            small: make("small", "20", "paper", "6"),
            _dir: dir,
        }
    })
}

/// One way of damaging a measurement file.
#[derive(Debug, Clone)]
enum Damage {
    None,
    /// One field of one data row set to a value.
    Field {
        row: usize,
        column: usize,
        value: f64,
    },
    /// Every data row written twice.
    Duplicated,
    /// Every length and position in millimetres.
    Millimetres,
    /// Every number of one row in double quotes.
    Quoted {
        row: usize,
    },
    /// Only the first `keep` rows.
    Truncated {
        keep: usize,
    },
}

fn damage() -> impl Strategy<Value = Damage> {
    let extreme = prop_oneof![
        Just(0.0),
        Just(-1.0),
        Just(1e6),
        Just(1e300),
        Just(-1e300),
        Just(400.0),
        Just(1e-300),
        -1e4..1e4f64
    ];
    prop_oneof![
        4 => Just(Damage::None),
        3 => (0usize..40, 0usize..11, extreme).prop_map(|(row, column, value)| Damage::Field { row, column, value }),
        1 => Just(Damage::Duplicated),
        1 => Just(Damage::Millimetres),
        1 => (0usize..40).prop_map(|row| Damage::Quoted { row }),
        1 => (0usize..12).prop_map(|keep| Damage::Truncated { keep }),
    ]
}

/// `csv` with `damage` applied (comment lines and the header kept).
fn damaged(csv: &str, damage: &Damage) -> String {
    let lines: Vec<&str> = csv.lines().collect();
    let header_at = lines.iter().position(|l| !l.starts_with('#')).unwrap_or(0);
    let (head, rows) = lines.split_at(header_at + 1);
    let rows: Vec<String> = match damage {
        Damage::None => rows.iter().map(|r| r.to_string()).collect(),
        Damage::Field { row, column, value } => rows
            .iter()
            .enumerate()
            .map(|(k, r)| {
                if k != row % rows.len() {
                    return r.to_string();
                }
                let mut cells: Vec<String> = r.split(',').map(str::to_string).collect();
                let c = column % cells.len();
                cells[c] = format!("{value:?}");
                cells.join(",")
            })
            .collect(),
        Damage::Duplicated => rows.iter().chain(rows.iter()).map(|r| r.to_string()).collect(),
        Damage::Millimetres => rows
            .iter()
            .map(|r| {
                r.split(',')
                    .enumerate()
                    .map(|(c, x)| match x.parse::<f64>() {
                        Ok(v) if c < 3 || (6..10).contains(&c) => format!("{:?}", v * 1000.0),
                        _ => x.to_string(),
                    })
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect(),
        Damage::Quoted { row } => rows
            .iter()
            .enumerate()
            .map(|(k, r)| {
                if k == row % rows.len() {
                    r.split(',').map(|x| format!("\"{x}\"")).collect::<Vec<_>>().join(",")
                } else {
                    r.to_string()
                }
            })
            .collect(),
        Damage::Truncated { keep } => rows.iter().take(*keep).map(|r| r.to_string()).collect(),
    };
    let mut text = head.join("\n") + "\n";
    for r in rows {
        text += &r;
        text += "\n";
    }
    text
}

// ---------------------------------------------------------------------------
// Commands

/// The commands the property runs.
#[derive(Debug, Clone)]
enum Job {
    Simulate {
        robot: RobotSpec,
        poses: usize,
        seed: u64,
        noise: &'static str,
        closure: &'static str,
        effect: Option<String>,
    },
    Plan {
        robot: RobotSpec,
        poses: usize,
        candidates: usize,
        seed: u64,
        workspace: Option<[f64; 6]>,
        plot: bool,
    },
    Calibrate {
        small: bool,
        /// Anchors of the guess moved by up to this many metres.
        guess_error_m: f64,
        guess_seed: u64,
        damage: Damage,
        sigmas: Option<(f64, f64, f64)>,
        robust: bool,
    },
    Localize {
        small: bool,
        /// Use a random robot instead of the data's.
        robot: Option<RobotSpec>,
        damage: Damage,
        readings_only: bool,
    },
    Verify {
        /// Use a random robot instead of the data's.
        robot: Option<RobotSpec>,
        small: bool,
        damage: Damage,
    },
}

fn noise() -> impl Strategy<Value = &'static str> {
    prop_oneof![Just("paper"), Just("authors"), Just("none")]
}

fn effect() -> impl Strategy<Value = Option<String>> {
    proptest::option::weighted(
        0.2,
        prop_oneof![
            log_uniform(1e2, 1e9).prop_map(|ea| format!("elastic:ea_n={ea:e}")),
            log_uniform(1e-3, 10.0).prop_map(|r| format!("pulley:radius_m={r}")),
            (0.9..1.1f64).prop_map(|g| format!("encoder-scale:gain={g}")),
            (-50.0..50.0f64, 0.5..1.5f64).prop_map(|(b, g)| format!("loadcell:bias_n={b},gain={g}")),
        ],
    )
}

fn job() -> impl Strategy<Value = Job> {
    let simulate = (
        robot(),
        0usize..4,
        any::<u64>(),
        noise(),
        prop_oneof![Just("level"), Just("yaw"), Just("mixed")],
        effect(),
    )
        .prop_map(|(robot, poses, seed, noise, closure, effect)| Job::Simulate {
            robot,
            poses,
            seed,
            noise,
            closure,
            effect,
        });
    let box6 = (
        proptest::array::uniform3(-300.0..300.0f64),
        proptest::array::uniform3(-5.0..100.0f64),
    )
        .prop_map(|(min, size)| {
            [
                min[0],
                min[0] + size[0],
                min[1],
                min[1] + size[1],
                min[2],
                min[2] + size[2],
            ]
        });
    let plan = (
        robot(),
        prop_oneof![1 => Just(0usize), 6 => 1usize..9],
        prop_oneof![1 => 0usize..4, 4 => 4usize..16],
        any::<u64>(),
        proptest::option::weighted(0.3, box6),
        proptest::bool::weighted(0.1),
    )
        .prop_map(|(robot, poses, candidates, seed, workspace, plot)| Job::Plan {
            robot,
            poses,
            candidates,
            seed,
            workspace,
            plot,
        });
    let sigmas = proptest::option::weighted(
        0.2,
        (
            log_uniform(1e-300, 1e300),
            log_uniform(1e-300, 1e300),
            log_uniform(1e-300, 1e300),
        ),
    );
    let calibrate = (
        any::<bool>(),
        log_uniform(0.01, 30.0),
        any::<u64>(),
        damage(),
        sigmas,
        proptest::bool::weighted(0.2),
    )
        .prop_map(
            |(small, guess_error_m, guess_seed, damage, sigmas, robust)| Job::Calibrate {
                small,
                guess_error_m,
                guess_seed,
                damage,
                sigmas,
                robust,
            },
        );
    let localize = (
        any::<bool>(),
        proptest::option::weighted(0.3, robot()),
        damage(),
        any::<bool>(),
    )
        .prop_map(|(small, robot, damage, readings_only)| Job::Localize {
            small,
            robot,
            damage,
            readings_only,
        });
    let verify = (proptest::option::weighted(0.5, robot()), any::<bool>(), damage())
        .prop_map(|(robot, small, damage)| Job::Verify { robot, small, damage });
    prop_oneof![3 => simulate, 3 => plan, 2 => calibrate, 2 => localize, 2 => verify]
}

/// A command ready to run: its arguments, its inputs (written before), its outputs
/// (must not exist after a failure) and its work budget in steps.
struct Prepared {
    args: Vec<String>,
    inputs: BTreeMap<String, String>,
    outputs: Vec<String>,
    budget_steps: u64,
}

/// The most steps one drawn pose may take: the costliest single draw seen
/// (a level solve whose reference-tension scan runs to its end, then the
/// plan's stability test) takes about 200 000 evaluations of the statics.
const STEPS_PER_DRAW: u64 = 250_000;

/// The most steps one calibration pose, localised row or verified row may
/// take (measured: about 200 per calibration pose with its gross-error refits,
/// 6 000 per row of a localisation's multistart search, 50 per verified row).
const STEPS_PER_ROW: u64 = 100_000;

/// The most steps one pose's start may take in one fit of a calibration:
/// its statics solved from the guess (measured: about 54 000 evaluations per
/// pose per fit with an encoder reading 14 m off).
const STEPS_PER_POSE_START: u64 = 150_000;

/// A calibration of `rows` rows: the first fit and one refit per reading the
/// gross-error search leaves out (at most 5 % of the 11 readings of a row,
/// `calib::gross_errors::GrossErrorOptions::max_excluded_fraction`), each
/// fit starting every pose once.
fn calibration_budget(rows: u64) -> u64 {
    let refits = rows * 11 / 20 + 2;
    refits * (rows + 1) * STEPS_PER_POSE_START
}

/// Draws the pose sampler makes at most for `poses` poses
/// (`sim::closed_form::sample_equilibria_with`: `100 count + 1000`).
fn sampler_draws(poses: usize) -> u64 {
    100 * poses as u64 + 1000
}

/// Draws a plan makes at most for `candidates` candidates: each candidate
/// draws positions until one is kept, at most
/// `sim::closed_form::FIRST_DRAWS` = 1000 in all
/// (`experiments::plan_candidates::draw_candidates`). (A budget of 50 draws
/// per candidate, the attempts' count, was exceeded by a box where
/// equilibria are rare: a candidate's first attempt drew 1000 positions.)
fn plan_draws(candidates: usize) -> u64 {
    1000 * candidates as u64
}

/// Command-line words from one line (no argument here holds a space).
fn words(line: &str) -> Vec<String> {
    line.split_whitespace().map(str::to_string).collect()
}

/// The readings-only columns of a measurement file (the four lengths and the load cell).
fn readings_only(csv: &str) -> String {
    let mut out = String::new();
    let mut header: Option<Vec<String>> = None;
    for line in csv.lines().filter(|l| !l.starts_with('#')) {
        let cells: Vec<&str> = line.split(',').collect();
        match &header {
            None => {
                header = Some(cells.iter().map(|c| c.to_string()).collect());
                out += "l1_m,l2_m,l3_m,l4_m,f_ref_n\n";
            }
            Some(h) => {
                let pick = |name: &str| h.iter().position(|c| c == name).and_then(|k| cells.get(k)).copied();
                let values: Vec<&str> = ["l1_m", "l2_m", "l3_m", "l4_m", "f_ref_n"]
                    .iter()
                    .map(|n| pick(n).unwrap_or(""))
                    .collect();
                out += &values.join(",");
                out += "\n";
            }
        }
    }
    out
}

/// The guess of a calibration: the truth's anchors moved at random by up to `error_m`, offsets zero.
fn guess_of(truth: &str, error_m: f64, seed: u64) -> String {
    let mut rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[(seed % 251) as u8; 32]);
    let mut out = String::new();
    for line in truth.lines() {
        if line.starts_with("length_offsets_m") || line.starts_with('#') {
            continue;
        }
        if let Some(rest) = line.strip_prefix("anchor_m = [") {
            let coords: Vec<f64> = rest
                .trim_end_matches(']')
                .split(',')
                .map(|x| x.trim().parse::<f64>().unwrap())
                .collect();
            let moved: Vec<String> = coords
                .iter()
                .map(|c| format!("{:?}", c + error_m * (2.0 * rng.random::<f64>() - 1.0)))
                .collect();
            out += &format!("anchor_m = [{}]\n", moved.join(", "));
        } else {
            out += line;
            out += "\n";
        }
    }
    out
}

fn prepare(job: &Job) -> Prepared {
    let pool = pool();
    let mut inputs = BTreeMap::new();
    let (args, outputs, budget_steps): (Vec<String>, Vec<String>, u64) = match job {
        Job::Simulate {
            robot,
            poses,
            seed,
            noise,
            closure,
            effect,
        } => {
            inputs.insert("robot.toml".into(), robot.toml());
            let mut args: Vec<String> = words(&format!("simulate --robot robot.toml --poses {poses} --seed {seed} --noise {noise} --closure {closure} --out m.csv --truth t.toml"));
            if let Some(effect) = effect {
                args.extend(["--effect".into(), effect.clone(), "--segments".into(), "20".into()]);
            }
            // The discretised simulator's settling adds a few steps per pose.
            let budget = sampler_draws(*poses) * STEPS_PER_DRAW;
            (args, vec!["m.csv".into(), "t.toml".into()], budget)
        }
        Job::Plan {
            robot,
            poses,
            candidates,
            seed,
            workspace,
            plot,
        } => {
            inputs.insert("robot.toml".into(), robot.toml());
            let mut args: Vec<String> = words(&format!(
                "plan --robot robot.toml --poses {poses} --candidates {candidates} --seed {seed} --out plan.csv --json"
            ));
            if let Some(w) = workspace {
                let text: Vec<String> = w.iter().map(|x| format!("{x}")).collect();
                args.push(format!("--workspace={}", text.join(",")));
            }
            let mut outputs = vec!["plan.csv".to_string()];
            if *plot {
                args.extend(["--plot".into(), "plan.svg".into()]);
                outputs.push("plan.svg".into());
            }
            // Drawing, then each candidate's information and the design's scans.
            let budget = plan_draws(*candidates) * STEPS_PER_DRAW + (*candidates as u64 + 1) * STEPS_PER_ROW;
            (args, outputs, budget)
        }
        Job::Calibrate {
            small,
            guess_error_m,
            guess_seed,
            damage,
            sigmas,
            robust,
        } => {
            let (truth, csv) = if *small { &pool.small } else { &pool.large };
            inputs.insert("guess.toml".into(), guess_of(truth, *guess_error_m, *guess_seed));
            inputs.insert("m.csv".into(), damaged(csv, damage));
            let mut args: Vec<String> = words("calibrate --robot guess.toml --data m.csv --out c.toml --json");
            if let Some((e, p, f)) = sigmas {
                args.extend([
                    format!("--encoder-sigma-m={e:e}"),
                    format!("--position-sigma-m={p:e}"),
                    format!("--load-cell-sigma-n={f:e}"),
                ]);
            }
            if *robust {
                args.extend(["--robust-encoder".into(), "huber".into()]);
            }
            let rows = inputs["m.csv"].lines().count() as u64;
            (args, vec!["c.toml".into()], calibration_budget(rows))
        }
        Job::Localize {
            small,
            robot,
            damage,
            readings_only: only,
        } => {
            let (truth, csv) = if *small { &pool.small } else { &pool.large };
            let robot_text = robot.as_ref().map_or_else(|| truth.clone(), RobotSpec::toml);
            inputs.insert("robot.toml".into(), robot_text);
            // A few rows only: each row's multistart search is the expensive part.
            let few = damaged(&damaged(csv, &Damage::Truncated { keep: 3 }), damage);
            let data = if *only { readings_only(&few) } else { few };
            inputs.insert("r.csv".into(), data);
            let args = words("localize --robot robot.toml --data r.csv --json --out lo.csv");
            let rows = inputs["r.csv"].lines().count() as u64;
            (args, vec!["lo.csv".into()], (rows + 1) * STEPS_PER_ROW)
        }
        Job::Verify { robot, small, damage } => {
            let (truth, csv) = if *small { &pool.small } else { &pool.large };
            let robot_text = robot.as_ref().map_or_else(|| truth.clone(), RobotSpec::toml);
            inputs.insert("robot.toml".into(), robot_text);
            inputs.insert("m.csv".into(), damaged(csv, damage));
            let args = words("verify --robot robot.toml --data m.csv --json");
            let rows = inputs["m.csv"].lines().count() as u64;
            (args, vec![], (rows + 1) * STEPS_PER_ROW)
        }
    };
    Prepared {
        args,
        inputs,
        outputs,
        budget_steps,
    }
}

// ---------------------------------------------------------------------------
// Running and checking

/// What one run did.
struct Outcome {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    steps: Option<u64>,
    elapsed: Duration,
}

fn run(dir: &Path, args: &[String]) -> Outcome {
    let start = Instant::now();
    let mut child = Command::new(binary())
        .args(args)
        .current_dir(dir)
        .env("SAGCAL_REPORT_STEPS", "1")
        .env("RUST_BACKTRACE", "0")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the binary starts");
    // Read the pipes on threads so a chatty command cannot block on a full pipe.
    let mut out_pipe = child.stdout.take().unwrap();
    let mut err_pipe = child.stderr.take().unwrap();
    let out_thread = std::thread::spawn(move || {
        let mut s = Vec::new();
        std::io::Read::read_to_end(&mut out_pipe, &mut s).ok();
        s
    });
    let err_thread = std::thread::spawn(move || {
        let mut s = Vec::new();
        std::io::Read::read_to_end(&mut err_pipe, &mut s).ok();
        s
    });
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break Some(status);
        }
        if start.elapsed() > SAFETY_TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stdout = String::from_utf8_lossy(&out_thread.join().unwrap()).to_string();
    let stderr = String::from_utf8_lossy(&err_thread.join().unwrap()).to_string();
    let steps = stderr
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("sagcal steps: "))
        .and_then(|s| s.trim().parse().ok());
    Outcome {
        code: status.and_then(|s| s.code()),
        stdout,
        stderr,
        steps,
        elapsed: start.elapsed(),
    }
}

/// Every number in a JSON value is finite (serde_json writes NaN as null; a
/// `null` where a number belongs is accepted, because reports use it for "none").
fn json_is_sane(text: &str) -> Result<serde_json::Value, String> {
    serde_json::from_str(text).map_err(|e| format!("stdout is not JSON: {e}"))
}

/// The consistency test of an exit-0 answer.
fn check_answer(job: &Job, dir: &Path, outcome: &Outcome) -> Result<(), String> {
    match job {
        Job::Simulate {
            robot,
            poses,
            noise,
            effect,
            ..
        } => {
            let rows = sagcal::io::measurements::read_measurements(
                &dir.join("m.csv"),
                &sagcal::io::measurements::ReadOptions::default(),
            )
            .map_err(|e| format!("the simulated file does not load: {e}"))?
            .poses
            .len();
            sagcal::model::Robot::from_file(&dir.join("t.toml"))
                .map_err(|e| format!("the truth does not load: {e}"))?;
            if rows != *poses {
                return Err(format!("{rows} rows written, {poses} asked for"));
            }
            // Noise-free closed-form data are the model itself: `verify` must
            // agree to rounding. A pulley in the robot file's `[effects]` sends
            // the simulation through the discretised simulator (100 elements
            // per cable), whose lengths differ from the catenary's by a term
            // of order 1/n^2 = 1e-4 of the sag's share: 0.01 % bounds it (the
            // property test found 0.0017 % for cables three times as heavy as
            // the platform).
            let tolerance_pct = if robot.pulley_radius_m.is_some() { 1e-2 } else { 1e-4 };
            if *noise == "none" && effect.is_none() && rows > 0 {
                let args: Vec<String> = words("verify --robot t.toml --data m.csv --json");
                let verified = run(dir, &args);
                let report = json_is_sane(&verified.stdout)
                    .map_err(|e| format!("verify of the noise-free data failed: {e}: {}", verified.stderr))?;
                let mpe = report["mpe_length_pct"].as_f64().unwrap_or(f64::NAN);
                if mpe.is_nan() || mpe >= tolerance_pct {
                    return Err(format!("verify of its own noise-free data gives MPE-L {mpe} %"));
                }
            }
            Ok(())
        }
        Job::Plan { poses, .. } => {
            let report = json_is_sane(&outcome.stdout)?;
            let bound = report["anchor_bound_m"].as_f64().unwrap_or(f64::NAN);
            if !(bound.is_finite() && bound > 0.0) {
                return Err(format!("the plan's anchor bound is {bound} m"));
            }
            let text = std::fs::read_to_string(dir.join("plan.csv")).map_err(|e| format!("no plan.csv: {e}"))?;
            let rows = text.lines().filter(|l| !l.starts_with('#')).count().saturating_sub(1);
            if rows != *poses {
                return Err(format!("plan.csv has {rows} poses, {poses} asked for"));
            }
            Ok(())
        }
        Job::Calibrate { .. } => {
            let report = json_is_sane(&outcome.stdout)?;
            let verdict = report["gross_errors"]["verdict"]["verdict"].as_str().unwrap_or("");
            if verdict != "consistent" {
                return Err(format!("exit 0 with verdict `{verdict}`"));
            }
            let robot = sagcal::model::Robot::from_file(&dir.join("c.toml"))
                .map_err(|e| format!("the calibrated robot does not load: {e}"))?;
            for sigma in report["anchor_sigma_m"].as_array().into_iter().flatten() {
                for s in sigma.as_array().into_iter().flatten() {
                    let s = s.as_f64().unwrap_or(f64::NAN);
                    // A 1-sigma larger than the robot itself means the data did not move the guess.
                    let size = robot.anchors_m.iter().map(|a| a.norm()).fold(0.0, f64::max);
                    if !(s.is_finite() && s < size) {
                        return Err(format!(
                            "exit 0 with an anchor 1-sigma of {s} m (robot size {size:.1} m)"
                        ));
                    }
                }
            }
            Ok(())
        }
        Job::Localize { .. } => {
            let report = json_is_sane(&outcome.stdout)?;
            let robot = sagcal::model::Robot::from_file(&dir.join("robot.toml")).map_err(|e| e.to_string())?;
            let top = robot.anchors_m.iter().map(|a| a.z).fold(f64::INFINITY, f64::min);
            let (lo, hi) = robot
                .anchors_m
                .iter()
                .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), a| {
                    ([lo[0].min(a.x), lo[1].min(a.y)], [hi[0].max(a.x), hi[1].max(a.y)])
                });
            for row in report["rows"].as_array().into_iter().flatten() {
                let ok = row["flag"].is_null() && row["consistent"].as_bool().unwrap_or(false);
                if !ok {
                    continue;
                }
                let p: Vec<f64> = row["position_m"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .map(|v| v.as_f64().unwrap_or(f64::NAN))
                    .collect();
                if p.len() != 3 || p.iter().any(|x| !x.is_finite()) {
                    return Err(format!("row {} ok with position {p:?}", row["row"]));
                }
                let inside = p[2] < top && p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1];
                if !inside {
                    return Err(format!(
                        "row {} called ok at {p:?}, outside the anchors' frame (x {:.1}..{:.1}, y {:.1}..{:.1}, below z {top:.1})",
                        row["row"], lo[0], hi[0], lo[1], hi[1]
                    ));
                }
            }
            Ok(())
        }
        Job::Verify { .. } => {
            let report = json_is_sane(&outcome.stdout)?;
            let kept = report["rows_kept"].as_u64().unwrap_or(0);
            let solved = report["rows"].as_array().map_or(0, |r| r.len());
            if kept == 0 || solved == 0 {
                return Err(format!("exit 0 with {kept} rows kept and {solved} verified"));
            }
            Ok(())
        }
    }
}

/// The job's command name, for the tally.
fn kind(job: &Job) -> &'static str {
    match job {
        Job::Simulate { .. } => "simulate",
        Job::Plan { .. } => "plan",
        Job::Calibrate { .. } => "calibrate",
        Job::Localize { .. } => "localize",
        Job::Verify { .. } => "verify",
    }
}

/// Cases run per command and exit code.
static TALLY: std::sync::Mutex<BTreeMap<(&'static str, Option<i32>), usize>> = std::sync::Mutex::new(BTreeMap::new());

/// Run one case and check every property; the failure's description, if any.
fn check(job: &Job) -> Result<(), String> {
    let prepared = prepare(job);
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (name, text) in &prepared.inputs {
        std::fs::write(dir.path().join(name), text).expect("an input is written");
    }
    if let (Ok(_), Some(keep)) = (
        std::env::var("SAGCAL_PROPERTY_ONLY"),
        std::env::var_os("SAGCAL_PROPERTY_COLLECT"),
    ) {
        // The one case being reproduced: keep its inputs and command.
        let keep = PathBuf::from(keep).join("inputs");
        std::fs::create_dir_all(&keep).ok();
        for (name, text) in &prepared.inputs {
            std::fs::write(keep.join(name), text).ok();
        }
        std::fs::write(keep.join("command.txt"), prepared.args.join(" ")).ok();
    }
    let outcome = run(dir.path(), &prepared.args);
    *TALLY.lock().unwrap().entry((kind(job), outcome.code)).or_default() += 1;
    if let Some(dir) = std::env::var_os("SAGCAL_PROPERTY_COLLECT") {
        // Every message, for a tally of what the commands refused and why.
        let first = outcome.stderr.lines().find(|l| l.starts_with("error")).unwrap_or("-");
        let line = format!("{}\t{:?}\t{first}\n", kind(job), outcome.code);
        std::fs::create_dir_all(&dir).ok();
        let log = std::path::Path::new(&dir).join("messages.tsv");
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(log)
            .expect("the log opens");
        std::io::Write::write_all(&mut file, line.as_bytes()).ok();
    }
    let command = format!("sagcal {}", prepared.args.join(" "));
    let fail = |what: String| {
        Err(format!(
            "{what}\n  command: {command}\n  exit: {:?}, steps: {:?}, {:.1} s\n  stderr: {}",
            outcome.code,
            outcome.steps,
            outcome.elapsed.as_secs_f64(),
            outcome.stderr.lines().take(6).collect::<Vec<_>>().join("\n          ")
        ))
    };
    let Some(code) = outcome.code else {
        return fail(format!(
            "no exit code: killed after {:?} or by a signal",
            SAFETY_TIMEOUT
        ));
    };
    if !(0..=2).contains(&code) || outcome.stderr.contains("panicked") {
        return fail("a panic or an unexpected exit code".into());
    }
    match outcome.steps {
        Some(steps) if steps <= prepared.budget_steps => {}
        steps => {
            return fail(format!(
                "work over its budget of {} steps: {steps:?}",
                prepared.budget_steps
            ))
        }
    }
    for (name, text) in &prepared.inputs {
        let now = std::fs::read_to_string(dir.path().join(name)).unwrap_or_default();
        if &now != text {
            return fail(format!("the input {name} changed"));
        }
    }
    if code != 0 {
        if !outcome.stderr.contains("error") {
            return fail("a non-zero exit without an error message".into());
        }
        if let Some(left) = prepared.outputs.iter().find(|o| dir.path().join(o).exists()) {
            return fail(format!("a non-zero exit left the output {left}"));
        }
        return Ok(());
    }
    if let Err(what) = check_answer(job, dir.path(), &outcome) {
        return fail(format!("exit 0 with an answer that fails its own test: {what}"));
    }
    Ok(())
}

#[test]
fn no_command_panics_hangs_loses_an_input_or_exits_zero_unchecked() {
    let cases: u32 = std::env::var("SAGCAL_PROPERTY_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(DEFAULT_CASES);
    let seed: u64 = std::env::var("SAGCAL_PROPERTY_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_261_126);
    let collect = std::env::var_os("SAGCAL_PROPERTY_COLLECT").map(PathBuf::from);
    let only: Option<usize> = std::env::var("SAGCAL_PROPERTY_ONLY").ok().and_then(|s| s.parse().ok());
    println!("property seed {seed}, {cases} cases, binary {}", binary().display());
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases,
            max_shrink_iters: if collect.is_some() { 0 } else { 16 },
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes),
    );
    let counter = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::atomic::AtomicUsize::new(0);
    let result = runner.run(&job(), |job| {
        let n = counter.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if only.is_some_and(|only| only != n) {
            return Ok(());
        }
        match (check(&job), &collect) {
            (Ok(()), _) => Ok(()),
            (Err(what), Some(dir)) => {
                failures.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                std::fs::create_dir_all(dir).ok();
                std::fs::write(dir.join(format!("case-{n:06}.txt")), format!("{what}\n\n{job:#?}\n")).ok();
                Ok(())
            }
            (Err(what), None) => Err(TestCaseError::fail(what)),
        }
    });
    println!(
        "{} cases run, {} failures collected",
        counter.load(std::sync::atomic::Ordering::Relaxed),
        failures.load(std::sync::atomic::Ordering::Relaxed)
    );
    for ((command, code), count) in TALLY.lock().unwrap().iter() {
        println!("  {command:<10} exit {code:?}: {count}");
    }
    if let Err(e) = result {
        panic!("{e}");
    }
}

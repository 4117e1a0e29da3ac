//! The README's numbers come from the commands printed beside them. Each
//! example here runs as the README prints it; every number the README quotes
//! is formatted from the command's own output and looked for in the README,
//! so a change of either fails this test until the README says what the
//! command says.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sagcal::model::Robot;

/// The repository's root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md with every run of white space one space (a phrase may wrap).
fn readme() -> String {
    let text = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Fail unless the README says `phrase` (white space as one space).
fn says(readme: &str, phrase: &str) {
    assert!(
        readme.contains(phrase),
        "README.md does not say `{phrase}`, which is what the command printed beside it gives"
    );
}

/// Run `sagcal ARGS` in `dir`; `robots/` names the repository's robots.
fn sagcal(dir: &Path, args: &[&str]) -> Output {
    let robots = root().join("robots");
    let args: Vec<String> = args
        .iter()
        .map(|a| match a.strip_prefix("robots/") {
            Some(file) => robots.join(file).to_string_lossy().into_owned(),
            None => a.to_string(),
        })
        .collect();
    Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(&args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

/// Stdout of a command that must succeed.
fn stdout(out: &Output) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The README's example commands that start with `sagcal <job>`, as printed.
fn example(readme: &str, job: &str) -> Vec<String> {
    let start = format!("sagcal {job} ");
    let mut found = Vec::new();
    let mut rest = readme;
    while let Some(at) = rest.find(&start) {
        let command = &rest[at..];
        // A command ends where the next one starts or the code block closes.
        let end = [command[1..].find(" sagcal ").map(|e| e + 1), command.find(" ```")]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(command.len());
        found.push(command[..end].trim().to_string());
        rest = &command[start.len()..];
    }
    found
}

/// The example command of `job` whose words include every one of `words`.
fn command_with(readme: &str, job: &str, words: &[&str]) -> Vec<String> {
    let command = example(readme, job)
        .into_iter()
        .find(|c| words.iter().all(|w| c.split(' ').any(|x| x == *w)))
        .unwrap_or_else(|| panic!("README.md has no `sagcal {job}` example with {words:?}"));
    command.split(' ').skip(1).map(str::to_string).collect()
}

fn args(words: &[String]) -> Vec<&str> {
    words.iter().map(String::as_str).collect()
}

#[test]
fn the_diagnose_example_says_what_diagnose_prints() {
    let readme = readme();
    let dir = tempfile::tempdir().unwrap();
    let simulate = command_with(&readme, "simulate", &["elastic:axial_stiffness_n=3e6"]);
    stdout(&sagcal(dir.path(), &args(&simulate)));
    let mut diagnose = command_with(&readme, "diagnose", &["el.csv"]);
    diagnose.push("--json".into());
    let report: serde_json::Value = serde_json::from_str(&stdout(&sagcal(dir.path(), &args(&diagnose)))).unwrap();
    let number = |pointer: &str| {
        report
            .pointer(pointer)
            .and_then(serde_json::Value::as_f64)
            .unwrap_or_else(|| panic!("no number at {pointer}"))
    };

    let encoders = &report["factor_tests"][0];
    assert_eq!(encoders["kind"], "catenary_length");
    says(
        &readme,
        &format!(
            "encoder chi-square is {:.0} for an expected {:.0}",
            number("/factor_tests/0/chi_square"),
            number("/factor_tests/0/expected")
        ),
    );
    let step = &report["steps"][0];
    assert_eq!(step["added"], "elastic");
    says(
        &readme,
        &format!(
            "elastic has likelihood ratio {:.0} on {} degree of freedom (p = {:.0e} against a threshold of {:e})",
            number("/steps/0/lr_statistic"),
            step["added_parameters"],
            number("/steps/0/p_value"),
            number("/steps/0/p_threshold")
        ),
    );
    assert_eq!(report["effects"][0]["params"][0]["name"], "compliance_per_mn");
    says(
        &readme,
        &format!(
            "compliance is {:.3} +- {:.3} /MN",
            number("/effects/0/params/0/value"),
            number("/effects/0/params/0/sigma")
        ),
    );
    says(
        &readme,
        &format!(
            "chi-square is {:.1} for {} degrees of freedom",
            number("/final_chi_square"),
            report["final_dof"]
        ),
    );
    assert_eq!(report["verdict"], "elastic");
    assert_eq!(report["explained"], true);
    says(
        &readme,
        &format!(
            "held-out residual RMS falls from {:.2} to {:.2}, the anchor MAE from {:.3} m to {:.3} m, and the offset MAE from {:.3} m to {:.3} m",
            number("/gain/residual_rms_before"),
            number("/gain/residual_rms_after"),
            number("/gain/anchor_mae_before_m"),
            number("/gain/anchor_mae_after_m"),
            number("/gain/offset_mae_before_m"),
            number("/gain/offset_mae_after_m")
        ),
    );
    // `pulley (power 0.00)`: the README says the name and its power.
    for undetectable in report["undetectable"].as_array().unwrap() {
        let text = undetectable.as_str().unwrap();
        let (name, power) = text.split_once(" (power ").unwrap();
        let power = power.trim_end_matches(')');
        assert!(
            readme.contains(&format!("{name} (power {power}")) || readme.contains(&format!("{name} ({power}")),
            "README.md does not say {name}'s power {power} ({text})"
        );
    }
}

/// The largest and smallest anchor error of `calibrated` against `truth`, m.
fn anchor_error_range_m(calibrated: &Path, truth: &Path) -> (f64, f64) {
    let calibrated = Robot::from_file(calibrated).unwrap();
    let truth = Robot::from_file(truth).unwrap();
    let errors: Vec<f64> = (0..4)
        .map(|i| (calibrated.anchors_m[i] - truth.anchors_m[i]).norm())
        .collect();
    (
        errors.iter().copied().fold(f64::INFINITY, f64::min),
        errors.iter().copied().fold(0.0, f64::max),
    )
}

/// `data.csv` of the demo with `edit` applied to data row `row` (1-based).
fn edited(demo: &Path, name: &str, edit: impl Fn(usize, Vec<f64>) -> Vec<f64>) -> PathBuf {
    let text = std::fs::read_to_string(demo.join("sagcal-demo/data.csv")).unwrap();
    let mut row = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            if line.starts_with('#') || line.starts_with("x_m") {
                return line.to_string();
            }
            row += 1;
            let values = line.split(',').map(|v| v.parse().unwrap()).collect();
            let values: Vec<String> = edit(row, values).iter().map(|v| format!("{v}")).collect();
            values.join(",")
        })
        .collect();
    let path = demo.join(name);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

#[test]
fn the_calibrate_table_says_what_calibrate_prints() {
    let readme = readme();
    let dir = tempfile::tempdir().unwrap();
    stdout(&sagcal(dir.path(), &["demo"]));
    let truth = dir.path().join("sagcal-demo/truth.toml");
    let calibrate_with = |data: &Path, more: &[&str]| {
        let data = data.to_string_lossy().into_owned();
        let mut words = vec![
            "calibrate",
            "--robot",
            "sagcal-demo/guess.toml",
            "--data",
            &data,
            "--out",
            "c.toml",
        ];
        words.extend_from_slice(more);
        sagcal(dir.path(), &words)
    };
    let calibrate = |data: &Path| calibrate_with(data, &[]);
    let range = |(low, high): (f64, f64)| format!("{low:.2}-{high:.2} m");

    // None.
    let clean = calibrate(&dir.path().join("sagcal-demo/data.csv"));
    assert!(stdout(&clean).contains("verdict: consistent with the stated noise"));
    let errors = anchor_error_range_m(&dir.path().join("c.toml"), &truth);
    says(
        &readme,
        &format!(
            "| none | `verdict: consistent with the stated noise`, exit 0 | {} |",
            range(errors)
        ),
    );

    // One encoder reading 5 m off, row 10 cable 1 (column 7).
    let slipped = edited(dir.path(), "slipped.csv", |row, mut v| {
        if row == 10 {
            v[6] += 5.0;
        }
        v
    });
    let out = stdout(&calibrate(&slipped));
    let named = out
        .lines()
        .find_map(|l| {
            l.find("row 10 (line 12), encoder of cable 1: ")
                .map(|at| l[at..].trim())
        })
        .unwrap_or_else(|| panic!("no reading of row 10 named:\n{out}"));
    let named = named.split(" m off, w = ").collect::<Vec<_>>();
    let w: String = named[1]
        .chars()
        .take_while(|c| !c.is_whitespace() && *c != ';')
        .collect();
    says(
        &readme,
        &format!(
            "`{} m off, w = {}`, left out; exit 0",
            named[0],
            w.trim_end_matches(',')
        ),
    );
    let errors = anchor_error_range_m(&dir.path().join("c.toml"), &truth);
    says(&readme, &format!("left out; exit 0 | {} |", range(errors)));

    // The load cell logged in mN (column 11): refused, nothing written.
    std::fs::remove_file(dir.path().join("c.toml")).unwrap();
    let millinewtons = edited(dir.path(), "mn.csv", |_, mut v| {
        v[10] *= 1000.0;
        v
    });
    let out = calibrate(&millinewtons);
    assert_eq!(out.status.code(), Some(1));
    assert!(!dir.path().join("c.toml").exists());
    let printed = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    let at = printed
        .find("the load cell's readings are ")
        .unwrap_or_else(|| panic!("no load-cell unit named:\n{printed}"));
    let sentence = printed[at..].split(": they look like mN, not N").next().unwrap();
    says(
        &readme,
        &format!("`{sentence}: they look like mN, not N`; exit 1, nothing written"),
    );
    // No switch accepts a unit mistake.
    let out = calibrate_with(&millinewtons, &["--accept-inconsistent"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!dir.path().join("c.toml").exists());
    says(&readme, "| (refused, with `--accept-inconsistent` too) |");
}

/// The README's plan command prints what the library's plan gives (checked
/// on 50 candidates, the command's only difference from
/// [`every_plan_row_says_what_plan_gives`], which checks the table's rows).
#[test]
fn the_plan_command_prints_what_the_library_plans() {
    use sagcal::experiments::pose_plan::{plan_calibration, CandidateSource, PlanSettings};
    let readme = readme();
    let dir = tempfile::tempdir().unwrap();
    let mut plan = command_with(&readme, "plan", &["robots/large.toml", "9", "1"]);
    plan.extend(["--candidates", "50", "--json"].map(String::from));
    let report: serde_json::Value = serde_json::from_str(&stdout(&sagcal(dir.path(), &args(&plan)))).unwrap();
    let large = Robot::from_file(&root().join("robots/large.toml")).unwrap();
    let settings = PlanSettings {
        candidates: CandidateSource::Drawn {
            workspace: None,
            count: 50,
        },
        ..PlanSettings::new(9)
    };
    let planned = plan_calibration(&large, &settings, &mut |_| {}).unwrap().report;
    // Both through the same text: serde_json reads a float to within an ulp.
    let planned: serde_json::Value = serde_json::from_str(&serde_json::to_string(&planned).unwrap()).unwrap();
    assert_eq!(report, planned);
    assert!(dir.path().join("plan.csv").exists() && dir.path().join("plan.svg").exists());
}

/// The plan table's every row and the sentence above it, from the library
/// calls `sagcal plan` makes (`plan_candidates`, then `plan_among` for each
/// noise and criterion: the large robot's 1000 candidates are drawn once
/// for its three rows). Row 1 is also run as the command above.
#[test]
fn every_plan_row_says_what_plan_gives() {
    use sagcal::experiments::pose_plan::{plan_among, plan_candidates, CandidateSource, PlanReport, PlanSettings};
    use sagcal::io::measurements::{read_measurements, ReadOptions};
    use sagcal::model::sensors::NoisePreset;
    use sagcal::plan::Criterion;

    // The table and the sentence stand in the README and in docs/plan.md.
    let plan_page = std::fs::read_to_string(root().join("docs/plan.md")).unwrap();
    let pages = [readme(), plan_page.split_whitespace().collect::<Vec<_>>().join(" ")];
    let says = |phrase: &str| {
        for (page, name) in pages.iter().zip(["README.md", "docs/plan.md"]) {
            assert!(
                page.contains(phrase),
                "{name} should say `{phrase}`, what `sagcal plan` gives"
            );
        }
    };
    let robot = |name: &str| Robot::from_file(&root().join("robots").join(name)).unwrap();
    let row = |label: &str, noise: &str, r: &PlanReport| {
        format!(
            "| {label} | {noise} | {:.3} | {:.3} | {:.3} | {:.0} |",
            r.anchor_bound_m,
            r.random_anchor_bound_m,
            r.random35_anchor_bound_m.expect("35 candidates or more"),
            r.path_length_m
        )
    };
    let settings = |noise, criterion| PlanSettings {
        noise,
        criterion,
        ..PlanSettings::new(9)
    };
    let quiet = &mut |_: sagcal::experiments::pose_plan::PlanProgress<'_>| {};

    let large = robot("large.toml");
    let drawn = plan_candidates(&large, &PlanSettings::new(9), quiet).unwrap();
    for (label, noise, criterion) in [
        ("large, 1000 in the frame", NoisePreset::Paper, Criterion::A),
        ("large, 1000 in the frame, D-optimal", NoisePreset::Paper, Criterion::D),
        ("large, 1000 in the frame", NoisePreset::Authors, Criterion::A),
    ] {
        let planned = plan_among(&large, &settings(noise, criterion), &drawn, quiet).unwrap();
        says(&row(label, &noise.to_string(), &planned.report));
    }

    let small = robot("small.toml");
    let planned = plan_among(
        &small,
        &PlanSettings::new(9),
        &plan_candidates(&small, &PlanSettings::new(9), quiet).unwrap(),
        quiet,
    )
    .unwrap();
    says(&row("small, 1000 in its `[workspace]`", "paper", &planned.report));

    let log = root().join("../shared/data/recurdyn-large/recurdyn_large.csv");
    if !log.exists() {
        println!("skipped the RecurDyn row: {} is absent", log.display());
        return;
    }
    let read = ReadOptions {
        reference_cable: large.reference_cable,
        keep_rounded: false,
    };
    let from = PlanSettings {
        candidates: CandidateSource::Logged {
            poses: read_measurements(&log, &read).unwrap().poses,
            label: log.display().to_string(),
        },
        ..PlanSettings::new(9)
    };
    let planned = plan_among(&large, &from, &plan_candidates(&large, &from, quiet).unwrap(), quiet).unwrap();
    let r = &planned.report;
    says(&row("large, the 57 RecurDyn poses (`--from`)", "paper", r));
    let random35 = r.random35_anchor_bound_m.unwrap();
    says(&format!(
        "the bound of 9 random RecurDyn poses is {:.2} m and of 35 is {:.2} m (RMS per anchor), a factor {:.1} where \
         `sqrt(35/9)` would give 2",
        r.random_anchor_bound_m,
        random35,
        r.random_anchor_bound_m / random35
    ));
}

/// The example of a robot of 3 to 8 cables prints what the README shows.
#[test]
fn the_eight_cable_example_prints_what_the_readme_shows() {
    let readme = readme();
    let command = command_with(&readme, "simulate", &["robots/eight.toml"]);
    let dir = tempfile::tempdir().unwrap();
    let printed = stdout(&sagcal(dir.path(), &args(&command)));
    for line in printed.lines() {
        says(&readme, &line.split_whitespace().collect::<Vec<_>>().join(" "));
    }
    assert!(
        printed.contains("8 cables, load cells on cable 1, cable 5"),
        "{printed}"
    );
    // The calibration of those readings prints the README's lines, and its
    // error (the data come from the file itself) is what the README says.
    let mut calibrate = command_with(&readme, "calibrate", &["robots/eight.toml"]);
    let printed = stdout(&sagcal(dir.path(), &args(&calibrate)));
    let anchor_row = |l: &str| (l.starts_with("1 ") || l.starts_with("8 ")) && l.split_whitespace().count() == 10;
    for line in printed.lines().filter(|l| anchor_row(l) || l.starts_with("chi-square")) {
        says(&readme, &line.split_whitespace().collect::<Vec<_>>().join(" "));
    }
    assert!(dir.path().join("eight-calibrated.toml").exists());
    calibrate.push("--json".into());
    let report: serde_json::Value = serde_json::from_str(&stdout(&sagcal(dir.path(), &args(&calibrate)))).unwrap();
    let mut worst: f64 = 0.0;
    for (change, sigma) in report["anchor_change_m"]
        .as_array()
        .unwrap()
        .iter()
        .zip(report["anchor_sigma_m"].as_array().unwrap())
    {
        for k in 0..3 {
            worst = worst.max(change[k].as_f64().unwrap().abs() / sigma[k].as_f64().unwrap());
        }
    }
    says(
        &readme,
        &format!("within {:.1} of its 1-sigma on every coordinate", worst.ceil_to_tenth()),
    );
}

/// Rounding up to a tenth, as the README states a bound.
trait CeilToTenth {
    fn ceil_to_tenth(self) -> f64;
}

impl CeilToTenth for f64 {
    fn ceil_to_tenth(self) -> f64 {
        (self * 10.0).ceil() / 10.0
    }
}

//! The examples of docs/robot-file.md and docs/measurements.md, read by
//! sagcal's own readers, and the numbers the two pages quote, formatted
//! from what the command printed beside them (or the library) gives and
//! looked for in the page.
//!
//! The pages' fenced blocks follow one convention, checked here:
//!
//! - robot-file.md: ```` ```toml ```` a complete robot file (the first one is
//!   the page's example, `hall.toml`), ```` ```toml fragment ```` keys or
//!   tables added to that example, ```` ```toml rejected ```` a file that must
//!   be refused with the message of the ```` ```text ```` block after it;
//! - measurements.md: ```` ```csv FORMAT ```` with FORMAT `sagcal`,
//!   `readings`, `recurdyn` or `authors FILE` (the `authors` blocks are the
//!   files of one folder), and ```` ```csv FORMAT rejected ````.
//!
//! A block of either language with another info string fails the test, so
//! no example goes unread.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use sagcal::io::measurements::{read_measurements, MeasurementFormat, ReadOptions};
use sagcal::io::readings::{read_readings, ReadingsFormat};
use sagcal::io::robot_file::CalibrationEntry;
use sagcal::model::effect_kind::EffectKind;
use sagcal::model::robot::{PaperRobot, ParameterCovariance};
use sagcal::model::{Effects, PlatformPose};
use sagcal::sim::closed_form::Workspace;

#[path = "common/doc_pages.rs"]
mod doc_pages;
use doc_pages::{
    blocks, keys_of, lines_phrase, load, of_language, option, page, point, quoted_command, root, run_ok, sagcal, says,
    shell_commands, spliced, Block,
};

// ---------------------------------------------------------------- robot files

/// The robot guide's blocks, each toml block's kind checked.
fn robot_blocks() -> Vec<Block> {
    let all = blocks(&page("robot-file.md"));
    for block in of_language(&all, "toml") {
        let kind: Vec<&str> = block.info.iter().map(String::as_str).collect();
        assert!(
            matches!(kind[..], ["toml"] | ["toml", "fragment"] | ["toml", "rejected"]),
            "robot-file.md: a block ```{} is neither toml, toml fragment nor toml rejected",
            kind.join(" ")
        );
    }
    assert!(
        of_language(&all, "csv").is_empty(),
        "robot-file.md: csv examples belong in measurements.md"
    );
    all
}

/// The robot guide's blocks of one kind (`toml`, `toml fragment`, `toml rejected`).
fn toml_blocks<'a>(all: &'a [Block], kind: &str) -> Vec<&'a Block> {
    all.iter().filter(|b| b.info.join(" ") == kind).collect()
}

/// The guide's complete example (`hall.toml`): its first complete toml block.
fn example_text() -> String {
    toml_blocks(&robot_blocks(), "toml")[0].text.clone()
}

#[test]
fn every_robot_example_loads_and_every_fragment_loads_in_the_example() {
    let all = robot_blocks();
    let dir = tempfile::tempdir().unwrap();
    let complete = toml_blocks(&all, "toml");
    let fragments = toml_blocks(&all, "toml fragment");
    assert!(
        !complete.is_empty() && fragments.len() >= 3,
        "the guide shows a complete file and fragments"
    );
    for (k, block) in complete.iter().enumerate() {
        load(dir.path(), &format!("complete-{k}.toml"), &block.text)
            .unwrap_or_else(|e| panic!("complete block {k}: {e}\n{}", block.text));
    }
    for (k, block) in fragments.iter().enumerate() {
        let text = spliced(&complete[0].text, &block.text);
        load(dir.path(), &format!("fragment-{k}.toml"), &text)
            .unwrap_or_else(|e| panic!("fragment {k}: {e}\n{}", block.text));
    }
}

#[test]
fn the_example_reads_as_its_keys_say() {
    let text = example_text();
    let dir = tempfile::tempdir().unwrap();
    let robot = load(dir.path(), "hall.toml", &text).unwrap();
    let file: toml::Table = toml::from_str(&text).unwrap();
    let numbers = |v: &toml::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_float().or(x.as_integer().map(|i| i as f64)).unwrap())
            .collect()
    };
    let cables = file["cables"].as_array().unwrap();
    for (i, cable) in cables.iter().enumerate() {
        assert_eq!(
            robot.anchors_m[i].as_slice(),
            &numbers(&cable["anchor_m"])[..],
            "cable {}",
            i + 1
        );
        assert_eq!(
            robot.attachments_m[i].as_slice(),
            &numbers(&cable["attachment_m"])[..],
            "cable {}",
            i + 1
        );
    }
    assert_eq!(robot.com_offset_m.as_slice(), &numbers(&file["com_offset_m"])[..]);
    assert_eq!(robot.platform_weight_n, file["platform_weight_n"].as_float().unwrap());
    assert_eq!(
        robot.cable_weight_n_per_m,
        file["cable_weight_n_per_m"].as_float().unwrap()
    );
    // The file counts cables from 1, the robot from 0; no offsets: zero; no paper robot.
    let reference = file["reference_cable"].as_integer().unwrap() as usize;
    assert_eq!(robot.reference_cable + 1, reference);
    says("robot-file.md", &format!("the load cell on cable {reference}"));
    assert_eq!(robot.length_offsets_m, [0.0; 4]);
    assert_eq!(robot.paper_robot, None);
    let workspace = robot.workspace.expect("the example has a [workspace]");
    assert_eq!(workspace.min_m.to_vec(), numbers(&file["workspace"]["min_m"]));
    assert_eq!(workspace.max_m.to_vec(), numbers(&file["workspace"]["max_m"]));
}

#[test]
fn a_mistyped_key_in_an_example_fails() {
    // Every key of the example and of every fragment, misspelled one at a
    // time, is refused by name: a typing mistake in the guide fails the test.
    let all = robot_blocks();
    let base = toml_blocks(&all, "toml")[0].text.clone();
    let dir = tempfile::tempdir().unwrap();
    let mut checked = 0;
    let mut texts = vec![base.clone()];
    texts.extend(
        toml_blocks(&all, "toml fragment")
            .iter()
            .map(|b| spliced(&base, &b.text)),
    );
    for text in &texts {
        for key in keys_of(text) {
            let typo = format!("{key}x");
            let mut done = false;
            let bad: String = text
                .lines()
                .map(|l| match l.trim_start().strip_prefix(&format!("{key} = ")) {
                    Some(value) if !done => {
                        done = true;
                        format!("{typo} = {value}\n")
                    }
                    _ => format!("{l}\n"),
                })
                .collect();
            let message = load(dir.path(), "typo.toml", &bad).unwrap_err().to_string();
            assert!(message.contains(&format!("unknown field `{typo}`")), "{key}: {message}");
            checked += 1;
        }
    }
    assert!(checked >= 30, "{checked} keys checked");
}

#[test]
fn every_rejected_example_is_refused_with_the_message_shown() {
    let all = robot_blocks();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("hall.toml"), example_text()).unwrap();
    let mut refused = 0;
    for (k, block) in all.iter().enumerate() {
        if block.info.join(" ") != "toml rejected" {
            continue;
        }
        assert!(
            load(dir.path(), "rejected.toml", &block.text).is_err(),
            "{}",
            block.text
        );
        let shown = all[k + 1..]
            .iter()
            .find(|b| b.info == ["text"])
            .expect("the message under it");
        let command = quoted_command(&format!("{}{}", block.before, shown.before));
        std::fs::write(dir.path().join(option(&command, "--robot")), &block.text).unwrap();
        let words: Vec<&str> = command.split_whitespace().skip(1).collect();
        let out = sagcal(dir.path(), &words);
        assert_eq!(out.status.code(), Some(1), "{command}");
        assert_eq!(
            String::from_utf8_lossy(&out.stderr).trim_end(),
            shown.text.trim_end(),
            "{command}"
        );
        refused += 1;
    }
    assert!(refused >= 2, "the guide shows refused files");
}

/// Every key the reader knows, as `table.key`: a file with every optional
/// part, written by sagcal itself.
fn keys_sagcal_reads() -> BTreeSet<String> {
    let dir = tempfile::tempdir().unwrap();
    let mut file = load(dir.path(), "hall.toml", &example_text())
        .unwrap()
        .to_file_contents();
    let mut effects = Effects::default();
    for spec in [
        "elastic:ea_n=3e6",
        "pulley:radius_m=0.05",
        "encoder-scale:gain1=1.001",
        "loadcell:bias_n=1,gain=1.01",
    ]
    .into_iter()
    .chain([
        "com:dx_m=0.01",
        "segments:n=50",
        "localiser-mount:rx_deg=0.5",
        "platform-weight:scale=1.1",
    ])
    .chain([
        "cable-weight:scale=0.9",
        "encoder-drift:rate_m=1e-4",
        "encoder-backlash:b_m=1e-3",
    ])
    .chain([
        "loadcell-drift:rate_n=0.1",
        "loadcell-friction:k=0.02",
        "attachments:dx1_m=0.01",
    ]) {
        effects.apply_spec(spec).unwrap();
    }
    file.paper_robot = Some(PaperRobot::Large);
    file.length_offsets_m = Some(vec![0.5; 4]);
    file.effects = Some(effects);
    file.calibration = Some(CalibrationEntry::from_covariance(&ParameterCovariance::identity()));
    let table: toml::Table = toml::from_str(&file.to_toml().unwrap()).unwrap();
    let mut keys = BTreeSet::new();
    for (key, value) in &table {
        let inner = match value {
            toml::Value::Table(t) => Some(t),
            toml::Value::Array(a) => a.first().and_then(toml::Value::as_table),
            _ => None,
        };
        match inner {
            Some(t) => keys.extend(t.keys().map(|k| format!("{key}.{k}"))),
            None => {
                keys.insert(key.clone());
            }
        }
    }
    keys
}

/// The rows of the guide's key tables under "## Every key": the key as
/// `table.key` and the row's cells.
fn documented_rows() -> Vec<(String, Vec<String>)> {
    let text = page("robot-file.md");
    let section = &text[text.find("## Every key").unwrap()..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |e| e + 3)];
    let mut table = String::new();
    let mut rows = Vec::new();
    for line in section.lines() {
        if let Some(heading) = line.strip_prefix("### ") {
            table = ["cables", "workspace", "effects", "calibration"]
                .into_iter()
                .find(|t| heading.contains(&format!("[{t}]")))
                .map_or(String::new(), |t| format!("{t}."));
        } else if let Some(row) = line.strip_prefix("| `") {
            let cells: Vec<String> = line
                .split(" | ")
                .map(|c| c.trim_matches(['|', ' ']).to_string())
                .collect();
            let key = &row[..row.find('`').unwrap()];
            rows.push((format!("{table}{key}"), cells));
        }
    }
    rows
}

#[test]
fn the_key_tables_name_every_key_sagcal_reads() {
    let documented: BTreeSet<String> = documented_rows().into_iter().map(|(k, _)| k).collect();
    let read = keys_sagcal_reads();
    assert_eq!(read.len(), 27, "{read:?}");
    assert_eq!(
        documented, read,
        "docs/robot-file.md's key tables against the reader's keys"
    );
}

#[test]
fn each_effect_key_is_what_its_effect_spelling_sets() {
    for (key, cells) in documented_rows() {
        let Some(key) = key.strip_prefix("effects.") else {
            continue;
        };
        let spelling = cells[4].split('`').nth(1).expect("a spelling in backticks");
        let effects = [0.5, 2.0]
            .iter()
            .find_map(|v| {
                let mut e = Effects::default();
                e.apply_spec(&format!("{spelling}={v}")).ok().map(|_| e)
            })
            .unwrap_or_else(|| panic!("`{spelling}` is not an effect spelling"));
        let set: toml::Table = toml::from_str(&toml::to_string(&effects).unwrap()).unwrap();
        let neutral: toml::Table = toml::from_str(&toml::to_string(&Effects::default()).unwrap()).unwrap();
        assert!(
            set.get(key).is_some() && set.get(key) != neutral.get(key),
            "`{spelling}` does not set `{key}`"
        );
    }
}

#[test]
fn the_every_effect_fragment_holds_every_effect() {
    let all = robot_blocks();
    let every = toml_blocks(&all, "toml fragment")
        .into_iter()
        .max_by_key(|b| keys_of(&b.text).len())
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let robot = load(dir.path(), "every.toml", &spliced(&example_text(), &every.text)).unwrap();
    for kind in EffectKind::ALL.into_iter().filter(|k| *k != EffectKind::CommonGain) {
        assert!(
            kind.present_in(&robot.effects),
            "{} is not in the fragment",
            kind.name()
        );
    }
}

#[test]
fn the_frames_example_is_what_platform_pose_gives() {
    let dir = tempfile::tempdir().unwrap();
    let robot = load(dir.path(), "hall.toml", &example_text()).unwrap();
    let level = PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(0.0, 0.0, 5.0), 0.0, 0.0, 0.0);
    let turned = PlatformPose::from_roll_pitch_yaw_deg(Vector3::new(0.0, 0.0, 5.0), 0.0, 0.0, 90.0);
    let world = |pose: &PlatformPose, b: &Vector3<f64>| pose.position_m + pose.rotation_matrix() * b;
    says(
        "robot-file.md",
        &format!(
            "attachment 1 is at {} m in the world and the centre of mass at {} m",
            point(&world(&level, &robot.attachments_m[0])),
            point(&world(&level, &robot.com_offset_m))
        ),
    );
    says(
        "robot-file.md",
        &format!(
            "yaw 90 degrees about the vertical, attachment 1 is at {} m",
            point(&world(&turned, &robot.attachments_m[0]))
        ),
    );
}

#[test]
fn the_default_workspace_is_what_simulate_draws_from() {
    let dir = tempfile::tempdir().unwrap();
    let mut table: toml::Table = toml::from_str(&example_text()).unwrap();
    table.remove("workspace").expect("the example has a [workspace]");
    let robot = load(dir.path(), "hall.toml", &toml::to_string(&table).unwrap()).unwrap();
    let w = Workspace::default_for(&robot);
    let printed = run_ok(
        dir.path(),
        "sagcal simulate --robot hall.toml --poses 1 --seed 1 --out m.csv",
    );
    assert!(printed.starts_with(&format!("workspace {w}:")), "{printed}");
    let axis = |k: usize| format!("{:.2} .. {:.2} m", w.min_m[k], w.max_m[k]);
    says("robot-file.md", &format!("x {}, y {}, z {}", axis(0), axis(1), axis(2)));
}

#[test]
fn the_simulate_line_quoted_is_what_simulate_prints() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("hall.toml"), example_text()).unwrap();
    let command = &shell_commands(&robot_blocks(), "--truth hall-truth.toml")[0];
    let printed = run_ok(dir.path(), command);
    says(
        "robot-file.md",
        &format!("prints `{}`", printed.lines().next().unwrap()),
    );
}

#[test]
fn the_offsets_add_to_the_cable_lengths() {
    let all = robot_blocks();
    let dir = tempfile::tempdir().unwrap();
    let base = example_text();
    let fragment = toml_blocks(&all, "toml fragment")
        .into_iter()
        .find(|b| b.text.contains("length_offsets_m"))
        .expect("the offsets fragment");
    std::fs::write(dir.path().join("hall.toml"), &base).unwrap();
    std::fs::write(dir.path().join("hall-offsets.toml"), spliced(&base, &fragment.text)).unwrap();
    let offsets = load(dir.path(), "hall-offsets.toml", &spliced(&base, &fragment.text))
        .unwrap()
        .length_offsets_m;
    for command in shell_commands(&all, "zero.csv") {
        run_ok(dir.path(), &command);
    }
    let read = |name: &str| {
        read_measurements(&dir.path().join(name), &ReadOptions::default())
            .unwrap()
            .poses[0]
    };
    let (zero, shifted) = (read("zero.csv"), read("offsets.csv"));
    assert_eq!(zero.position_m, shifted.position_m, "the same pose");
    for (i, offset) in offsets.iter().enumerate() {
        let difference = shifted.encoder_lengths_m[i] - zero.encoder_lengths_m[i];
        assert!(
            (difference - offset).abs() < 1e-9,
            "cable {}: {difference} != {offset}",
            i + 1
        );
    }
    let (z, s) = (zero.encoder_lengths_m, shifted.encoder_lengths_m);
    says("robot-file.md", &format!("`l1_m` {:.4} m, `l2_m` {:.4} m", z[0], z[1]));
    says(
        "robot-file.md",
        &format!("reads `l1_m` {:.4} m and `l2_m` {:.4} m", s[0], s[1]),
    );
    says("robot-file.md", &format!("(+{} m, {} m)", offsets[0], offsets[1]));
}

// ---------------------------------------------------------------- measurements

/// The measurement page's blocks, each csv block's kind checked.
fn measurement_blocks() -> Vec<Block> {
    let all = blocks(&page("measurements.md"));
    for block in of_language(&all, "csv") {
        let kind: Vec<&str> = block.info.iter().map(String::as_str).collect();
        assert!(
            matches!(
                kind[..],
                ["csv", "sagcal" | "readings" | "recurdyn"]
                    | ["csv", "sagcal" | "readings", "rejected"]
                    | ["csv", "authors", _]
            ),
            "measurements.md: a block ```{} is not one of the page's csv kinds",
            kind.join(" ")
        );
    }
    assert!(
        of_language(&all, "toml").is_empty(),
        "measurements.md: robot files belong in robot-file.md"
    );
    all
}

/// The csv blocks of one format (`sagcal`, `readings`, ...), rejected ones apart.
fn csv_blocks<'a>(all: &'a [Block], format: &str, rejected: bool) -> Vec<&'a Block> {
    of_language(all, "csv")
        .into_iter()
        .filter(|b| b.info[1] == format && (b.info.get(2).map(String::as_str) == Some("rejected")) == rejected)
        .collect()
}

/// `block` written to `dir/name`.
fn written(dir: &Path, name: &str, block: &Block) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, &block.text).unwrap();
    path
}

#[test]
fn every_sagcal_example_reads_as_the_page_says() {
    let all = measurement_blocks();
    let dir = tempfile::tempdir().unwrap();
    let examples = csv_blocks(&all, "sagcal", false);
    assert!(!examples.is_empty());
    for block in examples {
        let set = read_measurements(&written(dir.path(), "m.csv", block), &ReadOptions::default()).unwrap();
        assert_eq!(set.format, MeasurementFormat::Sagcal);
        let lines: Vec<usize> = set.poses.iter().map(|p| p.line).collect();
        says(
            "measurements.md",
            &format!("sagcal reads {} poses, on {}", lines.len(), lines_phrase(&lines)),
        );
    }
}

#[test]
fn the_sagcal_example_is_what_simulate_writes_rounded() {
    let all = measurement_blocks();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("hall.toml"), example_text()).unwrap();
    let command = quoted_command(&csv_blocks(&all, "sagcal", false)[0].before);
    run_ok(dir.path(), &command);
    let simulated = read_measurements(&dir.path().join(option(&command, "--out")), &ReadOptions::default()).unwrap();
    let shown = read_measurements(
        &written(dir.path(), "shown.csv", csv_blocks(&all, "sagcal", false)[0]),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(simulated.poses.len(), shown.poses.len());
    for (s, d) in simulated.poses.iter().zip(&shown.poses) {
        let (s, d) = (
            sagcal::io::measurements::pose_values(s),
            sagcal::io::measurements::pose_values(d),
        );
        for (a, b) in s.iter().zip(d) {
            assert!(
                (a - b).abs() <= 0.5e-4 + 1e-9,
                "{command}: {a} is not {b} to 4 decimals"
            );
        }
    }
}

#[test]
fn every_rejected_csv_is_refused_with_the_message_shown() {
    let all = measurement_blocks();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("hall.toml"), example_text()).unwrap();
    let mut refused = 0;
    for (k, block) in all.iter().enumerate() {
        if block.info.get(2).map(String::as_str) != Some("rejected") {
            continue;
        }
        let shown = all[k + 1..]
            .iter()
            .find(|b| b.info == ["text"])
            .expect("the message under it");
        let command = quoted_command(&shown.before);
        let path = written(dir.path(), option(&command, "--data"), block);
        let read_refuses = match block.info[1].as_str() {
            "sagcal" => read_measurements(&path, &ReadOptions::default()).is_err(),
            _ => read_readings(&path, 0).is_err(),
        };
        assert!(read_refuses, "sagcal's reader takes it:\n{}", block.text);
        let words: Vec<&str> = command.split_whitespace().skip(1).collect();
        let out = sagcal(dir.path(), &words);
        assert_eq!(out.status.code(), Some(1), "{command}");
        assert_eq!(
            String::from_utf8_lossy(&out.stderr).trim_end(),
            shown.text.trim_end(),
            "{command}"
        );
        refused += 1;
    }
    assert!(refused >= 1, "the page shows a refused file");
}

#[test]
fn every_readings_example_reads_as_the_page_says() {
    let all = measurement_blocks();
    let dir = tempfile::tempdir().unwrap();
    let examples = csv_blocks(&all, "readings", false);
    assert!(examples.len() >= 2);
    for block in examples {
        let file = read_readings(&written(dir.path(), "r.csv", block), 0).unwrap();
        assert_eq!(file.format, ReadingsFormat::ReadingsOnly);
        let lines: Vec<usize> = file.rows.iter().map(|r| r.line).collect();
        let load_cell: Vec<usize> = file
            .rows
            .iter()
            .filter(|r| r.load_cell_n.is_some())
            .map(|r| r.line)
            .collect();
        let rows = if lines.len() == 1 { "row" } else { "rows" };
        says(
            "measurements.md",
            &format!(
                "sagcal reads {} {rows}, on {}, the load cell on {}",
                lines.len(),
                lines_phrase(&lines),
                lines_phrase(&load_cell)
            ),
        );
    }
    // `localize` labels its rows by their data rows.
    std::fs::write(dir.path().join("hall.toml"), example_text()).unwrap();
    written(dir.path(), "readings.csv", csv_blocks(&all, "readings", false)[0]);
    let printed = run_ok(dir.path(), "sagcal localize --robot hall.toml --data readings.csv");
    let labels: Vec<&str> = printed
        .lines()
        .skip_while(|l| !l.starts_with("---"))
        .skip(1)
        .take_while(|l| !l.is_empty())
        .map(|l| l.split_whitespace().next().unwrap())
        .collect();
    says("measurements.md", &format!("labels its rows {}", labels.join(", ")));
}

#[test]
fn the_recurdyn_example_reads_as_the_page_says() {
    let all = measurement_blocks();
    let dir = tempfile::tempdir().unwrap();
    let (k, block) = all
        .iter()
        .enumerate()
        .find(|(_, b)| b.info == ["csv", "recurdyn"])
        .expect("a RecurDyn example");
    let path = written(dir.path(), "log.csv", block);
    let read = |cable: usize| {
        read_measurements(
            &path,
            &ReadOptions {
                reference_cable: cable,
                keep_rounded: false,
            },
        )
        .unwrap()
    };
    let (first, third) = (read(0), read(2));
    assert_eq!(first.format, MeasurementFormat::RecurDyn);
    let lines: Vec<usize> = first.poses.iter().map(|p| p.line).collect();
    says(
        "measurements.md",
        &format!(
            "sagcal reads {} poses, on {}, the load cell of line {} being `fc1` = {:.3} N with `reference_cable = 1` and `fc3` = {:.3} N with `reference_cable = 3`",
            lines.len(),
            lines_phrase(&lines),
            lines[0],
            first.poses[0].reference_tension_n,
            third.poses[0].reference_tension_n
        ),
    );
    let shown = all[k + 1..]
        .iter()
        .find(|b| b.info == ["text"])
        .expect("the rows left out");
    let left_out: Vec<String> = first
        .rejected
        .iter()
        .map(|r| format!("line {}: {}", r.line, r.reason))
        .collect();
    assert_eq!(shown.text.lines().collect::<Vec<_>>(), left_out);
}

#[test]
fn the_authors_example_reads_as_the_page_says() {
    let all = measurement_blocks();
    let dir = tempfile::tempdir().unwrap();
    let files = csv_blocks(&all, "authors", false);
    for name in [
        "pos_i_cpp_test.csv",
        "R_i_cpp_test.csv",
        "lc_meas_cpp_test.csv",
        "forces_cpp_test.csv",
    ] {
        assert!(files.iter().any(|b| b.info[2] == name), "no {name}");
    }
    for block in &files {
        written(dir.path(), &block.info[2], block);
    }
    let set = read_measurements(dir.path(), &ReadOptions::default()).unwrap();
    assert_eq!(set.format, MeasurementFormat::Authors);
    let forces = files.iter().find(|b| b.info[2] == "forces_cpp_test.csv").unwrap();
    let (f_h, f_v) = forces.text.lines().next().unwrap().split_once(',').unwrap();
    let lines: Vec<usize> = set.poses.iter().map(|p| p.line).collect();
    says(
        "measurements.md",
        &format!(
            "sagcal reads {} poses, on {}, the load cell of line 1 being hypot({f_h}, {f_v}) = {:.3} N",
            lines.len(),
            lines_phrase(&lines),
            set.poses[0].reference_tension_n
        ),
    );
}

#[test]
fn the_small_robots_ranges_are_what_simulate_prints() {
    let dir = tempfile::tempdir().unwrap();
    let small = root().join("robots/small.toml");
    let command = "sagcal simulate --robot robots/small.toml --poses 100 --seed 1 --out small.csv";
    says("measurements.md", command);
    let printed = run_ok(
        dir.path(),
        &command.replace("robots/small.toml", small.to_str().unwrap()),
    );
    let first = printed.lines().next().unwrap();
    says(
        "measurements.md",
        &format!("prints `{}`", &first[first.find("cable lengths").unwrap()..]),
    );
}

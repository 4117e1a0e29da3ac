//! The fenced blocks of a page of docs/ and the commands printed beside
//! them (included with `#[path]` by `tests/docs_examples.rs`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use nalgebra::Vector3;
use sagcal::model::Robot;

/// One fenced block of a page.
pub struct Block {
    /// The words after the opening fence.
    pub info: Vec<String>,
    /// The block's lines, each ending in `\n`.
    pub text: String,
    /// The page's text between the previous block and this one.
    pub before: String,
}

/// The repository's root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A page of docs/.
pub fn page(name: &str) -> String {
    std::fs::read_to_string(root().join("docs").join(name)).expect("the page exists")
}

/// The fenced blocks of a page, in order.
pub fn blocks(text: &str) -> Vec<Block> {
    let mut found = Vec::new();
    let mut prose = String::new();
    let mut open: Option<(Vec<String>, String)> = None;
    for line in text.lines() {
        match open.as_mut() {
            None => match line.trim_start().strip_prefix("```") {
                Some(info) => open = Some((info.split_whitespace().map(str::to_string).collect(), String::new())),
                None => prose += &format!("{line}\n"),
            },
            Some((info, body)) => {
                if line.trim() == "```" {
                    let before = std::mem::take(&mut prose);
                    found.push(Block {
                        info: std::mem::take(info),
                        text: std::mem::take(body),
                        before,
                    });
                    open = None;
                } else {
                    *body += &format!("{line}\n");
                }
            }
        }
    }
    assert!(open.is_none(), "a block is never closed");
    found
}

/// The blocks whose info string starts with `language`.
pub fn of_language<'a>(all: &'a [Block], language: &str) -> Vec<&'a Block> {
    all.iter()
        .filter(|b| b.info.first().is_some_and(|l| l == language))
        .collect()
}

/// `text` with every run of white space one space (a phrase may wrap).
pub fn flat(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Fail unless `page` says `phrase` (white space as one space).
pub fn says(page_name: &str, phrase: &str) {
    println!("{page_name}: {phrase}");
    assert!(
        flat(&page(page_name)).contains(&flat(phrase)),
        "docs/{page_name} does not say `{phrase}`, which is what the command beside it gives"
    );
}

/// `lines 3, 4, 7`, `line 2` or `no line`.
pub fn lines_phrase(lines: &[usize]) -> String {
    let list: Vec<String> = lines.iter().map(usize::to_string).collect();
    match lines.len() {
        0 => "no line".into(),
        1 => format!("line {}", list[0]),
        _ => format!("lines {}", list.join(", ")),
    }
}

/// A number as the pages write it: at most 6 decimals, no trailing zeros.
pub fn short(v: f64) -> String {
    let text = format!("{v:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// `(x, y, z)` as the pages write a point.
pub fn point(v: &Vector3<f64>) -> String {
    format!("({}, {}, {})", short(v.x), short(v.y), short(v.z))
}

/// Run `sagcal ARGS` in `dir`.
pub fn sagcal(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sagcal runs")
}

/// Run the command `line` (`sagcal ...`, as a page prints it) in `dir`; its stdout.
pub fn run_ok(dir: &Path, line: &str) -> String {
    let words: Vec<&str> = line.split_whitespace().skip(1).collect();
    let out = sagcal(dir, &words);
    assert!(out.status.success(), "{line}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The commands of a ```sh block whose text contains `needle`.
pub fn shell_commands(all: &[Block], needle: &str) -> Vec<String> {
    let block = of_language(all, "sh")
        .into_iter()
        .find(|b| b.text.contains(needle))
        .unwrap_or_else(|| panic!("no sh block with `{needle}`"));
    block.text.lines().map(str::to_string).collect()
}

/// The last `sagcal ...` command in backticks in `prose`.
pub fn quoted_command(prose: &str) -> String {
    let flat = flat(prose);
    let at = flat.rfind("`sagcal ").expect("a `sagcal ...` command beside the block");
    let rest = &flat[at + 1..];
    rest[..rest.find('`').expect("a closing backtick")].to_string()
}

/// The value of option `name` in `command`.
pub fn option<'a>(command: &'a str, name: &str) -> &'a str {
    let words: Vec<&str> = command.split_whitespace().collect();
    let at = words
        .iter()
        .position(|w| *w == name)
        .unwrap_or_else(|| panic!("{command}: no {name}"));
    words[at + 1]
}

/// `base` with `fragment`'s keys and tables added (a key or table of both: the fragment's).
pub fn spliced(base: &str, fragment: &str) -> String {
    let mut table: toml::Table = toml::from_str(base).expect("the example is TOML");
    let added: toml::Table = toml::from_str(fragment).expect("the fragment is TOML");
    table.extend(added);
    toml::to_string(&table).expect("TOML again")
}

/// Read `text` as the robot file `dir/name` with sagcal's reader.
pub fn load(dir: &Path, name: &str, text: &str) -> sagcal::Result<Robot> {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    Robot::from_file(&path)
}

/// Each `key = value` line of `text` (in any table), as its key.
pub fn keys_of(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.split_once(" = ").map(|(k, _)| k.trim().to_string()))
        .filter(|k| !k.starts_with('#'))
        .collect()
}

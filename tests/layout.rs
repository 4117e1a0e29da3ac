//! The crate's layout, checked on its source. Data flows one way,
//! io -> model -> graph -> solver -> calib / diagnose / localize / plan ->
//! experiments -> cli, and no module imports a module above it.
//!
//! `io` converts files into `model` types, so `io` may name `model`; `model`
//! names no file type and nothing above itself. Doc comments may link
//! anywhere: only code lines are checked. And the source stays readable: no
//! file under `src/` past 700 lines (but the discretised simulator and the
//! hand-drawn figures) and no function past 100 lines, counted on
//! rustfmt-formatted code.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Each top-level module of `src/` and the crate modules its code may name.
const ALLOWED: &[(&str, &[&str])] = &[
    ("error", &[]),
    ("steps", &[]),
    // The kernels' instruction set: a leaf, so that `graph` and `solver` follow one switch.
    ("simd", &[]),
    ("cancel", &["error"]),
    ("stats", &["error"]),
    ("model", &["error", "steps", "stats", "generated"]),
    ("io", &["error", "model"]),
    ("sim", &["error", "steps", "cancel", "stats", "generated", "model"]),
    ("graph", &["error", "stats", "generated", "model", "simd"]),
    (
        "solver",
        &["error", "steps", "cancel", "stats", "model", "graph", "simd"],
    ),
    ("calib", &["error", "stats", "generated", "model", "graph", "solver"]),
    (
        "diagnose",
        &["error", "stats", "generated", "model", "io", "graph", "solver", "calib"],
    ),
    (
        "localize",
        &[
            "error",
            "steps",
            "stats",
            "generated",
            "model",
            "graph",
            "solver",
            "calib",
        ],
    ),
    (
        "plan",
        &[
            "error",
            "steps",
            "stats",
            "generated",
            "model",
            "graph",
            "solver",
            "calib",
        ],
    ),
    (
        "experiments",
        &[
            "error",
            "stats",
            "generated",
            "model",
            "io",
            "sim",
            "graph",
            "solver",
            "calib",
            "diagnose",
            "localize",
            "plan",
        ],
    ),
    ("plot", &["error", "io"]),
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The crate modules named by `crate::<module>` in the code (not the comments) of `text`.
fn named_modules(text: &str) -> BTreeSet<String> {
    let mut named = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            let after = &rest[at + "crate::".len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            // `crate::Error` and `crate::Result` are the error module's re-exports.
            let name = if name == "Error" || name == "Result" {
                "error".to_string()
            } else {
                name
            };
            if !name.is_empty() {
                named.insert(name);
            }
            rest = after;
        }
    }
    named
}

#[test]
fn no_module_imports_a_higher_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut violations = Vec::new();
    let mut checked = 0;
    for (module, allowed) in ALLOWED {
        let mut files = Vec::new();
        let dir = src.join(module);
        if dir.is_dir() {
            rust_files(&dir, &mut files);
        }
        let file = src.join(format!("{module}.rs"));
        if file.is_file() {
            files.push(file);
        }
        for file in files {
            checked += 1;
            let text = std::fs::read_to_string(&file).unwrap();
            for name in named_modules(&text) {
                if name != *module && !allowed.contains(&name.as_str()) {
                    violations.push(format!("{} names crate::{name}", file.display()));
                }
            }
        }
    }
    assert!(checked > 40, "only {checked} files found under {}", src.display());
    assert!(violations.is_empty(), "layer violations:\n{}", violations.join("\n"));
}

#[test]
fn every_top_level_module_has_a_layer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let known: BTreeSet<&str> = ALLOWED.iter().map(|(m, _)| *m).chain(["cli", "lib", "main"]).collect();
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        assert!(
            known.contains(name.as_str()),
            "src/{name} has no layer in tests/layers.rs: place it in ALLOWED"
        );
    }
}

#[test]
fn the_checker_sees_an_upward_import() {
    let text = "use crate::calib::calibrate; // crate::cli in a comment\n/// [`crate::plot`]\n";
    let named = named_modules(text);
    assert_eq!(named.into_iter().collect::<Vec<_>>(), vec!["calib".to_string()]);
}

/// Files allowed past [`MAX_FILE_LINES`]: the discretised simulator and the
/// hand-drawn figures (one figure per file).
const LONG_FILES_ALLOWED: &[&str] = &["sim/discretised.rs", "plot/"];
/// The longest a file under `src/` may be, in lines.
const MAX_FILE_LINES: usize = 700;
/// The longest a function may be, in lines (signature to closing brace).
const MAX_FUNCTION_LINES: usize = 100;

/// Each function of rustfmt-formatted `text` as (name, first line, lines):
/// from its `fn` line to the closing brace at the same indentation.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    for (start, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        let is_fn = trimmed.starts_with("fn ")
            || trimmed.starts_with("pub fn ")
            || trimmed.starts_with("pub(crate) fn ")
            || trimmed.starts_with("pub(super) fn ")
            || trimmed.starts_with("const fn ")
            || trimmed.starts_with("pub const fn ");
        if !is_fn || line.trim_end().ends_with(';') {
            continue;
        }
        let name: String = trimmed
            .split("fn ")
            .nth(1)
            .unwrap_or("")
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let closing = " ".repeat(indent) + "}";
        if let Some(end) = (start..lines.len())
            .find(|&k| lines[k].trim_end() == closing || (k == start && line.trim_end().ends_with('}')))
        {
            found.push((name, start + 1, end - start + 1));
        }
    }
    found
}

#[test]
fn files_and_functions_stay_short() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut too_long = Vec::new();
    for file in &files {
        let relative = file.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
        let text = std::fs::read_to_string(file).unwrap();
        let line_count = text.lines().count();
        if line_count > MAX_FILE_LINES && !LONG_FILES_ALLOWED.iter().any(|a| relative.starts_with(a)) {
            too_long.push(format!("src/{relative}: {line_count} lines (at most {MAX_FILE_LINES})"));
        }
        for (name, first, length) in functions(&text) {
            if length > MAX_FUNCTION_LINES {
                too_long.push(format!(
                    "src/{relative}:{first}: fn {name} has {length} lines (at most {MAX_FUNCTION_LINES})"
                ));
            }
        }
    }
    assert!(too_long.is_empty(), "split these:\n{}", too_long.join("\n"));
}

#[test]
fn the_function_counter_measures_a_known_function() {
    let text = "impl A {\n    pub fn short(&self) -> u8 {\n        1\n    }\n}\nfn outer() {\n    let x = 1;\n}\nfn one_line() {}\n";
    let found = functions(text);
    assert_eq!(
        found,
        vec![
            ("short".to_string(), 2, 3),
            ("outer".to_string(), 6, 3),
            ("one_line".to_string(), 9, 1)
        ]
    );
}

//! The crate's layout, checked on its source. Data flows one way,
//! io -> model -> graph -> solver -> calib / diagnose / localize / plan ->
//! experiments -> cli, and no module imports a module above it.
//!
//! `io` converts files into `model` types, so `io` may name `model`; `model`
//! names no file type and nothing above itself. Doc comments may link
//! anywhere: only code lines are checked. And the source stays readable: no
//! file under `src/` past 700 lines (but the discretised simulator and the
//! hand-drawn figures) and no function past 100 lines, counted on
//! rustfmt-formatted code. A folder's `mod.rs` holds only its doc comment,
//! `mod` declarations and `use`/`pub use` re-exports (and attributes on
//! those): every definition lives in a file named for it. Inside a folder,
//! no files name each other in a ring (an item the folder's `mod.rs`
//! re-exports counts as its defining child's).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Each top-level module of `src/` and the crate modules its code may name.
const ALLOWED: &[(&str, &[&str])] = &[
    ("error", &[]),
    ("steps", &[]),
    // The kernels' instruction set: below `graph` and `solver`, so that both follow one switch.
    ("simd", &["error"]),
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
    // What sagcal understood from a user's files: read with `io`, checked as `calib` checks them.
    ("check", &["error", "stats", "model", "io", "sim", "calib"]),
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

/// A module's path under `src/` (`["calib", "mistakes"]` for
/// `src/calib/mistakes.rs`, `["calib"]` for `src/calib/mod.rs`), and whether
/// the file is a folder's module file (`mod.rs`, or `x.rs` beside a folder `x/`).
fn module_of(src: &Path, file: &Path) -> (Vec<String>, bool) {
    let relative = file.strip_prefix(src).unwrap().with_extension("");
    let mut path: Vec<String> = relative.iter().map(|p| p.to_string_lossy().to_string()).collect();
    if path.last().is_some_and(|p| p == "mod") {
        path.pop();
        return (path, true);
    }
    let folder = src.join(path.join("/"));
    (path, folder.is_dir())
}

/// The code of `text` that a build without tests compiles: comments dropped,
/// and everything from a `#[cfg(test)]` module on (tests sit at the end of a file).
fn production_code(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let end = (0..lines.len())
        .find(|&k| {
            lines[k].trim() == "#[cfg(test)]"
                && lines
                    .get(k + 1)
                    .is_some_and(|next| next.trim_start().starts_with("mod "))
        })
        .unwrap_or(lines.len());
    lines[..end]
        .iter()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths a `use` tree names, braces expanded: `a::{b, c::{d, e}}` ->
/// `a::b`, `a::c::d`, `a::c::e` (aliases dropped, `self` in a group is its prefix).
fn expand_use_tree(tree: &str) -> Vec<String> {
    let tree: String = tree.split_whitespace().collect::<Vec<_>>().join(" ");
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        let path = tree.split(" as ").next().unwrap_or("").trim();
        return vec![path.trim_end_matches("::self").to_string()];
    };
    let prefix = tree[..open].trim_end_matches("::");
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.trim().is_empty())
        .flat_map(expand_use_tree)
        .map(|p| {
            if p == "self" {
                prefix.to_string()
            } else {
                format!("{prefix}::{p}")
            }
        })
        .collect()
}

/// Every module path the code of a file names: its `use` trees expanded, and
/// inline `super::`, `self::` and `crate::` paths.
fn named_paths(code: &str) -> Vec<String> {
    let mut paths = Vec::new();
    let lines: Vec<&str> = code.lines().collect();
    for (k, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let Some(tree) = ["use ", "pub use ", "pub(crate) use ", "pub(super) use "]
            .iter()
            .find_map(|p| trimmed.strip_prefix(p))
        else {
            continue;
        };
        let mut statement = tree.to_string();
        for next in &lines[k + 1..] {
            if statement.contains(';') {
                break;
            }
            statement.push_str(next);
        }
        paths.extend(expand_use_tree(statement.split(';').next().unwrap_or("")));
    }
    for root in ["super::", "self::", "crate::"] {
        let mut rest = code;
        while let Some(at) = rest.find(root) {
            let before_ok = at == 0 || !rest[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == ':');
            let path: String = rest[at..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            if before_ok {
                paths.push(path.trim_end_matches(':').to_string());
            }
            rest = &rest[at + root.len()..];
        }
    }
    paths
}

/// `path` (as written in a file of module `module`) as a path from the crate root.
fn absolute(
    path: &str,
    module: &[String],
    is_folder_module: bool,
    children: &dyn Fn(&[String]) -> bool,
) -> Option<Vec<String>> {
    let segments: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let mut here: Vec<String> = module.to_vec();
    let mut rest = &segments[..];
    match rest.first() {
        Some(&"crate") => {
            here.clear();
            rest = &rest[1..];
        }
        Some(&"self") => rest = &rest[1..],
        Some(&"super") => {
            while rest.first() == Some(&"super") {
                here.pop()?;
                rest = &rest[1..];
            }
        }
        Some(first) if is_folder_module => {
            let mut child = module.to_vec();
            child.push(first.to_string());
            if !children(&child) {
                return None;
            }
        }
        _ => return None,
    }
    here.extend(rest.iter().map(|s| s.to_string()));
    Some(here)
}

/// The items a folder module's file re-exports, each with the child that
/// defines it (`pub use child::{A, b::C}`: `A` and `C` from `child`).
fn re_exports(code: &str, module: &[String], is_module: &dyn Fn(&[String]) -> bool) -> BTreeMap<String, String> {
    let mut found = BTreeMap::new();
    for statement in code.split(';') {
        let statement = statement.trim();
        let Some(tree) = ["pub use ", "pub(crate) use ", "pub(super) use "]
            .iter()
            .find_map(|p| statement.strip_prefix(p))
        else {
            continue;
        };
        for path in expand_use_tree(tree) {
            let Some(target) = absolute(&path, module, true, is_module) else {
                continue;
            };
            if target.len() > module.len() + 1 && target[..module.len()] == *module {
                found.insert(target.last().unwrap().clone(), target[module.len()].clone());
            }
        }
    }
    found
}

/// The circles among the files of each folder of `src`: per folder, the
/// groups of its children (files, sub-folders, and `mod` for the folder's
/// own module file) that name each other in a ring, in production code.
/// An item a folder's module file re-exports counts as its child's.
fn circles(src: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: BTreeMap<Vec<String>, (PathBuf, bool)> = files
        .iter()
        .map(|f| {
            let (module, folder) = module_of(src, f);
            (module, (f.clone(), folder))
        })
        .collect();
    let is_module = |p: &[String]| modules.contains_key(p);
    let code_of = |file: &Path| production_code(&std::fs::read_to_string(file).unwrap());
    let mut edges: BTreeMap<Vec<String>, BTreeSet<(String, String)>> = BTreeMap::new();
    for (module, (file, folder)) in &modules {
        for path in named_paths(&code_of(file)) {
            let Some(target) = absolute(&path, module, *folder, &is_module) else {
                continue;
            };
            let common = module.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if common == 0 || (common == module.len() && !folder) {
                continue;
            }
            let scope = module[..common].to_vec();
            let from = if common == module.len() {
                "mod".to_string()
            } else {
                module[common].clone()
            };
            let to = match target.get(common) {
                None => "mod".to_string(),
                Some(name) if is_module(&[&scope[..], std::slice::from_ref(name)].concat()) => name.clone(),
                Some(item) => {
                    let scope_file = &modules[&scope].0;
                    re_exports(&code_of(scope_file), &scope, &is_module)
                        .get(item)
                        .cloned()
                        .unwrap_or_else(|| "mod".to_string())
                }
            };
            if from != to {
                edges.entry(scope).or_default().insert((from, to));
            }
        }
    }
    let mut found = Vec::new();
    for (scope, edges) in edges {
        let nodes: BTreeSet<&String> = edges.iter().flat_map(|(a, b)| [a, b]).collect();
        let reach = |start: &String| -> BTreeSet<String> {
            let mut seen = BTreeSet::new();
            let mut stack = vec![start.clone()];
            while let Some(n) = stack.pop() {
                for (a, b) in &edges {
                    if *a == n && seen.insert(b.clone()) {
                        stack.push(b.clone());
                    }
                }
            }
            seen
        };
        let reaches: BTreeMap<&String, BTreeSet<String>> = nodes.iter().map(|n| (*n, reach(n))).collect();
        let mut placed = BTreeSet::new();
        for n in &nodes {
            if placed.contains(*n) {
                continue;
            }
            let ring: Vec<&String> = nodes
                .iter()
                .copied()
                .filter(|m| m == n || (reaches[n].contains(*m) && reaches[m].contains(*n)))
                .collect();
            if ring.len() > 1 {
                placed.extend(ring.iter().map(|m| (*m).clone()));
                let names: Vec<&str> = ring.iter().map(|m| m.as_str()).collect();
                found.push(format!("{}: {}", scope.join("/"), names.join(" <-> ")));
            }
        }
    }
    found
}

#[test]
fn no_circle_inside_a_folder() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let found = circles(&src);
    assert!(
        found.is_empty(),
        "circles inside folders (files that name each other in a ring; a folder's mod.rs only declares, documents and re-exports):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_circle_finder_sees_a_ring_through_a_re_export() {
    // a -> b directly, b -> a through the folder's re-export of `A`.
    let dir = std::env::temp_dir().join(format!("sagcal-layout-{}", std::process::id()));
    let folder = dir.join("top");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("mod.rs"), "//! Top.\nmod a;\nmod b;\npub use a::A;\n").unwrap();
    std::fs::write(folder.join("a.rs"), "use super::b::helper;\npub struct A;\n").unwrap();
    std::fs::write(folder.join("b.rs"), "use crate::top::A; // a comment: super::mod_only\npub fn helper() {}\n#[cfg(test)]\nmod tests {\n    use super::super::a;\n}\n").unwrap();
    std::fs::write(folder.join("c.rs"), "use super::{a::{self, A as Alias}, b};\n").unwrap();
    let found = circles(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found, vec!["top: a <-> b".to_string()]);
    assert_eq!(
        expand_use_tree("x::{y, z::{self, w as v}}"),
        vec!["x::y", "x::z", "x::z::w"]
    );
}

/// The first line of each folder module file (`mod.rs`) under `root` whose
/// code ([`production_code`]: comments and the tests at the end dropped) is
/// not a `mod` declaration, a `use` item (over one line or several) or an
/// attribute on one of them: (the file relative to `root`, line number, line).
fn mod_file_offences(root: &Path) -> Vec<(String, usize, String)> {
    let mut files = Vec::new();
    rust_files(root, &mut files);
    files.retain(|f| f.file_name().is_some_and(|n| n == "mod.rs"));
    files.sort();
    let mut found = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        if let Some(line) = first_definition(&production_code(&text)) {
            let relative = file.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
            found.push((
                relative,
                line + 1,
                text.lines().nth(line).unwrap_or("").trim().to_string(),
            ));
        }
    }
    found
}

/// The index of the first line of `code` that starts anything but a `mod`
/// declaration, a `use` item or an attribute on one of them (a dangling
/// attribute counts from its own line).
fn first_definition(code: &str) -> Option<usize> {
    let lines: Vec<&str> = code.lines().collect();
    let mut k = 0;
    let mut attribute_from = None;
    while k < lines.len() {
        let mut rest = lines[k].trim();
        // Attributes, each `#[...]` possibly over several lines.
        while rest.starts_with("#[") {
            attribute_from.get_or_insert(k);
            let mut depth = 0;
            let mut end = None;
            while end.is_none() {
                for (i, c) in rest.char_indices() {
                    match c {
                        '[' => depth += 1,
                        ']' => depth -= 1,
                        _ => continue,
                    }
                    if depth == 0 {
                        end = Some(i);
                        break;
                    }
                }
                if end.is_none() {
                    k += 1;
                    rest = match lines.get(k) {
                        Some(line) => line.trim(),
                        None => return attribute_from,
                    };
                }
            }
            rest = rest[end.unwrap() + 1..].trim();
        }
        if rest.is_empty() {
            k += 1;
            continue;
        }
        let item = without_visibility(rest);
        if let Some(name) = item.strip_prefix("mod ").and_then(|m| m.strip_suffix(';')) {
            if name.trim().chars().any(|c| !(c.is_alphanumeric() || c == '_')) {
                return Some(attribute_from.unwrap_or(k));
            }
        } else if item.starts_with("use ") {
            while !lines[k].contains(';') {
                k += 1;
                if k == lines.len() {
                    return Some(attribute_from.unwrap_or(k - 1));
                }
            }
        } else {
            return Some(attribute_from.unwrap_or(k));
        }
        attribute_from = None;
        k += 1;
    }
    attribute_from
}

/// `item` without a leading `pub`, `pub(crate)`, `pub(super)` or `pub(in path)`.
fn without_visibility(item: &str) -> &str {
    if let Some(rest) = item.strip_prefix("pub(") {
        return rest.split_once(')').map_or(item, |(_, after)| after.trim_start());
    }
    item.strip_prefix("pub ").unwrap_or(item)
}

#[test]
fn mod_files_only_declare_document_and_re_export() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let found: Vec<String> = mod_file_offences(&src)
        .into_iter()
        .map(|(file, line, text)| format!("src/{file}:{line}: {text}"))
        .collect();
    assert!(
        found.is_empty(),
        "a mod.rs holds only its doc comment, `mod` declarations and `use`/`pub use` re-exports; \
         move each definition into a file named for it:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_checker_sees_a_definition_in_a_mod_file() {
    let dir = std::env::temp_dir().join(format!("sagcal-layout-mod-files-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("top/inner")).unwrap();
    std::fs::create_dir_all(dir.join("clean")).unwrap();
    std::fs::write(
        dir.join("top/mod.rs"),
        "//! Top: `fn` in a doc comment.\nmod a;\npub(super) mod inner;\n\npub use a::{\n    A,\n    B,\n};\n#[cfg(test)]\npub(crate) use a::C;\n\n/// A helper.\nfn helper() {}\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("top/inner/mod.rs"),
        "//! Inner.\nmod b;\n#[derive(Debug)]\npub struct Defined;\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("clean/mod.rs"),
        "//! Clean.\npub mod a; // a comment: fn here\n#[cfg(any(\n    test,\n    feature = \"x\"\n))]\nuse a::A;\n\n#[cfg(test)]\nmod tests {\n    fn check() {}\n}\n",
    )
    .unwrap();
    let found = mod_file_offences(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(
        found,
        vec![
            ("top/inner/mod.rs".to_string(), 3, "#[derive(Debug)]".to_string()),
            ("top/mod.rs".to_string(), 13, "fn helper() {}".to_string()),
        ]
    );
}

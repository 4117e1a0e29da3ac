//! Every public module of the library opens with a runnable example
//! (issue 19): the file of each module reachable from `src/lib.rs` through
//! `pub mod` has, in its leading `//!` block, a code fence that rustdoc runs
//! as a doctest (no info string, `rust`, `no_run` or `should_panic`; not
//! `text`, `toml` or `ignore`). A module whose file is generated (the
//! `generated/` folder, rewritten by `make codegen`) may carry its example in
//! the `///` doc comment on its `pub mod` line instead.

use std::path::{Path, PathBuf};

/// A public module: its path in the crate, its file, and the outer (`///`)
/// doc comment on its declaration.
struct PublicModule {
    name: String,
    file: PathBuf,
    outer_doc: Vec<String>,
}

/// The `pub mod NAME;` declarations of `file` (a crate root or module file),
/// resolved to their files (`#[path = ...]` honoured), with their outer docs.
fn declared_modules(crate_path: &str, file: &Path) -> Vec<PublicModule> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let stem = file.file_stem().unwrap().to_string_lossy();
    let dir = file.parent().unwrap();
    // `lib.rs` and `mod.rs` declare their children beside themselves, `foo.rs` in `foo/`.
    let child_dir = if stem == "lib" || stem == "mod" {
        dir.to_path_buf()
    } else {
        dir.join(stem.as_ref())
    };
    let mut modules = Vec::new();
    let (mut outer_doc, mut path_attribute) = (Vec::new(), None);
    for line in text.lines().map(str::trim) {
        if let Some(doc) = line.strip_prefix("///") {
            outer_doc.push(doc.to_string());
        } else if let Some(path) = line.strip_prefix("#[path = \"").and_then(|p| p.strip_suffix("\"]")) {
            path_attribute = Some(dir.join(path));
        } else if !line.starts_with("#[") {
            if let Some(name) = line.strip_prefix("pub mod ").and_then(|n| n.strip_suffix(';')) {
                let file = path_attribute.take().unwrap_or_else(|| {
                    let flat = child_dir.join(format!("{name}.rs"));
                    if flat.is_file() {
                        flat
                    } else {
                        child_dir.join(name).join("mod.rs")
                    }
                });
                let name = if crate_path.is_empty() {
                    name.to_string()
                } else {
                    format!("{crate_path}::{name}")
                };
                modules.push(PublicModule {
                    name,
                    file,
                    outer_doc: std::mem::take(&mut outer_doc),
                });
            }
            outer_doc.clear();
            path_attribute = None;
        }
    }
    modules
}

/// Every public module of the crate, depth first from `src/lib.rs`.
fn public_modules() -> Vec<PublicModule> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lib.rs");
    let mut found = Vec::new();
    let mut pending = declared_modules("", &root);
    while let Some(module) = pending.pop() {
        pending.extend(declared_modules(&module.name, &module.file));
        found.push(module);
    }
    found
}

/// The `//!` lines of the comment block a file opens with (plain `//` lines,
/// such as a generated file's banner, belong to the block too).
fn leading_inner_doc(text: &str) -> Vec<String> {
    text.lines()
        .map(str::trim_start)
        .take_while(|line| line.starts_with("//"))
        .filter_map(|line| line.strip_prefix("//!").map(str::to_string))
        .collect()
}

/// Whether these doc lines hold a code fence rustdoc compiles and runs.
fn has_runnable_example(doc: &[String]) -> bool {
    let mut in_fence = false;
    for line in doc {
        let Some(info) = line.trim().strip_prefix("```") else {
            continue;
        };
        if in_fence {
            in_fence = false;
            continue;
        }
        in_fence = true;
        let runnable = info
            .split(',')
            .map(str::trim)
            .all(|word| matches!(word, "" | "rust" | "no_run" | "should_panic" | "edition2021"));
        if runnable {
            return true;
        }
    }
    false
}

#[test]
fn every_public_module_opens_with_a_runnable_example() {
    let modules = public_modules();
    // The 14 top-level modules and their public submodules (42 when this test was written).
    assert!(modules.len() >= 40, "only {} public modules found", modules.len());
    let mut missing = Vec::new();
    for module in &modules {
        let text = std::fs::read_to_string(&module.file)
            .unwrap_or_else(|e| panic!("module {}: {}: {e}", module.name, module.file.display()));
        let generated = module.file.components().any(|c| c.as_os_str() == "generated");
        let example =
            has_runnable_example(&leading_inner_doc(&text)) || (generated && has_runnable_example(&module.outer_doc));
        if !example {
            missing.push(format!("{} ({})", module.name, module.file.display()));
        }
    }
    assert!(
        missing.is_empty(),
        "public modules without a runnable example in their leading `//!` block:\n{}",
        missing.join("\n")
    );
}

#[test]
fn the_checker_tells_runnable_fences_from_text() {
    let lines = |text: &str| text.lines().map(str::to_string).collect::<Vec<_>>();
    assert!(!has_runnable_example(&lines(" ```text\n a = b\n ```")));
    assert!(!has_runnable_example(&lines(" ```ignore\n f();\n ```")));
    // The closing fence of a text block does not open an example.
    assert!(!has_runnable_example(&lines(
        " ```text\n a\n ```\n prose\n ```toml\n x = 1\n ```"
    )));
    assert!(has_runnable_example(&lines(
        " ```text\n a\n ```\n ```\n assert!(true);\n ```"
    )));
    assert!(has_runnable_example(&lines(" ```no_run\n f();\n ```")));
    let header = "// banner\n//! Docs.\n//! ```\n//! x();\n//! ```\nuse a;\n//! not leading\n";
    assert_eq!(leading_inner_doc(header).len(), 4);
}

#[test]
fn the_walk_finds_nested_and_path_modules() {
    let names: Vec<String> = public_modules().into_iter().map(|m| m.name).collect();
    for expected in [
        "model::catenary",
        "graph::values",
        "generated",
        "calib::report",
        "sim::closed_form",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} not found among {names:?}"
        );
    }
}

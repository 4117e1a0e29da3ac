//! The shared RecurDyn log beside the checkout (included with `#[path]`):
//! tests that read it skip, with a message naming the path, where it is absent.

use std::path::{Path, PathBuf};

/// `../shared/data/recurdyn-large/recurdyn_large.csv` relative to the
/// crate, or `None` (after printing why the caller skips) when it is absent.
pub fn recurdyn_log() -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/recurdyn-large/recurdyn_large.csv");
    if path.exists() {
        Some(path)
    } else {
        eprintln!(
            "skipped: {} not found (the shared RecurDyn data is not beside this checkout)",
            path.display()
        );
        None
    }
}

//! Atomic file writes: a command that fails leaves nothing half-written.
//!
//! ```
//! use sagcal::io::write_atomically;
//! let path = std::env::temp_dir().join(format!("sagcal-atomic-doc-{}.txt", std::process::id()));
//! write_atomically(&path, b"first")?;
//! write_atomically(&path, b"second")?; // replaces the file whole
//! assert_eq!(std::fs::read(&path).unwrap(), b"second");
//! // A folder that does not exist is an error naming the file; nothing is created.
//! let nowhere = path.with_extension("d").join("x.txt");
//! assert!(write_atomically(&nowhere, b"x").unwrap_err().to_string().contains("x.txt"));
//! # std::fs::remove_file(&path).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::ffi::OsString;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::{Error, Result};

/// Distinguishes temporary files of concurrent writers in one process.
static TEMP_COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Write `bytes` to a new temporary file next to `path`, then rename it to
/// `path`. On any error the temporary file is removed and `path` is untouched.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let Some(file_name) = path.file_name() else {
        return Err(Error::InvalidInput(format!(
            "cannot write {}: not a file path",
            path.display()
        )));
    };
    let dir = folder_of(path);

    let (temp_path, file) = create_temp(&dir, file_name).map_err(|e| Error::io(path, e))?;
    let result = write_and_sync(file, bytes).and_then(|()| std::fs::rename(&temp_path, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&temp_path);
        return Err(Error::io(path, e));
    }
    // Make the rename durable where the platform allows it; failure here does
    // not undo the write, so it is not an error.
    if let Ok(d) = File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// The folder `path` is in (`.` for a bare file name).
pub(super) fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Create a fresh temporary file `.<name>.<pid>.<n>.tmp` in `dir`.
pub(super) fn create_temp(dir: &Path, file_name: &std::ffi::OsStr) -> std::io::Result<(PathBuf, File)> {
    let mut attempts = 0;
    loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut name = OsString::from(".");
        name.push(file_name);
        name.push(format!(".{}.{n}.tmp", std::process::id()));
        let temp_path = dir.join(name);
        match OpenOptions::new().write(true).create_new(true).open(&temp_path) {
            Ok(file) => return Ok((temp_path, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && attempts < 100 => attempts += 1,
            Err(e) => return Err(e),
        }
    }
}

/// Write everything and flush it to disk.
pub(super) fn write_and_sync(mut file: File, bytes: &[u8]) -> std::io::Result<()> {
    file.write_all(bytes)?;
    file.sync_all()
}

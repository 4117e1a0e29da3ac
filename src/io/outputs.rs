//! Every file a command writes, written as one set: all of them or none, and
//! never one over a file the command read.
//!
//! A command declares its inputs ([`OutputSet::input`]), then adds each file
//! it writes with its bytes ([`OutputSet::file`]) and the folders it creates
//! ([`OutputSet::folder`]), each under the command-line flag that named it,
//! and calls [`OutputSet::write`] once. Before anything is written the set
//! refuses
//!
//! - an output that is one of the inputs, however spelled: the paths are
//!   compared resolved (`./d.csv`, `d.csv`, `dir/../d.csv` and a symbolic
//!   link to it are one file) and, on Unix, by device and inode (a hard link);
//!   a folder input (the authors' dataset) stands for the files read from it;
//! - two outputs naming the same file;
//! - an output that is an existing folder;
//!
//! with an [`Error::InvalidInput`] naming both flags and paths. Then every
//! file goes to a temporary file beside its target (as
//! [`write_atomically`](super::write_atomically) does for one file); only
//! when all of them are written and flushed are they renamed into place. On
//! any failure every temporary file and every folder the set created is
//! removed, and the error ([`Error::Io`]) names the file and its flag.
//!
//! ```
//! use sagcal::io::OutputSet;
//! let dir = std::env::temp_dir().join(format!("sagcal-outputs-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let data = dir.join("d.csv");
//! std::fs::write(&data, "the measurements").unwrap();
//!
//! // An output over the input, spelled differently: refused, nothing written.
//! let mut outputs = OutputSet::new();
//! outputs.input("--data", &data);
//! outputs.file("--out", &dir.join(".").join("d.csv"), "a robot");
//! outputs.file("--plot", &dir.join("p.svg"), "<svg/>");
//! let err = outputs.write().unwrap_err().to_string();
//! assert!(err.contains("--out") && err.contains("--data"), "{err}");
//! assert_eq!(std::fs::read_to_string(&data).unwrap(), "the measurements");
//! assert!(!dir.join("p.svg").exists());
//!
//! // One output that cannot be written: the others are not written either.
//! let mut outputs = OutputSet::new();
//! outputs.file("--out", &dir.join("o.toml"), "a robot");
//! outputs.file("--plot", &dir.join("no-such-folder").join("p.svg"), "<svg/>");
//! assert!(outputs.write().unwrap_err().to_string().contains("--plot"));
//! assert!(!dir.join("o.toml").exists());
//!
//! // All fine: both appear.
//! let mut outputs = OutputSet::new();
//! outputs.input("--data", &data);
//! outputs.file("--out", &dir.join("o.toml"), "a robot");
//! outputs.file("--plot", &dir.join("p.svg"), "<svg/>");
//! outputs.write()?;
//! assert_eq!(std::fs::read_to_string(dir.join("o.toml")).unwrap(), "a robot");
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::fs::File;
use std::path::{Component, Path, PathBuf};

use super::atomic::{create_temp, folder_of, write_and_sync};
use super::authors::{FORCES_FILE, LENGTHS_FILE, ORIENTATION_FILE, POSITION_FILE};
use crate::error::{Error, Result};

/// The files and folders one command writes, and the files it read (module docs).
#[derive(Debug, Default)]
pub struct OutputSet {
    /// What the command read, under the flag that named it.
    inputs: Vec<Named>,
    /// Folders to create (if missing) before the files are written.
    folders: Vec<Named>,
    /// The files to write with their contents.
    files: Vec<(Named, Vec<u8>)>,
}

/// A path with the command-line flag (or other name) that gave it.
#[derive(Debug, Clone)]
struct Named {
    flag: String,
    path: PathBuf,
}

impl Named {
    fn new(flag: &str, path: &Path) -> Self {
        Self {
            flag: flag.to_string(),
            path: path.to_path_buf(),
        }
    }

    /// `--flag path`, as the user wrote it.
    fn describe(&self) -> String {
        format!("{} {}", self.flag, self.path.display())
    }
}

impl OutputSet {
    /// An empty set: no inputs, nothing to write.
    pub fn new() -> Self {
        Self::default()
    }

    /// Declare a file the command read (`flag` names it in errors): no output
    /// may be this file. A folder (the authors' dataset, `--data DIR`) stands
    /// for itself and the four files read from it.
    pub fn input(&mut self, flag: &str, path: &Path) -> &mut Self {
        if path.is_dir() {
            for name in [POSITION_FILE, ORIENTATION_FILE, LENGTHS_FILE, FORCES_FILE] {
                self.inputs.push(Named::new(flag, &path.join(name)));
            }
        }
        self.inputs.push(Named::new(flag, path));
        self
    }

    /// Add a file to write: `bytes` at `path` (`flag` names it in errors).
    pub fn file(&mut self, flag: &str, path: &Path, bytes: impl Into<Vec<u8>>) -> &mut Self {
        self.files.push((Named::new(flag, path), bytes.into()));
        self
    }

    /// Add a folder to create, with its missing parents, before the files are
    /// written into it (`flag` names it in errors). If the set fails, the
    /// folders it created are removed again.
    pub fn folder(&mut self, flag: &str, dir: &Path) -> &mut Self {
        self.folders.push(Named::new(flag, dir));
        self
    }

    /// The paths of the files to write, in the order they were added.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(|(named, _)| named.path.as_path())
    }

    /// Refuse, writing nothing, an output that is an input, two outputs that
    /// are one file, a file output that is an existing folder or has no file
    /// name, and a folder output that is an existing file.
    pub fn check(&self) -> Result<()> {
        let inputs: Vec<(&Named, Identity)> = self.inputs.iter().map(|n| (n, Identity::of(&n.path))).collect();
        let mut outputs: Vec<(&Named, Identity)> = Vec::new();
        for (named, _) in &self.files {
            if named.path.file_name().is_none() {
                return Err(refusal(format!("{}: not a file name", named.describe())));
            }
            if named.path.is_dir() {
                return Err(refusal(format!("{}: is a folder, not a file", named.describe())));
            }
            let id = Identity::of(&named.path);
            if let Some((input, _)) = inputs.iter().find(|(_, i)| i.same_file(&id)) {
                return Err(refusal(format!(
                    "{} is the {} file {}: a command never writes over a file it reads",
                    named.describe(),
                    input.flag,
                    input.path.display()
                )));
            }
            if let Some((other, _)) = outputs.iter().find(|(_, o)| o.same_file(&id)) {
                return Err(refusal(format!(
                    "{} and {} name the same file",
                    other.describe(),
                    named.describe()
                )));
            }
            outputs.push((named, id));
        }
        for folder in &self.folders {
            if folder.path.exists() && !folder.path.is_dir() {
                return Err(refusal(format!("{}: exists and is not a folder", folder.describe())));
            }
        }
        Ok(())
    }

    /// Check the set ([`OutputSet::check`]), then write every file: each to a
    /// temporary file beside it first, all renamed into place only once every
    /// one is written. On any error nothing is left behind: no temporary
    /// file, no folder the set created, no output replaced. (The one
    /// exception is a rename failing after the earlier renames succeeded,
    /// which takes a folder appearing at an output's path meanwhile; the
    /// error then lists the files already in place.)
    pub fn write(self) -> Result<()> {
        self.check()?;
        let mut created = Vec::new();
        let result = self.write_checked(&mut created);
        if result.is_err() {
            // Deepest first; a folder that is not empty (another writer) stays.
            for dir in created.iter().rev() {
                let _ = std::fs::remove_dir(dir);
            }
        }
        result
    }

    /// Create the folders (recording in `created` each one made), write the
    /// temporaries, rename them.
    fn write_checked(&self, created: &mut Vec<PathBuf>) -> Result<()> {
        for folder in &self.folders {
            create_folder(&folder.path, created).map_err(|e| write_error(folder, "cannot create the folder", e))?;
        }
        let mut temporaries: Vec<(PathBuf, &Named)> = Vec::new();
        for (named, bytes) in &self.files {
            let written = temporary_with(&named.path, bytes);
            match written {
                Ok(temp) => temporaries.push((temp, named)),
                Err(e) => {
                    remove_all(temporaries.iter().map(|(t, _)| t));
                    return Err(write_error(named, "cannot write", e));
                }
            }
        }
        for (k, (temp, named)) in temporaries.iter().enumerate() {
            if let Err(e) = std::fs::rename(temp, &named.path) {
                remove_all(temporaries[k..].iter().map(|(t, _)| t));
                if k == 0 {
                    return Err(write_error(named, "cannot write", e));
                }
                let done: Vec<String> = temporaries[..k].iter().map(|(_, n)| n.describe()).collect();
                let message = format!(
                    "{}: cannot write: {e}; already written: {}",
                    named.flag,
                    done.join(", ")
                );
                return Err(Error::io(&named.path, std::io::Error::new(e.kind(), message)));
            }
        }
        // Make the renames durable where the platform allows it; failure here
        // does not undo the writes, so it is not an error.
        for (_, named) in &temporaries {
            if let Ok(d) = File::open(folder_of(&named.path)) {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }
}

/// An output refused before anything was written.
fn refusal(message: String) -> Error {
    Error::InvalidInput(format!("{message}; nothing was written"))
}

/// A write that failed before any file was put in place, naming the file and its flag.
fn write_error(named: &Named, what: &str, e: std::io::Error) -> Error {
    let message = format!("{}: {what}: {e}; nothing was written", named.flag);
    Error::io(&named.path, std::io::Error::new(e.kind(), message))
}

/// Write `bytes` to a new temporary file beside `path`; its path.
fn temporary_with(path: &Path, bytes: &[u8]) -> std::io::Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"))?;
    let (temp, file) = create_temp(&folder_of(path), name)?;
    match write_and_sync(file, bytes) {
        Ok(()) => Ok(temp),
        Err(e) => {
            let _ = std::fs::remove_file(&temp);
            Err(e)
        }
    }
}

/// Remove these temporary files (best effort: they are ours).
fn remove_all<'a>(paths: impl Iterator<Item = &'a PathBuf>) {
    for path in paths {
        let _ = std::fs::remove_file(path);
    }
}

/// Create `dir` and its missing parents, outermost first, recording each one made.
fn create_folder(dir: &Path, created: &mut Vec<PathBuf>) -> std::io::Result<()> {
    let mut missing = Vec::new();
    let mut current = Some(dir);
    while let Some(d) = current.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
        missing.push(d.to_path_buf());
        current = d.parent();
    }
    for d in missing.into_iter().rev() {
        match std::fs::create_dir(&d) {
            Ok(()) => created.push(d),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && d.is_dir() => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Which file a path names: its resolved absolute path and, on Unix, the
/// device and inode of the file when it exists.
#[derive(Debug, PartialEq, Eq)]
struct Identity {
    resolved: PathBuf,
    inode: Option<(u64, u64)>,
}

impl Identity {
    fn of(path: &Path) -> Self {
        Self {
            resolved: resolve(path),
            inode: inode(path),
        }
    }

    /// The same path once resolved, or the same existing file (a hard link).
    fn same_file(&self, other: &Identity) -> bool {
        self.resolved == other.resolved || (self.inode.is_some() && self.inode == other.inode)
    }
}

/// `path` made absolute with every existing part resolved by the operating
/// system (symbolic links, `.`, `..`) and the rest, which does not exist
/// yet, appended with `.` and `..` applied by name.
fn resolve(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut resolved = PathBuf::new();
    let mut exists = true;
    for component in absolute.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir if !exists => {
                resolved.pop();
            }
            other => {
                resolved.push(other);
                if exists {
                    match std::fs::canonicalize(&resolved) {
                        Ok(c) => resolved = c,
                        Err(_) => exists = false,
                    }
                }
            }
        }
    }
    resolved
}

/// Device and inode of the file `path` names (following links), if it exists.
#[cfg(unix)]
fn inode(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

/// Without inodes, files are told apart by their resolved paths alone.
#[cfg(not(unix))]
fn inode(_path: &Path) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names in `dir`, sorted (temporary files included).
    fn listing(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn all_files_or_none() {
        let dir = tempfile::tempdir().unwrap();
        let old = dir.path().join("o.toml");
        std::fs::write(&old, "before").unwrap();
        let mut outputs = OutputSet::new();
        outputs
            .file("--out", &old, "after")
            .file("--json-out", &dir.path().join("new.json"), "{}")
            .file("--plot", &dir.path().join("missing").join("p.svg"), "<svg/>");
        let err = outputs.write().unwrap_err();
        assert!(matches!(err, Error::Io { .. }), "{err:?}");
        let message = err.to_string();
        assert!(message.contains("--plot") && message.contains("p.svg"), "{message}");
        assert!(message.contains("nothing was written"), "{message}");
        // The existing output unchanged, the new one absent, no temporary file left.
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "before");
        assert_eq!(listing(dir.path()), ["o.toml"]);

        let mut outputs = OutputSet::new();
        outputs
            .file("--out", &old, "after")
            .file("--json-out", &dir.path().join("new.json"), "{}");
        outputs.write().unwrap();
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "after");
        assert_eq!(std::fs::read_to_string(dir.path().join("new.json")).unwrap(), "{}");
        assert_eq!(listing(dir.path()), ["new.json", "o.toml"]);
    }

    #[test]
    fn an_output_over_an_input_is_refused_however_spelled() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir(d.join("sub")).unwrap();
        std::fs::write(d.join("d.csv"), "data").unwrap();
        let mut spellings = vec![
            d.join("d.csv"),
            d.join(".").join("d.csv"),
            d.join("sub").join("..").join("d.csv"),
        ];
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(d.join("d.csv"), d.join("link.csv")).unwrap();
            std::fs::hard_link(d.join("d.csv"), d.join("hard.csv")).unwrap();
            spellings.push(d.join("link.csv"));
            spellings.push(d.join("hard.csv"));
        }
        for spelling in &spellings {
            let mut outputs = OutputSet::new();
            outputs
                .input("--robot", &d.join("r.toml"))
                .input("--data", &d.join("d.csv"));
            outputs
                .file("--plot", &d.join("p.svg"), "<svg/>")
                .file("--out", spelling, "robot");
            let message = outputs.write().unwrap_err().to_string();
            assert!(
                message.contains(&format!("--out {}", spelling.display())) && message.contains("--data"),
                "{message}"
            );
            assert_eq!(std::fs::read_to_string(d.join("d.csv")).unwrap(), "data");
            assert!(!d.join("p.svg").exists(), "{}", spelling.display());
        }
        // A relative spelling against the current folder resolves the same way.
        let cwd = std::env::current_dir().unwrap();
        let relative = Path::new("Cargo.toml");
        let mut outputs = OutputSet::new();
        outputs
            .input("--robot", &cwd.join("Cargo.toml"))
            .file("--out", relative, "x");
        assert!(outputs.check().unwrap_err().to_string().contains("--robot"));
    }

    #[test]
    fn a_dataset_folder_input_covers_its_files_only() {
        let dir = tempfile::tempdir().unwrap();
        let data = dir.path().join("dataset");
        std::fs::create_dir(&data).unwrap();
        let mut outputs = OutputSet::new();
        outputs
            .input("--data", &data)
            .file("--out", &data.join(LENGTHS_FILE), "x");
        let message = outputs.check().unwrap_err().to_string();
        assert!(
            message.contains(LENGTHS_FILE) && message.contains("--data"),
            "{message}"
        );
        let mut outputs = OutputSet::new();
        outputs
            .input("--data", &data)
            .file("--out", &data.join("calibrated.toml"), "x");
        outputs.write().unwrap();
        assert!(data.join("calibrated.toml").exists());
    }

    #[test]
    fn two_outputs_naming_one_file_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let mut outputs = OutputSet::new();
        outputs
            .file("--out", &d.join("m.csv"), "data")
            .file("--truth", &d.join(".").join("m.csv"), "truth");
        let message = outputs.write().unwrap_err().to_string();
        assert!(message.contains("--out") && message.contains("--truth"), "{message}");
        assert!(listing(d).is_empty(), "{:?}", listing(d));
    }

    #[test]
    fn folders_are_created_and_removed_again_on_failure() {
        let dir = tempfile::tempdir().unwrap();
        let plots = dir.path().join("a").join("plots");
        let mut outputs = OutputSet::new();
        outputs
            .folder("--plots", &plots)
            .file("--plots", &plots.join("r.svg"), "<svg/>")
            .file("--out", &dir.path().join("missing").join("o.toml"), "robot");
        let message = outputs.write().unwrap_err().to_string();
        assert!(message.contains("--out"), "{message}");
        assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));

        let mut outputs = OutputSet::new();
        outputs
            .folder("--plots", &plots)
            .file("--plots", &plots.join("r.svg"), "<svg/>");
        outputs.write().unwrap();
        assert_eq!(std::fs::read_to_string(plots.join("r.svg")).unwrap(), "<svg/>");
    }

    #[test]
    fn an_output_that_is_a_folder_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let mut outputs = OutputSet::new();
        outputs.file("--out", dir.path(), "x");
        let message = outputs.check().unwrap_err().to_string();
        assert!(message.contains("--out") && message.contains("folder"), "{message}");
        let file = dir.path().join("f");
        std::fs::write(&file, "x").unwrap();
        let mut outputs = OutputSet::new();
        outputs.folder("--plots", &file);
        assert!(outputs.check().unwrap_err().to_string().contains("not a folder"));
    }
}

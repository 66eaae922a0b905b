//! Files written whole or not at all.
//!
//! * [`write_set`]: `generate`'s and `report`'s outputs. Every file of the set is first
//!   written and synced to a unique temporary file beside its target
//!   (`.<name>.XXXXXX.motorgen.tmp`); only when all of them are complete are they renamed
//!   over their targets, back to back. A full disk, a file-size limit or a kill while
//!   writing leaves the previous files untouched; only a failing rename (which needs no
//!   space) could leave a mixed set, and it names the files already replaced. The output
//!   directory is locked meanwhile, so concurrent runs do not interleave their sets.
//! * [`LockedSpec`]: `identify`'s write-back. The spec (a symlink's target) is locked
//!   (`flock`, advisory, exclusive) *before* it is read, so two identifications of the
//!   same spec run one after the other and each rewrites what the other wrote; the new
//!   text goes through a temporary file renamed over the spec, with the spec's mode and
//!   (where permitted) owner.
//!
//! A writer killed between creating and renaming its temporary file (SIGKILL, SIGXFSZ)
//! leaves that file behind under the name above; the next writer of the same target,
//! holding the lock that every live writer holds while its temporary file exists,
//! removes it.

use std::ffi::OsString;
use std::fs::{File, Metadata, OpenOptions, Permissions};
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use tempfile::{Builder, NamedTempFile};

/// Suffix of every temporary file (with `.<name>.` before six random characters).
const TMP_SUFFIX: &str = ".motorgen.tmp";
/// Random characters in a temporary file's name.
const TMP_RANDOM: usize = 6;

/// An I/O failure on one path.
#[derive(Debug)]
pub struct IoFailure {
    /// What was being done, e.g. "write".
    pub action: &'static str,
    /// The path as the user named it (or as derived from it).
    pub path: PathBuf,
    /// Why it failed.
    pub error: String,
}

impl IoFailure {
    fn new(action: &'static str, path: &Path, error: impl std::fmt::Display) -> IoFailure {
        IoFailure {
            action,
            path: path.to_path_buf(),
            error: error.to_string(),
        }
    }
}

impl std::fmt::Display for IoFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot {} {}: {}", self.action, self.path.display(), self.error)
    }
}

/// The directory of `path` (`.` for a bare file name).
fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

fn file_name(path: &Path) -> OsString {
    path.file_name().map_or_else(|| "out".into(), ToOwned::to_owned)
}

/// Whether `name` is a temporary file of target `target_name` (see [`TMP_SUFFIX`]).
fn is_tmp_of(name: &str, target_name: &str) -> bool {
    name.strip_prefix('.')
        .and_then(|n| n.strip_prefix(target_name))
        .and_then(|n| n.strip_prefix('.'))
        .and_then(|n| n.strip_suffix(TMP_SUFFIX))
        .is_some_and(|random| random.chars().count() == TMP_RANDOM)
}

/// Removes temporary files of `targets` left in `dir` by killed writers; the caller
/// holds the lock every writer of those targets holds while its temporary file exists.
fn remove_stale(dir: &Path, targets: &[OsString]) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if targets.iter().any(|t| is_tmp_of(&name, &t.to_string_lossy())) {
            // Best effort: a file that cannot be removed is left as it was.
            if std::fs::remove_file(entry.path()).is_ok() {
                crate::output::warn(format_args!(
                    "removed {} left by an interrupted motorgen",
                    entry.path().display()
                ));
            }
        }
    }
}

/// `bytes` complete and synced in a new temporary file beside `target`, with `perms`
/// (a new file: 0666 less the umask, as `create` gives).
fn stage(target: &Path, bytes: &[u8], perms: Option<Permissions>) -> io::Result<NamedTempFile> {
    let prefix = format!(".{}.", file_name(target).to_string_lossy());
    let mut builder = Builder::new();
    builder.prefix(&prefix).suffix(TMP_SUFFIX).rand_bytes(TMP_RANDOM);
    #[cfg(unix)]
    if perms.is_none() {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(parent(target))?;
    if let Some(p) = perms {
        tmp.as_file().set_permissions(p)?;
    }
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    Ok(tmp)
}

/// Renames `tmp` over `target` and syncs the directory (so the rename survives a crash).
fn commit(tmp: NamedTempFile, target: &Path) -> io::Result<()> {
    tmp.persist(target).map_err(|e| e.error)?;
    // Where a directory cannot be opened or synced the rename is still done.
    if let Ok(d) = File::open(parent(target)) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Writes every `(path, bytes)` of `files` (all in `dir`) whose bytes differ from what
/// the path holds, all or nothing (see the module doc). Returns, per file, whether it
/// was written (`false`: already held exactly these bytes).
pub fn write_set(dir: &Path, files: &[(PathBuf, Vec<u8>)]) -> Result<Vec<bool>, IoFailure> {
    std::fs::create_dir_all(dir).map_err(|e| IoFailure::new("create", dir, e))?;
    let lock = File::open(dir).map_err(|e| IoFailure::new("open", dir, e))?;
    lock.lock().map_err(|e| IoFailure::new("lock", dir, e))?;
    let names: Vec<OsString> = files.iter().map(|(p, _)| file_name(p)).collect();
    remove_stale(dir, &names);
    // A target that is not a file (a directory, say) would fail its rename after other
    // files were replaced: refuse it before anything is written. A symlink is written
    // through to its target.
    let mut targets = Vec::new();
    for (path, _) in files {
        let target = match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => {
                std::fs::canonicalize(path).map_err(|e| IoFailure::new("resolve", path, e))?
            }
            _ => path.clone(),
        };
        if std::fs::metadata(&target).is_ok_and(|m| !m.is_file()) {
            return Err(IoFailure::new(
                "write",
                path,
                "it exists and is not a regular file (no file was replaced)",
            ));
        }
        targets.push(target);
    }
    let mut staged = Vec::new();
    for ((path, bytes), target) in files.iter().zip(&targets) {
        if std::fs::read(target).is_ok_and(|old| old == *bytes) {
            staged.push(None);
            continue;
        }
        // An existing file keeps its mode; dropping `staged` on an error removes the
        // temporary files written so far.
        let perms = std::fs::metadata(target).ok().map(|m| m.permissions());
        let tmp = stage(target, bytes, perms)
            .map_err(|e| IoFailure::new("write", path, format!("{e} (no file was replaced)")))?;
        staged.push(Some(tmp));
    }
    let mut written = Vec::new();
    for (((path, _), target), tmp) in files.iter().zip(&targets).zip(staged) {
        match tmp {
            None => written.push(false),
            Some(tmp) => {
                commit(tmp, target).map_err(|e| {
                    let done: Vec<String> = files
                        .iter()
                        .zip(&written)
                        .filter(|(_, w)| **w)
                        .map(|((p, _), _)| p.display().to_string())
                        .collect();
                    let replaced = if done.is_empty() {
                        "none of the files was replaced".to_string()
                    } else {
                        format!("already replaced: {}", done.join(", "))
                    };
                    IoFailure::new("rename into", path, format!("{e} ({replaced})"))
                })?;
                written.push(true);
            }
        }
    }
    drop(lock);
    Ok(written)
}

/// `Err` (the message) when `--out DIR` names something other than a directory.
pub fn check_out_dir(dir: &Path) -> Result<(), String> {
    match std::fs::metadata(dir) {
        Ok(m) if !m.is_dir() => Err(format!(
            "error: --out {}: this is a file; --out needs a directory (created if missing)",
            dir.display()
        )),
        _ => Ok(()),
    }
}

/// Writes a new file at `path` atomically, failing if `path` exists (`motorgen new`).
pub fn create_new(path: &Path, bytes: &[u8]) -> Result<(), IoFailure> {
    let dir = parent(path);
    std::fs::create_dir_all(dir).map_err(|e| IoFailure::new("create", dir, e))?;
    let tmp = stage(path, bytes, None).map_err(|e| IoFailure::new("write", path, e))?;
    tmp.persist_noclobber(path)
        .map_err(|e| IoFailure::new("create", path, e.error))?;
    Ok(())
}

/// `a` and `b` are the same file (device and inode).
#[cfg(unix)]
fn same_file(a: &Metadata, b: &Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    (a.dev(), a.ino()) == (b.dev(), b.ino())
}

#[cfg(not(unix))]
fn same_file(_: &Metadata, _: &Metadata) -> bool {
    true
}

/// A spec opened for rewriting: locked, its text read under the lock.
pub struct LockedSpec {
    /// The path the user gave (for messages).
    pub path: PathBuf,
    /// The file written: `path` with every symlink resolved.
    target: PathBuf,
    /// The locked file (the lock is released when it is dropped).
    file: File,
    /// The spec's metadata when locked.
    meta: Metadata,
    /// The spec's bytes, read under the lock.
    pub bytes: Vec<u8>,
}

impl LockedSpec {
    /// Locks the spec at `path` (a symlink's final target) and reads it. Refuses a spec
    /// that is read-only (no write bit, even for root) or not writable by this user.
    pub fn open(path: &Path) -> Result<LockedSpec, IoFailure> {
        let target = std::fs::canonicalize(path).map_err(|e| IoFailure::new("read", path, e))?;
        loop {
            let meta = std::fs::metadata(&target).map_err(|e| IoFailure::new("read", path, e))?;
            if !meta.is_file() {
                return Err(IoFailure::new("rewrite", path, "it is not a regular file"));
            }
            if meta.permissions().readonly() {
                return Err(IoFailure::new(
                    "rewrite",
                    path,
                    "the spec is read-only; make it writable (chmod u+w) to let identify update it, or use --dry-run",
                ));
            }
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .open(&target)
                .map_err(|e| IoFailure::new("open for writing", path, e))?;
            file.lock().map_err(|e| IoFailure::new("lock", path, e))?;
            // Another writer may have renamed its new spec over the path while this one
            // waited for the lock of the old file: lock the file now at the path.
            let locked = file.metadata().map_err(|e| IoFailure::new("read", path, e))?;
            let now = std::fs::metadata(&target).map_err(|e| IoFailure::new("read", path, e))?;
            if !same_file(&locked, &now) {
                continue;
            }
            let mut bytes = Vec::new();
            file.read_to_end(&mut bytes)
                .map_err(|e| IoFailure::new("read", path, e))?;
            return Ok(LockedSpec {
                path: path.to_path_buf(),
                target,
                file,
                meta: locked,
                bytes,
            });
        }
    }

    /// Number of hard links to the spec (each other link keeps the old text after
    /// [`LockedSpec::replace`]).
    #[cfg(unix)]
    pub fn links(&self) -> u64 {
        use std::os::unix::fs::MetadataExt;
        self.meta.nlink()
    }

    #[cfg(not(unix))]
    pub fn links(&self) -> u64 {
        1
    }

    /// Replaces the spec's content by `bytes` (temporary file with the spec's mode and
    /// owner, synced, renamed over the target). Releases the lock.
    pub fn replace(self, bytes: &[u8]) -> Result<(), IoFailure> {
        let name = file_name(&self.target);
        remove_stale(parent(&self.target), &[name]);
        let fail = |e: io::Error| IoFailure::new("write", &self.path, e);
        let tmp = stage(&self.target, bytes, Some(self.meta.permissions())).map_err(fail)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let mine = tmp.as_file().metadata().map_err(fail)?;
            if (mine.uid(), mine.gid()) != (self.meta.uid(), self.meta.gid())
                && std::os::unix::fs::fchown(tmp.as_file(), Some(self.meta.uid()), Some(self.meta.gid())).is_err()
            {
                crate::output::warn(format_args!(
                    "{}: could not keep the owner {}:{}; the rewritten spec belongs to you",
                    self.path.display(),
                    self.meta.uid(),
                    self.meta.gid()
                ));
            }
        }
        commit(tmp, &self.target).map_err(fail)?;
        drop(self.file);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_are_recognised_exactly() {
        assert!(is_tmp_of(".m.toml.a1B2c3.motorgen.tmp", "m.toml"));
        assert!(!is_tmp_of(".m.toml.a1B2c.motorgen.tmp", "m.toml"));
        assert!(!is_tmp_of(".mm.toml.a1B2c3.motorgen.tmp", "m.toml"));
        assert!(!is_tmp_of("m.toml", "m.toml"));
        assert!(!is_tmp_of(".m.toml.a1B2c3.tmp", "m.toml"));
    }
}

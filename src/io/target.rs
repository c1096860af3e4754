//! Where a command writes, checked before any work is done. An output is never one of the
//! command's own inputs (compared by device and inode, so links and `./` spellings are caught),
//! never a directory or a block device. Standard output (`-`), character devices (`/dev/null`)
//! and FIFOs are written in place: no temporary file, no rename, no sidecar. A regular file is
//! written as `OUT.partial` and renamed only when complete; a sweep holds an exclusive lock on
//! that `.partial` for its whole life ([`PartialLock`]), so two sweeps never write one output.

use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    #[error("{what} {}: {message}", path.display())]
    Refused {
        what: String,
        path: PathBuf,
        message: String,
    },
    #[error("{}: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
}

fn refused(what: &str, path: &Path, message: impl Into<String>) -> TargetError {
    TargetError::Refused {
        what: what.into(),
        path: path.into(),
        message: message.into(),
    }
}

/// An output as the user named it, resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// `-`: standard output.
    Stdout,
    /// A character device or a FIFO (`/dev/null`, a named pipe): written in place.
    Stream(PathBuf),
    /// A regular file, existing or not (a symbolic link is followed to the file it names):
    /// written as `FILE.partial`, renamed when complete.
    File(PathBuf),
}

impl Target {
    /// Resolve `path` (the value of `-o`, `--plot`, ...; `what` names the flag in errors).
    pub fn resolve(what: &str, path: &Path) -> Result<Target, TargetError> {
        if path.as_os_str() == "-" {
            return Ok(Target::Stdout);
        }
        if path.as_os_str().is_empty() {
            return Err(refused(what, path, "is empty: expected a file name"));
        }
        let link = std::fs::symlink_metadata(path);
        let path = match &link {
            Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(path).map_err(|e| {
                refused(
                    what,
                    path,
                    format!("is a symbolic link whose target cannot be reached ({e})"),
                )
            })?,
            _ => path.to_path_buf(),
        };
        match std::fs::metadata(&path) {
            Ok(m) if m.is_dir() => Err(refused(
                what,
                &path,
                "is a directory: expected a file name (e.g. DIR/results.csv)",
            )),
            Ok(m) if m.is_file() => Ok(Target::File(path)),
            Ok(m) => {
                #[cfg(unix)]
                {
                    use std::os::unix::fs::FileTypeExt;
                    let t = m.file_type();
                    if t.is_char_device() || t.is_fifo() {
                        return Ok(Target::Stream(path));
                    }
                }
                let _ = m;
                Err(refused(
                    what,
                    &path,
                    "is neither a regular file, a character device nor a FIFO: pound does not write to it",
                ))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let dir = match path.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                    _ => PathBuf::from("."),
                };
                if !dir.is_dir() {
                    return Err(refused(
                        what,
                        &path,
                        format!("cannot be created: {} is not a directory", dir.display()),
                    ));
                }
                Ok(Target::File(path))
            }
            Err(error) => Err(TargetError::Io { path, error }),
        }
    }

    /// The path written (`-` for standard output).
    pub fn path(&self) -> &Path {
        match self {
            Target::Stdout => Path::new("-"),
            Target::Stream(p) | Target::File(p) => p,
        }
    }

    /// A regular file: written as `.partial`, renamed, labelled with sidecars.
    pub fn is_file(&self) -> bool {
        matches!(self, Target::File(_))
    }

    /// For a file, check that a file can be created beside it (so a long computation does not
    /// end in "permission denied"): a probe file is created and removed.
    pub fn probe(&self, what: &str) -> Result<(), TargetError> {
        let Target::File(p) = self else {
            return Ok(());
        };
        let probe = crate::io::paths::sibling(p, &format!(".probe-{}", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&probe) {
            Ok(_) => {
                let _ = std::fs::remove_file(&probe);
                Ok(())
            }
            Err(e) => Err(refused(what, p, format!("cannot be written: {e}"))),
        }
    }
}

/// Refuse `outputs` that are one of `inputs` or write one file twice ([`check_distinct`]),
/// counting every file a pound output may write beside a file target: its `.partial`, its
/// sidecar `.meta.toml` and its journal `.progress.toml`.
pub fn check_outputs(
    inputs: &[(&str, &Path)],
    outputs: &[(&str, &Target)],
) -> Result<(), TargetError> {
    for (what, t) in outputs {
        if t.is_file() {
            refuse_bookkeeping(what, t.path())?;
        }
    }
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    for (what, t) in outputs {
        files.push((what.to_string(), t.path().to_path_buf()));
        if t.is_file() {
            for (beside, name) in [
                (
                    crate::io::paths::partial_path as fn(&Path) -> PathBuf,
                    "partial file",
                ),
                (crate::io::paths::meta_path, "sidecar"),
                (crate::io::paths::progress_path, "journal"),
            ] {
                files.push((format!("{what}'s {name}"), beside(t.path())));
            }
        }
    }
    let files: Vec<(&str, &Path)> = files
        .iter()
        .map(|(w, p)| (w.as_str(), p.as_path()))
        .collect();
    check_distinct(inputs, &files)
}

/// Refuse an output named like the bookkeeping of another output that holds something: the
/// `.partial` of an unfinished sweep (its journal exists), that journal, or the sidecar of an
/// existing output (`pound sweep b.toml -o r.csv.partial` would replace the rows `--resume` of
/// r.csv continues).
fn refuse_bookkeeping(what: &str, path: &Path) -> Result<(), TargetError> {
    let name = path.as_os_str().to_string_lossy();
    let owner = |suffix: &str| name.strip_suffix(suffix).map(PathBuf::from);
    if let Some(out) = owner(".partial") {
        let journal = crate::io::paths::progress_path(&out);
        if journal.exists() {
            return Err(refused(
                what,
                path,
                format!(
                    "is the .partial of {}, where an unfinished sweep keeps its rows (its journal {} exists): choose another output, or finish that sweep with --resume",
                    out.display(),
                    journal.display()
                ),
            ));
        }
    }
    if let Some(out) = owner(".progress.toml") {
        if path.exists() {
            return Err(refused(
                what,
                path,
                format!(
                    "is the journal of an unfinished sweep of {}: choose another output",
                    out.display()
                ),
            ));
        }
    }
    if let Some(out) = owner(".meta.toml") {
        if out.exists() {
            return Err(refused(
                what,
                path,
                format!(
                    "is the sidecar of {}, which vouches for its rows: choose another output",
                    out.display()
                ),
            ));
        }
    }
    Ok(())
}

/// The identity of an existing file: device and inode on Unix, the canonical path elsewhere.
#[derive(Debug, Clone, PartialEq, Eq)]
enum FileId {
    #[cfg(unix)]
    Inode(u64, u64),
    #[cfg(not(unix))]
    Path(PathBuf),
}

fn file_id(path: &Path) -> Option<FileId> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path)
            .ok()
            .map(|m| FileId::Inode(m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        std::fs::canonicalize(path).ok().map(FileId::Path)
    }
}

fn is_char_device(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        std::fs::metadata(path).is_ok_and(|m| m.file_type().is_char_device())
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        false
    }
}

/// Refuse any output that is one of the inputs, or that another output also writes. `inputs`
/// and `outputs` are (what, path) pairs, e.g. ("the config", cfg) and ("-o", out); `outputs`
/// should list every file a command writes, sidecars and `.partial` files included. Character
/// devices are exempt (reading and writing `/dev/null` destroys nothing), and so is `-`.
pub fn check_distinct(
    inputs: &[(&str, &Path)],
    outputs: &[(&str, &Path)],
) -> Result<(), TargetError> {
    let outs: Vec<(&str, &Path, Option<FileId>)> = outputs
        .iter()
        .filter(|(_, p)| p.as_os_str() != "-" && !is_char_device(p))
        .map(|&(w, p)| (w, p, file_id(p)))
        .collect();
    let spelled = |p: &Path| {
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::canonicalize(dir)
            .ok()
            .map(|d| d.join(p.file_name().unwrap_or_default()))
    };
    for &(what_in, input) in inputs {
        if input.as_os_str() == "-" || is_char_device(input) {
            continue;
        }
        let Some(id) = file_id(input) else { continue };
        for (what_out, out, oid) in &outs {
            if oid.as_ref() == Some(&id) {
                return Err(refused(
                    what_out,
                    out,
                    format!(
                        "is the same file as {what_in} {}: writing it would destroy it; choose another output",
                        input.display()
                    ),
                ));
            }
        }
    }
    // The `.partial` of an input is where a sweep resumes it: never an output, whether it
    // exists yet or not.
    for &(what_in, input) in inputs {
        if input.as_os_str() == "-" || is_char_device(input) {
            continue;
        }
        let partial = crate::io::paths::partial_path(input);
        let partial_id = file_id(&partial);
        for (what_out, out, oid) in &outs {
            let same = match (&partial_id, oid) {
                (Some(x), Some(y)) => x == y,
                _ => spelled(out).is_some() && spelled(out) == spelled(&partial),
            };
            if same {
                return Err(refused(
                    what_out,
                    out,
                    format!(
                        "is the .partial of {what_in} {}, where an unfinished sweep keeps its rows: choose another output",
                        input.display()
                    ),
                ));
            }
        }
    }
    // Two outputs that name one file (an existing one by identity, a new one by its
    // absolute spelling).
    for (i, (wa, a, ia)) in outs.iter().enumerate() {
        for (wb, b, ib) in &outs[i + 1..] {
            let same = match (ia, ib) {
                (Some(x), Some(y)) => x == y,
                _ => spelled(a).is_some() && spelled(a) == spelled(b),
            };
            if same {
                return Err(refused(
                    wb,
                    b,
                    format!(
                        "is also written as {wa} {}: give them different names",
                        a.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// An exclusive lock on an output's `.partial` file, held for a sweep's whole life (an
/// advisory `flock`, released by the OS when the process ends, so a killed sweep leaves no
/// stale lock). A second sweep on the same output is refused while the first runs.
#[derive(Debug)]
pub struct PartialLock {
    file: File,
    path: PathBuf,
}

impl PartialLock {
    /// Open `partial` (created if missing, never truncated here) and lock it. Fails at once if
    /// another process holds the lock.
    pub fn acquire(partial: &Path) -> Result<PartialLock, TargetError> {
        // The path may be renamed away by the holder between our open and our lock: then the
        // lock is on a file that is no longer `partial`; open again.
        for _ in 0..8 {
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(partial)
                .map_err(|error| TargetError::Io {
                    path: partial.into(),
                    error,
                })?;
            lock_exclusive(&file).map_err(|held| {
                refused(
                    "the output",
                    partial,
                    format!(
                        "is being written by another running `pound sweep` ({held}); wait for it to end, or stop it and rerun with --resume"
                    ),
                )
            })?;
            if same_open_file(&file, partial) {
                return Ok(PartialLock {
                    file,
                    path: partial.into(),
                });
            }
        }
        Err(refused(
            "the output",
            partial,
            "keeps being replaced while it is opened: another process is writing it",
        ))
    }

    /// A second handle on the locked file (the lock lasts while any handle is open).
    pub fn file(&self) -> Result<File, TargetError> {
        self.file.try_clone().map_err(|error| TargetError::Io {
            path: self.path.clone(),
            error,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(unix)]
fn lock_exclusive(f: &File) -> Result<(), String> {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a file descriptor this process owns.
    let rc = unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if rc == 0 {
        Ok(())
    } else {
        let e = std::io::Error::last_os_error();
        Err(if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
            "it holds the lock".into()
        } else {
            format!("cannot lock it: {e}")
        })
    }
}

#[cfg(not(unix))]
fn lock_exclusive(_: &File) -> Result<(), String> {
    Ok(())
}

#[cfg(unix)]
fn same_open_file(f: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (f.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => (a.dev(), a.ino()) == (b.dev(), b.ino()),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_open_file(_: &File, _: &Path) -> bool {
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_that_are_inputs_are_refused_through_links() {
        let d = tempfile::tempdir().unwrap();
        let cfg = d.path().join("v.toml");
        std::fs::write(&cfg, "x").unwrap();
        let hard = d.path().join("hard.csv");
        std::fs::hard_link(&cfg, &hard).unwrap();
        let dotted = d.path().join(".").join("v.toml");
        for out in [&cfg, &hard, &dotted] {
            let e = check_distinct(&[("the config", &cfg)], &[("-o", out)]).unwrap_err();
            assert!(e.to_string().contains("same file as the config"), "{e}");
        }
        let other = d.path().join("r.csv");
        check_distinct(&[("the config", &cfg)], &[("-o", &other)]).unwrap();
        let e = check_distinct(&[], &[("-o", &other), ("--plot", &other)]).unwrap_err();
        assert!(e.to_string().contains("also written as -o"), "{e}");
        // /dev/null as both is harmless.
        check_distinct(
            &[("the input", Path::new("/dev/null"))],
            &[("-o", Path::new("/dev/null"))],
        )
        .unwrap();
    }

    #[test]
    fn targets_are_classified() {
        let d = tempfile::tempdir().unwrap();
        assert_eq!(
            Target::resolve("-o", Path::new("-")).unwrap(),
            Target::Stdout
        );
        assert!(matches!(
            Target::resolve("-o", Path::new("/dev/null")).unwrap(),
            Target::Stream(_)
        ));
        let e = Target::resolve("-o", d.path()).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
        let e = Target::resolve("-o", &d.path().join("no/such/r.csv")).unwrap_err();
        assert!(e.to_string().contains("is not a directory"), "{e}");
        let f = d.path().join("r.csv");
        assert_eq!(Target::resolve("-o", &f).unwrap(), Target::File(f.clone()));
        #[cfg(unix)]
        {
            std::fs::write(&f, "").unwrap();
            let link = d.path().join("link.csv");
            std::os::unix::fs::symlink(&f, &link).unwrap();
            let t = Target::resolve("-o", &link).unwrap();
            assert_eq!(t, Target::File(std::fs::canonicalize(&f).unwrap()));
        }
    }

    #[test]
    fn a_partial_is_locked_once() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("r.csv.partial");
        let a = PartialLock::acquire(&p).unwrap();
        let e = PartialLock::acquire(&p).unwrap_err();
        assert!(e.to_string().contains("another running"), "{e}");
        drop(a);
        PartialLock::acquire(&p).unwrap();
    }
}

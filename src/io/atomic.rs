//! Files that appear whole or not at all: written into a locked `OUT.partial`, fsynced and
//! renamed; streams (standard output, character devices, FIFOs) written in place.

pub use crate::io::paths::{partial_path, sibling};
use crate::io::target::{PartialLock, Target};
use std::fs::File;
use std::io::Write;
use std::path::Path;

/// Open a stream target for writing in place.
pub fn open_stream(target: &Target) -> std::io::Result<Box<dyn Write + Send>> {
    Ok(match target {
        Target::Stdout => Box::new(std::io::stdout()),
        Target::Stream(p) => Box::new(std::fs::OpenOptions::new().write(true).open(p)?),
        Target::File(p) => Box::new(File::create(p)?),
    })
}

/// Empty a `.partial` left by an earlier attempt (a zero-length or non-regular one, such as a
/// device, is left as it is).
pub fn empty(file: &File) -> std::io::Result<()> {
    if file.metadata()?.len() > 0 {
        file.set_len(0)?;
    }
    Ok(())
}

/// Refuse to write `path` where its `OUT.partial` holds an unfinished sweep's rows (running:
/// locked; resumable: its journal exists): every writer of a file output asks first.
pub fn refuse_unfinished(path: &Path) -> std::io::Result<()> {
    let journal = crate::io::paths::progress_path(path);
    if journal.exists() {
        return Err(std::io::Error::other(format!(
            "{} holds the rows of an unfinished sweep (see {}): finish it with --resume, or delete both",
            partial_path(path).display(),
            journal.display()
        )));
    }
    Ok(())
}

/// Write `bytes` to `path` atomically (temporary file, fsync, rename); standard output (`-`), a
/// character device or a FIFO is written in place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let target = Target::resolve("the output", path).map_err(std::io::Error::other)?;
    if !target.is_file() {
        let mut w = open_stream(&target)?;
        w.write_all(bytes)?;
        return w.flush();
    }
    let path = target.path();
    let tmp = partial_path(path);
    refuse_unfinished(path)?;
    let lock = PartialLock::acquire(&tmp).map_err(std::io::Error::other)?;
    let written = lock
        .file()
        .map_err(std::io::Error::other)
        .and_then(|mut f| {
            empty(&f)?;
            f.write_all(bytes)?;
            f.sync_all()
        });
    match written {
        Ok(()) => std::fs::rename(&tmp, path),
        Err(e) => {
            // Nothing half-written stays behind (a full disk, say).
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

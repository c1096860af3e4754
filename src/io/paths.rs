//! The names of an output's files beside it: `OUT.partial` while it is written, its sidecar
//! `OUT.meta.toml` and its journal `OUT.progress.toml` (the lowest file of `io`: every writer and
//! checker names them).

use std::path::{Path, PathBuf};

/// `path` with `suffix` appended to its name (`OUT` -> `OUT.partial`): the unfinished file and
/// the sidecars of an output.
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let mut p = path.as_os_str().to_owned();
    p.push(suffix);
    PathBuf::from(p)
}

/// `OUT.partial` for the output `OUT`: where it is written until it is complete.
pub fn partial_path(out: &Path) -> PathBuf {
    sibling(out, ".partial")
}

/// `OUT.meta.toml` for the output `OUT`.
pub fn meta_path(out: &Path) -> PathBuf {
    sibling(out, ".meta.toml")
}

/// `OUT.progress.toml` for the output `OUT`: the journal of an unfinished one.
pub fn progress_path(out: &Path) -> PathBuf {
    sibling(out, ".progress.toml")
}

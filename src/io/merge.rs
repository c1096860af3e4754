//! `pound merge`: shard outputs combined into one, after checking they are one sweep's and hold
//! every run exactly once, with the content their sidecars vouch for.

use crate::io::provenance::{meta_path, read_toml, write_toml, Meta, SidecarError};
use crate::io::target::Target;
use std::path::{Path, PathBuf};

/// Combine finished shard outputs into `out`: every input must carry the same fingerprint, the
/// inputs together must hold every run of the plan exactly once (checked row by row), and each
/// input's rows must hash to what its sidecar recorded (the block of rows that differs is named).
/// Rows are streamed in run order; `out` appears only when complete. Returns the number of rows.
pub fn merge(out: &Path, inputs: &[PathBuf]) -> Result<u64, SidecarError> {
    let fail = |path: &Path, message: String| SidecarError::Io {
        path: path.into(),
        message,
    };
    if inputs.is_empty() {
        return Err(fail(out, "nothing to merge: give the shard outputs".into()));
    }
    let target = Target::resolve("-o", out)?;
    let mut parts = Vec::new();
    for p in inputs {
        let m = meta_path(p);
        if !m.exists() {
            return Err(fail(
                p,
                format!(
                    "no {} beside it: not a finished `pound sweep` output (an unfinished one has a .progress.toml; finish it with --resume)",
                    m.display()
                ),
            ));
        }
        let meta: Meta = read_toml(&m)?;
        if meta.content.is_none() {
            return Err(fail(
                &m,
                "carries no content hash of its rows (written by an older pound?): rerun that shard"
                    .into(),
            ));
        }
        parts.push((p.clone(), meta));
    }
    {
        let metas: Vec<PathBuf> = parts.iter().map(|(p, _)| meta_path(p)).collect();
        let mut ins: Vec<(&str, &Path)> = parts
            .iter()
            .map(|(p, _)| ("the input", p.as_path()))
            .collect();
        ins.extend(metas.iter().map(|m| ("the sidecar", m.as_path())));
        crate::io::target::check_outputs(&ins, &[("-o", &target)])?;
    }
    let (first_path, first) = (&parts[0].0, parts[0].1.clone());
    for (p, m) in &parts[1..] {
        // The keys that differ are named where both sidecars record them.
        let there = meta_path(first_path).display().to_string();
        if let Some(d) = m.differs(&first, &there) {
            return Err(fail(
                p,
                format!(
                    "{}: not shards of one sweep",
                    d.differs_from(&format!("{}'s", first_path.display()))
                ),
            ));
        }
    }
    parts.sort_by_key(|(_, m)| (m.first_run, m.end_run));
    let mut next = 0;
    for (p, m) in &parts {
        if m.first_run > next {
            return Err(fail(
                p,
                format!(
                    "runs {next}..{} are in no input (a shard is missing)",
                    m.first_run
                ),
            ));
        }
        if m.first_run < next {
            return Err(fail(
                p,
                format!(
                    "runs {}..{} are also in another input (a shard given twice?)",
                    m.first_run,
                    next.min(m.end_run)
                ),
            ));
        }
        next = m.end_run;
    }
    if next != first.plan_runs {
        return Err(fail(
            out,
            format!(
                "runs {next}..{} are in no input (a shard is missing)",
                first.plan_runs
            ),
        ));
    }
    if parts.iter().any(|(_, m)| m.columns != first.columns) {
        return Err(fail(
            out,
            "the inputs hold different columns (--columns)".into(),
        ));
    }
    // One plan's runs from two kernels (shards written by pounds that chose differently, e.g.
    // a row of two one-storey buildings before and after it took the pair's kernels).
    if let Some((p, m)) = parts
        .iter()
        .find(|(_, m)| m.kernel.is_some() && first.kernel.is_some() && m.kernel != first.kernel)
    {
        return Err(fail(
            p,
            format!(
                "its runs took the {} kernel, another input's the {}: rerun the shards with one pound",
                m.kernel.as_deref().unwrap_or("?"),
                first.kernel.as_deref().unwrap_or("?")
            ),
        ));
    }
    let header = crate::io::csv::header_for(first.columns.as_deref());
    let header_line = crate::io::csv::header_line(&header);
    for (p, m) in &parts {
        let content = m.content.as_ref().expect("checked above");
        if content.rows != m.end_run - m.first_run {
            return Err(fail(
                p,
                format!(
                    "holds {} rows, its sidecar's run range {}..{} needs {}",
                    content.rows,
                    m.first_run,
                    m.end_run,
                    m.end_run - m.first_run
                ),
            ));
        }
    }
    let lock = if target.is_file() {
        crate::io::atomic::refuse_unfinished(target.path())
            .map_err(|e| fail(out, e.to_string()))?;
        Some(crate::io::target::PartialLock::acquire(
            &crate::io::atomic::partial_path(target.path()),
        )?)
    } else {
        None
    };
    let mut w = crate::io::csv::CsvOut::create(&target, lock.as_ref(), &header, Some(0))
        .map_err(|e| fail(out, e.to_string()))?;
    let written = (|| -> Result<crate::io::journal::Content, SidecarError> {
        // Each shard is verified against its sidecar in the pass that copies it; the output is
        // put in place only if every shard passed.
        for (p, m) in &parts {
            let content = m.content.as_ref().expect("checked above");
            crate::io::journal::verify_rows(p, &header_line, Some(m.first_run), content, |row| {
                w.write_encoded(row)
                    .map_err(|error| crate::io::journal::VerifyError::Io {
                        path: out.into(),
                        error,
                    })
            })?;
        }
        let mut backends: Vec<&str> = parts.iter().map(|(_, m)| m.backend.as_str()).collect();
        backends.sort();
        backends.dedup();
        let merged = |content: &crate::io::journal::Content| Meta {
            fingerprint: first.fingerprint.clone(),
            plan_runs: first.plan_runs,
            first_run: 0,
            end_run: first.plan_runs,
            shard: None,
            backend: backends.join("+"),
            kernel: first.kernel.clone(),
            columns: first.columns.clone(),
            content: Some(content.clone()),
            // Shards share the fingerprint, so the setting; the first one's target is kept.
            target_error: first.target_error,
            settings: first.settings.clone(),
        };
        let is_file = target.is_file();
        let (_, content) = w
            .finish(Some(first.plan_runs), |c| {
                if is_file {
                    write_toml(&meta_path(target.path()), &merged(c))
                        .map_err(std::io::Error::other)?;
                }
                Ok(())
            })
            .map_err(|e| fail(out, e.to_string()))?;
        Ok(content)
    })();
    match written {
        Ok(c) => Ok(c.rows),
        Err(e) => {
            if let Some(l) = &lock {
                let _ = std::fs::remove_file(l.path());
                if !target.path().exists() {
                    let _ = std::fs::remove_file(meta_path(target.path()));
                }
            }
            Err(e)
        }
    }
}

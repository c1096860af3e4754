//! Sweeps beyond one process: the plan fingerprint written beside every output, deterministic
//! cost-balanced shards (`--shard I/N`, for Slurm job arrays or Kubernetes Indexed Jobs), and the
//! metadata sidecar `OUT.meta.toml` that `pound merge` and `--resume` check.

use crate::plan::Plan;
use crate::target::Target;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// What an output was computed from: the validated plan (axes, scheme, settings), the records'
/// content, and the engine version. Two outputs may be combined or continued only when all three
/// match.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fingerprint {
    pub plan: String,
    pub records: String,
    pub engine: String,
}

fn hex(d: impl AsRef<[u8]>) -> String {
    d.as_ref()
        .iter()
        .take(16)
        .map(|b| format!("{b:02x}"))
        .collect()
}

impl Fingerprint {
    pub fn of(plan: &Plan) -> Fingerprint {
        let s = &plan.spec;
        // Debug prints every f64 exactly (shortest round-trip), so equal plans hash equally.
        let text = format!(
            "{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
            s.laws,
            s.formulas,
            s.e,
            s.k_linear,
            s.beta,
            s.intensities,
            s.building1,
            s.building2,
            s.gaps,
            s.scheme,
            s.tail,
            s.samples,
            s.records.iter().map(|r| &r.name).collect::<Vec<_>>(),
        );
        let mut rec = Sha256::new();
        for r in &s.records {
            rec.update(r.name.as_bytes());
            rec.update(r.dt.to_le_bytes());
            rec.update(r.t0.to_le_bytes());
            rec.update((r.accel.len() as u64).to_le_bytes());
            for a in &r.accel {
                rec.update(a.to_le_bytes());
            }
        }
        Fingerprint {
            plan: hex(Sha256::digest(text.as_bytes())),
            records: hex(rec.finalize()),
            engine: env!("CARGO_PKG_VERSION").to_string(),
        }
    }

    /// The first part that differs from `other`, in words; None if they match.
    pub fn differs(&self, other: &Fingerprint) -> Option<&'static str> {
        if self.engine != other.engine {
            Some("the engine version")
        } else if self.records != other.records {
            Some("the records (their content)")
        } else if self.plan != other.plan {
            Some("the config (the validated plan)")
        } else {
            None
        }
    }
}

/// Shard `i` of `n` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// `I/N` with `0 <= I < N`.
    pub fn parse(s: &str) -> Option<Shard> {
        let (i, n) = s.split_once('/')?;
        let (index, count) = (i.trim().parse().ok()?, n.trim().parse().ok()?);
        (count > 0 && index < count).then_some(Shard { index, count })
    }
}

/// The runs of shard `shard`: contiguous ranges cut where the cumulative estimated cost reaches
/// `k / N` of the total. A run's cost is its number of record intervals (record plus tail): the
/// free stepping that every run pays; contact work is not known before the run. Shards of one
/// plan tile `0..len` exactly. Each cut is a binary search over [`Plan::cost_before`], so a
/// shard of 1e8 runs is planned in microseconds.
pub fn shard_range(plan: &Plan, shard: Shard) -> Range<u64> {
    let n = plan.len();
    let costs: Vec<u64> = plan
        .spec
        .records
        .iter()
        .map(|r| r.forcing(1.0, plan.spec.tail).intervals().max(1) as u64)
        .collect();
    let total = plan.cost_before(n, &costs);
    // Cut k: the first run i whose preceding cost reaches k / N of the total (exact integers).
    let cut = |k: u64| -> u64 {
        if k == 0 {
            return 0;
        }
        if k >= shard.count {
            return n;
        }
        let target = total * k as u128;
        let (mut lo, mut hi) = (0u64, n);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if plan.cost_before(mid, &costs) * shard.count as u128 >= target {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        lo
    };
    cut(shard.index)..cut(shard.index + 1)
}

/// The sidecar of a finished output (`OUT.meta.toml`): what it was computed from and which runs
/// it holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    pub fingerprint: Fingerprint,
    /// Runs in the whole plan.
    pub plan_runs: u64,
    pub first_run: u64,
    pub end_run: u64,
    pub shard: Option<Shard>,
    /// Where the runs were integrated: `cpu`, `gpu-f32` or `gpu-f64` (a resumed sweep must keep
    /// it; merged shards may mix them).
    pub backend: String,
    /// The columns written, when `--columns` chose them (all otherwise).
    #[serde(default)]
    pub columns: Option<Vec<String>>,
    /// What the file holds (rows and hashes): `pound merge` and the studies check it.
    #[serde(default)]
    pub content: Option<crate::journal::Content>,
}

/// `OUT.meta.toml` for the output `OUT`.
pub fn meta_path(out: &Path) -> PathBuf {
    crate::output::sibling(out, ".meta.toml")
}

/// Progress of an unfinished output (`OUT.progress.toml`), rewritten atomically after each
/// chunk's rows are on disk: the first `done` runs of the range are in the first `bytes` bytes of
/// `OUT.partial`, whose SHA-256 is `sha256`; anything after that is a half-written chunk. A hint,
/// never the truth: `--resume` re-reads and checks those bytes before it continues.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    pub meta: Meta,
    pub done: u64,
    pub bytes: u64,
    #[serde(default)]
    pub sha256: String,
}

pub fn progress_path(out: &Path) -> PathBuf {
    crate::output::sibling(out, ".progress.toml")
}

#[derive(Debug, thiserror::Error)]
pub enum ShardError {
    #[error("{}: {message}", path.display())]
    Io { path: PathBuf, message: String },
    #[error(transparent)]
    Verify(#[from] crate::journal::VerifyError),
    #[error(transparent)]
    Target(#[from] crate::target::TargetError),
}

/// Read a TOML sidecar.
pub fn read_toml<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, ShardError> {
    let text = std::fs::read_to_string(path).map_err(|e| ShardError::Io {
        path: path.into(),
        message: e.to_string(),
    })?;
    toml::from_str(&text).map_err(|e| ShardError::Io {
        path: path.into(),
        message: format!("not a valid sidecar: {e}"),
    })
}

/// Write a TOML sidecar atomically.
pub fn write_toml<T: Serialize>(path: &Path, v: &T) -> Result<(), ShardError> {
    let text = toml::to_string(v).map_err(|e| ShardError::Io {
        path: path.into(),
        message: e.to_string(),
    })?;
    crate::output::write_atomic(path, text.as_bytes()).map_err(|e| ShardError::Io {
        path: path.into(),
        message: e.to_string(),
    })
}

/// Combine finished shard outputs into `out`: every input must carry the same fingerprint, the
/// inputs together must hold every run of the plan exactly once (checked row by row), and each
/// input's rows must hash to what its sidecar recorded (the block of rows that differs is named).
/// Rows are streamed in run order; `out` appears only when complete. Returns the number of rows.
pub fn merge(out: &Path, inputs: &[PathBuf]) -> Result<u64, ShardError> {
    let fail = |path: &Path, message: String| ShardError::Io {
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
        crate::target::check_outputs(&ins, &[("-o", &target)])?;
    }
    let (first_path, first) = (&parts[0].0, parts[0].1.clone());
    for (p, m) in &parts[1..] {
        if let Some(what) = m.fingerprint.differs(&first.fingerprint) {
            return Err(fail(
                p,
                format!(
                    "{what} differs from {}'s: not shards of one sweep",
                    first_path.display()
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
    let header = crate::output::header_for(first.columns.as_deref());
    let header_line = crate::output::header_line(&header);
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
        Some(crate::target::PartialLock::acquire(
            &crate::output::sibling(target.path(), ".partial"),
        )?)
    } else {
        None
    };
    let mut w = crate::output::CsvOut::create(&target, lock.as_ref(), &header, Some(0))
        .map_err(|e| fail(out, e.to_string()))?;
    let written = (|| -> Result<crate::journal::Content, ShardError> {
        // Each shard is verified against its sidecar in the pass that copies it; the output is
        // put in place only if every shard passed.
        for (p, m) in &parts {
            let content = m.content.as_ref().expect("checked above");
            crate::journal::verify_rows(p, &header_line, Some(m.first_run), content, |row| {
                w.write_encoded(row)
                    .map_err(|error| crate::journal::VerifyError::Io {
                        path: out.into(),
                        error,
                    })
            })?;
        }
        let mut backends: Vec<&str> = parts.iter().map(|(_, m)| m.backend.as_str()).collect();
        backends.sort();
        backends.dedup();
        let merged = |content: &crate::journal::Content| Meta {
            fingerprint: first.fingerprint.clone(),
            plan_runs: first.plan_runs,
            first_run: 0,
            end_run: first.plan_runs,
            shard: None,
            backend: backends.join("+"),
            columns: first.columns.clone(),
            content: Some(content.clone()),
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

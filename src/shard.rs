//! Sweeps beyond one process: the plan fingerprint written beside every output, deterministic
//! cost-balanced shards (`--shard I/N`, for Slurm job arrays or Kubernetes Indexed Jobs), and the
//! metadata sidecar `OUT.meta.toml` that `pound merge` and `--resume` check.

use crate::plan::Plan;
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

/// The runs of shard `shard`: contiguous ranges cut where the cumulative estimated cost crosses
/// `k / N` of the total. A run's cost is its number of record intervals (record plus tail): the
/// free stepping that every run pays; contact work is not known before the run. Shards of one
/// plan tile `0..len` exactly.
pub fn shard_range(plan: &Plan, shard: Shard) -> Range<u64> {
    let n = plan.len();
    let costs: Vec<f64> = plan
        .spec
        .records
        .iter()
        .map(|r| r.forcing(1.0, plan.spec.tail).intervals().max(1) as f64)
        .collect();
    let cost = |i: u64| costs[plan.run(i).record];
    let total: f64 = (0..n).map(cost).sum();
    // Cut k is the first run at which the cost so far reaches k / N of the total; both cuts of
    // this shard come from one pass.
    let target = |k: u64| total * k as f64 / shard.count as f64;
    let (lo, hi) = (shard.index, shard.index + 1);
    let mut start = (lo == 0).then_some(0);
    let mut end = (hi >= shard.count).then_some(n);
    let mut acc = 0.0;
    for i in 0..n {
        if start.is_none() && acc >= target(lo) {
            start = Some(i);
        }
        if end.is_none() && acc >= target(hi) {
            end = Some(i);
        }
        if start.is_some() && end.is_some() {
            break;
        }
        acc += cost(i);
    }
    start.unwrap_or(n)..end.unwrap_or(n)
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
}

/// `OUT.meta.toml` for the output `OUT`.
pub fn meta_path(out: &Path) -> PathBuf {
    crate::output::sibling(out, ".meta.toml")
}

/// Progress of an unfinished output (`OUT.progress.toml`), rewritten atomically after each
/// chunk's rows are on disk: the first `done` runs of the range are in the first `bytes` bytes of
/// `OUT.partial`; anything after that is a half-written chunk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    pub meta: Meta,
    pub done: u64,
    pub bytes: u64,
}

pub fn progress_path(out: &Path) -> PathBuf {
    crate::output::sibling(out, ".progress.toml")
}

#[derive(Debug, thiserror::Error)]
pub enum ShardError {
    #[error("{}: {message}", path.display())]
    Io { path: PathBuf, message: String },
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

/// Combine finished shard outputs into `out`: every input must carry the same fingerprint and
/// the inputs together must hold every run of the plan exactly once (checked row by row). Rows
/// are streamed in run order; `out` appears only when complete. Returns the number of rows.
pub fn merge(out: &Path, inputs: &[PathBuf]) -> Result<u64, ShardError> {
    let fail = |path: &Path, message: String| ShardError::Io {
        path: path.into(),
        message,
    };
    if inputs.is_empty() {
        return Err(fail(out, "nothing to merge: give the shard outputs".into()));
    }
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
        parts.push((p.clone(), meta));
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
    let mut w =
        crate::output::CsvOut::create_with(out, &header).map_err(|e| fail(out, e.to_string()))?;
    let mut rows = 0u64;
    for (p, m) in &parts {
        let mut r = csv::Reader::from_path(p).map_err(|e| fail(p, e.to_string()))?;
        let h: Vec<String> = r
            .headers()
            .map_err(|e| fail(p, e.to_string()))?
            .iter()
            .map(String::from)
            .collect();
        if h != header {
            return Err(fail(
                p,
                "its columns differ from its sidecar's (not a `pound sweep` CSV?)".into(),
            ));
        }
        let mut expect = m.first_run;
        for (line, rec) in r.records().enumerate() {
            let rec = rec.map_err(|e| fail(p, e.to_string()))?;
            let run: Option<u64> = rec.get(0).and_then(|x| x.parse().ok());
            if run != Some(expect) || expect >= m.end_run {
                return Err(fail(
                    p,
                    format!(
                        "line {}: run {} where run {expect} was expected (rows missing, repeated or out of order)",
                        line + 2,
                        rec.get(0).unwrap_or("")
                    ),
                ));
            }
            w.write(std::iter::once(rec.iter().map(String::from).collect()))
                .map_err(|e| fail(out, e.to_string()))?;
            expect += 1;
            rows += 1;
        }
        if expect != m.end_run {
            return Err(fail(
                p,
                format!("ends at run {expect}, its sidecar says {}", m.end_run),
            ));
        }
    }
    let mut backends: Vec<&str> = parts.iter().map(|(_, m)| m.backend.as_str()).collect();
    backends.sort();
    backends.dedup();
    let merged = Meta {
        fingerprint: first.fingerprint.clone(),
        plan_runs: first.plan_runs,
        first_run: 0,
        end_run: first.plan_runs,
        shard: None,
        backend: backends.join("+"),
        columns: first.columns.clone(),
    };
    write_toml(&meta_path(out), &merged)?;
    w.finish().map_err(|e| fail(out, e.to_string()))?;
    Ok(rows)
}

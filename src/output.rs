//! CSV rows for runs, written to `<out>.partial` as chunks finish and renamed to `<out>` only
//! when the sweep is complete (after flush and fsync). A failed sweep leaves the `.partial`
//! file with every finished row.

use crate::model::RunOutput;
use crate::plan::{Intensity, Plan, RunSpec};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Swept parameters, then outputs. Units are in the names.
pub const COLUMNS: [&str; 28] = [
    "run",
    "law",
    "formula",
    "e",
    "impact_damping",
    "k_n_per_m",
    "beta_n_per_m1_5",
    "record",
    "target_pga_g",
    "scale_factor",
    "pga_g",
    "m1_kg",
    "t1_s",
    "xi1",
    "m2_kg",
    "t2_s",
    "xi2",
    "gap_m",
    "sample",
    "status",
    "impacts",
    "peak_force_n",
    "peak_penetration_m",
    "peak_u1_m",
    "peak_u2_m",
    "impact_velocity_m_s",
    "first_impact_s",
    "contact_time_s",
];

/// Output columns after the status (kept in one place for readers of the CSV). The last three,
/// the energy balance, are empty unless it was asked for (`run.energy`, `--energy`).
pub const EXTRA_COLUMNS: [&str; 5] = [
    "dissipated_energy_j",
    "substeps",
    "input_energy_j",
    "damping_energy_j",
    "energy_residual",
];

/// Shortest round-trip text; scientific notation outside [1e-4, 1e15) so tiny values stay short.
fn num(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && !(1e-4..1e15).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The fields of one row, in `COLUMNS` + `EXTRA_COLUMNS` order.
pub fn row(plan: &Plan, spec: &RunSpec, out: &RunOutput) -> Vec<String> {
    let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
    let hertz = spec.law.is_hertzian();
    vec![
        spec.index.to_string(),
        spec.law.key().to_string(),
        spec.formula
            .map(|f| f.key().to_string())
            .unwrap_or_default(),
        opt(spec.e),
        if spec.law.is_damped() {
            num(spec.damping)
        } else {
            String::new()
        },
        if hertz {
            String::new()
        } else {
            num(spec.stiffness)
        },
        if hertz {
            num(spec.stiffness)
        } else {
            String::new()
        },
        plan.spec.records[spec.record].name.clone(),
        match spec.intensity {
            Intensity::PgaG(g) => num(g),
            Intensity::Scale(_) => String::new(),
        },
        num(spec.scale),
        num(spec.pga_g),
        num(spec.m1),
        num(spec.t1),
        num(spec.xi1),
        num(spec.m2),
        num(spec.t2),
        num(spec.xi2),
        num(spec.gap),
        spec.sample.map(|s| s.to_string()).unwrap_or_default(),
        out.status.key().to_string(),
        out.impacts.to_string(),
        num(out.peak_force),
        num(out.peak_penetration),
        num(out.peak_u1),
        num(out.peak_u2),
        num(out.impact_velocity),
        opt(out.first_impact),
        num(out.contact_time),
        num(out.dissipated_energy),
        out.substeps.to_string(),
        opt(out.energy.map(|e| e.input)),
        opt(out.energy.map(|e| e.damping)),
        opt(out.energy.map(|e| e.residual)),
    ]
}

/// Indices into [`header`] of `names` (`run` first, added if missing), or the first name that is
/// not a column.
pub fn select(names: &[String]) -> Result<Vec<usize>, String> {
    let h = header();
    let mut idx = vec![0];
    for n in names {
        let i = h.iter().position(|c| c == n).ok_or_else(|| n.clone())?;
        if !idx.contains(&i) {
            idx.push(i);
        }
    }
    Ok(idx)
}

/// All column names.
pub fn header() -> Vec<&'static str> {
    COLUMNS
        .iter()
        .chain(EXTRA_COLUMNS.iter())
        .copied()
        .collect()
}

/// A CSV file that appears under its final name only when complete.
pub struct CsvOut {
    path: PathBuf,
    partial: PathBuf,
    w: BufWriter<File>,
}

/// CSV lines of records (quoted as the `csv` crate quotes them).
fn lines<I, R>(records: I) -> Vec<u8>
where
    I: IntoIterator<Item = R>,
    R: IntoIterator,
    R::Item: AsRef<[u8]>,
{
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    for r in records {
        w.write_record(r).expect("writing to memory");
    }
    w.into_inner().expect("writing to memory")
}

impl CsvOut {
    pub fn create(path: &Path) -> std::io::Result<CsvOut> {
        CsvOut::create_with(path, &header())
    }

    /// As [`CsvOut::create`], with the header `columns`.
    pub fn create_with(path: &Path, columns: &[&str]) -> std::io::Result<CsvOut> {
        let partial = sibling(path, ".partial");
        let file = File::create(&partial)?;
        let mut w = BufWriter::new(file);
        w.write_all(&lines([columns]))?;
        Ok(CsvOut {
            path: path.into(),
            partial,
            w,
        })
    }

    /// Continue `path`'s `.partial` file, whose first `bytes` bytes hold the header and the rows
    /// of finished chunks: anything after them (a chunk cut off mid-write) is truncated.
    pub fn resume(path: &Path, bytes: u64) -> std::io::Result<CsvOut> {
        let partial = sibling(path, ".partial");
        let file = std::fs::OpenOptions::new().write(true).open(&partial)?;
        let len = file.metadata()?.len();
        if len < bytes {
            return Err(std::io::Error::other(format!(
                "{} holds {len} bytes, fewer than the {bytes} its progress file records: it was changed or truncated; delete it and its .progress.toml to start over",
                partial.display()
            )));
        }
        file.set_len(bytes)?;
        file.sync_all()?;
        let mut file = file;
        std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0))?;
        let w = BufWriter::new(file);
        Ok(CsvOut {
            path: path.into(),
            partial,
            w,
        })
    }

    pub fn partial_path(&self) -> &Path {
        &self.partial
    }

    /// Push everything written to the disk (fsync) and return the file's length.
    pub fn sync(&mut self) -> std::io::Result<u64> {
        self.w.flush()?;
        let f = self.w.get_ref();
        f.sync_data()?;
        Ok(f.metadata()?.len())
    }

    /// Append rows and push them to the OS, so a crash keeps them in the `.partial` file.
    pub fn write(&mut self, rows: impl IntoIterator<Item = Vec<String>>) -> std::io::Result<()> {
        self.write_encoded(&lines(rows))
    }

    /// Append rows already encoded as CSV lines ([`encode_csv`]).
    pub fn write_encoded(&mut self, lines: &[u8]) -> std::io::Result<()> {
        self.w.write_all(lines)?;
        self.w.flush()
    }

    /// Flush, fsync and rename to the final name.
    pub fn finish(self) -> std::io::Result<PathBuf> {
        let file = self.w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&self.partial, &self.path)?;
        Ok(self.path)
    }
}

/// The cells of `columns` (all of them without).
pub fn pick(row: Vec<String>, columns: Option<&[usize]>) -> Vec<String> {
    match columns {
        Some(c) => c.iter().map(|&i| row[i].clone()).collect(),
        None => row,
    }
}

/// The cells of each run's row (`columns` as in [`pick`]), formatted in parallel.
pub fn cells(
    plan: &Plan,
    rows: &[(RunSpec, RunOutput)],
    columns: Option<&[usize]>,
) -> Vec<Vec<String>> {
    use rayon::prelude::*;
    rows.par_iter()
        .map(|(s, o)| pick(row(plan, s, o), columns))
        .collect()
}

/// Rows as CSV lines (`columns` as in [`pick`]): formatted in parallel blocks, the same bytes
/// as writing them one by one. Formatting, not the GPU, limited a 1e6-run sweep on an H100
/// (BENCHMARKS.md).
pub fn encode_csv(
    plan: &Plan,
    rows: &[(RunSpec, RunOutput)],
    columns: Option<&[usize]>,
) -> Vec<u8> {
    use rayon::prelude::*;
    let blocks: Vec<Vec<u8>> = rows
        .par_chunks(512)
        .map(|block| lines(block.iter().map(|(s, o)| pick(row(plan, s, o), columns))))
        .collect();
    blocks.concat()
}

/// `path` with `suffix` appended to its name (`OUT` -> `OUT.partial`): the unfinished file and
/// the sidecars of an output.
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let mut p = path.as_os_str().to_owned();
    p.push(suffix);
    PathBuf::from(p)
}

/// The column names of an output: those `--columns` chose, or all of [`header`].
pub fn header_for(columns: Option<&[String]>) -> Vec<&str> {
    match columns {
        Some(c) => c.iter().map(String::as_str).collect(),
        None => header(),
    }
}

/// Write `bytes` to `path` atomically (temporary file, fsync, rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = sibling(path, ".partial");
    let written = File::create(&tmp).and_then(|mut f| {
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

//! `[[record]]` decoded: each record read from its file (or synthesised), windowed and named.

use crate::config::read::missing_record;
use crate::config::sections::RawRecord;
use crate::record::{
    read_record, synthetic, Format, ReadOptions, Record, RecordError, SyntheticSpec, Units,
};
use std::path::Path;

pub(crate) enum LoadError {
    Invalid(String),
    Record(RecordError),
}

pub(crate) fn load_record(r: &RawRecord, base: &Path, records: &Path) -> Result<Record, LoadError> {
    let sources = [r.file.is_some(), r.path.is_some(), r.synthetic.is_some()]
        .iter()
        .filter(|x| **x)
        .count();
    if sources != 1 {
        return Err(LoadError::Invalid(
            "give exactly one of file, path or synthetic".into(),
        ));
    }
    let mut rec = if let Some(s) = &r.synthetic {
        if r.format.is_some() || r.units.is_some() || r.dt_s.is_some() || r.skip_lines.is_some() {
            return Err(LoadError::Invalid("format, units, dt_s and skip_lines apply to files, not synthetic records (use synthetic.dt_s)".into()));
        }
        let d = SyntheticSpec::default();
        let spec = SyntheticSpec {
            seed: s.seed,
            duration: s.duration_s.unwrap_or(d.duration),
            dt: s.dt_s.unwrap_or(d.dt),
            pga_g: s.pga_g.unwrap_or(d.pga_g),
            fg_hz: s.fg_hz.unwrap_or(d.fg_hz),
            zeta_g: s.zeta_g.unwrap_or(d.zeta_g),
        };
        synthetic(&spec).map_err(LoadError::Record)?
    } else {
        let file = r
            .file_path(base, records)
            .expect("one source checked above");
        if let Some(name) = &r.file {
            if !file.exists() {
                return Err(LoadError::Invalid(missing_record(name, records)));
            }
        }
        let format = match &r.format {
            Some(f) => Format::parse(f).ok_or_else(|| {
                LoadError::Invalid(format!("format `{f}`: expected {}", Format::KEYS))
            })?,
            None => Format::Auto,
        };
        let units = match &r.units {
            Some(u) => Some(Units::parse(u).ok_or_else(|| {
                LoadError::Invalid(format!("units `{u}`: expected {}", Units::KEYS))
            })?),
            None => None,
        };
        let opts = ReadOptions {
            format,
            units,
            dt: r.dt_s,
            skip_lines: r.skip_lines.unwrap_or(0),
        };
        read_record(&file, &opts).map_err(LoadError::Record)?
    };
    if let Some(w) = r.window_s {
        rec = rec.windowed(w).map_err(|m| {
            LoadError::Invalid(format!(
                "window_s = [{}, {}]: {m}",
                crate::plan::limits::show(w[0]),
                crate::plan::limits::show(w[1])
            ))
        })?;
    }
    if let Some(n) = &r.name {
        rec.name = n.clone();
    }
    Ok(rec)
}

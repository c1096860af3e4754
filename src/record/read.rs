//! Readers for PEER AT2 (old and NGA-West2 headers), free-format value files with a given `dt`,
//! and two-column time/acceleration files. The quirks handled here are listed in
//! `shared/records/SOURCES.md`: NPTS/DT line variants and positions, Fortran numbers without a
//! leading zero, CR CR LF line ends, whitespace-only and padded lines, trailing text.

use super::{Record, RecordError, G};
use std::path::{Path, PathBuf};

/// Acceleration units of a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    G,
    MPerS2,
    CmPerS2,
}

impl Units {
    pub fn to_si(self) -> f64 {
        match self {
            Units::G => G,
            Units::MPerS2 => 1.0,
            Units::CmPerS2 => 0.01,
        }
    }

    pub fn parse(s: &str) -> Option<Units> {
        match s.trim().to_ascii_lowercase().as_str() {
            "g" => Some(Units::G),
            "m/s2" | "m/s^2" | "mps2" => Some(Units::MPerS2),
            "cm/s2" | "cm/s^2" | "gal" => Some(Units::CmPerS2),
            _ => None,
        }
    }

    pub const KEYS: &'static str = "g, m/s2 or cm/s2";

    /// The key that names these units in a config (`units =`).
    pub fn key(self) -> &'static str {
        match self {
            Units::G => "g",
            Units::MPerS2 => "m/s2",
            Units::CmPerS2 => "cm/s2",
        }
    }
}

/// File layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Detect: a NPTS/DT header means AT2, rows of two increasing-time numbers mean two-column,
    /// anything else is a value file (which needs `dt`).
    Auto,
    At2,
    /// Whitespace-separated values, any number per line, uniform `dt` given by the caller.
    Values,
    /// `time accel` rows separated by whitespace, tab or comma.
    TwoColumn,
}

impl Format {
    pub fn parse(s: &str) -> Option<Format> {
        match s.trim().to_ascii_lowercase().replace('-', "_").as_str() {
            "auto" => Some(Format::Auto),
            "at2" | "peer" => Some(Format::At2),
            "values" | "one_column" | "single_column" => Some(Format::Values),
            "two_column" | "time_accel" | "timeacc" => Some(Format::TwoColumn),
            _ => None,
        }
    }

    pub const KEYS: &'static str = "auto, at2, values or two_column";
}

/// How to read a record file.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    pub format: Format,
    /// Units override; AT2 defaults to what the header says (g if it says nothing), other
    /// formats to g.
    pub units: Option<Units>,
    /// Sample interval for value files (required there; checked against AT2/two-column files).
    pub dt: Option<f64>,
    /// Lines to skip before anything is parsed (e.g. 3 for the ';'-commented KOBE_NS file).
    pub skip_lines: usize,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            format: Format::Auto,
            units: None,
            dt: None,
            skip_lines: 0,
        }
    }
}

/// The largest record file read (256 MiB).
pub const MAX_RECORD_BYTES: u64 = 256 << 20;

/// Read and parse a record file.
pub fn read_record(path: &Path, opts: &ReadOptions) -> Result<Record, RecordError> {
    let io = |error| RecordError::Io {
        path: path.into(),
        error,
    };
    // Bounded, so a path such as /dev/zero is an error, not a machine out of memory.
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(
        &mut std::io::Read::take(std::fs::File::open(path).map_err(io)?, MAX_RECORD_BYTES + 1),
        &mut bytes,
    )
    .map_err(io)?;
    if bytes.len() as u64 > MAX_RECORD_BYTES {
        return Err(RecordError::Invalid {
            path: path.into(),
            message: format!(
                "larger than {} MiB: not a ground-motion record as pound reads one (real records are under 1 MiB)",
                MAX_RECORD_BYTES >> 20
            ),
        });
    }
    let text = String::from_utf8_lossy(&bytes);
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    parse_record(&text, path, name, opts)
}

/// Parse record text; `path` is only used in error messages.
pub fn parse_record(
    text: &str,
    path: &Path,
    name: String,
    opts: &ReadOptions,
) -> Result<Record, RecordError> {
    // A UTF-8 byte-order mark (Windows editors write one) is not part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Split on LF and drop every trailing CR, so CR LF and CR CR LF both end up clean; numbering
    // follows the LF lines a text editor shows.
    let lines: Vec<(usize, &str)> = text
        .split('\n')
        .enumerate()
        .skip(opts.skip_lines)
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .collect();
    let ctx = Ctx {
        path: path.to_path_buf(),
    };
    if let Some(dt) = opts.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(ctx.invalid(format!(
                "dt must be a positive number of seconds, got {}",
                crate::show(dt)
            )));
        }
    }
    let format = match opts.format {
        Format::Auto => detect(&lines),
        f => f,
    };
    let (dt, t0, values, header_units) = match format {
        Format::At2 => parse_at2(&lines, &ctx)?,
        Format::TwoColumn => parse_two_column(&lines, &ctx)?,
        Format::Values | Format::Auto => {
            let Some(dt) = opts.dt else {
                return Err(ctx.invalid(
                    "this file has no NPTS/DT header and no time column: give its sample interval (dt_s in a config, --dt on the command line)".into(),
                ));
            };
            (dt, 0.0, parse_values(&lines, &ctx)?, None)
        }
    };
    if let (Some(given), Format::At2 | Format::TwoColumn) = (opts.dt, format) {
        if (given - dt).abs() > 1e-6 * dt {
            return Err(ctx.invalid(format!(
                "the file says dt = {} s but {} s was given",
                crate::show(dt),
                crate::show(given)
            )));
        }
    }
    if values.len() < 2 {
        return Err(ctx.invalid(format!(
            "a record needs at least 2 samples, found {}",
            values.len()
        )));
    }
    // Units the header states are the file's own: a contradicting `units` is refused, as a
    // contradicting `dt` is (a units slip scales every run by 9.81, 100 or 981).
    if let (Some(given), Some(stated)) = (opts.units, header_units) {
        if given != stated {
            return Err(ctx.invalid(format!(
                "the file's header says its values are in {} but units = {} was given (leave units out to use the header's)",
                stated.key(),
                given.key()
            )));
        }
    }
    let units = opts.units.or(header_units).unwrap_or(Units::G);
    let f = units.to_si();
    Ok(Record {
        name,
        dt,
        t0,
        accel: values.into_iter().map(|a| a * f).collect(),
    })
}

struct Ctx {
    path: PathBuf,
}

impl Ctx {
    fn parse(&self, line: usize, message: String) -> RecordError {
        RecordError::Parse {
            path: self.path.clone(),
            line,
            message,
        }
    }
    fn invalid(&self, message: String) -> RecordError {
        RecordError::Invalid {
            path: self.path.clone(),
            message,
        }
    }
}

fn detect(lines: &[(usize, &str)]) -> Format {
    if lines
        .iter()
        .take(12)
        .any(|(_, l)| npts_dt_numbers(l).is_some())
    {
        return Format::At2;
    }
    // Two-column: the first three numeric rows are pairs whose first column steps uniformly.
    let rows: Vec<Vec<f64>> = lines
        .iter()
        .filter(|(_, l)| !is_comment(l))
        .filter_map(|(_, l)| numbers(l))
        .filter(|r| !r.is_empty())
        .take(3)
        .collect();
    let two_col = rows.len() == 3 && rows.iter().all(|r| r.len() == 2) && {
        let (d1, d2) = (rows[1][0] - rows[0][0], rows[2][0] - rows[1][0]);
        d1 > 0.0 && (d2 - d1).abs() <= 1e-3 * d1 + 2e-6
    };
    if two_col {
        Format::TwoColumn
    } else {
        Format::Values
    }
}

/// Parse one number the way Fortran writes it: `.998E-03`, `-0.64E-02`, `1.0D+00`, and the
/// exponent-without-E form `1.234-105`.
pub fn parse_fortran(tok: &str) -> Option<f64> {
    let t = tok.trim();
    if t.is_empty() {
        return None;
    }
    // Rust accepts "nan"/"inf"; a record never should.
    if !t
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'+' | b'-' | b'e' | b'E' | b'd' | b'D'))
    {
        return None;
    }
    let t = t.replace(['d', 'D'], "E");
    if let Ok(v) = t.parse::<f64>() {
        return Some(v);
    }
    // Exponent sign without the letter: find a sign after a digit or dot.
    let b = t.as_bytes();
    for i in 1..b.len() {
        if (b[i] == b'-' || b[i] == b'+') && (b[i - 1].is_ascii_digit() || b[i - 1] == b'.') {
            let fixed = format!("{}E{}", &t[..i], &t[i..]);
            return fixed.parse::<f64>().ok();
        }
    }
    None
}

fn tokens(line: &str) -> impl Iterator<Item = &str> {
    line.split(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .filter(|s| !s.is_empty())
}

/// All tokens of a line as numbers, or None if any token is not a number.
fn numbers(line: &str) -> Option<Vec<f64>> {
    tokens(line).map(parse_fortran).collect()
}

fn is_comment(line: &str) -> bool {
    let t = line.trim_start();
    t.starts_with(';') || t.starts_with('#') || t.starts_with('%') || t.starts_with('!')
}

/// Find NPTS and DT on a header line: `NPTS=  5372, DT= .0100 SEC`, `NPTS = 7500 , DT = .020`,
/// or `4000    0.0100    NPTS, DT` (numbers first).
fn find_npts_dt(line: &str) -> Option<(usize, f64)> {
    let (npts, dt) = npts_dt_numbers(line)?;
    if npts >= 1.0 && npts.fract() == 0.0 && dt > 0.0 && dt.is_finite() {
        Some((npts as usize, dt))
    } else {
        None
    }
}

/// The NPTS and DT numbers of a header line as written, valid or not (`NPTS= 0`, `DT= .0000`).
fn npts_dt_numbers(line: &str) -> Option<(f64, f64)> {
    let up = line.to_ascii_uppercase();
    if !up.contains("NPTS") || !up.contains("DT") {
        return None;
    }
    let toks: Vec<&str> = up
        .split(|c: char| c.is_whitespace() || c == ',' || c == '=')
        .filter(|s| !s.is_empty())
        .collect();
    let first_num = |from: usize| toks[from..].iter().find_map(|t| parse_fortran(t));
    let (npts, dt) = if let (Some(a), Some(b)) = (
        toks.first().and_then(|t| parse_fortran(t)),
        toks.get(1).and_then(|t| parse_fortran(t)),
    ) {
        (a, b)
    } else {
        let i = toks.iter().position(|t| *t == "NPTS")?;
        let j = toks.iter().position(|t| *t == "DT")?;
        (first_num(i + 1)?, first_num(j + 1)?)
    };
    Some((npts, dt))
}

type Parsed = (f64, f64, Vec<f64>, Option<Units>);

/// The units a header states, if it states any: `CM/S`, `CM/SEC`, `CM/S2` or `GAL` words are
/// cm/s2, `M/S...` words m/s2, a word `G` (`UNITS OF G`, `(g)`) g. None where it says nothing.
fn stated_units<'a>(header: impl Iterator<Item = &'a str>) -> Option<Units> {
    let mut found = None;
    for line in header {
        let up = line.to_ascii_uppercase();
        for w in up
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '/' || c == '^'))
            .filter(|w| !w.is_empty())
        {
            let u = if w.starts_with("CM/S") || w == "GAL" || w == "GALS" {
                Units::CmPerS2
            } else if w.starts_with("M/S") {
                Units::MPerS2
            } else if w == "G" {
                Units::G
            } else {
                continue;
            };
            // The first statement counts (a later `G` can be a station's name).
            found.get_or_insert(u);
        }
    }
    found
}

fn parse_at2(lines: &[(usize, &str)], ctx: &Ctx) -> Result<Parsed, RecordError> {
    let Some(hdr) = lines
        .iter()
        .take(12)
        .position(|(_, l)| find_npts_dt(l).is_some())
    else {
        // A header with NPTS and DT whose values cannot be a record's.
        if let Some((n, (npts, dt))) = lines
            .iter()
            .take(12)
            .find_map(|(n, l)| npts_dt_numbers(l).map(|v| (*n, v)))
        {
            return Err(ctx.parse(
                n,
                format!("the header gives NPTS = {npts} and DT = {}: expected a whole number of points >= 1 and a sample interval > 0 s", crate::show(dt)),
            ));
        }
        let last = lines
            .get(lines.len().min(12).saturating_sub(1))
            .map_or(1, |(n, _)| *n);
        return Err(ctx.parse(last, "expected a PEER AT2 header line with NPTS and DT in the first 12 lines (e.g. `NPTS=  5372, DT= .0100 SEC`)".into()));
    };
    let (npts, dt) = find_npts_dt(lines[hdr].1).expect("checked above");
    let units = stated_units(lines[..hdr].iter().map(|(_, l)| *l));
    // The header is not trusted with the allocation: NPTS = 1e18 would abort the process.
    let mut values = Vec::with_capacity(npts.min(1 << 20));
    let mut last_line = lines[hdr].0;
    for &(n, l) in &lines[hdr + 1..] {
        if l.trim().is_empty() {
            continue;
        }
        let toks: Vec<&str> = tokens(l).collect();
        let parsed: Vec<Option<f64>> = toks.iter().map(|t| parse_fortran(t)).collect();
        if parsed.iter().all(Option::is_none) {
            // A trailer such as `*** End Data ***` ends the data; text before any data is skipped.
            if values.is_empty() {
                continue;
            }
            break;
        }
        if let Some(k) = parsed.iter().position(Option::is_none) {
            return Err(ctx.parse(n, format!("expected numbers, found `{}`", toks[k])));
        }
        last_line = n;
        values.extend(parsed.into_iter().flatten());
        if values.len() > npts {
            return Err(ctx.parse(n, format!("more values than the header's NPTS = {npts}")));
        }
    }
    if values.len() != npts {
        return Err(ctx.parse(
            last_line,
            format!(
                "the header says NPTS = {npts} but the data end after {} values",
                values.len()
            ),
        ));
    }
    Ok((dt, 0.0, values, units))
}

fn parse_values(lines: &[(usize, &str)], ctx: &Ctx) -> Result<Vec<f64>, RecordError> {
    let mut values = Vec::new();
    for &(n, l) in lines {
        if l.trim().is_empty() || is_comment(l) {
            continue;
        }
        for tok in tokens(l) {
            match parse_fortran(tok) {
                Some(v) => values.push(v),
                None => {
                    let hint = if values.is_empty() {
                        " (skip header lines with skip_lines / --skip-lines)"
                    } else {
                        ""
                    };
                    return Err(ctx.parse(
                        n,
                        format!("expected an acceleration value, found `{tok}`{hint}"),
                    ));
                }
            }
        }
    }
    Ok(values)
}

/// A line before the data of a two-column file shaped like a data row (two tokens, at least one
/// a number): a row with a typo, not header text.
fn looks_like_a_row(line: &str) -> bool {
    let toks: Vec<&str> = tokens(line).collect();
    let numeric = toks.iter().filter(|t| parse_fortran(t).is_some()).count();
    toks.len() == 2 && numeric >= 1
}

fn parse_two_column(lines: &[(usize, &str)], ctx: &Ctx) -> Result<Parsed, RecordError> {
    let mut times = Vec::new();
    let mut values = Vec::new();
    let mut rows: Vec<usize> = Vec::new();
    for &(n, l) in lines {
        if l.trim().is_empty() || is_comment(l) {
            continue;
        }
        match numbers(l) {
            Some(r) if r.len() == 2 => {
                times.push(r[0]);
                values.push(r[1]);
                rows.push(n);
            }
            // Free text before the numeric rows is a header; a line that holds numbers is not
            // (a row with a typo would silently shorten the record and shift its PGA).
            None if times.is_empty() && !looks_like_a_row(l) => continue,
            _ if times.is_empty() => {
                return Err(ctx.parse(
                    n,
                    format!(
                        "expected a header line of text or a row of 2 numbers (time, acceleration), found `{}`: a header holds no numbers (skip header lines with skip_lines / --skip-lines)",
                        l.trim()
                    ),
                ))
            }
            Some(r) => {
                return Err(ctx.parse(
                    n,
                    format!("expected 2 columns (time, acceleration), found {}", r.len()),
                ))
            }
            None => {
                return Err(ctx.parse(
                    n,
                    format!(
                        "expected 2 numbers (time, acceleration), found `{}`",
                        l.trim()
                    ),
                ))
            }
        }
    }
    if times.len() < 2 {
        return Err(ctx.invalid("expected at least 2 rows of `time acceleration`".into()));
    }
    // Each interval must match the first (to printing precision); dt is then fitted over the
    // whole column so rounding of single time stamps does not leak into it.
    let n = times.len();
    let step = times[1] - times[0];
    if step.is_nan() || step <= 0.0 {
        return Err(ctx.parse(rows[1], "time column must increase".into()));
    }
    for i in 1..n {
        let d = times[i] - times[i - 1];
        if (d - step).abs() > 1e-3 * step + 2e-6 {
            return Err(ctx.parse(
                rows[i],
                format!("time {} breaks the uniform step dt = {} s (previous time {}); only uniformly sampled records are supported", crate::show(times[i]), crate::show(step), crate::show(times[i - 1])),
            ));
        }
    }
    let dt = (times[n - 1] - times[0]) / (n - 1) as f64;
    Ok((dt, times[0], values, None))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_numbers() {
        assert_eq!(parse_fortran(".9984852E-03"), Some(0.9984852e-3));
        assert_eq!(parse_fortran("-.1779048E-03"), Some(-0.1779048e-3));
        assert_eq!(parse_fortran("1.5D+02"), Some(150.0));
        assert_eq!(parse_fortran("1.234-105"), Some(1.234e-105));
        assert_eq!(parse_fortran("nan"), None);
        assert_eq!(parse_fortran("SEC"), None);
    }

    #[test]
    fn npts_dt_variants() {
        assert_eq!(
            find_npts_dt("NPTS=   5372, DT=   .0100 SEC,   "),
            Some((5372, 0.01))
        );
        assert_eq!(
            find_npts_dt("NPTS =   7500 , DT =   .020 SEC ,"),
            Some((7500, 0.02))
        );
        assert_eq!(
            find_npts_dt("4000    0.0100    NPTS, DT"),
            Some((4000, 0.01))
        );
        assert_eq!(
            find_npts_dt("NPTS= 1991, DT= .0100 SEC,   0 POLE @ 30.00000 HZ, ..."),
            Some((1991, 0.01))
        );
        assert_eq!(find_npts_dt("ACCELERATION TIME SERIES IN UNITS OF G"), None);
    }

    #[test]
    fn header_units() {
        let u = |l: &str| stated_units(std::iter::once(l));
        assert_eq!(u("ACCELERATION TIME SERIES IN UNITS OF G"), Some(Units::G));
        assert_eq!(u("The units are (g)"), Some(Units::G));
        assert_eq!(u("ACCELERATION IN CM/SEC/SEC"), Some(Units::CmPerS2));
        assert_eq!(u("units: gal"), Some(Units::CmPerS2));
        assert_eq!(u("ACCELERATION IN M/S^2"), Some(Units::MPerS2));
        assert_eq!(u("IMPERIAL VALLEY 5/19/40 0439, EL CENTRO ARRAY #9"), None);
    }
}

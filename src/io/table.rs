//! Reading a results CSV back for studies (`pound plot`, `pound fragility`): named columns,
//! numeric cells, row filters, and units from the column names. Errors name the file, the line
//! and the column.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum TableError {
    #[error("{}: {message}", path.display())]
    Read { path: PathBuf, message: String },
    #[error("{}: no column `{column}`; the columns are: {available}", path.display())]
    NoColumn {
        path: PathBuf,
        column: String,
        available: String,
    },
    #[error("{}, line {line}, column `{column}`: `{value}` is not a number", path.display())]
    NotNumber {
        path: PathBuf,
        line: usize,
        column: String,
        value: String,
    },
    #[error("--where `{text}`: {message}")]
    Filter { text: String, message: String },
    #[error("{}: the column `{column}` appears {count} times (columns {positions}): a study reads a column by its name, and which of them is meant cannot be told; rename or drop all but one", path.display())]
    DuplicateColumn {
        path: PathBuf,
        column: String,
        count: usize,
        positions: String,
    },
}

/// A CSV with a header row, held in memory as text.
#[derive(Debug, Clone)]
pub struct Table {
    pub path: PathBuf,
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn read(path: &Path) -> Result<Table, TableError> {
        let fail = |message: String| TableError::Read {
            path: path.into(),
            message,
        };
        // A Parquet file (`pound sweep --format parquet`) starts with its magic bytes.
        let mut magic = [0u8; 4];
        if std::fs::File::open(path)
            .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
            .is_ok()
            && &magic == b"PAR1"
        {
            return Err(fail(
                "is a Parquet file: this command reads the CSV a sweep writes (run the sweep with --format csv, or convert the file)".into(),
            ));
        }
        let mut r = csv::Reader::from_path(path).map_err(|e| fail(e.to_string()))?;
        let header: Vec<String> = r
            .headers()
            .map_err(|e| fail(e.to_string()))?
            .iter()
            // A UTF-8 byte-order mark is not part of the first column's name.
            .map(|h| h.strip_prefix('\u{feff}').unwrap_or(h).to_string())
            .collect();
        let rows = r
            .records()
            .map(|rec| {
                rec.map(|r| r.iter().map(String::from).collect())
                    .map_err(|e| fail(e.to_string()))
            })
            .collect::<Result<_, _>>()?;
        let table = Table {
            path: path.into(),
            header,
            rows,
        };
        table.check_columns()?;
        Ok(table)
    }

    /// Refuse a header that names a column twice: a study reads a column by its name, and the
    /// first of two would be read silently (a column of zeros put first would stand for the
    /// other). [`Table::read`] checks it; a table built otherwise (the Python package's, from an
    /// Arrow table, whose names need not differ) is checked by the studies.
    pub fn check_columns(&self) -> Result<(), TableError> {
        match duplicate_column(&self.header) {
            Some((column, at)) => Err(self.named_twice(column, &at)),
            None => Ok(()),
        }
    }

    /// The refusal of `column`, which the header names at each index of `at`.
    fn named_twice(&self, column: String, at: &[usize]) -> TableError {
        TableError::DuplicateColumn {
            path: self.path.clone(),
            column,
            count: at.len(),
            // Columns numbered from 1, as a person counts them in the header.
            positions: at
                .iter()
                .map(|i| (i + 1).to_string())
                .collect::<Vec<_>>()
                .join(", "),
        }
    }

    /// Index of the column `name`; refused where the header names it twice.
    pub fn col(&self, name: &str) -> Result<usize, TableError> {
        let at: Vec<usize> = (0..self.header.len())
            .filter(|&i| self.header[i] == name)
            .collect();
        match at[..] {
            [i] => Ok(i),
            [] => Err(TableError::NoColumn {
                path: self.path.clone(),
                column: name.into(),
                available: self.header.join(", "),
            }),
            _ => Err(self.named_twice(name.into(), &at)),
        }
    }

    /// The number in row `i` (0-based, after the header), column `c`; None for an empty cell.
    pub fn num(&self, i: usize, c: usize) -> Result<Option<f64>, TableError> {
        let v = self.rows[i][c].trim();
        if v.is_empty() {
            return Ok(None);
        }
        v.parse().map(Some).map_err(|_| TableError::NotNumber {
            path: self.path.clone(),
            line: i + 2,
            column: self.header[c].clone(),
            value: v.into(),
        })
    }

    /// Rows that pass every filter.
    pub fn select(&self, filters: &[Filter]) -> Result<Vec<usize>, TableError> {
        let cols: Vec<usize> = filters
            .iter()
            .map(|f| self.col(&f.column))
            .collect::<Result<_, _>>()?;
        Ok((0..self.rows.len())
            .filter(|&i| {
                filters
                    .iter()
                    .zip(&cols)
                    .all(|(f, &c)| f.keeps(&self.rows[i][c]))
            })
            .collect())
    }
}

/// The first name that `header` holds more than once, and where it stands (0-based); None
/// where every name differs.
pub fn duplicate_column<S: AsRef<str>>(header: &[S]) -> Option<(String, Vec<usize>)> {
    let mut seen: std::collections::HashSet<&str> = std::collections::HashSet::new();
    let first = header.iter().map(AsRef::as_ref).find(|h| !seen.insert(h))?;
    let at = (0..header.len())
        .filter(|&i| header[i].as_ref() == first)
        .collect();
    Some((first.to_string(), at))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl std::fmt::Display for Filter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let op = match self.op {
            Op::Eq => "=",
            Op::Ne => "!=",
            Op::Lt => "<",
            Op::Le => "<=",
            Op::Gt => ">",
            Op::Ge => ">=",
        };
        write!(f, "{}{op}{}", self.column, self.value)
    }
}

/// The filters as a caption, in the words and units the axes use (`t2_s=0.9`, `law!=hertz` ->
/// `where period, building 2 = 0.9 s and contact law != hertz`); empty for none.
pub fn caption(filters: &[Filter]) -> String {
    if filters.is_empty() {
        return String::new();
    }
    let all: Vec<String> = filters
        .iter()
        .map(|f| {
            let (name, unit) = named(&f.column);
            let op = f.to_string();
            let op = op[f.column.len()..]
                .strip_suffix(f.value.as_str())
                .unwrap_or("=");
            // A unit after a number; a text value (a law, a record) stands alone.
            match unit {
                Some(u) if f.value.parse::<f64>().is_ok() => format!("{name} {op} {} {u}", f.value),
                _ => format!("{name} {op} {}", f.value),
            }
        })
        .collect();
    format!("where {}", all.join(" and "))
}

/// `column OP value` with OP one of `=`, `!=`, `<`, `<=`, `>`, `>=`. `=` and `!=` compare numbers
/// as numbers when both sides parse (so `gap_m=0.010` matches `0.01`), else as text.
#[derive(Debug, Clone, PartialEq)]
pub struct Filter {
    pub column: String,
    pub op: Op,
    pub value: String,
}

impl Filter {
    pub fn parse(text: &str) -> Result<Filter, TableError> {
        let fail = |message: &str| TableError::Filter {
            text: text.into(),
            message: message.into(),
        };
        let ops = [
            ("!=", Op::Ne),
            ("<=", Op::Le),
            (">=", Op::Ge),
            ("=", Op::Eq),
            ("<", Op::Lt),
            (">", Op::Gt),
        ];
        let (at, len, op) = ops
            .iter()
            .filter_map(|(s, op)| text.find(s).map(|i| (i, s.len(), *op)))
            .min_by_key(|(i, len, _)| (*i, usize::MAX - len))
            .ok_or_else(|| fail("expected COLUMN=VALUE (or !=, <, <=, >, >=)"))?;
        let column = text[..at].trim().to_string();
        let value = text[at + len..].trim().to_string();
        if column.is_empty() || value.is_empty() {
            return Err(fail("expected COLUMN=VALUE (or !=, <, <=, >, >=)"));
        }
        if !matches!(op, Op::Eq | Op::Ne) && !value.parse::<f64>().is_ok_and(f64::is_finite) {
            return Err(fail("<, <=, > and >= need a finite number"));
        }
        Ok(Filter { column, op, value })
    }

    /// Every `--where` text, parsed.
    pub fn parse_all(texts: &[String]) -> Result<Vec<Filter>, TableError> {
        texts.iter().map(|t| Filter::parse(t)).collect()
    }

    /// Numbers are compared at [`level`]: `pga_g=0.2` keeps a record scaled to
    /// `0.20000000000000004`.
    pub fn keeps(&self, cell: &str) -> bool {
        let num = cell.trim().parse::<f64>().ok().map(level);
        let want = self.value.parse::<f64>().ok().map(level);
        match (self.op, num, want) {
            (Op::Eq, Some(a), Some(b)) => a == b,
            (Op::Ne, Some(a), Some(b)) => a != b,
            (Op::Eq, _, _) => cell.trim() == self.value,
            (Op::Ne, _, _) => cell.trim() != self.value,
            (_, None, _) | (_, _, None) => false,
            (Op::Lt, Some(a), Some(b)) => a < b,
            (Op::Le, Some(a), Some(b)) => a <= b,
            (Op::Gt, Some(a), Some(b)) => a > b,
            (Op::Ge, Some(a), Some(b)) => a >= b,
        }
    }
}

/// A number as the studies compare it: rounded to 12 significant digits, so that one value
/// computed per record (a scaled PGA, `0.19999999999999998` and `0.20000000000000004`) is one
/// value in a filter, a level, a series and an x position.
pub fn level(x: f64) -> f64 {
    if x.is_finite() {
        format!("{x:.11e}").parse().unwrap_or(x)
    } else {
        x
    }
}

/// A map key that orders finite numbers like the numbers themselves (for grouping rows by a
/// numeric column in a `BTreeMap`).
pub fn order_key(x: f64) -> u64 {
    if x >= 0.0 {
        x.to_bits() ^ (1 << 63)
    } else {
        !x.to_bits()
    }
}

/// The unit suffixes of column names, longest first, and the units they stand for.
const UNITS: [(&str, &str); 11] = [
    ("_n_per_m1_5", "N/m^1.5"),
    ("_n_per_m", "N/m"),
    ("_m_s2", "m/s^2"),
    ("_m_s", "m/s"),
    ("_kg", "kg"),
    ("_g", "g"),
    ("_j", "J"),
    ("_n", "N"),
    ("_m", "m"),
    ("_s", "s"),
    ("_pct", "%"),
];

/// A column's name without its unit suffix, and the unit (None where it has none).
fn split_unit(column: &str) -> (&str, Option<&'static str>) {
    for (suffix, unit) in UNITS {
        if let Some(stem) = column.strip_suffix(suffix) {
            if !stem.is_empty() {
                return (stem, Some(unit));
            }
        }
    }
    (column, None)
}

/// A column's short name and unit (None for counts, ratios and text), from the one table of
/// column meanings ([`crate::plan::meaning`]) that `pound columns` and the docs print. A column
/// no sweep writes (another tool's CSV) is named by its words and the unit its suffix spells.
fn named(column: &str) -> (String, Option<&'static str>) {
    match crate::plan::meaning::meaning(column) {
        Some(m) => (m.label, (m.unit != "-").then_some(m.unit)),
        None => {
            let (stem, unit) = split_unit(column);
            (stem.replace('_', " "), unit)
        }
    }
}

/// An axis label: the column's short name and its unit in parentheses (`gap_m` -> `gap (m)`,
/// `pga_g` -> `PGA (g)`, `b2_peak_drift_ratio` -> `peak drift ratio, building 2 (m/m)`, which
/// a plot's linear axis shows in %).
pub fn label(column: &str) -> String {
    match named(column) {
        (name, Some(unit)) => format!("{name} ({unit})"),
        (name, None) => name,
    }
}

/// A column's short name, without its unit (for titles: the axes carry the units).
pub fn name(column: &str) -> String {
    named(column).0
}

/// A legend entry for `column = value`, with the unit after the value (`b1_t1_s`, `0.25` ->
/// `period T1, building 1 = 0.25 s`).
pub fn value_label(column: &str, value: &str) -> String {
    match named(column) {
        (name, Some(unit)) => format!("{name} = {value} {unit}"),
        (name, None) => format!("{name} = {value}"),
    }
}

/// A value of `column` with its unit, in engineering units where those read better (for legend
/// entries such as thresholds): `peak_force_n`, 1e6 -> `1 MN`; `dissipated_energy_j`, 2500 ->
/// `2.5 kJ`; `gap_m`, 0.05 -> `50 mm`; `pga_g`, 0.3 -> `0.3 g`; a ratio or a count as it is.
pub fn quantity(column: &str, v: f64) -> String {
    // Four significant digits, trailing zeros dropped.
    let short = |x: f64| {
        if x == 0.0 || !x.is_finite() {
            return format!("{x}");
        }
        if !(1e-6..1e15).contains(&x.abs()) {
            // Far from 1, digits would run to hundreds (1e-300): an exponent instead.
            let e = format!("{x:.3e}");
            let (m, p) = e.split_once('e').unwrap_or((&e, "0"));
            let m = m.trim_end_matches('0').trim_end_matches('.');
            return format!("{m}e{p}");
        }
        let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.digits$}");
        match s.contains('.') {
            true => s.trim_end_matches('0').trim_end_matches('.').to_string(),
            false => s,
        }
    };
    let unit = named(column).1;
    let large = |base: &str| -> String {
        match v.abs() {
            a if a >= 1e6 => format!("{} M{base}", short(v / 1e6)),
            a if a >= 1e3 => format!("{} k{base}", short(v / 1e3)),
            _ => format!("{} {base}", short(v)),
        }
    };
    match unit {
        Some(u @ ("N" | "J" | "N/m")) => large(u),
        Some("m") if v != 0.0 && v.abs() < 1.0 => format!("{} mm", short(v * 1e3)),
        Some("m/m") => format!("{} %", short(v * 1e2)),
        Some(u) => format!("{} {u}", short(v)),
        None => short(v),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantities_in_engineering_units() {
        assert_eq!(quantity("peak_force_n", 1e6), "1 MN");
        assert_eq!(quantity("peak_force_n", 3.5e6), "3.5 MN");
        assert_eq!(quantity("peak_force_n", 0.0), "0 N");
        assert_eq!(quantity("dissipated_energy_j", 2500.0), "2.5 kJ");
        assert_eq!(quantity("gap_1_2_m", 0.05), "50 mm");
        assert_eq!(quantity("peak_u1_m", 1.25), "1.25 m");
        assert_eq!(quantity("pga_g", 0.3), "0.3 g");
        assert_eq!(quantity("b2_peak_drift_ratio", 0.005), "0.5 %");
        assert_eq!(quantity("b2_s3_residual_drift_ratio", 0.0125), "1.25 %");
        assert_eq!(quantity("b2_peak_ductility", 2.5), "2.5");
        assert_eq!(quantity("impacts", 0.0), "0");
        assert_eq!(quantity("b1_peak_drift_ratio", 1e-300), "1e-298 %");
    }

    #[test]
    fn filters_and_labels() {
        let f = Filter::parse("gap_m<=0.01").unwrap();
        assert_eq!(
            (f.column.as_str(), f.op, f.value.as_str()),
            ("gap_m", Op::Le, "0.01")
        );
        assert!(f.keeps("0.010") && f.keeps("0") && !f.keeps("0.02") && !f.keeps(""));
        let f = Filter::parse("law=hertz").unwrap();
        assert!(f.keeps("hertz") && !f.keeps("linear"));
        assert!(Filter::parse("e=0.50").unwrap().keeps("0.5"));
        assert!(Filter::parse("law!=hertz").unwrap().keeps("linear"));
        assert!(Filter::parse("gap_m").is_err() && Filter::parse("law<x").is_err());
        assert_eq!(label("gap_m"), "gap (m)");
        assert_eq!(label("peak_force_n"), "peak force (N)");
        assert_eq!(label("impact_velocity_m_s"), "impact velocity (m/s)");
        assert_eq!(label("beta_n_per_m1_5"), "contact stiffness beta (N/m^1.5)");
        assert_eq!(label("impacts"), "impacts");
        let f = Filter::parse_all(&["t2_s=0.9".into(), "law!=hertz".into()]).unwrap();
        assert_eq!(
            caption(&f),
            "where period, building 2 = 0.9 s and contact law != hertz"
        );
        assert_eq!(caption(&[]), "");
        assert_eq!(label("gap_1_2_m"), "gap 1-2 (m)");
        assert_eq!(
            label("b2_peak_drift_ratio"),
            "peak drift ratio, building 2 (m/m)"
        );
        assert_eq!(
            label("b1_peak_accel_m_s2"),
            "peak floor acceleration, building 1 (m/s^2)"
        );
        assert_eq!(
            label("level_b1f3_b2f3_peak_force_n"),
            "peak force, level b1f3-b2f3 (N)"
        );
        assert_eq!(
            value_label("b1_t1_s", "0.25"),
            "period T1, building 1 = 0.25 s"
        );
        assert_eq!(value_label("law", "hertz"), "contact law = hertz");
        assert_eq!(label("pga_g"), "PGA (g)");
        // A column no sweep writes: its words, and the unit its suffix spells.
        assert_eq!(label("sd_drift_m"), "sd drift (m)");
        assert_eq!(quantity("sd_force_n", 2e3), "2 kN");
    }

    /// Every label, name and unit a plot prints for a sweep's column is the one table's
    /// ([`crate::plan::meaning`]): a pair's columns and a row's, building, storey, gap and level.
    #[test]
    fn labels_come_from_the_table_of_meanings() {
        let row = [
            "b2_peak_roof_m",
            "b3_peak_accel_m_s2",
            "b1_s2_hysteretic_energy_j",
            "gap_1_2_m",
            "level_b1f3_b2f2_impact_velocity_m_s",
        ];
        let header = crate::plan::columns::HEADER;
        for c in header.iter().copied().chain(row) {
            let m = crate::plan::meaning::meaning(c).unwrap();
            assert_eq!(name(c), m.label, "{c}");
            match m.unit {
                "-" => assert_eq!(label(c), m.label, "{c}"),
                u => assert_eq!(label(c), format!("{} ({u})", m.label), "{c}"),
            }
        }
    }
}

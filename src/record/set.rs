//! Record sets: a folder of PEER NGA-West2 downloads, read through the `_SearchResults.csv` the
//! search wrote beside its records. Its block " -- Summary of Metadata of Selected Records --"
//! lists each record (RSN, the search's scale factor, event, station, magnitude, distances and
//! each component's file); columns are found by name, so a search that adds or drops columns
//! reads the same.

use super::RecordError;
use std::path::{Path, PathBuf};

/// The file a set's folder holds its search's metadata in.
pub const SEARCH_RESULTS: &str = "_SearchResults.csv";

/// The block's first line.
const SUMMARY: &str = "-- Summary of Metadata of Selected Records --";

/// A record's components, as `components = [...]` and the labels name them.
pub const COMPONENTS: [&str; 3] = ["H1", "H2", "V"];

/// The columns read: the RSN and the files are needed, the rest read where given.
const RSN: &str = "Record Sequence Number";
const FILES: [&str; 3] = [
    "Horizontal-1 Acc. Filename",
    "Horizontal-2 Acc. Filename",
    "Vertical Acc. Filename",
];

/// One record of a set: its metadata and each component's file (None where the search has
/// none, `---`).
#[derive(Debug, Clone, PartialEq)]
pub struct SetRecord {
    pub rsn: u32,
    pub scale_factor: Option<f64>,
    pub event: String,
    pub year: String,
    pub station: String,
    pub magnitude: Option<f64>,
    pub mechanism: String,
    pub rjb_km: Option<f64>,
    pub rrup_km: Option<f64>,
    pub vs30_m_s: Option<f64>,
    /// Horizontal-1, horizontal-2 and vertical, in the set's folder.
    pub files: [Option<PathBuf>; 3],
    /// Its line in the search results (1-based).
    pub line: usize,
}

impl SetRecord {
    /// The label a component's runs carry: `RSN6_H1`.
    pub fn label(&self, component: usize) -> String {
        format!("RSN{}_{}", self.rsn, COMPONENTS[component])
    }

    /// What a sweep writes of component `component`'s runs ([`RecordMeta`]).
    pub fn meta(&self, component: usize) -> RecordMeta {
        RecordMeta {
            rsn: self.rsn,
            component: COMPONENTS[component],
            event: self.event.clone(),
            magnitude: self.magnitude,
            rjb_km: self.rjb_km,
            rrup_km: self.rrup_km,
            vs30_m_s: self.vs30_m_s,
        }
    }
}

/// A set's record as its runs' rows name it: the search's metadata of one component.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordMeta {
    pub rsn: u32,
    pub component: &'static str,
    pub event: String,
    pub magnitude: Option<f64>,
    pub rjb_km: Option<f64>,
    pub rrup_km: Option<f64>,
    pub vs30_m_s: Option<f64>,
}

/// A set: its search-results file and records, in the file's order.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordSet {
    pub results: PathBuf,
    pub records: Vec<SetRecord>,
}

/// The search-results file of the set `dir` names: [`SEARCH_RESULTS`] in it where it is a
/// folder, else `dir` itself (the file named directly).
pub fn results_path(dir: &Path) -> PathBuf {
    if dir.is_dir() {
        dir.join(SEARCH_RESULTS)
    } else {
        dir.to_path_buf()
    }
}

/// The set in `dir` (a folder holding [`SEARCH_RESULTS`], or that file itself). Every
/// component file it names must be in the folder.
pub fn read_set(dir: &Path) -> Result<RecordSet, RecordError> {
    let results = results_path(dir);
    let folder = results.parent().unwrap_or(Path::new("")).to_path_buf();
    if !results.is_file() {
        let message = if dir.is_dir() {
            format!("no {SEARCH_RESULTS} in it: a record set is the folder of a PEER NGA-West2 search, its records and the {SEARCH_RESULTS} the search wrote (a browser may have renamed it, e.g. `_SearchResults (1).csv`)")
        } else {
            format!("no such folder or file: a record set is the folder of a PEER NGA-West2 search, with its {SEARCH_RESULTS}")
        };
        return Err(RecordError::Invalid {
            path: dir.to_path_buf(),
            message,
        });
    }
    let text = std::fs::read_to_string(&results).map_err(|error| RecordError::Io {
        path: results.clone(),
        error,
    })?;
    let parse = |line: usize, message: String| RecordError::Parse {
        path: results.clone(),
        line,
        message,
    };
    let lines: Vec<&str> = text.lines().collect();
    let start = lines
        .iter()
        .position(|l| split_cells(l).first().is_some_and(|c| c.trim() == SUMMARY))
        .ok_or_else(|| RecordError::Invalid {
            path: results.clone(),
            message: format!("no `{SUMMARY}` block: expected a PEER NGA-West2 search's results"),
        })?;
    // The header: the block's first line with cells.
    let header_at = (start + 1..lines.len())
        .find(|&i| !is_blank(lines[i]))
        .ok_or_else(|| parse(start + 1, "the block has no header".into()))?;
    let header: Vec<String> = split_cells(lines[header_at])
        .iter()
        .map(|c| c.trim().to_string())
        .collect();
    let column = |name: &str| header.iter().position(|h| h == name);
    // The header's named cells (a line may be padded with empty ones).
    let named = header
        .iter()
        .rposition(|h| !h.is_empty())
        .map_or(0, |k| k + 1);
    let needed = |name: &str| {
        column(name).ok_or_else(|| {
            parse(
                header_at + 1,
                format!("no `{name}` column: the header names {}", header.join(", ")),
            )
        })
    };
    let rsn_at = needed(RSN)?;
    let file_at = [
        Some(needed(FILES[0])?),
        Some(needed(FILES[1])?),
        column(FILES[2]),
    ];
    let mut records: Vec<SetRecord> = Vec::new();
    for (i, line) in lines.iter().enumerate().skip(header_at + 1) {
        let cells = split_cells(line);
        let text_at = |at: Option<usize>| {
            at.and_then(|a| cells.get(a))
                .map_or(String::new(), |c| unquote(c))
        };
        // The block ends at its first line without an RSN (a blank line, the notes after it).
        let rsn_text = text_at(Some(rsn_at));
        if rsn_text.is_empty() {
            break;
        }
        let extra = cells.iter().skip(named).any(|c| !c.trim().is_empty());
        if cells.len() < named || extra {
            return Err(parse(
                i + 1,
                format!(
                    "has {} cells where the header names {named}{}",
                    cells
                        .iter()
                        .rposition(|c| !c.trim().is_empty())
                        .map_or(0, |k| k + 1),
                    if extra {
                        ": a cell with an unquoted comma?"
                    } else {
                        ""
                    }
                ),
            ));
        }
        let rsn: u32 = rsn_text.parse().map_err(|_| {
            parse(
                i + 1,
                format!("`{RSN}` is `{rsn_text}`: expected a whole number"),
            )
        })?;
        if let Some(r) = records.iter().find(|r| r.rsn == rsn) {
            return Err(parse(
                i + 1,
                format!("RSN {rsn} is listed twice (also line {})", r.line),
            ));
        }
        let number = |name: &str| -> Result<Option<f64>, RecordError> {
            let t = text_at(column(name));
            if t.is_empty() || t.starts_with("---") {
                return Ok(None);
            }
            t.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .map(Some)
                .ok_or_else(|| parse(i + 1, format!("`{name}` is `{t}`: expected a number")))
        };
        let mut files: [Option<PathBuf>; 3] = [None, None, None];
        for (c, at) in file_at.iter().enumerate() {
            let name = text_at(*at);
            if name.is_empty() || name.starts_with("---") {
                continue;
            }
            let file = folder.join(&name);
            if !file.is_file() {
                return Err(parse(
                    i + 1,
                    format!(
                        "RSN {rsn}'s {} file `{name}` is not in {}",
                        COMPONENTS[c],
                        folder.display()
                    ),
                ));
            }
            files[c] = Some(file);
        }
        records.push(SetRecord {
            rsn,
            scale_factor: number("Scale Factor")?,
            event: text_at(column("Earthquake Name")),
            year: text_at(column("Year")),
            station: text_at(column("Station Name")),
            magnitude: number("Magnitude")?,
            mechanism: text_at(column("Mechanism")),
            rjb_km: number("Rjb (km)")?,
            rrup_km: number("Rrup (km)")?,
            vs30_m_s: number("Vs30 (m/sec)")?,
            files,
            line: i + 1,
        });
    }
    if records.is_empty() {
        return Err(parse(header_at + 2, "the block lists no records".into()));
    }
    Ok(RecordSet { results, records })
}

/// A line's cells, split at commas outside double quotes (a quote inside a quoted cell
/// doubled), each as written inside its quotes.
fn split_cells(line: &str) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => cells.push(std::mem::take(&mut cell)),
            _ => cell.push(c),
        }
    }
    cells.push(cell);
    cells
}

/// A cell's text: trimmed, and a name PEER quotes (`"Landers"`) without its quotes.
fn unquote(cell: &str) -> String {
    let t = cell.trim();
    t.strip_prefix('"')
        .and_then(|t| t.strip_suffix('"'))
        .unwrap_or(t)
        .trim()
        .to_string()
}

fn is_blank(line: &str) -> bool {
    split_cells(line).iter().all(|c| c.trim().is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_split_outside_quotes_and_names_lose_their_quotes() {
        let cells = split_cells(r#" 1, 6," ""Imperial Valley-02""", 1940,"a, b""#);
        assert_eq!(cells.len(), 5);
        assert_eq!(unquote(&cells[2]), "Imperial Valley-02");
        assert_eq!(unquote(&cells[4]), "a, b");
        assert!(is_blank(",,, ,"));
    }
}

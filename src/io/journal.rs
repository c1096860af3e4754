//! What an output holds, checked rather than trusted. A CSV output's rows are hashed as they are
//! written ([`ContentHasher`]): the progress journal of an unfinished sweep records the hash of
//! the bytes it vouches for, and the sidecar of a finished one the hash of the whole file and of
//! each block of [`BLOCK_ROWS`] rows. `--resume` re-reads and re-hashes the `.partial` before it
//! continues ([`verify_prefix`]); `pound merge` re-hashes every shard and names the block that
//! differs; a finished sweep re-reads its file before renaming it into place ([`verify_file`]).

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// Rows per content-hash block: merge names the block of rows that differs.
pub const BLOCK_ROWS: u64 = 65536;

fn hex(d: impl AsRef<[u8]>) -> String {
    d.as_ref().iter().map(|b| format!("{b:02x}")).collect()
}

/// The content of a finished output, as recorded in its sidecar.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Content {
    /// Rows after the header.
    pub rows: u64,
    /// SHA-256 of the whole file, header included.
    pub sha256: String,
    /// SHA-256 of the rows of each block of [`BLOCK_ROWS`] (the last may be shorter); empty
    /// for outputs that are not one row per run (Parquet, summaries).
    #[serde(default)]
    pub blocks: Vec<String>,
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ContentError {
    #[error("line {line}: {message}")]
    Row { line: u64, message: String },
}

/// Hashes a CSV as it is written or read: the whole file, each block of rows, and (when runs
/// are numbered) checks that the rows hold runs `first_run, first_run + 1, ...` in order.
#[derive(Clone)]
pub struct ContentHasher {
    whole: Sha256,
    block: Sha256,
    blocks: Vec<String>,
    rows: u64,
    bytes: u64,
    /// The run the next row must hold; None for outputs that are not one row per run.
    next_run: Option<u64>,
}

impl std::fmt::Debug for ContentHasher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ContentHasher")
            .field("rows", &self.rows)
            .field("bytes", &self.bytes)
            .field("next_run", &self.next_run)
            .finish()
    }
}

impl ContentHasher {
    /// After the header line `header` (its bytes, newline included).
    pub fn new(header: &[u8], first_run: Option<u64>) -> ContentHasher {
        let mut whole = Sha256::new();
        whole.update(header);
        ContentHasher {
            whole,
            block: Sha256::new(),
            blocks: Vec::new(),
            rows: 0,
            bytes: header.len() as u64,
            next_run: first_run,
        }
    }

    /// One row's bytes (newline included).
    pub fn row(&mut self, row: &[u8]) -> Result<(), ContentError> {
        let line = self.rows + 2;
        if row.last() != Some(&b'\n') {
            return Err(ContentError::Row {
                line,
                message: "the row is cut off (no end of line)".into(),
            });
        }
        if let Some(expect) = self.next_run {
            let field = row
                .split(|&b| b == b',' || b == b'\n' || b == b'\r')
                .next()
                .unwrap_or_default();
            let run = std::str::from_utf8(field)
                .ok()
                .and_then(|s| s.parse::<u64>().ok());
            if run != Some(expect) {
                return Err(ContentError::Row {
                    line,
                    message: format!(
                        "holds run `{}` where run {expect} was expected (rows missing, repeated or out of order)",
                        String::from_utf8_lossy(field)
                    ),
                });
            }
            self.next_run = Some(expect + 1);
        }
        self.whole.update(row);
        self.block.update(row);
        self.rows += 1;
        self.bytes += row.len() as u64;
        if self.rows.is_multiple_of(BLOCK_ROWS) {
            self.close_block();
        }
        Ok(())
    }

    /// Every row of `bytes`, which must end at a row's end.
    pub fn rows(&mut self, bytes: &[u8]) -> Result<(), ContentError> {
        let mut rest = bytes;
        while !rest.is_empty() {
            let n = row_len(rest).unwrap_or(rest.len());
            self.row(&rest[..n])?;
            rest = &rest[n..];
        }
        Ok(())
    }

    fn close_block(&mut self) {
        let b = std::mem::take(&mut self.block);
        self.blocks.push(hex(b.finalize()));
    }

    pub fn rows_seen(&self) -> u64 {
        self.rows
    }

    /// Bytes hashed so far, header included.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// The hash of everything so far (the journal's checksum of its prefix).
    pub fn digest(&self) -> String {
        hex(self.whole.clone().finalize())
    }

    pub fn finish(mut self) -> Content {
        if !self.rows.is_multiple_of(BLOCK_ROWS) {
            self.close_block();
        }
        Content {
            rows: self.rows,
            sha256: hex(self.whole.finalize()),
            blocks: self.blocks,
        }
    }
}

/// Length of the first CSV row of `bytes` (through its newline; a newline inside a quoted field
/// does not end it), or None if no row ends in `bytes`.
pub fn row_len(bytes: &[u8]) -> Option<usize> {
    let mut quoted = false;
    for (i, &b) in bytes.iter().enumerate() {
        match b {
            b'"' => quoted = !quoted,
            b'\n' if !quoted => return Some(i + 1),
            _ => {}
        }
    }
    None
}

/// Reads CSV rows (raw bytes, newline included) from a stream; the last one may be cut off.
pub struct RowReader<R: Read> {
    inner: BufReader<R>,
}

impl<R: Read> RowReader<R> {
    pub fn new(r: R) -> RowReader<R> {
        RowReader {
            inner: BufReader::with_capacity(1 << 20, r),
        }
    }

    /// The next row into `buf` (cleared first); false at the end.
    pub fn next_row(&mut self, buf: &mut Vec<u8>) -> std::io::Result<bool> {
        buf.clear();
        let mut quoted = false;
        loop {
            let start = buf.len();
            if self.inner.read_until(b'\n', buf)? == 0 {
                return Ok(!buf.is_empty());
            }
            quoted ^= buf[start..].iter().filter(|&&b| b == b'"').count() % 2 == 1;
            if !quoted || buf.last() != Some(&b'\n') {
                return Ok(true);
            }
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum VerifyError {
    #[error("{}: {message}", path.display())]
    Bad { path: PathBuf, message: String },
    #[error("{}: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
}

/// Check that the first `bytes` bytes of `partial` are the header `header`, then exactly `rows`
/// complete rows of runs `first_run..first_run + rows`, hashing to `sha256` (what an unfinished
/// sweep's journal vouches for). Returns the hasher over that prefix, to continue from.
pub fn verify_prefix(
    partial: &Path,
    header: &[u8],
    first_run: u64,
    rows: u64,
    bytes: u64,
    sha256: &str,
) -> Result<ContentHasher, VerifyError> {
    let bad = |message: String| VerifyError::Bad {
        path: partial.into(),
        message,
    };
    let io = |error| VerifyError::Io {
        path: partial.into(),
        error,
    };
    let file = std::fs::File::open(partial).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    if len < bytes {
        return Err(bad(format!(
            "holds {len} bytes, fewer than the {bytes} its journal vouches for: it was truncated or replaced"
        )));
    }
    let mut r = after_header(partial, file.take(bytes), header)?;
    let mut row = Vec::new();
    let mut h = ContentHasher::new(header, Some(first_run));
    while r.next_row(&mut row).map_err(io)? {
        h.row(&row).map_err(|e| bad(e.to_string()))?;
        if h.rows_seen() > rows {
            break;
        }
    }
    if h.rows_seen() != rows || h.bytes() != bytes {
        let held = if h.rows_seen() > rows {
            format!("more than {rows} rows")
        } else {
            format!("{} rows in {} bytes", h.rows_seen(), h.bytes())
        };
        return Err(bad(format!(
            "its journal vouches for {rows} runs in {bytes} bytes, but the file holds {held} there"
        )));
    }
    if h.digest() != sha256 {
        return Err(bad(format!(
            "its first {bytes} bytes do not match the checksum its journal recorded: the file or the journal was edited"
        )));
    }
    Ok(h)
}

/// A reader of `file` (read as `path`) past its first row, which must be `header`.
fn after_header<R: Read>(path: &Path, file: R, header: &[u8]) -> Result<RowReader<R>, VerifyError> {
    let mut r = RowReader::new(file);
    let mut row = Vec::new();
    let read = r.next_row(&mut row).map_err(|error| VerifyError::Io {
        path: path.into(),
        error,
    })?;
    if !read || row != header {
        return Err(VerifyError::Bad {
            path: path.into(),
            message:
                "does not start with the header this sweep writes (another sweep's file, or edited)"
                    .into(),
        });
    }
    Ok(r)
}

/// Re-read a whole CSV and check it against `content` (hash, rows, blocks) and, with
/// `first_run`, that its rows hold consecutive runs from there. Used before a finished sweep's
/// `.partial` is renamed into place.
pub fn verify_file(
    path: &Path,
    header: &[u8],
    first_run: Option<u64>,
    content: &Content,
) -> Result<(), VerifyError> {
    verify_rows(path, header, first_run, content, |_| Ok(()))
}

/// [`verify_file`], handing each row to `each` once it is checked (its block's hash is checked
/// when the block closes): `pound merge` copies a shard in the same pass that verifies it. On
/// an error, rows already handed on may belong to a block that then fails.
pub fn verify_rows(
    path: &Path,
    header: &[u8],
    first_run: Option<u64>,
    content: &Content,
    mut each: impl FnMut(&[u8]) -> Result<(), VerifyError>,
) -> Result<(), VerifyError> {
    let bad = |message: String| VerifyError::Bad {
        path: path.into(),
        message,
    };
    let io = |error| VerifyError::Io {
        path: path.into(),
        error,
    };
    let mut r = after_header(path, std::fs::File::open(path).map_err(io)?, header)?;
    let mut row = Vec::new();
    let mut h = ContentHasher::new(header, first_run);
    let mut checked = 0;
    while r.next_row(&mut row).map_err(io)? {
        h.row(&row).map_err(|e| bad(e.to_string()))?;
        each(&row)?;
        // Compare each block as it closes, to name the rows that differ.
        if h.blocks.len() > checked {
            check_block(path, content, &h.blocks, checked, first_run)?;
            checked += 1;
        }
    }
    let rows = h.rows_seen();
    let got = h.finish();
    if got.blocks.len() > checked && checked < content.blocks.len() {
        check_block(path, content, &got.blocks, checked, first_run)?;
    }
    if rows != content.rows {
        return Err(bad(format!(
            "holds {rows} rows, its sidecar says {}",
            content.rows
        )));
    }
    if got.sha256 != content.sha256 {
        return Err(bad(
            "its content differs from what was written (SHA-256 in its sidecar)".into(),
        ));
    }
    Ok(())
}

fn check_block(
    path: &Path,
    content: &Content,
    got: &[String],
    k: usize,
    first_run: Option<u64>,
) -> Result<(), VerifyError> {
    if content.blocks.get(k) == got.get(k) {
        return Ok(());
    }
    let (lo, hi) = (k as u64 * BLOCK_ROWS, (k as u64 + 1) * BLOCK_ROWS);
    let hi = hi.min(content.rows.max(lo + 1));
    let runs = match first_run {
        Some(f) => format!("runs {}..{} ", f + lo, f + hi),
        None => String::new(),
    };
    Err(VerifyError::Bad {
        path: path.into(),
        message: format!(
            "{runs}(lines {}..{}) differ from what the sweep wrote (content hash in its sidecar): the file was edited",
            lo + 2,
            hi + 2
        ),
    })
}

/// SHA-256 of a file's bytes.
pub fn file_sha256(path: &Path) -> std::io::Result<String> {
    let mut f = std::fs::File::open(path)?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok(hex(h.finalize()))
}

/// A writer that hashes what passes through it (Parquet output and summaries).
pub struct HashingWriter<W> {
    inner: W,
    hash: Sha256,
}

impl<W: std::io::Write> HashingWriter<W> {
    pub fn new(inner: W) -> Self {
        HashingWriter {
            inner,
            hash: Sha256::new(),
        }
    }

    pub fn into_parts(self) -> (W, String) {
        (self.inner, hex(self.hash.finalize()))
    }
}

impl<W: std::io::Write> std::io::Write for HashingWriter<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hash.update(&buf[..n]);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_end_outside_quotes() {
        assert_eq!(row_len(b"1,a\n2,b\n"), Some(4));
        assert_eq!(row_len(b"1,\"a\nb\",c\n2"), Some(10));
        assert_eq!(row_len(b"1,\"a\"\"b\",c\n"), Some(11));
        assert_eq!(row_len(b"1,a"), None);
        let mut r = RowReader::new(&b"h\n1,\"x\ny\"\n2,z"[..]);
        let mut row = Vec::new();
        let mut got = Vec::new();
        while r.next_row(&mut row).unwrap() {
            got.push(row.clone());
        }
        assert_eq!(
            got,
            vec![b"h\n".to_vec(), b"1,\"x\ny\"\n".to_vec(), b"2,z".to_vec()]
        );
    }

    #[test]
    fn the_hasher_checks_run_order_and_names_the_line() {
        let mut h = ContentHasher::new(b"run,x\n", Some(5));
        h.row(b"5,1\n").unwrap();
        let e = h.row(b"7,1\n").unwrap_err();
        assert_eq!(
            e,
            ContentError::Row {
                line: 3,
                message: "holds run `7` where run 6 was expected (rows missing, repeated or out of order)".into()
            }
        );
        assert!(h.row(b"6,1").is_err(), "a cut-off row");
    }

    #[test]
    fn a_prefix_is_verified_against_its_journal() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("r.csv.partial");
        let header = b"run,x\n";
        let body = b"0,a\n1,b\n2,c\n3,";
        let mut all = header.to_vec();
        all.extend_from_slice(body);
        std::fs::write(&p, &all).unwrap();
        let mut h = ContentHasher::new(header, Some(0));
        h.rows(b"0,a\n1,b\n").unwrap();
        let (bytes, sha) = (h.bytes(), h.digest());
        let ok = verify_prefix(&p, header, 0, 2, bytes, &sha).unwrap();
        assert_eq!(ok.rows_seen(), 2);
        // A journal that claims more rows, fewer bytes, another checksum or another start.
        for (rows, b, s, first) in [
            (3, bytes, sha.as_str(), 0),
            (2, bytes - 1, sha.as_str(), 0),
            (2, bytes, "00", 0),
            (2, bytes, sha.as_str(), 1),
            (999_999, 1 << 40, sha.as_str(), 0),
        ] {
            assert!(verify_prefix(&p, header, first, rows, b, s).is_err());
        }
        // An edited row inside the prefix.
        all[header.len() + 2] = b'z';
        std::fs::write(&p, &all).unwrap();
        let e = verify_prefix(&p, header, 0, 2, bytes, &sha).unwrap_err();
        assert!(e.to_string().contains("checksum"), "{e}");
    }
}

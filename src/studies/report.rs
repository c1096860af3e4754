//! What a study of a results table gives (`pound fragility`, `pound ida`, and the Python
//! package's functions of the same names): the CSV it writes, the lines it says, its notices in
//! their places among those lines, and its figure.

use crate::studies::plot::Panel;

/// What a study gives: what its command writes, prints and draws.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyReport {
    /// The study's table: the bytes of the CSV (`-o`).
    pub csv: String,
    /// Its other tables, each by name and as CSV: a fragility's `fits` (`--fits`), an IDA's
    /// `long` form (`--long`).
    pub tables: Vec<(&'static str, String)>,
    /// The summary and its tables, with their line ends (standard output).
    pub said: String,
    /// Notices, a line each with no line end (standard error).
    pub notices: Vec<String>,
    /// Where each notice comes among the lines said: the length of `said` when it was told.
    pub notices_at: Vec<usize>,
    /// The figure (`--plot`).
    pub panels: Vec<Panel>,
}

impl StudyReport {
    /// Tell `said` and `notices` in the order the study told them ([`tell`]).
    pub fn tell<E>(
        &self,
        say: impl FnMut(&str) -> Result<(), E>,
        note: impl FnMut(&str),
    ) -> Result<(), E> {
        tell(&self.said, &self.notices, &self.notices_at, say, note)
    }
}

/// Tell `said` and `notices` in the order a study told them: each stretch of `said` up to a
/// notice's place (`notices_at`) to `say`, then the notice to `note`. A failed `say` (standard
/// output closed) ends the telling there.
pub fn tell<E>(
    said: &str,
    notices: &[String],
    notices_at: &[usize],
    mut say: impl FnMut(&str) -> Result<(), E>,
    mut note: impl FnMut(&str),
) -> Result<(), E> {
    let mut from = 0;
    for (n, &at) in notices.iter().zip(notices_at) {
        if at > from {
            say(&said[from..at])?;
            from = at;
        }
        note(n);
    }
    if said.len() > from {
        say(&said[from..])?;
    }
    Ok(())
}

/// What a study tells as it goes: lines said, notices, and where among the lines each came.
#[derive(Debug, Default)]
pub(crate) struct Telling {
    pub(crate) said: String,
    pub(crate) notices: Vec<String>,
    pub(crate) notices_at: Vec<usize>,
}

impl Telling {
    /// A line (its line end added).
    pub(crate) fn say(&mut self, line: impl std::fmt::Display) {
        use std::fmt::Write as _;
        let _ = writeln!(self.said, "{line}");
    }

    /// A notice, after the lines said so far.
    pub(crate) fn note(&mut self, line: impl std::fmt::Display) {
        self.notices_at.push(self.said.len());
        self.notices.push(line.to_string());
    }
}

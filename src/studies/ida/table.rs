//! An IDA's tables as CSV: the wide table of `pound ida -o` (a row per level, each curve a
//! column) and the long form of `--long` (a row per curve and level).

use super::{Ida, IdaSpec};
use crate::io::csv::quote_cell as quote;

impl Ida {
    /// One row per level: the intensity, the curves there, the fractiles, the curves collapsed
    /// there and their share, each curve's demand. A collapse is an infinite demand, written
    /// `inf` (a fractile it reaches too); an empty cell is no value (no run there, or none left).
    pub fn csv(&self, spec: &IdaSpec) -> String {
        let head: Vec<String> = self.header(spec).iter().map(|h| quote(h)).collect();
        let mut s = head.join(",");
        s.push('\n');
        for (l, im) in self.ims.iter().enumerate() {
            s.push_str(&format!("{im},{}", self.counts[l]));
            for f in self.fractiles[l] {
                // No fractile of no runs: an empty cell.
                s.push(',');
                if self.counts[l] > 0 {
                    s.push_str(&f.to_string());
                }
            }
            s.push_str(&format!(",{},", self.collapsed[l]));
            if let Some(f) = self.collapsed_fraction(l) {
                s.push_str(&f.to_string());
            }
            for (_, v) in &self.curves {
                s.push(',');
                if let Some(x) = v[l] {
                    s.push_str(&x.to_string());
                }
            }
            s.push('\n');
        }
        s
    }

    /// The curves in long form, a row per curve and level where it has a value: the curve (its
    /// `--curves` cells joined by `/`, under their names so joined; `curve` where that would name a
    /// column twice), the intensity, the demand (`inf` from its first collapse) and whether it
    /// has collapsed there (1 or 0).
    pub fn long_csv(&self, spec: &IdaSpec) -> String {
        let mut head = vec![spec.by.join("/"), spec.im.clone(), spec.edp.clone()];
        head.push("collapsed".into());
        if crate::io::table::duplicate_column(&head).is_some() {
            head[0] = "curve".into();
        }
        let mut s = (head.iter().map(|h| quote(h)))
            .collect::<Vec<_>>()
            .join(",");
        s.push('\n');
        for (name, values) in &self.curves {
            for (im, v) in self.ims.iter().zip(values) {
                if let Some(x) = v {
                    let collapsed = u8::from(x.is_infinite());
                    s.push_str(&format!("{},{im},{x},{collapsed}\n", quote(name)));
                }
            }
        }
        s
    }
}

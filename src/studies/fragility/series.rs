//! `pound fragility --series COLUMN`: the study of each value of a column (a gap, a period
//! ratio) in one figure and one table, so that curves of several settings are read side by side.

use super::{study, FragilityError, FragilityOptions};
use crate::io::table::{caption, value_label, Filter, Table};
use crate::studies::report::StudyReport;

/// At most this many values of a `--series` column: more curves than a figure can tell apart.
pub const MAX_SERIES: usize = 12;

/// The study of each value of `column` among the rows `o.filters` keeps (each a `--where
/// COLUMN=VALUE` study), numeric values in order: its lines under a heading per value, its
/// counts and fits in one table each with `column` first, and its curves in one panel, each
/// named by its value.
pub(super) fn study_series(
    table: &Table,
    o: &FragilityOptions,
    column: &str,
) -> Result<StudyReport, FragilityError> {
    let c = table.col(column)?;
    // A series splits the runs by a setting: not by what each curve is made of.
    let im = o.im.clone().unwrap_or_else(|| super::default_im(table));
    let by = o.by.clone().unwrap_or_else(|| super::default_groups(table));
    let clash = if column == im {
        Some("the intensity measure, whose levels each curve is fitted over")
    } else if column == o.edp {
        Some("the demand the curves count")
    } else if o.bootstrap > 0 && column == by {
        Some("the column whose groups the bootstrap draws (--bootstrap-groups, default record): each value would hold one group")
    } else {
        None
    };
    if let Some(what) = clash {
        return Err(FragilityError::Refused(format!(
            "--series {column}: {column} is {what}; give --series a setting the runs differ in (a gap, a period, a law)"
        )));
    }
    let filters = Filter::parse_all(&o.filters)?;
    let mut values: Vec<String> = Vec::new();
    for i in table.select(&filters)? {
        let v = table.rows[i][c].trim();
        if !v.is_empty() && !values.iter().any(|x| x == v) {
            values.push(v.to_string());
        }
    }
    let numbers: Option<Vec<f64>> = values.iter().map(|v| v.parse().ok()).collect();
    if let Some(n) = &numbers {
        let mut order: Vec<usize> = (0..values.len()).collect();
        order.sort_by(|&a, &b| n[a].total_cmp(&n[b]));
        values = order.into_iter().map(|k| values[k].clone()).collect();
    }
    if values.len() < 2 || values.len() > MAX_SERIES {
        return Err(FragilityError::Refused(format!(
            "--series {column}: {} {} among the rows kept ({}): a series needs 2 to {MAX_SERIES}; {}",
            values.len(),
            if values.len() == 1 { "value" } else { "values" },
            match values.len() {
                n if n > 6 => format!("{}, ...", values[..5].join(", ")),
                _ => values.join(", "),
            },
            if values.len() < 2 {
                "drop --series for one curve"
            } else {
                "keep fewer with --where"
            }
        )));
    }
    let mut out = StudyReport {
        csv: String::new(),
        tables: vec![("fits", String::new())],
        said: String::new(),
        notices: Vec::new(),
        notices_at: Vec::new(),
        panels: Vec::new(),
    };
    let mut styles = 0;
    for v in &values {
        let mut one = o.clone();
        one.series = None;
        one.filters.push(format!("{column}={v}"));
        let r = study(table, &one)?;
        let shown = value_label(column, v);
        let heading = format!("\n{column} = {v}:\n");
        let at = out.said.len() + heading.len();
        out.said.push_str(&heading);
        out.notices_at.extend(r.notices_at.iter().map(|k| at + k));
        // A notice names the value it is about.
        out.notices
            .extend(r.notices.into_iter().map(|n| match n.split_once(": ") {
                Some((kind, rest)) => format!("{kind}: ({column} = {v}) {rest}"),
                None => format!("({column} = {v}) {n}"),
            }));
        out.said.push_str(&r.said);
        prefix_rows(&mut out.csv, &r.csv, column, v);
        if let Some((_, fits)) = r.tables.iter().find(|(n, _)| *n == "fits") {
            prefix_rows(&mut out.tables[0].1, fits, column, v);
        }
        let mut panel = r
            .panels
            .into_iter()
            .next()
            .expect("a fragility draws one panel");
        let used = panel
            .series
            .iter()
            .filter_map(|s| s.style)
            .max()
            .map_or(0, |m| m + 1);
        for s in &mut panel.series {
            if !s.name.is_empty() {
                s.name = format!("{shown}, {}", s.name);
            }
            s.style = s.style.map(|k| k + styles);
        }
        styles += used;
        match out.panels.first_mut() {
            None => {
                // The first value's title, its own filter left out and the column named.
                let own = caption(&Filter::parse_all(&one.filters)?);
                let all = caption(&filters);
                let by = format!("by {}", crate::io::table::name(column));
                panel.title = match panel.title.strip_suffix(&format!("; {own}")) {
                    Some(head) if all.is_empty() => format!("{head}, {by}"),
                    Some(head) => format!("{head}, {by}; {all}"),
                    None => format!("{}, {by}", panel.title),
                };
                out.panels.push(panel);
            }
            Some(first) => first.series.extend(panel.series),
        }
    }
    Ok(out)
}

/// Append `csv`'s rows to `into` with `column` = `value` first (the header once).
fn prefix_rows(into: &mut String, csv: &str, column: &str, value: &str) {
    let mut lines = csv.lines();
    let head = lines.next().unwrap_or_default();
    if into.is_empty() {
        into.push_str(&format!("{column},{head}\n"));
    }
    let cell = crate::io::csv::quote_cell(value);
    for l in lines {
        into.push_str(&format!("{cell},{l}\n"));
    }
}

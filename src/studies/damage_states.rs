//! Named damage states: ordered limits of a demand (e.g. the peak interstorey drift ratio), each
//! a threshold of `pound fragility` (`--damage-states NAME` or a TOML file).
//!
//! Built in: HAZUS-MH's drift ratios of structural damage for concrete moment frames, low-rise
//! (C1L), per seismic design level. Source: FEMA, *Multi-hazard Loss Estimation Methodology,
//! Earthquake Model, HAZUS-MH MR5 Technical Manual* (2010), Chapter 5, Tables 5.9a (high-code),
//! 5.9b (moderate-code), 5.9c (low-code) and 5.9d (pre-code), "average inter-story drift ratio of
//! structural damage states". The values agree, to the 0.001 they are rounded to there, with the
//! C1 drift table of USGS ShakeCast's Advanced Engineering Building Module
//! (`sc/app/aebm/capacity.py`, whose high-code complete state reads 0.8 for 0.08).

use serde::Deserialize;
use std::path::Path;

/// Ordered, named limits of one demand.
#[derive(Debug, Clone, PartialEq)]
pub struct DamageStates {
    pub name: String,
    /// Where the limits come from.
    pub source: String,
    /// Ascending: (state, limit). Exceedance of a state is `EDP > limit`.
    pub states: Vec<(String, f64)>,
    /// The limits' unit, as the table of meanings writes units (`m/m` for drift ratios); None
    /// where a file gives none.
    pub unit: Option<String>,
}

const HAZUS: &str = "HAZUS-MH MR5 Technical Manual (FEMA 2010), Table 5.9";
const STATES: [&str; 4] = ["slight", "moderate", "extensive", "complete"];

/// The built-in sets: name, table and drift ratio limits.
const BUILT_IN: [(&str, &str, [f64; 4]); 4] = [
    ("hazus-c1l-high", "a", [0.0050, 0.0100, 0.0300, 0.0800]),
    ("hazus-c1l-moderate", "b", [0.0050, 0.0087, 0.0233, 0.0600]),
    ("hazus-c1l-low", "c", [0.0050, 0.0080, 0.0200, 0.0500]),
    ("hazus-c1l-pre", "d", [0.0040, 0.0064, 0.0160, 0.0400]),
];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStates {
    name: Option<String>,
    source: Option<String>,
    unit: Option<String>,
    #[serde(rename = "state")]
    states: Vec<RawState>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawState {
    name: String,
    limit: f64,
}

impl DamageStates {
    /// The names of the built-in sets, comma-separated.
    pub fn built_in_names() -> String {
        BUILT_IN.map(|b| b.0).join(", ")
    }

    /// A built-in set by name, or a TOML file (`[[state]]` with `name` and `limit`, ascending;
    /// `name` and `source` optional).
    pub fn get(given: &str) -> Result<DamageStates, String> {
        if let Some((name, table, limits)) = BUILT_IN.iter().find(|b| b.0 == given) {
            return Ok(DamageStates {
                name: name.to_string(),
                source: format!("{HAZUS}{table}, C1L"),
                states: STATES
                    .iter()
                    .zip(limits)
                    .map(|(s, l)| (s.to_string(), *l))
                    .collect(),
                unit: Some("m/m".into()),
            });
        }
        let path = Path::new(given);
        if !path.is_file() {
            return Err(format!(
                "--damage-states `{given}`: not a built-in set ({}) or a file",
                Self::built_in_names()
            ));
        }
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{}: cannot read: {e}", given))?;
        let raw: RawStates = toml::from_str(&text).map_err(|e| {
            let m = crate::plan::config::in_toml_words(e.to_string());
            // `unit` is the set's, written before the first [[state]] (after it, TOML puts it
            // in that state).
            let hint = if m.contains("unknown field `unit`") {
                "\nunit is the set's: write it at the top of the file, before the first [[state]]"
            } else {
                ""
            };
            format!("{given}: {m}{hint}")
        })?;
        if raw.states.is_empty() {
            return Err(format!("{given}: no [[state]]: give at least one"));
        }
        for (i, s) in raw.states.iter().enumerate() {
            // A name labels a table row, a legend entry and a CSV cell: one line of text,
            // telling its state apart.
            if s.name.trim().is_empty() {
                return Err(format!(
                    "{given}: state[{i}]: name is empty: give each state a name"
                ));
            }
            if s.name.chars().any(char::is_control) {
                return Err(format!(
                    "{given}: state[{i}] name {:?}: expected one line of text (no line break, tab or other control character)",
                    s.name
                ));
            }
            if let Some(j) = raw.states[..i]
                .iter()
                .position(|o| o.name.trim() == s.name.trim())
            {
                return Err(format!(
                    "{given}: state[{i}] name `{}` is also state[{j}]'s: give each state its own name",
                    s.name
                ));
            }
            if !s.limit.is_finite() {
                return Err(format!(
                    "{given}: state[{i}] ({}): limit {} is not finite",
                    s.name, s.limit
                ));
            }
            if i > 0 && s.limit <= raw.states[i - 1].limit {
                return Err(format!(
                    "{given}: state[{i}] ({}): limit {} is not above the state before ({}): give the states mildest first, limits ascending",
                    s.name,
                    s.limit,
                    raw.states[i - 1].limit
                ));
            }
        }
        Ok(DamageStates {
            name: raw.name.unwrap_or_else(|| given.to_string()),
            source: raw.source.unwrap_or_else(|| given.to_string()),
            states: raw.states.into_iter().map(|s| (s.name, s.limit)).collect(),
            unit: raw.unit,
        })
    }

    pub fn limits(&self) -> Vec<f64> {
        self.states.iter().map(|s| s.1).collect()
    }

    /// Why these limits cannot be read on column `edp` whose unit is `unit` (from the table of
    /// meanings): their unit is another. None where they can, or where either unit is unknown.
    pub fn unit_mismatch(&self, edp: &str, unit: Option<&str>) -> Option<String> {
        let (mine, theirs) = (self.unit.as_deref()?, unit?);
        (mine != theirs).then(|| {
            let example = if mine == "m/m" {
                " (a drift ratio column such as b1_peak_drift_ratio)"
            } else {
                ""
            };
            format!(
                "--damage-states {}: its limits are in {mine}, but --edp {edp} is in {theirs}: give an EDP in {mine}{example}, or limits in {theirs} (a damage-state file with unit = \"{theirs}\" at its top, before the first [[state]])",
                self.name
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_sets_ascend_and_files_are_checked() {
        for (name, ..) in BUILT_IN {
            let d = DamageStates::get(name).unwrap();
            assert!(d.limits().windows(2).all(|w| w[0] < w[1]), "{name}");
            assert!(d.source.contains("Table 5.9"));
        }
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("ds.toml");
        let write = |text: &str| std::fs::write(&p, text).unwrap();
        write("[[state]]\nname = \"light\"\nlimit = 0.004\n[[state]]\nname = \"heavy\"\nlimit = 0.02\n");
        let d = DamageStates::get(p.to_str().unwrap()).unwrap();
        assert_eq!(
            d.states,
            vec![("light".into(), 0.004), ("heavy".into(), 0.02)]
        );
        write("[[state]]\nname = \"a\"\nlimit = 0.02\n[[state]]\nname = \"b\"\nlimit = 0.01\n");
        let e = DamageStates::get(p.to_str().unwrap()).unwrap_err();
        assert!(e.contains("state[1] (b)") && e.contains("ascending"), "{e}");
        let e = DamageStates::get("hazus-c9").unwrap_err();
        assert!(e.contains("hazus-c1l-high"), "{e}");
    }
}

//! Named damage states: ordered limits of a demand (e.g. the peak interstorey drift ratio), each
//! a threshold of `pound fragility` (`--damage-states NAME` or a TOML file;
//! `--damage-states list` prints the built-in sets).
//!
//! Built in:
//!
//! - `hazus-TYPE-LEVEL`: HAZUS-MH's drift ratios of structural damage (slight, moderate,
//!   extensive, complete) for every model building type and seismic design level its tables
//!   give. Source: FEMA, *Multi-hazard Loss Estimation Methodology, Earthquake Model, HAZUS-MH
//!   MR5 Technical Manual* (2010), Chapter 5, Tables 5.9a (high-code), 5.9b (moderate-code),
//!   5.9c (low-code) and 5.9d (pre-code), "average inter-story drift ratio of structural damage
//!   states". Unreinforced masonry (URML, URMM) and the frames with unreinforced masonry infill
//!   (S5, C3) appear at low and pre code only, as in the tables. Their demand is the peak
//!   interstorey drift ratio (`bK_peak_drift_ratio`).
//!
//!   The values are those of NHERI SimCenter's DamageAndLossModelLibrary
//!   (`data_sources/seismic/building/portfolio/Hazus v5.1/input_files/hazus_data_eq.json`,
//!   `Structural_Fragility_Groups.EDP_limits`, commit 1ab3c1d5; its Hazus v6.1 copy holds the
//!   same values at these four levels, and adds two above them), which transcribes them to the
//!   table's 0.0001. They were checked against two other transcriptions:
//!   - the same tables' spectral displacement medians, as Rt's `RHazusBuildingModel.cpp`
//!     (github.com/steva44/Rts, commit 3609161c) gives them to 0.01 in: a type's median is its
//!     drift ratio times one constant (the fraction of the roof height at the pushover mode's
//!     displacement times that height), so every drift ratio here times its type's constant
//!     must give Rt's median to the rounding of both, and does for all 128 sets (the unit test
//!     `drift_ratios_agree_with_the_spectral_displacement_medians`);
//!   - USGS ShakeCast's Advanced Engineering Building Module (`sc/app/aebm/capacity.py`,
//!     github.com/usgs/shakecast, commit 2c5f8e95), per building system (the low-rise type's
//!     values) at 0.001: it agrees at every system and level the tables give except three: the
//!     complete state of C1 and C2 at high code reads 0.8 for 0.08; mobile homes take the wood
//!     high-code limits (0.004/0.012/0.04/0.1) at every level; W1 and W2 at low and pre code
//!     read 0.004/0.01/0.025/0.06 and 0.003/0.008/0.02/0.05, where SimCenter, and Rt's medians,
//!     give 0.004/0.0099/0.0306/0.075 and 0.0032/0.0079/0.0245/0.06. (It also gives S5, C3 and
//!     URM at high and moderate code, which the tables do not.)
//!
//! - `fema-p58-residual`: FEMA P-58-1, *Seismic Performance Assessment of Buildings, Volume 1:
//!   Methodology* (2012), Table 5-3, damage states for residual drift: DS1 0.2 % (realignment
//!   of nonstructural components), DS2 0.5 % (structural realignment), DS3 1 % (major structural
//!   realignment and repair), DS4 2 % (demolition: collapse level, not economically repairable).
//!   Their demand is the residual interstorey drift ratio (`bK_residual_drift_ratio`). These
//!   four values were not compared with a second transcription (none was found to read).

use serde::Deserialize;
use std::path::Path;

/// The demand a built-in set's limits are of (a file's set names none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DemandKind {
    /// The largest interstorey drift ratio a building reached (`bK_peak_drift_ratio`).
    PeakDrift,
    /// The largest residual interstorey drift ratio of a building at rest after the motion
    /// (`bK_residual_drift_ratio`).
    ResidualDrift,
}

impl DemandKind {
    /// The suffix of a building's column of this demand (`bK_` before it).
    pub fn suffix(self) -> &'static str {
        match self {
            DemandKind::PeakDrift => "peak_drift_ratio",
            DemandKind::ResidualDrift => "residual_drift_ratio",
        }
    }

    pub fn words(self) -> &'static str {
        match self {
            DemandKind::PeakDrift => "peak interstorey drift ratio",
            DemandKind::ResidualDrift => "residual interstorey drift ratio",
        }
    }
}

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
    /// The demand the limits are of (the built-in sets); None for a file's.
    pub demand: Option<DemandKind>,
}

const HAZUS: &str = "HAZUS-MH MR5 Technical Manual (FEMA 2010), Table 5.9";
const STATES: [&str; 4] = ["slight", "moderate", "extensive", "complete"];

/// The seismic design levels of HAZUS's Tables 5.9a-d: name (the last part of a set's name) and
/// table letter.
const LEVELS: [(&str, &str); 4] = [("high", "a"), ("moderate", "b"), ("low", "c"), ("pre", "d")];

/// Drift ratios at the thresholds of slight, moderate, extensive and complete damage, per code
/// level (high, moderate, low, pre), None where a level's table has no such type.
type ByLevel = [Option<[f64; 4]>; 4];

/// HAZUS Tables 5.9a-d, one row per model building type in the tables' order: the type, what
/// it is (HAZUS's Table 3.1 names), and per level (high, moderate, low, pre code: Tables 5.9a,
/// b, c, d) the drift ratios at the thresholds of slight, moderate, extensive and complete
/// structural damage, or None where that table has no such type.
#[rustfmt::skip]
const HAZUS_TYPES: [(&str, &str, ByLevel); 36] = [
    ("W1", "wood, light frame", [
        Some([0.0040, 0.0120, 0.0400, 0.1000]), // a
        Some([0.0040, 0.0099, 0.0306, 0.0750]), // b
        Some([0.0040, 0.0099, 0.0306, 0.0750]), // c
        Some([0.0032, 0.0079, 0.0245, 0.0600]), // d
    ]),
    ("W2", "wood, commercial and industrial", [
        Some([0.0040, 0.0120, 0.0400, 0.1000]), // a
        Some([0.0040, 0.0099, 0.0306, 0.0750]), // b
        Some([0.0040, 0.0099, 0.0306, 0.0750]), // c
        Some([0.0032, 0.0079, 0.0245, 0.0600]), // d
    ]),
    ("S1L", "steel moment frame, low-rise", [
        Some([0.0060, 0.0120, 0.0300, 0.0800]), // a
        Some([0.0060, 0.0104, 0.0235, 0.0600]), // b
        Some([0.0060, 0.0096, 0.0203, 0.0500]), // c
        Some([0.0048, 0.0076, 0.0162, 0.0400]), // d
    ]),
    ("S1M", "steel moment frame, mid-rise", [
        Some([0.0040, 0.0080, 0.0200, 0.0533]), // a
        Some([0.0040, 0.0069, 0.0157, 0.0400]), // b
        Some([0.0040, 0.0064, 0.0135, 0.0333]), // c
        Some([0.0032, 0.0051, 0.0108, 0.0267]), // d
    ]),
    ("S1H", "steel moment frame, high-rise", [
        Some([0.0030, 0.0060, 0.0150, 0.0400]), // a
        Some([0.0030, 0.0052, 0.0118, 0.0300]), // b
        Some([0.0030, 0.0048, 0.0101, 0.0250]), // c
        Some([0.0024, 0.0038, 0.0081, 0.0200]), // d
    ]),
    ("S2L", "steel braced frame, low-rise", [
        Some([0.0050, 0.0100, 0.0300, 0.0800]), // a
        Some([0.0050, 0.0087, 0.0233, 0.0600]), // b
        Some([0.0050, 0.0080, 0.0200, 0.0500]), // c
        Some([0.0040, 0.0064, 0.0160, 0.0400]), // d
    ]),
    ("S2M", "steel braced frame, mid-rise", [
        Some([0.0033, 0.0067, 0.0200, 0.0533]), // a
        Some([0.0033, 0.0058, 0.0156, 0.0400]), // b
        Some([0.0033, 0.0053, 0.0133, 0.0333]), // c
        Some([0.0027, 0.0043, 0.0107, 0.0267]), // d
    ]),
    ("S2H", "steel braced frame, high-rise", [
        Some([0.0025, 0.0050, 0.0150, 0.0400]), // a
        Some([0.0025, 0.0043, 0.0117, 0.0300]), // b
        Some([0.0025, 0.0040, 0.0100, 0.0250]), // c
        Some([0.0020, 0.0032, 0.0080, 0.0200]), // d
    ]),
    ("S3", "steel light frame", [
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // a
        Some([0.0040, 0.0070, 0.0187, 0.0525]), // b
        Some([0.0040, 0.0064, 0.0161, 0.0438]), // c
        Some([0.0032, 0.0051, 0.0128, 0.0350]), // d
    ]),
    ("S4L", "steel frame with cast-in-place concrete shear walls, low-rise", [
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // a
        Some([0.0040, 0.0069, 0.0187, 0.0525]), // b
        Some([0.0040, 0.0064, 0.0161, 0.0438]), // c
        Some([0.0032, 0.0051, 0.0128, 0.0350]), // d
    ]),
    ("S4M", "steel frame with cast-in-place concrete shear walls, mid-rise", [
        Some([0.0027, 0.0053, 0.0160, 0.0467]), // a
        Some([0.0027, 0.0046, 0.0125, 0.0350]), // b
        Some([0.0027, 0.0043, 0.0107, 0.0292]), // c
        Some([0.0021, 0.0034, 0.0086, 0.0233]), // d
    ]),
    ("S4H", "steel frame with cast-in-place concrete shear walls, high-rise", [
        Some([0.0020, 0.0040, 0.0120, 0.0350]), // a
        Some([0.0020, 0.0035, 0.0093, 0.0262]), // b
        Some([0.0020, 0.0032, 0.0080, 0.0219]), // c
        Some([0.0016, 0.0026, 0.0064, 0.0175]), // d
    ]),
    ("S5L", "steel frame with unreinforced masonry infill walls, low-rise", [
        None, // a
        None, // b
        Some([0.0030, 0.0060, 0.0150, 0.0350]), // c
        Some([0.0024, 0.0048, 0.0120, 0.0280]), // d
    ]),
    ("S5M", "steel frame with unreinforced masonry infill walls, mid-rise", [
        None, // a
        None, // b
        Some([0.0020, 0.0040, 0.0100, 0.0233]), // c
        Some([0.0016, 0.0032, 0.0080, 0.0187]), // d
    ]),
    ("S5H", "steel frame with unreinforced masonry infill walls, high-rise", [
        None, // a
        None, // b
        Some([0.0015, 0.0030, 0.0075, 0.0175]), // c
        Some([0.0012, 0.0024, 0.0060, 0.0140]), // d
    ]),
    ("C1L", "concrete moment frame, low-rise", [
        Some([0.0050, 0.0100, 0.0300, 0.0800]), // a
        Some([0.0050, 0.0087, 0.0233, 0.0600]), // b
        Some([0.0050, 0.0080, 0.0200, 0.0500]), // c
        Some([0.0040, 0.0064, 0.0160, 0.0400]), // d
    ]),
    ("C1M", "concrete moment frame, mid-rise", [
        Some([0.0033, 0.0067, 0.0200, 0.0533]), // a
        Some([0.0033, 0.0058, 0.0156, 0.0400]), // b
        Some([0.0033, 0.0053, 0.0133, 0.0333]), // c
        Some([0.0027, 0.0043, 0.0107, 0.0267]), // d
    ]),
    ("C1H", "concrete moment frame, high-rise", [
        Some([0.0025, 0.0050, 0.0150, 0.0400]), // a
        Some([0.0025, 0.0043, 0.0117, 0.0300]), // b
        Some([0.0025, 0.0040, 0.0100, 0.0250]), // c
        Some([0.0020, 0.0032, 0.0080, 0.0200]), // d
    ]),
    ("C2L", "concrete shear walls, low-rise", [
        Some([0.0040, 0.0100, 0.0300, 0.0800]), // a
        Some([0.0040, 0.0084, 0.0232, 0.0600]), // b
        Some([0.0040, 0.0076, 0.0197, 0.0500]), // c
        Some([0.0032, 0.0061, 0.0158, 0.0400]), // d
    ]),
    ("C2M", "concrete shear walls, mid-rise", [
        Some([0.0027, 0.0067, 0.0200, 0.0533]), // a
        Some([0.0027, 0.0056, 0.0154, 0.0400]), // b
        Some([0.0027, 0.0051, 0.0132, 0.0333]), // c
        Some([0.0021, 0.0041, 0.0105, 0.0267]), // d
    ]),
    ("C2H", "concrete shear walls, high-rise", [
        Some([0.0020, 0.0050, 0.0150, 0.0400]), // a
        Some([0.0020, 0.0042, 0.0116, 0.0300]), // b
        Some([0.0020, 0.0038, 0.0099, 0.0250]), // c
        Some([0.0016, 0.0031, 0.0079, 0.0200]), // d
    ]),
    ("C3L", "concrete frame with unreinforced masonry infill walls, low-rise", [
        None, // a
        None, // b
        Some([0.0030, 0.0060, 0.0150, 0.0350]), // c
        Some([0.0024, 0.0048, 0.0120, 0.0280]), // d
    ]),
    ("C3M", "concrete frame with unreinforced masonry infill walls, mid-rise", [
        None, // a
        None, // b
        Some([0.0020, 0.0040, 0.0100, 0.0233]), // c
        Some([0.0016, 0.0032, 0.0080, 0.0187]), // d
    ]),
    ("C3H", "concrete frame with unreinforced masonry infill walls, high-rise", [
        None, // a
        None, // b
        Some([0.0015, 0.0030, 0.0075, 0.0175]), // c
        Some([0.0012, 0.0024, 0.0060, 0.0140]), // d
    ]),
    ("PC1", "precast concrete tilt-up walls", [
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // a
        Some([0.0040, 0.0070, 0.0187, 0.0525]), // b
        Some([0.0040, 0.0064, 0.0161, 0.0438]), // c
        Some([0.0032, 0.0051, 0.0128, 0.0350]), // d
    ]),
    ("PC2L", "precast concrete frames with concrete shear walls, low-rise", [
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // a
        Some([0.0040, 0.0069, 0.0187, 0.0525]), // b
        Some([0.0040, 0.0064, 0.0161, 0.0438]), // c
        Some([0.0032, 0.0051, 0.0128, 0.0350]), // d
    ]),
    ("PC2M", "precast concrete frames with concrete shear walls, mid-rise", [
        Some([0.0027, 0.0053, 0.0160, 0.0467]), // a
        Some([0.0027, 0.0046, 0.0125, 0.0350]), // b
        Some([0.0027, 0.0043, 0.0107, 0.0292]), // c
        Some([0.0021, 0.0034, 0.0086, 0.0233]), // d
    ]),
    ("PC2H", "precast concrete frames with concrete shear walls, high-rise", [
        Some([0.0020, 0.0040, 0.0120, 0.0350]), // a
        Some([0.0020, 0.0035, 0.0094, 0.0263]), // b
        Some([0.0020, 0.0032, 0.0080, 0.0219]), // c
        Some([0.0016, 0.0026, 0.0064, 0.0175]), // d
    ]),
    ("RM1L", "reinforced masonry bearing walls with wood or metal deck diaphragms, low-rise", [
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // a
        Some([0.0040, 0.0069, 0.0187, 0.0525]), // b
        Some([0.0040, 0.0064, 0.0161, 0.0438]), // c
        Some([0.0032, 0.0051, 0.0128, 0.0350]), // d
    ]),
    ("RM1M", "reinforced masonry bearing walls with wood or metal deck diaphragms, mid-rise", [
        Some([0.0027, 0.0053, 0.0160, 0.0467]), // a
        Some([0.0027, 0.0046, 0.0125, 0.0350]), // b
        Some([0.0027, 0.0043, 0.0107, 0.0292]), // c
        Some([0.0021, 0.0034, 0.0086, 0.0233]), // d
    ]),
    ("RM2L", "reinforced masonry bearing walls with precast concrete diaphragms, low-rise", [
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // a
        Some([0.0040, 0.0069, 0.0187, 0.0525]), // b
        Some([0.0040, 0.0064, 0.0161, 0.0438]), // c
        Some([0.0032, 0.0051, 0.0128, 0.0350]), // d
    ]),
    ("RM2M", "reinforced masonry bearing walls with precast concrete diaphragms, mid-rise", [
        Some([0.0027, 0.0053, 0.0160, 0.0467]), // a
        Some([0.0027, 0.0046, 0.0125, 0.0350]), // b
        Some([0.0027, 0.0043, 0.0107, 0.0292]), // c
        Some([0.0021, 0.0034, 0.0086, 0.0233]), // d
    ]),
    ("RM2H", "reinforced masonry bearing walls with precast concrete diaphragms, high-rise", [
        Some([0.0020, 0.0040, 0.0120, 0.0350]), // a
        Some([0.0020, 0.0035, 0.0094, 0.0263]), // b
        Some([0.0020, 0.0032, 0.0080, 0.0219]), // c
        Some([0.0016, 0.0026, 0.0064, 0.0175]), // d
    ]),
    ("URML", "unreinforced masonry bearing walls, low-rise", [
        None, // a
        None, // b
        Some([0.0030, 0.0060, 0.0150, 0.0350]), // c
        Some([0.0024, 0.0048, 0.0120, 0.0280]), // d
    ]),
    ("URMM", "unreinforced masonry bearing walls, mid-rise", [
        None, // a
        None, // b
        Some([0.0020, 0.0040, 0.0100, 0.0233]), // c
        Some([0.0016, 0.0032, 0.0080, 0.0187]), // d
    ]),
    ("MH", "mobile homes", [
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // a
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // b
        Some([0.0040, 0.0080, 0.0240, 0.0700]), // c
        Some([0.0032, 0.0064, 0.0192, 0.0560]), // d
    ]),
];

const P58: &str = "FEMA P-58-1 (2012), Table 5-3, damage states for residual drift";

/// FEMA P-58-1's residual drift damage states and their residual drift ratios.
const P58_STATES: [(&str, f64); 4] = [("DS1", 0.002), ("DS2", 0.005), ("DS3", 0.01), ("DS4", 0.02)];

/// The name `list` takes in `--damage-states`: print the built-in sets.
pub const LIST: &str = "list";

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

/// A HAZUS set's name: `hazus-<type>-<level>`, lower case.
fn hazus_name(kind: &str, level: &str) -> String {
    format!("hazus-{}-{level}", kind.to_ascii_lowercase())
}

fn hazus_set(kind: &str, (level, table): (&str, &str), limits: &[f64; 4]) -> DamageStates {
    DamageStates {
        name: hazus_name(kind, level),
        source: format!("{HAZUS}{table}, {kind}"),
        states: STATES
            .iter()
            .zip(limits)
            .map(|(s, l)| (s.to_string(), *l))
            .collect(),
        unit: Some("m/m".into()),
        demand: Some(DemandKind::PeakDrift),
    }
}

fn digits(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())
}

impl DamageStates {
    /// Every built-in set: the HAZUS sets by building type in the tables' order, each type's
    /// code levels from high to pre, then FEMA P-58's residual drift states.
    pub fn built_in() -> Vec<DamageStates> {
        let mut sets = Vec::new();
        for (kind, _, levels) in &HAZUS_TYPES {
            for (level, limits) in LEVELS.iter().zip(levels) {
                if let Some(limits) = limits {
                    sets.push(hazus_set(kind, *level, limits));
                }
            }
        }
        sets.push(DamageStates {
            name: "fema-p58-residual".into(),
            source: P58.into(),
            states: P58_STATES
                .iter()
                .map(|(s, l)| (s.to_string(), *l))
                .collect(),
            unit: Some("m/m".into()),
            demand: Some(DemandKind::ResidualDrift),
        });
        sets
    }

    /// The names of the built-in sets, in the order of [`DamageStates::built_in`].
    pub fn built_in_names() -> Vec<String> {
        Self::built_in().into_iter().map(|d| d.name).collect()
    }

    /// The built-in sets as a table (`--damage-states list`): name, building type and code
    /// level, demand, source and limits.
    pub fn list() -> String {
        let mut s = String::from(
            "Built-in damage-state sets (pound fragility RESULTS.csv --edp COLUMN --damage-states SET; or a TOML file of [[state]] name and limit). A run is past a state where its EDP exceeds the state's limit; every limit is a drift ratio (m/m).\n\n| set | building type, code level | EDP (K: the building) | source | limits |\n|---|---|---|---|---|\n",
        );
        let about = |d: &DamageStates| -> String {
            let Some((kind, what, _)) = HAZUS_TYPES.iter().find(|(kind, ..)| {
                d.source.ends_with(&format!(", {kind}")) && d.source.starts_with(HAZUS)
            }) else {
                return "any".into();
            };
            let level = d.name.rsplit('-').next().unwrap_or_default();
            format!("{kind}: {what}, {level} code")
        };
        for d in Self::built_in() {
            let limits: Vec<String> = d
                .states
                .iter()
                .map(|(n, l)| format!("{n} {}", crate::show(*l)))
                .collect();
            let edp = d
                .demand
                .map_or("-".into(), |k| format!("bK_{}", k.suffix()));
            s.push_str(&format!(
                "| {} | {} | {edp} | {} | {} |\n",
                d.name,
                about(&d),
                d.source,
                limits.join(", ")
            ));
        }
        s
    }

    /// Why `given` names no built-in set, and what the built-in names are, grouped (`--damage-states
    /// list` prints each).
    fn unknown(given: &str) -> String {
        let start = format!("--damage-states `{given}`");
        // A HAZUS type at a level its table does not give.
        if let Some((kind, level)) = given
            .strip_prefix("hazus-")
            .and_then(|r| r.rsplit_once('-'))
        {
            let row = HAZUS_TYPES
                .iter()
                .find(|(k, ..)| k.eq_ignore_ascii_case(kind));
            let at = LEVELS.iter().position(|(l, _)| *l == level);
            if let (Some((kind, _, levels)), Some(at)) = (row, at) {
                let has: Vec<String> = LEVELS
                    .iter()
                    .zip(levels)
                    .filter(|(_, l)| l.is_some())
                    .map(|((l, _), _)| hazus_name(kind, l))
                    .collect();
                if levels[at].is_none() {
                    return format!(
                        "{start}: HAZUS Table 5.9{} ({level} code) has no {kind}: it has {}",
                        LEVELS[at].1,
                        has.join(", ")
                    );
                }
                if given != hazus_name(kind, level) {
                    return format!(
                        "{start}: not a built-in set: built-in names are lower case ({})",
                        hazus_name(kind, level)
                    );
                }
            }
        }
        let types: Vec<String> = HAZUS_TYPES
            .iter()
            .map(|(k, ..)| k.to_ascii_lowercase())
            .collect();
        // The types some levels lack, grouped by the levels they have.
        let mut partial: Vec<(Vec<&str>, Vec<String>)> = Vec::new();
        for (kind, _, levels) in &HAZUS_TYPES {
            let has: Vec<&str> = LEVELS
                .iter()
                .zip(levels)
                .filter(|(_, l)| l.is_some())
                .map(|((l, _), _)| *l)
                .collect();
            if has.len() == LEVELS.len() {
                continue;
            }
            match partial.iter_mut().find(|(h, _)| *h == has) {
                Some((_, k)) => k.push(kind.to_ascii_lowercase()),
                None => partial.push((has, vec![kind.to_ascii_lowercase()])),
            }
        }
        let partial: Vec<String> = partial
            .iter()
            .map(|(has, kinds)| format!("{} at {} code only", kinds.join(", "), has.join(" and ")))
            .collect();
        format!(
            "{start}: not a built-in set or a file. Built in: hazus-TYPE-LEVEL (e.g. hazus-c1l-high), HAZUS-MH MR5 Tables 5.9a-d peak drift ratios, with TYPE: {}; LEVEL: high, moderate, low or pre ({}); and fema-p58-residual, FEMA P-58-1 Table 5-3 residual drift ratios. `pound fragility --damage-states list` prints each set with its source and limits",
            types.join(", "),
            partial.join("; ")
        )
    }

    /// A built-in set by name, or a TOML file (`[[state]]` with `name` and `limit`, ascending;
    /// `name` and `source` optional).
    pub fn get(given: &str) -> Result<DamageStates, String> {
        if let Some(d) = Self::built_in().into_iter().find(|d| d.name == given) {
            return Ok(d);
        }
        let path = Path::new(given);
        if !path.is_file() {
            return Err(Self::unknown(given));
        }
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{}: cannot read: {e}", given))?;
        let raw: RawStates = toml::from_str(&text).map_err(|e| {
            let m = crate::config::in_toml_words(e.to_string());
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
            demand: None,
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
            let example = match (mine, self.demand) {
                ("m/m", Some(DemandKind::ResidualDrift)) => {
                    " (a residual drift ratio column such as b1_residual_drift_ratio)"
                }
                ("m/m", _) => " (a drift ratio column such as b1_peak_drift_ratio)",
                _ => "",
            };
            format!(
                "--damage-states {}: its limits are in {mine}, but --edp {edp} is in {theirs}: give an EDP in {mine}{example}, or limits in {theirs} (a damage-state file with unit = \"{theirs}\" at its top, before the first [[state]])",
                self.name
            )
        })
    }

    /// Why these limits cannot be read on column `edp`: the set names its demand (a built-in
    /// set) and `edp` is a column of a sweep's that holds another (a residual drift set on
    /// `b1_peak_drift_ratio`, a peak drift set on `b1_residual_drift_ratio`), or, for a residual
    /// drift set, a storey's signed residual drift (`bK_sJ_residual_drift_ratio`: a residual
    /// past a limit the other way would count as below it). None where they can be, and for a
    /// file's set or a column no sweep writes, whose demand is not known.
    pub fn demand_mismatch(&self, edp: &str) -> Option<String> {
        let kind = self.demand?;
        let (k, suffix) = edp
            .strip_prefix('b')
            .and_then(|r| r.split_once('_'))
            .filter(|(k, _)| digits(k))
            .unwrap_or(("K", edp));
        if suffix == kind.suffix() {
            return None;
        }
        let meaning = crate::plan::meaning::meaning(edp)?;
        let storey_residual = suffix.ends_with("_residual_drift_ratio");
        let other = [DemandKind::PeakDrift, DemandKind::ResidualDrift]
            .into_iter()
            .find(|o| *o != kind && suffix == o.suffix());
        let what = if storey_residual && kind == DemandKind::ResidualDrift {
            format!(
                "a storey's signed residual drift ({}), where a residual past a limit the negative way would count as below it",
                meaning.label
            )
        } else {
            format!("the {}", meaning.label)
        };
        let instead = other
            .and_then(|o| Self::built_in().into_iter().find(|d| d.demand == Some(o)))
            .map(|d| {
                format!(
                    ", or a set of {} limits such as {}",
                    d.demand.map_or("", DemandKind::words),
                    d.name
                )
            })
            .unwrap_or_default();
        let whole = if kind == DemandKind::ResidualDrift {
            " (the largest over the building's storeys, in magnitude)"
        } else {
            ""
        };
        Some(format!(
            "--damage-states {}: its limits are of the {} ({}), but --edp {edp} is {what}: give --edp b{k}_{}{whole}{instead}",
            self.name,
            kind.words(),
            self.source,
            kind.suffix()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(name: &str) -> DamageStates {
        DamageStates::get(name).unwrap()
    }

    /// The four sets there were before the other types came: unchanged, field by field.
    #[test]
    fn the_c1l_sets_are_as_they_were() {
        for (name, table, limits) in [
            ("hazus-c1l-high", "a", [0.005, 0.01, 0.03, 0.08]),
            ("hazus-c1l-moderate", "b", [0.005, 0.0087, 0.0233, 0.06]),
            ("hazus-c1l-low", "c", [0.005, 0.008, 0.02, 0.05]),
            ("hazus-c1l-pre", "d", [0.004, 0.0064, 0.016, 0.04]),
        ] {
            let d = set(name);
            assert_eq!(d.name, name);
            assert_eq!(
                d.source,
                format!("HAZUS-MH MR5 Technical Manual (FEMA 2010), Table 5.9{table}, C1L")
            );
            let want: Vec<(String, f64)> = ["slight", "moderate", "extensive", "complete"]
                .iter()
                .zip(limits)
                .map(|(s, l)| (s.to_string(), l))
                .collect();
            assert_eq!(d.states, want);
            assert_eq!(d.unit.as_deref(), Some("m/m"));
            assert_eq!(d.demand, Some(DemandKind::PeakDrift));
        }
    }

    #[test]
    fn built_in_sets_ascend_and_files_are_checked() {
        let names = DamageStates::built_in_names();
        // 28 types at high and moderate code, 36 at low and pre, and FEMA P-58's.
        assert_eq!(names.len(), 28 + 28 + 36 + 36 + 1);
        for (i, name) in names.iter().enumerate() {
            assert!(!names[..i].contains(name), "{name} twice");
            let d = set(name);
            let l = d.limits();
            assert_eq!(l.len(), 4, "{name}");
            assert!(l[0] > 0.0 && l[3] < 0.2, "{name}: {l:?}");
            assert!(l.windows(2).all(|w| w[0] < w[1]), "{name}: {l:?}");
            assert!(
                d.source.contains("Table 5.9") || d.source.contains("Table 5-3"),
                "{name}"
            );
            assert_eq!(d.unit.as_deref(), Some("m/m"));
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
        assert_eq!(d.demand, None);
        write("[[state]]\nname = \"a\"\nlimit = 0.02\n[[state]]\nname = \"b\"\nlimit = 0.01\n");
        let e = DamageStates::get(p.to_str().unwrap()).unwrap_err();
        assert!(e.contains("state[1] (b)") && e.contains("ascending"), "{e}");
    }

    /// Values read off Tables 5.9a-d (SimCenter's transcription), and the types a table leaves
    /// out.
    #[test]
    fn hazus_values_as_read_from_the_tables() {
        for (name, table, limits) in [
            ("hazus-w1-low", "c, W1", [0.004, 0.0099, 0.0306, 0.075]),
            (
                "hazus-s1m-moderate",
                "b, S1M",
                [0.004, 0.0069, 0.0157, 0.04],
            ),
            ("hazus-s2h-high", "a, S2H", [0.0025, 0.005, 0.015, 0.04]),
            (
                "hazus-s4h-moderate",
                "b, S4H",
                [0.002, 0.0035, 0.0093, 0.0262],
            ),
            ("hazus-c2l-pre", "d, C2L", [0.0032, 0.0061, 0.0158, 0.04]),
            ("hazus-c3m-low", "c, C3M", [0.002, 0.004, 0.01, 0.0233]),
            (
                "hazus-pc2h-moderate",
                "b, PC2H",
                [0.002, 0.0035, 0.0094, 0.0263],
            ),
            (
                "hazus-rm1m-pre",
                "d, RM1M",
                [0.0021, 0.0034, 0.0086, 0.0233],
            ),
            ("hazus-urmm-pre", "d, URMM", [0.0016, 0.0032, 0.008, 0.0187]),
            ("hazus-mh-pre", "d, MH", [0.0032, 0.0064, 0.0192, 0.056]),
        ] {
            let d = set(name);
            assert_eq!(d.limits(), limits, "{name}");
            assert!(
                d.source.ends_with(&format!("Table 5.9{table}")),
                "{name}: {}",
                d.source
            );
        }
        for absent in [
            "hazus-s5l-high",
            "hazus-s5h-moderate",
            "hazus-c3l-high",
            "hazus-urml-moderate",
            "hazus-urmm-high",
            "hazus-rm1h-low",
            "hazus-w1l-high",
        ] {
            assert!(DamageStates::get(absent).is_err(), "{absent}");
        }
        let p = set("fema-p58-residual");
        assert_eq!(p.limits(), [0.002, 0.005, 0.01, 0.02]);
        assert_eq!(p.demand, Some(DemandKind::ResidualDrift));
        assert_eq!(p.states[3].0, "DS4");
    }

    /// Tables 5.9a-d give, beside each drift ratio, the median spectral displacement of the
    /// damage state: the drift ratio times the fraction of the roof height at the pushover
    /// mode's displacement times that height, one constant per type. Rt (github.com/steva44/Rts,
    /// `RHazusBuildingModel.cpp`, commit 3609161c) transcribes the medians (inches, to 0.01),
    /// independently of SimCenter's drift ratios: every drift ratio here, times its type's
    /// constant, must give Rt's median to the rounding of both (0.00005 in the drift ratio,
    /// 0.005 in in the median). A digit wrong in either breaks it.
    #[test]
    fn drift_ratios_agree_with_the_spectral_displacement_medians() {
        #[rustfmt::skip]
        const RT_SD_IN: [(&str, ByLevel); 36] = [
        ("W1", [Some([0.5, 1.51, 5.04, 12.6]), Some([0.5, 1.25, 3.86, 9.45]), Some([0.5, 1.25, 3.86, 9.45]), Some([0.4, 1.0, 3.09, 7.56])]),
        ("W2", [Some([0.86, 2.59, 8.64, 21.6]), Some([0.86, 2.14, 6.62, 16.2]), Some([0.86, 2.14, 6.62, 16.2]), Some([0.69, 1.71, 5.29, 12.96])]),
        ("S1L", [Some([1.3, 2.59, 6.48, 17.28]), Some([1.3, 2.24, 5.08, 12.96]), Some([1.3, 2.07, 4.38, 10.8]), Some([1.04, 1.65, 3.5, 8.64])]),
        ("S1M", [Some([2.16, 4.32, 10.8, 28.8]), Some([2.16, 3.74, 8.46, 21.6]), Some([2.16, 3.44, 7.3, 18.0]), Some([1.73, 2.76, 5.84, 14.4])]),
        ("S1H", [Some([3.37, 6.74, 16.85, 44.93]), Some([3.37, 5.83, 13.21, 33.7]), Some([3.37, 5.37, 11.38, 28.08]), Some([2.7, 4.3, 9.11, 22.46])]),
        ("S2L", [Some([1.08, 2.16, 6.48, 17.28]), Some([1.08, 1.87, 5.04, 12.96]), Some([1.08, 1.73, 4.32, 10.8]), Some([0.86, 1.38, 3.46, 8.64])]),
        ("S2M", [Some([1.8, 3.6, 10.8, 28.8]), Some([1.8, 3.12, 8.4, 21.6]), Some([1.8, 2.88, 7.2, 18.0]), Some([1.44, 2.3, 5.76, 14.4])]),
        ("S2H", [Some([2.81, 5.62, 16.85, 44.93]), Some([2.81, 4.87, 13.1, 33.7]), Some([2.81, 4.49, 11.23, 28.08]), Some([2.25, 3.59, 8.99, 22.46])]),
        ("S3", [Some([0.54, 1.08, 3.24, 9.45]), Some([0.54, 0.94, 2.52, 7.09]), Some([0.54, 0.87, 2.17, 5.91]), Some([0.43, 0.69, 1.73, 4.73])]),
        ("S4L", [Some([0.86, 1.73, 5.18, 15.12]), Some([0.86, 1.5, 4.04, 11.34]), Some([0.86, 1.38, 3.47, 9.45]), Some([0.69, 1.11, 2.77, 7.56])]),
        ("S4M", [Some([1.44, 2.88, 8.64, 25.2]), Some([1.44, 2.5, 6.73, 18.9]), Some([1.44, 2.31, 5.78, 15.75]), Some([1.15, 1.85, 4.62, 12.6])]),
        ("S4H", [Some([2.25, 4.49, 13.48, 39.31]), Some([2.25, 3.9, 10.5, 29.48]), Some([2.25, 3.6, 9.01, 24.57]), Some([1.8, 2.88, 7.21, 19.66])]),
        ("S5L", [None, None, Some([0.65, 1.3, 3.24, 7.56]), Some([0.52, 1.04, 2.59, 6.05])]),
        ("S5M", [None, None, Some([1.08, 2.16, 5.4, 12.6]), Some([0.86, 1.73, 4.32, 10.08])]),
        ("S5H", [None, None, Some([1.68, 3.37, 8.42, 19.66]), Some([1.35, 2.7, 6.74, 15.72])]),
        ("C1L", [Some([0.9, 1.8, 5.4, 14.4]), Some([0.9, 1.56, 4.2, 10.8]), Some([0.9, 1.44, 3.6, 9.0]), Some([0.72, 1.15, 2.88, 7.2])]),
        ("C1M", [Some([1.5, 3.0, 9.0, 24.0]), Some([1.5, 2.6, 7.0, 18.0]), Some([1.5, 2.4, 6.0, 15.0]), Some([1.2, 1.92, 4.8, 12.0])]),
        ("C1H", [Some([2.16, 4.32, 12.96, 34.56]), Some([2.16, 3.74, 10.08, 25.92]), Some([2.16, 3.46, 8.64, 21.6]), Some([1.73, 2.76, 6.91, 17.28])]),
        ("C2L", [Some([0.72, 1.8, 5.4, 14.4]), Some([0.72, 1.52, 4.17, 10.8]), Some([0.72, 1.37, 3.55, 9.0]), Some([0.58, 1.1, 2.84, 7.2])]),
        ("C2M", [Some([1.2, 3.0, 9.0, 24.0]), Some([1.2, 2.53, 6.95, 18.0]), Some([1.2, 2.29, 5.92, 15.0]), Some([0.96, 1.83, 4.74, 12.0])]),
        ("C2H", [Some([1.73, 4.32, 12.96, 34.56]), Some([1.73, 3.64, 10.0, 25.92]), Some([1.73, 3.3, 8.53, 21.6]), Some([1.38, 2.64, 6.82, 17.28])]),
        ("C3L", [None, None, Some([0.54, 1.08, 2.7, 6.3]), Some([0.43, 0.86, 2.16, 5.04])]),
        ("C3M", [None, None, Some([0.9, 1.8, 4.5, 10.5]), Some([0.72, 1.44, 3.6, 8.4])]),
        ("C3H", [None, None, Some([1.3, 2.59, 6.48, 15.12]), Some([1.04, 2.07, 5.18, 12.1])]),
        ("PC1", [Some([0.54, 1.08, 3.24, 9.45]), Some([0.54, 0.94, 2.52, 7.09]), Some([0.54, 0.87, 2.17, 5.91]), Some([0.43, 0.69, 1.73, 4.73])]),
        ("PC2L", [Some([0.72, 1.44, 4.32, 12.6]), Some([0.72, 1.25, 3.37, 9.45]), Some([0.72, 1.15, 2.89, 7.88]), Some([0.58, 0.92, 2.31, 6.3])]),
        ("PC2M", [Some([1.2, 2.4, 7.2, 21.0]), Some([1.2, 2.08, 5.61, 15.75]), Some([1.2, 1.92, 4.81, 13.12]), Some([0.96, 1.54, 3.85, 10.5])]),
        ("PC2H", [Some([1.73, 3.46, 10.37, 30.24]), Some([1.73, 3.0, 8.08, 22.68]), Some([1.73, 2.77, 6.93, 18.9]), Some([1.38, 2.21, 5.55, 15.12])]),
        ("RM1L", [Some([0.72, 1.44, 4.32, 12.6]), Some([0.72, 1.25, 3.37, 9.45]), Some([0.72, 1.15, 2.89, 7.88]), Some([0.58, 0.92, 2.31, 6.3])]),
        ("RM1M", [Some([1.2, 2.4, 7.2, 21.0]), Some([1.2, 2.08, 5.61, 15.75]), Some([1.2, 1.92, 4.81, 13.12]), Some([0.96, 1.54, 3.85, 10.5])]),
        ("RM2L", [Some([0.72, 1.44, 4.32, 12.6]), Some([0.72, 1.25, 3.37, 9.45]), Some([0.72, 1.15, 2.89, 7.88]), Some([0.58, 0.92, 2.31, 6.3])]),
        ("RM2M", [Some([1.2, 2.4, 7.2, 21.0]), Some([1.2, 2.08, 5.61, 15.75]), Some([1.2, 1.92, 4.81, 13.12]), Some([0.96, 1.54, 3.85, 10.5])]),
        ("RM2H", [Some([1.73, 3.46, 10.37, 30.24]), Some([1.73, 3.0, 8.08, 22.68]), Some([1.73, 2.77, 6.93, 18.9]), Some([1.38, 2.21, 5.55, 15.12])]),
        ("URML", [None, None, Some([0.41, 0.81, 2.03, 4.73]), Some([0.32, 0.65, 1.62, 3.78])]),
        ("URMM", [None, None, Some([0.63, 1.26, 3.15, 7.35]), Some([0.5, 1.01, 2.52, 5.88])]),
        ("MH", [Some([0.48, 0.96, 2.88, 8.4]), Some([0.48, 0.96, 2.88, 8.4]), Some([0.48, 0.96, 2.88, 8.4]), Some([0.38, 0.77, 2.3, 6.72])]),
        ];
        assert_eq!(RT_SD_IN.len(), HAZUS_TYPES.len());
        for ((kind, sd), (ours, _, drifts)) in RT_SD_IN.iter().zip(&HAZUS_TYPES) {
            assert_eq!(kind, ours);
            let pairs: Vec<(f64, f64)> = sd
                .iter()
                .zip(drifts)
                .flat_map(|(s, d)| {
                    assert_eq!(s.is_some(), d.is_some(), "{kind}: the levels given differ");
                    s.iter()
                        .zip(d)
                        .flat_map(|(s, d)| s.iter().copied().zip(d.iter().copied()))
                })
                .collect();
            assert!(pairs.len() >= 8, "{kind}");
            // The constant: least squares of median = k drift.
            let k = pairs.iter().map(|(s, d)| s * d).sum::<f64>()
                / pairs.iter().map(|(_, d)| d * d).sum::<f64>();
            for (s, d) in pairs {
                let off = (s / k - d).abs();
                assert!(
                    off <= 0.00005 + 0.005 / k + 1e-12,
                    "{kind}: drift ratio {d} against median {s} in (k = {k:.1} in): off by {off:.6}"
                );
            }
        }
    }

    /// A lower code level never has a larger limit, nor a taller building of the same system.
    #[test]
    fn lower_codes_and_taller_buildings_never_have_larger_limits() {
        let no_larger = |a: &[f64; 4], b: &[f64; 4]| a.iter().zip(b).all(|(a, b)| b <= a);
        for (kind, _, levels) in &HAZUS_TYPES {
            let given: Vec<&[f64; 4]> = levels.iter().flatten().collect();
            for w in given.windows(2) {
                assert!(no_larger(w[0], w[1]), "{kind}: {:?} then {:?}", w[0], w[1]);
            }
        }
        let mut compared = 0;
        for (kind, _, levels) in &HAZUS_TYPES {
            let Some(system) = kind.strip_suffix('L') else {
                continue;
            };
            for taller in ["M", "H"] {
                let Some((.., tall)) = HAZUS_TYPES
                    .iter()
                    .find(|(k, ..)| *k == format!("{system}{taller}"))
                else {
                    continue;
                };
                for (low, tall) in levels.iter().zip(tall) {
                    if let (Some(low), Some(tall)) = (low, tall) {
                        assert!(no_larger(low, tall), "{kind} against {system}{taller}");
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 40, "{compared}");
    }

    #[test]
    fn a_built_in_set_is_read_on_its_own_demand() {
        let residual = set("fema-p58-residual");
        let peak = set("hazus-c1l-high");
        assert_eq!(residual.demand_mismatch("b2_residual_drift_ratio"), None);
        assert_eq!(peak.demand_mismatch("b12_peak_drift_ratio"), None);
        // A column no sweep writes: its demand is not known.
        assert_eq!(residual.demand_mismatch("my_drift"), None);
        let e = residual.demand_mismatch("b2_peak_drift_ratio").unwrap();
        for part in [
            "fema-p58-residual",
            "residual interstorey drift ratio",
            "b2_peak_drift_ratio is the peak drift ratio, building 2",
            "give --edp b2_residual_drift_ratio",
            "such as hazus-w1-high",
        ] {
            assert!(e.contains(part), "`{part}` in {e}");
        }
        let e = peak.demand_mismatch("b1_residual_drift_ratio").unwrap();
        for part in [
            "hazus-c1l-high",
            "give --edp b1_peak_drift_ratio",
            "such as fema-p58-residual",
        ] {
            assert!(e.contains(part), "`{part}` in {e}");
        }
        // A storey's residual drift is signed: the building's, a magnitude, is the one.
        let e = residual
            .demand_mismatch("b1_s3_residual_drift_ratio")
            .unwrap();
        assert!(
            e.contains("signed") && e.contains("give --edp b1_residual_drift_ratio"),
            "{e}"
        );
        assert!(peak.demand_mismatch("b1_s3_residual_drift_ratio").is_some());
        assert!(peak.demand_mismatch("b1_yield_drift_ratio").is_some());
        // A file's set names no demand: any column of its unit.
        let file = DamageStates {
            demand: None,
            ..peak.clone()
        };
        assert_eq!(file.demand_mismatch("b1_residual_drift_ratio"), None);
        // The unit's example names the set's own demand.
        let e = residual.unit_mismatch("peak_force_n", Some("N")).unwrap();
        assert!(e.contains("such as b1_residual_drift_ratio"), "{e}");
        let e = peak.unit_mismatch("peak_force_n", Some("N")).unwrap();
        assert!(e.contains("such as b1_peak_drift_ratio"), "{e}");
    }

    #[test]
    fn the_list_has_every_set_once_with_its_limits() {
        let list = DamageStates::list();
        let rows: Vec<Vec<&str>> = list
            .lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| set |"))
            .map(|l| l.split('|').map(str::trim).collect())
            .collect();
        let names = DamageStates::built_in_names();
        assert_eq!(rows.len(), names.len());
        for (row, name) in rows.iter().zip(&names) {
            let d = set(name);
            assert_eq!(row[1], name);
            assert_eq!(row[4], d.source);
            let limits: Vec<String> = d
                .states
                .iter()
                .map(|(s, l)| format!("{s} {}", crate::show(*l)))
                .collect();
            assert_eq!(row[5], limits.join(", "), "{name}");
        }
        assert!(list.contains(
            "| hazus-s1m-moderate | S1M: steel moment frame, mid-rise, moderate code | bK_peak_drift_ratio |"
        ));
        assert!(list.contains("| fema-p58-residual | any | bK_residual_drift_ratio |"));
    }

    #[test]
    fn an_unknown_name_is_told_what_there_is() {
        let e = DamageStates::get("hazus-c9").unwrap_err();
        assert!(
            e.contains("hazus-c1l-high") && e.contains("--damage-states list"),
            "{e}"
        );
        assert!(e.contains("urml, urmm at low and pre code only"), "{e}");
        // Grouped: not every name.
        assert!(!e.contains("hazus-rm2h-pre"), "{e}");
        let e = DamageStates::get("hazus-s5l-high").unwrap_err();
        assert!(
            e.contains("Table 5.9a (high code) has no S5L: it has hazus-s5l-low, hazus-s5l-pre"),
            "{e}"
        );
        let e = DamageStates::get("hazus-S1M-moderate").unwrap_err();
        assert!(e.contains("lower case (hazus-s1m-moderate)"), "{e}");
    }
}

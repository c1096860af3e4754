//! A row's columns: their names (which follow its buildings, storeys and contact levels) and
//! the cells of a run's row.

use crate::physics::row::{struck_side, LevelSide, RowOutput, StoreyOutput};
use crate::plan::columns::pair::{self as columns, num};
use crate::plan::row::{RowPlan, RowRunSpec};

/// The column prefix of a contact level: `level_b1f3_b2f3` for floor 3 of building 1 (`left`
/// = 0, buildings from 0 here) against floor 3 of building 2 (floors from 1);
/// `level_b1f3_b2c4` where floor 3 of building 1 strikes the columns of building 2's storey 4.
pub fn level_name(left: usize, sides: &[LevelSide; 2]) -> String {
    format!(
        "level_b{}{}_b{}{}",
        left + 1,
        sides[0].name(),
        left + 2,
        sides[1].name()
    )
}

/// Each building's output columns (after its `b1_` prefix).
pub const BUILDING_OUTPUTS: [&str; 5] = [
    "peak_roof_m",
    "peak_drift_ratio",
    "drift_storey",
    "peak_accel_m_s2",
    "accel_floor",
];

/// Where a run collapsed (empty where it did not): the time, the building and its storey (from
/// 1). Rows with a collapse limit have them.
pub const COLLAPSE_OUTPUTS: [&str; 3] = ["collapse_time_s", "collapse_building", "collapse_storey"];

/// Each building's collapse columns (after its `b1_` prefix), in rows with a collapse limit:
/// whether it collapsed (0 or 1), when and in which storey (empty where it did not).
pub const BUILDING_COLLAPSE_OUTPUTS: [&str; 3] =
    ["collapsed", "collapse_time_s", "collapse_storey"];

/// A yielding building's further output columns (after its `b1_` prefix).
pub const INELASTIC_OUTPUTS: [&str; 6] = [
    "residual_drift_ratio",
    "residual_storey",
    "peak_ductility",
    "ductility_storey",
    "hysteretic_energy_j",
    "yielded_storeys",
];

/// An IMK building's further output columns, after its yielding ones: its weakest storey's
/// strength ratio and the storeys that passed capping.
pub const IMK_OUTPUTS: [&str; 2] = ["strength_ratio", "capped_storeys"];

/// A yielding storey's output columns with `--columns` (after its `b1_s2_` prefix: building 1,
/// storey 2 from the ground).
pub const STOREY_OUTPUTS: [&str; 3] = [
    "residual_drift_ratio",
    "peak_ductility",
    "hysteretic_energy_j",
];

/// An IMK storey's further columns with `--columns`, after its [`STOREY_OUTPUTS`]: its
/// strength ratio and whether it passed capping (0 or 1).
pub const IMK_STOREY_OUTPUTS: [&str; 2] = ["strength_ratio", "capped"];

/// The column groups `--columns` may add to a row's columns: every building's storeys
/// (`bK_sJ_...`: each storey's peak drift ratio, its residual, and a yielding storey's own
/// columns) and floors (`bK_fJ_peak_accel_m_s2`, floor 0 the ground).
pub const COLUMN_GROUPS: [(&str, &str); 2] = [
    ("+storeys", "every building's storeys: peak and residual drift ratio, and a yielding storey's own columns"),
    ("+floors", "every building's floors: peak absolute acceleration, floor 0 the ground"),
];

/// A storey's or floor's column `bK_sJ_<suffix>` or `bK_fJ_<suffix>`: `b's'` or `b'f'`, the
/// building K (from 1) and the suffix.
fn storey_or_floor(column: &str) -> Option<(u8, usize, &str)> {
    let digits = |x: &str| !x.is_empty() && x.bytes().all(|c| c.is_ascii_digit());
    let (k, rest) = column.strip_prefix('b')?.split_once('_')?;
    let kind = *rest.as_bytes().first()?;
    let (j, suffix) = rest[1..].split_once('_')?;
    if !(matches!(kind, b's' | b'f') && digits(k) && digits(j) && !suffix.is_empty()) {
        return None;
    }
    Some((kind, k.parse().ok()?, suffix))
}

/// The group of `column` (`+storeys` for `b1_s2_...`, `+floors` for `b1_f0_...`), if any.
pub fn column_group(column: &str) -> Option<&'static str> {
    match storey_or_floor(column)? {
        (b's', ..) => Some("+storeys"),
        _ => Some("+floors"),
    }
}

impl RowPlan {
    /// Turn on the columns `columns` (`--columns`) asks for that a sweep writes only when
    /// asked: a group (`+storeys`, `+floors`), a yielding storey's own column
    /// (`b1_s2_peak_ductility`: written from what every run reports), or a demand column of a
    /// storey or floor (tracked on the CPU only).
    pub fn ask_columns(&mut self, columns: &[String]) {
        for c in columns {
            match c.as_str() {
                "+storeys" => (self.storey_demands, self.storey_columns) = (true, true),
                "+floors" => self.floor_demands = true,
                _ => match storey_or_floor(c) {
                    Some((b's', k, suffix)) => {
                        let yields = (k.checked_sub(1))
                            .and_then(|b| self.yielding.get(b))
                            .is_some_and(Option::is_some);
                        if yields && Self::asks_storey_columns(c) {
                            self.storey_columns = true;
                        } else if suffix == "peak_drift_ratio" || suffix == "residual_drift_ratio" {
                            self.storey_demands = true;
                        }
                    }
                    Some(_) => self.floor_demands = true,
                    None => {}
                },
            }
        }
    }

    /// A copy with every column group on (`pound columns --all`).
    pub fn with_every_group(&self) -> RowPlan {
        let mut every = self.clone();
        every.ask_columns(&COLUMN_GROUPS.map(|(g, _)| g.to_string()));
        every
    }

    /// Does the sweep track its buildings' demands storey by storey or floor by floor?
    pub fn tracks_demands(&self) -> bool {
        self.storey_demands || self.floor_demands
    }

    /// Does `column` name a yielding storey's own column (`b1_s2_peak_ductility`)?
    pub fn asks_storey_columns(column: &str) -> bool {
        storey_or_floor(column).is_some_and(|(kind, _, suffix)| {
            kind == b's'
                && (STOREY_OUTPUTS.contains(&suffix) || IMK_STOREY_OUTPUTS.contains(&suffix))
        })
    }
}

/// Each contact level's output columns (after its `level_b1f3_b2f3_` prefix).
pub const LEVEL_OUTPUTS: [&str; 4] = [
    "impacts",
    "peak_force_n",
    "peak_penetration_m",
    "impact_velocity_m_s",
];
impl RowPlan {
    /// Are building `b`'s storeys IMK (capped, deteriorating)? It then has [`IMK_OUTPUTS`].
    pub fn imk_building(&self, b: usize) -> bool {
        (self.yielding[b].as_ref()).is_some_and(|y| y.deterioration.is_some())
    }

    /// Has any building IMK storeys?
    pub fn has_imk(&self) -> bool {
        (0..self.buildings.len()).any(|b| self.imk_building(b))
    }

    /// The contact levels' column prefixes ([`level_name`]).
    pub fn level_names(&self) -> Vec<String> {
        (self.levels().iter())
            .map(|l| level_name(l.left, &l.sides))
            .collect()
    }

    /// The contact levels as a Markdown table: each one's column prefix, kind (floor/floor or
    /// floor/column), elevation and, on a column, the struck storey's height fraction `xi` and
    /// the share `s` of the force on its top floor (`pound columns CONFIG`).
    pub fn level_table(&self) -> String {
        let mut t = String::from(
            "| level | kind | elevation m | struck storey: xi | share on its top floor s |\n|---|---|---:|---:|---:|\n",
        );
        let row = self.row(&self.run(0));
        for (l, name) in row.levels.iter().zip(self.level_names()) {
            let (kind, xi, s) = match struck_side(&l.sides) {
                None => ("floor/floor", String::new(), String::new()),
                Some(k) => {
                    let side = &l.sides[k];
                    let (xi, s) = (side.xi, side.weight);
                    ("floor/column", format!("{xi:.3}"), format!("{s:.3}"))
                }
            };
            t.push_str(&format!(
                "| `{name}` | {kind} | {} | {xi} | {s} |\n",
                crate::show(l.elevation)
            ));
        }
        t
    }

    /// Every column, in file order: the contact and motion columns of the pair, each
    /// building's `Sa(T1)` of the scaled record (`b1_sa_t1_g`, ...), each building's
    /// parameters (`b1_...`), each gap, the status and totals, each building's
    /// peaks, each level's, and the energy balance (empty unless asked for).
    pub fn header(&self) -> Vec<String> {
        let mut h: Vec<String> = columns::HEADER[..columns::CONTACT_AND_MOTION]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let nb = self.buildings.len();
        for b in 1..=nb {
            h.push(format!("b{b}_{}", crate::plan::intensity::SA_T1_COLUMN));
        }
        for b in 1..=nb {
            for c in ["storeys", "mass_kg", "t1_s", "xi"] {
                h.push(format!("b{b}_{c}"));
            }
            for name in self.swept_names(b - 1) {
                h.push(format!("b{b}_{name}"));
            }
        }
        for a in 1..nb {
            h.push(format!("gap_{a}_{}_m", a + 1));
        }
        h.push("sample".into());
        for c in [
            "status",
            "impacts",
            "peak_force_n",
            "peak_penetration_m",
            "impact_velocity_m_s",
            "first_impact_s",
            "contact_time_s",
            "dissipated_energy_j",
            "substeps",
        ] {
            h.push(c.into());
        }
        if self.collapse_drift_ratio.is_finite() {
            for c in COLLAPSE_OUTPUTS {
                h.push(c.into());
            }
        }
        for (b, y) in self.yielding.iter().enumerate() {
            for c in BUILDING_OUTPUTS {
                h.push(format!("b{}_{c}", b + 1));
            }
            if self.buildings[b].p_delta.is_some() {
                h.push(format!("b{}_stability_coefficient", b + 1));
            }
            if self.collapse_drift_ratio.is_finite() {
                for c in BUILDING_COLLAPSE_OUTPUTS {
                    h.push(format!("b{}_{c}", b + 1));
                }
            }
            if y.is_some() {
                let imk = self.imk_building(b);
                let imk_outputs = |x: &'static [&'static str]| if imk { x } else { &[] };
                for c in INELASTIC_OUTPUTS.iter().chain(imk_outputs(&IMK_OUTPUTS)) {
                    h.push(format!("b{}_{c}", b + 1));
                }
                if self.storey_columns {
                    for j in 1..=self.buildings[b].storeys() {
                        for c in STOREY_OUTPUTS
                            .iter()
                            .chain(imk_outputs(&IMK_STOREY_OUTPUTS))
                        {
                            h.push(format!("b{}_s{j}_{c}", b + 1));
                        }
                    }
                }
            }
            let n = self.buildings[b].storeys();
            if self.storey_demands {
                for j in 1..=n {
                    h.push(format!("b{}_s{j}_peak_drift_ratio", b + 1));
                    if y.is_none() {
                        h.push(format!("b{}_s{j}_residual_drift_ratio", b + 1));
                    }
                }
            }
            if self.floor_demands {
                for j in 0..=n {
                    h.push(format!("b{}_f{j}_peak_accel_m_s2", b + 1));
                }
            }
        }
        for (l, struck) in self.level_names().iter().zip(&self.struck) {
            for c in LEVEL_OUTPUTS {
                h.push(format!("{l}_{c}"));
            }
            if let Some(yields) = struck {
                h.push(format!("{l}_column_shear_n"));
                if *yields {
                    h.push(format!("{l}_column_shear_ratio"));
                }
            }
        }
        for c in ["input_energy_j", "damping_energy_j", "energy_residual"] {
            h.push(c.into());
        }
        h.extend(
            columns::record_meta_columns(&self.contact)
                .iter()
                .map(|c| c.to_string()),
        );
        h
    }

    /// The number of parameter columns, which lead the header: the status column's index.
    pub fn parameter_columns(&self) -> usize {
        let swept: usize = (0..self.buildings.len())
            .map(|b| self.swept_names(b).len())
            .sum();
        columns::CONTACT_AND_MOTION + 5 * self.buildings.len() + swept + self.gaps.len() + 1
    }

    /// The outputs an `--aggregate` summary folds per group (as magnitudes): the row's totals,
    /// each building's peaks and each contact level's; not the storey and floor numbers, the
    /// first impact's time, the step count or the energy balance.
    pub fn summarised(&self) -> Vec<String> {
        let skip = [
            "first_impact_s",
            "substeps",
            "input_energy_j",
            "damping_energy_j",
            "energy_residual",
        ];
        self.header()
            .into_iter()
            .skip(self.parameter_columns() + 1)
            .filter(|c| {
                !skip.contains(&c.as_str())
                    && !COLLAPSE_OUTPUTS.contains(&c.as_str())
                    && !c.ends_with("_collapsed")
                    && !c.ends_with("_collapse_time_s")
                    && !c.ends_with("_collapse_storey")
                    && !c.ends_with("_stability_coefficient")
                    && !c.ends_with("_drift_storey")
                    && !c.ends_with("_accel_floor")
                    && !c.ends_with("_residual_storey")
                    && !c.ends_with("_ductility_storey")
            })
            .collect()
    }

    /// Building `k`'s storey and floor demands, where asked ([`RowPlan::storey_demands`],
    /// [`RowPlan::floor_demands`]): each storey's peak drift ratio (and an elastic building's
    /// residual, 0 where it stood to the end of a run that did not fail), each floor's peak
    /// absolute acceleration from floor 0, the ground's (the scaled record's PGA). Empty cells
    /// where the run did not track them (it failed before).
    fn demand_cells(&self, c: &mut Vec<String>, k: usize, run: &RowRunSpec, out: &RowOutput) {
        let n = self.buildings[k].storeys();
        let d = out.demands.get(k);
        let known = |x: Option<f64>| x.filter(|x| x.is_finite()).map(num).unwrap_or_default();
        if self.storey_demands {
            let settled = matches!(
                out.status,
                crate::physics::model::Status::Ok | crate::physics::model::Status::Collapsed
            ) && out.buildings[k].collapse.is_none();
            for j in 0..n {
                c.push(known(d.map(|d| d.peak_drift_ratio[j])));
                if self.yielding[k].is_none() {
                    c.push(if settled { "0".into() } else { String::new() });
                }
            }
        }
        if self.floor_demands {
            c.push(num(run.contact.pga_g * crate::record::G));
            for j in 0..n {
                c.push(known(d.map(|d| d.peak_accel[j])));
            }
        }
    }

    /// The fields of one run, in [`RowPlan::header`] order.
    pub fn cells(&self, run: &RowRunSpec, out: &RowOutput) -> Vec<String> {
        let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
        let mut c = columns::contact_and_motion(&self.contact, &run.contact);
        c.extend(
            run.period
                .iter()
                .map(|&t| num(self.contact.sa_g(&run.contact, t))),
        );
        for (b, a) in self.buildings.iter().enumerate() {
            c.push(a.storeys().to_string());
            c.push(opt(run.mass[b]));
            c.push(num(run.period[b]));
            c.push(num(run.damping[b]));
            c.extend(self.swept_values(b, run).into_iter().map(opt));
        }
        c.extend(run.gaps.iter().map(|&g| num(g)));
        c.push(run.sample.map(|s| s.to_string()).unwrap_or_default());
        let penetration = out
            .levels
            .iter()
            .map(|l| l.peak_penetration)
            .fold(0.0, f64::max);
        c.extend([
            out.status.key().to_string(),
            out.impacts.to_string(),
            num(out.peak_force),
            num(penetration),
            num(out.impact_velocity),
            opt(out.first_impact),
            num(out.contact_time),
            num(out.dissipated_energy),
            out.substeps.to_string(),
        ]);
        if self.collapse_drift_ratio.is_finite() {
            let cl = out.collapse;
            c.extend([
                opt(cl.map(|x| x.time)),
                cl.map(|x| x.building.to_string()).unwrap_or_default(),
                cl.map(|x| x.storey.to_string()).unwrap_or_default(),
            ]);
        }
        let mut storeys = out.storeys.iter();
        for (k, (b, y)) in out.buildings.iter().zip(&self.yielding).enumerate() {
            c.extend([
                num(b.peak_roof),
                num(b.peak_drift_ratio),
                b.drift_storey.to_string(),
                num(b.peak_accel),
                b.accel_floor.to_string(),
            ]);
            let a = &self.buildings[k];
            if a.p_delta.is_some() {
                c.push(num(a.stability_at_1s * run.period[k] * run.period[k]));
            }
            if self.collapse_drift_ratio.is_finite() {
                let cl = b.collapse;
                c.extend([
                    (cl.is_some() as u8).to_string(),
                    opt(cl.map(|x| x.time)),
                    cl.map(|x| x.storey.to_string()).unwrap_or_default(),
                ]);
            }
            if y.is_some() {
                // A run that failed, or did not settle, has no residual drift: empty, and no
                // storey of it.
                let ie = b.inelastic.unwrap_or_default();
                let known = |x: f64| if x.is_finite() { num(x) } else { String::new() };
                let residual_known = ie.residual_drift_ratio.is_finite();
                c.extend([
                    known(ie.residual_drift_ratio),
                    if residual_known {
                        ie.residual_storey.to_string()
                    } else {
                        String::new()
                    },
                    num(ie.peak_ductility),
                    ie.ductility_storey.to_string(),
                    num(ie.hysteretic_energy),
                    ie.yielded_storeys.to_string(),
                ]);
                let imk = self.imk_building(k);
                if imk {
                    // A run without its storeys' outputs has no strength known: empty.
                    let strength = b.inelastic.map_or(f64::NAN, |i| i.strength_ratio);
                    c.extend([known(strength), ie.capped_storeys.to_string()]);
                }
                for _ in 0..self.buildings[k].storeys() {
                    let st = storeys.next().copied().unwrap_or(StoreyOutput {
                        residual_drift_ratio: f64::NAN,
                        peak_ductility: f64::NAN,
                        hysteretic_energy: f64::NAN,
                        yielded: false,
                        strength_ratio: f64::NAN,
                        capped: false,
                    });
                    if self.storey_columns {
                        c.extend([
                            known(st.residual_drift_ratio),
                            known(st.peak_ductility),
                            known(st.hysteretic_energy),
                        ]);
                        if imk {
                            // A storey without its outputs has no strength known: empty.
                            let capped = st.strength_ratio.is_finite().then_some(st.capped);
                            c.extend([
                                known(st.strength_ratio),
                                capped.map(|x| (x as u8).to_string()).unwrap_or_default(),
                            ]);
                        }
                    }
                }
            }
            self.demand_cells(&mut c, k, run, out);
        }
        for (l, struck) in out.levels.iter().zip(&self.struck) {
            c.extend([
                l.impacts.to_string(),
                num(l.peak_force),
                num(l.peak_penetration),
                num(l.impact_velocity),
            ]);
            if let Some(yields) = struck {
                c.push(num(l.column_shear));
                if *yields {
                    c.push(num(l.column_shear_ratio));
                }
            }
        }
        c.extend([
            opt(out.energy.map(|e| e.input)),
            opt(out.energy.map(|e| e.damping)),
            opt(out.energy.map(|e| e.residual)),
        ]);
        c.extend(columns::record_meta_cells(&self.contact, &run.contact));
        c
    }
}

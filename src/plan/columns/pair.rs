//! The schema of a run: its swept parameters and outputs as named columns (units in the
//! names), and the text of each cell. CSV, Parquet, `--columns`, `--aggregate` groups and the
//! device fold all name columns from here.

use crate::physics::model::RunOutput;
use crate::plan::contact::{ContactPlan, ContactRun};
use crate::plan::intensity::{target_values, IM_COLUMNS};
use crate::plan::pair::{PairPlan, RunSpec};

/// Every column, in file order: the swept parameters (with the intensity measures of the scaled
/// record, which every run writes whatever it was scaled to), then the status and the outputs.
/// Units are in the names. The last three, the energy balance, are empty unless it was asked
/// for (`run.energy`, `--energy`).
pub const HEADER: [&str; 43] = [
    "run",
    "law",
    "formula",
    "e",
    "impact_damping",
    "k_n_per_m",
    "beta_n_per_m1_5",
    "record",
    "target_pga_g",
    "target_sa_g",
    "sa_period_s",
    "target_sa_avg_g",
    "sa_avg_from_s",
    "sa_avg_to_s",
    "scale_factor",
    "pga_g",
    "pgv_m_s",
    "arias_m_s",
    "cav_m_s",
    "sa_t1_g",
    "sa_t2_g",
    "m1_kg",
    "t1_s",
    "xi1",
    "m2_kg",
    "t2_s",
    "xi2",
    "gap_m",
    "sample",
    "status",
    "impacts",
    "peak_force_n",
    "peak_penetration_m",
    "peak_u1_m",
    "peak_u2_m",
    "impact_velocity_m_s",
    "first_impact_s",
    "contact_time_s",
    "dissipated_energy_j",
    "substeps",
    "input_energy_j",
    "damping_energy_j",
    "energy_residual",
];

/// The outputs an `--aggregate` summary folds per group (as magnitudes): every numeric output
/// but the first impact's time (absent where nothing touches), the step count and the energy
/// balance (absent unless asked for). Each is a column of [`HEADER`] after `status`, checked
/// when compiled ([`at`]).
pub const SUMMARISED: [&str; 8] = {
    let names = [
        "impacts",
        "peak_force_n",
        "peak_penetration_m",
        "peak_u1_m",
        "peak_u2_m",
        "impact_velocity_m_s",
        "contact_time_s",
        "dissipated_energy_j",
    ];
    let mut i = 0;
    while i < names.len() {
        assert!(
            at(names[i]) > at("status"),
            "a summarised column is an output"
        );
        i += 1;
    }
    names
};

/// The index of `name` in [`HEADER`] (a compile-time error in a constant where it is none).
pub const fn at(name: &str) -> usize {
    let mut i = 0;
    while i < HEADER.len() {
        let (a, b) = (HEADER[i].as_bytes(), name.as_bytes());
        if a.len() == b.len() {
            let mut k = 0;
            while k < a.len() && a[k] == b[k] {
                k += 1;
            }
            if k == a.len() {
                return i;
            }
        }
        i += 1;
    }
    panic!("not a column of HEADER")
}

/// Shortest round-trip text; scientific notation outside [1e-4, 1e15) so tiny values stay short
/// ([`crate::show`], the one form of a number every output and message writes).
pub(crate) fn num(x: f64) -> String {
    crate::show(x)
}

/// The columns of the contact and the ground motion: the first [`CONTACT_AND_MOTION`] of
/// [`HEADER`], which rows of multi-storey buildings share ([`crate::plan::row`]): through
/// `pga_g`, then the intensity measures that do not depend on the buildings
/// ([`IM_COLUMNS`]). Each building's `Sa(T1)` follows them (`sa_t1_g`, `sa_t2_g` in a pair;
/// `b1_sa_t1_g`, ... in a row).
pub const CONTACT_AND_MOTION: usize = RECORD_IMS + IM_COLUMNS.len();

/// Where the record's intensity measures ([`IM_COLUMNS`]) start in [`HEADER`]: after the
/// record, its targets, `scale_factor` and `pga_g` (the columns `record..RECORD_IMS`).
pub const RECORD_IMS: usize = at("pga_g") + 1;

/// The fields of one row, in [`HEADER`] order.
pub fn row(plan: &PairPlan, spec: &RunSpec, out: &RunOutput) -> Vec<String> {
    let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
    let mut cells = contact_and_motion(&plan.contact, &spec.contact);
    cells.extend([
        num(plan.contact.sa_g(&spec.contact, spec.t1)),
        num(plan.contact.sa_g(&spec.contact, spec.t2)),
        num(spec.m1),
        num(spec.t1),
        num(spec.xi1),
        num(spec.m2),
        num(spec.t2),
        num(spec.xi2),
        num(spec.gap),
        spec.sample.map(|s| s.to_string()).unwrap_or_default(),
        out.status.key().to_string(),
        out.impacts.to_string(),
        num(out.peak_force),
        num(out.peak_penetration),
        num(out.peak_u1),
        num(out.peak_u2),
        num(out.impact_velocity),
        opt(out.first_impact),
        num(out.contact_time),
        num(out.dissipated_energy),
        out.substeps.to_string(),
        opt(out.energy.map(|e| e.input)),
        opt(out.energy.map(|e| e.damping)),
        opt(out.energy.map(|e| e.residual)),
    ]);
    cells.extend(record_meta_cells(&plan.contact, &spec.contact));
    cells
}

/// A record set's columns ([`crate::record::set`]), after every other column of a sweep
/// whose records came from one ([`ContactPlan::has_record_meta`]): the search's RSN, the
/// component, the event, its magnitude, the distances and the station's Vs30.
pub const RECORD_META: [&str; 7] = [
    "record_rsn",
    "record_component",
    "record_event",
    "record_magnitude",
    "record_rjb_km",
    "record_rrup_km",
    "record_vs30_m_s",
];

/// The [`RECORD_META`] columns of a plan whose records came from a set; none otherwise.
pub fn record_meta_columns(plan: &ContactPlan) -> &'static [&'static str] {
    if plan.has_record_meta() {
        &RECORD_META
    } else {
        &[]
    }
}

/// A run's [`RECORD_META`] cells where its plan has those columns (empty where its own record
/// is not a set's), none where it has not.
pub fn record_meta_cells(plan: &ContactPlan, spec: &ContactRun) -> Vec<String> {
    if !plan.has_record_meta() {
        return Vec::new();
    }
    let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
    match &plan.spec.record_meta[spec.record] {
        Some(m) => vec![
            m.rsn.to_string(),
            m.component.to_string(),
            m.event.clone(),
            opt(m.magnitude),
            opt(m.rjb_km),
            opt(m.rrup_km),
            opt(m.vs30_m_s),
        ],
        None => vec![String::new(); RECORD_META.len()],
    }
}

/// A pair's columns: [`HEADER`], and [`RECORD_META`] where its records came from a set.
pub fn pair_header(plan: &PairPlan) -> Vec<String> {
    (HEADER.iter().chain(record_meta_columns(&plan.contact)))
        .map(|c| c.to_string())
        .collect()
}

/// The first [`CONTACT_AND_MOTION`] fields of a row.
pub fn contact_and_motion(plan: &ContactPlan, spec: &ContactRun) -> Vec<String> {
    let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
    let hertz = spec.law.is_hertzian();
    let mut cells = vec![
        spec.index.to_string(),
        spec.law.key().to_string(),
        spec.formula
            .map(|f| f.key().to_string())
            .unwrap_or_default(),
        opt(spec.e),
        if spec.law.is_damped() {
            num(spec.damping)
        } else {
            String::new()
        },
        if hertz {
            String::new()
        } else {
            num(spec.stiffness)
        },
        if hertz {
            num(spec.stiffness)
        } else {
            String::new()
        },
        plan.spec.records[spec.record].name.clone(),
    ];
    cells.extend(
        target_values(&spec.intensity, spec.im_periods)
            .into_iter()
            .map(opt),
    );
    cells.extend([num(spec.scale), num(spec.pga_g)]);
    cells.extend(plan.record_ims(spec).map(num));
    cells
}

/// Indices into [`header`] of `names` (`run` first, added if missing), or the first name that is
/// not a column.
pub fn select(names: &[String]) -> Result<Vec<usize>, String> {
    select_in(&header(), names)
}

/// Indices into `h` (whose first column is `run`) of `names`, `run` first and added if
/// missing, or the first name that is not a column (rows of multi-storey buildings have their
/// own header).
pub fn select_in<S: AsRef<str>>(h: &[S], names: &[String]) -> Result<Vec<usize>, String> {
    let h: Vec<&str> = h.iter().map(|c| c.as_ref()).collect();
    let mut idx = vec![0];
    for n in names {
        let i = h.iter().position(|c| c == n).ok_or_else(|| n.clone())?;
        if !idx.contains(&i) {
            idx.push(i);
        }
    }
    Ok(idx)
}

/// All column names.
pub fn header() -> Vec<&'static str> {
    HEADER.to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::intensity::TARGET_COLUMNS;

    #[test]
    fn select_keeps_run_first_once_and_names_the_first_unknown() {
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let h = header();
        let at = |c: &str| h.iter().position(|x| *x == c).unwrap();
        assert_eq!(
            select(&names(&["gap_m", "peak_force_n"])),
            Ok(vec![0, at("gap_m"), at("peak_force_n")])
        );
        assert_eq!(
            select(&names(&["peak_force_n", "run", "peak_force_n"])),
            Ok(vec![0, at("peak_force_n")])
        );
        assert_eq!(select(&[]), Ok(vec![0]));
        assert_eq!(
            select(&names(&["gap_m", "gap", "nope"])),
            Err("gap".to_string())
        );
    }

    #[test]
    fn target_columns_follow_the_record_in_the_header() {
        let at = HEADER.iter().position(|c| *c == "record").unwrap() + 1;
        assert_eq!(HEADER[at..at + TARGET_COLUMNS.len()], TARGET_COLUMNS);
        assert_eq!(HEADER[at + TARGET_COLUMNS.len()], "scale_factor");
    }

    /// The record's intensity measures follow `pga_g`, the contact and motion columns end with
    /// them, and the pair's `Sa(T1)` of each building come next; all are parameters.
    #[test]
    fn intensity_measures_follow_the_pga_as_parameters() {
        let pga = at("pga_g");
        assert_eq!(HEADER[pga + 1..pga + 4], IM_COLUMNS);
        assert_eq!(RECORD_IMS, pga + 1);
        assert_eq!(CONTACT_AND_MOTION, pga + 4);
        assert_eq!(
            HEADER[CONTACT_AND_MOTION..CONTACT_AND_MOTION + 3],
            ["sa_t1_g", "sa_t2_g", "m1_kg"]
        );
        assert!(at("sa_t2_g") < at("status"));
        assert_eq!(at("run"), 0);
        assert_eq!(HEADER[at("dissipated_energy_j")], "dissipated_energy_j");
    }

    #[test]
    fn header_names_are_unique_and_summarised_outputs_are_outputs() {
        let mut h = header();
        h.sort();
        h.dedup();
        assert_eq!(h.len(), HEADER.len());
        let status = HEADER.iter().position(|c| *c == "status").unwrap();
        for s in SUMMARISED {
            let i = HEADER.iter().position(|c| *c == s).unwrap();
            assert!(i > status, "{s} is an output column");
        }
    }
}

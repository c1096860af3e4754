//! The one plan every command holds: a pair or a row.

use crate::physics::solver::Scheme;
use crate::plan::axes::Motions;
use crate::plan::columns;
use crate::plan::contact::ContactPlan;
use crate::plan::limits;
use crate::plan::pair::PairPlan;
use crate::plan::row::RowPlan;

/// A validated sweep of one scene, the one plan every command holds: the config reader
/// ([`crate::plan::config::load_text`]) decides the scene's kind once, and the layers below ask
/// the plan, never the config. A `[building1]`/`[building2]` config is a pair of one-storey buildings,
/// planned by [`PairPlan`] (whose runs the engine's pair kernels take); a `[[building]]` config
/// is a row of 2..n shear buildings of 1..N storeys, planned by [`RowPlan`] (the row
/// kernels). Both number their runs in the same axis order (contact, record, intensity,
/// sample, each building's values, the gaps), so a pair written as a row of two one-storey
/// buildings has the same runs in the same order (`tests/it/scenes.rs`).
#[derive(Debug, Clone)]
pub enum Plan {
    Pair(PairPlan),
    Row(RowPlan),
}

impl Plan {
    /// Number of runs.
    pub fn len(&self) -> u64 {
        match self {
            Plan::Pair(p) => p.len(),
            Plan::Row(r) => r.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The plan of the axes every scene shares: contact, record, intensity, scheme.
    pub fn contact(&self) -> &ContactPlan {
        match self {
            Plan::Pair(p) => &p.contact,
            Plan::Row(r) => &r.contact,
        }
    }

    /// The integration scheme the runs take.
    pub fn scheme(&self) -> Scheme {
        self.contact().spec.scheme
    }

    /// Set the scheme as run (the fingerprint covers it).
    pub fn set_scheme(&mut self, scheme: Scheme) {
        match self {
            Plan::Pair(p) => p.contact.spec.scheme = scheme,
            Plan::Row(r) => r.contact.spec.scheme = scheme,
        }
    }

    /// The accuracy suite that calibrates `--target-error` for this scene.
    pub fn suite(&self) -> crate::physics::solver::calibration::Suite {
        use crate::physics::solver::calibration::Suite;
        match self {
            // A row of two one-storey buildings runs on the pair's kernels.
            Plan::Pair(_) => Suite::Pairs,
            Plan::Row(r) if r.runs_as_pair() => Suite::Pairs,
            Plan::Row(_) if self.yields() => Suite::YieldingRows,
            Plan::Row(_) => Suite::Rows,
        }
    }

    /// Write the columns `columns` (`--columns`) asks for that a sweep writes only when asked
    /// ([`RowPlan::ask_columns`]): each yielding storey's own (`b1_s2_peak_ductility`), every
    /// building's storeys and floors (`+storeys`, `+floors`); a pair has none.
    pub fn ask_columns(&mut self, columns: &[String]) {
        if let Plan::Row(r) = self {
            r.ask_columns(columns);
        }
    }

    /// Do some building's storeys yield?
    pub fn yields(&self) -> bool {
        match self {
            Plan::Pair(_) => false,
            Plan::Row(r) => r.yielding.iter().any(Option::is_some),
        }
    }

    /// The most storeys of any building (1 for a pair).
    pub fn max_storeys(&self) -> usize {
        match self {
            Plan::Pair(_) => 1,
            Plan::Row(r) => r.buildings.iter().map(|b| b.storeys()).max().unwrap_or(1),
        }
    }

    /// The scene in words: `a pair of one-storey buildings`, `a row of 3 buildings (9
    /// storeys, 7 contact levels)`.
    pub fn scene(&self) -> String {
        match self {
            Plan::Pair(_) => "a pair of one-storey buildings".into(),
            Plan::Row(r) => {
                let yielding: Vec<String> = (0..r.buildings.len())
                    .filter(|&b| r.yielding[b].is_some())
                    .map(|b| (b + 1).to_string())
                    .collect();
                let leaning = r.buildings.iter().any(|b| b.p_delta.is_some());
                let tail = format!(
                    "{}{}",
                    if yielding.is_empty() {
                        String::new()
                    } else {
                        format!("; yielding storeys in building {}", yielding.join(", "))
                    },
                    if leaning { "; P-Delta" } else { "" }
                );
                if r.buildings.len() == 1 {
                    return format!(
                        "one building alone ({} storeys{tail})",
                        r.buildings[0].storeys()
                    );
                }
                let levels = r.levels();
                let columns = levels.iter().filter(|l| l.floor_column()).count();
                let columns = match columns {
                    0 => String::new(),
                    c => format!(", {c} of them floor against column"),
                };
                format!(
                    "a row of {} buildings ({} storeys, {} contact levels{columns}{tail})",
                    r.buildings.len(),
                    r.buildings.iter().map(|b| b.storeys()).sum::<usize>(),
                    levels.len(),
                )
            }
        }
    }

    /// What a user should hear before any run, for contact substeps of `substeps_per_contact`
    /// (a row's cost grows with its stiffest building): absurd intensities, a row's pairs that
    /// never touch, keys no run uses, extreme costs.
    pub fn warnings(&self, substeps_per_contact: f64) -> Vec<String> {
        let mut w = self.input_warnings();
        if let Plan::Row(r) = self {
            w.extend(r.cost_warning(substeps_per_contact));
        }
        w
    }

    /// [`Plan::warnings`] without the cost of contact (for studies that integrate none).
    pub fn input_warnings(&self) -> Vec<String> {
        match self {
            Plan::Pair(p) => p.warnings(),
            Plan::Row(r) => r.warnings(),
        }
    }

    /// Each adjacent pair of buildings with no floor at a common elevation, and why (none for
    /// a pair of one-storey buildings, which touch at their roofs).
    pub fn pairs_without_levels(&self) -> Vec<String> {
        match self {
            Plan::Pair(_) => Vec::new(),
            Plan::Row(r) => r.pairs_without_levels(),
        }
    }

    /// How a building's height is known, for the warning on runs whose displacement passes it.
    pub fn height_basis(&self) -> String {
        match self {
            Plan::Pair(_) => format!(
                "estimated from its period, {} m per s: T ~ 0.1 s per 3 m storey",
                limits::HEIGHT_PER_PERIOD_M
            ),
            Plan::Row(_) => "the sum of its storey heights, storey_height_m".into(),
        }
    }

    /// Every column, in file order: the pair's fixed schema ([`columns::header`]) or the
    /// row's, which follows its buildings and levels ([`RowPlan::header`]).
    pub fn header(&self) -> Vec<String> {
        match self {
            Plan::Pair(p) => columns::pair_header(p),
            Plan::Row(r) => r.header(),
        }
    }

    /// The summed cost of runs `0..end` when a run costs `record_cost[r]` for its record `r`.
    pub fn cost_before(&self, end: u64, record_cost: &[u64]) -> u128 {
        match self {
            Plan::Pair(p) => p.cost_before(end, record_cost),
            Plan::Row(r) => r.cost_before(end, record_cost),
        }
    }

    /// The runs that differ in their motion before any contact ([`PairPlan::motions`]).
    pub fn motions(&self) -> Motions {
        match self {
            Plan::Pair(p) => p.motions(),
            Plan::Row(r) => r.motions(),
        }
    }
}

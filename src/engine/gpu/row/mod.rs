//! Rows of shear buildings on the GPU (`shaders/row.wgsl`, the twin of
//! [`crate::physics::solver::row::fast`]): the row's shape, which the kernel is built for
//! (storey counts and contact levels become WGSL constants, so a kernel loops over exactly the
//! modes and levels its row has); packing runs and their building models into flat buffers;
//! the dispatch loop; reading results back.
//!
//! Buffers, per run: a block of reals (`P_*`: record and contact settings, the gaps, each
//! level's contact), a block of u32 (`M_*`: law, record, each building's model), and the state
//! that persists between dispatches (`S_*` reals, `C_*` u32). Building models (modes, shapes,
//! masses, heights, propagators) are shared by the runs that use the same one.

use super::context::{check_stop, stopped, GpuContext, GpuError, Kernel, Stage, Stop};
use super::layout::{MODE_FREE, STATUS_COLLAPSE, STATUS_HANDOFF, STATUS_NON_FINITE, STATUS_OK};
use super::precision::Precision;
use super::run::{
    bind_group, read, storage, unit_cap, wait, zeroed, ChunkTimes, GpuOptions, GpuRecords,
    WorkLists,
};
use super::sweep::GpuTimes;
use crate::engine::Summary;
use crate::physics::contact::LawKind;
use crate::physics::model::{Forcing, Oscillator, Status};
use crate::physics::propagator::{CoupledPropagator, Propagator};
use crate::physics::row::{struck_side, BuildingOutput, LevelOutput, RowOutput, StoreyOutput};
use crate::physics::solver::row::yielding::settle_intervals;
use crate::physics::solver::row::{simulate_row, BuildingModel, RowModel, RowScheme};
use crate::physics::solver::FastOptions;
use crate::plan::row::{RowPlan, RowRunSpec};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

// A run's parameter block (reals).
pub const P_DT: usize = 0;
pub const P_T0: usize = 1;
pub const P_SCALE: usize = 2;
pub const P_PER_CONTACT: usize = 3;
/// The first level's stiffness (each level reads its own, `LEVEL_PARAMS`).
pub const P_STIFFNESS: usize = 4;
pub const P_RATIO: usize = 5;
/// The row's structural rate (`RowModel::structural_rate`).
pub const P_RATE: usize = 6;
/// The collapse limit on a storey's drift ratio (`RowModel::collapse_limit`, infinite: none;
/// in f32 rounded up, [`collapse_param`]).
pub const P_COLLAPSE: usize = 7;
/// Then one gap per adjacent pair, then per level its contact (`LEVEL_PARAMS`), then each struck
/// storey's stiffness (`RowShape::p_columns`).
pub const P_GAPS: usize = 8;
// A run's meta block (u32), then each building's model block offset.
pub const M_LAW: usize = 0;
pub const M_REC_OFFSET: usize = 1;
pub const M_REC_LEN: usize = 2;
pub const M_INTERVALS: usize = 3;
pub const M_MODELS: usize = 4;
// A run's counters (u32), then each level's (LC_*), then each building's (BC_*).
pub const C_STATUS: usize = 0;
pub const C_SUBSTEPS: usize = 1;
pub const C_I: usize = 2;
pub const C_J: usize = 3;
pub const C_M: usize = 4;
pub const C_PIECES: usize = 5;
pub const C_FREE_STEPS: usize = 6;
/// The event search between units (`Locator` in `shaders/row.wgsl`): its phase, iterations,
/// and last side (an i32's bits).
pub const C_LOCATE: usize = 7;
pub const C_LEVELS: usize = 10;
pub const LC_MODE: usize = 0;
pub const LC_IMPACTS: usize = 1;
pub const LC_I_ONSET: usize = 2;
/// Whether the level's event fires in the step being located.
pub const LC_FIRE: usize = 3;
pub const LC_STRIDE: usize = 4;
pub const BC_DRIFT_STOREY: usize = 0;
pub const BC_ACCEL_FLOOR: usize = 1;
pub const BC_STRIDE: usize = 2;
// Rows with yielding storeys add, after the buildings' counters: whether the run settled
// (`RowModel::settled`), then per storey its spring state (`SM_*` in `shaders/yielding.wgsl`)
// whether it has yielded, and whether its event fires in the step being located.
pub const SC_MODE: usize = 0;
pub const SC_YIELDED: usize = 1;
pub const SC_FIRE: usize = 2;
pub const SC_STRIDE: usize = 3;
// A run's state (reals): z, the local time, the event search's reals (its bracket `a, f(a),
// b, f(b)`, tolerance and guard probe), then each level's (LS_*), then each building's.
pub const LOCATE_REALS: usize = 6;
pub const LS_V0: usize = 0;
pub const LS_TAU_ONSET: usize = 1;
pub const LS_IMP_PEAK: usize = 2;
pub const LS_PEAK_FORCE: usize = 3;
pub const LS_IMPACT_VELOCITY: usize = 4;
pub const LS_PENETRATION: usize = 5;
pub const LS_FIRST_IMPACT: usize = 6;
pub const LS_CONTACT_TIME: usize = 7;
pub const LS_DISSIPATED: usize = 8;
/// Reals per contact level in a run's parameters: its stiffness, damping, effective mass and
/// contact-time coefficient.
pub const LEVEL_PARAMS: usize = 4;
/// The struck column's largest shear, where a floor strikes a column.
pub const LS_COLUMN_SHEAR: usize = 9;
pub const LS_STRIDE: usize = 10;
pub const BS_ROOF: usize = 0;
pub const BS_DRIFT: usize = 1;
pub const BS_ACCEL: usize = 2;
pub const BS_STRIDE: usize = 3;
/// Reals per mode in a building model: `w^2`, `2 xi w`, the participation, then the
/// propagator's `uu, uv, ua0, ua1, vu, vv, va0, va1`.
pub const MW: usize = 11;
/// Reals per yielding storey after its building's model block: `k`, `d_y`, `b`, then its
/// modal row (the drift in the building's modes).
pub const STOREY_HEAD: usize = 4;

/// lavapipe ends a shader's loops after about 65,535 back edges per invocation, counted over
/// all its loops (see [`super::run::CPU_ADAPTER_BUDGET`]): a dispatch's units on a software
/// adapter are capped to stay below this many loop trips.
const SOFTWARE_LOOP_TRIPS: u64 = 60_000;

/// The most `sum n^2` over a row's buildings whose per-shape functions are written out
/// ([`RowShape::unrolled`]).
pub const UNROLL_MAX_SQUARES: usize = 65;

/// What a row kernel is built for: each building's storeys, and each contact level's left
/// building and floors (from 0).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct RowShape {
    pub storeys: Vec<usize>,
    pub levels: Vec<[usize; 3]>,
    /// Each building: do its storeys yield?
    pub yielding: Vec<bool>,
    /// Each building: may its damping couple its modes (P-Delta with Rayleigh damping on
    /// `K0`, several storeys)? Its block then carries the coupling and the exact step of its
    /// modes together (zeros and the per-mode step where a run's storeys lean alike).
    pub coupled: Vec<bool>,
    /// The levels where a floor strikes a column: the level, the struck side (0 left, 1
    /// right) and its weight's bits (`LevelSide::weight`, the share on the storey's top
    /// floor). Empty where every level is floor against floor.
    pub columns: Vec<(usize, usize, u64)>,
}

impl RowShape {
    /// The shape of every run of `plan` (storeys, levels, which buildings yield or may couple
    /// their modes are the config's, not a run's), from its first run; `plan` has one.
    pub fn of_plan(plan: &RowPlan) -> RowShape {
        RowShape::of(&RowModel::new(&plan.row(&plan.run(0))))
    }

    pub fn of(m: &RowModel) -> RowShape {
        RowShape {
            storeys: m.buildings.iter().map(|b| b.n()).collect(),
            levels: m
                .levels
                .iter()
                .map(|l| [l.buildings.0, l.sides[0].floor - 1, l.sides[1].floor - 1])
                .collect(),
            columns: (m.levels.iter().enumerate())
                .filter_map(|(l, lm)| {
                    let side = struck_side(&lm.sides)?;
                    Some((l, side, lm.sides[side].weight.to_bits()))
                })
                .collect(),
            yielding: m
                .buildings
                .iter()
                .map(|b| b.first_storey.is_some())
                .collect(),
            coupled: m.buildings.iter().map(may_couple).collect(),
        }
    }

    /// An elastic row's shape.
    pub fn elastic(storeys: Vec<usize>, levels: Vec<[usize; 3]>) -> RowShape {
        let yielding = vec![false; storeys.len()];
        let coupled = yielding.clone();
        RowShape {
            storeys,
            levels,
            yielding,
            coupled,
            columns: Vec::new(),
        }
    }

    /// Where a floor strikes a yielding storey's column at level `l`: that storey's index
    /// among the run's yielding storeys.
    fn struck_storey(&self, l: usize) -> Option<usize> {
        let &(_, side, _) = self.columns.iter().find(|c| c.0 == l)?;
        let [a, fa, fb] = self.levels[l];
        let (b, storey) = (a + side, if side == 0 { fa } else { fb });
        // The yielding storeys of the buildings before it come first (`first_storeys`, without
        // its vector: this runs per run at readback).
        let before = (self.storeys[..b].iter().zip(&self.yielding))
            .filter(|(_, &y)| y)
            .map(|(n, _)| n)
            .sum::<usize>();
        self.yielding[b].then_some(before + storey)
    }

    /// Level `l`'s weight on side `side` (1 on a floor).
    fn weight(&self, l: usize, side: usize) -> f64 {
        (self.columns.iter())
            .find(|c| c.0 == l && c.1 == side)
            .map_or(1.0, |c| f64::from_bits(c.2))
    }

    /// The yielding storeys (every storey of each yielding building).
    fn yielding_storeys(&self) -> usize {
        self.storeys
            .iter()
            .zip(&self.yielding)
            .filter(|(_, &y)| y)
            .map(|(n, _)| n)
            .sum()
    }

    /// Each building's first yielding storey among the yielding storeys (None: elastic).
    fn first_storeys(&self) -> Vec<Option<usize>> {
        let mut next = 0;
        self.storeys
            .iter()
            .zip(&self.yielding)
            .map(|(&n, &y)| {
                let first = y.then_some(next);
                next += if y { n } else { 0 };
                first
            })
            .collect()
    }

    fn modes(&self) -> usize {
        self.storeys.iter().sum()
    }

    /// The state slot of the first plastic drift (`RowModel::plastic_slot(0)`).
    fn plastic_slot0(&self) -> usize {
        2 * self.modes() + self.levels.len() + 2
    }

    fn zlen(&self) -> usize {
        self.plastic_slot0() + 2 * self.yielding_storeys()
    }

    /// A yielding row's extra block: one more meta word (the settle end), counter and state.
    fn yields(&self) -> usize {
        (self.yielding_storeys() > 0) as usize
    }

    fn p_stride(&self) -> usize {
        self.p_columns() + self.columns.len()
    }

    /// Where the struck storeys' stiffnesses start in a run's parameters (one per level where
    /// a floor strikes a column), after each level's contact.
    fn p_columns(&self) -> usize {
        P_GAPS + self.storeys.len() - 1 + LEVEL_PARAMS * self.levels.len()
    }

    fn m_stride(&self) -> usize {
        M_MODELS + self.storeys.len() + self.yields()
    }

    /// The event search's reals, after z and the local time.
    fn s_locate(&self) -> usize {
        self.zlen() + 1
    }

    fn s_levels(&self) -> usize {
        self.s_locate() + LOCATE_REALS
    }

    fn s_buildings(&self) -> usize {
        self.s_levels() + LS_STRIDE * self.levels.len()
    }

    fn s_storeys(&self) -> usize {
        self.s_buildings() + BS_STRIDE * self.storeys.len()
    }

    fn s_stride(&self) -> usize {
        self.s_storeys() + self.yielding_storeys()
    }

    fn c_buildings(&self) -> usize {
        C_LEVELS + LC_STRIDE * self.levels.len()
    }

    fn c_settled(&self) -> usize {
        self.c_buildings() + BC_STRIDE * self.storeys.len()
    }

    fn c_storeys(&self) -> usize {
        self.c_settled() + 1
    }

    fn c_stride(&self) -> usize {
        self.c_settled() + self.yields() * (1 + SC_STRIDE * self.yielding_storeys())
    }

    /// The last record interval any run of a chunk with meta blocks `meta` may reach: its
    /// record's end, or with yielding storeys its settling time's.
    fn last_interval(&self, meta: &[u32]) -> u64 {
        let end = M_MODELS + self.storeys.len();
        (meta.chunks(self.m_stride()))
            .map(|m| match self.yields() {
                0 => m[M_INTERVALS],
                _ => m[M_INTERVALS].max(m[end]),
            })
            .max()
            .unwrap_or(0) as u64
    }

    /// Bytes of a run's largest per-run block in `precision` (the chunk's cap follows from it).
    pub fn largest_block_bytes(&self, precision: Precision) -> usize {
        let reals = self.s_stride().max(self.p_stride()) * precision.bytes();
        reals.max(4 * self.c_stride().max(self.m_stride()))
    }

    /// Reals of one building's model block before its coupled part (with its storeys' where
    /// they yield).
    fn model_head_len(n: usize, yields: bool) -> usize {
        MW * n + n * n + 2 * n + if yields { n * (STOREY_HEAD + n) } else { 0 }
    }

    /// Reals of one building's model block: where its modes may couple, whether they do in
    /// this run (1 or 0), the coupling `E` (`N x N`), the exact step of its `[q, q']` (`2N x
    /// 2N`) and its ground terms (`2 x 2N`).
    fn model_len(n: usize, yields: bool, coupled: bool) -> usize {
        Self::model_head_len(n, yields) + if coupled { 1 + 5 * n * n + 4 * n } else { 0 }
    }

    /// The shape and layout as WGSL constants, prepended to `row.wgsl`.
    pub fn wgsl_constants(&self) -> String {
        let list = |v: &[usize]| -> String {
            let items: Vec<String> = v.iter().map(|x| format!("{x}u")).collect();
            items.join(", ")
        };
        let nb = self.storeys.len();
        let nl = self.levels.len();
        let nla = nl.max(1);
        let offs = self.mode_offsets();
        let pick = |k: usize| -> Vec<usize> {
            let v: Vec<usize> = self.levels.iter().map(|l| l[k]).collect();
            if v.is_empty() {
                vec![0]
            } else {
                v
            }
        };
        let mut s = String::new();
        let mut c = |name: &str, v: usize| s.push_str(&format!("const {name}: u32 = {v}u;\n"));
        let ns = self.yielding_storeys();
        c("NB", nb);
        c("NM", self.modes());
        c("NL", nl);
        c("NLA", nla);
        c("NS", ns);
        c("NSA", ns.max(1));
        c("PS0", self.plastic_slot0());
        c("ZLEN", self.zlen());
        c("MAXN", *self.storeys.iter().max().unwrap_or(&1));
        c("FLEN", 10 * self.modes());
        c("MW", MW);
        for (name, v) in [
            ("P_DT", P_DT),
            ("P_T0", P_T0),
            ("P_SCALE", P_SCALE),
            ("P_PER_CONTACT", P_PER_CONTACT),
            ("P_STIFFNESS", P_STIFFNESS),
            ("P_RATIO", P_RATIO),
            ("P_RATE", P_RATE),
            ("P_COLLAPSE", P_COLLAPSE),
            ("P_GAPS", P_GAPS),
            ("P_LEVELS", P_GAPS + nb - 1),
            ("LEVEL_PARAMS", LEVEL_PARAMS),
            ("P_COLUMNS", self.p_columns()),
            ("P_STRIDE", self.p_stride()),
            ("M_LAW", M_LAW),
            ("M_REC_OFFSET", M_REC_OFFSET),
            ("M_REC_LEN", M_REC_LEN),
            ("M_INTERVALS", M_INTERVALS),
            ("M_MODELS", M_MODELS),
            ("M_SETTLE_END", M_MODELS + nb),
            ("M_STRIDE", self.m_stride()),
            ("C_STATUS", C_STATUS),
            ("STATUS_COLLAPSE", STATUS_COLLAPSE as usize),
            ("C_SUBSTEPS", C_SUBSTEPS),
            ("C_I", C_I),
            ("C_J", C_J),
            ("C_M", C_M),
            ("C_PIECES", C_PIECES),
            ("C_FREE_STEPS", C_FREE_STEPS),
            ("C_LOCATE", C_LOCATE),
            ("C_LEVELS", C_LEVELS),
            ("C_BUILDINGS", self.c_buildings()),
            ("C_SETTLED", self.c_settled()),
            ("C_STOREYS", self.c_storeys()),
            ("SC_MODE", SC_MODE),
            ("SC_YIELDED", SC_YIELDED),
            ("SC_FIRE", SC_FIRE),
            ("SC_STRIDE", SC_STRIDE),
            ("STOREY_HEAD", STOREY_HEAD),
            ("C_STRIDE", self.c_stride()),
            ("LC_MODE", LC_MODE),
            ("LC_IMPACTS", LC_IMPACTS),
            ("LC_I_ONSET", LC_I_ONSET),
            ("LC_FIRE", LC_FIRE),
            ("LC_STRIDE", LC_STRIDE),
            ("BC_DRIFT_STOREY", BC_DRIFT_STOREY),
            ("BC_ACCEL_FLOOR", BC_ACCEL_FLOOR),
            ("BC_STRIDE", BC_STRIDE),
            ("S_TAU", self.zlen()),
            ("S_LOCATE", self.s_locate()),
            ("S_LEVELS", self.s_levels()),
            ("S_BUILDINGS", self.s_buildings()),
            ("S_STOREYS", self.s_storeys()),
            ("S_STRIDE", self.s_stride()),
            ("LS_V0", LS_V0),
            ("LS_TAU_ONSET", LS_TAU_ONSET),
            ("LS_IMP_PEAK", LS_IMP_PEAK),
            ("LS_PEAK_FORCE", LS_PEAK_FORCE),
            ("LS_IMPACT_VELOCITY", LS_IMPACT_VELOCITY),
            ("LS_PENETRATION", LS_PENETRATION),
            ("LS_FIRST_IMPACT", LS_FIRST_IMPACT),
            ("LS_CONTACT_TIME", LS_CONTACT_TIME),
            ("LS_DISSIPATED", LS_DISSIPATED),
            ("LS_COLUMN_SHEAR", LS_COLUMN_SHEAR),
            ("LS_STRIDE", LS_STRIDE),
            ("BS_ROOF", BS_ROOF),
            ("BS_DRIFT", BS_DRIFT),
            ("BS_ACCEL", BS_ACCEL),
            ("BS_STRIDE", BS_STRIDE),
        ] {
            c(name, v);
        }
        // Private arrays, not `const` ones: they are indexed at run time.
        let mut a = |name: &str, len: &str, v: &[usize]| {
            s.push_str(&format!(
                "var<private> {name}: array<u32, {len}> = array<u32, {len}>({});\n",
                list(v)
            ))
        };
        a("B_N", "NB", &self.storeys);
        a("B_OFF", "NB", &offs);
        a("L_A", "NLA", &pick(0));
        a("L_FA", "NLA", &pick(1));
        a("L_FB", "NLA", &pick(2));
        // Where floors strike columns: each level's struck side (2: none) and its index among
        // such levels, each side's weight (1 on a floor).
        let (mut struck, mut index) = (vec![2; nla], vec![0; nla]);
        for (i, &(l, side, _)) in self.columns.iter().enumerate() {
            (struck[l], index[l]) = (side, i);
        }
        a("L_CS", "NLA", &struck);
        a("L_CI", "NLA", &index);
        let mut weights = String::new();
        for (name, side) in [("L_WA", 0), ("L_WB", 1)] {
            let w: Vec<String> = (0..nla)
                .map(|l| format!("{:?}", self.weight(l, side)))
                .collect();
            weights.push_str(&format!(
                "var<private> {name}: array<real, NLA> = array<real, NLA>({});\n",
                w.join(", ")
            ));
        }
        // The yielding storeys: each one's building and storey, each building's first (NS
        // where it is elastic).
        let firsts = self.first_storeys();
        let first: Vec<usize> = firsts.iter().map(|f| f.unwrap_or(ns)).collect();
        let (mut sb, mut sj) = (Vec::new(), Vec::new());
        for (b, (&n, f)) in self.storeys.iter().zip(&firsts).enumerate() {
            if f.is_some() {
                sb.extend(std::iter::repeat_n(b, n));
                sj.extend(0..n);
            }
        }
        if ns == 0 {
            (sb, sj) = (vec![0], vec![0]);
        }
        a("S_B", "NSA", &sb);
        a("S_J", "NSA", &sj);
        a("B_S0", "NB", &first);
        // Where each building's coupled part starts in its block (0: its modes are uncoupled).
        let cp: Vec<usize> = (self.storeys.iter().zip(&self.yielding).zip(&self.coupled))
            .map(|((&n, &y), &c)| if c { Self::model_head_len(n, y) } else { 0 })
            .collect();
        a("B_CP", "NB", &cp);
        s.push_str(&weights);
        s.push_str(&format!(
            "const COUPLED: bool = {};\nconst HAS_COLUMNS: bool = {};\n",
            self.coupled.iter().any(|&c| c),
            !self.columns.is_empty()
        ));
        s.push_str(&self.wgsl_collapse_reached());
        if self.unrolled() {
            s.push_str(&self.wgsl_unrolled());
        } else {
            s.push_str(super::shader::ROW_LOOPS_WGSL);
        }
        s
    }

    /// `collapse_reached()`: has a building's peak drift ratio reached the run's collapse
    /// limit (the host's test of a run's output, `!(peak < limit)`, so that a NaN peak ends it
    /// too)? Written out per building: no loop, so the loop trips per unit stay as counted.
    fn wgsl_collapse_reached(&self) -> String {
        let mut e = String::from("false");
        for b in 0..self.storeys.len() {
            e.push_str(&format!(
                " || !(rstate[RS + S_BUILDINGS + {}u] < limit)",
                BS_STRIDE * b + BS_DRIFT
            ));
        }
        format!("fn collapse_reached() -> bool {{\n    let limit = rp(P_COLLAPSE);\n    return {e};\n}}\n")
    }

    /// Is the row small enough to write its per-shape functions out (`wgsl_unrolled`)? The
    /// written-out floors grow as the square of a building's storeys, and lavapipe's compile
    /// time faster still; taller rows take `shaders/row_loops.wgsl`.
    pub fn unrolled(&self) -> bool {
        self.storeys.iter().map(|n| n * n).sum::<usize>() <= UNROLL_MAX_SQUARES
    }

    /// Where each building's modes start in the state (`B_OFF`).
    fn mode_offsets(&self) -> Vec<usize> {
        (self.storeys.iter())
            .scan(0, |o, &n| {
                let at = *o;
                *o += n;
                Some(at)
            })
            .collect()
    }

    /// The row's per-shape functions (`row::rhs`, each level's gap, rate, bound and structural
    /// acceleration, the floors' `fill`, a storey's drift, the plastic loads) written out for
    /// this shape, with what they read per run cached where every index is a constant (each
    /// building's mode shapes and masses in `SHP`, each coupled building's `E` in `CPE`, each
    /// yielding storey's row in `STR`, loaded by `load_shape_rows`).
    /// lavapipe turns a private array indexed at run time into a per-lane loop of loads and
    /// stores; written out, the state's indices are constants and its reals stay in
    /// registers. The operations and their order are those of the loops this replaces
    /// (`side_of`, `force`, `coupled_term`), so the values are the same.
    fn wgsl_unrolled(&self) -> String {
        let nm = self.modes();
        let offs = self.mode_offsets();
        let mut s = String::new();
        let mut load = String::new();
        // Each building's mode shapes (floor-major) and floor masses, for `fill`.
        let mut shp = Vec::new();
        let mut nshp = 0;
        for (b, &n) in self.storeys.iter().enumerate() {
            shp.push(nshp);
            for x in 0..n * n + n {
                load.push_str(&format!(
                    "    SHP[{}u] = models[MB[{b}u] + {}u];\n",
                    nshp + x,
                    MW * n + x
                ));
            }
            nshp += n * n + n;
        }
        // Each level's two sides' rows of mode shapes: where their n reals start in SHP (a
        // floor's row, or on a column its storey's floors' rows by their shares, as
        // `BuildingModel::point_row`).
        let mut rows: Vec<[usize; 2]> = Vec::new();
        for (l, &[a, fa, fb]) in self.levels.iter().enumerate() {
            let mut pair = [0; 2];
            for (side, (b, f)) in [(a, fa), (a + 1, fb)].into_iter().enumerate() {
                let n = self.storeys[b];
                let row = |f: usize| shp[b] + f * n;
                let w = self.weight(l, side);
                if w == 1.0 {
                    pair[side] = row(f);
                    continue;
                }
                pair[side] = nshp;
                for i in 0..n {
                    let top = format!("{:?} * SHP[{}u]", w, row(f) + i);
                    let x = if f == 0 {
                        top
                    } else {
                        format!("{:?} * SHP[{}u] + {top}", 1.0 - w, row(f - 1) + i)
                    };
                    load.push_str(&format!("    SHP[{}u] = {x};\n", nshp + i));
                }
                nshp += n;
            }
            rows.push(pair);
        }
        let mut cpe = Vec::new();
        let mut ncpe = 0;
        for (b, &n) in self.storeys.iter().enumerate() {
            if self.coupled[b] {
                cpe.push((b, ncpe));
                for i in 0..n {
                    for k in 0..n {
                        load.push_str(&format!(
                            "    CPE[{}u] = cpl_e({b}u, {i}u, {k}u);\n",
                            ncpe + n * i + k
                        ));
                    }
                }
                ncpe += n * n;
            }
        }
        // Each yielding storey's modal row (`st_row`), for its drift and plastic load.
        let mut str_at = Vec::new();
        let mut nstr = 0;
        let mut st = 0;
        for (b, (&n, &y)) in self.storeys.iter().zip(&self.yielding).enumerate() {
            if !y {
                continue;
            }
            for _ in 0..n {
                str_at.push((b, nstr));
                for i in 0..n {
                    load.push_str(&format!("    STR[{}u] = st_row({st}u, {i}u);\n", nstr + i));
                }
                nstr += n;
                st += 1;
            }
        }
        s.push_str(&format!(
            "var<private> STR: array<real, {}>;\n",
            nstr.max(1)
        ));
        s.push_str(&format!(
            "var<private> CPE: array<real, {}>;\nvar<private> SHP: array<real, {nshp}>;\n",
            ncpe.max(1)
        ));
        s.push_str("fn load_shape_rows() {\n");
        s.push_str(&load);
        s.push_str("}\n");
        // phi . q of a side row from offset `at` of z (side_of).
        let dot = |row: usize, b: usize, at: usize| -> String {
            let mut e = String::from("0.0");
            for i in 0..self.storeys[b] {
                e.push_str(&format!(
                    " + SHP[{}u] * (*z)[{}u]",
                    row + i,
                    at + offs[b] + i
                ));
            }
            e
        };
        // Each level's gap and its rate (row/mod.rs LevelModel), a case per level.
        for (name, at, gap) in [("delta", 0, true), ("ddelta", nm, false)] {
            s.push_str(&format!(
                "fn {name}(l: u32, z: ptr<function, ZA>) -> real {{\n    switch l {{\n"
            ));
            for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
                let gap = if gap {
                    format!(" - rp(P_GAPS + {a}u)")
                } else {
                    String::new()
                };
                s.push_str(&format!(
                    "        case {l}u: {{ return ({}) - ({}){gap}; }}\n",
                    dot(ra, a, at),
                    dot(rb, a + 1, at)
                ));
            }
            s.push_str("        default: { return 0.0; }\n    }\n}\n");
        }
        // (E q')_i of coupled building b whose E starts at c in CPE (row.wgsl's coupled_term).
        let coupled_term = |b: usize, c: usize, i: usize| -> String {
            let n = self.storeys[b];
            let mut e = String::from("0.0");
            for k in 0..n {
                e.push_str(&format!(
                    " + CPE[{}u] * (*z)[{}u]",
                    c + n * i + k,
                    nm + offs[b] + k
                ));
            }
            e
        };
        let cpe_of = |b: usize| cpe.iter().find(|(x, _)| *x == b).map(|&(_, c)| c);
        // Each level's bound (its floors' mode shapes by the modes' bounds QB) and its floors'
        // structural relative acceleration (row_loops.wgsl's level_bound, floor_accel).
        s.push_str("fn level_bound(l: u32) -> real {\n    switch l {\n");
        for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
            let side = |row: usize, b: usize| -> String {
                let mut e = String::from("0.0");
                for i in 0..self.storeys[b] {
                    e.push_str(&format!(" + abs(SHP[{}u]) * QB[{}u]", row + i, offs[b] + i));
                }
                e
            };
            s.push_str(&format!(
                "        case {l}u: {{ return ({}) + ({}); }}\n",
                side(ra, a),
                side(rb, a + 1)
            ));
        }
        s.push_str("        default: { return 0.0; }\n    }\n}\n");
        s.push_str(
            "fn structural_rel_accel(l: u32, z: ptr<function, ZA>) -> real {\n    switch l {\n",
        );
        for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
            s.push_str(&format!("        case {l}u: {{\n"));
            for (name, row, b) in [("sa", ra, a), ("sb", rb, a + 1)] {
                let mut e = String::from("0.0");
                for i in 0..self.storeys[b] {
                    let k = offs[b] + i;
                    e.push_str(&format!(
                        " + SHP[{}u] * (-TXW[{k}u] * (*z)[{}u] - W2[{k}u] * (*z)[{k}u])",
                        row + i,
                        nm + k
                    ));
                }
                s.push_str(&format!("            var {name} = {e};\n"));
                if let Some(c) = cpe_of(b) {
                    s.push_str(&format!("            if (coupled({b}u)) {{\n"));
                    for i in 0..self.storeys[b] {
                        s.push_str(&format!(
                            "                {name} -= SHP[{}u] * ({});\n",
                            row + i,
                            coupled_term(b, c, i)
                        ));
                    }
                    s.push_str("            }\n");
                }
            }
            s.push_str("            return sa - sb;\n        }\n");
        }
        s.push_str("        default: { return 0.0; }\n    }\n}\n");
        // Floors::fill of building b at end e (row.wgsl's `fill`), a case per building.
        s.push_str("fn fill(b: u32, e: u32, z: ptr<function, ZA>, ag: real) {\n    var acc: array<real, MAXN>;\n    var jrk: array<real, MAXN>;\n    switch b {\n");
        for (b, &n) in self.storeys.iter().enumerate() {
            let o = offs[b];
            s.push_str(&format!("        case {b}u: {{\n            let yields = NS > 0u && B_S0[{b}u] < NS;\n            if (yields) {{ plastic_loads({b}u, z); }}\n"));
            for i in 0..n {
                let k = o + i;
                s.push_str(&format!(
                    "            {{\n                var a = -TXW[{k}u] * (*z)[{v}u] - W2[{k}u] * (*z)[{k}u];\n                if (yields) {{ a += PLA[{i}u]; }}\n                acc[{i}u] = a;\n                let qdd = a - PART[{k}u] * ag;\n                jrk[{i}u] = -TXW[{k}u] * qdd - W2[{k}u] * (*z)[{v}u];\n                if (yields) {{ jrk[{i}u] += PLJ[{i}u]; }}\n            }}\n",
                    v = nm + k
                ));
            }
            if let Some(c) = cpe_of(b) {
                s.push_str(&format!("            if (coupled({b}u)) {{\n"));
                for i in 0..n {
                    let e = coupled_term(b, c, i);
                    s.push_str(&format!(
                        "                {{\n                    let ev = {e};\n                    acc[{i}u] -= ev;\n                    jrk[{i}u] += TXW[{}u] * ev;\n                }}\n",
                        o + i
                    ));
                }
                for i in 0..n {
                    let mut e = String::from("0.0");
                    for k in 0..n {
                        e.push_str(&format!(
                            " + CPE[{}u] * (acc[{k}u] - PART[{}u] * ag)",
                            c + n * i + k,
                            o + k
                        ));
                    }
                    s.push_str(&format!("                jrk[{i}u] -= {e};\n"));
                }
                s.push_str("            }\n");
            }
            let at = shp[b];
            for j in 0..n {
                let sum = |x: &dyn Fn(usize) -> String| -> String {
                    let mut e = String::from("0.0");
                    for i in 0..n {
                        e.push_str(&format!(" + SHP[{}u] * {}", at + j * n + i, x(i)));
                    }
                    e
                };
                let k = o + j;
                s.push_str(&format!(
                    "            {{\n                let u = {};\n                let v = {};\n                let aa = ({}) + FF[{k}u] / SHP[{}u];\n                let je = {};\n                FL[fli(e, 0u, {k}u)] = u;\n                FL[fli(e, 1u, {k}u)] = v;\n                FL[fli(e, 2u, {k}u)] = aa - ag;\n                FL[fli(e, 3u, {k}u)] = aa;\n                FL[fli(e, 4u, {k}u)] = je;\n            }}\n",
                    sum(&|i| format!("(*z)[{}u]", o + i)),
                    sum(&|i| format!("(*z)[{}u]", nm + o + i)),
                    sum(&|i| format!("acc[{i}u]")),
                    at + n * n + j,
                    sum(&|i| format!("jrk[{i}u]")),
                ));
            }
            s.push_str("        }\n");
        }
        s.push_str("        default: {}\n    }\n}\n");
        // RowRun::track_buildings (row_loops.wgsl's), each building and storey written out.
        s.push_str("fn track_buildings(z0: ptr<function, ZA>, z1: ptr<function, ZA>, ag0: real, ag1: real, h: real) {\n    if (ENDS_VALID) {\n        copy_floor_ends();\n    } else {\n        set_floor_forces(true);\n");
        for b in 0..self.storeys.len() {
            s.push_str(&format!("        fill({b}u, 0u, z0, ag0);\n"));
        }
        s.push_str("    }\n    set_floor_forces(false);\n");
        for b in 0..self.storeys.len() {
            s.push_str(&format!("    var touched{b} = false;\n"));
        }
        for (l, &[a, _, _]) in self.levels.iter().enumerate() {
            s.push_str(&format!(
                "    if (LMODE[{l}u] != MODE_FREE) {{\n        touched{a} = true;\n        touched{} = true;\n    }}\n",
                a + 1
            ));
        }
        for b in 0..self.storeys.len() {
            s.push_str(&format!("    fill({b}u, 1u, z1, ag1);\n"));
        }
        let fl = |e: usize, q: usize, k: usize| format!("FL[{}u]", (5 * e + q) * nm + k);
        for (b, &n) in self.storeys.iter().enumerate() {
            let (o, top) = (offs[b], offs[b] + n - 1);
            s.push_str(&format!(
                "    {{\n        let free = !touched{b};\n        let sb = RS + S_BUILDINGS + BS_STRIDE * {b}u;\n        let cb = RC + C_BUILDINGS + BC_STRIDE * {b}u;\n        rstate[sb + BS_ROOF] = raise(free, rstate[sb + BS_ROOF], {}, {}, {}, {}, {}, {}, h);\n        var drift = rstate[sb + BS_DRIFT];\n        var accel = rstate[sb + BS_ACCEL];\n",
                fl(0, 0, top), fl(1, 0, top), fl(0, 1, top), fl(1, 1, top), fl(0, 2, top), fl(1, 2, top)
            ));
            for j in 0..n {
                let k = o + j;
                // Floor 0 is the ground: it moves with the frame.
                let rel = |e: usize, q: usize| {
                    if j == 0 {
                        format!("({} - 0.0)", fl(e, q, k))
                    } else {
                        format!("({} - {})", fl(e, q, k), fl(e, q, k - 1))
                    }
                };
                s.push_str(&format!(
                    "        {{\n            let inv_h = 1.0 / height_at({b}u, {j}u);\n            let y0 = {} * inv_h;\n            let y1 = {} * inv_h;\n            let d0 = {} * inv_h;\n            let d1 = {} * inv_h;\n            let a0 = {} * inv_h;\n            let a1 = {} * inv_h;\n            let p = raise(free, drift, y0, y1, d0, d1, a0, a1, h);\n            if (p > drift) {{\n                drift = p;\n                rcount[cb + BC_DRIFT_STOREY] = {}u;\n            }}\n",
                    rel(0, 0), rel(1, 0), rel(0, 1), rel(1, 1), rel(0, 2), rel(1, 2), j + 1
                ));
                if self.yielding[b] {
                    s.push_str(&format!("            if (NS > 0u) {{\n                raise_storey({b}u, {j}u, free, y0, y1, d0, d1, a0, a1, h);\n            }}\n"));
                }
                s.push_str(&format!(
                    "            var pa: real;\n            if (free) {{\n                pa = raise_cubic_peak(accel, {}, {}, {}, {}, h);\n            }} else {{\n                pa = max(max(accel, abs({})), abs({}));\n            }}\n            if (pa > accel) {{\n                accel = pa;\n                rcount[cb + BC_ACCEL_FLOOR] = {}u;\n            }}\n        }}\n",
                    fl(0, 3, k), fl(0, 4, k), fl(1, 3, k), fl(1, 4, k), fl(0, 3, k), fl(1, 3, k), j + 1
                ));
            }
            s.push_str("        rstate[sb + BS_DRIFT] = drift;\n        rstate[sb + BS_ACCEL] = accel;\n    }\n");
        }
        s.push_str("}\n");
        // Yielding storeys (yielding.wgsl): each one's drift or its rate (StoreyModel::drift),
        // and their plastic loads in the right-hand side (row::plastic_rhs).
        let ns = str_at.len();
        if ns > 0 {
            s.push_str("fn storey_drift(s: u32, z: ptr<function, ZA>, at: u32) -> real {\n    switch s {\n");
            for (st, &(b, c)) in str_at.iter().enumerate() {
                let mut e = String::from("0.0");
                for i in 0..self.storeys[b] {
                    e.push_str(&format!(" + STR[{}u] * (*z)[at + {}u]", c + i, offs[b] + i));
                }
                s.push_str(&format!("        case {st}u: {{ return {e}; }}\n"));
            }
            s.push_str("        default: { return 0.0; }\n    }\n}\n");
            s.push_str("fn plastic_rhs(z: ptr<function, ZA>, out: ptr<function, ZA>) {\n");
            for (st, &(b, c)) in str_at.iter().enumerate() {
                let ps = self.plastic_slot0() + st;
                s.push_str(&format!(
                    "    {{\n        (*out)[{ps}u] = 0.0;\n        (*out)[{}u] = 0.0;\n        let p = (*z)[{ps}u];\n        let k = st_k({st}u);\n        let kp = k * p;\n",
                    ps + ns
                ));
                for i in 0..self.storeys[b] {
                    s.push_str(&format!(
                        "        (*out)[{}u] += STR[{}u] * kp;\n",
                        nm + offs[b] + i,
                        c + i
                    ));
                }
                s.push_str(&format!(
                    "        if (SM[{st}u] != SM_ELASTIC) {{\n            let dp = (1.0 - st_b({st}u)) * storey_drift({st}u, z, NM);\n            (*out)[{ps}u] = dp;\n            (*out)[{}u] = k * (storey_drift({st}u, z, 0u) - p) * dp;\n        }}\n    }}\n",
                    ps + ns
                ));
            }
            s.push_str("}\n");
        } else {
            // An elastic row's kernel enters neither (`NS > 0` guards every call).
            s.push_str("fn storey_drift(s: u32, z: ptr<function, ZA>, at: u32) -> real {\n    return 0.0;\n}\nfn plastic_rhs(z: ptr<function, ZA>, out: ptr<function, ZA>) {}\n");
        }
        s.push_str("fn rhs(ag: real, z: ptr<function, ZA>, out: ptr<function, ZA>) {\n");
        for i in 0..nm {
            s.push_str(&format!(
                "    (*out)[{i}u] = (*z)[{v}u];\n    (*out)[{v}u] = -TXW[{i}u] * (*z)[{v}u] - W2[{i}u] * (*z)[{i}u] - PART[{i}u] * ag;\n",
                v = nm + i
            ));
        }
        for &(b, c) in &cpe {
            let n = self.storeys[b];
            s.push_str(&format!("    if (coupled({b}u)) {{\n"));
            for i in 0..n {
                let e = coupled_term(b, c, i);
                s.push_str(&format!("        (*out)[{}u] -= {e};\n", nm + offs[b] + i));
            }
            s.push_str("    }\n");
        }
        s.push_str("    if (NS > 0u) {\n        plastic_rhs(z, out);\n    }\n");
        for (l, (&[a, _, _], &[ra, rb])) in self.levels.iter().zip(&rows).enumerate() {
            let w = 2 * nm + l;
            s.push_str(&format!(
                "    if (LMODE[{l}u] == MODE_FREE) {{\n        (*out)[{w}u] = 0.0;\n    }} else {{\n"
            ));
            s.push_str(&format!(
                "        let d = delta({l}u, z);\n        let r = ddelta({l}u, z);\n        use_level({l}u);\n        let f = contact_force(d, r, LV0[{l}u], LMODE[{l}u] == MODE_APPROACH);\n"
            ));
            for (row, b, sign) in [(ra, a, "-"), (rb, a + 1, "+")] {
                for i in 0..self.storeys[b] {
                    s.push_str(&format!(
                        "        (*out)[{}u] {sign}= SHP[{}u] * f;\n",
                        nm + offs[b] + i,
                        row + i
                    ));
                }
            }
            s.push_str(&format!("        (*out)[{w}u] = f * r;\n    }}\n"));
        }
        let nl = self.levels.len();
        s.push_str(&format!(
            "    (*out)[{}u] = 0.0;\n    (*out)[{}u] = 0.0;\n}}\n",
            2 * nm + nl,
            2 * nm + nl + 1
        ));
        s
    }

    /// An upper bound on the loop trips of one unit of work (a record interval's start with its
    /// free step, or one RK4 step of a piece), counted as the kernel's loops run, with a tenth
    /// more for what a count by hand may miss (this count and a review's, made apart, agree
    /// within 1 % on a row of five and a pair of 14-storey buildings).
    pub fn loop_trips_per_unit(&self) -> u64 {
        let nm = self.modes() as u64;
        let nl = self.levels.len() as u64;
        let nmax = *self.storeys.iter().max().unwrap_or(&1) as u64;
        let zlen = self.zlen() as u64;
        let sq: u64 = self.storeys.iter().map(|&n| (n * n + 2 * n) as u64).sum();
        let nb_all = self.storeys.len() as u64;
        // One gap (`delta`) or its rate at every level: a loop over each side's modes.
        let d: u64 = (self.levels.iter())
            .map(|l| (self.storeys[l[0]] + self.storeys[l[0] + 1]) as u64)
            .sum();
        // Yielding storeys (none in an elastic row): each one's drift and rate are products
        // with its modal row.
        let ns = self.yielding_storeys() as u64;
        let yields = (ns > 0) as u64;
        let storeys = ns * (2 * nmax + 4);
        // Buildings whose damping couples their modes: `E q'` (n^2) in every right-hand side
        // and floor acceleration, twice in a fill, the coupled bounds and the exact step.
        let sqc: u64 = (self.storeys.iter().zip(&self.coupled))
            .filter(|(_, &c)| c)
            .map(|(&n, _)| (n * n) as u64)
            .sum();
        let coupled = (sqc > 0) as u64;
        // rhs: per level the force (gap and rate), its rate again, the force onto both sides.
        let rhs = nm + 4 * d + nl + 1 + storeys + ns * nmax + sqc + nb_all * coupled;
        let rk4 = 4 * rhs + 4 * zlen;
        // The levels' gaps and rates at a substep's two ends, once (`level_ends`); the event
        // values, the forces, the tracking and the transitions read them.
        let ends = 4 * d + nl + ns * (4 * nmax + 1);
        let event_values = nl + storeys;
        let forces = nm + nl;
        // track: the floors at both ends (fill), each building's storeys, and per level.
        let track = 5 * nm + 2 * forces + 2 * sq + nl + nm + 2 * nl;
        let track = track + 2 * (storeys + ns * nmax) + ns + 4 * sqc + 2 * nb_all * coupled;
        let transitions = 2 * nl + storeys;
        // A unit is one RK4 step of a piece (its trial, a probe of a hidden touch or of the
        // event search, the step to its far end) or a record interval's start, then the
        // tracking and transitions of the units that end a piece or a free step. A software
        // adapter runs a group of lanes in SIMD lockstep through every branch any of them
        // takes: the bound sums the branches (a new piece's trial and a search's step share
        // one RK4 call). In a small row the right-hand side, the gaps and the floors are
        // written out (`wgsl_unrolled`), loop-free; they are still counted as loops here,
        // which only over-counts.
        // Past RK4: the gaps and rates at the step's ends and the events' values at its end
        // and (starting a search) its start, each once, then read from their arrays: the
        // largest three times, the firing ones marked once and their largest twice; the probe
        // of a hidden touch per level.
        let substep = nl + rk4 + ends + 2 * event_values + 6 * (nl + ns) + nl + storeys + 2;
        let tail = track + transitions + storeys + d + nl + 3 * zlen;
        // begin: the modes' bounds (`fill_mode_bounds`), the gaps and rates at the free step's
        // ends once (`level_ends`; the start's alone in contact), per level may_touch (both
        // sides' bounds), the touching level's estimates (structural accelerations), a contact
        // level's.
        let begin = nl + 2 * nm + 7 * d + 3 * d * (1 + coupled) + 6 * nl + zlen;
        let begin = begin + 3 * nm * yields + 2 * storeys + ns * nmax;
        // mode_bounds (with yielding storeys or coupled modes) and the coupled parts.
        let begin = begin + 3 * nm * yields.max(coupled);
        let begin = begin + (8 * sqc + nb_all + nl * 6 * nmax * nmax) * coupled;
        // The settling test each unit passes through (with P-Delta, the static response and
        // each storey's drift in it).
        let settle = (nl + 4 * ns + 8 * nm + 4 * ns * nmax) * yields;
        (begin + substep + tail + settle + 1) * 11 / 10
    }
}

/// The building models of a chunk, each stored once.
#[derive(Debug, Default)]
struct ModelTable {
    reals: Vec<f64>,
    index: HashMap<Vec<u64>, u32>,
}

impl ModelTable {
    fn add(&mut self, block: Vec<f64>) -> u32 {
        let key: Vec<u64> = block.iter().map(|x| x.to_bits()).collect();
        let reals = &mut self.reals;
        *self.index.entry(key).or_insert_with(|| {
            let at = reals.len() as u32;
            reals.extend_from_slice(&block);
            at
        })
    }
}

/// What a yielding storey's outputs need beside the kernel's state: its height and yield
/// drift, and where gravity leans on it (P-Delta) its drift at rest as a combination of its
/// building's plastic drifts (`RowModel::residual_row`).
#[derive(Debug, Clone)]
struct StoreyReadout {
    /// Its index among the run's yielding storeys.
    index: usize,
    height: f64,
    d_y: f64,
    /// Its yield force `k d_y`, N.
    yield_force: f64,
    leaning: Option<(usize, Vec<f64>)>,
}

impl StoreyReadout {
    fn of(m: &RowModel, s: usize) -> StoreyReadout {
        let sm = &m.storeys[s];
        StoreyReadout {
            index: s,
            height: sm.height,
            d_y: sm.d_y,
            yield_force: sm.k * sm.d_y,
            leaning: (sm.geometric != 0.0).then(|| m.residual_row(s)),
        }
    }

    /// Its drift at rest from the run's plastic drifts `p` (every yielding storey's).
    fn residual(&self, p: &[f64]) -> f64 {
        match &self.leaning {
            Some((first, c)) => c.iter().zip(&p[*first..]).map(|(c, p)| c * p).sum(),
            None => p[self.index],
        }
    }
}

/// A chunk of row runs packed for the kernel.
#[derive(Debug)]
pub struct PackedRows {
    pub shape: RowShape,
    params: Vec<f64>,
    meta: Vec<u32>,
    models: ModelTable,
    runs: usize,
    /// Each run's yielding storeys, for their outputs.
    storey_readouts: Vec<StoreyReadout>,
}

fn law_code(l: LawKind) -> u32 {
    LawKind::ALL.iter().position(|&k| k == l).unwrap() as u32
}

impl PackedRows {
    pub fn new(shape: RowShape) -> PackedRows {
        PackedRows {
            shape,
            params: Vec::new(),
            meta: Vec::new(),
            models: ModelTable::default(),
            runs: 0,
            storey_readouts: Vec::new(),
        }
    }

    pub fn len(&self) -> usize {
        self.runs
    }

    pub fn is_empty(&self) -> bool {
        self.runs == 0
    }

    /// The runs' parameters for a kernel in `precision` (each collapse limit as
    /// [`collapse_param`] gives it).
    fn params_in(&self, precision: Precision) -> Vec<f64> {
        let mut params = self.params.clone();
        for run in params.chunks_mut(self.shape.p_stride()) {
            run[P_COLLAPSE] = collapse_param(run[P_COLLAPSE], precision);
        }
        params
    }

    /// Add one run of model `m` (of this chunk's shape) on `forcing`, the `record`-th of `recs`.
    pub fn push(
        &mut self,
        m: &RowModel,
        forcing: &Forcing,
        record: usize,
        recs: &GpuRecords,
        fast: &FastOptions,
    ) {
        let blocks = model_blocks(m, forcing.dt);
        self.push_with_blocks(m, forcing, record, recs, fast, blocks);
    }

    /// [`PackedRows::push`] with the run's model blocks already computed ([`model_blocks`]:
    /// every mode's propagator, the part of packing worth doing on every thread).
    fn push_with_blocks(
        &mut self,
        m: &RowModel,
        forcing: &Forcing,
        record: usize,
        recs: &GpuRecords,
        fast: &FastOptions,
        blocks: Vec<Vec<f64>>,
    ) {
        assert_eq!(
            RowShape::of(m),
            self.shape,
            "a chunk holds rows of one shape"
        );
        let dt = forcing.dt;
        let first = m.levels.first().map(|l| l.contact);
        self.params.extend([
            dt,
            forcing.t0,
            forcing.scale,
            fast.substeps_per_contact,
            first.map_or(0.0, |c| c.stiffness),
            first.map_or(0.0, |c| c.damping_ratio),
            m.structural_rate(),
            m.collapse_limit,
        ]);
        let mut gaps = vec![0.0; self.shape.storeys.len() - 1];
        for l in &m.levels {
            gaps[l.buildings.0] = l.gap;
        }
        self.params.extend(gaps);
        // Each level's own stiffness: two points about to become one level take shares of it.
        for l in &m.levels {
            let c = &l.contact;
            self.params
                .extend([c.stiffness, c.damping, c.m_eff, c.tc_coef()]);
        }
        // Each struck storey's stiffness, where a floor strikes a column.
        self.params
            .extend(m.levels.iter().filter_map(|l| l.column.map(|c| c.k)));
        let (offset, len) = recs.record(record);
        debug_assert_eq!(forcing.accel.len(), len as usize);
        self.meta.extend([
            first.map_or(0, |c| law_code(c.kind)),
            offset,
            len,
            forcing.intervals() as u32,
        ]);
        for block in blocks {
            let at = self.models.add(block);
            self.meta.push(at);
        }
        if !m.storeys.is_empty() {
            self.meta.push(settle_intervals(m, forcing) as u32);
            self.storey_readouts
                .extend((0..m.storeys.len()).map(|s| StoreyReadout::of(m, s)));
        }
        self.runs += 1;
    }
}

/// The collapse limit `limit` as the kernel in `precision` compares with it: in f32 the least
/// f32 not below it, so that an f32 peak `d` is below it exactly where `d as f64 < limit` (the
/// host's test of a run's output); round to nearest, it could fall below the limit and end a
/// run at a peak the host keeps.
pub fn collapse_param(limit: f64, precision: Precision) -> f64 {
    match precision {
        Precision::F64 => limit,
        Precision::F32 => {
            let x = limit as f32;
            if (x as f64) < limit {
                x.next_up() as f64
            } else {
                x as f64
            }
        }
    }
}

/// Each building's model block for the kernel at record step `dt`: per mode `w^2`, `2 xi w`,
/// the participation and the exact propagator; the mode shapes, floor masses, storey heights.
fn model_blocks(m: &RowModel, dt: f64) -> Vec<Vec<f64>> {
    m.buildings
        .iter()
        .map(|b| {
            let n = b.n();
            let coupled = may_couple(b);
            let mut block =
                Vec::with_capacity(RowShape::model_len(n, b.first_storey.is_some(), coupled));
            for i in 0..n {
                let k = b.off + i;
                let osc = Oscillator {
                    m: 1.0,
                    k: m.w2[k],
                    c: m.two_xi_w[k],
                };
                let p = Propagator::new(&osc, dt);
                block.extend([
                    m.w2[k],
                    m.two_xi_w[k],
                    m.part[k],
                    p.uu,
                    p.uv,
                    p.ua0,
                    p.ua1,
                    p.vu,
                    p.vv,
                    p.va0,
                    p.va1,
                ]);
            }
            for row in &b.modes.shape {
                block.extend_from_slice(row);
            }
            block.extend_from_slice(&b.masses);
            block.extend_from_slice(&b.heights);
            if let Some(first) = b.first_storey {
                for s in &m.storeys[first..first + n] {
                    block.extend([s.k, s.d_y, s.b, s.geometric]);
                    block.extend_from_slice(&s.modal_row);
                }
            }
            if coupled {
                // The coupling (zero where this run's storeys lean alike) and the exact step of
                // the building's modes over dt with it, as the CPU's CoupledStep takes it.
                let r = b.off..b.off + n;
                let zero = vec![vec![0.0; n]; n];
                block.push(b.modes.coupling.is_some() as u8 as f64);
                let e = b.modes.coupling.as_ref().unwrap_or(&zero);
                for row in e {
                    block.extend_from_slice(row);
                }
                let p = CoupledPropagator::new(
                    &m.w2[r.clone()],
                    &m.two_xi_w[r.clone()],
                    e,
                    &m.part[r],
                    dt,
                );
                let (step, f0, f1) = p.coefficients();
                block.extend_from_slice(step);
                block.extend_from_slice(f0);
                block.extend_from_slice(f1);
            }
            debug_assert_eq!(
                block.len(),
                RowShape::model_len(n, b.first_storey.is_some(), coupled)
            );
            block
        })
        .collect()
}

/// May building `b`'s damping couple its modes (P-Delta with Rayleigh damping on `K0`, over one
/// storey)? Where it does in a run, `b.modes.coupling` is set.
fn may_couple(b: &BuildingModel) -> bool {
    b.n() > 1 && b.floor_form.as_ref().is_some_and(|f| f.geometric.is_some())
}

/// The row kernels, kept by the context as every other (it knows no row shape: the shape
/// gives the stage its key and its source).
impl GpuContext {
    /// The row kernel for `shape` in `precision`, compiled on first use.
    pub fn row_kernel(
        &self,
        precision: Precision,
        shape: &RowShape,
    ) -> Result<Arc<Kernel>, GpuError> {
        self.row_kernel_until(precision, shape, None)
    }

    /// [`GpuContext::row_kernel`] watching `stop` while it is built ([`GpuContext::stage`]).
    pub fn row_kernel_until(
        &self,
        precision: Precision,
        shape: &RowShape,
        stop: Stop<'_>,
    ) -> Result<Arc<Kernel>, GpuError> {
        use std::hash::{Hash, Hasher};
        let constants = shape.wgsl_constants();
        let mut h = std::collections::hash_map::DefaultHasher::new();
        constants.hash(&mut h);
        let stage = Stage::Row {
            hash: h.finish(),
            loops: !shape.unrolled(),
        };
        self.stage(
            stage,
            precision,
            || super::shader::row_source(precision, &constants),
            stop,
        )
    }
}

/// Units of work per dispatch on a software adapter (unbounded on hardware), or an error when
/// a row of `shape` cannot run there at all.
fn software_cap(ctx: &GpuContext, shape: &RowShape) -> Result<u64, GpuError> {
    let cap = SOFTWARE_LOOP_TRIPS / shape.loop_trips_per_unit();
    if ctx.is_software() && cap == 0 {
        return Err(GpuError::Other {
            message: format!(
                "a row of {} storeys and {} contact levels is too large for the software adapter's loop limit (use --backend cpu)",
                shape.modes(),
                shape.levels.len()
            ),
        });
    }
    Ok(cap)
}

/// Can the row kernel run `plan` on `ctx`? Decided from the plan alone, so a sweep refuses
/// before it makes any file.
pub fn check_fits(ctx: &GpuContext, plan: &RowPlan) -> Result<(), GpuError> {
    if plan.is_empty() {
        return Ok(());
    }
    let shape = RowShape::of_plan(plan);
    software_cap(ctx, &shape).map(|_| ())
}

/// How the kernel left a run. Nearly every run ends with its output, so it is not boxed.
#[allow(clippy::large_enum_variant)]
enum Ended {
    Output(RowOutput),
    /// More substeps per record step than the precision resolves (`STATUS_HANDOFF`).
    HandedBack,
    /// A building's peak drift ratio reached the collapse limit (`STATUS_COLLAPSE`).
    Collapse,
}

impl Ended {
    fn output(self) -> Option<RowOutput> {
        match self {
            Ended::Output(o) => Some(o),
            Ended::HandedBack | Ended::Collapse => None,
        }
    }
}

/// Integrate a chunk of packed rows over their whole records; results in input order, None
/// for runs handed back to the host (more substeps per record step than `opts` allows the
/// precision, or a building's peak drift ratio reached the collapse limit: the kernel ends
/// such a run there).
pub fn run_rows(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedRows,
    opts: &GpuOptions,
) -> Result<(Vec<Option<RowOutput>>, ChunkTimes), GpuError> {
    let (ends, times) = integrate_rows(ctx, recs, chunk, opts, None)?;
    Ok((ends.into_iter().map(Ended::output).collect(), times))
}

/// [`run_rows`], each run's end as the kernel left it; `stop` watched between dispatches
/// (`Err(Interrupted)` once raised).
fn integrate_rows(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedRows,
    opts: &GpuOptions,
    stop: Stop<'_>,
) -> Result<(Vec<Ended>, ChunkTimes), GpuError> {
    let mut times = ChunkTimes::default();
    let n = chunk.runs;
    if n == 0 {
        return Ok((Vec::new(), times));
    }
    if opts.fast.energy {
        return Err(GpuError::Other {
            message: "the GPU row kernel does not integrate the energy balance".into(),
        });
    }
    let shape = &chunk.shape;
    let cap = software_cap(ctx, shape)?;
    let kernel = ctx.row_kernel_until(opts.precision, shape, stop)?;
    let t = Instant::now();
    let p = opts.precision;
    let params = storage(
        ctx,
        "row params",
        &p.reals(&chunk.params_in(p)),
        wgpu::BufferUsages::empty(),
    )?;
    let meta = storage(
        ctx,
        "row metas",
        bytemuck::cast_slice(&chunk.meta),
        wgpu::BufferUsages::empty(),
    )?;
    let models = storage(
        ctx,
        "building models",
        &p.reals(&chunk.models.reals),
        wgpu::BufferUsages::empty(),
    )?;
    // Runs start at rest: a new buffer is zeroed, which is the state at rest, every level
    // free and every counter 0.
    let states = zeroed(
        ctx,
        "row states",
        (n * shape.s_stride() * p.bytes()) as u64,
        wgpu::BufferUsages::COPY_SRC,
    )?;
    let counters = zeroed(
        ctx,
        "row counters",
        (n * shape.c_stride() * 4) as u64,
        wgpu::BufferUsages::COPY_SRC,
    )?;
    let lists = WorkLists::new(ctx, n)?;
    let bind = |from: &wgpu::Buffer, to: &wgpu::Buffer, label| {
        let buffers = [
            &lists.uniform,
            &params,
            &meta,
            recs.buffer(),
            &states,
            &counters,
            &lists.tally,
            from,
            to,
            &models,
        ];
        bind_group(ctx, &kernel.layout, label, &buffers)
    };
    let binds = [
        bind(&lists.ids[0], &lists.ids[1], "row bind group a->b"),
        bind(&lists.ids[1], &lists.ids[0], "row bind group b->a"),
    ];
    wait(ctx)?;
    times.upload = t.elapsed();
    let budget = opts
        .units_per_dispatch
        .max(1)
        .min(unit_cap(ctx, cap.min(u32::MAX as u64) as u32));
    let max_units = row_units(shape.last_interval(&chunk.meta), &opts.fast);
    lists.run(
        "row", ctx, &kernel, &binds, budget, max_units, opts, stop, &mut times,
    )?;
    let t = Instant::now();
    let sbytes = read(ctx, &states)?;
    let cbytes = read(ctx, &counters)?;
    let reals: Vec<f64> = match p {
        Precision::F64 => bytemuck::cast_slice::<u8, f64>(&sbytes).to_vec(),
        Precision::F32 => bytemuck::cast_slice::<u8, f32>(&sbytes)
            .iter()
            .map(|&x| x as f64)
            .collect(),
    };
    let words: &[u32] = bytemuck::cast_slice(&cbytes);
    unfinished(shape, &chunk.meta, words)?;
    let out = (0..n)
        .map(|r| {
            let s = &reals[r * shape.s_stride()..(r + 1) * shape.s_stride()];
            let c = &words[r * shape.c_stride()..(r + 1) * shape.c_stride()];
            let ns = shape.yielding_storeys();
            output(shape, s, c, &chunk.storey_readouts[r * ns..(r + 1) * ns])
        })
        .collect();
    times.readback = t.elapsed();
    Ok((out, times))
}

/// The most units of work a row run of at most `end` record intervals (its settling tail
/// included) can take with `fast`'s caps (`shaders/row.wgsl`, `integrate_run`), doubled for
/// what a count by hand may miss: each interval is begun once; a piece takes one RK4 substep in
/// its trial (the run ends at `max_substeps + 1`), then at most a probe of a hidden touch and
/// its retake, or the event search (its estimates each with a guard probe, its bisections, the
/// step to its end); a unit that only moves to the next substep comes at most
/// `max_substeps_per_step` times per interval.
fn row_units(end: u64, fast: &FastOptions) -> u64 {
    use crate::physics::solver::fast::{LOCATE_BISECTIONS, LOCATE_ITERATIONS};
    let search = 2 * LOCATE_ITERATIONS as u64 + LOCATE_BISECTIONS as u64 + 1;
    let pieces = (fast.max_substeps as u64 + 1).saturating_mul(2 + search);
    let moves = end.saturating_mul(fast.max_substeps_per_step as u64);
    let count = end.saturating_add(moves).saturating_add(pieces);
    count.saturating_mul(2)
}

/// Every run of a chunk read back (`meta` and `counters`: the chunk's blocks) must have ended
/// as `ended()` in `shaders/row.wgsl` says (its record integrated and, with yielding storeys,
/// settled or its settling time spent), or with a status that ends it: one still running would
/// be written as a finished run with part of its record.
fn unfinished(shape: &RowShape, meta: &[u32], counters: &[u32]) -> Result<(), GpuError> {
    let nb = shape.storeys.len();
    // The interval a run runs to, and whether it is there.
    let ended = |r: usize| {
        let m = &meta[r * shape.m_stride()..(r + 1) * shape.m_stride()];
        let c = &counters[r * shape.c_stride()..(r + 1) * shape.c_stride()];
        let recorded = c[C_I] >= m[M_INTERVALS];
        let done = if shape.yields() == 0 {
            recorded
        } else {
            recorded && (c[shape.c_settled()] != 0 || c[C_I] >= m[M_MODELS + nb])
        };
        let end = match shape.yields() {
            0 => m[M_INTERVALS],
            _ => m[M_MODELS + nb],
        };
        (c[C_STATUS] != STATUS_OK || done, c[C_I], end)
    };
    let runs = meta.len() / shape.m_stride();
    let left: Vec<usize> = (0..runs).filter(|&r| !ended(r).0).collect();
    match left.first() {
        Some(&k) => {
            let (_, i, end) = ended(k);
            Err(GpuError::Other {
                message: format!(
                    "{} runs of a chunk of {runs} came back from the device unfinished (the first, chunk run {k}, at record interval {i} of {end}); their results cannot be trusted",
                    left.len()
                ),
            })
        }
        None => Ok(()),
    }
}

/// A run's results from its final state and counters (what `RowRun::finish` does on the CPU,
/// without the energy balance), `storeys`: its yielding storeys'; or that it was handed back.
fn output(shape: &RowShape, s: &[f64], c: &[u32], storeys: &[StoreyReadout]) -> Ended {
    let status = match c[C_STATUS] {
        STATUS_HANDOFF => return Ended::HandedBack,
        STATUS_COLLAPSE => return Ended::Collapse,
        STATUS_OK => Status::Ok,
        STATUS_NON_FINITE => Status::NonFinite,
        _ => Status::StepLimit,
    };
    let levels = (0..shape.levels.len())
        .map(|l| {
            let ls = &s[shape.s_levels() + LS_STRIDE * l..];
            let lc = &c[C_LEVELS + LC_STRIDE * l..];
            let (mut peak_force, mut impact_velocity) = (ls[LS_PEAK_FORCE], ls[LS_IMPACT_VELOCITY]);
            // An impact still under way ends with the run.
            if lc[LC_MODE] != MODE_FREE && ls[LS_IMP_PEAK] > peak_force {
                peak_force = ls[LS_IMP_PEAK];
                impact_velocity = ls[LS_V0];
            }
            LevelOutput {
                impacts: lc[LC_IMPACTS],
                peak_force,
                peak_penetration: ls[LS_PENETRATION],
                impact_velocity,
                first_impact: (lc[LC_IMPACTS] > 0).then_some(ls[LS_FIRST_IMPACT]),
                contact_time: ls[LS_CONTACT_TIME],
                dissipated_energy: ls[LS_DISSIPATED],
                column_shear: ls[LS_COLUMN_SHEAR],
                column_shear_ratio: shape
                    .struck_storey(l)
                    .map_or(0.0, |st| ls[LS_COLUMN_SHEAR] / storeys[st].yield_force),
            }
        })
        .collect();
    let buildings = (0..shape.storeys.len())
        .map(|b| {
            let bs = &s[shape.s_buildings() + BS_STRIDE * b..];
            let bc = &c[shape.c_buildings() + BC_STRIDE * b..];
            BuildingOutput {
                peak_roof: bs[BS_ROOF],
                peak_drift_ratio: bs[BS_DRIFT],
                drift_storey: bc[BC_DRIFT_STOREY],
                peak_accel: bs[BS_ACCEL],
                accel_floor: bc[BC_ACCEL_FLOOR],
                inelastic: None,
                collapse: None,
            }
        })
        .collect();
    let mut out = RowOutput {
        status,
        levels,
        buildings,
        substeps: c[C_SUBSTEPS] as u64,
        free_steps: c[C_FREE_STEPS] as u64,
        ..RowOutput::default()
    };
    let ns = shape.yielding_storeys();
    if ns > 0 {
        let ps = shape.plastic_slot0();
        out.storeys = storeys
            .iter()
            .enumerate()
            .map(|(k, st)| StoreyOutput {
                residual_drift_ratio: st.residual(&s[ps..ps + ns]) / st.height,
                peak_ductility: s[shape.s_storeys() + k] * st.height / st.d_y,
                hysteretic_energy: s[ps + ns + k],
                yielded: c[shape.c_storeys() + SC_STRIDE * k + SC_YIELDED] != 0,
            })
            .collect();
        let spans: Vec<_> = (shape.first_storeys().into_iter())
            .zip(&shape.storeys)
            .map(|(f, &n)| f.map(|f| f..f + n))
            .collect();
        let settled = c[shape.c_settled()] != 0 && status == Status::Ok;
        out.gather_storeys(&spans, &vec![settled; spans.len()]);
    }
    out.gather();
    Ended::Output(out)
}

/// The runs `runs` of a row plan on the GPU in chunks of `chunk`, each chunk's runs handed back
/// by the kernel finished on the CPU in f64 (as for pairs); `sink` gets each chunk in run order,
/// `progress` the runs done after each. With the summary, where the time went and the kernel's
/// lane tally (`handed_off`: the runs the kernel handed back; `handoff` also times the runs
/// that reached the collapse limit, run again on the CPU).
pub fn sweep_rows<E: From<GpuError>>(
    ctx: &GpuContext,
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    chunk: usize,
    opts: &GpuOptions,
    sink: impl FnMut(&[(RowRunSpec, RowOutput)]) -> Result<(), E>,
    progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    sweep_rows_until(ctx, plan, runs, chunk, opts, None, sink, progress)
}

/// [`sweep_rows`] watching `stop`: looked at before each dispatch, before each run's model is
/// built for the next chunk and before each run taken again on the CPU; `Err(Interrupted)` once
/// it is raised (the sink has had whole chunks, in run order).
#[allow(clippy::too_many_arguments)]
pub fn sweep_rows_until<E: From<GpuError>>(
    ctx: &GpuContext,
    plan: &RowPlan,
    runs: std::ops::Range<u64>,
    chunk: usize,
    opts: &GpuOptions,
    stop: Stop<'_>,
    mut sink: impl FnMut(&[(RowRunSpec, RowOutput)]) -> Result<(), E>,
    mut progress: impl FnMut(u64),
) -> Result<(Summary, GpuTimes), E> {
    let start = Instant::now();
    let mut times = GpuTimes::default();
    if runs.is_empty() {
        return Ok((Summary::default(), times));
    }
    let accels = plan.contact.accels();
    let recs = GpuRecords::upload(ctx, opts.precision, &accels)?;
    // Every per-run buffer of a chunk must fit one binding (tall rows carry large blocks).
    let shape = RowShape::of_plan(plan);
    let chunk =
        (chunk.max(1) as u64).min(ctx.runs_fitting(shape.largest_block_bytes(opts.precision)));
    let cpu = RowScheme::Fast(opts.fast);
    let mut summary = Summary::default();
    // A chunk's host work: its runs, their models (a Jacobi decomposition per building) and
    // model blocks (a propagator per mode) on every thread, then packed in run order. The next
    // chunk's is done while the device integrates this one, as for pairs.
    let prep = |first: u64| {
        let t = Instant::now();
        let end = (first + chunk).min(runs.end);
        let specs: Vec<RowRunSpec> = (first..end).into_par_iter().map(|i| plan.run(i)).collect();
        // Stopped while the device integrates the chunk before: the rest left unbuilt.
        let built: Option<Vec<(RowModel, Vec<Vec<f64>>)>> = specs
            .par_iter()
            .map(|s| {
                if stopped(stop) {
                    return None;
                }
                let m = RowModel::new(&plan.row(s));
                let b = model_blocks(&m, plan.forcing(s).dt);
                Some((m, b))
            })
            .collect();
        let (models, blocks): (Vec<RowModel>, Vec<Vec<Vec<f64>>>) =
            built.ok_or(GpuError::Interrupted)?.into_iter().unzip();
        let mut packed = PackedRows::new(shape.clone());
        for ((s, m), b) in specs.iter().zip(&models).zip(blocks) {
            let forcing = plan.forcing(s);
            packed.push_with_blocks(m, &forcing, s.contact.record, &recs, &opts.fast, b);
        }
        Ok((specs, models, packed, t.elapsed().as_secs_f64()))
    };
    let mut first = runs.start;
    // The kernel is built while the first chunk is prepared (lavapipe builds a tall row's for
    // seconds), watching the stop; the chunks then find it built.
    software_cap(ctx, &shape)?;
    let (kernel, prepared) = rayon::join(
        || ctx.row_kernel_until(opts.precision, &shape, stop),
        || prep(first),
    );
    kernel?;
    let mut next = Some(prepared?);
    while let Some((specs, models, packed, pack_s)) = next.take() {
        let end = first + specs.len() as u64;
        times.pack += pack_s;
        let (done, upcoming) = rayon::join(
            || integrate_rows(ctx, &recs, &packed, opts, stop),
            || (end < runs.end).then(|| prep(end)),
        );
        let (outs, ct) = done?;
        next = upcoming.transpose()?;
        times.add_chunk(&ct);
        let t = Instant::now();
        times.handed_off += outs
            .iter()
            .filter(|o| matches!(o, Ended::HandedBack))
            .count() as u64;
        // The runs handed back, on every thread.
        let rows: Vec<(RowRunSpec, RowOutput)> = specs
            .into_par_iter()
            .zip(outs)
            .zip(&models)
            .map(|((s, o), m)| -> Result<_, GpuError> {
                // The kernel has no collapse event: it ends a run once a building's peak drift
                // ratio reaches the limit (`Ended::Collapse`), and the CPU runs it again and
                // ends it at the collapse. The kernel's test is this one (the limit rounded up
                // in f32), so this only restates it.
                let o = o.output().filter(|o| {
                    o.buildings
                        .iter()
                        .all(|b| b.peak_drift_ratio < plan.collapse_drift_ratio)
                });
                let o = match o {
                    Some(o) => o,
                    None => {
                        check_stop(stop)?;
                        simulate_row(m, &plan.forcing(&s), m.at_rest(), &cpu)
                    }
                };
                Ok((s, o))
            })
            .collect::<Result<_, GpuError>>()?;
        times.handoff += t.elapsed().as_secs_f64();
        for (_, o) in &rows {
            summary.count_row(o);
        }
        sink(&rows)?;
        progress(summary.runs);
        first = end;
    }
    summary.seconds = start.elapsed().as_secs_f64();
    Ok((summary, times))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In f32 the kernel's limit is the least f32 not below the collapse limit, so an f32
    /// peak is below it exactly where the host finds the peak below the limit; in f64 (or
    /// with no limit) it is the limit.
    #[test]
    fn an_f32_peak_is_below_the_kernels_limit_where_the_host_finds_it_below() {
        // f32 rounds 0.12 down and 0.1 up.
        for limit in [0.1, 0.12, 0.3, 0.04, 1.0] {
            assert_eq!(collapse_param(limit, Precision::F64), limit);
            let x = collapse_param(limit, Precision::F32);
            assert_eq!(x as f32 as f64, x, "{limit}: an f32");
            let x = x as f32;
            let mut d = x.next_down().next_down();
            for _ in 0..5 {
                assert_eq!(d < x, (d as f64) < limit, "{limit}: peak {d}");
                d = d.next_up();
            }
        }
        let none = collapse_param(f64::INFINITY, Precision::F32);
        assert_eq!(none, f64::INFINITY);
    }

    /// A row read back with its status OK before its record's end (or, with yielding storeys,
    /// before it settled or its settling time ran out) is refused, named.
    #[test]
    fn a_row_read_back_unfinished_is_an_error() {
        // Three runs of 10 record intervals; counters (status, interval, settled).
        let check = |shape: &RowShape, runs: &[(u32, u32, u32)]| {
            let (ms, cs) = (shape.m_stride(), shape.c_stride());
            let mut meta = vec![0; ms * runs.len()];
            let mut counters = vec![0; cs * runs.len()];
            for (r, &(status, i, settled)) in runs.iter().enumerate() {
                meta[r * ms + M_INTERVALS] = 10;
                if shape.yields() > 0 {
                    meta[r * ms + M_MODELS + shape.storeys.len()] = 15;
                    counters[r * cs + shape.c_settled()] = settled;
                }
                counters[r * cs + C_STATUS] = status;
                counters[r * cs + C_I] = i;
            }
            unfinished(shape, &meta, &counters).map_err(|e| e.to_string())
        };
        let elastic = RowShape::elastic(vec![2, 3], vec![[0, 1, 2]]);
        let ended = [
            (STATUS_OK, 10, 0),
            (STATUS_NON_FINITE, 3, 0),
            (STATUS_HANDOFF, 0, 0),
            (STATUS_COLLAPSE, 4, 0),
        ];
        check(&elastic, &ended).unwrap();
        let e = check(
            &elastic,
            &[(STATUS_OK, 10, 0), (STATUS_OK, 4, 0), (STATUS_OK, 0, 0)],
        )
        .unwrap_err();
        assert!(
            e.contains("2 runs of a chunk of 3")
                && e.contains("chunk run 1, at record interval 4 of 10"),
            "{e}"
        );
        // With yielding storeys a run goes on past its record until it settles (or its
        // settling time, here 15 intervals, runs out).
        let yielding = RowShape {
            yielding: vec![true, false],
            ..elastic
        };
        check(&yielding, &[(STATUS_OK, 12, 1), (STATUS_OK, 15, 0)]).unwrap();
        let e = check(&yielding, &[(STATUS_OK, 12, 1), (STATUS_OK, 12, 0)]).unwrap_err();
        assert!(
            e.contains("1 runs of a chunk of 2")
                && e.contains("chunk run 1, at record interval 12 of 15"),
            "{e}"
        );
        let e = check(&yielding, &[(STATUS_OK, 9, 1)]).unwrap_err();
        assert!(e.contains("at record interval 9 of 15"), "{e}");
    }

    /// Every loop in the shaders ends after a count, as building them without naga's loop
    /// bounding requires (context.rs): no `while`, every `for` has a step, every `loop` leaves
    /// once its budget is spent and spends it each pass; the per-shape code the host writes
    /// has no loop at all.
    #[test]
    fn every_loop_counts() {
        use crate::engine::gpu::shader::{
            AGGREGATE_WGSL, CONTACT_WGSL, FAST_WGSL, HERMITE_WGSL, LANES_WGSL, ROW_LOOPS_WGSL,
            ROW_WGSL, TYPES_WGSL, YIELDING_WGSL,
        };
        let shape = RowShape::elastic(vec![3, 6], vec![[0, 0, 0], [0, 1, 1]]);
        let written = shape.wgsl_constants();
        let sources = [
            ("types", TYPES_WGSL),
            ("contact", CONTACT_WGSL),
            ("hermite", HERMITE_WGSL),
            ("fast", FAST_WGSL),
            ("row", ROW_WGSL),
            ("row_loops", ROW_LOOPS_WGSL),
            ("yielding", YIELDING_WGSL),
            ("lanes", LANES_WGSL),
            ("aggregate", AGGREGATE_WGSL),
            ("written out for 3 + 6 storeys", written.as_str()),
        ];
        let (mut fors, mut loops) = (0, 0);
        for (name, src) in sources {
            let code: Vec<&str> = src.lines().map(|l| l.split("//").next().unwrap()).collect();
            for (i, line) in code.iter().enumerate() {
                let at = format!("{name}.wgsl line {}: {line}", i + 1);
                assert!(!line.contains("while"), "{at}");
                if let Some(h) = line.find("for (") {
                    let header = line[h..].split(") {").next().unwrap();
                    let clauses: Vec<&str> = header.split(';').collect();
                    assert_eq!(clauses.len(), 3, "{at}");
                    assert!(!clauses[2].trim().is_empty(), "{at}");
                    fors += 1;
                }
                if line.contains("loop {") {
                    let body = code[i..(i + 12).min(code.len())].join("\n");
                    assert!(body.contains("budget == 0u"), "{at}");
                    assert!(body.contains("budget = budget - 1u"), "{at}");
                    loops += 1;
                }
            }
            if name.starts_with("written") {
                assert!(!src.contains("for (") && !src.contains("loop {"));
            }
        }
        assert!(fors > 20 && loops == 2, "{fors} for, {loops} loop");
    }
}

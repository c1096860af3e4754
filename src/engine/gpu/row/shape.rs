//! A row kernel's shape (each building's storeys, each contact level's buildings and floors,
//! which buildings yield or may couple their modes) and the layout of its per-run buffers
//! that follows from it: the offsets of each block (`P_*` reals and `M_*` u32 per run, the
//! state `S_*` reals and `C_*` u32 that persists between dispatches), their strides, and the
//! loop trips one unit of work runs.

use crate::engine::gpu::precision::Precision;
use crate::physics::row::struck_side;
use crate::physics::solver::row::{BuildingModel, RowModel};
use crate::plan::row::RowPlan;

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
/// in f32 rounded up, `pack::collapse_param`).
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
/// Reals per IMK storey after its building's model block (`IP_*` in `shaders/imk.wgsl`: rule,
/// `k`, `F_y`, `b k`, `u_p`, `u_pc`, residual strength, ultimate drift, whether it has an energy
/// capacity, the capacity).
pub const IMK_PARAMS: usize = 10;
/// Reals per yielding storey in the state of a row with IMK storeys (`IR_*`: each side's
/// backbone, the unloading stiffness, the work and its mark, the piece).
pub const IS_STRIDE: usize = 31;
/// Where a side's backbone starts in them, and its capping force there (`IR_SIDE`, `fcap`).
pub const IR_SIDE: usize = 10;
pub const IR_FCAP: usize = 4;
/// u32 per yielding storey in the counters of a row with IMK storeys (`IC_*`: branch, its
/// side, the piece's two marks, flags), and the flags' bits read back.
pub const IC_STRIDE: usize = 5;
pub const IC_FLAGS: usize = 4;
pub const IF_FAILED0: u32 = 1;
pub const IF_CAPPED: u32 = 8;

/// What a row kernel is built for: each building's storeys, and each contact level's left
/// building and floors (from 0).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct RowShape {
    pub storeys: Vec<usize>,
    pub levels: Vec<[usize; 3]>,
    /// Each building: do its storeys yield?
    pub yielding: Vec<bool>,
    /// Each building: are its storeys IMK springs (deteriorating)? Only a kernel whose row has
    /// one carries their code (`shaders/imk.wgsl`).
    pub imk: Vec<bool>,
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
            imk: (m.buildings.iter())
                .map(|b| b.first_storey.is_some_and(|f| m.storeys[f].imk.is_some()))
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
            imk: yielding.clone(),
            yielding,
            coupled,
            columns: Vec::new(),
        }
    }

    /// Where a floor strikes a yielding storey's column at level `l`: that storey's index
    /// among the run's yielding storeys.
    pub(super) fn struck_storey(&self, l: usize) -> Option<usize> {
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
    pub(super) fn weight(&self, l: usize, side: usize) -> f64 {
        (self.columns.iter())
            .find(|c| c.0 == l && c.1 == side)
            .map_or(1.0, |c| f64::from_bits(c.2))
    }

    /// The yielding storeys (every storey of each yielding building).
    pub(super) fn yielding_storeys(&self) -> usize {
        self.storeys
            .iter()
            .zip(&self.yielding)
            .filter(|(_, &y)| y)
            .map(|(n, _)| n)
            .sum()
    }

    /// Each building's first yielding storey among the yielding storeys (None: elastic).
    pub(super) fn first_storeys(&self) -> Vec<Option<usize>> {
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

    pub(super) fn modes(&self) -> usize {
        self.storeys.iter().sum()
    }

    /// The state slot of the first plastic drift (`RowModel::plastic_slot(0)`).
    pub(super) fn plastic_slot0(&self) -> usize {
        2 * self.modes() + self.levels.len() + 2
    }

    pub(super) fn zlen(&self) -> usize {
        self.plastic_slot0() + 2 * self.yielding_storeys()
    }

    /// A yielding row's extra block: one more meta word (the settle end), counter and state.
    pub(super) fn yields(&self) -> usize {
        (self.yielding_storeys() > 0) as usize
    }

    pub(super) fn p_stride(&self) -> usize {
        self.p_columns() + self.columns.len()
    }

    /// Where the struck storeys' stiffnesses start in a run's parameters (one per level where
    /// a floor strikes a column), after each level's contact.
    pub(super) fn p_columns(&self) -> usize {
        P_GAPS + self.storeys.len() - 1 + LEVEL_PARAMS * self.levels.len()
    }

    pub(super) fn m_stride(&self) -> usize {
        M_MODELS + self.storeys.len() + self.yields()
    }

    /// The event search's reals, after z and the local time.
    pub(super) fn s_locate(&self) -> usize {
        self.zlen() + 1
    }

    pub(super) fn s_levels(&self) -> usize {
        self.s_locate() + LOCATE_REALS
    }

    pub(super) fn s_buildings(&self) -> usize {
        self.s_levels() + LS_STRIDE * self.levels.len()
    }

    pub(super) fn s_storeys(&self) -> usize {
        self.s_buildings() + BS_STRIDE * self.storeys.len()
    }

    /// Does the row have IMK storeys?
    pub fn has_imk(&self) -> bool {
        self.imk.iter().any(|&i| i)
    }

    /// Each yielding storey's IMK reals (`IS_STRIDE`; in a row with IMK storeys).
    pub(super) fn s_imk(&self) -> usize {
        self.s_storeys() + self.yielding_storeys()
    }

    pub(super) fn s_stride(&self) -> usize {
        self.s_imk() + self.has_imk() as usize * IS_STRIDE * self.yielding_storeys()
    }

    pub(super) fn c_buildings(&self) -> usize {
        C_LEVELS + LC_STRIDE * self.levels.len()
    }

    pub(super) fn c_settled(&self) -> usize {
        self.c_buildings() + BC_STRIDE * self.storeys.len()
    }

    pub(super) fn c_storeys(&self) -> usize {
        self.c_settled() + 1
    }

    /// Each yielding storey's IMK u32s (`IC_STRIDE`; in a row with IMK storeys).
    pub(super) fn c_imk(&self) -> usize {
        self.c_settled() + self.yields() * (1 + SC_STRIDE * self.yielding_storeys())
    }

    pub(super) fn c_stride(&self) -> usize {
        self.c_imk() + self.has_imk() as usize * IC_STRIDE * self.yielding_storeys()
    }

    /// The last record interval any run of a chunk with meta blocks `meta` may reach: its
    /// record's end, or with yielding storeys its settling time's.
    pub(super) fn last_interval(&self, meta: &[u32]) -> u64 {
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
    pub(super) fn model_head_len(n: usize, yields: bool) -> usize {
        MW * n + n * n + 2 * n + if yields { n * (STOREY_HEAD + n) } else { 0 }
    }

    /// Reals of one building's model block: where its modes may couple, whether they do in
    /// this run (1 or 0), the coupling `E` (`N x N`), the exact step of its `[q, q']` (`2N x
    /// 2N`) and its ground terms (`2 x 2N`); then, where its storeys are IMK springs, theirs
    /// (`IMK_PARAMS` each).
    pub(super) fn model_len(n: usize, yields: bool, coupled: bool, imk: bool) -> usize {
        Self::model_coupled_len(n, yields, coupled) + if imk { n * IMK_PARAMS } else { 0 }
    }

    /// Where a building's IMK block starts in its model block.
    pub(super) fn model_coupled_len(n: usize, yields: bool, coupled: bool) -> usize {
        Self::model_head_len(n, yields) + if coupled { 1 + 5 * n * n + 4 * n } else { 0 }
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
        // IMK storeys (`shaders/imk.wgsl`): a transition takes up to 16 changes of piece, each
        // two thresholds of up to 6 backbone segments; the set-up at a dispatch's start; their
        // events, watch and settling (a storey's drift each).
        let imk = if self.has_imk() {
            ns * (16 * 2 * 8 + 2 * 8 + 4 + 4 * nmax)
        } else {
            0
        };
        (begin + substep + tail + settle + imk + 1) * 11 / 10
    }
}

/// May building `b`'s damping couple its modes (P-Delta with Rayleigh damping on `K0`, over one
/// storey)? Where it does in a run, `b.modes.coupling` is set.
pub(super) fn may_couple(b: &BuildingModel) -> bool {
    b.n() > 1 && b.floor_form.as_ref().is_some_and(|f| f.geometric.is_some())
}

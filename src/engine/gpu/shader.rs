//! WGSL sources and their per-precision prelude.

use super::layout::{Layout, FORMS_PER_RUN, WORKGROUP_SIZE};
use super::precision::Precision;

/// Codes, settings and shader-only structs every stage shares, then one file per stage, as in
/// `shaders/` (the structs and codes shared with the host are written from `layout`:
/// [`shared_with_host`]).
pub const TYPES_WGSL: &str = include_str!("../../../shaders/types.wgsl");
pub const CONTACT_WGSL: &str = include_str!("../../../shaders/contact.wgsl");
pub const HERMITE_WGSL: &str = include_str!("../../../shaders/hermite.wgsl");
pub const FAST_WGSL: &str = include_str!("../../../shaders/fast.wgsl");
pub const ROW_WGSL: &str = include_str!("../../../shaders/row.wgsl");
/// The per-shape functions of `row.wgsl` as loops, for rows too tall to write them out.
pub const ROW_LOOPS_WGSL: &str = include_str!("../../../shaders/row_loops.wgsl");
pub const YIELDING_WGSL: &str = include_str!("../../../shaders/yielding.wgsl");
/// The IMK storey (a row kernel's whose row has one).
pub const IMK_WGSL: &str = include_str!("../../../shaders/imk.wgsl");
pub const LANES_WGSL: &str = include_str!("../../../shaders/lanes.wgsl");
pub const AGGREGATE_WGSL: &str = include_str!("../../../shaders/aggregate.wgsl");

/// The WGSL declarations of the buffer structs every stage shares with the host, and the run
/// modes and statuses it reads from `Counters`, written from their Rust definitions in `layout`
/// (one source for both sides; `real` is the prelude's alias, so one text serves both
/// precisions). `STATUS_COLLAPSE` is the row kernel's alone: its shape constants carry it.
pub fn shared_with_host() -> String {
    use super::layout::{
        Counters, Dispatch, Meta, Params64, State64, MODE_APPROACH, MODE_FREE, MODE_RESTITUTION,
        STATUS_HANDOFF, STATUS_NON_FINITE, STATUS_OK, STATUS_STEP_LIMIT,
    };
    format!(
        "// Structs and codes shared with the host, written from src/engine/gpu/layout.rs.\n{}{}{}{}\
         const MODE_FREE: u32 = {MODE_FREE}u;\nconst MODE_APPROACH: u32 = {MODE_APPROACH}u;\n\
         const MODE_RESTITUTION: u32 = {MODE_RESTITUTION}u;\nconst STATUS_OK: u32 = {STATUS_OK}u;\n\
         const STATUS_NON_FINITE: u32 = {STATUS_NON_FINITE}u;\n\
         const STATUS_STEP_LIMIT: u32 = {STATUS_STEP_LIMIT}u;\n\
         const STATUS_HANDOFF: u32 = {STATUS_HANDOFF}u;\n{}",
        Params64::wgsl(),
        State64::wgsl(),
        Meta::wgsl(),
        Counters::wgsl(),
        Dispatch::wgsl(),
    )
}

/// What every stage starts with: the `real` alias, its epsilon, a tiny and a huge number (for
/// degenerate-cubic and finiteness tests), the workgroup size, the structs and codes shared with
/// the host ([`shared_with_host`]), then `types.wgsl`.
fn prelude(precision: Precision) -> String {
    let real = match precision {
        Precision::F32 => "alias real = f32;\nconst EPS: real = 1.1920929e-7;\nconst TINY: real = 1e-30;\nconst BIG: real = 1e37;\n",
        Precision::F64 => "alias real = f64;\nconst EPS: real = 2.220446049250313e-16;\nconst TINY: real = 1e-300;\nconst BIG: real = 1e300;\n",
    };
    format!(
        "{real}const WG: u32 = {WORKGROUP_SIZE}u;\n{}{TYPES_WGSL}",
        shared_with_host()
    )
}

/// `shaders/fast.wgsl` for `precision`, after the prelude: with the reals per run of the
/// `forms` buffer, and `ENERGY`: whether this variant integrates the energy balance. Two
/// variants rather than a uniform branch, because lavapipe compiled the untaken energy code
/// into the free step and lost 30 % of its runs/s (measured with `pound bench`).
/// The shared free response's table layout and slack come from `shared` and the physics.
/// `ACCEL`: whether this variant tracks each building's peak absolute acceleration (a row of
/// two one-storey buildings reports it; a pair does not, and its kernel carries none of it).
pub fn fast_source(precision: Precision, energy: bool, accel: bool) -> String {
    use super::layout::NO_RESPONSE;
    use super::shared::{header_reals, reals_per_check, CHECK_EVERY};
    use crate::physics::solver::shared::REACH_SLACK;
    let (header, per_check) = (header_reals(accel), reals_per_check(accel));
    format!(
        "{}const FORMS: u32 = {FORMS_PER_RUN}u;\nconst ENERGY: bool = {energy};\n\
         const ACCEL: bool = {accel};\n\
         const NO_RESPONSE: u32 = {NO_RESPONSE}u;\nconst SH_HEADER: u32 = {header}u;\n\
         const SH_CHECK: u32 = {per_check}u;\nconst SH_EVERY: u32 = {CHECK_EVERY}u;\nconst REACH_SLACK: real = {REACH_SLACK:e};\n{CONTACT_WGSL}{HERMITE_WGSL}{FAST_WGSL}{LANES_WGSL}",
        prelude(precision)
    )
}

/// The band's slack in f32 (`row::yielding::YIELD_SLACK` is f64's): a storey leaves its band edge
/// inside the band once f32 has rounded its back drift `d - p / (1 - b)`, whose terms are up
/// to the ductility times `d_y` (a few 1e-7 each): 1e-4 of `d_y` keeps an unloading storey
/// from re-yielding on rounding at ductilities up to a few hundred.
pub const F32_YIELD_SLACK: f64 = 1e-4;

/// `shaders/row.wgsl` for `precision`, after the prelude and the row's shape `constants`
/// (`RowShape::wgsl_constants`, in `row/`).
/// Every row kernel carries `yielding.wgsl`; its functions are entered only where the shape
/// has yielding storeys (`NS > 0`, a constant), so an elastic row's kernel compiles none of it.
/// A row with IMK storeys (`imk`) adds `imk.wgsl` and the lines marked for it ([`for_imk`]).
pub fn row_source(precision: Precision, constants: &str, imk: bool) -> String {
    let slack = match precision {
        Precision::F64 => crate::physics::solver::row::yielding::YIELD_SLACK,
        Precision::F32 => F32_YIELD_SLACK,
    };
    let (row, yielding) = (for_imk(ROW_WGSL, imk), for_imk(YIELDING_WGSL, imk));
    let imk = if imk { IMK_WGSL } else { "" };
    format!(
        "{}{constants}const YIELD_SLACK: real = {slack:e};\n{CONTACT_WGSL}{HERMITE_WGSL}{row}{yielding}{imk}{LANES_WGSL}",
        prelude(precision)
    )
}

/// `src` for a kernel with IMK storeys or without (`imk`): a line ending in `// IMK` is kept
/// only with them, one ending in `// !IMK` only without (its mark taken off), so a kernel
/// without them is the text it was before they came, and carries none of their code.
pub fn for_imk(src: &str, imk: bool) -> String {
    let mut out = String::with_capacity(src.len());
    for line in src.split_inclusive('\n') {
        let body = line.strip_suffix('\n').unwrap_or(line);
        let end = &line[body.len()..];
        if let Some(code) = body.strip_suffix(" // !IMK") {
            if !imk {
                out.push_str(code);
                out.push_str(end);
            }
        } else if body.ends_with(" // IMK") {
            if imk {
                out.push_str(line);
            }
        } else {
            out.push_str(line);
        }
    }
    out
}

/// `shaders/aggregate.wgsl` for `precision`, after the prelude: with the sketch's bucket range,
/// the partials' layout and the stage's own buffer structs, all from `aggregate` and `layout`
/// (one source of truth).
pub fn aggregate_source(precision: Precision) -> String {
    use super::layout::{
        AggConfig, Segment, PART_R, PART_U, P_EXCEED, P_FAILURES, P_IMPACTS, P_POUNDED, P_RUNS,
    };
    use crate::engine::aggregate::{
        BUCKETS, GAMMA, KMAX, KMIN, MAX_EXCEED, NOUT, SKETCH_MAX, SKETCH_MIN,
    };
    let inv_ln_g = 1.0 / GAMMA.ln();
    format!(
        "{}const NOUT: u32 = {NOUT}u;\nconst BUCKETS: u32 = {BUCKETS}u;\nconst KMIN: i32 = {KMIN}i;\nconst KMAX: i32 = {KMAX}i;\n\
         const SKETCH_MIN: real = {SKETCH_MIN:e};\nconst SKETCH_MAX: real = {SKETCH_MAX:e};\nconst INV_LN_G: f32 = {inv_ln_g:?};\n\
         const MAX_EXCEED: u32 = {MAX_EXCEED}u;\nconst PART_U: u32 = {PART_U}u;\nconst PART_R: u32 = {PART_R}u;\n\
         const P_RUNS: u32 = {P_RUNS}u;\nconst P_FAILURES: u32 = {P_FAILURES}u;\n\
         const P_POUNDED: u32 = {P_POUNDED}u;\nconst P_IMPACTS: u32 = {P_IMPACTS}u;\nconst P_EXCEED: u32 = {P_EXCEED}u;\n{}{}{AGGREGATE_WGSL}",
        prelude(precision),
        AggConfig::wgsl(),
        Segment::wgsl(),
    )
}

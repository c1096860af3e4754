//! WGSL sources and their per-precision prelude.

use super::layout::{FORMS_PER_RUN, WORKGROUP_SIZE};

/// Floating-point precision of the GPU path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Precision {
    F32,
    F64,
}

impl Precision {
    pub fn key(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }

    pub fn from_key(s: &str) -> Option<Precision> {
        match s {
            "f32" => Some(Precision::F32),
            "f64" => Some(Precision::F64),
            _ => None,
        }
    }

    /// `x` as this precision's reals, in bytes (as the shaders' `array<real>` reads them).
    pub fn reals(self, x: &[f64]) -> Vec<u8> {
        match self {
            Precision::F64 => bytemuck::cast_slice(x).to_vec(),
            Precision::F32 => {
                let v: Vec<f32> = x.iter().map(|&y| y as f32).collect();
                bytemuck::cast_slice(&v).to_vec()
            }
        }
    }

    /// Bytes per real.
    pub fn bytes(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }
}

/// Structs and codes every stage shares, then one file per stage, as in `shaders/`.
pub const TYPES_WGSL: &str = include_str!("../../../shaders/types.wgsl");
pub const CONTACT_WGSL: &str = include_str!("../../../shaders/contact.wgsl");
pub const HERMITE_WGSL: &str = include_str!("../../../shaders/hermite.wgsl");
pub const FAST_WGSL: &str = include_str!("../../../shaders/fast.wgsl");
pub const ROW_WGSL: &str = include_str!("../../../shaders/row.wgsl");
/// The per-shape functions of `row.wgsl` as loops, for rows too tall to write them out.
pub const ROW_LOOPS_WGSL: &str = include_str!("../../../shaders/row_loops.wgsl");
pub const YIELDING_WGSL: &str = include_str!("../../../shaders/yielding.wgsl");
pub const LANES_WGSL: &str = include_str!("../../../shaders/lanes.wgsl");
pub const AGGREGATE_WGSL: &str = include_str!("../../../shaders/aggregate.wgsl");

/// What every stage starts with: the `real` alias, its epsilon, a tiny and a huge number (for
/// degenerate-cubic and finiteness tests), the workgroup size, then `types.wgsl`.
fn prelude(precision: Precision) -> String {
    let real = match precision {
        Precision::F32 => "alias real = f32;\nconst EPS: real = 1.1920929e-7;\nconst TINY: real = 1e-30;\nconst BIG: real = 1e37;\n",
        Precision::F64 => "alias real = f64;\nconst EPS: real = 2.220446049250313e-16;\nconst TINY: real = 1e-300;\nconst BIG: real = 1e300;\n",
    };
    format!("{real}const WG: u32 = {WORKGROUP_SIZE}u;\n{TYPES_WGSL}")
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

/// `shaders/row.wgsl` for `precision`, after the prelude and the row's shape `constants`
/// ([`super::row::RowShape::wgsl_constants`]).
/// Every row kernel carries `yielding.wgsl`; its functions are entered only where the shape
/// has yielding storeys (`NS > 0`, a constant), so an elastic row's kernel compiles none of it.
pub fn row_source(precision: Precision, constants: &str) -> String {
    let slack = match precision {
        Precision::F64 => crate::physics::solver::row::yielding::YIELD_SLACK,
        Precision::F32 => super::row::F32_YIELD_SLACK,
    };
    format!(
        "{}{constants}const YIELD_SLACK: real = {slack:e};\n{CONTACT_WGSL}{HERMITE_WGSL}{ROW_WGSL}{YIELDING_WGSL}{LANES_WGSL}",
        prelude(precision)
    )
}

/// `shaders/aggregate.wgsl` for `precision`, after the prelude: with the sketch's bucket range
/// and the partials' layout, all from `aggregate` and `layout` (one source of truth).
pub fn aggregate_source(precision: Precision) -> String {
    use super::layout::{PART_R, PART_U, P_EXCEED, P_FAILURES, P_IMPACTS, P_POUNDED, P_RUNS};
    use crate::engine::aggregate::{
        BUCKETS, GAMMA, KMAX, KMIN, MAX_EXCEED, NOUT, SKETCH_MAX, SKETCH_MIN,
    };
    let inv_ln_g = 1.0 / GAMMA.ln();
    format!(
        "{}const NOUT: u32 = {NOUT}u;\nconst BUCKETS: u32 = {BUCKETS}u;\nconst KMIN: i32 = {KMIN}i;\nconst KMAX: i32 = {KMAX}i;\n\
         const SKETCH_MIN: real = {SKETCH_MIN:e};\nconst SKETCH_MAX: real = {SKETCH_MAX:e};\nconst INV_LN_G: f32 = {inv_ln_g:?};\n\
         const MAX_EXCEED: u32 = {MAX_EXCEED}u;\nconst PART_U: u32 = {PART_U}u;\nconst PART_R: u32 = {PART_R}u;\n\
         const P_RUNS: u32 = {P_RUNS}u;\nconst P_FAILURES: u32 = {P_FAILURES}u;\n\
         const P_POUNDED: u32 = {P_POUNDED}u;\nconst P_IMPACTS: u32 = {P_IMPACTS}u;\nconst P_EXCEED: u32 = {P_EXCEED}u;\n{AGGREGATE_WGSL}",
        prelude(precision)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every loop in the shaders ends after a count, as building them without naga's loop
    /// bounding requires (context.rs): no `while`, every `for` has a step, every `loop` leaves
    /// once its budget is spent and spends it each pass; the per-shape code the host writes
    /// has no loop at all.
    #[test]
    fn every_loop_counts() {
        let shape = super::super::row::RowShape::elastic(vec![3, 6], vec![[0, 0, 0], [0, 1, 1]]);
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

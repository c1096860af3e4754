//! Every struct shared with the WGSL shaders, one `#[repr(C)]` Pod type each, and the
//! workgroup/buffer-size arithmetic. The shaders' declarations of these structs are written from
//! the same field lists ([`Layout::wgsl`], put before the stages by `shader.rs`), so there is no
//! copy to keep in sync; `tests/it/gpu.rs` parses the assembled shaders with naga and checks
//! every size and offset against these types (WGSL's alignment rules against `repr(C)`'s).
//!
//! Structs of reals come in two precisions with the same fields (`...64` for f64, `...32` for
//! f32): the shader is compiled with `alias real = f64;` or `f32;` prepended. Each is all-real so
//! it has no padding in either precision; integer fields live in separate all-`u32` structs.

use bytemuck::{Pod, Zeroable};

/// Invocations per workgroup (`@workgroup_size` in the shader is substituted from this).
pub const WORKGROUP_SIZE: u32 = 64;

/// A struct shared with the shaders: its WGSL declaration, and its field names and byte offsets
/// for the layout test.
pub trait Layout {
    const NAME: &'static str;
    fn fields() -> Vec<(&'static str, usize)>;
    /// `struct NAME { field: type, ... }` as the shaders declare it, from the Rust field list.
    fn wgsl() -> String;
}

/// A field's type in WGSL: `real` (the prelude's alias for the kernel's precision) for the
/// reals of a `real_structs!` pair, `u32` and arrays of it for the integer structs.
pub trait WgslType {
    fn wgsl() -> String;
}

impl WgslType for u32 {
    fn wgsl() -> String {
        "u32".into()
    }
}

impl WgslType for f64 {
    fn wgsl() -> String {
        "real".into()
    }
}

impl WgslType for f32 {
    fn wgsl() -> String {
        "real".into()
    }
}

impl<const N: usize> WgslType for [u32; N] {
    fn wgsl() -> String {
        format!("array<u32, {N}>")
    }
}

/// The WGSL declaration of struct `name` with `fields` (name, WGSL type), one field a line.
fn wgsl_struct(name: &str, fields: &[(&str, String)]) -> String {
    let body: String = fields
        .iter()
        .map(|(f, ty)| format!("    {f}: {ty},\n"))
        .collect();
    format!("struct {name} {{\n{body}}}\n")
}

macro_rules! real_structs {
    ($(#[$doc:meta])* $name:literal, $n64:ident, $n32:ident { $($(#[$fdoc:meta])* $f:ident),* $(,)? }) => {
        $(#[$doc])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
        pub struct $n64 { $($(#[$fdoc])* pub $f: f64),* }

        /// f32 twin of the f64 struct of the same name.
        #[repr(C)]
        #[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
        pub struct $n32 { $(pub $f: f32),* }

        impl $n32 {
            pub fn from_f64(x: &$n64) -> Self {
                $n32 { $($f: x.$f as f32),* }
            }
            pub fn to_f64(&self) -> $n64 {
                $n64 { $($f: self.$f as f64),* }
            }
        }

        impl Layout for $n64 {
            const NAME: &'static str = $name;
            fn fields() -> Vec<(&'static str, usize)> {
                vec![$((stringify!($f), core::mem::offset_of!($n64, $f))),*]
            }
            fn wgsl() -> String {
                wgsl_struct($name, &[$((stringify!($f), <f64 as WgslType>::wgsl())),*])
            }
        }

        impl Layout for $n32 {
            const NAME: &'static str = $name;
            fn fields() -> Vec<(&'static str, usize)> {
                vec![$((stringify!($f), core::mem::offset_of!($n32, $f))),*]
            }
            fn wgsl() -> String {
                wgsl_struct($name, &[$((stringify!($f), <f32 as WgslType>::wgsl())),*])
            }
        }
    };
}

/// An all-`u32` struct shared with the shaders (so no padding the two sides could disagree on):
/// the `#[repr(C)]` Pod type and its [`Layout`], from one field list.
macro_rules! u32_struct {
    ($(#[$doc:meta])* $name:ident { $($(#[$fdoc:meta])* $f:ident: $ty:ty),* $(,)? }) => {
        $(#[$doc])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
        pub struct $name { $($(#[$fdoc])* pub $f: $ty),* }

        impl Layout for $name {
            const NAME: &'static str = stringify!($name);
            fn fields() -> Vec<(&'static str, usize)> {
                vec![$((stringify!($f), core::mem::offset_of!($name, $f))),*]
            }
            fn wgsl() -> String {
                wgsl_struct(Self::NAME, &[$((stringify!($f), <$ty as WgslType>::wgsl())),*])
            }
        }
    };
}

real_structs! {
    /// Per-run parameters, all precomputed on the host (no transcendentals in the shader).
    "Params", Params64, Params32 {
        m1, c1, k1, m2, c2, k2,
        /// m
        gap,
        /// `k` or `beta`
        stiffness,
        /// `c`, `c0` or Hunt-Crossley `a` (see `Contact::damping`)
        damping,
        damping_ratio,
        m_eff,
        /// Contact duration: `t_c = tc_coef` (linear laws) or `tc_coef v^(-1/5)` (Hertz-type).
        tc_coef,
        /// Record step and start, s; factor applied to the record's samples.
        dt, t0, scale,
        /// RK4 substeps per estimated contact duration.
        substeps_per_contact,
        /// Exact propagator of building 1 over `dt` (see `propagator::Propagator`).
        p1_uu, p1_uv, p1_ua0, p1_ua1, p1_vu, p1_vv, p1_va0, p1_va1,
        /// Same for building 2.
        p2_uu, p2_uv, p2_ua0, p2_ua1, p2_vu, p2_vv, p2_va0, p2_va1,
    }
}

real_structs! {
    /// Per-run integration state and running results; carried from one dispatch to the next.
    "State", State64, State32 {
        u1, v1, u2, v2,
        /// Contact work so far, J.
        w,
        /// Approach speed of the current impact.
        v0,
        /// Peak force of the current impact.
        imp_peak,
        /// Local time of the current impact's onset within its record interval.
        tau_onset,
        /// Local time reached within the current record interval.
        tau,
        peak_force, impact_velocity, peak_penetration, peak_u1, peak_u2,
        /// Valid when `impacts > 0`.
        first_impact,
        contact_time,
        dissipated,
        /// Input and structural damping work so far, and the largest input reached, J (the
        /// energy balance: `cpu::State` and `Tracker`).
        e_in, e_damp, e_peak,
        /// Each building's peak absolute acceleration, where the run tracks it (the `ACCEL`
        /// variant: a row of two one-storey buildings).
        peak_a1, peak_a2,
    }
}

u32_struct! {
    /// Per-run integers fixed for the sweep.
    Meta {
        /// `LAW_*` code.
        law: u32,
        /// First sample of the run's record in the records buffer.
        rec_offset: u32,
        /// Samples in the record.
        rec_len: u32,
        /// Record intervals to simulate (record plus tail).
        intervals: u32,
        /// First real of the run's shared free response in the `responses` buffer
        /// (`shared.rs`), or [`NO_RESPONSE`].
        response: u32,
    }
}

/// `Meta::response` of a run that steps its whole record.
pub const NO_RESPONSE: u32 = u32::MAX;

u32_struct! {
    /// Per-run integer state, carried between dispatches.
    Counters {
        /// `MODE_*`
        mode: u32,
        impacts: u32,
        /// `STATUS_*`; a run that is not `STATUS_OK` is not stepped again.
        status: u32,
        /// RK4 substeps taken so far.
        substeps: u32,
        /// Record interval of the current impact's onset.
        i_onset: u32,
        /// Current record interval.
        i: u32,
        /// Current RK4 substep of interval `i` (1..=m), 0 before the interval is started.
        j: u32,
        /// RK4 substeps of interval `i`.
        m: u32,
        /// Pieces (event cuts) taken in substep `j`.
        pieces: u32,
        /// Record intervals taken by the exact free step.
        free_steps: u32,
        /// Record intervals settled by the shared free response (skipped at the start, or at an
        /// early end).
        shared_steps: u32,
    }
}

u32_struct! {
    /// Uniforms of one dispatch: at most `budget` units of work (a free interval, or one piece of a
    /// substep) for each of the `nactive` runs listed in the dispatch's run-id buffer.
    Dispatch {
        budget: u32,
        nactive: u32,
        /// A record step needing more substeps ends the run with `STATUS_STEP_LIMIT`.
        max_substeps_per_step: u32,
        /// Substep budget of one run.
        max_substeps: u32,
        /// A record step needing more substeps ends the run with `STATUS_HANDOFF`.
        handoff_substeps_per_step: u32,
        _pad1: u32,
        _pad2: u32,
        _pad3: u32,
    }
}

// Codes shared with the shaders (`shader::shared_with_host` writes their WGSL `const`s; the row
// kernel gets `STATUS_COLLAPSE` with its shape constants).
pub const MODE_FREE: u32 = 0;
pub const MODE_APPROACH: u32 = 1;
pub const MODE_RESTITUTION: u32 = 2;
pub const STATUS_OK: u32 = 0;
pub const STATUS_NON_FINITE: u32 = 1;
pub const STATUS_STEP_LIMIT: u32 = 2;
/// The run needs more substeps per record step than the kernel's precision resolves; the host
/// finishes it on the CPU.
pub const STATUS_HANDOFF: u32 = 3;
/// The row kernel: a building's peak drift ratio reached the run's collapse limit. The kernel
/// has no collapse event; it ends the run there and the host runs it again on the CPU, which
/// locates the collapse (past the limit a P-Delta storey runs away, and its substeps per
/// record step grow with it).
pub const STATUS_COLLAPSE: u32 = 4;

/// Reals per run in the `forms` buffer: the exact free-step energy integrals
/// (`propagator::EnergyForms`) of building 1 (`vv`, then `agv`), then building 2. The shader's
/// `FORMS` constant comes from here (see `shader::fast_source`).
pub const FORMS_PER_RUN: usize = 40;

/// A run's `forms` entries.
pub fn forms(
    f1: &crate::physics::propagator::EnergyForms,
    f2: &crate::physics::propagator::EnergyForms,
) -> [f64; FORMS_PER_RUN] {
    let mut out = [0.0; FORMS_PER_RUN];
    for (k, c) in [f1.vv, f1.agv, f2.vv, f2.agv].iter().enumerate() {
        out[10 * k..10 * k + 10].copy_from_slice(c);
    }
    out
}

/// Workgroups for `n` runs.
pub fn workgroups(n: u32) -> u32 {
    n.div_ceil(WORKGROUP_SIZE)
}

/// Bytes of one `Params` at `precision`.
pub fn params_bytes(precision: super::precision::Precision) -> usize {
    core::mem::size_of::<Params64>() / 8 * precision.bytes()
}

/// Bytes of one `State` at `precision`.
pub fn state_bytes(precision: super::precision::Precision) -> usize {
    core::mem::size_of::<State64>() / 8 * precision.bytes()
}

u32_struct! {
    /// Settings of the aggregation stage (`shaders/aggregate.wgsl`), in a read-only storage buffer
    /// (a uniform array would need 16-byte strides).
    AggConfig {
        /// Segments in this dispatch.
        nseg: u32,
        /// `--exceed` thresholds in use (their values are in the `thresholds` buffer).
        nexceed: u32,
        _pad0: u32,
        _pad1: u32,
        /// Output index (`aggregate::OUTPUTS`) of each threshold.
        exceed_output: [u32; crate::engine::aggregate::MAX_EXCEED],
    }
}

u32_struct! {
    /// Consecutive runs of a chunk (in the order they were packed) that belong to one group; the
    /// stage folds each segment in one workgroup.
    Segment {
        /// First run (index into the chunk's buffers) and run count.
        start: u32,
        len: u32,
        /// The group's histogram slot in the `hist` buffer.
        slot: u32,
        _pad: u32,
    }
}

// A segment's partial counts: `PART_U` u32 words at these offsets (keep in sync with
// aggregate.wgsl, which gets PART_U and the P_* offsets from `shader::aggregate_source`).
pub const PART_U: usize = 16;
/// Runs folded (handed-back runs are not), of which failed.
pub const P_RUNS: usize = 0;
pub const P_FAILURES: usize = 1;
/// Runs with at least one impact, and their impacts.
pub const P_POUNDED: usize = 2;
pub const P_IMPACTS: usize = 3;
/// `MAX_EXCEED` exceedance counts from here.
pub const P_EXCEED: usize = 4;
/// A segment's reals: the max of each output, then the sum of each.
pub const PART_R: usize = 2 * crate::engine::aggregate::NOUT;
/// Longest segment: keeps each invocation's loop at `MAX_SEGMENT / WORKGROUP_SIZE` iterations,
/// far below lavapipe's loop limit (longer runs of one group are cut into several segments).
pub const MAX_SEGMENT: u32 = 1 << 16;
/// Histogram counters of one slot (one group): `NOUT` outputs of `BUCKETS` each.
pub const SLOT_WORDS: usize = crate::engine::aggregate::NOUT * crate::engine::aggregate::BUCKETS;

/// The partial of segment `k` from the read-back `part_u` words and `part_r` reals.
pub fn partial(part_u: &[u32], part_r: &[f64], k: usize) -> crate::engine::aggregate::Partial {
    use crate::engine::aggregate::{MAX_EXCEED, NOUT};
    let u = &part_u[k * PART_U..(k + 1) * PART_U];
    let r = &part_r[k * PART_R..(k + 1) * PART_R];
    let mut p = crate::engine::aggregate::Partial {
        runs: u[P_RUNS] as u64,
        failures: u[P_FAILURES] as u64,
        pounded: u[P_POUNDED] as u64,
        impacts: u[P_IMPACTS] as u64,
        ..Default::default()
    };
    for e in 0..MAX_EXCEED {
        p.exceed[e] = u[P_EXCEED + e] as u64;
    }
    p.max.copy_from_slice(&r[..NOUT]);
    p.sum.copy_from_slice(&r[NOUT..]);
    p
}

/// Workgroups for `n` segments, one each, as an `(x, y)` grid within `max_per_dim`.
pub fn segment_grid(n: u32, max_per_dim: u32) -> (u32, u32) {
    let x = n.clamp(1, max_per_dim);
    (x, n.div_ceil(x))
}

// Rust twin: src/engine/gpu/layout.rs (the #[repr(C)] Pod types and codes).
// Structs and codes shared by every stage (fast.wgsl, aggregate.wgsl); the host prepends this
// file after the precision prelude (src/engine/gpu/shader.rs). Keep in sync with the twin: the
// layout test parses each stage with naga and checks every size, offset and code against Rust.

struct Params {
    m1: real, c1: real, k1: real, m2: real, c2: real, k2: real,
    gap: real,
    stiffness: real,
    damping: real,
    damping_ratio: real,
    m_eff: real,
    tc_coef: real,
    dt: real, t0: real, scale: real,
    substeps_per_contact: real,
    p1_uu: real, p1_uv: real, p1_ua0: real, p1_ua1: real,
    p1_vu: real, p1_vv: real, p1_va0: real, p1_va1: real,
    p2_uu: real, p2_uv: real, p2_ua0: real, p2_ua1: real,
    p2_vu: real, p2_vv: real, p2_va0: real, p2_va1: real,
}

struct State {
    u1: real, v1: real, u2: real, v2: real,
    w: real,
    v0: real,
    imp_peak: real,
    tau_onset: real,
    tau: real,
    peak_force: real, impact_velocity: real, peak_penetration: real, peak_u1: real, peak_u2: real,
    first_impact: real,
    contact_time: real,
    dissipated: real,
    e_in: real, e_damp: real, e_peak: real,
    peak_a1: real, peak_a2: real,
}

struct Meta {
    law: u32,
    rec_offset: u32,
    rec_len: u32,
    intervals: u32,
    response: u32,
}

struct Counters {
    mode: u32,
    impacts: u32,
    status: u32,
    substeps: u32,
    i_onset: u32,
    i: u32,
    j: u32,
    m: u32,
    pieces: u32,
    free_steps: u32,
    shared_steps: u32,
}

// Run modes and statuses (the MODE_/STATUS_ constants in layout.rs).
const MODE_FREE: u32 = 0u;
const MODE_APPROACH: u32 = 1u;
const MODE_RESTITUTION: u32 = 2u;
const STATUS_OK: u32 = 0u;
const STATUS_NON_FINITE: u32 = 1u;
const STATUS_STEP_LIMIT: u32 = 2u;
const STATUS_HANDOFF: u32 = 3u;

// The uniform of a fast or row dispatch (layout::Dispatch).
struct Dispatch {
    budget: u32,
    nactive: u32,
    max_substeps_per_step: u32,
    max_substeps: u32,
    handoff_substeps_per_step: u32,
    _pad1: u32,
    _pad2: u32,
    _pad3: u32,
}

// Runs still integrating after this dispatch: their count, and their indices (in any order)
// for the next dispatch, which then launches only those. Packing the unfinished runs together
// keeps lanes busy: runs that pound for long are rare and spread over every workgroup.
// With them, the lane tally of the dispatch: loop trips that did work, summed over lanes, and
// the trips the lanes were held for (each workgroup's longest lane times WG). Their ratio is
// the lane utilisation.
struct Tally {
    active_runs: atomic<u32>,
    lane_units: atomic<u32>,
    lane_slots: atomic<u32>,
}

// A record interval: ground accelerations at its ends and its length.
struct Seg { a0: real, a1: real, dt: real }

// Settings of the fast scheme both integrating stages share (fast.wgsl, row.wgsl):
// fast::MAX_PIECES_PER_SUBSTEP, fast::SUSTAINED, and the event location's tolerance,
// iterations and bisections after them.
const MAX_PIECES_PER_SUBSTEP: u32 = 64u;
const SUSTAINED: real = 2.0;
const LOCATE_TOL: real = 1e-9;
const LOCATE_ITER: u32 = 16u;
const LOCATE_BISECT: u32 = 32u;

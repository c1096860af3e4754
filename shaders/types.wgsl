// Rust twin: src/physics/solver/fast.rs (the settings at the end).
// Shader-only structs and settings shared by every stage (fast.wgsl, row.wgsl, aggregate.wgsl).
// The host prepends this file after the precision prelude and the structs and codes it shares
// with the host (Params, State, Meta, Counters, Dispatch, the MODE_/STATUS_ codes), which it
// writes from their Rust definitions in layout.rs (src/engine/gpu/shader.rs). The layout test
// parses each stage with naga and checks every shared struct's size and offsets, and every
// setting, against Rust.

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

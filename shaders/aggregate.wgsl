// Rust twin: src/engine/aggregate.rs (Group::add, the host fold; host side in
// src/engine/gpu/reduce.rs).
// `--aggregate` on the device: folds the runs of a finished chunk into per-group summaries, so
// only kilobytes come back instead of a state per run. One workgroup per segment (consecutive
// runs of one group: the host packs each chunk sorted by group). Each invocation folds every
// WG-th run of the segment; counts meet in workgroup atomics, max and sum in a tree reduction,
// and each output's value bumps its bucket of the group's histogram slot with a global atomic
// (the slots live across chunks; the host reads them back when the sweep ends or the slots run
// out). The per-run body is the twin of `Group::add` in src/engine/aggregate.rs; `outputs` is the twin
// of `gpu::output`. Runs the fast stage handed back (STATUS_HANDOFF) are listed, not folded:
// the host finishes them on the CPU and folds them there.
//
// The host prepends the prelude (src/engine/gpu/shader.rs): `real`, WG, the structs and codes
// shared with the host, types.wgsl, the sketch and partial layout constants (NOUT, BUCKETS, KMIN, KMAX,
// SKETCH_MIN, SKETCH_MAX, INV_LN_G, MAX_EXCEED, PART_U, PART_R, P_*), and this stage's buffer
// structs AggConfig and Segment, all written from src/engine/gpu/layout.rs. The bucket's log is
// taken in f32 (lavapipe's f64 log is wrong): a value within f32 rounding of a bucket boundary
// may land one bucket over, which moves a quantile by at most one bucket's 2 %.

@group(0) @binding(0) var<storage, read> cfg: AggConfig;
@group(0) @binding(1) var<storage, read> thresholds: array<real>;
@group(0) @binding(2) var<storage, read> segments: array<Segment>;
@group(0) @binding(3) var<storage, read> states: array<State>;
@group(0) @binding(4) var<storage, read> counters: array<Counters>;
// Per segment: PART_U counts (P_* offsets) and PART_R reals (max of each output, then sums).
@group(0) @binding(5) var<storage, read_write> part_u: array<u32>;
@group(0) @binding(6) var<storage, read_write> part_r: array<real>;
// Per slot: NOUT histograms of BUCKETS counters.
@group(0) @binding(7) var<storage, read_write> hist: array<atomic<u32>>;
// [0]: how many runs were handed back; then their indices in the chunk.
@group(0) @binding(8) var<storage, read_write> handoffs: array<atomic<u32>>;

var<workgroup> w_count: array<atomic<u32>, PART_U>;
var<workgroup> w_max: array<array<real, NOUT>, WG>;
var<workgroup> w_sum: array<array<real, NOUT>, WG>;

// A run's summarised outputs, in aggregate::OUTPUTS order, as magnitudes (gpu::output: an
// impact still in progress at the end counts with its peak so far).
fn outputs(s: State, c: Counters) -> array<real, NOUT> {
    var peak_force = s.peak_force;
    var impact_velocity = s.impact_velocity;
    if (c.mode != MODE_FREE && s.imp_peak > peak_force) {
        peak_force = s.imp_peak;
        impact_velocity = s.v0;
    }
    return array<real, NOUT>(
        real(c.impacts), abs(peak_force), abs(s.peak_penetration), abs(s.peak_u1),
        abs(s.peak_u2), abs(impact_velocity), abs(s.contact_time), abs(s.dissipated),
    );
}

// aggregate::bucket
fn bucket(x: real) -> u32 {
    if (!(x >= SKETCH_MIN)) {
        return 0u;
    }
    let k = i32(ceil(log(f32(min(x, SKETCH_MAX))) * INV_LN_G));
    return u32(clamp(k, KMIN, KMAX) - KMIN + 1);
}

@compute @workgroup_size(WG)
fn main(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let s = wid.x + wid.y * nwg.x;
    // The same for the whole workgroup, so the barriers below stay in uniform control flow.
    if (s >= cfg.nseg) {
        return;
    }
    let seg = segments[s];
    var mx: array<real, NOUT>;
    var sm: array<real, NOUT>;
    for (var k = lid; k < seg.len; k = k + WG) {
        let i = seg.start + k;
        let c = counters[i];
        if (c.status == STATUS_HANDOFF) {
            let at = atomicAdd(&handoffs[0], 1u);
            atomicStore(&handoffs[1u + at], i);
            continue;
        }
        atomicAdd(&w_count[P_RUNS], 1u);
        if (c.status != STATUS_OK) {
            atomicAdd(&w_count[P_FAILURES], 1u);
            continue;
        }
        var x = outputs(states[i], c);
        if (c.impacts > 0u) {
            atomicAdd(&w_count[P_POUNDED], 1u);
        }
        atomicAdd(&w_count[P_IMPACTS], c.impacts);
        for (var e = 0u; e < cfg.nexceed; e = e + 1u) {
            if (x[cfg.exceed_output[e]] > thresholds[e]) {
                atomicAdd(&w_count[P_EXCEED + e], 1u);
            }
        }
        let base = seg.slot * NOUT * BUCKETS;
        for (var o = 0u; o < NOUT; o = o + 1u) {
            mx[o] = max(mx[o], x[o]);
            sm[o] = sm[o] + x[o];
            atomicAdd(&hist[base + o * BUCKETS + bucket(x[o])], 1u);
        }
    }
    w_max[lid] = mx;
    w_sum[lid] = sm;
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride = stride / 2u) {
        if (lid < stride) {
            for (var o = 0u; o < NOUT; o = o + 1u) {
                w_max[lid][o] = max(w_max[lid][o], w_max[lid + stride][o]);
                w_sum[lid][o] = w_sum[lid][o] + w_sum[lid + stride][o];
            }
        }
        workgroupBarrier();
    }
    if (lid < PART_U) {
        part_u[s * PART_U + lid] = atomicLoad(&w_count[lid]);
    }
    if (lid < NOUT) {
        part_r[s * PART_R + lid] = w_max[0][lid];
        part_r[s * PART_R + NOUT + lid] = w_sum[0][lid];
    }
}

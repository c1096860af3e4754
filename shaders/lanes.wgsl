// The entry point of both integrating stages (fast.wgsl, row.wgsl), appended after the stage,
// which defines `integrate_run(lane) -> u32` (the units of work its lane did): one invocation
// per active run, and the dispatch's lane tally (see `Tally` in types.wgsl).

var<workgroup> longest_lane: atomic<u32>;

@compute @workgroup_size(WG)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let units = integrate_run(gid.x);
    if (units > 0u) {
        atomicAdd(&tally.lane_units, units);
        atomicMax(&longest_lane, units);
    }
    workgroupBarrier();
    if (lid == 0u) {
        atomicAdd(&tally.lane_slots, atomicLoad(&longest_lane) * WG);
    }
}

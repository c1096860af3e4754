// Rust twin: src/physics/solver/row/fast.rs (with row/mod.rs), function for function (same
// names, same operation order), except that the CPU takes the contact substeps of buildings of
// 4 or more storeys with Rayleigh damping in floor coordinates (the same motion, O(N) per
// right-hand side) where this kernel stays in modes, and that the CPU lets the buildings no
// contact reaches stand still through a step's substeps and steps them exactly at its end
// where this kernel substeps the whole row (the CPU's `simulate_whole_row` is this kernel's
// twin step for step). The fast scheme on a row of shear buildings, in modal coordinates,
// one invocation per run; resumable as fast.wgsl (at most `disp.budget` units of work per run
// and dispatch: a record interval's start with its free step, or one RK4 step of a substep's
// piece (its trial, a probe of a hidden touch or of the event search, the step to the event),
// the units that end a free step or a piece then tracking it in code they all share, so that a
// unit's loop trips stay those of about one RK4 step and one tracking, however long the search).
//
// The host prepends the prelude, then the row's shape (src/engine/gpu/row/shape.rs, `RowShape`,
// written out by row/wgsl.rs): NB buildings, NM modes in all, NL contact levels (NLA = max(NL, 1) sizes their arrays), ZLEN
// reals of state, MAXN the most storeys; each building's storeys and first mode (B_N, B_OFF);
// each level's left building and floors (L_A, L_FA, L_FB); the offsets and strides of the
// per-run blocks (P_*, M_*, S_*, C_*, LS_*, LC_*, BS_*, BC_*, MW); then the functions that run
// over the shape (the right-hand side `rhs`, each level's gap `delta`, rate `ddelta`, bound
// `level_bound` and `structural_rel_accel`, the floors' `fill`, a storey's drift and the
// plastic loads, `collapse_reached`), written out with constant indices
// where the row is small (`RowShape::unrolled`: a lane's state stays in registers, where lavapipe
// turns an index known only at run time into a loop over the lanes), else row_loops.wgsl's
// loops. Then contact.wgsl and hermite.wgsl. So a kernel carries exactly the code its row needs.
//
// The state z is [q (NM), q' (NM), w (one per level), e_in, e_damp, then each yielding storey's
// plastic drift and plastic work], as on the CPU; this kernel does not integrate the energy
// balance (the host refuses to ask for it), so e_in and e_damp stay 0. Yielding storeys
// (yielding.wgsl) enter where `NS > 0`, a constant.

alias ZA = array<real, ZLEN>;

@group(0) @binding(0) var<uniform> disp: Dispatch;
// Per run: P_STRIDE reals (record and contact settings, gaps, each level's contact), M_STRIDE
// u32 (law, record, each building's model block).
@group(0) @binding(1) var<storage, read> rparams: array<real>;
@group(0) @binding(2) var<storage, read> rmeta: array<u32>;
@group(0) @binding(3) var<storage, read> records: array<real>;
// Per run: S_STRIDE reals and C_STRIDE u32 that persist between dispatches.
@group(0) @binding(4) var<storage, read_write> rstate: array<real>;
@group(0) @binding(5) var<storage, read_write> rcount: array<u32>;
@group(0) @binding(6) var<storage, read_write> tally: Tally;
@group(0) @binding(7) var<storage, read> run_ids: array<u32>;
@group(0) @binding(8) var<storage, read_write> next_ids: array<u32>;
// Building models, shared by the runs that use them: per mode MW reals (w^2, 2 xi w, the
// participation, the 8 propagator coefficients), the mode shapes (floor-major), floor masses
// and storey heights.
@group(0) @binding(9) var<storage, read> models: array<real>;

const TWO_PI: real = 6.283185307179586;

// This invocation's run: where its blocks start, and what it reads most.
var<private> RP: u32;
var<private> RS: u32;
var<private> RC: u32;
var<private> MB: array<u32, NB>;
var<private> W2: array<real, NM>;
var<private> TXW: array<real, NM>;
var<private> PART: array<real, NM>;
var<private> LMODE: array<u32, NLA>;
var<private> LV0: array<real, NLA>;
// Each level's event fires in the step being located (RowRun::firing).
var<private> LFIRE: array<bool, NLA>;

// events.rs `Locator`: the event search in a step from (TAU, z), kept between units of work,
// and the piece's steps before it. phase: LOC_IDLE (a new piece is due), LOC_ESTIMATE (an
// estimate is due), LOC_GUARD (the probe `guard` is due), LOC_HIDDEN (the probe `guard` of a
// touch hidden inside the trial of length b), LOC_RETAKE (the trial of length b is accepted: no
// touch was hidden); last: the side the last estimate moved (1: b, -1: a, 0: none yet).
struct Locator {
    a: real,
    fa: real,
    b: real,
    fb: real,
    tol: real,
    guard: real,
    phase: u32,
    it: u32,
    last: i32,
}

const LOC_IDLE: u32 = 0u;
const LOC_ESTIMATE: u32 = 1u;
const LOC_GUARD: u32 = 2u;
const LOC_HIDDEN: u32 = 3u;
const LOC_RETAKE: u32 = 4u;

// What a unit of work ends with (run_unit): nothing to track, a free record step, an accepted
// piece, a piece ended at a located event.
const END_NONE: u32 = 0u;
const END_FREE: u32 = 1u;
const END_STEP: u32 = 2u;
const END_EVENT: u32 = 3u;
// An event fires at the step's end: substep_unit starts the search over it.
const END_SEARCH: u32 = 4u;

var<private> LOC: Locator;
var<private> LAW: u32;
var<private> REC_OFF: u32;
var<private> REC_LEN: u32;
var<private> INTERVALS: u32;
var<private> DT: real;
var<private> T0: real;
var<private> SCALE: real;
var<private> PER_CONTACT: real;
var<private> RATE: real;
// Counters: the interval i, substep j of m, pieces of this substep, local time in the interval.
var<private> CI: u32;
var<private> CJ: u32;
var<private> CM: u32;
var<private> PIECES: u32;
var<private> SUBSTEPS: u32;
var<private> FREE_STEPS: u32;
var<private> STATUS: u32;
var<private> TAU: real;
// Floor kinematics at the two ends of the last tracked piece (row/mod.rs `Floors`): quantity q
// (u, v, relative and absolute acceleration, jerk) of floor j of building b at end e is
// FL[(5 e + q) NM + B_OFF[b] + j]. ENDS_VALID: end 1 describes the state in the current modes,
// so the next piece starts from it (never across dispatches: recomputing gives the same bits).
var<private> FL: array<real, FLEN>;
var<private> ENDS_VALID: bool;
// The contact force on each floor (positive to the right).
var<private> FF: array<real, NM>;

fn sample(i: u32) -> real {
    if (i < REC_LEN) {
        return records[REC_OFF + i] * SCALE;
    }
    return 0.0;
}

// Segment::at, at local time tau of the interval.
fn seg_at(seg: Seg, tau: real) -> real {
    return seg.a0 + (seg.a1 - seg.a0) * (tau / seg.dt);
}

fn rp(k: u32) -> real {
    return rparams[RP + k];
}

// The contact element of level l into K (contact.wgsl).
fn use_level(l: u32) {
    let b = RP + P_LEVELS + LEVEL_PARAMS * l;
    K = Law(LAW, rparams[b], rparams[b + 1u], rp(P_RATIO), rparams[b + 2u], rparams[b + 3u]);
}

fn shape_at(b: u32, j: u32, i: u32) -> real {
    let n = B_N[b];
    return models[MB[b] + MW * n + j * n + i];
}

fn mass_at(b: u32, j: u32) -> real {
    let n = B_N[b];
    return models[MB[b] + MW * n + n * n + j];
}

fn height_at(b: u32, j: u32) -> real {
    let n = B_N[b];
    return models[MB[b] + MW * n + n * n + n + j];
}

// Level l's reals and u32 in the run's blocks.
fn lsi(l: u32, f: u32) -> u32 {
    return RS + S_LEVELS + LS_STRIDE * l + f;
}

fn lci(l: u32, f: u32) -> u32 {
    return RC + C_LEVELS + LC_STRIDE * l + f;
}

fn fli(e: u32, q: u32, k: u32) -> u32 {
    return (5u * e + q) * NM + k;
}

// ---- row/mod.rs: LevelModel ----

// delta(l, z) and ddelta(l, z), level l's gap and its rate, are written out per shape by the
// host (RowShape::wgsl_unrolled).

// structural_rel_accel(l, z), the structural relative acceleration of level l's floors (no
// ground, no contact), is written out per shape by the host (RowShape::wgsl_unrolled).

// Each level's gap and rate at the start (D0, R0) and the end (D1, R1) of a substep unit's RK4
// step, computed once (`level_ends`) and read by its event values, the probe of a hidden touch,
// the transitions and the tracking: a dozen places, and a lavapipe group runs every one any of
// its lanes reaches. The same values, so the same bits. A record interval's start sets them
// for its exact free step (D0 and R0 alone where a level is in contact).
var<private> D0: array<real, NLA>;
// Per level on a struck column (by L_CI) over the tracked piece: its force and rate at both
// ends, a bound on |F|, and whether the piece begins at the touch or ends at the separation.
var<private> CLOAD: array<array<real, 4>, NCA>;
var<private> CBOUND: array<real, NCA>;
var<private> CTOUCH: array<bool, NCA>;
var<private> R0: array<real, NLA>;
var<private> D1: array<real, NLA>;
var<private> R1: array<real, NLA>;

fn level_ends(z0: ptr<function, ZA>, z1: ptr<function, ZA>) {
    level_starts(z0);
    for (var l = 0u; l < NL; l++) {
        D1[l] = delta(l, z1);
        R1[l] = ddelta(l, z1);
    }
    if (NS > 0u) {
        storey_ends(z0, z1);
    }
}

fn level_starts(z0: ptr<function, ZA>) {
    for (var l = 0u; l < NL; l++) {
        D0[l] = delta(l, z0);
        R0[l] = ddelta(l, z0);
    }
}

// Level l's contact force in `mode` at gap d and rate r.
fn force_of(l: u32, mode: u32, v0: real, d: real, r: real) -> real {
    if (mode == MODE_FREE) {
        return 0.0;
    }
    use_level(l);
    return contact_force(d, r, v0, mode == MODE_APPROACH);
}

fn force(l: u32, mode: u32, v0: real, z: ptr<function, ZA>) -> real {
    if (mode == MODE_FREE) {
        return 0.0;
    }
    return force_of(l, mode, v0, delta(l, z), ddelta(l, z));
}

// Level l's event value in `mode` at gap d and rate r.
fn event_value(l: u32, mode: u32, v0: real, d: real, r: real) -> real {
    use_level(l);
    let g = gauge(d, r, v0);
    switch mode {
        case MODE_FREE: { return g; }
        case MODE_APPROACH: { return -r; }
        default: {
            if (force_depends_on_phase()) {
                return max(-g, r);
            }
            return -g;
        }
    }
}

// LevelModel::reapproaches: a restitution that closes again (r: the gap's rate).
fn reapproaches(mode: u32, r: real) -> bool {
    return mode == MODE_RESTITUTION && r > 0.0;
}

// Each mode's fourth-derivative bound over the free step being tried (QB), which every
// level's bound sums over its two floors (`level_bound`, written out per shape by the host):
// once per mode, not per level and floor (the same values).
var<private> QB: array<real, NM>;

fn fill_mode_bounds(seg: Seg, z0: ptr<function, ZA>, z1: ptr<function, ZA>) {
    for (var k = 0u; k < NM; k++) {
        if (NS > 0u || COUPLED) {
            // mode_bounds: about the static response to the plastic loads, coupled modes'.
            QB[k] = MBND[k];
            continue;
        }
        let sk = Seg(seg.a0 * PART[k], seg.a1 * PART[k], seg.dt);
        let q = max(abs((*z0)[k]), abs((*z1)[k]));
        let qd = max(abs((*z0)[NM + k]), abs((*z1)[NM + k]));
        QB[k] = fourth_derivative_bound(1.0, W2[k], TXW[k], q, qd, sk);
    }
}

// Level l over the exact free step of length h whose ends' gaps and rates are in D0, R0, D1, R1.
fn may_touch(l: u32, h: real, v0: real) -> bool {
    let d0 = D0[l];
    let d1 = D1[l];
    let r0 = R0[l];
    let r1 = R1[l];
    let bound = level_bound(l);
    let margin = -error_margin(bound, h);
    if (cubic_max_bound(d0, r0, d1, r1, h) <= margin) {
        return false;
    }
    use_level(l);
    if (gauge(d0, r0, v0) > 0.0 || gauge(d1, r1, v0) > 0.0) {
        return true;
    }
    return hermite_range(d0, r0, d1, r1, h).hi > margin;
}

// row::rhs (the force on each floor, the modes' accelerations) is written out per shape by
// the host (RowShape::wgsl_unrolled), with load_shape_rows.

// fast.rs `rk4`: classic RK4 over h from local time tau, into `out`.
fn rk4(seg: Seg, tau: real, z: ptr<function, ZA>, h: real, out: ptr<function, ZA>) {
    let ag0 = seg_at(seg, tau);
    let agm = seg_at(seg, tau + 0.5 * h);
    let ag1 = seg_at(seg, tau + h);
    var k1: ZA;
    var k2: ZA;
    var k3: ZA;
    var k4: ZA;
    var y: ZA;
    rhs(ag0, z, &k1);
    for (var i = 0u; i < ZLEN; i++) { y[i] = (*z)[i] + 0.5 * h * k1[i]; }
    rhs(agm, &y, &k2);
    for (var i = 0u; i < ZLEN; i++) { y[i] = (*z)[i] + 0.5 * h * k2[i]; }
    rhs(agm, &y, &k3);
    for (var i = 0u; i < ZLEN; i++) { y[i] = (*z)[i] + h * k3[i]; }
    rhs(ag1, &y, &k4);
    for (var i = 0u; i < ZLEN; i++) {
        (*out)[i] = (*z)[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

// Each level's event value at the end of the unit's RK4 step (EV) and at its start (EV0), as
// each yielding storey's (SEV, SEV0): computed once per unit and read by event_max,
// firing_max, mark_firing and transitions, eight places a lavapipe group would otherwise
// evaluate them at. The same values, so the same bits.
var<private> EV: array<real, NLA>;
var<private> EV0: array<real, NLA>;

// The events' values in z: the step's start (EV0, from D0 and R0) where `start`, else its end
// (EV, from D1 and R1).
fn event_values(z: ptr<function, ZA>, start: bool) {
    for (var l = 0u; l < NL; l++) {
        if (start) {
            EV0[l] = event_value(l, LMODE[l], LV0[l], D0[l], R0[l]);
        } else {
            EV[l] = event_value(l, LMODE[l], LV0[l], D1[l], R1[l]);
        }
    }
    if (NS > 0u) {
        storey_event_values(z, start);
    }
}

// RowRun::event_max at the step's end: the largest of the levels' and storeys' event values.
fn event_max() -> real {
    var m = -BIG;
    for (var l = 0u; l < NL; l++) {
        m = max(m, EV[l]);
    }
    if (NS > 0u) {
        m = storey_event_max(m);
    }
    return m;
}

// RowRun::firing_max at the step's start (`start`) or end: the largest event value of the
// events that fire in the step's trial (LFIRE, SFIRE), the function an event is located on.
fn firing_max(start: bool) -> real {
    var m = -BIG;
    for (var l = 0u; l < NL; l++) {
        if (LFIRE[l]) {
            m = max(m, select(EV[l], EV0[l], start));
        }
    }
    if (NS > 0u) {
        m = storey_firing_max(m, start);
    }
    return m;
}

// RowRun::mark_firing: the events whose value is positive at the step's end.
fn mark_firing() {
    for (var l = 0u; l < NL; l++) {
        LFIRE[l] = EV[l] > 0.0;
    }
    if (NS > 0u) {
        storey_mark_firing();
    }
}

// ---- Modes::coupling: damping that couples a building's modes (P-Delta, Rayleigh on K0) ----

// Does building b's damping couple its modes in this run? Its block's coupled part (where the
// shape lets it couple, B_CP) starts with 1 where it does; COUPLED (a constant) leaves the
// loops out of every other kernel.
fn coupled(b: u32) -> bool {
    return COUPLED && B_CP[b] != 0u && models[MB[b] + B_CP[b]] != 0.0;
}

// E[i][k] of building b.
fn cpl_e(b: u32, i: u32, k: u32) -> real {
    return models[MB[b] + B_CP[b] + 1u + B_N[b] * i + k];
}

// (E x)_i of building b, x its modes of z from offset `at` (NM: the velocities).
fn coupled_term(b: u32, i: u32, z: ptr<function, ZA>, at: u32) -> real {
    var s: real = 0.0;
    let o = at + B_OFF[b];
    for (var k = 0u; k < B_N[b]; k++) {
        s += cpl_e(b, i, k) * (*z)[o + k];
    }
    return s;
}

// CoupledStep::step over a record step: building b's modes of z (about QS where storeys
// yield) into z1, the ground from seg.a0 to seg.a1; the host packed the exact step over DT.
fn coupled_step(b: u32, seg: Seg, z: ptr<function, ZA>, z1: ptr<function, ZA>) {
    let n = B_N[b];
    let o = B_OFF[b];
    let n2 = 2u * n;
    let at = MB[b] + B_CP[b] + 1u + n * n;
    for (var i = 0u; i < n2; i++) {
        var x: real = 0.0;
        for (var j = 0u; j < n2; j++) {
            var x0: real;
            if (j < n) {
                x0 = (*z)[o + j];
                if (NS > 0u) {
                    x0 = x0 - QS[o + j];
                }
            } else {
                x0 = (*z)[NM + o + j - n];
            }
            x += models[at + n2 * i + j] * x0;
        }
        x = x + models[at + n2 * n2 + i] * seg.a0 + models[at + n2 * n2 + n2 + i] * seg.a1;
        if (i < n) {
            if (NS > 0u) {
                x = x + QS[o + i];
            }
            (*z1)[o + i] = x;
        } else {
            (*z1)[NM + o + i - n] = x;
        }
    }
}

// RowModel::fourth_derivative_bounds into MBND over the free step z0 -> z1: each mode's
// |q''''| bound (about QS where storeys yield; QS stays 0 in a kernel without), and where
// damping couples a building's modes, each bound's terms gain the coupling's, at most
// sum_k |E_ik| (coupling_sums) times the largest of the other modes'.
fn mode_bounds(seg: Seg, z0: ptr<function, ZA>, z1: ptr<function, ZA>) {
    for (var k = 0u; k < NM; k++) {
        MBND[k] = shifted_mode_bound(k, seg, z0, z1);
    }
    if (!COUPLED) {
        return;
    }
    for (var b = 0u; b < NB; b++) {
        if (!coupled(b)) {
            continue;
        }
        let o = B_OFF[b];
        let n = B_N[b];
        var sums: array<real, MAXN>;
        var a2: array<real, MAXN>;
        var vm: real = 0.0;
        for (var i = 0u; i < n; i++) {
            var c: real = 0.0;
            for (var j = 0u; j < n; j++) {
                c += abs(cpl_e(b, i, j));
            }
            sums[i] = c;
            vm = max(vm, max(abs((*z0)[NM + o + i]), abs((*z1)[NM + o + i])));
        }
        var a2m: real = 0.0;
        for (var i = 0u; i < n; i++) {
            let k = o + i;
            let q = max(abs((*z0)[k] - QS[k]), abs((*z1)[k] - QS[k]));
            let v = max(abs((*z0)[NM + k]), abs((*z1)[NM + k]));
            a2[i] = W2[k] * q + TXW[k] * v + max(abs(PART[k] * seg.a0), abs(PART[k] * seg.a1)) + sums[i] * vm;
            a2m = max(a2m, a2[i]);
        }
        var a3: array<real, MAXN>;
        var a3m: real = 0.0;
        for (var i = 0u; i < n; i++) {
            let k = o + i;
            let v = max(abs((*z0)[NM + k]), abs((*z1)[NM + k]));
            a3[i] = W2[k] * v + TXW[k] * a2[i] + abs(PART[k] * (seg.a1 - seg.a0) / seg.dt) + sums[i] * a2m;
            a3m = max(a3m, a3[i]);
        }
        for (var i = 0u; i < n; i++) {
            let k = o + i;
            MBND[k] = W2[k] * a2[i] + TXW[k] * a3[i] + sums[i] * a3m;
        }
    }
}

// ---- row/mod.rs: RowRun ----

// physics/row.rs LevelSide::at: quantity q at end e (FL) of a level's side on building b,
// floor f (from 0), weight w: the floor's, or on a column its storey's floors' by their shares
// (the ground's 0).
fn side_fl(e: u32, q: u32, b: u32, f: u32, w: real) -> real {
    let top = FL[fli(e, q, B_OFF[b] + f)];
    if (w == 1.0) {
        return top;
    }
    var below: real = 0.0;
    if (f > 0u) {
        below = FL[fli(e, q, B_OFF[b] + f - 1u)];
    }
    return w * top + (1.0 - w) * below;
}

// A force on a column's point reaches its storey's floors by the same shares (LevelSide::shares).
fn spread_on_column(b: u32, f: u32, w: real, force: real) {
    if (f > 0u) {
        FF[B_OFF[b] + f - 1u] += (1.0 - w) * force;
    }
    FF[B_OFF[b] + f] += w * force;
}

// The contact forces on the floors (FF) at the start (`start`) or end of the unit's step, from
// its levels' gaps and rates (D0, R0, D1, R1).
fn set_floor_forces(start: bool) {
    for (var k = 0u; k < NM; k++) { FF[k] = 0.0; }
    for (var l = 0u; l < NL; l++) {
        if (LMODE[l] == MODE_FREE) {
            continue;
        }
        let f = force_of(l, LMODE[l], LV0[l], select(D1[l], D0[l], start), select(R1[l], R0[l], start));
        let a = L_A[l];
        if (HAS_COLUMNS && L_CS[l] < 2u) {
            spread_on_column(a, L_FA[l], L_WA[l], -f);
            spread_on_column(a + 1u, L_FB[l], L_WB[l], f);
            continue;
        }
        FF[B_OFF[a] + L_FA[l]] -= f;
        FF[B_OFF[a + 1u] + L_FB[l]] += f;
    }
}

// Floors::fill of building b at end e from z at ground acceleration ag, with FF set, is
// written out per shape by the host (RowShape::wgsl_unrolled).

fn raise(free: bool, peak: real, y0: real, y1: real, d0: real, d1: real, a0: real, a1: real, h: real) -> real {
    if (free) {
        return raise_quintic_peak(peak, y0, y1, d0, d1, a0, a1, h);
    }
    return raise_cubic_peak(peak, y0, d0, y1, d1, h);
}

// The floors at the end of the last piece become those at the start of the next.
fn copy_floor_ends() {
    for (var x = 0u; x < 5u * NM; x++) { FL[x] = FL[5u * NM + x]; }
}

// track_buildings(z0, z1, ag0, ag1, h), RowRun::track_buildings (each building's peaks over a
// piece), is written out per shape by the host (`RowShape::wgsl_unrolled`), or taken as loops
// from row_loops.wgsl for rows too tall.

// Time since level l's impact began, at local time tau of the current interval.
fn since_onset(l: u32, tau: real) -> real {
    return real(CI - rcount[lci(l, LC_I_ONSET)]) * DT + (tau - rstate[lsi(l, LS_TAU_ONSET)]);
}

// RowRun::track: a piece tau0 -> tau0 + h from z0 to z1 in the current modes (a contact
// level's gaps and rates at its ends in D0, R0, D1, R1).
fn track(tau0: real, h: real, z0: ptr<function, ZA>, z1: ptr<function, ZA>, ag0: real, ag1: real) {
    track_buildings(z0, z1, ag0, ag1, h);
    ENDS_VALID = true;
    for (var l = 0u; l < NL; l++) {
        let mode = LMODE[l];
        if (mode == MODE_FREE) {
            continue;
        }
        rstate[lsi(l, LS_CONTACT_TIME)] += h;
        let y0 = D0[l];
        let d0 = R0[l];
        let y1 = D1[l];
        let d1 = R1[l];
        let pen = rstate[lsi(l, LS_PENETRATION)];
        if (cubic_max_bound(y0, d0, y1, d1, h) > pen) {
            rstate[lsi(l, LS_PENETRATION)] = max(pen, hermite_range(y0, d0, y1, d1, h).hi);
        }
        rstate[lsi(l, LS_DISSIPATED)] = (*z1)[2u * NM + l];
        // The force's rates from the floors' relative accelerations at both ends (FL, with
        // the contact forces of these modes).
        let a = L_A[l];
        let accel0 = side_fl(0u, 2u, a, L_FA[l], L_WA[l]) - side_fl(0u, 2u, a + 1u, L_FB[l], L_WB[l]);
        let accel1 = side_fl(1u, 2u, a, L_FA[l], L_WA[l]) - side_fl(1u, 2u, a + 1u, L_FB[l], L_WB[l]);
        let approaching = mode == MODE_APPROACH;
        let v0 = LV0[l];
        let f = force_of(l, mode, v0, y1, d1);
        let r1 = contact_force_rate(y1, d1, accel1, v0, approaching);
        // The start's force and rate where the force's peak or a struck column needs them.
        let column = HAS_COLUMNS && L_CS[l] < 2u;
        var f0: real = 0.0;
        var r0: real = 0.0;
        if (r1 < 0.0 || column) {
            f0 = force_of(l, mode, v0, y0, d0);
            r0 = contact_force_rate(y0, d0, accel0, v0, approaching);
        }
        rstate[lsi(l, LS_IMP_PEAK)] = raise_force_peak(rstate[lsi(l, LS_IMP_PEAK)], f0, r0, f, r1, h);
        if (column) {
            let ci = L_CI[l];
            CLOAD[ci] = array<real, 4>(f0, r0, f, r1);
            var bound = max(abs(f0), abs(f));
            if (r1 < 0.0 && r0 > 0.0) {
                bound = max(bound, hermite_range(f0, r0, f, r1, h).hi);
            }
            CBOUND[ci] = bound;
            CTOUCH[ci] = y0 <= 0.0 || y1 <= 0.0;
        }
    }
    if (HAS_COLUMNS) {
        for (var l = 0u; l < NL; l++) {
            if (L_CS[l] < 2u && LMODE[l] != MODE_FREE) {
                track_column(l, z0, z1, h);
            }
        }
    }
}

// row/outputs.rs raise_column_peak: `peak` raised to the largest |V + L| over a contact piece
// (L the contact forces' shares on a column segment), the ends and the hump's cubic held
// within max |V| + load_bound.
fn raise_column_peak(peak: real, v0: real, vr0: real, v1: real, vr1: real, l0: real, lr0: real, l1: real, lr1: real, load_bound: real, touches: bool, h: real) -> real {
    let y0 = v0 + l0;
    let y1 = v1 + l1;
    let ends = max(peak, max(abs(y0), abs(y1)));
    if (touches) {
        return ends;
    }
    let hump = raise_hump_peak(ends, y0, vr0 + lr0, y1, vr1 + lr1, h);
    if (hump <= ends) {
        return ends;
    }
    let bound = raise_cubic_peak(0.0, v0, vr0, v1, vr1, h) + load_bound;
    return max(ends, min(hump, bound));
}

// Level l's struck building and storey (its side's floor above the point, from 0).
fn struck_storey(l: u32) -> vec2<u32> {
    if (L_CS[l] == 1u) {
        return vec2<u32>(L_A[l] + 1u, L_FB[l]);
    }
    return vec2<u32>(L_A[l], L_FA[l]);
}

// Level l's weight s on its struck side and the sign of its force on the struck building.
fn struck_weight(l: u32) -> vec2<real> {
    if (L_CS[l] == 1u) {
        return vec2<real>(L_WB[l], 1.0);
    }
    return vec2<real>(L_WA[l], -1.0);
}

// Level m is in contact on the columns of storey `at` (building, storey).
fn strikes(m: u32, at: vec2<u32>) -> bool {
    return L_CS[m] < 2u && LMODE[m] != MODE_FREE && all(struck_storey(m) == at);
}

// `peak` raised by the column segment of storey `at` below the points whose weight is at least
// `cut_s` (2: the segment above every point): `V + sum_i w_i F_i`, `w_i = 1 - s_i` below point
// i, `-s_i` above it, each force signed onto the struck building.
fn column_segment(peak: real, at: vec2<u32>, cut_s: real, v0: real, vr0: real, v1: real, vr1: real, touches: bool, h: real) -> real {
    var load = array<real, 4>(0.0, 0.0, 0.0, 0.0);
    var bound: real = 0.0;
    for (var m = 0u; m < NL; m++) {
        if (!strikes(m, at)) {
            continue;
        }
        let sw = struck_weight(m);
        var share = -sw.x;
        if (sw.x >= cut_s) {
            share = 1.0 - sw.x;
        }
        share = sw.y * share;
        let f = CLOAD[L_CI[m]];
        for (var i = 0u; i < 4u; i++) {
            load[i] += share * f[i];
        }
        bound += abs(share) * CBOUND[L_CI[m]];
    }
    return raise_column_peak(peak, v0, vr0, v1, vr1, load[0], load[1], load[2], load[3], bound, touches, h);
}

// RowRun::track_columns (row/outputs.rs): the largest shear of the struck storey's column
// segments over a contact piece, its spring force `V` with the shares of every contact force
// on that storey's columns at once (above every point `V - sum s_i F_i`, below point k `F_i`
// more for each point at or above it), by the hump's cubic, or at the piece's ends alone where
// one of them begins at the touch or ends at the separation (the force's rate unbounded there).
fn track_column(l: u32, z0: ptr<function, ZA>, z1: ptr<function, ZA>, h: real) {
    let at = struck_storey(l);
    let b = at.x;
    let j = at.y;
    let k = rp(P_COLUMNS + L_CI[l]);
    let o = B_OFF[b];
    var drift: array<real, 2>;
    var rate: array<real, 2>;
    for (var e = 0u; e < 2u; e++) {
        drift[e] = FL[fli(e, 0u, o + j)];
        rate[e] = FL[fli(e, 1u, o + j)];
        if (j > 0u) {
            drift[e] -= FL[fli(e, 0u, o + j - 1u)];
            rate[e] -= FL[fli(e, 1u, o + j - 1u)];
        }
    }
    var spring = array<real, 2>(k * drift[0], k * drift[1]);
    var spring_rate = array<real, 2>(k * rate[0], k * rate[1]);
    if (NS > 0u && B_S0[b] < NS) {
        let s = B_S0[b] + j;
        var pv = array<real, 2>(0.0, 0.0);
        if (SM[s] != SM_ELASTIC) {
            pv[0] = (1.0 - st_b(s)) * rate[0]; // !IMK
            pv[1] = (1.0 - st_b(s)) * rate[1]; // !IMK
            pv[0] = storey_flow(s) * rate[0]; // IMK
            pv[1] = storey_flow(s) * rate[1]; // IMK
        }
        spring[0] = k * (drift[0] - (*z0)[PS0 + s]);
        spring[1] = k * (drift[1] - (*z1)[PS0 + s]);
        spring_rate[0] = k * (rate[0] - pv[0]);
        spring_rate[1] = k * (rate[1] - pv[1]);
    }
    var touches = false;
    for (var m = 0u; m < NL; m++) {
        if (strikes(m, at)) {
            touches = touches || CTOUCH[L_CI[m]];
        }
    }
    // The segment above every point, then the one below each point.
    var peak = column_segment(rstate[lsi(l, LS_COLUMN_SHEAR)], at, 2.0, spring[0], spring_rate[0], spring[1], spring_rate[1], touches, h);
    for (var cut = 0u; cut < NL; cut++) {
        if (strikes(cut, at)) {
            peak = column_segment(peak, at, struck_weight(cut).x, spring[0], spring_rate[0], spring[1], spring_rate[1], touches, h);
        }
    }
    rstate[lsi(l, LS_COLUMN_SHEAR)] = peak;
}

fn onset(l: u32, tau: real, v0: real, f: real) {
    let impacts = rcount[lci(l, LC_IMPACTS)] + 1u;
    rcount[lci(l, LC_IMPACTS)] = impacts;
    if (impacts == 1u) {
        rstate[lsi(l, LS_FIRST_IMPACT)] = T0 + real(CI) * DT + tau;
    }
    LV0[l] = v0;
    rstate[lsi(l, LS_TAU_ONSET)] = tau;
    rcount[lci(l, LC_I_ONSET)] = CI;
    rstate[lsi(l, LS_IMP_PEAK)] = max(f, 0.0);
}

fn end_impact(l: u32) {
    let imp = rstate[lsi(l, LS_IMP_PEAK)];
    if (imp > rstate[lsi(l, LS_PEAK_FORCE)]) {
        rstate[lsi(l, LS_PEAK_FORCE)] = imp;
        rstate[lsi(l, LS_IMPACT_VELOCITY)] = LV0[l];
    }
}

// RowRun::transitions at state z, the end of the unit's step (local time tau; its event values
// in EV, the levels' gaps and rates at both ends in D0, R0, D1, R1).
fn transitions(tau: real) {
    for (var l = 0u; l < NL; l++) {
        let mode = LMODE[l];
        let v0 = LV0[l];
        if (EV[l] <= 0.0) {
            if (reapproaches(mode, R1[l])) {
                LMODE[l] = MODE_APPROACH;
                ENDS_VALID = false;
            }
            continue;
        }
        ENDS_VALID = false;
        if (mode == MODE_FREE) {
            // events::touch
            let r = R1[l];
            var nv0 = v0;
            if (D0[l] <= 0.0 || v0 <= 0.0) {
                nv0 = abs(r);
            }
            nv0 = max(nv0, 1e-12);
            var next = MODE_RESTITUTION;
            if (r > 0.0) { next = MODE_APPROACH; }
            let f = force_of(l, next, nv0, D1[l], r);
            onset(l, tau, nv0, f);
            LMODE[l] = next;
        } else if (mode == MODE_APPROACH) {
            LMODE[l] = MODE_RESTITUTION;
        } else if (reapproaches(mode, R1[l])) {
            // Closing again: the same impact goes on.
            LMODE[l] = MODE_APPROACH;
        } else {
            end_impact(l);
            LMODE[l] = MODE_FREE;
        }
    }
}

// Locator::next: the length to probe next, or -1 once the bracket is closed.
fn locator_next() -> real {
    if (LOC.phase == LOC_GUARD) {
        return LOC.guard;
    }
    let a = LOC.a;
    let b = LOC.b;
    if (LOC.it >= LOCATE_ITER + LOCATE_BISECT || b - a <= LOC.tol) {
        return -1.0;
    }
    var x = 0.5 * (a + b);
    if (LOC.it < LOCATE_ITER && LOC.fb != LOC.fa) {
        x = b - LOC.fb * (b - a) / (LOC.fb - LOC.fa);
    }
    if (!(x > a && x < b)) {
        x = 0.5 * (a + b);
    }
    return x;
}

// Locator::take: the event value fx at the probe x; regula falsi (Illinois), each estimate
// followed by a guard probe, then bisections (events::locate).
fn locator_take(x: real, fx: real) {
    let fires = fx > 0.0;
    if (LOC.phase == LOC_GUARD) {
        if (fires) {
            LOC.b = x; LOC.fb = fx;
        } else {
            LOC.a = x; LOC.fa = fx;
        }
        LOC.it = LOC.it + 1u;
        LOC.phase = LOC_ESTIMATE;
        return;
    }
    var g: real;
    if (fires) {
        LOC.b = x; LOC.fb = fx;
        if (LOC.last == 1) { LOC.fa = LOC.fa * 0.5; }
        LOC.last = 1;
        g = x - 0.5 * LOC.tol;
    } else {
        LOC.a = x; LOC.fa = fx;
        if (LOC.last == -1) { LOC.fb = LOC.fb * 0.5; }
        LOC.last = -1;
        g = x + 0.5 * LOC.tol;
    }
    if (LOC.it < LOCATE_ITER && g > LOC.a && g < LOC.b) {
        LOC.guard = g;
        LOC.phase = LOC_GUARD;
    } else {
        LOC.it = LOC.it + 1u;
    }
}

// RowRun::accept, step by step: each of its RK4 steps from (TAU, z) is a unit of work (the
// trial, the probe of a hidden touch, the trial re-taken, each probe of the event search, the
// step to its far end); substep_unit takes the step `step_length` gives and `step_taken` says
// what it means.

// The event search over the step of length h from z0 whose end has events firing (event value
// f1 > 0; RowRun::accept's `locate`). substep_unit calls it at one place for the trial and the
// probe of a hidden touch, so that lavapipe evaluates the events at z0 once.
fn start_search(h: real, f1: real, z0: ptr<function, ZA>) {
    mark_firing();
    event_values(z0, true);
    let f0 = firing_max(true);
    let tol = max(LOCATE_TOL * h, 4.0 * EPS * DT);
    LOC = Locator(0.0, min(f0, 0.0), h, f1, tol, 0.0, LOC_ESTIMATE, 0u, 0);
}

// The trial of length h from z0 ended at `trial` (its event values in EV): an event inside
// starts the search; a touch hidden inside a free level (or a storey's yield) is probed next;
// else the step is accepted.
fn trial_taken(h: real, trial: ptr<function, ZA>, z0: ptr<function, ZA>) -> u32 {
    if (event_max() > 0.0) {
        return END_SEARCH;
    }
    // The earliest touch hidden inside the step at a free level.
    var best: real = -1.0;
    for (var l = 0u; l < NL; l++) {
        if (LMODE[l] != MODE_FREE) {
            continue;
        }
        let s = hidden_rise(D0[l], R0[l], D1[l], R1[l], h);
        if (s >= 0.0 && (best < 0.0 || s < best)) {
            best = s;
        }
    }
    if (NS > 0u) {
        best = hidden_yield(z0, trial, h, best);
    }
    if (best >= 0.0) {
        LOC.b = h;
        LOC.guard = best * h;
        LOC.phase = LOC_HIDDEN;
        return END_NONE;
    }
    return END_STEP;
}

// The length of this unit's RK4 step from (TAU, z) in a search or probe; `last` is set where
// it is the step to the search's far end.
fn step_length(last: ptr<function, bool>) -> real {
    *last = false;
    switch LOC.phase {
        case LOC_HIDDEN: { return LOC.guard; }
        case LOC_RETAKE: { return LOC.b; }
        default: {
            let x = locator_next();
            if (x >= 0.0) {
                return x;
            }
            *last = true;
            return LOC.b;
        }
    }
}

// What the step of length x (not the trial; its end's event values in EV) means for the
// piece's phase.
fn step_taken(x: real, last: bool) -> u32 {
    switch LOC.phase {
        case LOC_HIDDEN: {
            if (event_max() > 0.0) {
                return END_SEARCH;
            }
            LOC.phase = LOC_RETAKE;
            return END_NONE;
        }
        case LOC_RETAKE: { return END_STEP; }
        default: {
            if (last) {
                return END_EVENT;
            }
            locator_take(x, firing_max(false));
            return END_NONE;
        }
    }
}

fn finite(z: ptr<function, ZA>) -> bool {
    // abs(x) <= BIG is false for NaN and for +-inf.
    for (var i = 0u; i < 2u * NM + NL; i++) {
        if (!(abs((*z)[i]) <= BIG)) {
            return false;
        }
    }
    return true;
}

// ---- fast.rs `run`, loop body ----

// The substep a contact level asks for to stay stable at penetration d_est (K set to it).
fn h_rate_of(d_est: real, v0: real) -> real {
    return TWO_PI / PER_CONTACT / max(local_rate(2.0 * d_est, v0), RATE);
}

// The start of the current record interval: its exact step with the modal propagators into z1,
// taken (true; run_unit tracks it) where no level can touch inside, else its M RK4 substeps
// set up.
fn begin_interval(seg: Seg, z: ptr<function, ZA>, z1: ptr<function, ZA>) -> bool {
    let dt = DT;
    var h = TWO_PI / PER_CONTACT / RATE;
    var contact = false;
    for (var l = 0u; l < NL; l++) {
        contact = contact || LMODE[l] != MODE_FREE;
    }
    if (!contact) {
        // Yielding storeys: the step is exact about the static response to the plastic loads.
        if (NS > 0u) {
            static_offsets(z);
        }
        *z1 = *z;
        for (var b = 0u; b < NB; b++) {
            if (coupled(b)) {
                coupled_step(b, seg, z, z1);
                continue;
            }
            for (var i = 0u; i < B_N[b]; i++) {
                let k = B_OFF[b] + i;
                let c = MB[b] + MW * i + 3u;
                let a0 = PART[k] * seg.a0;
                let a1 = PART[k] * seg.a1;
                var u = (*z)[k];
                if (NS > 0u) {
                    u = u - QS[k];
                }
                let v = (*z)[NM + k];
                (*z1)[k] = models[c] * u + models[c + 1u] * v + models[c + 2u] * a0 + models[c + 3u] * a1;
                if (NS > 0u) {
                    (*z1)[k] = (*z1)[k] + QS[k];
                }
                (*z1)[NM + k] = models[c + 4u] * u + models[c + 5u] * v + models[c + 6u] * a0
                    + models[c + 7u] * a1;
            }
        }
        level_ends(z, z1);
        // A storey that yields, or may in the free step, takes the step in substeps.
        if (NS > 0u || COUPLED) {
            mode_bounds(seg, z, z1);
        }
        var yielding = false;
        if (NS > 0u) {
            yielding = yield_watch(z, z1, dt);
        }
        fill_mode_bounds(seg, z, z1);
        var touching = false;
        for (var l = 0u; l < NL; l++) {
            if (!may_touch(l, dt, LV0[l])) {
                continue;
            }
            touching = true;
            let v_est = 1.5 * max(abs(R0[l]), abs(R1[l]));
            let d_est = max(D0[l], D1[l]);
            let a_est = max(abs(structural_rel_accel(l, z)), abs(structural_rel_accel(l, z1)));
            use_level(l);
            h = min(h, min(impact_step(v_est, a_est, PER_CONTACT), h_rate_of(d_est, LV0[l])));
        }
        if (!touching && !yielding) {
            // The free step: run_unit tracks it.
            return true;
        }
    } else {
        level_starts(z);
        for (var l = 0u; l < NL; l++) {
            let d = D0[l];
            let r = R0[l];
            let a = abs(structural_rel_accel(l, z));
            use_level(l);
            if (LMODE[l] == MODE_FREE) {
                // A free level beside a contact: size for its touch if it could close within
                // the step at its present rate.
                if (d + 2.0 * max(r, 0.0) * dt > 0.0) {
                    h = min(h, impact_step(1.5 * abs(r), a, PER_CONTACT));
                }
                continue;
            }
            let v0 = LV0[l];
            let h_rate = h_rate_of(d, v0);
            if (since_onset(l, 0.0) > SUSTAINED * duration_estimate(v0)) {
                h = min(h, h_rate);
            } else {
                h = min(h, min(impact_step(max(v0, abs(r)), a, PER_CONTACT), h_rate));
            }
        }
    }
    let mf = max(ceil(dt / h), 1.0);
    if (!(mf <= real(disp.max_substeps_per_step))) {
        STATUS = STATUS_STEP_LIMIT;
    } else if (mf > real(disp.handoff_substeps_per_step)) {
        // More substeps than this precision resolves: the host finishes the run on the CPU.
        STATUS = STATUS_HANDOFF;
    } else {
        CM = u32(mf);
        CJ = 1u;
        PIECES = 0u;
        TAU = 0.0;
    }
    return false;
}

fn end_substep(tau_target: real) {
    TAU = tau_target;
    CJ = CJ + 1u;
    PIECES = 0u;
    if (CJ > CM) {
        CJ = 0u;
        CI = CI + 1u;
    }
}

// One unit of substep j of the current interval (as fast.wgsl `piece`): a new piece's trial
// or one of its later steps, from (TAU, z) into zx over *x; returns what it ends with. Both
// take their RK4 step at one call, so that a SIMD group whose lanes take both (lavapipe runs
// every branch any lane takes) runs RK4 once.
fn substep_unit(seg: Seg, z: ptr<function, ZA>, zx: ptr<function, ZA>, x: ptr<function, real>) -> u32 {
    let searching = LOC.phase != LOC_IDLE;
    var last = false;
    var h: real;
    if (searching) {
        h = step_length(&last);
    } else {
        let tau_target = substep_target();
        let tol = substep_tol();
        if (!(tau_target - TAU > tol)) {
            end_substep(tau_target);
            return END_NONE;
        }
        SUBSTEPS = SUBSTEPS + 1u;
        // Cut at the graded mesh after a touch (RowRun::onset_cut); such pieces do not count
        // against the cap on event cuts.
        h = tau_target - TAU;
        for (var l = 0u; l < NL; l++) {
            if (LMODE[l] == MODE_APPROACH) {
                use_level(l);
                h = min(h, onset_cut(since_onset(l, TAU), LV0[l], PER_CONTACT, tol));
            }
        }
        if (h == tau_target - TAU) {
            PIECES = PIECES + 1u;
        }
        if (SUBSTEPS > disp.max_substeps || PIECES > MAX_PIECES_PER_SUBSTEP) {
            STATUS = STATUS_STEP_LIMIT;
            return END_NONE;
        }
    }
    *x = h;
    rk4(seg, TAU, z, h, zx);
    level_ends(z, zx);
    event_values(zx, false);
    var end: u32;
    if (searching) {
        end = step_taken(h, last);
    } else {
        end = trial_taken(h, zx, z);
    }
    if (end == END_SEARCH) {
        start_search(h, event_max(), z);
        return END_NONE;
    }
    return end;
}

// The local time substep j of M ends at (the record step's end for the last).
fn substep_target() -> real {
    if (CJ < CM) {
        return real(CJ) * (DT / real(CM));
    }
    return DT;
}

// How close to its target a substep counts as ended.
fn substep_tol() -> real {
    return max(LOCATE_TOL * (DT / real(CM)), 4.0 * EPS * DT);
}

// The end of a piece that advanced to TAU with state z: ends its substep once at the target.
fn end_piece(z: ptr<function, ZA>) {
    let tau_target = substep_target();
    if (!finite(z)) {
        STATUS = STATUS_NON_FINITE;
    } else if (!(tau_target - TAU > substep_tol())) {
        end_substep(tau_target);
    }
}

// One unit of work of the run from (TAU, z) (CJ == 0: the start of a record interval, else a
// step of a substep's piece), then what it ends with: the buildings' and levels' tracking
// over it, shared by every kind of unit, and the events' transitions.
fn run_unit(seg: Seg, z: ptr<function, ZA>) {
    var zx: ZA;
    var x: real = DT;
    var tau0: real = 0.0;
    var ag0 = seg.a0;
    var ag1 = seg.a1;
    var end = END_NONE;
    if (CJ == 0u) {
        if (begin_interval(seg, z, &zx)) {
            end = END_FREE;
        }
    } else {
        end = substep_unit(seg, z, &zx, &x);
        tau0 = TAU;
        ag0 = seg_at(seg, TAU);
        ag1 = seg_at(seg, TAU + x);
    }
    if (end == END_NONE) {
        return;
    }
    track(tau0, x, z, &zx, ag0, ag1);
    if (end == END_FREE) {
        FREE_STEPS = FREE_STEPS + 1u;
        *z = zx;
        if (!finite(z)) {
            STATUS = STATUS_NON_FINITE;
        }
        CI = CI + 1u;
        return;
    }
    if (end == END_EVENT) {
        transitions(TAU + x);
        if (NS > 0u) {
            storey_transitions(&zx);
        }
    } else {
        // A level whose phase is not an event (the law's force does not depend on it).
        for (var l = 0u; l < NL; l++) {
            if (reapproaches(LMODE[l], R1[l])) {
                LMODE[l] = MODE_APPROACH;
                ENDS_VALID = false;
            }
        }
    }
    LOC.phase = LOC_IDLE;
    TAU = TAU + x;
    *z = zx;
    end_piece(z);
}

// Has the run ended? At the record's end, or with yielding storeys once it settled
// (yielding::next_segment) or its settling time ran out.
fn ended() -> bool {
    if (NS == 0u) {
        return CI >= INTERVALS;
    }
    return CI >= INTERVALS && (SETTLED != 0u || CI >= END);
}

// The run's event search from its blocks, and back.
fn load_locator() {
    let s = RS + S_LOCATE;
    let c = RC + C_LOCATE;
    LOC = Locator(rstate[s], rstate[s + 1u], rstate[s + 2u], rstate[s + 3u], rstate[s + 4u],
        rstate[s + 5u], rcount[c], rcount[c + 1u], bitcast<i32>(rcount[c + 2u]));
}

fn store_locator() {
    let s = RS + S_LOCATE;
    let c = RC + C_LOCATE;
    rstate[s] = LOC.a;
    rstate[s + 1u] = LOC.fa;
    rstate[s + 2u] = LOC.b;
    rstate[s + 3u] = LOC.fb;
    rstate[s + 4u] = LOC.tol;
    rstate[s + 5u] = LOC.guard;
    rcount[c] = LOC.phase;
    rcount[c + 1u] = LOC.it;
    rcount[c + 2u] = bitcast<u32>(LOC.last);
}

// One lane's work in a dispatch: at most disp.budget units of run run_ids[lane]; returns the
// units it did.
fn integrate_run(lane: u32) -> u32 {
    if (lane >= disp.nactive) {
        return 0u;
    }
    let r = run_ids[lane];
    RC = r * C_STRIDE;
    let rm = r * M_STRIDE;
    STATUS = rcount[RC + C_STATUS];
    CI = rcount[RC + C_I];
    INTERVALS = rmeta[rm + M_INTERVALS];
    if (NS > 0u) {
        load_storeys(rm);
    }
    if (STATUS != STATUS_OK || ended()) {
        return 0u;
    }
    RP = r * P_STRIDE;
    RS = r * S_STRIDE;
    LAW = rmeta[rm + M_LAW];
    REC_OFF = rmeta[rm + M_REC_OFFSET];
    REC_LEN = rmeta[rm + M_REC_LEN];
    DT = rp(P_DT);
    T0 = rp(P_T0);
    SCALE = rp(P_SCALE);
    PER_CONTACT = rp(P_PER_CONTACT);
    RATE = rp(P_RATE);
    for (var b = 0u; b < NB; b++) {
        let mb = rmeta[rm + M_MODELS + b];
        MB[b] = mb;
        for (var i = 0u; i < B_N[b]; i++) {
            let k = B_OFF[b] + i;
            W2[k] = models[mb + MW * i];
            TXW[k] = models[mb + MW * i + 1u];
            PART[k] = models[mb + MW * i + 2u];
        }
    }
    load_shape_rows();
    for (var l = 0u; l < NL; l++) {
        LMODE[l] = rcount[lci(l, LC_MODE)];
        LV0[l] = rstate[lsi(l, LS_V0)];
        LFIRE[l] = rcount[lci(l, LC_FIRE)] != 0u;
    }
    load_locator();
    CJ = rcount[RC + C_J];
    CM = rcount[RC + C_M];
    PIECES = rcount[RC + C_PIECES];
    SUBSTEPS = rcount[RC + C_SUBSTEPS];
    FREE_STEPS = rcount[RC + C_FREE_STEPS];
    TAU = rstate[RS + S_TAU];
    imk_begin(); // IMK
    ENDS_VALID = false;
    var z: ZA;
    for (var i = 0u; i < ZLEN; i++) { z[i] = rstate[RS + i]; }
    var budget = disp.budget;
    loop {
        // After the record, a run with yielding storeys ends once none can yield again.
        if (NS > 0u && STATUS == STATUS_OK && CI >= INTERVALS && SETTLED == 0u
            && LOC.phase == LOC_IDLE && settles(&z)) {
            SETTLED = 1u;
        }
        if (STATUS != STATUS_OK || ended() || budget == 0u) {
            break;
        }
        budget = budget - 1u;
        var seg = Seg(sample(CI), sample(CI + 1u), DT);
        if (NS > 0u && CI >= INTERVALS) {
            // The settling tail: free vibration, the ground at rest.
            seg = Seg(0.0, 0.0, DT);
        }
        run_unit(seg, &z);
        // No collapse event here: a run whose building's peak drift ratio reached the limit
        // ends, and the host runs it again on the CPU. Past the limit a P-Delta storey runs
        // away, its contacts stiffen and its substeps per record step grow with it (in f64
        // such a run did not finish in 300 s on lavapipe).
        if (STATUS == STATUS_OK && collapse_reached()) {
            STATUS = STATUS_COLLAPSE;
        }
    }
    for (var i = 0u; i < ZLEN; i++) { rstate[RS + i] = z[i]; }
    rstate[RS + S_TAU] = TAU;
    for (var l = 0u; l < NL; l++) {
        rcount[lci(l, LC_MODE)] = LMODE[l];
        rstate[lsi(l, LS_V0)] = LV0[l];
        rcount[lci(l, LC_FIRE)] = u32(LFIRE[l]);
    }
    store_locator();
    rcount[RC + C_STATUS] = STATUS;
    rcount[RC + C_I] = CI;
    rcount[RC + C_J] = CJ;
    rcount[RC + C_M] = CM;
    rcount[RC + C_PIECES] = PIECES;
    rcount[RC + C_SUBSTEPS] = SUBSTEPS;
    rcount[RC + C_FREE_STEPS] = FREE_STEPS;
    if (NS > 0u) {
        store_storeys();
    }
    if (STATUS == STATUS_OK && !ended()) {
        next_ids[atomicAdd(&tally.active_runs, 1u)] = r;
    }
    return disp.budget - budget;
}

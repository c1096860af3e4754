// Rust twin: src/physics/solver/row/{storey,yielding}.rs (StoreyModel, the RowModel and RowRun parts
// of yielding storeys, and their steps in fast.rs), function for function, in modes only (as
// row.wgsl). Yielding storeys in the row kernel (physics.md section 8): storey s is a bilinear
// spring with kinematic hardening, force k (d - p), band |d - p / (1 - b)| <= d_y; while
// every storey is in its band, free steps are exact about the static response to the plastic
// loads; a storey that yields, or may reach its band edge, moves its row in substeps, yield
// onset and unloading located as events.
//
// Every row kernel carries this file; row.wgsl enters its functions only where NS > 0 (a
// constant), so an elastic row's kernel compiles none of it. The host's constants: NS storeys
// (NSA = max(NS, 1) sizes their arrays), each one's building and storey (S_B, S_J), each
// building's first (B_S0, NS where elastic), PS0 the slot of the first plastic drift (each
// storey's plastic work NS slots later), YIELD_SLACK per precision. Each yielding building's
// model block ends with its storeys' STOREY_HEAD reals (k, d_y, b, P / h) and modal rows.

const SM_ELASTIC: u32 = 0u;
const SM_UP: u32 = 1u;
const SM_DOWN: u32 = 2u;

// Each storey's spring state (StoreyMode), and whether the run has settled.
var<private> SM: array<u32, NSA>;
// Each storey's event fires in the step being located (RowRun::firing).
var<private> SFIRE: array<bool, NSA>;
var<private> SETTLED: u32;
// The last record step of a run that has not settled (yielding::settle_intervals).
var<private> END: u32;
// The static modal response to the plastic loads, and each mode's |q''''| bound about it,
// over the free step being tried (mode_bounds; QS stays 0 in a kernel without storeys).
var<private> QS: array<real, NM>;
var<private> MBND: array<real, NM>;
// A yielding building's plastic loads on its modes and their rates (Floors::plastic).
var<private> PLA: array<real, MAXN>;
var<private> PLJ: array<real, MAXN>;

fn st_at(s: u32, f: u32) -> real {
    let b = S_B[s];
    let n = B_N[b];
    return models[MB[b] + (MW + 2u) * n + n * n + (STOREY_HEAD + n) * S_J[s] + f];
}

fn st_k(s: u32) -> real { return st_at(s, 0u); }
fn st_dy(s: u32) -> real { return st_at(s, 1u); }
fn st_b(s: u32) -> real { return st_at(s, 2u); }
// Its geometric stiffness P / h (0 without P-Delta).
fn st_geo(s: u32) -> real { return st_at(s, 3u); }
fn st_row(s: u32, i: u32) -> real { return st_at(s, STOREY_HEAD + i); }

// StoreyModel::drift(s, z, at), the drift (at 0) or its rate (at NM) in state z, is written out
// per shape by the host (RowShape::wgsl_unrolled), as is row::plastic_rhs.

fn back_drift(s: u32, d: real, p: real) -> real {
    return d - p / (1.0 - st_b(s));
}

fn mode_sign(mode: u32) -> real {
    return select(real(-1.0), real(1.0), mode == SM_UP);
}

// StoreyModel::event_value: positive once `mode` must end.
fn storey_event(s: u32, mode: u32, d: real, r: real, p: real) -> real {
    if (IS_IMK[s]) { return imk_event(s, d, r); } // IMK
    if (mode == SM_ELASTIC) {
        return abs(back_drift(s, d, p)) - st_dy(s) * (1.0 + YIELD_SLACK);
    }
    return -mode_sign(mode) * r;
}

// Each storey's event value at the unit's step end (SEV) and start (SEV0), beside the levels'
// (row.wgsl's EV, EV0); its drift and drift rate at the step's start (SD0, SR0) and end (SD1,
// SR1), beside the levels' gaps and rates (`level_ends`, which calls storey_ends).
var<private> SEV: array<real, NSA>;
var<private> SEV0: array<real, NSA>;
var<private> SD0: array<real, NSA>;
var<private> SR0: array<real, NSA>;
var<private> SD1: array<real, NSA>;
var<private> SR1: array<real, NSA>;

fn storey_ends(z0: ptr<function, ZA>, z1: ptr<function, ZA>) {
    for (var s = 0u; s < NS; s++) {
        SD0[s] = storey_drift(s, z0, 0u);
        SR0[s] = storey_drift(s, z0, NM);
        SD1[s] = storey_drift(s, z1, 0u);
        SR1[s] = storey_drift(s, z1, NM);
    }
}

// The storeys' part of event_values: in z, the step's start where `start`, else its end.
fn storey_event_values(z: ptr<function, ZA>, start: bool) {
    for (var s = 0u; s < NS; s++) {
        let e = storey_event(s, SM[s], select(SD1[s], SD0[s], start), select(SR1[s], SR0[s], start),
            (*z)[PS0 + s]);
        if (start) {
            SEV0[s] = e;
        } else {
            SEV[s] = e;
        }
    }
}

// The storeys' part of RowRun::event_max, from `m` (the levels').
fn storey_event_max(m_in: real) -> real {
    var m = m_in;
    for (var s = 0u; s < NS; s++) {
        m = max(m, SEV[s]);
    }
    return m;
}

// The storeys' part of RowRun::firing_max, from `m` (the levels').
fn storey_firing_max(m_in: real, start: bool) -> real {
    var m = m_in;
    for (var s = 0u; s < NS; s++) {
        if (SFIRE[s]) {
            m = max(m, select(SEV[s], SEV0[s], start));
        }
    }
    return m;
}

// The storeys' part of RowRun::mark_firing.
fn storey_mark_firing() {
    for (var s = 0u; s < NS; s++) {
        SFIRE[s] = SEV[s] > 0.0;
    }
}

// RowModel::add_plastic for building b into PLA and PLJ (its modes from 0).
fn plastic_loads(b: u32, z: ptr<function, ZA>) {
    let n = B_N[b];
    for (var i = 0u; i < n; i++) {
        PLA[i] = 0.0;
        PLJ[i] = 0.0;
    }
    for (var s = B_S0[b]; s < B_S0[b] + n; s++) {
        let k = st_k(s);
        let kp = k * (*z)[PS0 + s];
        var kdp: real = 0.0;
        if (SM[s] != SM_ELASTIC) {
            kdp = k * (1.0 - st_b(s)) * storey_drift(s, z, NM); // !IMK
            kdp = k * storey_flow(s) * storey_drift(s, z, NM); // IMK
        }
        for (var i = 0u; i < n; i++) {
            let r = st_row(s, i);
            PLA[i] += r * kp;
            PLJ[i] += r * kdp;
        }
    }
}

// RowModel::static_offsets of state z into QS.
fn static_offsets(z: ptr<function, ZA>) {
    for (var k = 0u; k < NM; k++) {
        QS[k] = 0.0;
    }
    for (var s = 0u; s < NS; s++) {
        let kp = st_k(s) * (*z)[PS0 + s];
        if (kp == 0.0) {
            continue;
        }
        let o = B_OFF[S_B[s]];
        for (var i = 0u; i < B_N[S_B[s]]; i++) {
            QS[o + i] += st_row(s, i) * kp / W2[o + i];
        }
    }
}

// Mode k's |q''''| bound over the free step z0 -> z1 about its static response
// (RowModel::fourth_derivative_bounds).
fn shifted_mode_bound(k: u32, seg: Seg, z0: ptr<function, ZA>, z1: ptr<function, ZA>) -> real {
    let sk = Seg(seg.a0 * PART[k], seg.a1 * PART[k], seg.dt);
    let q = max(abs((*z0)[k] - QS[k]), abs((*z1)[k] - QS[k]));
    let qd = max(abs((*z0)[NM + k]), abs((*z1)[NM + k]));
    return fourth_derivative_bound(1.0, W2[k], TXW[k], q, qd, sk);
}

// StoreyModel::may_yield: could the elastic storey s reach a bounding line inside a free
// step of length h (drift and rate d0, r0 -> d1, r1, plastic drift p, |d''''| <= bound)?
fn may_yield(s: u32, d0: real, r0: real, d1: real, r1: real, p: real, bound: real, h: real) -> bool {
    let margin = -error_margin(bound, h);
    let dy = st_dy(s) * (1.0 + YIELD_SLACK);
    let s0 = back_drift(s, d0, p);
    let s1 = back_drift(s, d1, p);
    for (var e = 0u; e < 2u; e++) {
        let sg = select(real(-1.0), real(1.0), e == 0u);
        let a0 = sg * s0 - dy;
        let a1 = sg * s1 - dy;
        let ar0 = sg * r0;
        let ar1 = sg * r1;
        if (cubic_max_bound(a0, ar0, a1, ar1, h) > margin
            && (a0 > 0.0 || a1 > 0.0 || hermite_range(a0, ar0, a1, ar1, h).hi > margin)) {
            return true;
        }
    }
    return false;
}

// RowModel::yield_watch over the exact free step z0 -> z1 of length h (QS and, by
// mode_bounds, MBND set; the storeys' drifts at its ends in SD0, SR0, SD1, SR1): does a storey
// yield now, or may it reach a bounding line?
fn yield_watch(z0: ptr<function, ZA>, z1: ptr<function, ZA>, h: real) -> bool {
    var watch = false;
    for (var s = 0u; s < NS; s++) {
        if (SM[s] != SM_ELASTIC) {
            watch = true;
            break;
        }
        let o = B_OFF[S_B[s]];
        var bound: real = 0.0;
        for (var i = 0u; i < B_N[S_B[s]]; i++) {
            bound += abs(st_row(s, i)) * MBND[o + i];
        }
        if (IS_IMK[s]) { if (imk_may_reach(s, SD0[s], SR0[s], SD1[s], SR1[s], bound, h)) { watch = true; break; } continue; } // IMK
        if (may_yield(s, SD0[s], SR0[s], SD1[s], SR1[s], (*z0)[PS0 + s], bound, h)) {
            watch = true;
            break;
        }
    }
    return watch;
}

// RowRun::hidden_yield: the earliest fraction of the step z0 -> z1 (length h; the storeys'
// drifts at its ends in SD0, SR0, SD1, SR1) at which an elastic storey's back drift could rise
// past its band between the ends, from `best` (-1: none yet).
fn hidden_yield(z0: ptr<function, ZA>, z1: ptr<function, ZA>, h: real, best_in: real) -> real {
    var best = best_in;
    for (var s = 0u; s < NS; s++) {
        if (IS_IMK[s]) { best = imk_hidden(s, h, best); continue; } // IMK
        if (SM[s] != SM_ELASTIC) {
            continue;
        }
        let dy = st_dy(s) * (1.0 + YIELD_SLACK);
        let s0 = back_drift(s, SD0[s], (*z0)[PS0 + s]);
        let s1 = back_drift(s, SD1[s], (*z1)[PS0 + s]);
        let r0 = SR0[s];
        let r1 = SR1[s];
        for (var e = 0u; e < 2u; e++) {
            let sg = select(real(-1.0), real(1.0), e == 0u);
            let x = hidden_rise(sg * s0 - dy, sg * r0, sg * s1 - dy, sg * r1, h);
            if (x >= 0.0 && (best < 0.0 || x < best)) {
                best = x;
            }
        }
    }
    return best;
}

// RowRun::storey_transitions at state z, the end of the unit's step (the storeys' drifts there
// in SD1, SR1): yield onset on a bounding line when moving outwards, unloading when the drift
// rate reverses; a storey that reached its line already turning back takes the return map (its
// plastic drift moves by (1 - b) times the overshoot, with the work of that flow) and stays
// elastic.
fn storey_transitions(z: ptr<function, ZA>) {
    for (var s = 0u; s < NS; s++) {
        let slot = PS0 + s;
        let d = SD1[s];
        let r = SR1[s];
        let p = (*z)[slot];
        let mode = SM[s];
        if (storey_event(s, mode, d, r, p) <= 0.0) {
            continue;
        }
        // The plastic load's rate at the last piece's end was the old state's.
        ENDS_VALID = false;
        if (IS_IMK[s]) { imk_transition(s, z, d, r, p); continue; } // IMK
        if (mode != SM_ELASTIC) {
            SM[s] = SM_ELASTIC;
            continue;
        }
        let sg = select(real(-1.0), real(1.0), back_drift(s, d, p) >= 0.0);
        rcount[RC + C_STOREYS + SC_STRIDE * s + SC_YIELDED] = 1u;
        if (sg * r > 0.0) {
            SM[s] = select(SM_DOWN, SM_UP, sg > 0.0);
        } else {
            let p_new = (1.0 - st_b(s)) * (d - sg * st_dy(s));
            let f_mid = st_k(s) * (d - 0.5 * (p + p_new));
            (*z)[slot + NS] += f_mid * (p_new - p);
            (*z)[slot] = p_new;
        }
    }
}

// yielding::next_segment's test after the record: no level in contact, no storey on a line,
// and RowModel::settled (no storey can yield again in the free motion from z).
fn settles(z: ptr<function, ZA>) -> bool {
    for (var l = 0u; l < NL; l++) {
        if (LMODE[l] != MODE_FREE) {
            return false;
        }
    }
    return imk_settles(z); // IMK
    for (var s = 0u; s < NS; s++) {
        if (SM[s] != SM_ELASTIC) {
            return false;
        }
    }
    for (var s = 0u; s < NS; s++) {
        if (st_geo(s) != 0.0) {
            return settles_leaning(z);
        }
    }
    // RowModel::mechanical_energy: the modes' kinetic and strain energy, and what the
    // springs hold beyond it (plastic_strain_correction).
    var e: real = 0.0;
    for (var k = 0u; k < NM; k++) {
        e += 0.5 * ((*z)[NM + k] * (*z)[NM + k] + W2[k] * (*z)[k] * (*z)[k]);
    }
    var c: real = 0.0;
    for (var s = 0u; s < NS; s++) {
        let p = (*z)[PS0 + s];
        c += st_k(s) * p * (0.5 * p - storey_drift(s, z, 0u));
    }
    e = max(e + c, 0.0);
    for (var s = 0u; s < NS; s++) {
        let p = (*z)[PS0 + s];
        let b = st_b(s);
        if (!(sqrt(2.0 * e / st_k(s)) + b * abs(p) / (1.0 - b) <= st_dy(s) * (1.0 + YIELD_SLACK))) {
            return false;
        }
    }
    return true;
}

// RowModel::settled_p_delta: about the static response QS to the plastic loads the drifts
// are d_s (gravity leans on them); the energy of the motion about it bounds each storey's
// excursion by sqrt(2 E / (k - P/h)). Overwrites QS (begin_interval sets it before use).
fn settles_leaning(z: ptr<function, ZA>) -> bool {
    static_offsets(z);
    var e: real = 0.0;
    for (var k = 0u; k < NM; k++) {
        let x = (*z)[k] - QS[k];
        e += 0.5 * ((*z)[NM + k] * (*z)[NM + k] + W2[k] * x * x);
    }
    for (var s = 0u; s < NS; s++) {
        let o = B_OFF[S_B[s]];
        var d_s: real = 0.0;
        for (var i = 0u; i < B_N[S_B[s]]; i++) {
            d_s += st_row(s, i) * QS[o + i];
        }
        let p = (*z)[PS0 + s];
        if (!(sqrt(2.0 * e / (st_k(s) - st_geo(s))) + abs(back_drift(s, d_s, p))
              <= st_dy(s) * (1.0 + YIELD_SLACK))) {
            return false;
        }
    }
    return true;
}

// Storey j of building b's peak drift ratio (StoreyState), raised as the building's.
fn raise_storey(b: u32, j: u32, free: bool, y0: real, y1: real, d0: real, d1: real, a0: real, a1: real, h: real) {
    if (B_S0[b] >= NS) {
        return;
    }
    let i = RS + S_STOREYS + B_S0[b] + j;
    rstate[i] = raise(free, rstate[i], y0, y1, d0, d1, a0, a1, h);
}

// The run's storey states from its blocks, and back.
fn load_storeys(rm: u32) {
    END = rmeta[rm + M_SETTLE_END];
    SETTLED = rcount[RC + C_SETTLED];
    for (var s = 0u; s < NS; s++) {
        SM[s] = rcount[RC + C_STOREYS + SC_STRIDE * s + SC_MODE];
        SFIRE[s] = rcount[RC + C_STOREYS + SC_STRIDE * s + SC_FIRE] != 0u;
    }
}

fn store_storeys() {
    rcount[RC + C_SETTLED] = SETTLED;
    for (var s = 0u; s < NS; s++) {
        rcount[RC + C_STOREYS + SC_STRIDE * s + SC_MODE] = SM[s];
        rcount[RC + C_STOREYS + SC_STRIDE * s + SC_FIRE] = u32(SFIRE[s]);
    }
}

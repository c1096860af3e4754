// Rust twin: src/physics/solver/fast.rs (with src/physics/solver/{mod,events,tracker}.rs and
// src/physics/contact.rs), function for function (same names, same operation order).
// The `fast` scheme, one invocation per run.
// Each dispatch does at most `disp.budget` units of work per run (a free record interval, or one
// piece of an RK4 substep) and saves the state, so the host repeats dispatches until no run is
// active: no dispatch runs long, and lavapipe's loop limiter (about 65,535 loop iterations per
// invocation; a loop past it silently exits) is never reached. The resumable form changes no
// arithmetic: the CPU path takes the same steps in one pass.
//
// The host prepends a prelude (src/engine/gpu/shader.rs): `alias real = f32;` or `f64;`, the precision
// constants EPS, TINY, BIG, and WG (the workgroup size). Only sqrt, abs, min, max, ceil on reals:
// lavapipe's f64 pow/exp/sin are wrong, so every transcendental coefficient comes precomputed in
// `Params`, and the one fifth root is an f32 seed refined by Newton steps in `real`.

// Params, State, Meta, Counters, Dispatch and the MODE_/STATUS_ codes are written by the host
// from their Rust definitions (src/engine/gpu/layout.rs, put in the prelude by shader.rs); Tally
// and Seg are in types.wgsl; the contact laws in contact.wgsl; Hermite interpolation in
// hermite.wgsl.

@group(0) @binding(0) var<uniform> disp: Dispatch;
@group(0) @binding(1) var<storage, read> params: array<Params>;
@group(0) @binding(2) var<storage, read> metas: array<Meta>;
@group(0) @binding(3) var<storage, read> records: array<real>;
@group(0) @binding(4) var<storage, read_write> states: array<State>;
@group(0) @binding(5) var<storage, read_write> counters: array<Counters>;
@group(0) @binding(6) var<storage, read_write> tally: Tally;
@group(0) @binding(7) var<storage, read> run_ids: array<u32>;
@group(0) @binding(8) var<storage, read_write> next_ids: array<u32>;
// Exact free-step energy integrals, FORMS reals per run (layout::forms); read only in the ENERGY
// variant (otherwise a one-element placeholder).
@group(0) @binding(9) var<storage, read> forms: array<real>;
// The chunk's shared free responses (src/engine/gpu/shared.rs: SH_HEADER reals, then SH_CHECK
// per checkpoint); a run's table starts at M.response. Read only outside the ENERGY variant
// (otherwise a one-element placeholder).
@group(0) @binding(10) var<storage, read> responses: array<real>;

// This invocation's run.
var<private> P: Params;
var<private> M: Meta;
var<private> S: State;
var<private> C: Counters;
// The state [u1, v1, u2, v2, w, ein, ed].
var<private> ZS: Z;
// This invocation's run index (for `forms`).
var<private> R: u32;

// cpu::State: [u1, v1, u2, v2, w, e_in, e_damp]
struct Z { u1: real, v1: real, u2: real, v2: real, w: real, ein: real, ed: real }

fn sample(i: u32) -> real {
    if (i < M.rec_len) {
        return records[M.rec_offset + i] * P.scale;
    }
    return 0.0;
}

// model.rs Pair::structural_rate: the faster oscillator's sqrt(k/m) + c/m.
fn structural_rate() -> real {
    return max(sqrt(P.k1 / P.m1) + P.c1 / P.m1, sqrt(P.k2 / P.m2) + P.c2 / P.m2);
}

// ---- cpu/mod.rs ----

fn delta(z: Z) -> real {
    return z.u1 - z.u2 - P.gap;
}

fn ddelta(z: Z) -> real {
    return z.v1 - z.v2;
}

fn force(mode: u32, v0: real, z: Z) -> real {
    if (mode == MODE_FREE) {
        return 0.0;
    }
    return contact_force(delta(z), ddelta(z), v0, mode == MODE_APPROACH);
}

// solver::rhs: the masses' reciprocals `r1`, `r2` come from the caller, once per rk4.
fn rhs(mode: u32, v0: real, ag: real, z: Z, r1: real, r2: real) -> Z {
    let f = force(mode, v0, z);
    return Z(
        z.v1,
        (-P.c1 * z.v1 - P.k1 * z.u1 - f) * r1 - ag,
        z.v2,
        (-P.c2 * z.v2 - P.k2 * z.u2 + f) * r2 - ag,
        f * ddelta(z),
        select(0.0, -ag * (P.m1 * z.v1 + P.m2 * z.v2), ENERGY),
        select(0.0, P.c1 * z.v1 * z.v1 + P.c2 * z.v2 * z.v2, ENERGY),
    );
}

fn structural_rel_accel(z: Z) -> real {
    return -(P.c1 * z.v1 + P.k1 * z.u1) / P.m1 + (P.c2 * z.v2 + P.k2 * z.u2) / P.m2;
}

// solver::force_rate: the rate of force at z in mode (the ground moves both bodies alike).
fn force_rate(mode: u32, v0: real, z: Z, f: real) -> real {
    if (mode == MODE_FREE) {
        return 0.0;
    }
    let a = structural_rel_accel(z) - f * (1.0 / P.m1 + 1.0 / P.m2);
    return contact_force_rate(delta(z), ddelta(z), a, v0, mode == MODE_APPROACH);
}

fn event_value(mode: u32, v0: real, z: Z) -> real {
    switch mode {
        case MODE_FREE: { return gauge(delta(z), ddelta(z), v0); }
        case MODE_APPROACH: { return -ddelta(z); }
        default: { return -gauge(delta(z), ddelta(z), v0); }
    }
}

fn zadd(z: Z, k: Z, s: real) -> Z {
    return Z(z.u1 + s * k.u1, z.v1 + s * k.v1, z.u2 + s * k.u2, z.v2 + s * k.v2, z.w + s * k.w,
             z.ein + s * k.ein, z.ed + s * k.ed);
}

// fast.rs `rk4`: classic RK4 over `h` from local time `tau`.
fn rk4(mode: u32, v0: real, seg: Seg, tau: real, z: Z, h: real) -> Z {
    // Three ground samples and two reciprocal masses per call, off the stages' dependency chain.
    let slope = (seg.a1 - seg.a0) / seg.dt;
    let ag0 = seg.a0 + slope * tau;
    let ag1 = seg.a0 + slope * (tau + 0.5 * h);
    let ag2 = seg.a0 + slope * (tau + h);
    let r1 = 1.0 / P.m1;
    let r2 = 1.0 / P.m2;
    let k1 = rhs(mode, v0, ag0, z, r1, r2);
    let k2 = rhs(mode, v0, ag1, zadd(z, k1, 0.5 * h), r1, r2);
    let k3 = rhs(mode, v0, ag1, zadd(z, k2, 0.5 * h), r1, r2);
    let k4 = rhs(mode, v0, ag2, zadd(z, k3, h), r1, r2);
    let h6 = h / 6.0;
    return Z(
        z.u1 + h6 * (k1.u1 + 2.0 * k2.u1 + 2.0 * k3.u1 + k4.u1),
        z.v1 + h6 * (k1.v1 + 2.0 * k2.v1 + 2.0 * k3.v1 + k4.v1),
        z.u2 + h6 * (k1.u2 + 2.0 * k2.u2 + 2.0 * k3.u2 + k4.u2),
        z.v2 + h6 * (k1.v2 + 2.0 * k2.v2 + 2.0 * k3.v2 + k4.v2),
        z.w + h6 * (k1.w + 2.0 * k2.w + 2.0 * k3.w + k4.w),
        z.ein + h6 * (k1.ein + 2.0 * k2.ein + 2.0 * k3.ein + k4.ein),
        z.ed + h6 * (k1.ed + 2.0 * k2.ed + 2.0 * k3.ed + k4.ed),
    );
}

struct Located { x: real, z: Z }

// events::locate: Illinois regula falsi with a guard probe, then bisections if the bracket is
// still open; the step is re-taken by rk4 from (tau, z0).
fn locate(h: real, f0: real, z1: Z, f1: real, tol: real,
          mode: u32, v0: real, seg: Seg, tau: real, z0: Z) -> Located {
    var a: real = 0.0;
    var fa = min(f0, 0.0);
    var b = h;
    var fb = f1;
    var zb = z1;
    var last = 0;
    for (var it = 0u; it < LOCATE_ITER + LOCATE_BISECT; it++) {
        if (b - a <= tol) { break; }
        var x = 0.5 * (a + b);
        if (it < LOCATE_ITER && fb != fa) {
            x = b - fb * (b - a) / (fb - fa);
        }
        if (!(x > a && x < b)) {
            x = 0.5 * (a + b);
        }
        let zx = rk4(mode, v0, seg, tau, z0, x);
        let fx = event_value(mode, v0, zx);
        var g: real;
        if (fx > 0.0) {
            b = x; fb = fx; zb = zx;
            if (last == 1) { fa = fa * 0.5; }
            last = 1;
            g = x - 0.5 * tol;
        } else {
            a = x; fa = fx;
            if (last == -1) { fb = fb * 0.5; }
            last = -1;
            g = x + 0.5 * tol;
        }
        if (it < LOCATE_ITER && g > a && g < b) {
            let zg = rk4(mode, v0, seg, tau, z0, g);
            let fg = event_value(mode, v0, zg);
            if (fg > 0.0) {
                b = g; fb = fg; zb = zg;
            } else {
                a = g; fa = fg;
            }
        }
    }
    return Located(b, zb);
}

// events::hidden_touch: where delta's Hermite cubic rises above 0 inside the step (-1: nowhere).
fn hidden_touch(z0: Z, z1: Z, h: real) -> real {
    return hidden_rise(delta(z0), ddelta(z0), delta(z1), ddelta(z1), h);
}


fn may_touch(seg: Seg, z0: Z, z1: Z, h: real, v0: real) -> bool {
    let d0 = delta(z0);
    let d1 = delta(z1);
    if (gauge(d0, ddelta(z0), v0) > 0.0 || gauge(d1, ddelta(z1), v0) > 0.0) {
        return true;
    }
    let r = hermite_range(d0, ddelta(z0), d1, ddelta(z1), h);
    let u1 = max(abs(z0.u1), abs(z1.u1));
    let v1 = max(abs(z0.v1), abs(z1.v1));
    let u2 = max(abs(z0.u2), abs(z1.u2));
    let v2 = max(abs(z0.v2), abs(z1.v2));
    let bound = fourth_derivative_bound(P.m1, P.k1, P.c1, u1, v1, seg)
        + fourth_derivative_bound(P.m2, P.k2, P.c2, u2, v2, seg);
    let h2 = h * h;
    return r.hi > -2.0 * h2 * h2 / 384.0 * bound;
}

// ---- Tracker ----

// Time since the current impact's onset at local time tau of the current interval.
fn since_onset(tau: real) -> real {
    return real(C.i - C.i_onset) * P.dt + (tau - S.tau_onset);
}

// tracker::free_accel_and_jerk: a free oscillator's absolute acceleration -(c v + k u) / m and
// its rate -(c a + k v) / m (a the relative acceleration under ground acceleration ag).
struct AJ { a: real, j: real }
fn free_accel_and_jerk(m: real, c: real, k: real, u: real, v: real, ag: real) -> AJ {
    let a = (-c * v - k * u) / m;
    return AJ(a, (-c * (a - ag) - k * v) / m);
}

// hermite::raise_cubic_peak of an acceleration through both ends' values and rates.
fn raise_accel_peak(peak: real, e0: AJ, e1: AJ, h: real) -> real {
    let r = hermite_range(e0.a, e0.j, e1.a, e1.j, h);
    return max(max(peak, abs(r.hi)), abs(r.lo));
}

// hermite::raise_hump_peak: the ends' |a|, and the cubic's largest |a| where |a| rises at the
// start and falls at the end (a contact force's rate is unbounded at first touch).
fn raise_accel_hump(peak: real, e0: AJ, e1: AJ, h: real) -> real {
    var p = max(max(peak, abs(e0.a)), abs(e1.a));
    if (e0.a * e0.j > 0.0 && e1.a * e1.j < 0.0 && e0.a * e1.a > 0.0) {
        let r = hermite_range(e0.a, e0.j, e1.a, e1.j, h);
        p = max(max(p, abs(r.hi)), abs(r.lo));
    }
    return p;
}

// tracker::accel_and_jerk in contact: building b's (1 or 2) absolute acceleration and its rate
// at z, with the contact force f and its rate r on it (-f on building 1, +f on building 2).
fn contact_accel_and_jerk(b: u32, z: Z, f: real, r: real, ag: real) -> AJ {
    if (b == 1u) {
        let a = (-P.c1 * z.v1 - P.k1 * z.u1 - f) / P.m1;
        return AJ(a, (-P.c1 * (a - ag) - P.k1 * z.v1 - r) / P.m1);
    }
    let a = (-P.c2 * z.v2 - P.k2 * z.u2 + f) / P.m2;
    return AJ(a, (-P.c2 * (a - ag) - P.k2 * z.v2 + r) / P.m2);
}

// Tracker::free_step: a free record step's peak displacements from the quintic Hermite, and in
// the ACCEL variant its peak accelerations from the cubic with their rates (free_accel_peak).
fn track_free_step(seg: Seg, z0: Z, z1: Z) {
    let a10 = (-P.c1 * z0.v1 - P.k1 * z0.u1) / P.m1 - seg.a0;
    let a11 = (-P.c1 * z1.v1 - P.k1 * z1.u1) / P.m1 - seg.a1;
    S.peak_u1 = max(S.peak_u1, quintic_peak_abs(z0.u1, z1.u1, z0.v1, z1.v1, a10, a11, seg.dt));
    let a20 = (-P.c2 * z0.v2 - P.k2 * z0.u2) / P.m2 - seg.a0;
    let a21 = (-P.c2 * z1.v2 - P.k2 * z1.u2) / P.m2 - seg.a1;
    S.peak_u2 = max(S.peak_u2, quintic_peak_abs(z0.u2, z1.u2, z0.v2, z1.v2, a20, a21, seg.dt));
    if (ACCEL) {
        S.peak_a1 = raise_accel_peak(S.peak_a1,
            free_accel_and_jerk(P.m1, P.c1, P.k1, z0.u1, z0.v1, seg.a0),
            free_accel_and_jerk(P.m1, P.c1, P.k1, z1.u1, z1.v1, seg.a1), seg.dt);
        S.peak_a2 = raise_accel_peak(S.peak_a2,
            free_accel_and_jerk(P.m2, P.c2, P.k2, z0.u2, z0.v2, seg.a0),
            free_accel_and_jerk(P.m2, P.c2, P.k2, z1.u2, z1.v2, seg.a1), seg.dt);
    }
    if (ENERGY) {
        S.e_peak = max(S.e_peak, z1.ein);
    }
}

// Tracker::step: a piece tau -> tau + h of the record interval seg, spent in mode.
fn track_step(mode: u32, h: real, z0: Z, z1: Z, seg: Seg, tau: real) {
    let r1 = hermite_range(z0.u1, z0.v1, z1.u1, z1.v1, h);
    S.peak_u1 = max(max(S.peak_u1, abs(r1.hi)), abs(r1.lo));
    let r2 = hermite_range(z0.u2, z0.v2, z1.u2, z1.v2, h);
    S.peak_u2 = max(max(S.peak_u2, abs(r2.hi)), abs(r2.lo));
    if (ENERGY) {
        S.e_peak = max(S.e_peak, z1.ein);
    }
    if (ACCEL) {
        let slope = (seg.a1 - seg.a0) / seg.dt;
        let ag0 = seg.a0 + slope * tau;
        let ag1 = seg.a0 + slope * (tau + h);
        if (mode == MODE_FREE) {
            // In free flight the cubic Hermite with the accelerations' rates.
            S.peak_a1 = raise_accel_peak(S.peak_a1,
                free_accel_and_jerk(P.m1, P.c1, P.k1, z0.u1, z0.v1, ag0),
                free_accel_and_jerk(P.m1, P.c1, P.k1, z1.u1, z1.v1, ag1), h);
            S.peak_a2 = raise_accel_peak(S.peak_a2,
                free_accel_and_jerk(P.m2, P.c2, P.k2, z0.u2, z0.v2, ag0),
                free_accel_and_jerk(P.m2, P.c2, P.k2, z1.u2, z1.v2, ag1), h);
        } else {
            // In contact with the force and its rate, where the acceleration peaks inside.
            let fa = force(mode, S.v0, z0);
            let ra = force_rate(mode, S.v0, z0, fa);
            // tracker.rs: the end in the mode the run goes on in (reapproach).
            let mb = reapproach(mode, z1);
            let fb = force(mb, S.v0, z1);
            let rb = force_rate(mb, S.v0, z1, fb);
            S.peak_a1 = raise_accel_hump(S.peak_a1, contact_accel_and_jerk(1u, z0, fa, ra, ag0),
                contact_accel_and_jerk(1u, z1, fb, rb, ag1), h);
            S.peak_a2 = raise_accel_hump(S.peak_a2, contact_accel_and_jerk(2u, z0, fa, ra, ag0),
                contact_accel_and_jerk(2u, z1, fb, rb, ag1), h);
        }
    }
    if (mode != MODE_FREE) {
        S.contact_time = S.contact_time + h;
        let rd = hermite_range(delta(z0), ddelta(z0), delta(z1), ddelta(z1), h);
        S.peak_penetration = max(S.peak_penetration, rd.hi);
        S.dissipated = z1.w;
        let f = force(mode, S.v0, z1);
        let r1 = force_rate(mode, S.v0, z1, f);
        var f0: real = 0.0;
        var r0: real = 0.0;
        if (r1 < 0.0) {
            f0 = force(mode, S.v0, z0);
            r0 = force_rate(mode, S.v0, z0, f0);
        }
        S.imp_peak = raise_force_peak(S.imp_peak, f0, r0, f, r1, h);
    }
}

fn onset(tau: real, v0: real, f: real) {
    C.impacts = C.impacts + 1u;
    if (C.impacts == 1u) {
        S.first_impact = P.t0 + real(C.i) * P.dt + tau;
    }
    S.v0 = v0;
    S.imp_peak = max(f, 0.0);
    C.i_onset = C.i;
    S.tau_onset = tau;
}

fn end_impact() {
    if (S.imp_peak > S.peak_force) {
        S.peak_force = S.imp_peak;
        S.impact_velocity = S.v0;
    }
}

fn transition(mode: u32, tau: real, z: Z, before: Z) -> u32 {
    if (mode == MODE_FREE) {
        let v = ddelta(z);
        var v0 = S.v0;
        if (delta(before) <= 0.0 || S.v0 <= 0.0) {
            v0 = abs(v);
        }
        v0 = max(v0, 1e-12);
        var next = MODE_RESTITUTION;
        if (v > 0.0) { next = MODE_APPROACH; }
        onset(tau, v0, force(next, v0, z));
        return next;
    }
    if (mode == MODE_APPROACH) {
        return MODE_RESTITUTION;
    }
    end_impact();
    return MODE_FREE;
}

fn reapproach(mode: u32, z: Z) -> u32 {
    if (mode == MODE_RESTITUTION && ddelta(z) > 0.0) {
        return MODE_APPROACH;
    }
    return mode;
}

// Integration::accept for an RK4 trial step tau -> tau + h from z0; returns the length advanced
// and leaves the new state in `out`.
fn accept(tau: real, h_in: real, trial_in: Z, seg: Seg, z0: Z, out: ptr<function, Z>) -> real {
    let mode = C.mode;
    let v0 = S.v0;
    var trial = trial_in;
    var h = h_in;
    var f1 = event_value(mode, v0, trial);
    if (mode == MODE_FREE && f1 <= 0.0) {
        let s = hidden_touch(z0, trial, h);
        if (s >= 0.0) {
            let zs = rk4(mode, v0, seg, tau, z0, s * h);
            let fs = event_value(mode, v0, zs);
            if (fs > 0.0) {
                trial = zs;
                f1 = fs;
                h = s * h;
            }
        }
    }
    if (f1 > 0.0) {
        let f0 = event_value(mode, v0, z0);
        let tol = max(LOCATE_TOL * h, 4.0 * EPS * P.dt);
        let l = locate(h, f0, trial, f1, tol, mode, v0, seg, tau, z0);
        track_step(mode, l.x, z0, l.z, seg, tau);
        C.mode = transition(mode, tau + l.x, l.z, z0);
        *out = l.z;
        return l.x;
    }
    track_step(mode, h, z0, trial, seg, tau);
    *out = trial;
    C.mode = reapproach(mode, trial);
    return h;
}

fn finite(z: Z) -> bool {
    // abs(x) <= BIG is false for NaN and for +-inf.
    return abs(z.u1) <= BIG && abs(z.v1) <= BIG && abs(z.u2) <= BIG && abs(z.v2) <= BIG
        && abs(z.w) <= BIG && (!ENERGY || (abs(z.ein) <= BIG && abs(z.ed) <= BIG));
}

// propagator::quadratic: y^T form y for y = [u, v, a0, a1], the form's 10 upper-triangle
// coefficients at forms[base..].
fn quadratic(base: u32, u: real, v: real, a0: real, a1: real) -> real {
    let c = base;
    return u * (forms[c] * u + forms[c + 1u] * v + forms[c + 2u] * a0 + forms[c + 3u] * a1)
        + v * (forms[c + 4u] * v + forms[c + 5u] * a0 + forms[c + 6u] * a1)
        + a0 * (forms[c + 7u] * a0 + forms[c + 8u] * a1)
        + a1 * forms[c + 9u] * a1;
}

// ---- shared.rs: the run's shared free response (FreeResponse's methods on its table) ----

// Is the run beside a shared free response? Never in the ENERGY variant (the host shares none
// there; the constant keeps the code out of it).
fn sharing() -> bool {
    return !ENERGY && M.response != NO_RESPONSE;
}

// R of each building (FreeResponse::distance).
struct Dist { r1: real, r2: real }

// FreeResponse::distance at checkpoint sample i (a multiple of SH_EVERY).
fn shared_distance(i: u32, z: Z) -> Dist {
    let h = M.response;
    let c = h + SH_HEADER + SH_CHECK * (i / SH_EVERY);
    let eu1 = z.u1 - responses[c];
    let ev1 = (z.v1 - responses[c + 1u]) / responses[h];
    let eu2 = z.u2 - responses[c + 2u];
    let ev2 = (z.v2 - responses[c + 3u]) / responses[h + 1u];
    return Dist(
        sqrt(eu1 * eu1 + ev1 * ev1) * (1.0 + REACH_SLACK),
        sqrt(eu2 * eu2 + ev2 * ev2) * (1.0 + REACH_SLACK),
    );
}

// FreeResponse::clear_of: a reach grown by the run's distance stays clear of its gap.
fn shared_clear(reach: real, d: Dist) -> bool {
    let h = M.response;
    return reach + responses[h + 2u] * d.r1 + responses[h + 3u] * d.r2
        < P.gap * (1.0 - REACH_SLACK);
}

// Do peak bounds grown by the distance stay below the peaks?
fn shared_settled(bound1: real, bound2: real, d: Dist) -> bool {
    let h = M.response;
    return bound1 + responses[h + 4u] * d.r1 < S.peak_u1
        && bound2 + responses[h + 5u] * d.r2 < S.peak_u2;
}

// FreeResponse::can_end at checkpoint sample i, for a run at distance d (in the ACCEL variant
// the accelerations' bounds too: table entries 7 and 8, their growth in header entries 6, 7).
fn shared_can_end(i: u32, d: Dist) -> bool {
    let h = M.response;
    let c = h + SH_HEADER + SH_CHECK * (i / SH_EVERY);
    var accel_settled = true;
    if (ACCEL) {
        accel_settled = responses[c + 7u] + responses[h + 6u] * d.r1 < S.peak_a1
            && responses[c + 8u] + responses[h + 7u] * d.r2 < S.peak_a2;
    }
    return shared_clear(responses[c + 4u], d)
        && shared_settled(responses[c + 5u], responses[c + 6u], d) && accel_settled;
}

// The start of the current record interval (fast.rs `run`, loop body): take it with the exact
// free step if no contact can occur inside, else set up its M RK4 substeps.
fn begin_interval(seg: Seg) {
    let dt = P.dt;
    let z0 = ZS;
    var v_est: real;
    var d_est: real;
    var a_est: real;
    var substep = true;
    if (C.mode == MODE_FREE) {
        // fast.rs: every SH_EVERY samples a run beside a shared response takes its distance
        // from it, and ends here if the rest of the record can neither close its gap nor raise
        // its peaks.
        if (sharing() && C.i % SH_EVERY == 0u) {
            if (shared_can_end(C.i, shared_distance(C.i, z0))) {
                C.shared_steps = C.shared_steps + (M.intervals - C.i);
                C.i = M.intervals;
                return;
            }
        }
        let u1 = P.p1_uu * z0.u1 + P.p1_uv * z0.v1 + P.p1_ua0 * seg.a0 + P.p1_ua1 * seg.a1;
        let v1 = P.p1_vu * z0.u1 + P.p1_vv * z0.v1 + P.p1_va0 * seg.a0 + P.p1_va1 * seg.a1;
        let u2 = P.p2_uu * z0.u2 + P.p2_uv * z0.v2 + P.p2_ua0 * seg.a0 + P.p2_ua1 * seg.a1;
        let v2 = P.p2_vu * z0.u2 + P.p2_vv * z0.v2 + P.p2_va0 * seg.a0 + P.p2_va1 * seg.a1;
        var z1 = Z(u1, v1, u2, v2, z0.w, z0.ein, z0.ed);
        // Unlike fast.rs, each free step takes the full near-contact test and peak search even
        // beside a shared response: settling them from its per-step tables made lavapipe's
        // kernel 15 % slower (the lanes that cannot settle hold the rest).
        if (!may_touch(seg, z0, z1, dt, S.v0)) {
            if (ENERGY) {
                // fast.rs: the exact free-step input and damping work (EnergyForms::integrals).
                let b = R * FORMS;
                let vv1 = quadratic(b, z0.u1, z0.v1, seg.a0, seg.a1);
                let agv1 = quadratic(b + 10u, z0.u1, z0.v1, seg.a0, seg.a1);
                let vv2 = quadratic(b + 20u, z0.u2, z0.v2, seg.a0, seg.a1);
                let agv2 = quadratic(b + 30u, z0.u2, z0.v2, seg.a0, seg.a1);
                z1.ein = z1.ein - (P.m1 * agv1 + P.m2 * agv2);
                z1.ed = z1.ed + (P.c1 * vv1 + P.c2 * vv2);
            }
            track_free_step(seg, z0, z1);
            C.free_steps = C.free_steps + 1u;
            ZS = z1;
            if (!finite(z1)) {
                C.status = STATUS_NON_FINITE;
            }
            C.i = C.i + 1u;
            substep = false;
        } else {
            let a = abs(structural_rel_accel(z0));
            v_est = 1.5 * max(abs(ddelta(z0)), abs(ddelta(z1)));
            d_est = max(delta(z0), delta(z1));
            a_est = max(a, abs(structural_rel_accel(z1)));
        }
    } else {
        v_est = max(S.v0, abs(ddelta(z0)));
        d_est = delta(z0);
        a_est = abs(structural_rel_accel(z0));
    }
    if (substep) {
        // Resolve an impact at v_est, and stay stable at twice the current penetration.
        let h_rate = 6.283185307179586 / P.substeps_per_contact
            / max(local_rate(2.0 * d_est, S.v0), structural_rate());
        // fast.rs: a contact that has lasted SUSTAINED contact durations needs only h_rate.
        var h0 = h_rate;
        if (!(C.mode != MODE_FREE && since_onset(0.0) > SUSTAINED * duration_estimate(S.v0))) {
            h0 = min(impact_step(v_est, a_est, P.substeps_per_contact), h_rate);
        }
        let mf = max(ceil(dt / h0), 1.0);
        if (!(mf <= real(disp.max_substeps_per_step))) {
            C.status = STATUS_STEP_LIMIT;
        } else if (mf > real(disp.handoff_substeps_per_step)) {
            // More substeps than this precision resolves (f32 increments drown in rounding):
            // the host finishes the run on the CPU in f64.
            C.status = STATUS_HANDOFF;
        } else {
            C.m = u32(mf);
            C.j = 1u;
            C.pieces = 0u;
            S.tau = 0.0;
        }
    }
}

// The move past the end of substep j: to the next substep, or to the next interval.
fn end_substep(tau_target: real) {
    S.tau = tau_target;
    C.j = C.j + 1u;
    C.pieces = 0u;
    if (C.j > C.m) {
        C.j = 0u;
        C.i = C.i + 1u;
    }
}

// One piece of substep j of the current interval: an RK4 step to the substep's end, cut short
// at a located event, and the move on once the end is reached (in the same unit of work: a
// unit of its own would hold the lanes for another loop trip per substep).
fn piece(seg: Seg) {
    let dt = P.dt;
    let h = dt / real(C.m);
    var tau_target = dt;
    if (C.j < C.m) {
        tau_target = real(C.j) * h;
    }
    let tol = max(LOCATE_TOL * h, 4.0 * EPS * dt);
    if (tau_target - S.tau > tol) {
        C.substeps = C.substeps + 1u;
        // Cut at the graded mesh after a touch (onset_cut); such pieces do not count against
        // the cap on event cuts.
        var hs = tau_target - S.tau;
        if (C.mode == MODE_APPROACH) {
            hs = min(hs, onset_cut(since_onset(S.tau), S.v0, P.substeps_per_contact, tol));
        }
        if (hs == tau_target - S.tau) {
            C.pieces = C.pieces + 1u;
        }
        if (C.substeps > disp.max_substeps || C.pieces > MAX_PIECES_PER_SUBSTEP) {
            C.status = STATUS_STEP_LIMIT;
        } else {
            let z = ZS;
            let trial = rk4(C.mode, S.v0, seg, S.tau, z, hs);
            var znew: Z;
            S.tau = S.tau + accept(S.tau, hs, trial, seg, z, &znew);
            ZS = znew;
            if (!finite(znew)) {
                C.status = STATUS_NON_FINITE;
            } else if (!(tau_target - S.tau > tol)) {
                end_substep(tau_target);
            }
        }
    } else {
        end_substep(tau_target);
    }
}

// One lane's work in a dispatch: at most disp.budget units of run run_ids[lane]; returns the
// units it did.
fn integrate_run(lane: u32) -> u32 {
    if (lane >= disp.nactive) {
        return 0u;
    }
    let r = run_ids[lane];
    R = r;
    C = counters[r];
    M = metas[r];
    if (C.status != STATUS_OK || C.i >= M.intervals) {
        return 0u;
    }
    P = params[r];
    K = Law(M.law, P.stiffness, P.damping, P.damping_ratio, P.m_eff, P.tc_coef);
    S = states[r];
    ZS = Z(S.u1, S.v1, S.u2, S.v2, S.w, S.e_in, S.e_damp);
    var budget = disp.budget;
    loop {
        if (C.status != STATUS_OK || C.i >= M.intervals || budget == 0u) {
            break;
        }
        budget = budget - 1u;
        let seg = Seg(sample(C.i), sample(C.i + 1u), P.dt);
        if (C.j == 0u) {
            begin_interval(seg);
        } else {
            piece(seg);
        }
    }
    S.u1 = ZS.u1;
    S.v1 = ZS.v1;
    S.u2 = ZS.u2;
    S.v2 = ZS.v2;
    S.w = ZS.w;
    S.e_in = ZS.ein;
    S.e_damp = ZS.ed;
    states[r] = S;
    counters[r] = C;
    if (C.status == STATUS_OK && C.i < M.intervals) {
        next_ids[atomicAdd(&tally.active_runs, 1u)] = r;
    }
    return disp.budget - budget;
}

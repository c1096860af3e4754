// Rust twin: src/physics/imk/{mod,side}.rs (ImkState::advance and what it calls, Side), and the
// IMK parts of src/physics/solver/row/{storey,events,yielding}.rs, function for function in
// the same order of operations (so that f64 agrees to rounding). Only a kernel whose row has
// IMK storeys carries this file, and the lines of yielding.wgsl, row.wgsl and row_loops.wgsl
// marked `// IMK` that call it (RowShape::wgsl_source).
//
// The host's constants: IS_IMK (each yielding storey: is it an IMK spring?), IMK_AT (where each
// building's IMK block starts in its model block: IMK_PARAMS reals per storey, IP_*), S_IMK and
// IS_STRIDE (each yielding storey's IMK reals in the state, IR_*), C_IMK and IC_STRIDE (its
// u32s in the counters, IC_*). Infinite drifts are BIG.

const IP_RULE: u32 = 0u;
const IP_K: u32 = 1u;
const IP_FY: u32 = 2u;
const IP_KP: u32 = 3u;
const IP_UP: u32 = 4u;
const IP_UPC: u32 = 5u;
const IP_FRES: u32 = 6u;
const IP_UU: u32 = 7u;
const IP_HAS_ET: u32 = 8u;
const IP_ET: u32 = 9u;
// One side's backbone (Side) at IR_SIDE * side, then the spring's reals.
const IR_SIDE: u32 = 10u;
const IR_KUNLOAD: u32 = 20u;
const IR_WORK: u32 = 21u;
const IR_WORK_MARK: u32 = 22u;
const IR_D0: u32 = 23u;
const IR_F0: u32 = 24u;
const IR_SLOPE: u32 = 25u;
const IR_LO: u32 = 26u;
const IR_HI: u32 = 27u;
const IR_HEADING: u32 = 28u;
const IR_REST_LO: u32 = 29u;
const IR_REST_HI: u32 = 30u;
const IC_BRANCH: u32 = 0u;
const IC_BRANCH_SIDE: u32 = 1u;
const IC_MARK_HI: u32 = 2u;
const IC_MARK_LO: u32 = 3u;
const IC_FLAGS: u32 = 4u;
// IC_FLAGS' bits: each side failed, yielded, capped, the residual reached.
const IF_FAILED0: u32 = 1u;
const IF_YIELDED: u32 = 4u;
const IF_CAPPED: u32 = 8u;
const IF_RESIDUAL: u32 = 16u;
// An IMK storey on a piece that is not free (SM, beside yielding.wgsl's SM_*).
const SM_IMK: u32 = 3u;
// Branch (0: the spring not yet set up).
const BR_ELASTIC: u32 = 1u;
const BR_UNLOADING: u32 = 2u;
const BR_LOCAL: u32 = 3u;
const BR_GLOBAL: u32 = 4u;
const BR_BACKBONE: u32 = 5u;
const BR_COLLAPSED: u32 = 6u;
// Mark.
const MK_NONE: u32 = 0u;
const MK_BACKBONE: u32 = 1u;
const MK_ZERO: u32 = 2u;
const MK_BREAK: u32 = 3u;
const MK_ULTIMATE: u32 = 4u;
const MK_NO_STRENGTH: u32 = 5u;
const MK_LOCAL_PEAK: u32 = 6u;
const MK_GLOBAL_PEAK: u32 = 7u;
const MK_RESIDUAL: u32 = 8u;

struct ImkSide {
    fy: real,
    uy: real,
    kp: real,
    ucap: real,
    fcap: real,
    kpc: real,
    x_local: real,
    g_local: real,
    x_global: real,
    g_global: real,
    failed: bool,
}

// A backbone segment: force, slope, where it ends and what comes there.
struct ImkSegment {
    g: real,
    slope: real,
    end: real,
    mark: u32,
}

// A threshold: the first, where it leads, and the first other than a zero crossing.
struct ImkThreshold {
    x: real,
    mark: u32,
    rest: real,
}

fn imk_ip(s: u32, f: u32) -> real {
    let b = S_B[s];
    return models[MB[b] + IMK_AT[b] + IMK_PARAMS * S_J[s] + f];
}

fn imk_ir(s: u32, f: u32) -> real {
    return rstate[RS + S_IMK + IS_STRIDE * s + f];
}

fn set_imk_ir(s: u32, f: u32, v: real) {
    rstate[RS + S_IMK + IS_STRIDE * s + f] = v;
}

fn imk_ic(s: u32, f: u32) -> u32 {
    return rcount[RC + C_IMK + IC_STRIDE * s + f];
}

fn set_imk_ic(s: u32, f: u32, v: u32) {
    rcount[RC + C_IMK + IC_STRIDE * s + f] = v;
}

fn imk_flag(s: u32, bit: u32) -> bool {
    return (imk_ic(s, IC_FLAGS) & bit) != 0u;
}

fn set_imk_flag(s: u32, bit: u32) {
    set_imk_ic(s, IC_FLAGS, imk_ic(s, IC_FLAGS) | bit);
}

fn imk_peak_oriented(s: u32) -> bool {
    return imk_ip(s, IP_RULE) != 0.0;
}

// ImkSpring::slack.
fn imk_slack(s: u32) -> real {
    return 1e-9 * imk_ip(s, IP_FY) / imk_ip(s, IP_K);
}

// ImkSpring::fcap0.
fn imk_fcap0(s: u32) -> real {
    return imk_ip(s, IP_FY) + imk_ip(s, IP_KP) * imk_ip(s, IP_UP);
}

// Side index of a sign (idx).
fn imk_index(sign: real) -> u32 {
    return select(0u, 1u, sign < 0.0);
}

fn imk_side(s: u32, i: u32) -> ImkSide {
    let o = IR_SIDE * i;
    return ImkSide(imk_ir(s, o), imk_ir(s, o + 1u), imk_ir(s, o + 2u), imk_ir(s, o + 3u), imk_ir(s, o + 4u),
        imk_ir(s, o + 5u), imk_ir(s, o + 6u), imk_ir(s, o + 7u), imk_ir(s, o + 8u), imk_ir(s, o + 9u),
        imk_flag(s, IF_FAILED0 << i));
}

fn set_imk_side(s: u32, i: u32, x: ImkSide) {
    let o = IR_SIDE * i;
    set_imk_ir(s, o, x.fy);
    set_imk_ir(s, o + 1u, x.uy);
    set_imk_ir(s, o + 2u, x.kp);
    set_imk_ir(s, o + 3u, x.ucap);
    set_imk_ir(s, o + 4u, x.fcap);
    set_imk_ir(s, o + 5u, x.kpc);
    set_imk_ir(s, o + 6u, x.x_local);
    set_imk_ir(s, o + 7u, x.g_local);
    set_imk_ir(s, o + 8u, x.x_global);
    set_imk_ir(s, o + 9u, x.g_global);
    if (x.failed) {
        set_imk_flag(s, IF_FAILED0 << i);
    }
}

// Side::ures.
fn imk_ures(s: u32, x: ImkSide) -> real {
    if (x.kpc < 0.0) {
        return x.ucap + (imk_ip(s, IP_FRES) - x.fcap) / x.kpc;
    }
    return BIG;
}

// Side::segment.
fn imk_segment(s: u32, side: ImkSide, x: real, other_failed: bool) -> ImkSegment {
    if (side.failed) {
        return ImkSegment(0.0, 0.0, BIG, MK_NONE);
    }
    let fres = imk_ip(s, IP_FRES);
    let ures = imk_ures(s, side);
    let at_residual = select(MK_NO_STRENGTH, MK_BREAK, fres > 0.0);
    if (!imk_peak_oriented(s)) {
        if (other_failed) {
            return ImkSegment(fres, 0.0, BIG, MK_NONE);
        }
        if (x < side.ucap) {
            let g = side.fcap + side.kp * (x - side.ucap);
            if (side.kp > 0.0) {
                let x_floor = side.ucap + (fres - side.fcap) / side.kp;
                if (x < x_floor) {
                    return ImkSegment(fres, 0.0, x_floor, MK_BREAK);
                }
            }
            return ImkSegment(g, side.kp, side.ucap, MK_BREAK);
        } else if (x < ures) {
            let g = side.fcap + side.kpc * (x - side.ucap);
            return ImkSegment(g, side.kpc, ures, at_residual);
        } else if (side.kpc < 0.0) {
            return ImkSegment(fres, 0.0, BIG, MK_NONE);
        }
        return ImkSegment(max(side.fcap, fres), 0.0, BIG, MK_NONE);
    }
    if (x < side.ucap) {
        return ImkSegment(side.fcap + side.kp * (x - side.ucap), side.kp, side.ucap, MK_BREAK);
    } else if (x < ures) {
        let g = side.fcap + side.kpc * (x - side.ucap);
        return ImkSegment(g, side.kpc, ures, at_residual);
    }
    return ImkSegment(fres, 0.0, BIG, MK_NONE);
}

// Side::in_residual.
fn imk_in_residual(s: u32, side: ImkSide, x: real) -> bool {
    if (side.kpc < 0.0) {
        return x >= imk_ures(s, side);
    }
    return side.fcap <= imk_ip(s, IP_FRES);
}

// Side::bilin_meet.
fn imk_bilin_meet(s: u32, side: ImkSide, x0: real, g0: real, slope: real, other_failed: bool) -> real {
    var x = x0;
    for (var it = 0u; it < 6u; it++) {
        let seg = imk_segment(s, side, x, other_failed);
        let gap = seg.g - (g0 + slope * (x - x0));
        if (gap <= 0.0) {
            return x;
        }
        if (slope > seg.slope) {
            let hit = x + gap / (slope - seg.slope);
            if (hit <= seg.end) {
                return hit;
            }
        }
        if (!(seg.end < BIG)) {
            return BIG;
        }
        x = seg.end;
    }
    return BIG;
}

// Side::deteriorate.
fn imk_deteriorate(s: u32, side_in: ImkSide, beta: real, x_from: real, g_from: real, kunload: real) -> ImkSide {
    var x = side_in;
    let k = imk_ip(s, IP_K);
    let fres = imk_ip(s, IP_FRES);
    let keep = 1.0 - beta;
    let fcap_proj = (x.fcap - x.kpc * x.ucap) * keep;
    x.fy *= keep;
    x.kp *= keep;
    x.uy = x.fy / k;
    let peak = imk_peak_oriented(s);
    if (!peak) {
        let kpc0 = imk_fcap0(s) / imk_ip(s, IP_UPC);
        if (x.fy < fres) {
            x.kpc = 0.0;
        } else {
            x.kpc = -kpc0 * (x.fy - fres) / (imk_ip(s, IP_FY) - fres);
        }
    }
    let fy_proj = x.fy - x.kp * x.uy;
    if (x.kp <= x.kpc) {
        x.ucap = 0.0;
    } else {
        x.ucap = (fcap_proj - fy_proj) / (x.kp - x.kpc);
    }
    x.fcap = fy_proj + x.kp * x.ucap;
    if (!peak) {
        let to_residual = x.ucap - x_from - (fres - g_from) / kunload;
        let candidate = (x.fcap - fres) / to_residual;
        if (x.fcap < fres) {
            x.fy = fres;
            x.fcap = fres;
            x.kp = 0.0;
            x.kpc = 0.0;
            x.uy = x.fy / k;
            x.ucap = 0.0;
        } else if (candidate > 0.0 && x.kp > candidate) {
            x.kp = candidate;
        }
    } else {
        let u = x.x_global;
        var g: real;
        if (u < x.uy) {
            g = k * u;
        } else if (u < x.ucap) {
            g = x.fy + x.kp * (u - x.uy);
        } else {
            g = x.fcap + x.kpc * (u - x.ucap);
        }
        x.g_global = max(g, fres);
    }
    return x;
}

fn imk_take(t: ImkThreshold, x: real, m: u32) -> ImkThreshold {
    var o = t;
    if (x < o.x) {
        o.x = x;
        o.mark = m;
    }
    if (m != MK_ZERO && m != MK_LOCAL_PEAK) {
        o.rest = min(o.rest, x);
    }
    return o;
}

// ImkState::threshold.
fn imk_threshold(s: u32, sign: real, x0: real, g0: real, slope: real) -> ImkThreshold {
    let side = imk_side(s, imk_index(sign));
    let other_failed = imk_flag(s, IF_FAILED0 << imk_index(-sign));
    let branch = imk_ic(s, IC_BRANCH);
    let on = select(real(1.0), real(-1.0), imk_ic(s, IC_BRANCH_SIDE) != 0u) == sign;
    let peak = imk_peak_oriented(s);
    var t = ImkThreshold(BIG, MK_NONE, BIG);
    if (!side.failed && branch != BR_COLLAPSED) {
        t = imk_take(t, imk_ip(s, IP_UU), MK_ULTIMATE);
    }
    if (branch == BR_ELASTIC) {
        if (!peak) {
            t = imk_take(t, imk_bilin_meet(s, side, x0, g0, slope, other_failed), MK_BACKBONE);
        } else {
            t = imk_take(t, side.uy, MK_BACKBONE);
        }
    } else if (branch == BR_UNLOADING) {
        if (g0 < 0.0 && slope > 0.0 && imk_flag(s, IF_YIELDED)) {
            t = imk_take(t, x0 - g0 / slope, MK_ZERO);
        }
        if (!peak) {
            t = imk_take(t, imk_bilin_meet(s, side, x0, g0, slope, other_failed), MK_BACKBONE);
            if (!imk_flag(s, IF_RESIDUAL) && !side.failed && !other_failed && side.kpc < 0.0) {
                let x = imk_ures(s, side);
                if (x > x0) {
                    t = imk_take(t, x, MK_RESIDUAL);
                }
            }
        } else if (g0 > 0.0 || (g0 == 0.0 && side.x_local > x0)) {
            t = imk_take(t, side.x_local, MK_LOCAL_PEAK);
        }
    } else if (branch == BR_LOCAL && on) {
        t = imk_take(t, side.x_local, MK_LOCAL_PEAK);
    } else if (branch == BR_GLOBAL && on) {
        t = imk_take(t, side.x_global, MK_GLOBAL_PEAK);
    } else if (branch == BR_BACKBONE && on) {
        let seg = imk_segment(s, side, x0, other_failed);
        t = imk_take(t, seg.end, seg.mark);
    }
    return t;
}

// The piece's force at drift d (Piece::force).
fn imk_force(s: u32, d: real) -> real {
    return imk_ir(s, IR_F0) + imk_ir(s, IR_SLOPE) * (d - imk_ir(s, IR_D0));
}

// ImkState::set_piece on branch `branch` of side `side` (0 +, 1 -).
fn imk_set_piece(s: u32, d0: real, f0: real, slope: real, branch: u32, side: u32) {
    set_imk_ic(s, IC_BRANCH, branch);
    set_imk_ic(s, IC_BRANCH_SIDE, side);
    let hi = imk_threshold(s, 1.0, 1.0 * d0, 1.0 * f0, slope);
    let lo = imk_threshold(s, -1.0, -1.0 * d0, -1.0 * f0, slope);
    set_imk_ir(s, IR_D0, d0);
    set_imk_ir(s, IR_F0, f0);
    set_imk_ir(s, IR_SLOPE, slope);
    set_imk_ir(s, IR_HI, hi.x);
    set_imk_ir(s, IR_REST_HI, hi.rest);
    set_imk_ir(s, IR_LO, -lo.x);
    set_imk_ir(s, IR_REST_LO, -lo.rest);
    set_imk_ic(s, IC_MARK_HI, hi.mark);
    set_imk_ic(s, IC_MARK_LO, lo.mark);
    var heading: real = 0.0;
    if (branch == BR_BACKBONE || branch == BR_LOCAL || branch == BR_GLOBAL) {
        heading = select(real(1.0), real(-1.0), side != 0u);
    }
    set_imk_ir(s, IR_HEADING, heading);
}

// ImkState::new.
fn imk_new(s: u32) {
    let k = imk_ip(s, IP_K);
    let fy = imk_ip(s, IP_FY);
    let uy = fy / k;
    let fcap = imk_fcap0(s);
    let side = ImkSide(fy, uy, imk_ip(s, IP_KP), uy + imk_ip(s, IP_UP), fcap, -fcap / imk_ip(s, IP_UPC),
        uy, fy, uy, fy, false);
    set_imk_ic(s, IC_FLAGS, 0u);
    set_imk_side(s, 0u, side);
    set_imk_side(s, 1u, side);
    set_imk_ir(s, IR_KUNLOAD, k);
    set_imk_ir(s, IR_WORK, 0.0);
    set_imk_ir(s, IR_WORK_MARK, 0.0);
    imk_set_piece(s, 0.0, 0.0, k, BR_ELASTIC, 0u);
}

// Set up each IMK spring of a run that starts.
fn imk_begin() {
    for (var s = 0u; s < NS; s++) {
        if (IS_IMK[s] && imk_ic(s, IC_BRANCH) == 0u) {
            imk_new(s);
        }
    }
}

// The energy rule's factor (beta), -1 once the capacity is spent.
fn imk_beta(spent: real, left: real) -> real {
    if (left <= 0.0) {
        return -1.0;
    }
    let b = max(spent, 0.0) / left;
    return select(real(-1.0), b, b <= 1.0);
}

// ImkState::collapse.
fn imk_collapse(s: u32, d: real) {
    set_imk_flag(s, IF_FAILED0 | (IF_FAILED0 << 1u));
    set_imk_ic(s, IC_BRANCH, BR_COLLAPSED);
    set_imk_ir(s, IR_D0, d);
    set_imk_ir(s, IR_F0, 0.0);
    set_imk_ir(s, IR_SLOPE, 0.0);
    set_imk_ir(s, IR_LO, -BIG);
    set_imk_ir(s, IR_HI, BIG);
    set_imk_ir(s, IR_HEADING, 0.0);
    set_imk_ir(s, IR_REST_LO, -BIG);
    set_imk_ir(s, IR_REST_HI, BIG);
    set_imk_ic(s, IC_MARK_HI, MK_NONE);
    set_imk_ic(s, IC_MARK_LO, MK_NONE);
}

// ImkState::reverse.
fn imk_reverse(s: u32, d: real) {
    let f = imk_force(s, d);
    var sign = imk_ir(s, IR_HEADING);
    if (f > 0.0) {
        sign = 1.0;
    } else if (f < 0.0) {
        sign = -1.0;
    }
    if (imk_peak_oriented(s)) {
        let i = imk_index(sign);
        var side = imk_side(s, i);
        let x = sign * d;
        let g = sign * f;
        side.x_local = x;
        side.g_local = g;
        if (x > side.x_global) {
            side.x_global = x;
            side.g_global = g;
        }
        set_imk_side(s, i, side);
    }
    var kunload = imk_ir(s, IR_KUNLOAD);
    if (imk_ip(s, IP_HAS_ET) != 0.0) {
        let work = imk_ir(s, IR_WORK);
        let stored = 0.5 * f * f / kunload;
        let spent = work - stored;
        let since = work - imk_ir(s, IR_WORK_MARK) - stored;
        let b = imk_beta(since, imk_ip(s, IP_ET) - spent);
        if (b < 0.0) {
            imk_collapse(s, d);
            return;
        }
        kunload *= 1.0 - b;
    }
    if (!imk_peak_oriented(s) && imk_flag(s, IF_RESIDUAL)) {
        kunload = 0.5 * imk_ip(s, IP_K);
    }
    set_imk_ir(s, IR_KUNLOAD, kunload);
    imk_set_piece(s, d, f, kunload, BR_UNLOADING, 0u);
}

// ImkState::on_backbone.
fn imk_on_backbone(s: u32, d: real, sign: real) {
    let i = imk_index(sign);
    let other_failed = imk_flag(s, IF_FAILED0 << imk_index(-sign));
    let side = imk_side(s, i);
    let x = sign * d;
    let seg = imk_segment(s, side, x, other_failed);
    if (!side.failed && x > side.ucap) {
        set_imk_flag(s, IF_CAPPED);
    }
    if (!imk_peak_oriented(s) && !side.failed && imk_in_residual(s, side, x)) {
        set_imk_flag(s, IF_RESIDUAL);
    }
    imk_set_piece(s, d, sign * seg.g, seg.slope, BR_BACKBONE, i);
}

// ImkState::new_excursion.
fn imk_new_excursion(s: u32, d: real, sign: real) {
    let has_et = imk_ip(s, IP_HAS_ET) != 0.0;
    let peak = imk_peak_oriented(s);
    var b: real = 0.0;
    if (has_et) {
        let work = imk_ir(s, IR_WORK);
        let since = max(work - imk_ir(s, IR_WORK_MARK), 0.0);
        set_imk_ir(s, IR_WORK_MARK, work);
        b = imk_beta(since, imk_ip(s, IP_ET) - work);
        if (b < 0.0) {
            imk_collapse(s, d);
            return;
        }
    }
    let i = imk_index(sign);
    let kunload = imk_ir(s, IR_KUNLOAD);
    if (has_et || !peak) {
        set_imk_side(s, i, imk_deteriorate(s, imk_side(s, i), b, sign * d, 0.0, kunload));
    }
    let f = imk_force(s, d);
    if (!peak) {
        imk_set_piece(s, d, f, kunload, BR_UNLOADING, 0u);
        return;
    }
    let side = imk_side(s, i);
    if (side.g_global <= 0.0) {
        imk_collapse(s, d);
        return;
    }
    let u0 = sign * d;
    let k_global = side.g_global / (side.x_global - u0);
    let k_local = side.g_local / (side.x_local - u0);
    if (u0 < side.x_local && side.g_local < side.g_global && k_local > k_global) {
        imk_set_piece(s, d, f, k_local, BR_LOCAL, i);
    } else {
        imk_set_piece(s, d, f, k_global, BR_GLOBAL, i);
    }
}

// ImkState::cross: drift d passed the threshold `mark` of side `sign`.
fn imk_cross(s: u32, d: real, sign: real, mark: u32) {
    let f = imk_force(s, d);
    let i = imk_index(sign);
    let x = sign * d;
    if (mark == MK_ULTIMATE || mark == MK_NO_STRENGTH) {
        if (imk_peak_oriented(s) || imk_flag(s, IF_FAILED0 << imk_index(-sign))) {
            imk_collapse(s, d);
            return;
        }
        set_imk_flag(s, (IF_FAILED0 << i) | IF_RESIDUAL);
        imk_on_backbone(s, d, sign);
    } else if (mark == MK_BACKBONE || mark == MK_BREAK || mark == MK_GLOBAL_PEAK) {
        set_imk_flag(s, IF_YIELDED);
        imk_on_backbone(s, d, sign);
    } else if (mark == MK_RESIDUAL) {
        set_imk_flag(s, IF_RESIDUAL);
        imk_set_piece(s, d, f, imk_ir(s, IR_SLOPE), imk_ic(s, IC_BRANCH), imk_ic(s, IC_BRANCH_SIDE));
    } else if (mark == MK_LOCAL_PEAK) {
        let side = imk_side(s, i);
        if (side.x_global > x) {
            let k = (side.g_global - side.g_local) / (side.x_global - side.x_local);
            imk_set_piece(s, d, f, k, BR_GLOBAL, i);
        } else {
            imk_on_backbone(s, d, sign);
        }
    } else if (mark == MK_ZERO) {
        imk_new_excursion(s, d, sign);
    }
}

// ImkState::advance: every change of piece due at drift d, rate `rate`; the force there.
fn imk_advance(s: u32, d: real, rate: real) -> real {
    for (var it = 0u; it < 16u; it++) {
        let slack = imk_slack(s);
        let heading = imk_ir(s, IR_HEADING);
        var sign: real = 0.0;
        if (heading != 0.0 && -heading * rate > 0.0) {
            sign = 0.0;
        } else if (d - imk_ir(s, IR_HI) - slack > 0.0) {
            sign = 1.0;
        } else if (imk_ir(s, IR_LO) - d - slack > 0.0) {
            sign = -1.0;
        } else {
            break;
        }
        // close_work: the work on the piece up to d, where it ends.
        let f0 = imk_ir(s, IR_F0);
        set_imk_ir(s, IR_WORK, imk_ir(s, IR_WORK) + 0.5 * (f0 + imk_force(s, d)) * (d - imk_ir(s, IR_D0)));
        if (sign == 0.0) {
            imk_reverse(s, d);
        } else if (sign > 0.0) {
            imk_cross(s, d, 1.0, imk_ic(s, IC_MARK_HI));
        } else {
            imk_cross(s, d, -1.0, imk_ic(s, IC_MARK_LO));
        }
    }
    return imk_force(s, d);
}

// Piece::event_value: positive once the piece must end.
fn imk_event(s: u32, d: real, rate: real) -> real {
    let slack = imk_slack(s);
    return max(max(d - imk_ir(s, IR_HI) - slack, imk_ir(s, IR_LO) - d - slack),
        -imk_ir(s, IR_HEADING) * rate);
}

// StoreyModel::free: a piece of the initial stiffness that does not flow one way.
fn imk_free(s: u32) -> bool {
    return imk_ir(s, IR_SLOPE) == st_k(s) && imk_ir(s, IR_HEADING) == 0.0;
}

// StoreyModel::flow: the plastic drift's rate over the drift's.
fn storey_flow(s: u32) -> real {
    if (IS_IMK[s]) {
        return 1.0 - imk_ir(s, IR_SLOPE) / st_k(s);
    }
    return 1.0 - st_b(s);
}

// StoreyModel::may_yield of an IMK storey: could its drift pass a threshold of its piece inside
// the free step (drift and rate d0, r0 -> d1, r1, |d''''| <= bound)?
fn imk_may_reach(s: u32, d0: real, r0: real, d1: real, r1: real, bound: real, h: real) -> bool {
    let margin = -error_margin(bound, h);
    let slack = imk_slack(s);
    let hi = imk_ir(s, IR_HI);
    let lo = imk_ir(s, IR_LO);
    for (var e = 0u; e < 2u; e++) {
        var a0 = d0 - hi - slack;
        var a1 = d1 - hi - slack;
        var ar0 = r0;
        var ar1 = r1;
        if (e == 1u) {
            a0 = lo - d0 - slack;
            a1 = lo - d1 - slack;
            ar0 = -r0;
            ar1 = -r1;
        }
        if (cubic_max_bound(a0, ar0, a1, ar1, h) > margin
            && (a0 > 0.0 || a1 > 0.0 || hermite_range(a0, ar0, a1, ar1, h).hi > margin)) {
            return true;
        }
    }
    return false;
}

// RowRun::hidden_yield of an IMK storey: the earliest fraction of the step at which its drift
// could pass a threshold of its piece between the ends, from `best` (-1: none yet).
fn imk_hidden(s: u32, h: real, best_in: real) -> real {
    var best = best_in;
    let slack = imk_slack(s);
    let hi = imk_ir(s, IR_HI);
    let lo = imk_ir(s, IR_LO);
    var xs = array<real, 2>(hidden_rise(SD0[s] - hi - slack, SR0[s], SD1[s] - hi - slack, SR1[s], h),
        hidden_rise(lo - SD0[s] - slack, -SR0[s], lo - SD1[s] - slack, -SR1[s], h));
    for (var e = 0u; e < 2u; e++) {
        let x = xs[e];
        if (x >= 0.0 && (best < 0.0 || x < best)) {
            best = x;
        }
    }
    return best;
}

// RowRun::storey_transitions of IMK storey s at drift d, rate r, plastic drift p (its event
// fires): the spring takes its pieces' changes; the plastic drift moves to the new piece's
// force, with the work of that move.
fn imk_transition(s: u32, z: ptr<function, ZA>, d: real, r: real, p: real) {
    let slot = PS0 + s;
    let f = imk_advance(s, d, r);
    if (imk_flag(s, IF_YIELDED)) {
        rcount[RC + C_STOREYS + SC_STRIDE * s + SC_YIELDED] = 1u;
    }
    let k = st_k(s);
    let p_new = d - f / k;
    let f_mid = k * (d - 0.5 * (p + p_new));
    (*z)[slot + NS] += f_mid * (p_new - p);
    (*z)[slot] = p_new;
    SM[s] = select(SM_IMK, SM_ELASTIC, imk_free(s));
}

// RowModel::settled_imk (after settles' test of the levels): each storey on a linear piece
// `f = a + K d` comes to rest where its spring force is gravity's P-Delta shear `g d`, and the
// motion's energy about there bounds its reach; no bilinear storey on a line, no IMKBilin one on
// a piece that flows one way, and each within its rest thresholds (bilinear ones in their bands).
fn imk_settles(z: ptr<function, ZA>) -> bool {
    var e: real = 0.0;
    for (var k = 0u; k < NM; k++) {
        e += 0.5 * (*z)[NM + k] * (*z)[NM + k];
    }
    for (var b = 0u; b < NB; b++) {
        var storeys = false;
        for (var s = 0u; s < NS; s++) {
            if (S_B[s] == b) {
                storeys = true;
            }
        }
        if (!storeys) {
            for (var i = 0u; i < B_N[b]; i++) {
                let k = B_OFF[b] + i;
                e += 0.5 * W2[k] * (*z)[k] * (*z)[k];
            }
        }
    }
    var rest: array<real, NSA>;
    var stiff: array<real, NSA>;
    for (var s = 0u; s < NS; s++) {
        let d = storey_drift(s, z, 0u);
        var a: real = 0.0;
        var slope: real = 0.0;
        if (IS_IMK[s]) {
            if (imk_ir(s, IR_HEADING) != 0.0 && !imk_peak_oriented(s)) {
                return false;
            }
            slope = imk_ir(s, IR_SLOPE);
            a = imk_ir(s, IR_F0) - slope * imk_ir(s, IR_D0);
        } else {
            if (SM[s] != SM_ELASTIC) {
                return false;
            }
            slope = st_k(s);
            a = -st_k(s) * (*z)[PS0 + s];
        }
        let stiffness = slope - st_geo(s);
        if (stiffness <= 0.0) {
            return false;
        }
        rest[s] = -a / stiffness;
        stiff[s] = stiffness;
        e += 0.5 * stiffness * (d - rest[s]) * (d - rest[s]);
    }
    for (var s = 0u; s < NS; s++) {
        let reach = sqrt(2.0 * e / stiff[s]);
        if (IS_IMK[s]) {
            let slack = imk_slack(s);
            var rest_reach = BIG;
            if (imk_peak_oriented(s)) {
                // ImkSpring::rest_reach.
                rest_reach = 1e-4 * imk_ip(s, IP_FY) / imk_ip(s, IP_K);
            }
            if (!(reach <= rest_reach && rest[s] - reach >= imk_ir(s, IR_REST_LO) - slack
                  && rest[s] + reach <= imk_ir(s, IR_REST_HI) + slack)) {
                return false;
            }
        } else if (!(abs(back_drift(s, rest[s], (*z)[PS0 + s])) + reach <= st_dy(s) * (1.0 + YIELD_SLACK))) {
            return false;
        }
    }
    return true;
}

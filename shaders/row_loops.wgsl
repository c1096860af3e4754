// The row kernel's per-shape functions as loops over the shape's tables, for rows too tall to
// write out (src/engine/gpu/row/shape.rs, `RowShape::unrolled`): appended to row.wgsl in place of
// the code `RowShape::wgsl_unrolled` writes for smaller rows, with the same names, operations
// and order (so either gives the same values). Twins: row/mod.rs (LevelModel, Floors::fill),
// row::rhs, yielding.rs (StoreyModel::drift, row::plastic_rhs).

// Nothing to cache: these read the shapes from `models` as they go.
fn load_shape_rows() {}

// A level side's mode-shape row at mode i (BuildingModel::point_row): floor f's, or on a
// column its storey's floors' by their shares.
fn side_shape(b: u32, f: u32, w: real, i: u32) -> real {
    if (w == 1.0) {
        return shape_at(b, f, i);
    }
    var s: real = 0.0;
    if (f > 0u) {
        s = (1.0 - w) * shape_at(b, f - 1u, i);
    }
    return s + w * shape_at(b, f, i);
}

// row . q of a level side, from z at offset `at` (0: displacements, NM: velocities).
fn side_of(b: u32, f: u32, w: real, z: ptr<function, ZA>, at: u32) -> real {
    var s: real = 0.0;
    let o = at + B_OFF[b];
    for (var i = 0u; i < B_N[b]; i++) {
        s += side_shape(b, f, w, i) * (*z)[o + i];
    }
    return s;
}

fn delta(l: u32, z: ptr<function, ZA>) -> real {
    let a = L_A[l];
    return side_of(a, L_FA[l], L_WA[l], z, 0u) - side_of(a + 1u, L_FB[l], L_WB[l], z, 0u) - rp(P_GAPS + a);
}

fn ddelta(l: u32, z: ptr<function, ZA>) -> real {
    let a = L_A[l];
    return side_of(a, L_FA[l], L_WA[l], z, NM) - side_of(a + 1u, L_FB[l], L_WB[l], z, NM);
}

// row::rhs at ground acceleration ag, into `out`.
fn rhs(ag: real, z: ptr<function, ZA>, out: ptr<function, ZA>) {
    for (var i = 0u; i < NM; i++) {
        let v = (*z)[NM + i];
        (*out)[i] = v;
        (*out)[NM + i] = -TXW[i] * v - W2[i] * (*z)[i] - PART[i] * ag;
    }
    if (COUPLED) {
        for (var b = 0u; b < NB; b++) {
            if (coupled(b)) {
                for (var i = 0u; i < B_N[b]; i++) {
                    (*out)[NM + B_OFF[b] + i] -= coupled_term(b, i, z, NM);
                }
            }
        }
    }
    if (NS > 0u) {
        plastic_rhs(z, out);
    }
    for (var l = 0u; l < NL; l++) {
        if (LMODE[l] == MODE_FREE) {
            (*out)[2u * NM + l] = 0.0;
            continue;
        }
        let f = force(l, LMODE[l], LV0[l], z);
        let a = L_A[l];
        let oa = NM + B_OFF[a];
        for (var i = 0u; i < B_N[a]; i++) {
            (*out)[oa + i] -= side_shape(a, L_FA[l], L_WA[l], i) * f;
        }
        let ob = NM + B_OFF[a + 1u];
        for (var i = 0u; i < B_N[a + 1u]; i++) {
            (*out)[ob + i] += side_shape(a + 1u, L_FB[l], L_WB[l], i) * f;
        }
        (*out)[2u * NM + l] = f * ddelta(l, z);
    }
    (*out)[2u * NM + NL] = 0.0;
    (*out)[2u * NM + NL + 1u] = 0.0;
}

// Floors::fill of building b at end e from z at ground acceleration ag, with FF set.
fn fill(b: u32, e: u32, z: ptr<function, ZA>, ag: real) {
    let n = B_N[b];
    let o = B_OFF[b];
    var acc: array<real, MAXN>;
    var jrk: array<real, MAXN>;
    let yields = NS > 0u && B_S0[b] < NS;
    if (yields) {
        plastic_loads(b, z);
    }
    for (var i = 0u; i < n; i++) {
        let k = o + i;
        var a = -TXW[k] * (*z)[NM + k] - W2[k] * (*z)[k];
        if (yields) {
            a += PLA[i];
        }
        acc[i] = a;
        let qdd = a - PART[k] * ag;
        jrk[i] = -TXW[k] * qdd - W2[k] * (*z)[NM + k];
        if (yields) {
            jrk[i] += PLJ[i];
        }
    }
    // Damping that couples the modes: -E q' in the accelerations, -E q'' in the jerks (whose
    // own damping term read the acceleration without it).
    if (coupled(b)) {
        for (var i = 0u; i < n; i++) {
            let ev = coupled_term(b, i, z, NM);
            acc[i] -= ev;
            jrk[i] += TXW[o + i] * ev;
        }
        for (var i = 0u; i < n; i++) {
            var eq: real = 0.0;
            for (var k = 0u; k < n; k++) {
                eq += cpl_e(b, i, k) * (acc[k] - PART[o + k] * ag);
            }
            jrk[i] -= eq;
        }
    }
    for (var j = 0u; j < n; j++) {
        var u: real = 0.0;
        var v: real = 0.0;
        var aa: real = 0.0;
        var je: real = 0.0;
        for (var i = 0u; i < n; i++) {
            let s = shape_at(b, j, i);
            u += s * (*z)[o + i];
            v += s * (*z)[NM + o + i];
            aa += s * acc[i];
            je += s * jrk[i];
        }
        aa = aa + FF[o + j] / mass_at(b, j);
        FL[fli(e, 0u, o + j)] = u;
        FL[fli(e, 1u, o + j)] = v;
        FL[fli(e, 2u, o + j)] = aa - ag;
        FL[fli(e, 3u, o + j)] = aa;
        FL[fli(e, 4u, o + j)] = je;
    }
}

// StoreyModel::drift: the drift (at 0) or its rate (at NM) in state z.
fn storey_drift(s: u32, z: ptr<function, ZA>, at: u32) -> real {
    let b = S_B[s];
    let o = at + B_OFF[b];
    var d: real = 0.0;
    for (var i = 0u; i < B_N[b]; i++) {
        d += st_row(s, i) * (*z)[o + i];
    }
    return d;
}

// row::plastic_rhs: each plastic load on the modal accelerations; while a storey yields, its
// plastic drift rate (1 - b) d' and plastic work rate f p'.
fn plastic_rhs(z: ptr<function, ZA>, out: ptr<function, ZA>) {
    for (var s = 0u; s < NS; s++) {
        let ps = PS0 + s;
        (*out)[ps] = 0.0;
        (*out)[ps + NS] = 0.0;
        let p = (*z)[ps];
        let k = st_k(s);
        let kp = k * p;
        let b = S_B[s];
        let o = NM + B_OFF[b];
        for (var i = 0u; i < B_N[b]; i++) {
            (*out)[o + i] += st_row(s, i) * kp;
        }
        if (SM[s] != SM_ELASTIC) {
            let dp = (1.0 - st_b(s)) * storey_drift(s, z, NM); // !IMK
            let dp = storey_flow(s) * storey_drift(s, z, NM); // IMK
            (*out)[ps] = dp;
            (*out)[ps + NS] = k * (storey_drift(s, z, 0u) - p) * dp;
        }
    }
}

// The structural acceleration of a level side (floor f of building b, weight w) (no ground,
// no contact).
fn floor_accel(b: u32, f: u32, w: real, z: ptr<function, ZA>) -> real {
    var s: real = 0.0;
    let o = B_OFF[b];
    for (var i = 0u; i < B_N[b]; i++) {
        let k = o + i;
        s += side_shape(b, f, w, i) * (-TXW[k] * (*z)[NM + k] - W2[k] * (*z)[k]);
    }
    if (coupled(b)) {
        for (var i = 0u; i < B_N[b]; i++) {
            s -= side_shape(b, f, w, i) * coupled_term(b, i, z, NM);
        }
    }
    return s;
}

fn structural_rel_accel(l: u32, z: ptr<function, ZA>) -> real {
    let a = L_A[l];
    return floor_accel(a, L_FA[l], L_WA[l], z) - floor_accel(a + 1u, L_FB[l], L_WB[l], z);
}

// The fourth-derivative bound of one level side: its modes' bounds (QB) by its row.
fn side_bound(b: u32, f: u32, w: real) -> real {
    var s: real = 0.0;
    let o = B_OFF[b];
    for (var i = 0u; i < B_N[b]; i++) {
        s += abs(side_shape(b, f, w, i)) * QB[o + i];
    }
    return s;
}

fn level_bound(l: u32) -> real {
    let a = L_A[l];
    return side_bound(a, L_FA[l], L_WA[l]) + side_bound(a + 1u, L_FB[l], L_WB[l]);
}

// RowRun::track_buildings: each building's peaks over a piece from z0 to z1.
fn track_buildings(z0: ptr<function, ZA>, z1: ptr<function, ZA>, ag0: real, ag1: real, h: real) {
    if (ENDS_VALID) {
        copy_floor_ends();
    } else {
        set_floor_forces(true);
        for (var b = 0u; b < NB; b++) { fill(b, 0u, z0, ag0); }
    }
    set_floor_forces(false);
    var touched: array<bool, NB>;
    for (var l = 0u; l < NL; l++) {
        if (LMODE[l] != MODE_FREE) {
            touched[L_A[l]] = true;
            touched[L_A[l] + 1u] = true;
        }
    }
    for (var b = 0u; b < NB; b++) { fill(b, 1u, z1, ag1); }
    for (var b = 0u; b < NB; b++) {
        let free = !touched[b];
        let n = B_N[b];
        let o = B_OFF[b];
        let sb = RS + S_BUILDINGS + BS_STRIDE * b;
        let cb = RC + C_BUILDINGS + BC_STRIDE * b;
        let top = o + n - 1u;
        rstate[sb + BS_ROOF] = raise(free, rstate[sb + BS_ROOF],
            FL[fli(0u, 0u, top)], FL[fli(1u, 0u, top)], FL[fli(0u, 1u, top)], FL[fli(1u, 1u, top)],
            FL[fli(0u, 2u, top)], FL[fli(1u, 2u, top)], h);
        var drift = rstate[sb + BS_DRIFT];
        var accel = rstate[sb + BS_ACCEL];
        for (var j = 0u; j < n; j++) {
            let k = o + j;
            // Floor 0 is the ground: it moves with the frame.
            var bu0: real = 0.0; var bu1: real = 0.0; var bv0: real = 0.0; var bv1: real = 0.0;
            var ba0: real = 0.0; var ba1: real = 0.0;
            if (j > 0u) {
                bu0 = FL[fli(0u, 0u, k - 1u)]; bu1 = FL[fli(1u, 0u, k - 1u)];
                bv0 = FL[fli(0u, 1u, k - 1u)]; bv1 = FL[fli(1u, 1u, k - 1u)];
                ba0 = FL[fli(0u, 2u, k - 1u)]; ba1 = FL[fli(1u, 2u, k - 1u)];
            }
            let inv_h = 1.0 / height_at(b, j);
            let y0 = (FL[fli(0u, 0u, k)] - bu0) * inv_h;
            let y1 = (FL[fli(1u, 0u, k)] - bu1) * inv_h;
            let d0 = (FL[fli(0u, 1u, k)] - bv0) * inv_h;
            let d1 = (FL[fli(1u, 1u, k)] - bv1) * inv_h;
            let a0 = (FL[fli(0u, 2u, k)] - ba0) * inv_h;
            let a1 = (FL[fli(1u, 2u, k)] - ba1) * inv_h;
            let p = raise(free, drift, y0, y1, d0, d1, a0, a1, h);
            if (p > drift) {
                drift = p;
                rcount[cb + BC_DRIFT_STOREY] = j + 1u;
            }
            if (NS > 0u) {
                raise_storey(b, j, free, y0, y1, d0, d1, a0, a1, h);
            }
            var pa: real;
            if (free) {
                pa = raise_cubic_peak(accel, FL[fli(0u, 3u, k)], FL[fli(0u, 4u, k)],
                    FL[fli(1u, 3u, k)], FL[fli(1u, 4u, k)], h);
            } else {
                pa = max(max(accel, abs(FL[fli(0u, 3u, k)])), abs(FL[fli(1u, 3u, k)]));
            }
            if (pa > accel) {
                accel = pa;
                rcount[cb + BC_ACCEL_FLOOR] = j + 1u;
            }
        }
        rstate[sb + BS_DRIFT] = drift;
        rstate[sb + BS_ACCEL] = accel;
    }
}

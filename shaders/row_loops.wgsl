// The row kernel's per-shape functions as loops over the shape's tables, for rows too tall to
// write out (src/engine/gpu/row.rs, `RowShape::unrolled`): appended to row.wgsl in place of
// the code `RowShape::wgsl_unrolled` writes for smaller rows, with the same names, operations
// and order (so either gives the same values). Twins: row/mod.rs (LevelModel, Floors::fill),
// row::rhs, yielding.rs (StoreyModel::drift, row::plastic_rhs).

// Nothing to cache: these read the shapes from `models` as they go.
fn load_shape_rows() {}

// phi . q of floor `f` of building `b`, from z at offset `at` (0: displacements, NM: velocities).
fn floor_of(b: u32, f: u32, z: ptr<function, ZA>, at: u32) -> real {
    var s: real = 0.0;
    let o = at + B_OFF[b];
    for (var i = 0u; i < B_N[b]; i++) {
        s += shape_at(b, f, i) * (*z)[o + i];
    }
    return s;
}

fn delta(l: u32, z: ptr<function, ZA>) -> real {
    let a = L_A[l];
    return floor_of(a, L_FA[l], z, 0u) - floor_of(a + 1u, L_FB[l], z, 0u) - rp(P_GAPS + a);
}

fn ddelta(l: u32, z: ptr<function, ZA>) -> real {
    let a = L_A[l];
    return floor_of(a, L_FA[l], z, NM) - floor_of(a + 1u, L_FB[l], z, NM);
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
            (*out)[oa + i] -= shape_at(a, L_FA[l], i) * f;
        }
        let ob = NM + B_OFF[a + 1u];
        for (var i = 0u; i < B_N[a + 1u]; i++) {
            (*out)[ob + i] += shape_at(a + 1u, L_FB[l], i) * f;
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
            let dp = (1.0 - st_b(s)) * storey_drift(s, z, NM);
            (*out)[ps] = dp;
            (*out)[ps + NS] = k * (storey_drift(s, z, 0u) - p) * dp;
        }
    }
}

// The structural acceleration of floor f of building b (no ground, no contact).
fn floor_accel(b: u32, f: u32, z: ptr<function, ZA>) -> real {
    var s: real = 0.0;
    let o = B_OFF[b];
    for (var i = 0u; i < B_N[b]; i++) {
        let k = o + i;
        s += shape_at(b, f, i) * (-TXW[k] * (*z)[NM + k] - W2[k] * (*z)[k]);
    }
    if (coupled(b)) {
        for (var i = 0u; i < B_N[b]; i++) {
            s -= shape_at(b, f, i) * coupled_term(b, i, z, NM);
        }
    }
    return s;
}

fn structural_rel_accel(l: u32, z: ptr<function, ZA>) -> real {
    let a = L_A[l];
    return floor_accel(a, L_FA[l], z) - floor_accel(a + 1u, L_FB[l], z);
}

// The fourth-derivative bound of one side's floor: its modes' bounds (QB) by its mode shape.
fn side_bound(b: u32, f: u32) -> real {
    var s: real = 0.0;
    let o = B_OFF[b];
    for (var i = 0u; i < B_N[b]; i++) {
        s += abs(shape_at(b, f, i)) * QB[o + i];
    }
    return s;
}

fn level_bound(l: u32) -> real {
    let a = L_A[l];
    return side_bound(a, L_FA[l]) + side_bound(a + 1u, L_FB[l]);
}

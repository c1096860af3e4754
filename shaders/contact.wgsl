// Rust twin: src/physics/contact.rs (with solver::impact_step), function for function.
// The contact laws of one contact element, read from the private `K` that each stage sets
// before calling them: once per run for a pair (fast.wgsl), per contact level for a row
// (row.wgsl), so both stages share one copy of the laws.

// Law codes (keep in sync with LawKind::ALL order).
const LAW_LINEAR: u32 = 0u;
const LAW_KELVIN_VOIGT: u32 = 1u;
const LAW_KELVIN_VOIGT_NO_TENSION: u32 = 2u;
const LAW_MODIFIED_LINEAR: u32 = 3u;
const LAW_HERTZ: u32 = 4u;
const LAW_NONLINEAR_VISCOELASTIC: u32 = 5u;
// 6..9: the Hunt-Crossley family.
// contact::HC_V0_MIN, contact::HERTZ floor on v.
const HC_V0_MIN: real = 1e-3;
const V_MIN: real = 1e-6;

// contact::Contact, with the law's code and `tc_coef` (its contact-duration coefficient).
struct Law {
    law: u32,
    stiffness: real,
    damping: real,
    damping_ratio: real,
    m_eff: real,
    tc_coef: real,
}

var<private> K: Law;

fn is_hertzian() -> bool {
    return K.law >= LAW_HERTZ;
}

// LawKind::force_depends_on_phase: damping acts only while the bodies approach.
fn force_depends_on_phase() -> bool {
    return K.law == LAW_MODIFIED_LINEAR || K.law == LAW_NONLINEAR_VISCOELASTIC;
}

fn is_hunt_crossley() -> bool {
    return K.law > LAW_NONLINEAR_VISCOELASTIC;
}

fn chi(v0: real) -> real {
    return K.damping / max(v0, HC_V0_MIN);
}

fn contact_force(d: real, dd: real, v0: real, approaching: bool) -> real {
    let k = K.stiffness;
    let c = K.damping;
    switch K.law {
        case LAW_LINEAR: { return k * d; }
        case LAW_KELVIN_VOIGT, LAW_KELVIN_VOIGT_NO_TENSION: { return k * d + c * dd; }
        case LAW_MODIFIED_LINEAR: {
            var f = k * d;
            if (approaching) { f = f + c * dd; }
            return f;
        }
        case LAW_HERTZ: { return k * d * sqrt(abs(d)); }
        case LAW_NONLINEAR_VISCOELASTIC: {
            let r = sqrt(abs(d));
            var f = k * d * r;
            if (approaching) { f = f + c * sqrt(r) * dd; }
            return f;
        }
        default: { return k * d * sqrt(abs(d)) * (1.0 + chi(v0) * dd); }
    }
}

// Contact::force_rate: the rate of contact_force along a motion with penetration rate dd and
// acceleration ddd, on the same branch.
fn contact_force_rate(d: real, dd: real, ddd: real, v0: real, approaching: bool) -> real {
    let k = K.stiffness;
    let c = K.damping;
    switch K.law {
        case LAW_LINEAR: { return k * dd; }
        case LAW_KELVIN_VOIGT, LAW_KELVIN_VOIGT_NO_TENSION: { return k * dd + c * ddd; }
        case LAW_MODIFIED_LINEAR: {
            var r = k * dd;
            if (approaching) { r = r + c * ddd; }
            return r;
        }
        case LAW_HERTZ: { return 1.5 * k * sqrt(abs(d)) * dd; }
        case LAW_NONLINEAR_VISCOELASTIC: {
            let r = sqrt(abs(d));
            var rate = 1.5 * k * r * dd;
            if (approaching && r > 0.0) {
                let q = sqrt(r);
                rate = rate + c * (0.25 * dd * dd / (r * q) + q * ddd);
            }
            return rate;
        }
        default: {
            let r = sqrt(abs(d));
            let x = chi(v0);
            return k * r * (1.5 * dd * (1.0 + x * dd) + d * x * ddd);
        }
    }
}

fn gauge(d: real, dd: real, v0: real) -> real {
    if (K.law == LAW_KELVIN_VOIGT_NO_TENSION) {
        return d + min(K.damping / K.stiffness * dd, 0.0);
    }
    if (is_hunt_crossley() && d > 0.0) {
        return d * min(1.0 + chi(v0) * dd, 1.0);
    }
    return d;
}

fn local_rate(delta: real, v0: real) -> real {
    let d = max(delta, 0.0);
    let k = K.stiffness;
    let c = K.damping;
    var kl = k;
    var cl: real = 0.0;
    switch K.law {
        case LAW_LINEAR: {}
        case LAW_KELVIN_VOIGT, LAW_KELVIN_VOIGT_NO_TENSION, LAW_MODIFIED_LINEAR: { cl = c; }
        case LAW_HERTZ: { kl = 1.5 * k * sqrt(d); }
        case LAW_NONLINEAR_VISCOELASTIC: { kl = 1.5 * k * sqrt(d); cl = c * sqrt(sqrt(d)); }
        default: { kl = 1.5 * k * sqrt(d); cl = k * d * sqrt(d) * chi(v0); }
    }
    return sqrt(kl / K.m_eff) + cl / K.m_eff;
}

// Two Newton steps, unrolled (every loop iteration counts against lavapipe's limiter).
fn inv_fifth_root(v: real) -> real {
    var y = real(pow(f32(v), -0.2));
    var y2 = y * y;
    y = y * (6.0 - v * (y2 * y2 * y)) / 5.0;
    y2 = y * y;
    y = y * (6.0 - v * (y2 * y2 * y)) / 5.0;
    return y;
}

fn duration_estimate(v: real) -> real {
    if (is_hertzian()) {
        return K.tc_coef * inv_fifth_root(max(v, V_MIN));
    }
    return K.tc_coef;
}

// Contact::onset_cut: from `elapsed` since the onset (approaching) to the first point of the
// graded mesh tc (k / N)^4 more than `tol` ahead; "infinite" (a huge step) where the law needs
// none.
fn onset_cut(elapsed: real, v0: real, per_contact: real, tol: real) -> real {
    if (K.law != LAW_NONLINEAR_VISCOELASTIC) {
        return BIG;
    }
    let tc = duration_estimate(v0);
    var k = ceil(per_contact * sqrt(sqrt((max(elapsed, 0.0) + tol) / tc)));
    for (var i = 0u; i < 3u; i++) {
        let s = k / per_contact;
        let cut = tc * (s * s) * (s * s) - elapsed;
        if (cut > tol) {
            return cut;
        }
        k = k + 1.0;
    }
    return BIG;
}

// solver::impact_step, `per_contact` substeps per impact.
fn impact_step(v: real, a: real, per_contact: real) -> real {
    let tc = duration_estimate(v);
    var t = tc;
    if (a != 0.0) {
        t = min(tc, max(2.0 * v / abs(a), tc / 16.0));
    }
    return t / (per_contact * (1.0 + 2.0 * K.damping_ratio));
}

// Rust twin: src/physics/solver/hermite.rs (with the pure helpers of events.rs and tracker.rs),
// function for function: interpolation inside a step, shared by fast.wgsl and row.wgsl.

struct Range { lo: real, hi: real }

fn hermite_eval(y0: real, m0: real, b: real, c: real, s: real) -> real {
    return y0 + s * (m0 + s * (b + s * c));
}

fn range_check(r: Range, y0: real, m0: real, b: real, c: real, s: real) -> Range {
    var o = r;
    if (s > 0.0 && s < 1.0) {
        let v = hermite_eval(y0, m0, b, c, s);
        o.lo = min(o.lo, v);
        o.hi = max(o.hi, v);
    }
    return o;
}

fn hermite_range(y0: real, d0: real, y1: real, d1: real, h: real) -> Range {
    let m0 = h * d0;
    let m1 = h * d1;
    let b = 3.0 * (y1 - y0) - 2.0 * m0 - m1;
    let c = 2.0 * (y0 - y1) + m0 + m1;
    var r = Range(min(y0, y1), max(y0, y1));
    let ex = hermite_extrema(m0, b, c);
    r = range_check(r, y0, m0, b, c, ex[0]);
    r = range_check(r, y0, m0, b, c, ex[1]);
    return r;
}

// cpu::hermite_extrema: roots of m0 + 2 b s + 3 c s^2 by the stable formula, -1 where none.
fn hermite_extrema(m0: real, b: real, c: real) -> array<real, 2> {
    let qa = 3.0 * c;
    let qb = 2.0 * b;
    let qc = m0;
    if (abs(qa) < TINY) {
        if (qb != 0.0) {
            return array<real, 2>(-qc / qb, -1.0);
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if (disc >= 0.0) {
            // Rust's signum: +1 for +0.
            var sg: real = 1.0;
            if (qb < 0.0) { sg = -1.0; }
            let q = -0.5 * (qb + sg * sqrt(disc));
            if (q != 0.0) {
                return array<real, 2>(q / qa, qc / q);
            }
        }
    }
    return array<real, 2>(-1.0, -1.0);
}

// cpu::quintic_peak_abs: largest |y| over [0, h] of the quintic Hermite through (y, y', y'')
// at both ends; each cubic extremum inside the step refined by three Newton steps.
fn quintic_peak_abs(y0: real, y1: real, d0: real, d1: real, a0: real, a1: real, h: real) -> real {
    let m0 = h * d0;
    let m1 = h * d1;
    let q0 = h * h * a0;
    let q1 = h * h * a1;
    let dy = y1 - y0;
    let c2 = 0.5 * q0;
    let c3 = 10.0 * dy - 6.0 * m0 - 4.0 * m1 - 1.5 * q0 + 0.5 * q1;
    let c4 = -15.0 * dy + 8.0 * m0 + 7.0 * m1 + 1.5 * q0 - q1;
    let c5 = 6.0 * dy - 3.0 * m0 - 3.0 * m1 - 0.5 * q0 + 0.5 * q1;
    var peak = max(abs(y0), abs(y1));
    let b = 3.0 * dy - 2.0 * m0 - m1;
    let c = -2.0 * dy + m0 + m1;
    var roots = hermite_extrema(m0, b, c);
    // Unrolled: two candidates, three Newton steps each (no long loops on lavapipe).
    for (var k = 0u; k < 2u; k = k + 1u) {
        let s0 = roots[k];
        if (s0 > 0.0 && s0 < 1.0) {
            var s = s0;
            for (var it = 0u; it < 3u; it = it + 1u) {
                let g1 = m0 + s * (2.0 * c2 + s * (3.0 * c3 + s * (4.0 * c4 + s * 5.0 * c5)));
                let g2 = 2.0 * c2 + s * (6.0 * c3 + s * (12.0 * c4 + s * 20.0 * c5));
                if (g2 != 0.0) {
                    s = clamp(s - g1 / g2, 0.0, 1.0);
                }
            }
            let v = y0 + s * (m0 + s * (c2 + s * (c3 + s * (c4 + s * c5))));
            peak = max(peak, abs(v));
        }
    }
    return peak;
}

fn fourth_derivative_bound(m: real, k: real, c: real, u: real, v: real, seg: Seg) -> real {
    let w2 = k / m;
    let cm = c / m;
    let a2 = w2 * u + cm * v + max(abs(seg.a0), abs(seg.a1));
    let a3 = w2 * v + cm * a2 + abs((seg.a1 - seg.a0) / seg.dt);
    return w2 * a2 + cm * a3;
}

// events::hidden_rise: the fraction of the step at the highest point of the Hermite cubic
// through (y0, d0), (y1, d1) if it rises above 0 inside the step while y1 <= 0; -1 if not.
fn hidden_rise(y0: real, d0: real, y1: real, d1: real, h: real) -> real {
    if (y1 > 0.0 || (d0 <= 0.0 && d1 >= 0.0)) {
        return -1.0;
    }
    let m0 = h * d0;
    let m1 = h * d1;
    let b = 3.0 * (y1 - y0) - 2.0 * m0 - m1;
    let c = 2.0 * (y0 - y1) + m0 + m1;
    let qa = 3.0 * c;
    let qb = 2.0 * b;
    let qc = m0;
    var best_v: real = 0.0;
    var best_s: real = -1.0;
    let disc = qb * qb - 4.0 * qa * qc;
    if (abs(qa) > TINY && disc >= 0.0) {
        let r = sqrt(disc);
        // Both roots, unrolled.
        let s1 = (-qb + r) / (2.0 * qa);
        if (s1 > 0.0 && s1 < 1.0) {
            let v = y0 + s1 * (m0 + s1 * (b + s1 * c));
            if (v > 0.0) {
                best_v = v;
                best_s = s1;
            }
        }
        let s2 = (-qb - r) / (2.0 * qa);
        if (s2 > 0.0 && s2 < 1.0) {
            let v = y0 + s2 * (m0 + s2 * (b + s2 * c));
            if (v > 0.0 && (best_s < 0.0 || v > best_v)) {
                best_v = v;
                best_s = s2;
            }
        }
    }
    return best_s;
}

// hermite.rs: bounds on the Hermite interpolants that let a step skip a peak search.
const CUBIC_SLOPE_WEIGHT: real = 0.14814814814814814;
const QUINTIC_SLOPE_WEIGHT: real = 0.19753086419753085;
const QUINTIC_CURVATURE_WEIGHT: real = 0.01728;
const BOUND_SLACK: real = 1.000000001;

fn cubic_max_bound(y0: real, d0: real, y1: real, d1: real, h: real) -> real {
    let m = CUBIC_SLOPE_WEIGHT * h * (abs(d0) + abs(d1));
    let top = max(y0, y1) + m;
    return top + (abs(top) + m) * (BOUND_SLACK - 1.0);
}

fn raise_cubic_peak(peak: real, y0: real, d0: real, y1: real, d1: real, h: real) -> real {
    let m = CUBIC_SLOPE_WEIGHT * h * (abs(d0) + abs(d1));
    if ((max(abs(y0), abs(y1)) + m) * BOUND_SLACK <= peak) {
        return peak;
    }
    let r = hermite_range(y0, d0, y1, d1, h);
    return max(max(peak, abs(r.hi)), abs(r.lo));
}

fn quintic_max_bound(y0: real, y1: real, d0: real, d1: real, a0: real, a1: real, h: real) -> real {
    return max(abs(y0), abs(y1)) + QUINTIC_SLOPE_WEIGHT * h * (abs(d0) + abs(d1))
        + QUINTIC_CURVATURE_WEIGHT * h * h * (abs(a0) + abs(a1));
}

fn raise_quintic_peak(peak: real, y0: real, y1: real, d0: real, d1: real, a0: real, a1: real, h: real) -> real {
    if (quintic_max_bound(y0, y1, d0, d1, a0, a1, h) * BOUND_SLACK <= peak) {
        return peak;
    }
    return max(peak, quintic_peak_abs(y0, y1, d0, d1, a0, a1, h));
}

// events::error_margin: twice the cubic Hermite's interpolation error bound over a step of h
// for a fourth derivative bounded by `bound`.
fn error_margin(bound: real, h: real) -> real {
    let h2 = h * h;
    return 2.0 * h2 * h2 / 384.0 * bound;
}

// tracker::raise_force_peak: peak raised to the force f1 at a contact piece's end and, where
// the force rises at its start (r0 > 0) and falls at its end (r1 < 0), to the largest value of
// the cubic Hermite through both ends' forces and rates.
fn raise_force_peak(peak: real, f0: real, r0: real, f1: real, r1: real, h: real) -> real {
    var p = max(peak, f1);
    if (r1 < 0.0 && r0 > 0.0) {
        p = max(p, hermite_range(f0, r0, f1, r1, h).hi);
    }
    return p;
}

// hermite::raise_hump_peak: the ends' |y|, and the cubic's largest |y| where |y| rises at the
// start and falls at the end (a hump inside, on one side of 0).
fn raise_hump_peak(peak: real, y0: real, d0: real, y1: real, d1: real, h: real) -> real {
    var p = max(peak, max(abs(y0), abs(y1)));
    if (y0 * d0 > 0.0 && y1 * d1 < 0.0 && y0 * y1 > 0.0) {
        let r = hermite_range(y0, d0, y1, d1, h);
        p = max(p, max(abs(r.hi), abs(r.lo)));
    }
    return p;
}

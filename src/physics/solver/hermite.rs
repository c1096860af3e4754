//! Hermite interpolation inside a step: the range of the contact gap and the peak displacement
//! between the states the solvers keep.

/// Min and max over `[0, h]` of the cubic Hermite through `(y0, y0')` and `(y1, y1')`.
#[inline]
pub(crate) fn hermite_range(y0: f64, d0: f64, y1: f64, d1: f64, h: f64) -> (f64, f64) {
    let (m0, m1) = (h * d0, h * d1);
    let b = 3.0 * (y1 - y0) - 2.0 * m0 - m1;
    let c = 2.0 * (y0 - y1) + m0 + m1;
    let p = |s: f64| y0 + s * (m0 + s * (b + s * c));
    let (mut lo, mut hi) = (y0.min(y1), y0.max(y1));
    for s in hermite_extrema(m0, b, c) {
        if s > 0.0 && s < 1.0 {
            let v = p(s);
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    (lo, hi)
}

/// Where the cubic Hermite `y0 + s (m0 + s (b + s c))` may have extrema: the roots of
/// `p'(s) = m0 + 2 b s + 3 c s^2` by the stable formula, -1 where there is none. Callers keep
/// those in `(0, 1)`.
#[inline]
pub(crate) fn hermite_extrema(m0: f64, b: f64, c: f64) -> [f64; 2] {
    let (qa, qb, qc) = (3.0 * c, 2.0 * b, m0);
    if qa.abs() < 1e-300 {
        if qb != 0.0 {
            return [-qc / qb, -1.0];
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let q = -0.5 * (qb + qb.signum() * disc.sqrt());
            if q != 0.0 {
                return [q / qa, qc / q];
            }
        }
    }
    [-1.0, -1.0]
}

/// Slope weights of the cubic Hermite basis are at most 4/27 in magnitude (at s = 1/3, 2/3);
/// the quintic's at most 16/81 and its curvature weights at most 54/3125. The position weights
/// of both lie in [0, 1] and sum to 1. So `max|y|` over a step is at most the larger end plus
/// these times the ends' scaled slopes (and curvatures): a bound that lets a step that cannot
/// raise a peak skip the search for it. The factor covers rounding in the searched value.
pub(crate) const CUBIC_SLOPE_WEIGHT: f64 = 4.0 / 27.0;
const QUINTIC_SLOPE_WEIGHT: f64 = 16.0 / 81.0;
const QUINTIC_CURVATURE_WEIGHT: f64 = 54.0 / 3125.0;
const BOUND_SLACK: f64 = 1.0 + 1e-9;

/// Upper bound on the cubic Hermite through `(y0, y0')`, `(y1, y1')` over `[0, h]`.
#[inline]
pub(crate) fn cubic_max_bound(y0: f64, d0: f64, y1: f64, d1: f64, h: f64) -> f64 {
    let m = CUBIC_SLOPE_WEIGHT * h * (d0.abs() + d1.abs());
    let top = y0.max(y1) + m;
    top + (top.abs() + m) * (BOUND_SLACK - 1.0)
}

/// Upper bound on `|y|` of the cubic Hermite through `(y0, y0')`, `(y1, y1')` over `[0, h]`
/// (without the rounding slack [`raise_cubic_peak`] adds).
#[inline]
pub(crate) fn cubic_abs_bound(y0: f64, d0: f64, y1: f64, d1: f64, h: f64) -> f64 {
    y0.abs().max(y1.abs()) + CUBIC_SLOPE_WEIGHT * h * (d0.abs() + d1.abs())
}

/// `peak` raised to the largest `|y|` of the cubic Hermite over `[0, h]` (the search skipped
/// when the cubic cannot reach `peak`).
#[inline]
pub(crate) fn raise_cubic_peak(peak: f64, y0: f64, d0: f64, y1: f64, d1: f64, h: f64) -> f64 {
    if cubic_abs_bound(y0, d0, y1, d1, h) * BOUND_SLACK <= peak {
        return peak;
    }
    let (lo, hi) = hermite_range(y0, d0, y1, d1, h);
    peak.max(hi.abs()).max(lo.abs())
}

/// `peak` raised to `|y|` at both ends of a piece and, where `|y|` rises at its start and falls
/// at its end (a hump inside, on one side of 0), to the largest `|y|` of the cubic Hermite
/// through both ends' values and rates. As `tracker::raise_force_peak`, for a quantity whose
/// rate may be unbounded at an end where nothing peaks (a contact force's at first touch).
#[inline]
pub(crate) fn raise_hump_peak(peak: f64, y0: f64, d0: f64, y1: f64, d1: f64, h: f64) -> f64 {
    let peak = peak.max(y0.abs()).max(y1.abs());
    if y0 * d0 > 0.0 && y1 * d1 < 0.0 && y0 * y1 > 0.0 {
        let (lo, hi) = hermite_range(y0, d0, y1, d1, h);
        peak.max(hi.abs()).max(lo.abs())
    } else {
        peak
    }
}

/// Upper bound on `|y|` of the quintic Hermite through `(y, y', y'')` at both ends over `[0, h]`.
#[inline]
pub(crate) fn quintic_max_bound(y: [f64; 2], d: [f64; 2], a: [f64; 2], h: f64) -> f64 {
    y[0].abs().max(y[1].abs())
        + QUINTIC_SLOPE_WEIGHT * h * (d[0].abs() + d[1].abs())
        + QUINTIC_CURVATURE_WEIGHT * h * h * (a[0].abs() + a[1].abs())
}

/// `peak` raised to [`quintic_peak_abs`] (the search skipped when the quintic cannot reach
/// `peak`).
#[inline]
pub(crate) fn raise_quintic_peak(peak: f64, y: [f64; 2], d: [f64; 2], a: [f64; 2], h: f64) -> f64 {
    if quintic_max_bound(y, d, a, h) * BOUND_SLACK <= peak {
        return peak;
    }
    peak.max(quintic_peak_abs(y, d, a, h))
}

/// Largest `|y|` over `[0, h]` of the quintic Hermite through `(y, y', y'')` at both ends.
/// Used for peak displacements over free record steps, where the cubic's error,
/// `(omega h)^4 / 384`, reaches 5e-3 at `omega h` = 1.3; the quintic's is about
/// `(omega h)^6 / 46080`. Its extrema lie near the cubic's: each cubic extremum inside the step
/// is refined by three Newton steps on the quintic's derivative.
#[inline]
pub(crate) fn quintic_peak_abs(y: [f64; 2], d: [f64; 2], a: [f64; 2], h: f64) -> f64 {
    let mut peak = y[0].abs().max(y[1].abs());
    for (_, v) in quintic_interior(y, d, a, h).into_iter().flatten() {
        peak = peak.max(v.abs());
    }
    peak
}

/// Min and max over `[0, h]` of the quintic Hermite through `(y, y', y'')` at both ends, each
/// with where it lies as a fraction `s` of the step: `[(lo, s_lo), (hi, s_hi)]`.
#[inline]
pub(crate) fn quintic_range(y: [f64; 2], d: [f64; 2], a: [f64; 2], h: f64) -> [(f64, f64); 2] {
    let (mut lo, mut hi) = if y[0] <= y[1] {
        ((y[0], 0.0), (y[1], 1.0))
    } else {
        ((y[1], 1.0), (y[0], 0.0))
    };
    for (s, v) in quintic_interior(y, d, a, h).into_iter().flatten() {
        if v < lo.0 {
            lo = (v, s);
        }
        if v > hi.0 {
            hi = (v, s);
        }
    }
    [lo, hi]
}

/// The quintic Hermite's extrema inside the step, `(s, value)`: each extremum of the cubic
/// Hermite inside it, refined by three Newton steps on the quintic's derivative.
#[inline(always)]
fn quintic_interior(y: [f64; 2], d: [f64; 2], a: [f64; 2], h: f64) -> [Option<(f64, f64)>; 2] {
    let (m0, m1, q0, q1) = (h * d[0], h * d[1], h * h * a[0], h * h * a[1]);
    let dy = y[1] - y[0];
    let b = 3.0 * dy - 2.0 * m0 - m1;
    let c = -2.0 * dy + m0 + m1;
    let starts = hermite_extrema(m0, b, c);
    let inside = |s: f64| s > 0.0 && s < 1.0;
    let mut out = [None, None];
    if !inside(starts[0]) && !inside(starts[1]) {
        return out;
    }
    let c2 = 0.5 * q0;
    let c3 = 10.0 * dy - 6.0 * m0 - 4.0 * m1 - 1.5 * q0 + 0.5 * q1;
    let c4 = -15.0 * dy + 8.0 * m0 + 7.0 * m1 + 1.5 * q0 - q1;
    let c5 = 6.0 * dy - 3.0 * m0 - 3.0 * m1 - 0.5 * q0 + 0.5 * q1;
    for (o, s0) in out.iter_mut().zip(starts) {
        if !inside(s0) {
            continue;
        }
        let mut s = s0;
        for _ in 0..3 {
            let d1 = m0 + s * (2.0 * c2 + s * (3.0 * c3 + s * (4.0 * c4 + s * 5.0 * c5)));
            let d2 = 2.0 * c2 + s * (6.0 * c3 + s * (12.0 * c4 + s * 20.0 * c5));
            if d2 != 0.0 {
                s = (s - d1 / d2).clamp(0.0, 1.0);
            }
        }
        *o = Some((s, y[0] + s * (m0 + s * (c2 + s * (c3 + s * (c4 + s * c5))))));
    }
    out
}

/// Upper bound on the quintic Hermite through `(y, y', y'')` at both ends over `[0, h]`
/// (and, negated, a lower bound): [`quintic_max_bound`] without the absolute values of `y`.
#[inline]
pub(crate) fn quintic_signed_bounds(y: [f64; 2], d: [f64; 2], a: [f64; 2], h: f64) -> (f64, f64) {
    let m = QUINTIC_SLOPE_WEIGHT * h * (d[0].abs() + d[1].abs())
        + QUINTIC_CURVATURE_WEIGHT * h * h * (a[0].abs() + a[1].abs());
    (y[0].min(y[1]) - m, y[0].max(y[1]) + m)
}

#[cfg(test)]
mod tests {
    use super::{quintic_peak_abs, raise_hump_peak};

    /// A hump inside a piece, on either side of 0, is the cubic's (exact for a quadratic); a
    /// piece that rises throughout, however steeply at its start (a force's rate at first
    /// touch), raises the peak only to its ends.
    #[test]
    fn a_hump_is_searched_only_where_it_rises_then_falls() {
        let f = |t: f64| 2.0 - (t - 0.3) * (t - 0.3);
        let r = |t: f64| -2.0 * (t - 0.3);
        let p = raise_hump_peak(0.0, f(0.0), r(0.0), f(1.0), r(1.0), 1.0);
        assert!((p - 2.0).abs() < 1e-15, "{p}");
        let p = raise_hump_peak(0.0, -f(0.0), -r(0.0), -f(1.0), -r(1.0), 1.0);
        assert!((p - 2.0).abs() < 1e-15, "{p}");
        assert_eq!(raise_hump_peak(0.5, 0.0, 1e12, 1.0, 0.5, 1.0), 1.0);
        assert_eq!(raise_hump_peak(3.0, 1.0, 1.0, 2.0, -1.0, 1.0), 3.0);
    }

    /// Exact for a quintic, and within its error bound `(omega h)^6 / 46080` for a sine whose
    /// crest lies inside the step (where the cubic Hermite is off by up to `(omega h)^4 / 384`).
    #[test]
    fn quintic_peak_is_exact_for_quintics_and_tight_for_sines() {
        let p = |t: f64| 0.3 + t * (1.0 + t * (-2.0 + t * (0.5 + t * (0.2 - 0.1 * t))));
        let dp = |t: f64| 1.0 + t * (-4.0 + t * (1.5 + t * (0.8 - 0.5 * t)));
        let ddp = |t: f64| -4.0 + t * (3.0 + t * (2.4 - 2.0 * t));
        let h = 1.0;
        let exact = (0..=100_000)
            .map(|i| p(i as f64 * 1e-5).abs())
            .fold(0.0, f64::max);
        let got = quintic_peak_abs([p(0.0), p(h)], [dp(0.0), dp(h)], [ddp(0.0), ddp(h)], h);
        assert!((got - exact).abs() < 1e-9, "{got} vs {exact}");
        for wh in [0.3f64, 0.8, 1.3] {
            // Step [1.2, 2.2]: the crest pi / (2 w) lies inside for w = 0.8 and 1.3, not 0.3.
            let (w, t0) = (wh, 1.2);
            let t1 = t0 + 1.0;
            let y = |t: f64| (w * t).sin();
            let got = quintic_peak_abs(
                [y(t0), y(t1)],
                [w * (w * t0).cos(), w * (w * t1).cos()],
                [-w * w * y(t0), -w * w * y(t1)],
                1.0,
            );
            let truth = if (t0..t1).contains(&(std::f64::consts::FRAC_PI_2 / w)) {
                1.0
            } else {
                y(t0).abs().max(y(t1).abs())
            };
            assert!(
                (got - truth).abs() <= wh.powi(6) / 46080.0 * 2.0 + 1e-15,
                "omega h = {wh}: {got} vs {truth}"
            );
        }
    }
}

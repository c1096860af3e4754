//! Intensity measures of a record (`shared/docs/physics.md` section 9), with the record linear
//! between its samples and every response from rest:
//!
//! - `Sa(T, xi)`: pseudo-spectral acceleration `w^2 max_t |u(t)|` of the linear oscillator
//!   `u'' + 2 xi w u' + w^2 u = -ag(t)`, stepped with the exact propagator (Nigam-Jennings) on
//!   substeps of at most `T / 32` (`ag` is linear there too, so they are exact as well); a peak
//!   between substep ends is located where the velocity changes sign, by Newton steps on the
//!   exact solution, so the peak is the response's own, not a sample's.
//! - `Sa_avg(Ta..Tb)`: the geometric mean of `Sa` at `n` periods spaced evenly in log.
//! - PGV and PGD: the velocity and displacement of the ground, integrated exactly from the
//!   piecewise-linear acceleration (the trapezoid rule for the velocity is exact then), from
//!   rest and with no baseline correction; peaks between samples are included.
//! - Arias intensity `I_a = pi / (2 g) * integral ag^2 dt` and CAV `integral |ag| dt` (both
//!   m/s): integrated exactly for the piecewise-linear acceleration (`|ag|` split at the zero
//!   of a step whose samples change sign).

use super::Record;
use crate::physics::model::Oscillator;
use crate::physics::propagator::Propagator;
use crate::physics::solver::hermite::quintic_max_bound;

/// The damping ratio of a response spectrum unless stated.
pub const DEFAULT_DAMPING: f64 = 0.05;

/// Substeps per period of the oscillator (at least): with fewer than a quarter period per
/// substep, the velocity changes sign at most once in one for all but grazing extrema.
const SUBSTEPS_PER_PERIOD: f64 = 32.0;

/// Relative slack on the bound that lets an extremum below the peak skip its search.
const SEARCH_SLACK: f64 = 1e-6;

/// The oscillator's peak `|u|` (m) under `rec`, from rest, over the record (no free tail).
pub fn peak_displacement(rec: &Record, period: f64, xi: f64) -> f64 {
    peak_searched(rec, period, xi, false)
}

/// [`peak_displacement`], locating every extremum inside a substep where `every_extremum`
/// (not only those whose bound reaches the peak so far): the same value, slower.
fn peak_searched(rec: &Record, period: f64, xi: f64, every_extremum: bool) -> f64 {
    let o = Oscillator::from_period(1.0, period, xi);
    let parts = (rec.dt * SUBSTEPS_PER_PERIOD / period).ceil().max(1.0) as usize;
    let h = rec.dt / parts as f64;
    let step = Propagator::new(&o, h);
    let (w2, c) = (o.k, o.c);
    let (mut u, mut v) = (0.0f64, 0.0f64);
    let mut peak = 0.0f64;
    for pair in rec.accel.windows(2) {
        let (a0, a1) = (pair[0], pair[1]);
        for k in 0..parts {
            let (b0, b1) = (
                a0 + (a1 - a0) * k as f64 / parts as f64,
                a0 + (a1 - a0) * (k + 1) as f64 / parts as f64,
            );
            let (u1, v1) = step.step(u, v, b0, b1);
            // An extremum inside, worth locating only where it may pass the peak: the quintic
            // Hermite through both ends' u, v and u'' bounds |u| over the substep (the exact
            // solution lies within (w h)^6 / 46080 of the amplitude of it, 1.2e-9 at T / 32;
            // the slack covers it). Most extrema lie below the peak and skip the Newton steps
            // below, each a propagator of its own (exponential, sine and cosine).
            let may_pass = || {
                if every_extremum {
                    return true;
                }
                let acc = [-w2 * u - c * v - b0, -w2 * u1 - c * v1 - b1];
                quintic_max_bound([u, u1], [v, v1], acc, h) * (1.0 + SEARCH_SLACK) >= peak
            };
            if v * v1 < 0.0 && may_pass() {
                // The root of v, from the linear guess, refined by Newton on the exact
                // solution (v' = -w^2 u - c v - ag).
                let at = |tau: f64| {
                    let ag = b0 + (b1 - b0) * tau / h;
                    let (ut, vt) = Propagator::new(&o, tau).step(u, v, b0, ag);
                    (ut, vt, -w2 * ut - c * vt - ag)
                };
                let mut tau = h * v / (v - v1);
                let mut best = at(tau);
                for _ in 0..4 {
                    let (_, vt, acc) = best;
                    if acc == 0.0 {
                        break;
                    }
                    let next = (tau - vt / acc).clamp(0.0, h);
                    if next == tau {
                        break;
                    }
                    tau = next;
                    best = at(tau);
                }
                peak = peak.max(best.0.abs());
            }
            peak = peak.max(u1.abs());
            (u, v) = (u1, v1);
        }
    }
    peak
}

/// `Sa(T, xi)`, m/s^2: `w^2` times the peak displacement.
pub fn sa(rec: &Record, period: f64, xi: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI / period;
    w * w * peak_displacement(rec, period, xi)
}

/// `n` periods from `from` to `to`, evenly spaced in log (one period where `n` is 1).
pub fn log_periods(from: f64, to: f64, n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![from];
    }
    let (a, b) = (from.ln(), to.ln());
    (0..n)
        .map(|i| {
            if i == 0 {
                from
            } else if i + 1 == n {
                to
            } else {
                (a + (b - a) * i as f64 / (n - 1) as f64).exp()
            }
        })
        .collect()
}

/// `Sa_avg`, m/s^2: the geometric mean of `Sa` at `periods`.
pub fn sa_avg(rec: &Record, periods: &[f64], xi: f64) -> f64 {
    let logs: f64 = periods.iter().map(|&t| sa(rec, t, xi).ln()).sum();
    (logs / periods.len().max(1) as f64).exp()
}

/// Peak ground velocity (m/s) and displacement (m) ([module docs](self)).
pub fn pgv_pgd(rec: &Record) -> (f64, f64) {
    let h = rec.dt;
    let (mut v, mut d) = (0.0f64, 0.0f64);
    let (mut pgv, mut pgd) = (0.0f64, 0.0f64);
    // Over a step, a = a0 + s t, v = v0 + a0 t + s t^2 / 2, d = d0 + v0 t + a0 t^2 / 2 + s t^3 / 6.
    for pair in rec.accel.windows(2) {
        let (a0, a1) = (pair[0], pair[1]);
        let s = (a1 - a0) / h;
        let vel = |t: f64| v + a0 * t + 0.5 * s * t * t;
        let disp = |t: f64| d + v * t + 0.5 * a0 * t * t + s * t * t * t / 6.0;
        // Velocity peaks where a = 0 inside the step.
        if a0 * a1 < 0.0 {
            pgv = pgv.max(vel(-a0 / s).abs());
        }
        // Displacement peaks where v = 0 inside the step: the roots of the quadratic.
        let roots: Vec<f64> = if s == 0.0 {
            if a0 != 0.0 {
                vec![-v / a0]
            } else {
                vec![]
            }
        } else {
            let disc = a0 * a0 - 2.0 * s * v;
            if disc < 0.0 {
                vec![]
            } else {
                let r = disc.sqrt();
                vec![(-a0 - r) / s, (-a0 + r) / s]
            }
        };
        for t in roots.into_iter().filter(|t| *t > 0.0 && *t < h) {
            pgd = pgd.max(disp(t).abs());
        }
        (v, d) = (vel(h), disp(h));
        pgv = pgv.max(v.abs());
        pgd = pgd.max(d.abs());
    }
    (pgv, pgd)
}

/// Arias intensity `pi / (2 g) * integral ag^2 dt` and cumulative absolute velocity
/// `integral |ag| dt` (both m/s) over the record's samples ([module docs](self)): exact for the
/// acceleration linear between samples.
pub fn arias_cav(rec: &Record) -> (f64, f64) {
    let h = rec.dt;
    let (mut squares, mut absolute) = (0.0f64, 0.0f64);
    for pair in rec.accel.windows(2) {
        let (a0, a1) = (pair[0], pair[1]);
        // Over a step, a = a0 + (a1 - a0) t / h: integral a^2 = h (a0^2 + a0 a1 + a1^2) / 3.
        squares += h * (a0 * a0 + a0 * a1 + a1 * a1) / 3.0;
        let (b0, b1) = (a0.abs(), a1.abs());
        absolute += if a0 * a1 < 0.0 {
            // Two triangles either side of the zero at t = h b0 / (b0 + b1).
            0.5 * h * (b0 * b0 + b1 * b1) / (b0 + b1)
        } else {
            0.5 * h * (b0 + b1)
        };
    }
    (std::f64::consts::PI / (2.0 * super::G) * squares, absolute)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(dt: f64, accel: Vec<f64>) -> Record {
        Record {
            name: "test".into(),
            dt,
            t0: 0.0,
            accel,
        }
    }

    /// A step `ag = A` from t = 0: `Sa = A (1 + exp(-xi pi / sqrt(1 - xi^2)))`, the first
    /// overshoot, which falls between samples for every period here.
    #[test]
    fn step_gives_the_first_overshoot() {
        let a = 2.5;
        for (period, xi, dt) in [(1.0, 0.05, 0.01), (0.37, 0.02, 0.02), (2.3, 0.1, 0.013)] {
            let rec = record(dt, vec![a; (3.0 * period / dt) as usize]);
            let want = a * (1.0 + (-xi * std::f64::consts::PI / (1.0 - xi * xi).sqrt()).exp());
            let got = sa(&rec, period, xi);
            assert!(
                ((got - want) / want).abs() < 1e-10,
                "T {period}: {got} vs {want}"
            );
        }
    }

    /// A long resonant sine of amplitude A: `Sa -> A / (2 xi)` (the steady amplitude; the
    /// record's linear interpolation of the sine costs O((w dt)^2)).
    #[test]
    fn resonant_sine_reaches_a_over_two_xi() {
        let (a, period, xi, dt) = (1.0, 0.5, 0.05, 0.0025);
        let w = 2.0 * std::f64::consts::PI / period;
        let n = (60.0 / dt) as usize;
        let rec = record(dt, (0..n).map(|i| a * (w * i as f64 * dt).sin()).collect());
        let got = sa(&rec, period, xi);
        let want = a / (2.0 * xi);
        assert!(((got - want) / want).abs() < 2e-3, "{got} vs {want}");
    }

    /// Against an independent integration: RK4 at 1/400 of the period on the same
    /// piecewise-linear record, with the peak taken over its fine samples.
    #[test]
    fn matches_an_independent_integration() {
        let dt = 0.02;
        let accel: Vec<f64> = (0..600)
            .map(|i| {
                let t = i as f64 * dt;
                (3.1 * t).sin() + 0.6 * (11.7 * t + 0.4).sin() - 0.3 * (23.0 * t).cos()
            })
            .collect();
        let rec = record(dt, accel.clone());
        for (period, xi) in [(0.05, 0.05), (0.3, 0.05), (1.7, 0.02)] {
            let w = 2.0 * std::f64::consts::PI / period;
            let sub = (400.0 * dt / period).ceil() as usize;
            let h = dt / sub as f64;
            let ag = |t: f64| {
                let i = ((t / dt).floor() as usize).min(accel.len() - 2);
                let f = t / dt - i as f64;
                accel[i] + (accel[i + 1] - accel[i]) * f
            };
            let f = |t: f64, u: f64, v: f64| (v, -w * w * u - 2.0 * xi * w * v - ag(t));
            let (mut u, mut v, mut peak) = (0.0f64, 0.0f64, 0.0f64);
            for k in 0..(accel.len() - 1) * sub {
                let t = k as f64 * h;
                let k1 = f(t, u, v);
                let k2 = f(t + h / 2.0, u + h / 2.0 * k1.0, v + h / 2.0 * k1.1);
                let k3 = f(t + h / 2.0, u + h / 2.0 * k2.0, v + h / 2.0 * k2.1);
                let k4 = f(t + h, u + h * k3.0, v + h * k3.1);
                u += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
                v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
                peak = peak.max(u.abs());
            }
            let got = peak_displacement(&rec, period, xi);
            assert!(
                ((got - peak) / peak).abs() < 1e-5,
                "T {period}: {got} vs {peak}"
            );
        }
    }

    /// The bound that lets an extremum below the peak skip its search never skips one that
    /// would raise it: the same peaks, bit for bit, as searching every extremum, over periods
    /// from 0.02 to 6 s on a record of mixed frequencies with a pulse.
    #[test]
    fn skipped_extrema_never_raise_the_peak() {
        let dt = 0.01;
        let accel: Vec<f64> = (0..3000)
            .map(|i| {
                let t = i as f64 * dt;
                (2.3 * t).sin() + 0.7 * (13.1 * t + 0.4).sin() - 0.4 * (31.0 * t).cos()
                    + 3.0 * (-((t - 9.0) / 0.4).powi(2)).exp()
            })
            .collect();
        let rec = record(dt, accel);
        let mut searched = 0;
        for period in log_periods(0.02, 6.0, 300) {
            for xi in [0.02, 0.05, 0.2] {
                let fast = peak_searched(&rec, period, xi, false);
                let every = peak_searched(&rec, period, xi, true);
                assert_eq!(fast.to_bits(), every.to_bits(), "T {period}, xi {xi}");
                searched += 1;
            }
        }
        assert_eq!(searched, 900);
    }

    #[test]
    fn sa_avg_is_the_geometric_mean() {
        let rec = record(0.01, (0..800).map(|i| ((i as f64) * 0.037).sin()).collect());
        let periods = log_periods(0.2, 1.5, 7);
        assert_eq!(periods.len(), 7);
        assert!((periods[6] - 1.5).abs() < 1e-15 && (periods[0] - 0.2).abs() < 1e-15);
        let product: f64 = periods.iter().map(|&t| sa(&rec, t, 0.05)).product();
        let want = product.powf(1.0 / 7.0);
        assert!((sa_avg(&rec, &periods, 0.05) - want).abs() < 1e-12 * want);
    }

    /// A triangle pulse 0, A, 0 at dt = 1: v rises to A, and d reaches A at the end (closed
    /// forms of the piecewise-linear acceleration); a pulse followed by its negative brings v
    /// back to 0 with a peak between samples.
    #[test]
    fn ground_velocity_and_displacement() {
        let a = 3.0;
        let (pgv, pgd) = pgv_pgd(&record(1.0, vec![0.0, a, 0.0]));
        assert!(
            (pgv - a).abs() < 1e-14 && (pgd - a).abs() < 1e-14,
            "{pgv} {pgd}"
        );
        // a = 0, A, -A, 0: v(1) = A/2, a crosses 0 at t = 1.5 where v = A/2 + A/4 = 3A/4.
        let (pgv, _) = pgv_pgd(&record(1.0, vec![0.0, a, -a, 0.0]));
        assert!((pgv - 0.75 * a).abs() < 1e-14, "{pgv}");
    }

    /// Closed forms of the piecewise-linear acceleration: a constant A over duration D gives
    /// `integral a^2 = A^2 D` and `integral |a| = A D`; a ramp 0 to A over one step gives
    /// `A^2 h / 3` and `A h / 2`; a step from A to -B crosses zero at `h A / (A + B)`, so
    /// `integral |a| = h (A^2 + B^2) / (2 (A + B))`, not the trapezoid's `h (A - B) / 2`.
    #[test]
    fn arias_and_cav_of_piecewise_linear_records() {
        let k = std::f64::consts::PI / (2.0 * crate::record::G);
        let rel = |x: f64, y: f64| ((x - y) / y).abs();
        let (a, dt, n) = (-2.0, 0.02, 101);
        let (arias, cav) = arias_cav(&record(dt, vec![a; n]));
        let d = (n - 1) as f64 * dt;
        assert!(rel(arias, k * a * a * d) < 1e-13 && rel(cav, a.abs() * d) < 1e-13);
        let (arias, cav) = arias_cav(&record(0.5, vec![0.0, 3.0]));
        assert!(rel(arias, k * 9.0 * 0.5 / 3.0) < 1e-15 && rel(cav, 0.75) < 1e-15);
        let (arias, cav) = arias_cav(&record(1.0, vec![3.0, -1.0]));
        assert!(rel(cav, (9.0 + 1.0) / 8.0) < 1e-15, "{cav}");
        assert!(rel(arias, k * (9.0 - 3.0 + 1.0) / 3.0) < 1e-15, "{arias}");
        // Scaling: Arias with the square of the factor, CAV with the factor.
        let accel: Vec<f64> = (0..300).map(|i| (i as f64 * 0.21).sin()).collect();
        let (a1, c1) = arias_cav(&record(0.01, accel.clone()));
        let (a2, c2) = arias_cav(&record(0.01, accel.iter().map(|x| 2.0 * x).collect()));
        assert!(rel(a2, 4.0 * a1) < 1e-13 && rel(c2, 2.0 * c1) < 1e-13);
    }
}

/// One period of a response spectrum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectralOrdinate {
    pub period_s: f64,
    /// Pseudo-acceleration, m/s^2 (omega^2 Sd).
    pub sa_m_s2: f64,
    /// Peak relative displacement, m.
    pub sd_m: f64,
}

/// The `damping`-damped pseudo-acceleration response spectrum of `rec` at `periods` (each an
/// exact response over the whole record), computed in parallel.
pub fn spectrum(rec: &Record, periods: &[f64], damping: f64) -> Vec<SpectralOrdinate> {
    use rayon::prelude::*;
    periods
        .par_iter()
        .map(|&t| {
            let sd = peak_displacement(rec, t, damping);
            let w = 2.0 * std::f64::consts::PI / t;
            SpectralOrdinate {
                period_s: t,
                sa_m_s2: w * w * sd,
                sd_m: sd,
            }
        })
        .collect()
}

//! Seeded synthetic ground motion: Kanai-Tajimi filtered noise under a trapezoidal-quadratic
//! envelope, scaled to a target PGA.
//!
//! Only `+ - * /` and `sqrt` (which IEEE 754 rounds exactly) are used, never libm's `ln`, `sin` or
//! `exp`, whose last bits vary between platforms: the same spec gives the same bits everywhere.
//! Gaussian noise comes from the Irwin-Hall sum of 12 uniforms (exact mean 0, variance 1).

use super::rng::SplitMix64;
use super::{Record, RecordError, G};
use std::path::PathBuf;

/// Parameters of a synthetic record.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticSpec {
    pub seed: u64,
    /// Length, s.
    pub duration: f64,
    /// Sample interval, s.
    pub dt: f64,
    /// Peak ground acceleration of the result, g.
    pub pga_g: f64,
    /// Kanai-Tajimi ground frequency, Hz.
    pub fg_hz: f64,
    /// Kanai-Tajimi ground damping ratio.
    pub zeta_g: f64,
}

impl Default for SyntheticSpec {
    fn default() -> Self {
        // Firm-soil Kanai-Tajimi values (about 15.6 rad/s, 0.6).
        SyntheticSpec {
            seed: 1,
            duration: 20.0,
            dt: 0.01,
            pga_g: 0.35,
            fg_hz: 2.5,
            zeta_g: 0.6,
        }
    }
}

/// Gaussian noise: the Irwin-Hall sum of 12 uniforms (exact mean 0, variance 1; no libm).
fn normal(rng: &mut SplitMix64) -> f64 {
    (0..12).map(|_| rng.uniform_from_zero()).sum::<f64>() - 6.0
}

fn envelope(t: f64, d: f64) -> f64 {
    let (t1, t2) = (0.15 * d, 0.5 * d);
    if t < t1 {
        (t / t1) * (t / t1)
    } else if t <= t2 {
        1.0
    } else {
        let x = ((d - t) / (d - t2)).max(0.0);
        x * x
    }
}

/// Generate a synthetic record.
pub fn synthetic(spec: &SyntheticSpec) -> Result<Record, RecordError> {
    let name = format!("synthetic-s{}", spec.seed);
    let bad = |message: String| RecordError::Invalid {
        path: PathBuf::from(&name),
        message,
    };
    for (key, v) in [
        ("duration_s", spec.duration),
        ("dt_s", spec.dt),
        ("pga_g", spec.pga_g),
        ("fg_hz", spec.fg_hz),
        ("zeta_g", spec.zeta_g),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(format!(
                "synthetic.{key} must be a positive number, got {}",
                crate::show(v)
            )));
        }
    }
    if spec.fg_hz > 0.5 / spec.dt {
        return Err(bad(format!(
            "synthetic.fg_hz = {} is above the Nyquist frequency of dt_s = {} ({} Hz)",
            crate::show(spec.fg_hz),
            crate::show(spec.dt),
            crate::show_derived(0.5 / spec.dt)
        )));
    }
    if spec.zeta_g > 2.0 {
        return Err(bad(format!(
            "synthetic.zeta_g = {}: expected at most 2 (a ground filter damped far past critical passes almost nothing)",
            crate::show(spec.zeta_g)
        )));
    }
    // The count as a float first: `as usize` saturates (1e300 would read 18446744073709551615).
    let samples = (spec.duration / spec.dt).round();
    if !(2.0..=1e8).contains(&samples) {
        return Err(bad(format!(
            "synthetic record would have {} samples (duration_s / dt_s); expected 2 to 1e8",
            crate::show(samples)
        )));
    }
    let n = samples as usize;
    let wg = 2.0 * std::f64::consts::PI * spec.fg_hz;
    let (k, c) = (wg * wg, 2.0 * spec.zeta_g * wg);
    // Filter x'' + c x' + k x = -w, w held per sample; output ag = -(c x' + k x), the filter's
    // absolute acceleration. RK4 substeps keep the filter accurate for any dt.
    let sub = ((spec.dt * wg / 0.2).ceil() as usize).max(1);
    let h = spec.dt / sub as f64;
    let f = |x: f64, v: f64, w: f64| (v, -c * v - k * x - w);
    let mut rng = SplitMix64::new(spec.seed ^ 0x005E_ED0F_90D1_u64);
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let mut accel = Vec::with_capacity(n);
    for i in 0..n {
        let t = i as f64 * spec.dt;
        accel.push(-(c * v + k * x) * envelope(t, spec.duration));
        let w = normal(&mut rng);
        for _ in 0..sub {
            let (k1x, k1v) = f(x, v, w);
            let (k2x, k2v) = f(x + 0.5 * h * k1x, v + 0.5 * h * k1v, w);
            let (k3x, k3v) = f(x + 0.5 * h * k2x, v + 0.5 * h * k2v, w);
            let (k4x, k4v) = f(x + h * k3x, v + h * k3v, w);
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
    }
    let mut rec = Record {
        name,
        dt: spec.dt,
        t0: 0.0,
        accel,
    };
    let s = rec.scale_to_pga(spec.pga_g * G)?;
    rec.accel.iter_mut().for_each(|a| *a *= s);
    Ok(rec)
}

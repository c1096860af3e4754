//! Exact one-step propagator of a linear oscillator under piecewise-linear ground acceleration
//! (the Nigam-Jennings idea): over a step `h` with `ag` linear from `a0` to `a1`,
//! `u1 = uu u0 + uv v0 + ua0 a0 + ua1 a1` and likewise for `v1`, with no truncation error.
//!
//! The coefficients come from `exp(M h)` of the augmented system `[u, v, f, g]`
//! (`u' = v`, `v' = -(k/m) u - (c/m) v - f`, `f' = g`, `g' = 0`) by scaling and squaring, so
//! they hold for any damping (also >= critical) and for a free mass (`k = 0`). They need
//! transcendentals once per (oscillator, h): the GPU path takes them precomputed from here.

use crate::model::Oscillator;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Propagator {
    pub uu: f64,
    pub uv: f64,
    pub ua0: f64,
    pub ua1: f64,
    pub vu: f64,
    pub vv: f64,
    pub va0: f64,
    pub va1: f64,
}

type M4 = [[f64; 4]; 4];

fn mul(a: &M4, b: &M4) -> M4 {
    let mut r = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            r[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

fn expm(a: &M4) -> M4 {
    let norm = a
        .iter()
        .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let s = if norm > 0.5 {
        (norm / 0.5).log2().ceil() as i32
    } else {
        0
    };
    let f = 0.5f64.powi(s);
    let a: M4 = a.map(|r| r.map(|x| x * f));
    let mut result = [[0.0; 4]; 4];
    let mut term = [[0.0; 4]; 4];
    for i in 0..4 {
        result[i][i] = 1.0;
        term[i][i] = 1.0;
    }
    for k in 1..=24 {
        term = mul(&term, &a).map(|r| r.map(|x| x / k as f64));
        for i in 0..4 {
            for j in 0..4 {
                result[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..s {
        result = mul(&result, &result);
    }
    result
}

impl Propagator {
    pub fn new(o: &Oscillator, h: f64) -> Propagator {
        let m: M4 = [
            [0.0, h, 0.0, 0.0],
            [-o.k / o.m * h, -o.c / o.m * h, -h, 0.0],
            [0.0, 0.0, 0.0, h],
            [0.0; 4],
        ];
        let e = expm(&m);
        // Forcing enters as f = a0, g = (a1 - a0) / h.
        Propagator {
            uu: e[0][0],
            uv: e[0][1],
            ua0: e[0][2] - e[0][3] / h,
            ua1: e[0][3] / h,
            vu: e[1][0],
            vv: e[1][1],
            va0: e[1][2] - e[1][3] / h,
            va1: e[1][3] / h,
        }
    }

    #[inline]
    pub fn step(&self, u: f64, v: f64, a0: f64, a1: f64) -> (f64, f64) {
        (
            self.uu * u + self.uv * v + self.ua0 * a0 + self.ua1 * a1,
            self.vu * u + self.vv * v + self.va0 * a0 + self.va1 * a1,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_mass_under_linear_ramp() {
        // v' = -ag, ag from a0 to a1: v1 = v0 - h (a0 + a1)/2, u1 = u0 + v0 h - h^2 (a0/3 + a1/6).
        let p = Propagator::new(&Oscillator::free(3.0), 0.1);
        let (u, v) = p.step(0.2, 1.0, 2.0, 5.0);
        assert!((v - (1.0 - 0.1 * 3.5)).abs() < 1e-14);
        assert!((u - (0.2 + 0.1 - 0.01 * (2.0 / 3.0 + 5.0 / 6.0))).abs() < 1e-14);
    }
}

//! Samples of uncertain parameters for fragility-style sweeps: Latin hypercube or Monte Carlo
//! draws from uniform, normal and lognormal distributions (optionally truncated), reproducible
//! from a seed on every platform (own generator, no library whose stream may change).

/// A distribution of one parameter. Normal and lognormal may be truncated to `[min, max]`
/// (by inverse CDF on the truncated range, so Latin hypercube strata stay equal in probability).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Dist {
    Uniform {
        min: f64,
        max: f64,
    },
    Normal {
        mean: f64,
        sd: f64,
        min: f64,
        max: f64,
    },
    LogNormal {
        median: f64,
        beta: f64,
        min: f64,
        max: f64,
    },
}

impl Dist {
    /// The value at cumulative probability `u` in (0, 1).
    pub fn quantile(&self, u: f64) -> f64 {
        match *self {
            Dist::Uniform { min, max } => min + u * (max - min),
            Dist::Normal { mean, sd, min, max } => {
                let (lo, hi) = (phi((min - mean) / sd), phi((max - mean) / sd));
                mean + sd * phi_inv(lo + u * (hi - lo))
            }
            Dist::LogNormal {
                median,
                beta,
                min,
                max,
            } => {
                let z = |x: f64| {
                    if x <= 0.0 {
                        f64::NEG_INFINITY
                    } else {
                        (x / median).ln() / beta
                    }
                };
                let (lo, hi) = (phi(z(min)), phi(z(max)));
                median * (beta * phi_inv(lo + u * (hi - lo))).exp()
            }
        }
    }
}

/// How the unit-cube points are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Each axis cut into `n` equally likely strata, one point in each, strata paired at random.
    LatinHypercube,
    MonteCarlo,
}

/// The plans' samples draw from the crate's one seeded generator (the same stream everywhere).
pub use crate::record::rng::SplitMix64 as Rng;

/// `n` points of the unit cube in `dims` dimensions (row per point).
pub fn unit_points(method: Method, n: usize, dims: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = Rng::new(seed);
    let mut pts = vec![vec![0.0; dims]; n];
    for d in 0..dims {
        match method {
            Method::MonteCarlo => {
                for p in pts.iter_mut() {
                    p[d] = rng.uniform();
                }
            }
            Method::LatinHypercube => {
                let mut strata: Vec<usize> = (0..n).collect();
                // Fisher-Yates.
                for i in (1..n).rev() {
                    strata.swap(i, rng.below(i + 1));
                }
                for (p, s) in pts.iter_mut().zip(strata) {
                    p[d] = (s as f64 + rng.uniform()) / n as f64;
                }
            }
        }
    }
    pts
}

/// `n` samples of the distributions `dists` (row per sample, column per distribution).
pub fn draw(method: Method, n: usize, dists: &[Dist], seed: u64) -> Vec<Vec<f64>> {
    unit_points(method, n, dists.len(), seed)
        .into_iter()
        .map(|u| u.iter().zip(dists).map(|(&u, d)| d.quantile(u)).collect())
        .collect()
}

/// Why column `j` of drawn `points` is refused: the first value `check` refuses, in the words
/// both plans' errors use; None if every value passes.
pub(crate) fn refused_draw(
    points: &[Vec<f64>],
    j: usize,
    check: crate::plan::axes::Check,
) -> Option<String> {
    let (ok, expected) = check;
    points
        .iter()
        .map(|p| p[j])
        .enumerate()
        .find(|&(_, v)| !ok(v))
        .map(|(i, v)| {
            format!(
                "sample {i} drew {}: expected {expected}; truncate the distribution with min/max",
                crate::plan::limits::show(v)
            )
        })
}

/// Standard normal CDF (via `erfc`, relative error below 1.2e-7 everywhere).
pub fn phi(x: f64) -> f64 {
    if x == f64::NEG_INFINITY {
        return 0.0;
    }
    if x == f64::INFINITY {
        return 1.0;
    }
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Complementary error function (Numerical Recipes' Chebyshev fit, fractional error < 1.2e-7).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Standard normal quantile: Acklam's rational approximation, then one Newton step on
/// [`phi`] (so the two are consistent to the CDF's own accuracy).
pub fn phi_inv(p: f64) -> f64 {
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    let x = if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    };
    let pdf = (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt();
    x - (phi(x) - p) / pdf
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_cdf_and_quantile() {
        assert!((phi(0.0) - 0.5).abs() < 1e-7);
        assert!((phi(1.959_963_985) - 0.975).abs() < 1e-7);
        for p in [1e-6, 0.01, 0.2, 0.5, 0.9, 0.999] {
            assert!((phi(phi_inv(p)) - p).abs() < 1e-7 * p.max(1e-3), "{p}");
        }
        assert!((phi_inv(0.975) - 1.959_964).abs() < 1e-5);
    }

    /// One point per stratum on every axis, and the truncated and lognormal quantiles land
    /// where they should.
    #[test]
    fn latin_hypercube_stratifies_and_quantiles_map() {
        let n = 50;
        let pts = unit_points(Method::LatinHypercube, n, 3, 9);
        for d in 0..3 {
            let mut seen = vec![false; n];
            for p in &pts {
                let s = (p[d] * n as f64) as usize;
                assert!(!seen[s], "axis {d}: stratum {s} twice");
                seen[s] = true;
            }
        }
        assert_eq!(pts, unit_points(Method::LatinHypercube, n, 3, 9));
        assert_ne!(pts, unit_points(Method::LatinHypercube, n, 3, 10));
        let ln = Dist::LogNormal {
            median: 0.5,
            beta: 0.3,
            min: 0.0,
            max: f64::INFINITY,
        };
        assert!((ln.quantile(0.5) - 0.5).abs() < 1e-6);
        assert!((ln.quantile(phi(1.0)) - 0.5 * 0.3f64.exp()).abs() < 1e-6);
        let tn = Dist::Normal {
            mean: 0.05,
            sd: 0.02,
            min: 0.0,
            max: 0.1,
        };
        for u in [1e-9, 0.3, 1.0 - 1e-9] {
            let x = tn.quantile(u);
            assert!((0.0..=0.1).contains(&x), "{x}");
        }
    }
}

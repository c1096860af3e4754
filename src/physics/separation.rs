//! Separation rules of building codes: the gap two neighbours need, estimated from their peak
//! displacements `UA = max|uA|` and `UB = max|uB|` alone (the time-history answer,
//! `max_t (uA - uB)`, is [`crate::physics::solver::separation`]).
//!
//! - ABS: `UA + UB` (the buildings at their peaks, towards each other, at once);
//! - SRSS: `sqrt(UA^2 + UB^2)` (peaks uncorrelated);
//! - DDC, the double difference combination (Jeng, Kasai & Maison 1992; Penzien 1997):
//!   `sqrt(UA^2 + UB^2 - 2 rho UA UB)`, with `rho` the CQC correlation of the two buildings'
//!   fundamental modes ([`cqc_rho`]).

/// A combination rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    Abs,
    Srss,
    Ddc,
}

impl Rule {
    pub const ALL: [Rule; 3] = [Rule::Abs, Rule::Srss, Rule::Ddc];

    /// The name in column names and tables.
    pub fn key(self) -> &'static str {
        match self {
            Rule::Abs => "abs",
            Rule::Srss => "srss",
            Rule::Ddc => "ddc",
        }
    }

    /// The gap this rule asks for, from the peak displacements `ua`, `ub` (m) and the
    /// correlation `rho` of the two buildings (DDC only).
    pub fn gap(self, ua: f64, ub: f64, rho: f64) -> f64 {
        match self {
            Rule::Abs => ua + ub,
            Rule::Srss => ua.hypot(ub),
            // Rounding can take the sum a hair below 0 where rho = 1 and ua = ub.
            Rule::Ddc => (ua * ua + ub * ub - 2.0 * rho * ua * ub).max(0.0).sqrt(),
        }
    }
}

/// The CQC correlation coefficient of two linear oscillators under white noise (Der Kiureghian
/// 1981): with `r = omega_b / omega_a`,
/// `rho = 8 sqrt(xi_a xi_b) (xi_a + r xi_b) r^1.5 /
///        ((1 - r^2)^2 + 4 xi_a xi_b r (1 + r^2) + 4 (xi_a^2 + xi_b^2) r^2)`.
/// 1 for identical oscillators (exactly, not to rounding), 0 where either is undamped and
/// they differ.
pub fn cqc_rho(omega_a: f64, xi_a: f64, omega_b: f64, xi_b: f64) -> f64 {
    if omega_a == omega_b && xi_a == xi_b {
        return 1.0;
    }
    let r = omega_b / omega_a;
    let num = 8.0 * (xi_a * xi_b).sqrt() * (xi_a + r * xi_b) * r * r.sqrt();
    let one_minus = 1.0 - r * r;
    let den = one_minus * one_minus
        + 4.0 * xi_a * xi_b * r * (1.0 + r * r)
        + 4.0 * (xi_a * xi_a + xi_b * xi_b) * r * r;
    if den == 0.0 {
        // r = 1 with both undamped: two identical undamped oscillators.
        return 1.0;
    }
    (num / den).clamp(-1.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `rho` as its definition: the correlation of the two displacement responses to white
    /// noise, `int Re(H_a conj(H_b)) / sqrt(int |H_a|^2 int |H_b|^2)` over frequency, with
    /// `H(w) = 1 / (w_n^2 - w^2 + 2 i xi w_n w)`, integrated numerically (Simpson on a
    /// stretched grid) independently of the closed form.
    fn rho_by_quadrature(wa: f64, xa: f64, wb: f64, xb: f64) -> f64 {
        let h = |wn: f64, xi: f64, w: f64| (wn * wn - w * w, 2.0 * xi * wn * w);
        // w = tan(theta) * scale maps (0, pi/2) onto (0, inf); fine near the resonances.
        let scale = wa.max(wb);
        let n = 400_000;
        let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
        for i in 0..=n {
            let th = std::f64::consts::FRAC_PI_2 * i as f64 / n as f64;
            if i == n {
                continue; // the integrands vanish as w^-4 there
            }
            let w = scale * th.tan();
            let jac = scale / th.cos().powi(2);
            let (ra, ia) = h(wa, xa, w);
            let (rb, ib) = h(wb, xb, w);
            let (da, db) = (ra * ra + ia * ia, rb * rb + ib * ib);
            // H = 1 / (r + i m): Re(H_a conj(H_b)) = (ra rb + ia ib) / (|.|^2 |.|^2).
            let wgt = if i == 0 {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            } * jac;
            ab += wgt * (ra * rb + ia * ib) / (da * db);
            aa += wgt / da;
            bb += wgt / db;
        }
        ab / (aa * bb).sqrt()
    }

    #[test]
    fn rho_is_the_white_noise_correlation() {
        for (ta, xa, tb, xb) in [
            (0.5, 0.05, 0.3, 0.05),
            (1.0, 0.05, 0.9, 0.05),
            (1.0, 0.02, 1.1, 0.07),
            (0.4, 0.05, 2.0, 0.05),
            (0.8, 0.10, 0.8, 0.02),
            (0.7, 0.05, 0.7, 0.05),
        ] {
            let (wa, wb) = (
                2.0 * std::f64::consts::PI / ta,
                2.0 * std::f64::consts::PI / tb,
            );
            let closed = cqc_rho(wa, xa, wb, xb);
            let quad = rho_by_quadrature(wa, xa, wb, xb);
            assert!(
                (closed - quad).abs() < 1e-6,
                "T {ta}/{tb}, xi {xa}/{xb}: closed form {closed} against quadrature {quad}"
            );
            // Symmetric in the two oscillators.
            assert!((cqc_rho(wb, xb, wa, xa) - closed).abs() < 1e-12);
        }
    }

    #[test]
    fn rules_order_and_identical_buildings() {
        let (ua, ub) = (0.03, 0.05);
        let rho = cqc_rho(10.0, 0.05, 12.0, 0.05);
        assert!(rho > 0.0 && rho < 1.0, "{rho}");
        let [a, s, d] = Rule::ALL.map(|r| r.gap(ua, ub, rho));
        assert!(a > s && s > d && d > (ub - ua), "{a} {s} {d}");
        assert_eq!(cqc_rho(10.0, 0.05, 10.0, 0.05), 1.0);
        assert_eq!(Rule::Ddc.gap(0.04, 0.04, 1.0), 0.0);
        // Identical undamped oscillators are fully correlated, different ones not at all.
        assert_eq!(cqc_rho(10.0, 0.0, 10.0, 0.0), 1.0);
        assert_eq!(cqc_rho(10.0, 0.0, 11.0, 0.0), 0.0);
    }
}

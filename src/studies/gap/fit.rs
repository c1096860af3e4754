//! The lognormal fitted by maximum likelihood to the runs' required gaps (exact, or censored
//! by a collapse), and the probability of pounding it gives.

use crate::plan::sample::phi;

/// The probability of pounding against the gap, fitted to the runs' required gaps: a share
/// `closing / runs` of the runs whose floors close at all, and among those a lognormal
/// required gap, `P(pounding | gap g) = closing / runs * (1 - Phi(ln(g / median) / beta))`.
///
/// Every run's required gap is known exactly, so the lognormal is fitted to those values by
/// maximum likelihood (`ln median` their mean logarithm, `beta` the root-mean-square spread
/// of the logarithms about it), not to counts at the gaps a grid happens to hold: counts at a
/// coarse grid move the median by as much as the grid's spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapFit {
    /// m: the median of the closing runs' required gaps.
    pub median: f64,
    pub beta: f64,
    /// Standard errors of `ln median` (`beta / sqrt(n)`) and of `beta` (`beta / sqrt(2 n)`).
    pub se_ln_median: f64,
    pub se_beta: f64,
    /// Runs counted, and of those, runs whose floors close (required gap > 0).
    pub runs: u64,
    pub closing: u64,
    /// Of the closing runs, those whose required gap is a lower bound ([`GapFit::censored`]).
    pub censored: u64,
}

/// Why no lognormal could be fitted to the required gaps.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum NoGapFit {
    #[error("no run at this intensity")]
    NoRuns,
    #[error("the floors close in no run: no gap is needed")]
    NoneClose,
    #[error("the floors close in only one run: a lognormal needs two")]
    OneCloses,
    #[error("every run whose floors close needs the same gap: the dispersion is 0")]
    AllEqual,
    #[error("fewer than two exact gaps (the other runs collapsed): their lower bounds alone fix no lognormal")]
    TooFewExact,
}

impl GapFit {
    /// The maximum-likelihood lognormal of the positive values of `required` (m), with the
    /// share of runs whose floors close.
    pub fn of(required: &[f64]) -> Result<GapFit, NoGapFit> {
        let logs: Vec<f64> = required
            .iter()
            .filter(|&&r| r > 0.0)
            .map(|r| r.ln())
            .collect();
        let n = logs.len();
        match (required.len(), n) {
            (0, _) => return Err(NoGapFit::NoRuns),
            (_, 0) => return Err(NoGapFit::NoneClose),
            (_, 1) => return Err(NoGapFit::OneCloses),
            _ => {}
        }
        let mean = logs.iter().sum::<f64>() / n as f64;
        let beta = (logs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64).sqrt();
        // Equal values give a spread of rounding noise, not a dispersion.
        if beta.is_nan() || beta <= 1e-12 {
            return Err(NoGapFit::AllEqual);
        }
        Ok(GapFit {
            median: mean.exp(),
            beta,
            se_ln_median: beta / (n as f64).sqrt(),
            se_beta: beta / (2.0 * n as f64).sqrt(),
            runs: required.len() as u64,
            closing: n as u64,
            censored: 0,
        })
    }

    /// As [`GapFit::of`], with `bounds` the required gaps of runs a collapse censored: each is
    /// a lower bound (the floors had closed that far when a building collapsed; how far they
    /// would have closed had it stood is unknown). A bound above 0 is a run whose floors close
    /// and enters the likelihood with the probability of exceeding it,
    /// `1 - Phi((ln b - ln median) / beta)` (right-censored maximum likelihood, as survival
    /// analysis fits lifetimes still running); a bound of 0 says nothing and is left out.
    /// At least two exact required gaps above 0, not all equal, are needed: the bounds alone
    /// fix no lognormal (its likelihood grows without limit as the median does).
    ///
    /// The maximum is found by Newton's method in `(ln median / beta, 1 / beta)`, where the
    /// log-likelihood is concave (Olsen 1978, for the Tobit model), so it is the only one;
    /// the standard errors are from the observed information there.
    pub fn censored(required: &[f64], bounds: &[f64]) -> Result<GapFit, NoGapFit> {
        let c: Vec<f64> = bounds
            .iter()
            .filter(|&&b| b > 0.0)
            .map(|b| b.ln())
            .collect();
        if c.is_empty() {
            return GapFit::of(required);
        }
        let x: Vec<f64> = required
            .iter()
            .filter(|&&r| r > 0.0)
            .map(|r| r.ln())
            .collect();
        if x.len() < 2 {
            return Err(NoGapFit::TooFewExact);
        }
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let spread = (x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt();
        if spread.is_nan() || spread <= 1e-12 {
            return Err(NoGapFit::AllEqual);
        }
        // (g, h) = (mu / sigma, 1 / sigma): an exact value's log-density is
        // ln h - (h x - g)^2 / 2, a bound's ln(1 - Phi(h c - g)).
        let loglik = |g: f64, h: f64| -> f64 {
            let exact: f64 = x.iter().map(|&v| h.ln() - 0.5 * (h * v - g).powi(2)).sum();
            exact + c.iter().map(|&v| ln_upper_tail(h * v - g)).sum::<f64>()
        };
        // The gradient and the Hessian (negative definite everywhere).
        let derivatives = |g: f64, h: f64| -> ([f64; 2], [f64; 3]) {
            let (mut dg, mut dh) = (0.0, 0.0);
            let (mut hgg, mut hgh, mut hhh) = (0.0, 0.0, 0.0);
            for &v in &x {
                let r = h * v - g;
                dg += r;
                dh += 1.0 / h - r * v;
                hgg -= 1.0;
                hgh += v;
                hhh -= 1.0 / (h * h) + v * v;
            }
            for &v in &c {
                let z = h * v - g;
                let l = mills(z);
                let d = l * (l - z);
                dg += l;
                dh -= l * v;
                hgg -= d;
                hgh += d * v;
                hhh -= d * v * v;
            }
            ([dg, dh], [hgg, hgh, hhh])
        };
        let (mut g, mut h) = (mean / spread, 1.0 / spread);
        for _ in 0..200 {
            let ([dg, dh], [a, b, d]) = derivatives(g, h);
            let det = a * d - b * b;
            // Newton's step -H^-1 grad.
            let (mut sg, mut sh) = (-(d * dg - b * dh) / det, -(a * dh - b * dg) / det);
            let l0 = loglik(g, h);
            let mut halvings = 0;
            while !(h + sh > 0.0 && loglik(g + sg, h + sh) >= l0 - 1e-12 * l0.abs())
                && halvings < 60
            {
                sg *= 0.5;
                sh *= 0.5;
                halvings += 1;
            }
            if halvings == 60 {
                break;
            }
            g += sg;
            h += sh;
            if sg.abs() <= 1e-12 * (1.0 + g.abs()) && sh.abs() <= 1e-12 * h {
                break;
            }
        }
        let (_, [a, b, d]) = derivatives(g, h);
        // Covariance of (g, h): the inverse of the observed information -H; then the delta
        // method for ln median = g / h and beta = 1 / h.
        let det = a * d - b * b;
        let (vgg, vgh, vhh) = (-d / det, b / det, -a / det);
        let (ug, uh) = (1.0 / h, -g / (h * h));
        let var_ln_median = ug * ug * vgg + 2.0 * ug * uh * vgh + uh * uh * vhh;
        let beta = 1.0 / h;
        if !(beta.is_finite() && beta > 1e-12 && g.is_finite()) {
            return Err(NoGapFit::AllEqual);
        }
        let positive = |v: &[f64]| v.iter().filter(|&&r| r > 0.0).count() as u64;
        let known = required.len() as u64 + c.len() as u64;
        Ok(GapFit {
            median: (g / h).exp(),
            beta,
            se_ln_median: var_ln_median.max(0.0).sqrt(),
            se_beta: vhh.max(0.0).sqrt() / (h * h),
            runs: known,
            closing: positive(required) + c.len() as u64,
            censored: c.len() as u64,
        })
    }

    /// The share of runs whose floors close.
    pub fn closing_share(&self) -> f64 {
        self.closing as f64 / self.runs as f64
    }

    /// The fitted probability of pounding at a gap of `g` m.
    pub fn pounding(&self, g: f64) -> f64 {
        if g <= 0.0 {
            return self.closing_share();
        }
        self.closing_share() * (1.0 - phi((g / self.median).ln() / self.beta))
    }

    /// The gap at which the fitted probability of pounding is `p` (0 where the runs whose
    /// floors close are fewer than that share: no gap is needed for it).
    pub fn gap_for(&self, p: f64) -> Option<f64> {
        if !(p > 0.0 && p < 1.0) {
            return None;
        }
        let q = p / self.closing_share();
        if q >= 1.0 {
            return Some(0.0);
        }
        Some(self.median * (self.beta * crate::plan::sample::phi_inv(1.0 - q)).exp())
    }
}

/// `ln(1 - Phi(z))`, also where `1 - Phi(z)` underflows (its asymptotic series there).
fn ln_upper_tail(z: f64) -> f64 {
    if z < 30.0 {
        phi(-z).ln()
    } else {
        -0.5 * z * z - (z * (2.0 * std::f64::consts::PI).sqrt()).ln() + (-1.0 / (z * z)).ln_1p()
    }
}

/// The inverse Mills ratio `phi(z) / (1 - Phi(z))`: the mean of a standard normal above `z`.
fn mills(z: f64) -> f64 {
    if z < 30.0 {
        let density = (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
        density / phi(-z)
    } else {
        // z + 1/z - 2/z^3 + ...: within 1e-7 of it from z = 30.
        z + 1.0 / z - 2.0 / (z * z * z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fit of the required gaps: the lognormal's maximum-likelihood parameters, the runs
    /// whose floors never close as a share apart, and `gap_for` the inverse of `pounding`.
    #[test]
    fn the_gap_fit_is_the_required_gaps_lognormal() {
        let f = GapFit::of(&[0.0, 0.01, 0.04, 0.0]).unwrap();
        assert_eq!((f.runs, f.closing), (4, 2));
        assert!((f.median - 0.02).abs() < 1e-15);
        assert!((f.beta - 2f64.ln()).abs() < 1e-15);
        assert_eq!(f.pounding(0.0), 0.5);
        assert!((f.pounding(0.02) - 0.25).abs() < 1e-7);
        for p in [0.01, 0.1, 0.4] {
            let g = f.gap_for(p).unwrap();
            assert!((f.pounding(g) - p).abs() < 1e-7, "{p}: {g}");
        }
        // No gap is needed for a probability the closing runs cannot reach.
        assert_eq!(f.gap_for(0.6), Some(0.0));
        assert_eq!(GapFit::of(&[]), Err(NoGapFit::NoRuns));
        assert_eq!(GapFit::of(&[0.0, 0.0]), Err(NoGapFit::NoneClose));
        assert_eq!(GapFit::of(&[0.0, 0.03]), Err(NoGapFit::OneCloses));
        assert_eq!(GapFit::of(&[0.03, 0.03]), Err(NoGapFit::AllEqual));
    }

    /// The right-censored fit: with no bound above 0 it is the exact fit; bounds far below
    /// every exact gap carry no information (the same median, beta and standard errors, from
    /// the observed information); bounds above them raise the median.
    #[test]
    fn a_censored_fit_without_information_is_the_exact_one() {
        let exact = [0.0, 0.011, 0.023, 0.017, 0.031, 0.014];
        assert_eq!(GapFit::censored(&exact, &[]), GapFit::of(&exact));
        assert_eq!(GapFit::censored(&exact, &[0.0, 0.0]), GapFit::of(&exact));
        let of = GapFit::of(&exact).unwrap();
        let far = GapFit::censored(&exact, &[1e-9, 2e-9]).unwrap();
        assert_eq!((far.runs, far.closing, far.censored), (8, 7, 2));
        for (a, b) in [
            (far.median, of.median),
            (far.beta, of.beta),
            (far.se_ln_median, of.se_ln_median),
            (far.se_beta, of.se_beta),
        ] {
            assert!((a - b).abs() < 1e-9 * b, "{a} against {b}");
        }
        let high = GapFit::censored(&exact, &[0.03, 0.04]).unwrap();
        assert!(high.median > of.median * 1.2, "{high:?}");
        assert_eq!(
            GapFit::censored(&[0.0, 0.02], &[0.03]),
            Err(NoGapFit::TooFewExact)
        );
        assert_eq!(
            GapFit::censored(&[0.02, 0.02], &[0.03]),
            Err(NoGapFit::AllEqual)
        );
    }

    /// The right-censored fit is the maximum of its likelihood, written here in `(ln median,
    /// beta)` and searched on a grid: no grid point beats it, and the best is within a grid
    /// step of it.
    #[test]
    fn the_censored_fit_maximises_its_likelihood() {
        let exact = [0.012, 0.02, 0.027, 0.035, 0.016, 0.05, 0.022];
        let bounds = [0.03, 0.045, 0.06, 0.018];
        let f = GapFit::censored(&exact, &bounds).unwrap();
        assert_eq!((f.runs, f.closing, f.censored), (11, 11, 4));
        let loglik = |mu: f64, beta: f64| -> f64 {
            let density: f64 = exact
                .iter()
                .map(|g| {
                    let z = (g.ln() - mu) / beta;
                    -beta.ln() - 0.5 * z * z
                })
                .sum();
            let tails: f64 = bounds
                .iter()
                .map(|b| (1.0 - phi((b.ln() - mu) / beta)).ln())
                .sum();
            density + tails
        };
        let (mu, beta) = (f.median.ln(), f.beta);
        let top = loglik(mu, beta);
        let (step_mu, step_beta) = (0.002, 0.001);
        let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
        for i in -200..=200 {
            for j in -200..=200 {
                let (m, b) = (mu + i as f64 * step_mu, beta + j as f64 * step_beta);
                let l = loglik(m, b);
                assert!(l <= top + 1e-6, "({m}, {b}): {l} above {top}");
                if l > best.0 {
                    best = (l, m, b);
                }
            }
        }
        assert!((best.1 - mu).abs() <= step_mu && (best.2 - beta).abs() <= step_beta);
        // The censored runs needed more than their bounds: the median is above the exact
        // gaps' alone.
        assert!(f.median > GapFit::of(&exact).unwrap().median);
    }
}

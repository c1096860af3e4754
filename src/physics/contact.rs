//! Contact force laws `F(delta, delta')` of `shared/docs/physics.md` section 2, resolved per run
//! into a `Contact` that the integrators evaluate.
//!
//! Conventions: `delta = u1 - u2 - gap` (penetration, > 0 in contact), `ddelta = u1' - u2'`
//! (> 0 approaching), `F >= 0` compressive. The integrators track a contact *phase* (approach
//! or restitution) located at the instant `ddelta` changes sign, so the right-hand side is smooth
//! inside every step; the phase-switching laws read it instead of the sign of `ddelta`.
//!
//! Inside a step the integrator may probe `delta` slightly below 0 before the separation event
//! is located, so the Hertz-type powers use the odd extension `delta |delta|^(1/2)`: smooth, no NaN.

/// Which law. Keys are the config/CSV spelling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LawKind {
    /// `k delta`
    Linear,
    /// `k delta + c delta'`, tension allowed before separation (Anagnostopoulos 1988).
    KelvinVoigt,
    /// Kelvin-Voigt clamped at `F >= 0`: contact ends when the force reaches 0.
    KelvinVoigtNoTension,
    /// `k delta + c delta'` while approaching, `k delta` while restituting (Mahmoud & Jankowski).
    ModifiedLinear,
    /// `beta delta^1.5`
    Hertz,
    /// `beta delta^1.5 + c delta'` approaching, `beta delta^1.5` restituting,
    /// `c = 2 zeta sqrt(beta sqrt(delta) m_eff)` (Jankowski 2005, the seed's eq. 9).
    NonlinearViscoelastic,
    /// `beta delta^1.5 (1 + chi delta')`, `chi = 3(1-e)/(2 v0)`.
    HuntCrossley,
    /// Hunt-Crossley form with `chi = 3(1-e^2)/(4 v0)` (Lankarani-Nikravesh; "Hertzdamp").
    LankaraniNikravesh,
    /// Hunt-Crossley form with `chi = 8(1-e)/(5 e v0)` (Ye, Li & Zhu 2009; Flores et al. 2011).
    Flores,
    /// Hunt-Crossley form with `chi = a(e)/v0`, `a` root-found so one isolated collision
    /// reproduces `e` exactly (the Hunt-Crossley counterpart of the `exact` zeta).
    HuntCrossleyExact,
}

impl LawKind {
    pub const ALL: [LawKind; 10] = [
        LawKind::Linear,
        LawKind::KelvinVoigt,
        LawKind::KelvinVoigtNoTension,
        LawKind::ModifiedLinear,
        LawKind::Hertz,
        LawKind::NonlinearViscoelastic,
        LawKind::HuntCrossley,
        LawKind::LankaraniNikravesh,
        LawKind::Flores,
        LawKind::HuntCrossleyExact,
    ];

    pub fn key(self) -> &'static str {
        match self {
            LawKind::Linear => "linear",
            LawKind::KelvinVoigt => "kelvin_voigt",
            LawKind::KelvinVoigtNoTension => "kelvin_voigt_no_tension",
            LawKind::ModifiedLinear => "modified_linear",
            LawKind::Hertz => "hertz",
            LawKind::NonlinearViscoelastic => "nonlinear_viscoelastic",
            LawKind::HuntCrossley => "hunt_crossley",
            LawKind::LankaraniNikravesh => "lankarani_nikravesh",
            LawKind::Flores => "flores",
            LawKind::HuntCrossleyExact => "hunt_crossley_exact",
        }
    }

    pub fn from_key(s: &str) -> Option<LawKind> {
        LawKind::ALL.into_iter().find(|l| l.key() == s)
    }

    pub fn keys() -> String {
        LawKind::ALL.map(|l| l.key()).join(", ")
    }

    /// Force grows as `delta^1.5` (stiffness is `beta`, N/m^1.5) rather than `delta` (`k`, N/m).
    pub fn is_hertzian(self) -> bool {
        !matches!(
            self,
            LawKind::Linear
                | LawKind::KelvinVoigt
                | LawKind::KelvinVoigtNoTension
                | LawKind::ModifiedLinear
        )
    }

    /// The force differs between approach and restitution (damping acts only while the
    /// bodies approach): the phase is then part of the motion, and its change is located.
    pub fn force_depends_on_phase(self) -> bool {
        matches!(
            self,
            LawKind::ModifiedLinear | LawKind::NonlinearViscoelastic
        )
    }

    /// Uses an impact damping ratio `zeta(e)` from a restitution formula.
    pub fn uses_zeta(self) -> bool {
        matches!(
            self,
            LawKind::KelvinVoigt
                | LawKind::KelvinVoigtNoTension
                | LawKind::ModifiedLinear
                | LawKind::NonlinearViscoelastic
        )
    }

    /// Dissipates energy (takes a coefficient of restitution `e`).
    pub fn is_damped(self) -> bool {
        !matches!(self, LawKind::Linear | LawKind::Hertz)
    }

    /// Hunt-Crossley family: damping `chi = a / v0`.
    pub fn is_hunt_crossley(self) -> bool {
        matches!(
            self,
            LawKind::HuntCrossley
                | LawKind::LankaraniNikravesh
                | LawKind::Flores
                | LawKind::HuntCrossleyExact
        )
    }

    /// Contact ends when the force reaches 0 before `delta` does (clamped at `F >= 0`).
    pub fn clamps_tension(self) -> bool {
        self == LawKind::KelvinVoigtNoTension || self.is_hunt_crossley()
    }

    /// Damping switches off when `delta'` turns negative.
    pub fn switches_phase(self) -> bool {
        matches!(
            self,
            LawKind::ModifiedLinear | LawKind::NonlinearViscoelastic
        )
    }

    /// `a` in `chi = a / v0` for the printed Hunt-Crossley variants.
    pub fn chi_coefficient(self, e: f64) -> Option<f64> {
        match self {
            LawKind::HuntCrossley => Some(1.5 * (1.0 - e)),
            LawKind::LankaraniNikravesh => Some(0.75 * (1.0 - e * e)),
            LawKind::Flores => Some(8.0 * (1.0 - e) / (5.0 * e)),
            _ => None,
        }
    }
}

/// The Hertz contact-duration constant: `t_c = HERTZ_TC * delta_max / v0`, where
/// `HERTZ_TC = 2 * integral_0^1 (1 - x^(5/2))^(-1/2) dx = (4/5) B(2/5, 1/2)`.
pub const HERTZ_TC: f64 = 2.943_275_184_324_7;

/// Hunt-Crossley `chi = a / v0` is singular for grazing impacts; `v0` below this (m/s) counts
/// as this. The same floor applies on every path, so paths agree.
pub const HC_V0_MIN: f64 = 1e-3;

/// A contact element resolved for one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    pub kind: LawKind,
    /// `k` (N/m) for linear laws, `beta` (N/m^1.5) for Hertz-type laws.
    pub stiffness: f64,
    /// Linear laws: `c = 2 zeta sqrt(k m_eff)` (N s/m). Nonlinear viscoelastic:
    /// `c0 = 2 zeta sqrt(beta m_eff)`, so `c = c0 delta^(1/4)`. Hunt-Crossley family: `a` in
    /// `chi = a / v0`. 0 for elastic laws.
    pub damping: f64,
    /// Dimensionless damping measure used to size steps: `zeta`, or `a` for Hunt-Crossley.
    pub damping_ratio: f64,
    /// `m1 m2 / (m1 + m2)`, kg.
    pub m_eff: f64,
    /// [`Contact::tc_coef`], computed once: its `powf` on every step sizing was 1.3 % of a
    /// row sweep's CPU time.
    tc: f64,
}

impl Contact {
    /// `kind` with stiffness and dimensionless damping (`zeta`, or `a` for Hunt-Crossley).
    pub fn new(kind: LawKind, stiffness: f64, damping_ratio: f64, m_eff: f64) -> Contact {
        let damping = if !kind.is_damped() {
            0.0
        } else if kind.is_hunt_crossley() {
            damping_ratio
        } else {
            2.0 * damping_ratio * (stiffness * m_eff).sqrt()
        };
        let damping_ratio = if kind.is_damped() { damping_ratio } else { 0.0 };
        let tc = if kind.is_hertzian() {
            HERTZ_TC * (1.25 * m_eff / stiffness).powf(0.4)
        } else {
            std::f64::consts::PI * (m_eff / stiffness).sqrt()
        };
        Contact {
            kind,
            stiffness,
            damping,
            damping_ratio,
            m_eff,
            tc,
        }
    }

    /// Force while in contact (may be negative only for Kelvin-Voigt with tension, and just
    /// before a clamped separation is located). `approaching` is the integrator's phase; `v0` the
    /// approach speed at first touch of the current impact.
    #[inline]
    pub fn force(&self, delta: f64, ddelta: f64, v0: f64, approaching: bool) -> f64 {
        let (k, c) = (self.stiffness, self.damping);
        match self.kind {
            LawKind::Linear => k * delta,
            LawKind::KelvinVoigt | LawKind::KelvinVoigtNoTension => k * delta + c * ddelta,
            LawKind::ModifiedLinear => k * delta + if approaching { c * ddelta } else { 0.0 },
            LawKind::Hertz => k * delta * delta.abs().sqrt(),
            LawKind::NonlinearViscoelastic => {
                let r = delta.abs().sqrt();
                k * delta * r
                    + if approaching {
                        c * r.sqrt() * ddelta
                    } else {
                        0.0
                    }
            }
            LawKind::HuntCrossley
            | LawKind::LankaraniNikravesh
            | LawKind::Flores
            | LawKind::HuntCrossleyExact => {
                k * delta * delta.abs().sqrt() * (1.0 + self.chi(v0) * ddelta)
            }
        }
    }

    /// The time derivative of [`Contact::force`] along a motion with penetration rate `ddelta`
    /// and acceleration `dddelta`, on the same branch (`approaching`): the peak force inside a
    /// step is read from the cubic Hermite of the force through both ends' values and rates.
    /// At the touch of the nonlinear viscoelastic law, where its damping grows as `delta^(1/4)`
    /// and the rate is unbounded, the damping's share is left out (0: no peak is sought there).
    #[inline]
    pub fn force_rate(
        &self,
        delta: f64,
        ddelta: f64,
        dddelta: f64,
        v0: f64,
        approaching: bool,
    ) -> f64 {
        let (k, c) = (self.stiffness, self.damping);
        match self.kind {
            LawKind::Linear => k * ddelta,
            LawKind::KelvinVoigt | LawKind::KelvinVoigtNoTension => k * ddelta + c * dddelta,
            LawKind::ModifiedLinear => k * ddelta + if approaching { c * dddelta } else { 0.0 },
            LawKind::Hertz => 1.5 * k * delta.abs().sqrt() * ddelta,
            LawKind::NonlinearViscoelastic => {
                let r = delta.abs().sqrt();
                1.5 * k * r * ddelta
                    + if approaching && r > 0.0 {
                        let q = r.sqrt();
                        c * (0.25 * ddelta * ddelta / (r * q) + q * dddelta)
                    } else {
                        0.0
                    }
            }
            LawKind::HuntCrossley
            | LawKind::LankaraniNikravesh
            | LawKind::Flores
            | LawKind::HuntCrossleyExact => {
                let (r, chi) = (delta.abs().sqrt(), self.chi(v0));
                k * r * (1.5 * ddelta * (1.0 + chi * ddelta) + delta * chi * dddelta)
            }
        }
    }

    /// Hunt-Crossley `chi` for an impact at `v0` (floored at [`HC_V0_MIN`]).
    #[inline]
    pub fn chi(&self, v0: f64) -> f64 {
        self.damping / v0.max(HC_V0_MIN)
    }

    /// Positive exactly when the bodies are in contact, and continuous (events are located by
    /// regula falsi on it): `delta` for most laws. For laws clamped at zero tension it is also
    /// <= 0 once the force is: Kelvin-Voigt `delta + min(0, (c/k) delta')` (= F/k when that is
    /// smaller), Hunt-Crossley `delta min(1, 1 + chi delta')` for `delta > 0`.
    #[inline]
    pub fn gauge(&self, delta: f64, ddelta: f64, v0: f64) -> f64 {
        match self.kind {
            LawKind::KelvinVoigtNoTension => {
                delta + (self.damping / self.stiffness * ddelta).min(0.0)
            }
            k if k.is_hunt_crossley() && delta > 0.0 => {
                delta * (1.0 + self.chi(v0) * ddelta).min(1.0)
            }
            _ => delta,
        }
    }

    /// Bound on the contact's fastest rate (1/s) at penetration `delta`: `sqrt(k_loc/m_eff)` plus
    /// `c_loc/m_eff`, from the local stiffness and damping. Keeps explicit substeps stable when
    /// the bodies stay pressed together far beyond an impact's penetration.
    pub fn local_rate(&self, delta: f64, v0: f64) -> f64 {
        let d = delta.max(0.0);
        let (k, c) = (self.stiffness, self.damping);
        let (kl, cl) = match self.kind {
            LawKind::Linear => (k, 0.0),
            LawKind::KelvinVoigt | LawKind::KelvinVoigtNoTension | LawKind::ModifiedLinear => {
                (k, c)
            }
            LawKind::Hertz => (1.5 * k * d.sqrt(), 0.0),
            LawKind::NonlinearViscoelastic => (1.5 * k * d.sqrt(), c * d.sqrt().sqrt()),
            _ => (1.5 * k * d.sqrt(), k * d * d.sqrt() * self.chi(v0)),
        };
        (kl / self.m_eff).sqrt() + cl / self.m_eff
    }

    /// The length from `elapsed` (time since an impact's onset, while approaching) to the next
    /// point of the graded mesh `tc (k / N)^4` (`tc` the duration estimate at `v0`, `N`
    /// `per_contact`) that lies more than `tol` ahead; infinite for the laws that need none.
    /// The nonlinear viscoelastic law's damping `c delta^(1/4) delta'` grows as `t^(1/4)` from
    /// the onset, so an RK4 step that starts there has a local error `O(h^1.25)` in velocity
    /// and the peak force converged only as `h^1.4` (issue 34). On this mesh every piece's
    /// error is `O(N^-4)`: a `t^alpha` singularity needs an exponent `>= 4 / (1 + alpha)` =
    /// 3.2; 4 is reached with products and square roots alone (the shaders have no f64 `pow`).
    /// Mirrored in `shaders/contact.wgsl`.
    #[inline]
    pub fn onset_cut(&self, elapsed: f64, v0: f64, per_contact: f64, tol: f64) -> f64 {
        if self.kind != LawKind::NonlinearViscoelastic {
            return f64::INFINITY;
        }
        let tc = self.duration_estimate(v0);
        // The first point past `elapsed + tol` (where the mesh is denser than `tol`, as near
        // the onset in f32, the first one that is not), then the next while rounding leaves it
        // within `tol`.
        let mut k = (per_contact * ((elapsed.max(0.0) + tol) / tc).sqrt().sqrt()).ceil();
        for _ in 0..3 {
            let s = k / per_contact;
            let cut = tc * (s * s) * (s * s) - elapsed;
            if cut > tol {
                return cut;
            }
            k += 1.0;
        }
        f64::INFINITY
    }

    /// Estimated contact duration for approach speed `v` (Hertz-type durations shrink as
    /// `v^(-1/5)`), s: `tc_coef()` for linear laws, `tc_coef() v^(-1/5)` for Hertz-type laws
    /// (the fifth root by Newton steps, so the shader computes the same number without `pow`).
    pub fn duration_estimate(&self, v: f64) -> f64 {
        if self.kind.is_hertzian() {
            self.tc_coef() * inv_fifth_root(v.max(1e-6))
        } else {
            self.tc_coef()
        }
    }

    /// The speed-independent factor of [`Contact::duration_estimate`]: `pi sqrt(m_eff / k)` for
    /// linear laws; for Hertz-type laws, from `delta_max = (5 m_eff v^2 / (4 beta))^(2/5)`,
    /// `HERTZ_TC (1.25 m_eff / beta)^(2/5)`.
    pub fn tc_coef(&self) -> f64 {
        self.tc
    }
}

/// `v^(-1/5)` for `v > 0`: an f32 `powf` seed and two Newton steps on `y^-5 = v`
/// (`y <- y (6 - v y^5) / 5`), arithmetic only in f64; mirrored in the shader.
#[inline]
pub fn inv_fifth_root(v: f64) -> f64 {
    let mut y = (v as f32).powf(-0.2) as f64;
    for _ in 0..2 {
        let y2 = y * y;
        y = y * (6.0 - v * (y2 * y2 * y)) / 5.0;
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inv_fifth_root_is_accurate() {
        for v in [1e-6f64, 3.7e-4, 0.01, 0.5, 1.0, 2.3, 47.0, 1e3] {
            let exact = v.powf(-0.2);
            assert!(
                (inv_fifth_root(v) - exact).abs() <= 4.0 * f64::EPSILON * exact,
                "{v}"
            );
        }
    }

    /// The force's rate is the derivative of the force along a motion, for every law and both
    /// branches: against a central difference of `force` along `delta(t) = d + v t + a t^2 / 2`.
    #[test]
    fn force_rate_is_the_derivative_of_the_force() {
        for l in LawKind::ALL {
            let stiffness = if l.is_hertzian() { 2.75e9 } else { 1e9 };
            let c = Contact::new(l, stiffness, 0.3, 5e4);
            for (d, v, a) in [(2e-3, 0.4, -30.0), (5e-4, -0.2, 12.0), (1e-3, 0.05, -200.0)] {
                for approaching in [true, false] {
                    let at =
                        |t: f64| c.force(d + v * t + 0.5 * a * t * t, v + a * t, 0.3, approaching);
                    let e = 1e-7;
                    let numeric = (at(e) - at(-e)) / (2.0 * e);
                    let rate = c.force_rate(d, v, a, 0.3, approaching);
                    assert!(
                        (rate - numeric).abs() <= 1e-6 * numeric.abs().max(1.0),
                        "{l:?} approaching {approaching} at {d} {v} {a}: {rate} against {numeric}"
                    );
                }
            }
        }
    }

    #[test]
    fn keys_round_trip() {
        for l in LawKind::ALL {
            assert_eq!(LawKind::from_key(l.key()), Some(l));
        }
    }
}

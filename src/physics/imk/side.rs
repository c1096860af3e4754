//! One side's backbone of an IMK spring, in magnitudes (`x` drift outwards, `g` force outwards):
//! its deteriorated yield and capping points, the line segments it is made of, and how an energy
//! excursion deteriorates it (OpenSees' `IMKBilin` and `IMKPeakOriented`, the positive side's
//! code; the negative side's is its mirror).

use super::{ImkSpring, Mark};
use crate::physics::shear::ImkRule;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Side {
    /// Yield force and drift; hardening stiffness.
    pub fy: f64,
    pub uy: f64,
    pub kp: f64,
    /// Capping drift and force; post-capping stiffness (`<= 0`).
    pub ucap: f64,
    pub fcap: f64,
    pub kpc: f64,
    /// It has no strength left.
    pub failed: bool,
    /// Peak-oriented: the last reversal point from a loading branch, and the farthest.
    pub x_local: f64,
    pub g_local: f64,
    pub x_global: f64,
    pub g_global: f64,
}

impl Side {
    pub fn new(sp: &ImkSpring) -> Side {
        let uy = sp.fy / sp.k;
        let fcap = sp.fcap0();
        Side {
            fy: sp.fy,
            uy,
            kp: sp.kp,
            ucap: uy + sp.up,
            fcap,
            kpc: -fcap / sp.upc,
            failed: false,
            x_local: uy,
            g_local: sp.fy,
            x_global: uy,
            g_global: sp.fy,
        }
    }

    /// The drift where the post-capping line reaches the residual strength (infinite where it
    /// is flat).
    fn ures(&self, sp: &ImkSpring) -> f64 {
        if self.kpc < 0.0 {
            self.ucap + (sp.fres - self.fcap) / self.kpc
        } else {
            f64::INFINITY
        }
    }

    /// The backbone at `x`: its force, slope, and the drift where that segment ends with what
    /// comes there (`other_failed`: `IMKBilin` holds a side at its residual strength once the
    /// other has lost its own).
    pub fn segment(&self, sp: &ImkSpring, x: f64, other_failed: bool) -> (f64, f64, f64, Mark) {
        let inf = f64::INFINITY;
        if self.failed {
            return (0.0, 0.0, inf, Mark::None);
        }
        let ures = self.ures(sp);
        let at_residual = if sp.fres > 0.0 {
            Mark::Break
        } else {
            Mark::NoStrength
        };
        match sp.rule {
            ImkRule::Bilinear => {
                if other_failed {
                    return (sp.fres, 0.0, inf, Mark::None);
                }
                if x < self.ucap {
                    // The hardening line, floored at the residual strength far inside.
                    let g = self.fcap + self.kp * (x - self.ucap);
                    if self.kp > 0.0 {
                        let x_floor = self.ucap + (sp.fres - self.fcap) / self.kp;
                        if x < x_floor {
                            return (sp.fres, 0.0, x_floor, Mark::Break);
                        }
                    }
                    (g, self.kp, self.ucap, Mark::Break)
                } else if x < ures {
                    let g = self.fcap + self.kpc * (x - self.ucap);
                    (g, self.kpc, ures, at_residual)
                } else if self.kpc < 0.0 {
                    (sp.fres, 0.0, inf, Mark::None)
                } else {
                    (self.fcap.max(sp.fres), 0.0, inf, Mark::None)
                }
            }
            ImkRule::PeakOriented => {
                if x < self.ucap {
                    (
                        self.fcap + self.kp * (x - self.ucap),
                        self.kp,
                        self.ucap,
                        Mark::Break,
                    )
                } else if x < ures {
                    let g = self.fcap + self.kpc * (x - self.ucap);
                    (g, self.kpc, ures, at_residual)
                } else {
                    (sp.fres, 0.0, inf, Mark::None)
                }
            }
        }
    }

    /// `IMKBilin`: is `x` on the residual plateau?
    pub fn in_residual(&self, sp: &ImkSpring, x: f64) -> bool {
        if self.kpc < 0.0 {
            x >= self.ures(sp)
        } else {
            self.fcap <= sp.fres
        }
    }

    /// `IMKBilin`: the residual drift a piece off the backbone may pass (its flag), if any.
    pub fn bilin_residual_drift(&self, sp: &ImkSpring, other_failed: bool) -> Option<f64> {
        (!self.failed && !other_failed && self.kpc < 0.0).then(|| self.ures(sp))
    }

    /// `IMKBilin`: the first drift from `x0` outwards where the line through `(x0, g0)` with
    /// `slope` reaches this side's bounding line from below (infinite: never).
    pub fn bilin_meet(
        &self,
        sp: &ImkSpring,
        x0: f64,
        g0: f64,
        slope: f64,
        other_failed: bool,
    ) -> f64 {
        let mut x = x0;
        for _ in 0..6 {
            let (g_b, s_b, end, _) = self.segment(sp, x, other_failed);
            let gap = g_b - (g0 + slope * (x - x0));
            if gap <= 0.0 {
                return x;
            }
            if slope > s_b {
                let hit = x + gap / (slope - s_b);
                if hit <= end {
                    return hit;
                }
            }
            if !end.is_finite() {
                return f64::INFINITY;
            }
            x = end;
        }
        f64::INFINITY
    }

    /// Deteriorate by the factor `beta` of a new excursion towards this side that starts at
    /// `(x_from, g_from)` with unloading stiffness `kunload`: yield strength and hardening
    /// scaled by `1 - beta`, the post-capping line moved towards the origin by the same factor,
    /// the capping point their new intersection (OpenSees' rule, both materials; `IMKBilin`
    /// also flattens the post-capping slope with the strength and keeps the hardening line
    /// above the residual strength).
    pub fn deteriorate(
        &mut self,
        sp: &ImkSpring,
        beta: f64,
        (x_from, g_from, kunload): (f64, f64, f64),
    ) {
        let keep = 1.0 - beta;
        let fcap_proj = (self.fcap - self.kpc * self.ucap) * keep;
        self.fy *= keep;
        self.kp *= keep;
        self.uy = self.fy / sp.k;
        if sp.rule == ImkRule::Bilinear {
            let kpc0 = sp.fcap0() / sp.upc;
            self.kpc = if self.fy < sp.fres {
                0.0
            } else {
                -kpc0 * (self.fy - sp.fres) / (sp.fy - sp.fres)
            };
        }
        let fy_proj = self.fy - self.kp * self.uy;
        self.ucap = if self.kp <= self.kpc {
            0.0
        } else {
            (fcap_proj - fy_proj) / (self.kp - self.kpc)
        };
        self.fcap = fy_proj + self.kp * self.ucap;
        match sp.rule {
            ImkRule::Bilinear => {
                let to_residual = self.ucap - x_from - (sp.fres - g_from) / kunload;
                let candidate = (self.fcap - sp.fres) / to_residual;
                if self.fcap < sp.fres {
                    self.fy = sp.fres;
                    self.fcap = sp.fres;
                    self.kp = 0.0;
                    self.kpc = 0.0;
                    self.uy = self.fy / sp.k;
                    self.ucap = 0.0;
                } else if candidate > 0.0 && self.kp > candidate {
                    self.kp = candidate;
                }
            }
            ImkRule::PeakOriented => {
                // The peak to reload to, on the deteriorated backbone at its drift.
                let x = self.x_global;
                let g = if x < self.uy {
                    sp.k * x
                } else if x < self.ucap {
                    self.fy + self.kp * (x - self.uy)
                } else {
                    self.fcap + self.kpc * (x - self.ucap)
                };
                self.g_global = g.max(sp.fres);
            }
        }
    }
}

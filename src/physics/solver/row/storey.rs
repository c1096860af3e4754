//! One yielding storey as the integrators see it (its spring's state, its drift and its band
//! in the model's coordinates) and the band-edge checks a step makes: the part of the
//! storeys' model ([`super::yielding`]) that the row's model and its integration read.

use super::algebra::dot;
use crate::physics::imk::{ImkSpring, Piece};
use crate::physics::solver::events::error_margin;
use crate::physics::solver::hermite::{cubic_max_bound, hermite_range};

/// A storey yields once its back drift passes its band by this fraction: the band edge an
/// unloading storey leaves from is then inside its band, not on it, to rounding.
pub(crate) const YIELD_SLACK: f64 = 1e-9;

/// The state of one storey's spring.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) enum StoreyMode {
    /// Inside its band: force slope `k`, plastic drift constant.
    #[default]
    Elastic,
    /// On its upper (`+1`) or lower (`-1`) bounding line: force slope `b k`.
    Yielding(f64),
    /// A deteriorating (IMK) storey on this piece of its force-drift law
    /// ([`crate::physics::imk`]): force slope `piece.slope`.
    Imk(Piece),
}

/// One yielding storey, as the integrators see it.
#[derive(Debug, Clone)]
pub(crate) struct StoreyModel {
    pub building: usize,
    /// Storey of the building, from 0 (storey 0 joins the ground and floor 0).
    pub storey: usize,
    /// Initial stiffness, N/m; yield drift `F_y / k`, m; post-yield ratio; storey height, m.
    pub k: f64,
    pub d_y: f64,
    pub b: f64,
    pub height: f64,
    /// Geometric stiffness `P / h` of P-Delta, N/m (0 without).
    pub geometric: f64,
    /// The drift in the building's modes: `d = modal_row . q`.
    pub modal_row: Vec<f64>,
    /// The drift in the model's coordinates: `d = row . z[off..off + row.len()]` (the modes, or
    /// the two floors where the building is in floor coordinates).
    pub off: usize,
    pub row: Vec<f64>,
    /// How the storey's plastic load `k p` enters the accelerations `z'[n + off + i]`: the
    /// modal row again (`Phi^T D^T`), or `+-1 / m` of the two floors.
    pub psi: Vec<f64>,
    /// Its IMK spring where it deteriorates (None: bilinear).
    pub imk: Option<ImkSpring>,
}

impl StoreyModel {
    /// Drift (`n = 0`) or drift rate (`n` the mode count) in state `z`.
    #[inline]
    pub fn drift(&self, z: &[f64], n: usize) -> f64 {
        dot(&self.row, &z[n + self.off..n + self.off + self.row.len()])
    }

    /// Back drift `d - p / (1 - b)`: the band is `|s| <= d_y`.
    #[inline]
    pub fn back_drift(&self, d: f64, p: f64) -> f64 {
        d - p / (1.0 - self.b)
    }

    /// Positive once `mode` must end: the back drift past the band (elastic), the drift
    /// velocity reversed (yielding), an IMK piece's threshold passed or its heading reversed.
    #[inline]
    pub fn event_value(&self, mode: StoreyMode, d: f64, rate: f64, p: f64) -> f64 {
        match mode {
            StoreyMode::Elastic => self.back_drift(d, p).abs() - self.d_y * (1.0 + YIELD_SLACK),
            StoreyMode::Yielding(sign) => -sign * rate,
            StoreyMode::Imk(piece) => piece.event_value(d, rate, self.imk_slack()),
        }
    }

    /// An IMK piece's event parts ([`Piece::event_parts`]); None in the other modes.
    #[inline]
    pub fn event_parts(&self, mode: StoreyMode, d: f64, rate: f64) -> Option<[f64; 3]> {
        match mode {
            StoreyMode::Imk(piece) => Some(piece.event_parts(d, rate, self.imk_slack())),
            _ => None,
        }
    }

    /// The drift an IMK piece's threshold may be passed by before its event fires.
    #[inline]
    fn imk_slack(&self) -> f64 {
        self.imk.as_ref().map_or(0.0, ImkSpring::slack)
    }

    /// The plastic drift's rate over the drift's in `mode`: `p' = flow d'` (0 where the force
    /// moves with the initial stiffness, so the plastic drift stands still).
    #[inline]
    pub fn flow(&self, mode: StoreyMode) -> f64 {
        match mode {
            StoreyMode::Elastic => 0.0,
            StoreyMode::Yielding(_) => 1.0 - self.b,
            StoreyMode::Imk(piece) => 1.0 - piece.slope / self.k,
        }
    }

    /// Can the storey in `mode` take an exact free step (its plastic drift standing still, and
    /// no reversal to watch)? An elastic storey, an IMK one on a piece of the initial stiffness
    /// that does not flow one way.
    #[inline]
    pub fn free(&self, mode: StoreyMode) -> bool {
        match mode {
            StoreyMode::Elastic => true,
            StoreyMode::Yielding(_) => false,
            StoreyMode::Imk(piece) => piece.slope == self.k && piece.heading == 0.0,
        }
    }

    /// The edges of what `mode` may not pass without an event, as functions that reach 0 on
    /// them, with their rates (for the checks of a step that no event hides inside it): the
    /// band of an elastic storey, the thresholds of an IMK piece; none while it yields.
    #[inline]
    pub fn mode_edges(
        &self,
        mode: StoreyMode,
        d: f64,
        rate: f64,
        p: f64,
    ) -> Option<[(f64, f64); 2]> {
        match mode {
            StoreyMode::Elastic => Some(self.edges(d, rate, p)),
            StoreyMode::Yielding(_) => None,
            StoreyMode::Imk(piece) => {
                let slack = self.imk_slack();
                Some([(d - piece.hi - slack, rate), (piece.lo - d - slack, -rate)])
            }
        }
    }

    /// Could the elastic storey reach a bounding line inside a free step of length `h` with
    /// drift and rate `[d0, d0', d1, d1']` at its ends and plastic drift `p`, when `bound`
    /// bounds `|d''''|` over it? As a level's `may_touch`: the Hermite cubic of each edge
    /// function within twice its error bound of 0.
    pub fn may_yield(
        &self,
        mode: StoreyMode,
        [d0, r0, d1, r1]: [f64; 4],
        p: f64,
        bound: f64,
        h: f64,
    ) -> bool {
        match (
            self.mode_edges(mode, d0, r0, p),
            self.mode_edges(mode, d1, r1, p),
        ) {
            (Some(e0), Some(e1)) => may_reach(e0, e1, bound, h),
            _ => true,
        }
    }

    /// The band's two edges as functions that reach 0 on them: `[s - d_y, -s - d_y]` with
    /// their rates, for the hidden-yield checks of a step.
    #[inline]
    pub fn edges(&self, d: f64, rate: f64, p: f64) -> [(f64, f64); 2] {
        band_edges(self.back_drift(d, p), rate, self.d_y * (1.0 + YIELD_SLACK))
    }
}

/// The edges of the band `|x| <= half` as functions that reach 0 on them, `[x - half, -x -
/// half]`, with their rates from `x`'s `rate`: a yielding storey's band in its back drift, a
/// drift's collapse limit.
#[inline]
pub(crate) fn band_edges(x: f64, rate: f64, half: f64) -> [(f64, f64); 2] {
    [(x - half, rate), (-x - half, -rate)]
}

/// Could an edge function (value and rate at both ends of a free step of length `h`, `bound`
/// bounding its fourth derivative) reach 0 inside the step? As a level's `may_touch`: the
/// Hermite cubic of each within twice its error bound of 0.
pub(crate) fn may_reach(e0: [(f64, f64); 2], e1: [(f64, f64); 2], bound: f64, h: f64) -> bool {
    let margin = -error_margin(bound, h);
    e0.iter().zip(&e1).any(|(a, b)| {
        cubic_max_bound(a.0, a.1, b.0, b.1, h) > margin
            && (a.0 > 0.0 || b.0 > 0.0 || hermite_range(a.0, a.1, b.0, b.1, h).1 > margin)
    })
}

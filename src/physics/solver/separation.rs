//! The separation a row of buildings needs: at every floor level two neighbours share, the
//! largest closing of their floors `max_t (u_left(t) - u_right(t))` with no contact at all
//! (pounding happens at that level if and only if the gap is smaller), and each of those floors'
//! peak displacement `max_t |u|`, which the code rules of [`crate::physics::separation`] combine.
//!
//! Every building is stepped from rest in its modes by the exact propagator, so the states at the
//! record's samples carry no truncation error. Between samples each quantity is a smooth
//! function whose value, slope and curvature are known at both ends, and the quintic Hermite
//! through them is within `h^6 max|f^(6)| / 46080` of it. That bound is computed per step
//! (`FreeMode::sixth_derivative_bound`): only a step whose quintic comes within it of the running
//! extremum could raise that extremum, and such a step is stepped again exactly in
//! [`REFINE_SUBSTEPS`] parts, whose quintics are `REFINE_SUBSTEPS^6` (1.7e7) times closer. So
//! every extremum is exact to [`Separation::error_bound`], which is reported. The result is
//! linear in the record's scale: a response at one scale serves every intensity
//! ([`Separation::scaled`]). Modes whose damping couples them (Rayleigh damping of a P-Delta
//! building whose storeys lean unequally) are stepped together by the exact coupled propagator,
//! as the sweep's free steps take them, with one bound for them all
//! (`Coupled::sixth_derivative_bound`).
//!
//! Buildings with yielding storeys are not linear: [`yielding_separation`] runs the row scheme
//! with the levels out of reach, once per intensity, and takes the same quantities from its
//! pieces (the quintic Hermite of each free piece, as the sweep's peaks); no bound is known
//! there, so none is reported (its error is measured against the reference, docs/inelastic.md).

use super::hermite::{quintic_range, quintic_signed_bounds};
use super::row::{simulate_uncoupled, RowModel, RowScheme, UNCOUPLED_GAP_M};
use super::state::Segment;
use crate::physics::contact::LawKind;
use crate::physics::model::{Forcing, Oscillator, Status};
use crate::physics::propagator::{CoupledPropagator, Propagator};
use crate::physics::row::{contact_points, LevelRule, LevelSide, Row};
use crate::physics::shear::{Modes, ShearBuilding};

/// Most parts a refined step is cut into: 2, 4, 8 or 16, the fewest that bring the parts'
/// error bound within [`TOLERANCE`] of the quantity.
pub const REFINE_SUBSTEPS: usize = 16;

/// The part counts a step may be refined with.
const PART_COUNTS: [usize; 4] = [2, 4, 8, 16];

/// One floor level that two neighbours share, and what it needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelSeparation {
    /// The left building of the pair (the right one is `pair + 1`).
    pub pair: usize,
    /// Where it meets the two buildings: a floor, or a storey's columns (floors from 1).
    pub sides: [LevelSide; 2],
    /// m
    pub elevation: f64,
    /// `max(0, max_t (u_left - u_right))`, m: the smallest gap at which this level never
    /// touches.
    pub required: f64,
    /// When that closing is reached, s (None when the floors never close past 0).
    pub time: Option<f64>,
    /// `max_t |u|` of the two floors, m.
    pub peak_left: f64,
    pub peak_right: f64,
}

/// The separation a run needs, level by level (ordered by pair, then elevation).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Separation {
    pub levels: Vec<LevelSeparation>,
    /// Record steps stepped again in parts (the work beyond the exact steps).
    pub refined_steps: u64,
    /// Substeps taken where storeys yield ([`yielding_separation`]; 0 elsewhere).
    pub substeps: u64,
    /// Per building, its fundamental mode's circular frequency (rad/s) and damping ratio.
    pub fundamental: Vec<(f64, f64)>,
    /// A bound on the error of every displacement here (m, at the record's scale): the largest
    /// interpolation error of the quintics the extrema were taken from (None where storeys
    /// yield: [`yielding_separation`]).
    pub error_bound: Option<f64>,
}

impl Separation {
    /// The separation under the same record scaled by `s > 0`: every displacement scales by `s`,
    /// times do not.
    pub fn scaled(&self, s: f64) -> Separation {
        Separation {
            levels: self
                .levels
                .iter()
                .map(|l| LevelSeparation {
                    required: l.required * s,
                    peak_left: l.peak_left * s,
                    peak_right: l.peak_right * s,
                    ..*l
                })
                .collect(),
            refined_steps: self.refined_steps,
            substeps: self.substeps,
            fundamental: self.fundamental.clone(),
            error_bound: self.error_bound.map(|e| e * s),
        }
    }
}

/// One building's modes and propagators.
struct Stepped {
    modes: Modes,
    osc: Vec<Oscillator>,
    whole: Vec<Propagator>,
    free: Vec<FreeMode>,
    /// Per entry of [`PART_COUNTS`], the propagators of one part.
    parts: Vec<Vec<Propagator>>,
    /// Where its damping couples its modes (Rayleigh damping of a P-Delta building whose
    /// storeys lean unequally), their exact coupled steps, as the sweep's free steps take them.
    coupled: Option<Coupled>,
}

/// The modes of a building whose damping couples them: `q'' + D q' + W^2 q = -L ag` with `D`
/// the full modal damping (`2 xi w` on its diagonal, the coupling `E` off it).
struct Coupled {
    whole: CoupledPropagator,
    /// Per entry of [`PART_COUNTS`], the propagator of one part.
    parts: Vec<CoupledPropagator>,
    /// `D`, row-major.
    damping: Vec<f64>,
    /// `w_i^2`
    w2: Vec<f64>,
}

impl Coupled {
    fn new(modes: &Modes, e: &[Vec<f64>], dt: f64) -> Coupled {
        let n = modes.count();
        let w2: Vec<f64> = modes.omega.iter().map(|w| w * w).collect();
        let c: Vec<f64> = (0..n).map(|i| 2.0 * modes.xi[i] * modes.omega[i]).collect();
        let at = |h: f64| CoupledPropagator::new(&w2, &c, e, &modes.participation, h);
        let damping = (0..n)
            .flat_map(|i| (0..n).map(move |k| (i, k)))
            .map(|(i, k)| if i == k { c[i] } else { e[i][k] })
            .collect();
        Coupled {
            whole: at(dt),
            parts: PART_COUNTS.iter().map(|&p| at(dt / p as f64)).collect(),
            damping,
            w2,
        }
    }

    /// `(D v)_i`
    #[inline]
    fn damp(&self, v: &[f64], i: usize) -> f64 {
        let n = v.len();
        self.damping[i * n..(i + 1) * n]
            .iter()
            .zip(v)
            .map(|(d, v)| d * v)
            .sum()
    }

    /// A bound on the energy norm `|y|_E = sqrt(sum w_i^2 x_i^2 + x_i'^2)` of the sixth
    /// derivative of the modes' homogeneous motion `y = (x, x')` over a step from `m` under
    /// `L ag`, `ag = f + g t`.
    ///
    /// The load's particular response `q_p = alpha + beta t` is linear (`W^2 beta = -L g`,
    /// `W^2 alpha = -L f - D beta`), so the sixth derivative is the homogeneous part's, whose
    /// derivatives all solve the free equation `y' = A y`. There `d|y|_E^2 / dt = -2 x'^T D x'
    /// <= 0` (`D = Phi^T (a0 M + a1 K0) Phi` is positive semi-definite): free motion never
    /// gains energy, so over the whole step `|y^(6)|_E <= |A^6 y(0)|_E`, computed exactly.
    fn sixth_derivative_bound(
        &self,
        m: &Modal,
        l: &[f64],
        f: f64,
        g: f64,
        scratch: &mut [f64],
    ) -> f64 {
        let n = self.w2.len();
        let (x, rest) = scratch.split_at_mut(n);
        let (v, rest) = rest.split_at_mut(n);
        let (dv, _) = rest.split_at_mut(n);
        for i in 0..n {
            v[i] = -l[i] * g / self.w2[i];
        }
        for i in 0..n {
            x[i] = m.q[i] + (l[i] * f + self.damp(v, i)) / self.w2[i];
        }
        for (v, qd) in v.iter_mut().zip(&m.qd) {
            *v = qd - *v;
        }
        for _ in 0..6 {
            for i in 0..n {
                dv[i] = -self.w2[i] * x[i] - self.damp(v, i);
            }
            x.copy_from_slice(v);
            v.copy_from_slice(dv);
        }
        (0..n)
            .map(|i| self.w2[i] * x[i] * x[i] + v[i] * v[i])
            .sum::<f64>()
            .sqrt()
    }
}

impl Stepped {
    fn new(b: &ShearBuilding, dt: f64) -> Stepped {
        let modes = b.modes();
        let osc: Vec<Oscillator> = (0..modes.count()).map(|i| modes.oscillator(i)).collect();
        let whole = osc.iter().map(|o| Propagator::new(o, dt)).collect();
        let parts = PART_COUNTS
            .iter()
            .map(|&n| {
                osc.iter()
                    .map(|o| Propagator::new(o, dt / n as f64))
                    .collect()
            })
            .collect();
        let coupled = modes.coupling.as_ref().map(|e| Coupled::new(&modes, e, dt));
        Stepped {
            free: osc.iter().map(FreeMode::new).collect(),
            modes,
            osc,
            whole,
            parts,
            coupled,
        }
    }

    /// Step the modes `q`, `q'` over `ag` from `a0` to `a1` with the propagators `p` (or, where
    /// the modes are coupled, with the coupled one of `part`: None for the whole step, else
    /// the entry of [`PART_COUNTS`]).
    #[inline]
    fn step(&self, m: &mut Modal, p: &[Propagator], part: Option<usize>, a0: f64, a1: f64) {
        if let Some(c) = &self.coupled {
            let cp = part.map_or(&c.whole, |k| &c.parts[k]);
            let n = m.q.len();
            let (x0, x1) = m.scratch.split_at_mut(2 * n);
            x0[..n].copy_from_slice(&m.q);
            x0[n..].copy_from_slice(&m.qd);
            cp.step(x0, a0, a1, &mut x1[..2 * n]);
            m.q.copy_from_slice(&x1[..n]);
            m.qd.copy_from_slice(&x1[n..2 * n]);
            return;
        }
        for (i, p) in p.iter().enumerate() {
            let l = self.modes.participation[i];
            (m.q[i], m.qd[i]) = p.step(m.q[i], m.qd[i], l * a0, l * a1);
        }
    }

    /// Per mode, [`sixth_derivative_bound`] over a step from `m` with `ag` from `a0` to `a1`,
    /// `inv_dt = 1 / dt`; where the modes are coupled, one bound for them all
    /// ([`Coupled::sixth_derivative_bound`]), in `out[0]`.
    #[inline]
    fn sixth_bounds(&self, m: &mut Modal, a0: f64, a1: f64, inv_dt: f64, out: &mut [f64]) {
        let slope = (a1 - a0) * inv_dt;
        if let Some(c) = &self.coupled {
            let mut scratch = std::mem::take(&mut m.scratch);
            out[0] =
                c.sixth_derivative_bound(m, &self.modes.participation, a0, slope, &mut scratch);
            m.scratch = scratch;
            return;
        }
        for (i, o) in self.free.iter().enumerate() {
            let l = self.modes.participation[i];
            out[i] = o.sixth_derivative_bound(m.q[i], m.qd[i], l * a0, l * slope);
        }
    }

    /// Per mode, the weight of its sixth-derivative bound in that of the point whose mode-shape
    /// row is `shape`: `|shape_i|`; where the modes are coupled, one weight for their energy
    /// norm's bound, `sqrt(sum (shape_i / w_i)^2)` (Cauchy-Schwarz).
    fn bound_row(&self, shape: &[f64]) -> Vec<f64> {
        match &self.coupled {
            None => shape.iter().map(|p| p.abs()).collect(),
            Some(c) => vec![shape
                .iter()
                .zip(&c.w2)
                .map(|(p, w2)| p * p / w2)
                .sum::<f64>()
                .sqrt()],
        }
    }

    /// Displacement, velocity and acceleration (relative to the ground) of the point whose
    /// mode-shape row is `shape`.
    #[inline]
    fn floor(&self, m: &Modal, shape: &[f64], ag: f64) -> [f64; 3] {
        let (mut u, mut v, mut a) = (0.0, 0.0, 0.0);
        if let Some(c) = &self.coupled {
            for (i, o) in self.osc.iter().enumerate() {
                let qdd = -o.k * m.q[i] - c.damp(&m.qd, i) - self.modes.participation[i] * ag;
                u += shape[i] * m.q[i];
                v += shape[i] * m.qd[i];
                a += shape[i] * qdd;
            }
            return [u, v, a];
        }
        for (i, o) in self.osc.iter().enumerate() {
            let qdd = -o.c * m.qd[i] - o.k * m.q[i] - self.modes.participation[i] * ag;
            u += shape[i] * m.q[i];
            v += shape[i] * m.qd[i];
            a += shape[i] * qdd;
        }
        [u, v, a]
    }
}

/// A unit-mass oscillator `q'' = -k q - c q' - f - g t`, with what
/// [`FreeMode::sixth_derivative_bound`] needs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FreeMode {
    c: f64,
    inv_k: f64,
    /// `1 / omega`, `omega = sqrt(k)`.
    inv_omega: f64,
    /// `(omega + c)^6`
    growth: f64,
}

impl FreeMode {
    pub fn new(o: &Oscillator) -> FreeMode {
        let (k, c) = (o.k / o.m, o.c / o.m);
        let omega = k.sqrt();
        FreeMode {
            c,
            inv_k: 1.0 / k,
            inv_omega: 1.0 / omega,
            growth: (omega + c).powi(6),
        }
    }

    /// A bound on `|q^(6)|` over a step from `(q, q')` under a load `f + g t` that is linear
    /// over the step.
    ///
    /// The load's particular response is linear in `t` (its sixth derivative is 0), so
    /// `q^(6)` is that of the homogeneous part `x = q - q_p`, whose derivatives all solve the
    /// free equation `y' = A y`, `y = (x, x')`. Free motion never gains energy: the norm
    /// `|y| = sqrt(x^2 + x'^2 / k)` of every derivative never grows (damping only takes it
    /// out, at any damping ratio). In that norm `|A| <= omega + c`, so for the rest of the step
    /// `|x^(6)| <= |A^6 y(0)| <= (omega + c)^6 (|x| + |x'| / omega)`.
    #[inline]
    pub fn sixth_derivative_bound(&self, q: f64, qd: f64, f: f64, g: f64) -> f64 {
        // q_p = alpha + beta t with -k q_p - c beta = f + g t.
        let beta = -g * self.inv_k;
        let alpha = -(f + self.c * beta) * self.inv_k;
        self.growth * ((q - alpha).abs() + (qd - beta).abs() * self.inv_omega)
    }
}

/// One building's modal displacements and velocities.
#[derive(Clone)]
struct Modal {
    q: Vec<f64>,
    qd: Vec<f64>,
    /// Room for the coupled modes' steps and bounds (empty where the modes are not coupled).
    scratch: Vec<f64>,
}

impl Modal {
    /// Copy `other` in place (the derived `clone_from` would allocate).
    #[inline]
    fn set(&mut self, other: &Modal) {
        self.q.copy_from_slice(&other.q);
        self.qd.copy_from_slice(&other.qd);
    }
}

/// A quantity whose extrema are tracked: one floor's displacement, or the difference of two.
struct Tracked {
    /// Indices into the watched floors: `plus - minus` (no `minus` for one floor).
    plus: usize,
    minus: Option<usize>,
    /// Track the minimum too (a floor's peak is `max |u|`; a closing needs only its maximum).
    both: bool,
    /// Identically 0: the closing of the same floor of two identical buildings.
    zero: bool,
    lo: f64,
    hi: f64,
    t_hi: f64,
    /// How far the quantity could reach past `lo` and `hi`: the extrema of the quintics
    /// they were taken from, widened by each one's error bound.
    reach_lo: f64,
    reach_hi: f64,
}

impl Tracked {
    fn new(plus: usize, minus: Option<usize>) -> Tracked {
        Tracked {
            plus,
            minus,
            both: minus.is_none(),
            zero: false,
            lo: 0.0,
            hi: 0.0,
            t_hi: 0.0,
            reach_lo: 0.0,
            reach_hi: 0.0,
        }
    }

    /// The largest magnitude so far.
    #[inline]
    fn magnitude(&self) -> f64 {
        self.hi.max(-self.lo)
    }

    /// How far the extrema it reports could be from the quantity's.
    fn error(&self) -> f64 {
        let hi = self.reach_hi - self.hi;
        if self.both {
            hi.max(self.lo - self.reach_lo)
        } else {
            hi
        }
    }

    /// The sum over its floors of `per_floor`.
    #[inline]
    fn sum(&self, per_floor: &[f64]) -> f64 {
        per_floor[self.plus] + self.minus.map_or(0.0, |m| per_floor[m])
    }

    /// Value, slope and curvature from the watched floors' `[u, u', u'']`.
    #[inline]
    fn of(&self, floors: &[[f64; 3]]) -> [f64; 3] {
        let p = floors[self.plus];
        match self.minus {
            Some(m) => {
                let n = floors[m];
                [p[0] - n[0], p[1] - n[1], p[2] - n[2]]
            }
            None => p,
        }
    }

    /// Raise the extrema to those of the quintic through `a` and `b` over a step `h` from
    /// `t0`, which is within `e` of the quantity.
    #[inline]
    fn raise(&mut self, a: [f64; 3], b: [f64; 3], t0: f64, h: f64, e: f64) {
        if self.zero {
            return;
        }
        let [(lo, _), (hi, s)] = quintic_range([a[0], b[0]], [a[1], b[1]], [a[2], b[2]], h);
        self.reach_lo = self.reach_lo.min(lo - e);
        self.reach_hi = self.reach_hi.max(hi + e);
        self.lo = self.lo.min(lo);
        if hi > self.hi {
            self.hi = hi;
            self.t_hi = t0 + s * h;
        }
    }

    /// What a step from `a` to `b` needs, given `m`, its quintic's error bound: nothing where
    /// the quintic stays more than `m` inside the extrema (the quantity cannot raise them);
    /// else the quintic's extrema where `m` is within [`TOLERANCE`] of the quantity's
    /// magnitude (or of `floors`, its floors' magnitude, for a closing, which is 0 between
    /// buildings that move as one); else refining. Returns the magnitude too.
    #[inline]
    fn needs(&self, a: [f64; 3], b: [f64; 3], h: f64, m: f64, floors: f64) -> (Need, f64) {
        let (y, d, c) = ([a[0], b[0]], [a[1], b[1]], [a[2], b[2]]);
        let (lo, hi) = quintic_signed_bounds(y, d, c, h);
        if self.zero || (hi < self.hi - m && !(self.both && lo <= self.lo + m)) {
            return (Need::Nothing, 0.0);
        }
        let scale = self.magnitude().max(y[0].abs()).max(y[1].abs()).max(floors);
        if m <= TOLERANCE * scale {
            return (Need::Quintic, scale);
        }
        let [(lo, _), (hi, _)] = quintic_range(y, d, c, h);
        if hi >= self.hi - m || (self.both && lo <= self.lo + m) {
            (Need::Refining, scale)
        } else {
            (Need::Nothing, scale)
        }
    }
}

/// What one record step needs for one tracked quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Need {
    Nothing,
    /// The quintic's extrema, within the tolerated error.
    Quintic,
    Refining,
}

/// A step is not refined where its quintic's error bound is at most this share of the
/// quantity's magnitude: the extrema are taken from the quintic, within the bound.
pub const TOLERANCE: f64 = 1e-8;

/// The watched floors' `[u, u', u'']` at one instant, into `out`.
fn floors_at(
    stepped: &[Stepped],
    watched: &[Watched],
    state: &[Modal],
    ag: f64,
    out: &mut [[f64; 3]],
) {
    for (o, w) in out.iter_mut().zip(watched) {
        *o = stepped[w.building].floor(&state[w.building], &w.row, ag);
    }
}

/// A point whose motion a separation watches: a floor, or a storey's columns at a height.
struct Watched {
    building: usize,
    side: LevelSide,
    /// Its mode-shape row.
    row: Vec<f64>,
    /// Its building's sixth-derivative bounds' weights ([`Stepped::bound_row`]).
    bound_row: Vec<f64>,
}

/// The separation `buildings` (left to right, on one ground) need under `forcing`, from rest,
/// at the contact levels of [`LevelRule::default`].
pub fn separation(buildings: &[ShearBuilding], forcing: &Forcing) -> Separation {
    separation_with(buildings, forcing, LevelRule::default())
}

/// [`separation`] at the contact levels `rule` gives.
pub fn separation_with(
    buildings: &[ShearBuilding],
    forcing: &Forcing,
    rule: LevelRule,
) -> Separation {
    let dt = forcing.dt;
    let stepped: Vec<Stepped> = buildings.iter().map(|b| Stepped::new(b, dt)).collect();
    // The points to watch, each once.
    let mut watched: Vec<Watched> = Vec::new();
    let mut watch = |b: usize, side: LevelSide| match watched
        .iter()
        .position(|w| w.building == b && w.side == side)
    {
        Some(i) => i,
        None => {
            let row = side.mode_row(&stepped[b].modes.shape);
            watched.push(Watched {
                building: b,
                side,
                bound_row: stepped[b].bound_row(&row),
                row,
            });
            watched.len() - 1
        }
    };
    let mut levels = Vec::new();
    // Per level: the closing, then the two floors.
    let mut tracked = Vec::new();
    for (a, pair) in buildings.windows(2).enumerate() {
        for point in contact_points(&pair[0], &pair[1], rule) {
            let [sl, sr] = point.sides;
            let (l, r) = (watch(a, sl), watch(a + 1, sr));
            levels.push(LevelSeparation {
                pair: a,
                sides: point.sides,
                elevation: point.elevation,
                required: 0.0,
                time: None,
                peak_left: 0.0,
                peak_right: 0.0,
            });
            let closing = Tracked {
                zero: pair[0] == pair[1] && sl == sr,
                ..Tracked::new(l, Some(r))
            };
            tracked.push([closing, Tracked::new(l, None), Tracked::new(r, None)]);
        }
    }
    let nw = watched.len();
    let rest: Vec<Modal> = stepped
        .iter()
        .map(|s| Modal {
            q: vec![0.0; s.modes.count()],
            qd: vec![0.0; s.modes.count()],
            scratch: vec![
                0.0;
                if s.coupled.is_some() {
                    4 * s.modes.count()
                } else {
                    0
                }
            ],
        })
        .collect();
    let (mut z0, mut z1, mut zp) = (rest.clone(), rest.clone(), rest);
    let mut ends0 = vec![[0.0; 3]; nw];
    let mut ends1 = vec![[0.0; 3]; nw];
    let mut parts = vec![[0.0; 3]; nw * (REFINE_SUBSTEPS + 1)];
    let mut refined_steps = 0;
    floors_at(&stepped, &watched, &z0, forcing.sample(0), &mut ends0);
    // The quintic's error is at most h^6 max|f^(6)| / 46080 (the weight s^3 (1 - s)^3 / 720
    // peaks at s = 1/2); the slack covers rounding in the bound.
    let weight = dt.powi(6) / 46080.0 * (1.0 + 1e-6);
    let mut sixth: Vec<Vec<f64>> = stepped.iter().map(|s| vec![0.0; s.modes.count()]).collect();
    let mut floor_error = vec![0.0; nw];
    for i in 0..forcing.intervals() {
        let seg = Segment::of(forcing, i);
        for (b, s) in stepped.iter().enumerate() {
            z1[b].set(&z0[b]);
            s.step(&mut z1[b], &s.whole, None, seg.a0, seg.a1);
            s.sixth_bounds(&mut z0[b], seg.a0, seg.a1, 1.0 / dt, &mut sixth[b]);
        }
        floors_at(&stepped, &watched, &z1, seg.a1, &mut ends1);
        for (e, w) in floor_error.iter_mut().zip(&watched) {
            *e = weight
                * w.bound_row
                    .iter()
                    .zip(&sixth[w.building])
                    .map(|(p, s)| p * s)
                    .sum::<f64>();
        }
        let mut need = Need::Nothing;
        let mut part_count = PART_COUNTS[0];
        for [d, left, right] in &tracked {
            let floors = left.magnitude().max(right.magnitude());
            for (t, floors) in [(d, floors), (left, 0.0), (right, 0.0)] {
                let e = t.sum(&floor_error);
                let (n, scale) = t.needs(t.of(&ends0), t.of(&ends1), dt, e, floors);
                if n == Need::Refining {
                    // The fewest parts whose error bound, (1 / parts)^6 of the step's, is
                    // within the tolerance.
                    let fits = |n: &usize| e <= TOLERANCE * scale * (*n as f64).powi(6);
                    let n = PART_COUNTS
                        .into_iter()
                        .find(fits)
                        .unwrap_or(REFINE_SUBSTEPS);
                    part_count = part_count.max(n);
                }
                need = need.max(n);
            }
        }
        match need {
            Need::Nothing => {}
            Need::Quintic => {
                for t in tracked.iter_mut().flatten() {
                    let (a, b) = (t.of(&ends0), t.of(&ends1));
                    let e = t.sum(&floor_error);
                    t.raise(a, b, seg.t0, dt, e);
                }
            }
            Need::Refining => {
                // Step every building again in parts, exactly (ag is linear within the step).
                refined_steps += 1;
                let set = PART_COUNTS
                    .iter()
                    .position(|&n| n == part_count)
                    .expect("a part count");
                let h = dt / part_count as f64;
                for (p, z) in zp.iter_mut().zip(&z0) {
                    p.set(z);
                }
                parts[..nw].copy_from_slice(&ends0);
                for k in 1..=part_count {
                    let (aa, ab) = (
                        seg.at(seg.t0 + (k - 1) as f64 * h),
                        seg.at(seg.t0 + k as f64 * h),
                    );
                    for (b, s) in stepped.iter().enumerate() {
                        s.step(&mut zp[b], &s.parts[set], Some(set), aa, ab);
                    }
                    floors_at(
                        &stepped,
                        &watched,
                        &zp,
                        ab,
                        &mut parts[k * nw..(k + 1) * nw],
                    );
                }
                // The parts' quintics: (1 / parts)^6 of the step's error.
                let shrink = (part_count as f64).powi(-6);
                for t in tracked.iter_mut().flatten() {
                    let e = t.sum(&floor_error) * shrink;
                    for k in 0..part_count {
                        let (a, b) = (
                            t.of(&parts[k * nw..(k + 1) * nw]),
                            t.of(&parts[(k + 1) * nw..(k + 2) * nw]),
                        );
                        t.raise(a, b, seg.t0 + k as f64 * h, h, e);
                    }
                }
            }
        }
        std::mem::swap(&mut z0, &mut z1);
        std::mem::swap(&mut ends0, &mut ends1);
    }
    let error_bound = tracked
        .iter()
        .flatten()
        .map(Tracked::error)
        .fold(0.0, f64::max);
    for (l, [d, left, right]) in levels.iter_mut().zip(&tracked) {
        l.required = d.hi.max(0.0);
        l.time = (d.hi > 0.0).then_some(d.t_hi);
        l.peak_left = left.hi.max(-left.lo);
        l.peak_right = right.hi.max(-right.lo);
    }
    Separation {
        levels,
        refined_steps,
        substeps: 0,
        fundamental: stepped
            .iter()
            .map(|s| (s.modes.omega[0], s.modes.xi[0]))
            .collect(),
        error_bound: Some(error_bound),
    }
}

/// Per building of `buildings` (elastic, on one ground), its largest storey drift ratio under
/// `forcing` from rest at the record's samples, its modes stepped exactly as
/// [`separation_with`] steps them: whether a run of them may near a collapse limit (the
/// samples miss the crests between them, so a caller compares with a margin).
pub fn sampled_peak_drift_ratios(buildings: &[ShearBuilding], forcing: &Forcing) -> Vec<f64> {
    buildings
        .iter()
        .map(|b| {
            let s = Stepped::new(b, forcing.dt);
            let n = s.modes.count();
            let rows: Vec<Vec<f64>> = (0..n)
                .map(|j| crate::physics::shear::storey_drift_row(&s.modes.shape, j))
                .collect();
            let mut z = Modal {
                q: vec![0.0; n],
                qd: vec![0.0; n],
                scratch: vec![0.0; if s.coupled.is_some() { 4 * n } else { 0 }],
            };
            let mut peak = 0.0f64;
            for i in 0..forcing.intervals() {
                let seg = Segment::of(forcing, i);
                s.step(&mut z, &s.whole, None, seg.a0, seg.a1);
                for (row, h) in rows.iter().zip(&b.heights) {
                    let d: f64 = row.iter().zip(&z.q).map(|(r, q)| r * q).sum();
                    peak = peak.max(d.abs() / h);
                }
            }
            peak
        })
        .collect()
}

/// The separation `buildings` (left to right, on one ground; storeys may yield) need under
/// `forcing`, from rest, at the contact levels `rule` gives, by the row `scheme` with every level out of reach
/// ([`simulate_uncoupled`]). The fundamental modes are the initial stiffness's (as the
/// buildings' damping). Err: why the run did not end.
pub fn yielding_separation(
    buildings: &[ShearBuilding],
    forcing: &Forcing,
    scheme: &RowScheme,
    rule: LevelRule,
) -> Result<Separation, String> {
    let (sep, out) = uncoupled_separation(buildings.to_vec(), rule, f64::INFINITY, forcing, scheme);
    if out.status != Status::Ok {
        return Err(format!("the run ended early ({})", out.status.key()));
    }
    if out.impacts > 0 {
        return Err(format!("a floor moved {UNCOUPLED_GAP_M} m"));
    }
    Ok(sep)
}

/// [`yielding_separation`] under a collapse drift ratio (infinite: none), with the run's output
/// for the caller to judge: its status, each building's collapse (a level's closing and peaks
/// are over the time before the earlier collapse of its two buildings), and impacts where a
/// floor travelled the levels' gap of [`UNCOUPLED_GAP_M`] (a runaway).
pub fn uncoupled_separation(
    buildings: Vec<ShearBuilding>,
    rule: LevelRule,
    collapse_drift_ratio: f64,
    forcing: &Forcing,
    scheme: &RowScheme,
) -> (Separation, crate::physics::row::RowOutput) {
    let gaps = vec![UNCOUPLED_GAP_M; buildings.len() - 1];
    // The contact law is never reached; it only has to be valid.
    let row = Row::with_levels(buildings, gaps, LawKind::Linear, 1.0, 0.0, rule)
        .with_collapse(collapse_drift_ratio);
    let model = RowModel::new(&row);
    let out = simulate_uncoupled(&model, forcing, scheme);
    let levels = row
        .levels
        .iter()
        .zip(&out.closings)
        .map(|(l, c)| LevelSeparation {
            pair: l.left,
            sides: l.sides,
            elevation: l.elevation,
            required: c.closing.max(0.0),
            time: c.time,
            peak_left: c.peak_left,
            peak_right: c.peak_right,
        })
        .collect();
    let sep = Separation {
        levels,
        refined_steps: 0,
        substeps: out.substeps,
        // The model's modes: each building's were computed once, for the run.
        fundamental: model
            .buildings
            .iter()
            .map(|b| (b.modes.omega[0], b.modes.xi[0]))
            .collect(),
        error_bound: None,
    };
    (sep, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::contact::{Contact, LawKind};
    use crate::physics::model::{Initial, Pair};
    use crate::physics::shear::Damping;
    use crate::physics::solver::{simulate, FastOptions, Scheme};

    /// A ground motion rich from 0.7 to 2.3 Hz, 8 s at `dt`.
    fn ground_motion(dt: f64) -> Vec<f64> {
        let n = (8.0 / dt).round() as usize;
        (0..=n)
            .map(|i| {
                let t = i as f64 * dt;
                let envelope = (t / 1.5).min(1.0) * (1.0 - (t - 4.0).max(0.0) / 4.0);
                let w = 2.0 * std::f64::consts::PI;
                envelope
                    * (2.5 * (w * 1.1 * t).sin()
                        + 1.5 * (w * 2.3 * t + 0.4).sin()
                        + 1.0 * (w * 0.7 * t + 1.3).sin())
            })
            .collect()
    }

    fn forcing(accel: &[f64], dt: f64) -> Forcing<'_> {
        Forcing {
            accel,
            dt,
            t0: 0.0,
            scale: 1.0,
            tail: 0.0,
        }
    }

    /// The same ground motion, linear between the samples, sampled `parts` times as finely.
    fn finer(accel: &[f64], parts: usize) -> Vec<f64> {
        let mut out = Vec::with_capacity((accel.len() - 1) * parts + 1);
        for w in accel.windows(2) {
            out.extend((0..parts).map(|k| w[0] + (w[1] - w[0]) * k as f64 / parts as f64));
        }
        out.push(accel[accel.len() - 1]);
        out
    }

    fn shear(n: usize, period: f64, xi: f64) -> ShearBuilding {
        ShearBuilding::from_period(
            vec![3e5; n],
            &vec![1.0; n],
            vec![3.0; n],
            period,
            Damping::Rayleigh(xi),
        )
    }

    fn single(period: f64, xi: f64) -> ShearBuilding {
        ShearBuilding::single(&Oscillator::from_period(1e5, period, xi), xi, 3.0)
    }

    fn relative(a: f64, b: f64) -> f64 {
        (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
    }

    /// An elastic separation's error bound.
    fn bound(s: &Separation) -> f64 {
        s.error_bound.expect("an elastic separation has a bound")
    }

    /// `b` with storeys yielding at drift ratio `theta` and post-yield ratio `post`.
    fn yielding(mut b: ShearBuilding, theta: f64, post: f64) -> ShearBuilding {
        let n = b.storeys();
        b.yielding = Some(crate::physics::shear::Yielding::from_drift_ratio(
            &b.stiffness,
            &b.heights,
            &vec![theta; n],
            vec![post; n],
        ));
        b
    }

    /// The fast scheme at 64 substeps: the tests below hold separations to the reference and
    /// to the elastic closed form at 1e-6 (at the default 16 a yielding one is within 1.5e-4).
    fn fast() -> RowScheme {
        RowScheme::Fast(FastOptions {
            substeps_per_contact: 64.0,
            ..FastOptions::default()
        })
    }

    /// Storeys too strong to yield: the row scheme's separation is the exact elastic one (its
    /// unrefined quintics within 1e-6), for a pair and for a 3 beside a 2 storey (two levels).
    #[test]
    fn strong_storeys_need_the_elastic_separation() {
        let dt = 0.01;
        let accel = ground_motion(dt);
        let f = forcing(&accel, dt);
        for row in [
            vec![single(0.45, 0.05), single(0.3, 0.05)],
            vec![shear(3, 0.5, 0.05), shear(2, 0.3, 0.05)],
        ] {
            let exact = separation(&row, &f);
            let strong: Vec<ShearBuilding> =
                row.iter().map(|b| yielding(b.clone(), 1.0, 0.0)).collect();
            let s = yielding_separation(&strong, &f, &fast(), LevelRule::default()).unwrap();
            assert_eq!(s.levels.len(), exact.levels.len());
            assert_eq!(s.substeps, 0, "nothing yields: every step is exact");
            assert_eq!(s.fundamental, exact.fundamental);
            for (a, b) in s.levels.iter().zip(&exact.levels) {
                assert_eq!((a.pair, a.sides), (b.pair, b.sides));
                assert!(relative(a.required, b.required) < 1e-6);
                assert!(relative(a.peak_left, b.peak_left) < 1e-6);
                assert!(relative(a.peak_right, b.peak_right) < 1e-6);
                assert!((a.time.unwrap() - b.time.unwrap()).abs() < 1e-3);
            }
        }
    }

    /// Yielding storeys: the pair's sweep run never touches a hair above the required gap
    /// and touches a hair below it, near the time the closing peaks; its peaks are the
    /// tracker's; and the fast scheme's gap is the reference's to 1e-4.
    #[test]
    fn yielding_pair_touches_below_its_required_gap_only() {
        let dt = 0.01;
        let accel: Vec<f64> = ground_motion(dt).iter().map(|a| 2.5 * a).collect();
        let f = forcing(&accel, dt);
        let buildings = vec![
            yielding(single(0.45, 0.05), 0.004, 0.0),
            yielding(single(0.3, 0.05), 0.003, 0.05),
        ];
        let s = yielding_separation(&buildings, &f, &fast(), LevelRule::default()).unwrap();
        let l = s.levels[0];
        assert!(s.substeps > 0, "the storeys yield");
        let run = |gap: f64| {
            let row = Row::new(
                buildings.clone(),
                vec![gap],
                LawKind::NonlinearViscoelastic,
                2.75e9,
                0.35,
            );
            let m = RowModel::new(&row);
            super::super::row::simulate_row(&m, &f, m.at_rest(), &fast())
        };
        let free = run(1.0);
        assert_eq!(free.impacts, 0);
        assert!(free
            .buildings
            .iter()
            .all(|b| b.inelastic.unwrap().yielded_storeys == 1));
        assert!(relative(free.buildings[0].peak_roof, l.peak_left) < 1e-12);
        assert!(relative(free.buildings[1].peak_roof, l.peak_right) < 1e-12);
        assert_eq!(run(l.required * (1.0 + 1e-6)).impacts, 0);
        let touched = run(l.required * (1.0 - 1e-4));
        assert!(touched.impacts > 0, "{touched:?}");
        assert!((touched.first_impact.unwrap() - l.time.unwrap()).abs() < 0.05);
    }

    /// Yielding storeys, a pair and a 3 beside a 2 storey (two levels): the fast scheme's
    /// separation is the reference's (tolerance 1e-11) to 1e-6 (measured 3e-8).
    #[test]
    fn yielding_separation_is_the_reference_one() {
        let dt = 0.01;
        let accel: Vec<f64> = ground_motion(dt).iter().map(|a| 2.5 * a).collect();
        let f = forcing(&accel, dt);
        let reference = RowScheme::Reference(crate::physics::solver::ReferenceOptions {
            rtol: 1e-11,
            ..Default::default()
        });
        for row in [
            vec![single(0.45, 0.05), single(0.3, 0.05)],
            vec![shear(3, 0.5, 0.05), shear(2, 0.3, 0.05)],
        ] {
            let row: Vec<ShearBuilding> =
                row.into_iter().map(|b| yielding(b, 0.004, 0.03)).collect();
            let s = yielding_separation(&row, &f, &fast(), LevelRule::default()).unwrap();
            let r = yielding_separation(&row, &f, &reference, LevelRule::default()).unwrap();
            assert!(s.substeps > 0, "the storeys yield");
            for (a, b) in s.levels.iter().zip(&r.levels) {
                let what = format!("{a:?} against {b:?}");
                assert!(a.required > 0.0, "{what}");
                assert!(relative(a.required, b.required) < 1e-6, "{what}");
                assert!(relative(a.peak_left, b.peak_left) < 1e-6, "{what}");
                assert!(relative(a.peak_right, b.peak_right) < 1e-6, "{what}");
                assert!((a.time.unwrap() - b.time.unwrap()).abs() < 1e-6, "{what}");
            }
        }
    }

    /// Against the same scenes stepped 64 times as finely (where the quintic's error is
    /// 64^6 = 7e10 times smaller): the required gap, its time and the peaks agree to 1e-9, for
    /// a stiff pair on a coarse record (omega h = 1.3), a 3 beside a 6 storey, a 20 beside a
    /// 12 storey (highest modes with omega h up to 4) and a P-Delta 4 storey whose Rayleigh
    /// damping couples its modes beside a 3 storey.
    #[test]
    fn separation_is_that_of_steps_64_times_finer() {
        let leaning = ShearBuilding::from_period(
            vec![3e5; 4],
            &[1.0, 0.9, 0.8, 0.6],
            vec![4.0, 3.5, 3.5, 3.5],
            1.0,
            Damping::Rayleigh(0.05),
        )
        .with_p_delta(2.0);
        assert!(leaning.modes().coupling.is_some());
        let stiff = ShearBuilding::from_period(
            vec![2.5e5; 3],
            &[1.0; 3],
            vec![4.0, 3.5, 3.5],
            0.3,
            Damping::Rayleigh(0.05),
        );
        let scenes: [(Vec<ShearBuilding>, f64); 4] = [
            (vec![single(0.35, 0.05), single(0.1, 0.02)], 0.02),
            (vec![shear(3, 0.35, 0.05), shear(6, 0.8, 0.05)], 0.01),
            (vec![shear(20, 2.0, 0.05), shear(12, 1.1, 0.03)], 0.02),
            (vec![leaning, stiff], 0.02),
        ];
        for (buildings, dt) in scenes {
            let accel = ground_motion(dt);
            let coarse = separation(&buildings, &forcing(&accel, dt));
            let fine_accel = finer(&accel, 64);
            let fine = separation(&buildings, &forcing(&fine_accel, dt / 64.0));
            assert!(!coarse.levels.is_empty());
            for (c, f) in coarse.levels.iter().zip(&fine.levels) {
                assert!(c.required > 0.0, "{c:?}");
                let what = format!(
                    "{} storeys, dt {dt}: {c:?} against {f:?}",
                    buildings[0].storeys()
                );
                let bound = bound(&coarse) + bound(&fine) + 1e-11 * c.peak_left.max(c.peak_right);
                assert!((c.required - f.required).abs() <= bound, "{what}");
                assert!((c.peak_left - f.peak_left).abs() <= bound, "{what}");
                assert!((c.peak_right - f.peak_right).abs() <= bound, "{what}");
                assert!(relative(c.required, f.required) < 1e-9, "{what}");
                assert!((c.time.unwrap() - f.time.unwrap()).abs() < 1e-6, "{what}");
            }
            // Refining is the exception, not the rule, even at omega h = 4.
            let n = accel.len() as u64 - 1;
            assert!(
                coarse.refined_steps < n / 2,
                "{} of {n}",
                coarse.refined_steps
            );
            // Within the bound it reports, itself far below the tolerance.
            assert!(bound(&coarse) < 1e-7 * coarse.levels[0].peak_left);
        }
    }

    /// Brute force, independent of the Hermite machinery: the largest closing over samples
    /// of the exact pair response at steps of dt / 256 (each within (omega h)^2 / 8 of the
    /// crest between them).
    #[test]
    fn separation_of_a_pair_is_the_largest_closing_of_its_exact_response() {
        let dt = 0.01;
        let accel = ground_motion(dt);
        let fine = finer(&accel, 256);
        let (o1, o2) = (
            Oscillator::from_period(1e5, 0.5, 0.05),
            Oscillator::from_period(2e5, 0.27, 0.03),
        );
        let h = dt / 256.0;
        let (p1, p2) = (Propagator::new(&o1, h), Propagator::new(&o2, h));
        let (mut s1, mut s2) = ((0.0, 0.0), (0.0, 0.0));
        let (mut closing, mut peak1, mut peak2) = (0.0f64, 0.0f64, 0.0f64);
        for w in fine.windows(2) {
            s1 = p1.step(s1.0, s1.1, w[0], w[1]);
            s2 = p2.step(s2.0, s2.1, w[0], w[1]);
            closing = closing.max(s1.0 - s2.0);
            peak1 = peak1.max(s1.0.abs());
            peak2 = peak2.max(s2.0.abs());
        }
        let got = separation(
            &[
                ShearBuilding::single(&o1, 0.05, 3.0),
                ShearBuilding::single(&o2, 0.03, 3.0),
            ],
            &forcing(&accel, dt),
        );
        let l = got.levels[0];
        // (omega h)^2 / 8 with omega h = 2 pi / 0.27 * dt / 256: 7e-7.
        for (a, b) in [
            (l.required, closing),
            (l.peak_left, peak1),
            (l.peak_right, peak2),
        ] {
            assert!(
                a >= b * (1.0 - 1e-12) && relative(a, b) < 1e-6,
                "{a} against {b}"
            );
        }
    }

    #[test]
    fn identical_buildings_need_no_gap_and_the_record_scales() {
        let dt = 0.01;
        let accel = ground_motion(dt);
        let f = forcing(&accel, dt);
        let same = separation(&[shear(4, 0.6, 0.05), shear(4, 0.6, 0.05)], &f);
        assert_eq!(same.levels.len(), 4);
        for l in &same.levels {
            assert_eq!((l.required, l.time), (0.0, None), "{l:?}");
            assert!(l.peak_left > 0.0 && l.peak_left == l.peak_right);
        }
        // Same period and damping, other masses: identical motion to rounding.
        let heavy = ShearBuilding::single(&Oscillator::from_period(7e5, 0.6, 0.05), 0.05, 3.0);
        let light = ShearBuilding::single(&Oscillator::from_period(1e4, 0.6, 0.05), 0.05, 3.0);
        let l = separation(&[heavy, light], &f).levels[0];
        assert!(l.required <= 1e-12 * l.peak_left, "{l:?}");
        // Linear in the record's scale.
        let buildings = [shear(3, 0.3, 0.05), shear(5, 0.7, 0.05)];
        let unit = separation(&buildings, &f).scaled(2.5);
        let scaled = separation(&buildings, &Forcing { scale: 2.5, ..f });
        for (a, b) in unit.levels.iter().zip(&scaled.levels) {
            assert!(relative(a.required, b.required) < 1e-12, "{a:?} {b:?}");
            assert!(relative(a.peak_left, b.peak_left) < 1e-12);
            assert!(relative(a.peak_right, b.peak_right) < 1e-12);
        }
    }

    /// The peaks are those a pair run reports where its buildings never touch (its tracker's
    /// quintic, unrefined), and a run with a gap a hair below the required one touches.
    #[test]
    fn separation_agrees_with_the_pair_runs() {
        let dt = 0.01;
        let accel = ground_motion(dt);
        let f = forcing(&accel, dt);
        let (b1, b2) = (
            Oscillator::from_period(1e5, 0.45, 0.05),
            Oscillator::from_period(1e5, 0.3, 0.05),
        );
        let l = separation(
            &[
                ShearBuilding::single(&b1, 0.05, 3.0),
                ShearBuilding::single(&b2, 0.05, 3.0),
            ],
            &f,
        )
        .levels[0];
        let run = |gap: f64| {
            let pair = Pair {
                b1,
                b2,
                gap,
                contact: Contact::new(LawKind::NonlinearViscoelastic, 2.75e9, 0.35, 5e4),
            };
            simulate(
                &pair,
                &f,
                &Initial::default(),
                &Scheme::Fast(FastOptions::default()),
            )
        };
        let free = run(1.0);
        assert_eq!(free.impacts, 0);
        assert!(relative(free.peak_u1, l.peak_left) < 1e-9);
        assert!(relative(free.peak_u2, l.peak_right) < 1e-9);
        assert_eq!(run(l.required * (1.0 + 1e-6)).impacts, 0);
        let touched = run(l.required * (1.0 - 1e-4));
        assert!(touched.impacts > 0, "{touched:?}");
        assert!((touched.first_impact.unwrap() - l.time.unwrap()).abs() < 0.05);
    }
}

//! The deteriorating storey spring of Ibarra, Medina & Krawinkler (physics.md section 13) as a
//! material of linear pieces: between events its force is `f = f0 + slope (d - d0)` in its
//! drift `d`, so the solvers keep their linear free flight and locate each change of piece as an
//! event (a drift threshold passed, or the drift rate turning against a piece that flows one
//! way). What happens at each event follows OpenSees 3.8's `IMKBilin` and `IMKPeakOriented`
//! (`SRC/material/uniaxial/`), taken to the limit of small steps: their energies are the work
//! `int f dd` up to the event, exact on linear pieces. One change: once the energy dissipated
//! reaches the capacity `E_t` (where OpenSees clamps and stops deteriorating) the storey has no
//! strength left.
//!
//! Each side's backbone is kept in magnitudes (`x` drift outwards, `g` force outwards), so one
//! code serves both directions: `x = sign d`, `g = sign f`.

mod side;
#[cfg(test)]
mod tests;

use crate::physics::shear::ImkRule;
use side::Side;

/// One storey's IMK spring in absolute units (storey drift m, shear N).
#[derive(Debug, Clone, PartialEq)]
pub struct ImkSpring {
    pub rule: ImkRule,
    /// Initial stiffness `k`, N/m.
    pub k: f64,
    /// Yield force `F_y = k theta_y h`, N.
    pub fy: f64,
    /// Hardening stiffness `b k`, N/m.
    pub kp: f64,
    /// Yield to capping `theta_p h`, m; capping to zero strength `theta_pc h`, m.
    pub up: f64,
    pub upc: f64,
    /// Residual strength `kappa F_y`, N.
    pub fres: f64,
    /// No strength beyond this drift `theta_u h`, m (infinite: none).
    pub uu: f64,
    /// Energy capacity `E_t = gamma F_y theta_y h`, J (None: no cyclic deterioration).
    pub e_t: Option<f64>,
}

impl ImkSpring {
    /// Storey `j`'s spring from its stiffness `k`, height `h`, yield drift ratio `theta_y`,
    /// hardening ratio `b` and the IMK ratios.
    #[allow(clippy::too_many_arguments)]
    pub fn from_ratios(
        rule: ImkRule,
        k: f64,
        h: f64,
        theta_y: f64,
        b: f64,
        (theta_p, theta_pc, kappa, theta_u): (f64, f64, f64, f64),
        gamma: Option<f64>,
    ) -> ImkSpring {
        let fy = k * theta_y * h;
        ImkSpring {
            rule,
            k,
            fy,
            kp: b * k,
            up: theta_p * h,
            upc: theta_pc * h,
            fres: kappa * fy,
            uu: theta_u * h,
            e_t: gamma.map(|g| g * fy * theta_y * h),
        }
    }

    /// The drift a located event may pass its threshold by (as a bilinear storey's band).
    pub fn slack(&self) -> f64 {
        1e-9 * self.fy / self.k
    }

    /// How close to rest a storey must be before its residual drift is taken, m: the reach of
    /// its motion (from the energy left) about where its force is zero. `IMKBilin` returns to
    /// the same line at each zero crossing (exact at any reach within its piece's rest
    /// thresholds); a peak-oriented storey's small loops (reloading towards its peaks through
    /// the crossing, unloading at each turn) move its rest point by up to the reach: taken once
    /// that is below 1e-4 of the yield drift, on any of its pieces.
    pub fn rest_reach(&self) -> f64 {
        match self.rule {
            ImkRule::Bilinear => f64::INFINITY,
            ImkRule::PeakOriented => 1e-4 * self.fy / self.k,
        }
    }

    /// The capping strength before any deterioration, N.
    pub fn fcap0(&self) -> f64 {
        self.fy + self.kp * self.up
    }
}

/// The piece a storey's force is on: `f = f0 + slope (d - d0)` while `lo <= d <= hi`, and, where
/// `heading` is `+-1`, while the drift rate does not turn against it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    pub d0: f64,
    pub f0: f64,
    pub slope: f64,
    pub lo: f64,
    pub hi: f64,
    pub heading: f64,
    /// The thresholds other than the force's zero crossing and a local peak: a new excursion
    /// there moves no `IMKBilin` line, and a peak-oriented storey's small loops about rest
    /// (unloading, reloading through the crossing, on through the local peak) keep its force
    /// continuous, so a storey at rest settles within these ([`ImkSpring::rest_reach`]).
    pub rest_lo: f64,
    pub rest_hi: f64,
}

impl Piece {
    /// The line through `(d0, f0)` with `slope`, with no threshold and no heading yet.
    fn line(d0: f64, f0: f64, slope: f64) -> Piece {
        Piece {
            d0,
            f0,
            slope,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
            heading: 0.0,
            rest_lo: f64::NEG_INFINITY,
            rest_hi: f64::INFINITY,
        }
    }

    /// The force at drift `d`.
    #[inline]
    pub fn force(&self, d: f64) -> f64 {
        self.f0 + self.slope * (d - self.d0)
    }

    /// Positive once the piece must end: `d` past a threshold by more than `slack`, or the rate
    /// against its heading.
    #[inline]
    pub fn event_value(&self, d: f64, rate: f64, slack: f64) -> f64 {
        let [hi, lo, back] = self.event_parts(d, rate, slack);
        hi.max(lo).max(back)
    }

    /// [`Piece::event_value`]'s parts: past `hi`, past `lo`, against the heading (an event is
    /// located on the parts that fire alone: the others, a drift and a rate, are not on its
    /// scale, and their maximum has a kink that regula falsi creeps along).
    #[inline]
    pub fn event_parts(&self, d: f64, rate: f64, slack: f64) -> [f64; 3] {
        [
            d - self.hi - slack,
            self.lo - d - slack,
            -self.heading * rate,
        ]
    }
}

/// Which branch a storey is on (OpenSees' branch numbers in brackets where it has them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Branch {
    /// The initial elastic line through the origin [0].
    Elastic,
    /// Unloading or reloading with the unloading stiffness, off the backbone [1].
    Unloading,
    /// Peak-oriented reloading towards the side's last (`local`) or largest (`global`) peak
    /// [3, 4 and 13, 14], on side `sign`.
    TowardsLocal(f64),
    TowardsGlobal(f64),
    /// On side `sign`'s backbone: hardening, post-capping, residual or no strength [5-7].
    Backbone(f64),
    /// No strength left in either direction.
    Collapsed,
}

impl Branch {
    /// The branch's name and side for traces.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Elastic => "elastic",
            Branch::Unloading => "unloading",
            Branch::TowardsLocal(_) => "reloading_local",
            Branch::TowardsGlobal(_) => "reloading_global",
            Branch::Backbone(_) => "backbone",
            Branch::Collapsed => "collapsed",
        }
    }
}

/// Where a piece's threshold leads.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mark {
    None,
    /// The off-backbone line meets the backbone of the side it moves towards.
    Backbone,
    /// The force crosses zero off the backbone: a new excursion.
    Zero,
    /// A break of the backbone (capping, residual, the floor of the hardening line).
    Break,
    /// The ultimate drift: the side loses its strength.
    Ultimate,
    /// The residual plateau at zero strength reached: the side loses its strength.
    NoStrength,
    /// Peak-oriented: the local peak reached, on to the global peak or the backbone.
    LocalPeak,
    /// Peak-oriented: the global peak reached, on to the backbone.
    GlobalPeak,
    /// `IMKBilin`: the residual drift passed off the backbone (its unloading stiffness rule).
    Residual,
}

/// One storey spring's state: its deteriorated backbones, energies and current piece.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImkState {
    /// The backbones of the positive and negative sides, in magnitudes.
    sides: [Side; 2],
    /// The unloading stiffness, N/m.
    kunload: f64,
    /// The work `int f dd` done on the spring so far, and its value at the last new excursion.
    work: f64,
    work_mark: f64,
    pub branch: Branch,
    piece: Piece,
    marks: [Mark; 2],
    /// It left the elastic line (deterioration starts from there).
    pub yielded: bool,
    /// A backbone passed its capping point.
    pub capped: bool,
    /// `IMKBilin` reached a residual plateau (later reversals unload at half the stiffness).
    residual_reached: bool,
}

/// Side index of a sign.
#[inline]
fn idx(sign: f64) -> usize {
    usize::from(sign < 0.0)
}

impl ImkState {
    /// A spring at rest on its elastic line.
    pub fn new(sp: &ImkSpring) -> ImkState {
        let side = Side::new(sp);
        let mut st = ImkState {
            sides: [side, side],
            kunload: sp.k,
            work: 0.0,
            work_mark: 0.0,
            branch: Branch::Elastic,
            piece: Piece::line(0.0, 0.0, sp.k),
            marks: [Mark::None; 2],
            yielded: false,
            capped: false,
            residual_reached: false,
        };
        st.set_piece(sp, 0.0, 0.0, sp.k, Branch::Elastic);
        st
    }

    /// The piece the force is on.
    #[inline]
    pub fn piece(&self) -> &Piece {
        &self.piece
    }

    /// Positive once the current piece must end at drift `d` and rate `rate`.
    #[inline]
    pub fn event_value(&self, sp: &ImkSpring, d: f64, rate: f64) -> f64 {
        self.piece.event_value(d, rate, sp.slack())
    }

    /// The work `int f dd` done on the spring up to drift `d` on the current piece, J.
    pub fn work_at(&self, d: f64) -> f64 {
        let p = &self.piece;
        self.work + 0.5 * (p.f0 + p.force(d)) * (d - p.d0)
    }

    /// The capping strength left over the initial one, the weaker side's (0 once it has none).
    pub fn strength_ratio(&self, sp: &ImkSpring) -> f64 {
        let left = |s: &Side| if s.failed { 0.0 } else { s.fcap };
        left(&self.sides[0]).min(left(&self.sides[1])) / sp.fcap0()
    }

    /// Take every change of piece due at drift `d`, rate `rate` (the drift reached on the
    /// current piece); the force there on the new piece.
    pub fn advance(&mut self, sp: &ImkSpring, d: f64, rate: f64) -> f64 {
        // Each change moves to a piece that does not end at once, but a corner where several
        // thresholds meet may take a few.
        for _ in 0..16 {
            let p = self.piece;
            let slack = sp.slack();
            if p.heading != 0.0 && -p.heading * rate > 0.0 {
                self.close_work(d);
                self.reverse(sp, d);
            } else if d - p.hi - slack > 0.0 {
                self.close_work(d);
                self.cross(sp, d, 1.0, self.marks[0]);
            } else if p.lo - d - slack > 0.0 {
                self.close_work(d);
                self.cross(sp, d, -1.0, self.marks[1]);
            } else {
                break;
            }
        }
        self.piece.force(d)
    }

    /// Follow a drift that moves monotonically from the current one to `d` (a quasi-static
    /// protocol), calling `seen(d, f, branch)` at every change of piece on the way; the force
    /// at `d`.
    pub fn follow(
        &mut self,
        sp: &ImkSpring,
        from: f64,
        d: f64,
        seen: &mut dyn FnMut(f64, f64, Branch),
    ) -> f64 {
        let rate = if d >= from { 1.0 } else { -1.0 };
        let mut at = from;
        self.advance(sp, at, rate);
        for _ in 0..10_000 {
            let p = self.piece;
            let slack = sp.slack();
            // The next threshold this way, or a point just past it.
            let next = if rate > 0.0 {
                p.hi + 2.0 * slack
            } else {
                p.lo - 2.0 * slack
            };
            if (rate > 0.0 && next >= d) || (rate < 0.0 && next <= d) || !next.is_finite() {
                break;
            }
            at = next;
            let before = self.branch;
            let f = self.advance(sp, at, rate);
            if self.branch != before || self.piece != p {
                seen(at, f, self.branch);
            }
        }
        self.advance(sp, d, rate)
    }

    /// Add the work on the current piece up to `d`, where it ends.
    fn close_work(&mut self, d: f64) {
        self.work = self.work_at(d);
    }

    /// Start a piece `f = f0 + slope (d - d0)` on `branch` at drift `d0`, with its thresholds.
    fn set_piece(&mut self, sp: &ImkSpring, d0: f64, f0: f64, slope: f64, branch: Branch) {
        self.branch = branch;
        let mut piece = Piece::line(d0, f0, slope);
        let mut marks = [Mark::None; 2];
        // Each side's threshold in its own magnitudes, found from the piece in them.
        for sign in [1.0, -1.0] {
            let (x0, g0) = (sign * d0, sign * f0);
            let ((x, mark), rest) = self.threshold(sp, sign, x0, g0, slope);
            if sign > 0.0 {
                (piece.hi, marks[0], piece.rest_hi) = (x, mark, rest);
            } else {
                (piece.lo, marks[1], piece.rest_lo) = (-x, mark, -rest);
            }
        }
        piece.heading = match branch {
            Branch::Backbone(s) | Branch::TowardsLocal(s) | Branch::TowardsGlobal(s) => s,
            _ => 0.0,
        };
        self.piece = piece;
        self.marks = marks;
    }

    /// The first threshold a piece through `(x0, g0)` with `slope` meets moving outwards on side
    /// `sign` (in that side's magnitudes), and where it leads; and the first other than a zero
    /// crossing.
    fn threshold(
        &self,
        sp: &ImkSpring,
        sign: f64,
        x0: f64,
        g0: f64,
        slope: f64,
    ) -> ((f64, Mark), f64) {
        let side = &self.sides[idx(sign)];
        let other_failed = self.sides[idx(-sign)].failed;
        let mut best = (f64::INFINITY, Mark::None);
        let mut rest = f64::INFINITY;
        let mut take = |x: f64, m: Mark| {
            if x < best.0 {
                best = (x, m);
            }
            if m != Mark::Zero && m != Mark::LocalPeak {
                rest = rest.min(x);
            }
        };
        if !side.failed && self.branch != Branch::Collapsed {
            take(sp.uu, Mark::Ultimate);
        }
        match self.branch {
            Branch::Collapsed => {}
            Branch::Elastic => match sp.rule {
                ImkRule::Bilinear => {
                    let bilin = side.bilin_meet(sp, x0, g0, slope, other_failed);
                    take(bilin, Mark::Backbone)
                }
                ImkRule::PeakOriented => take(side.uy, Mark::Backbone),
            },
            Branch::Unloading => {
                // The new excursion where the force crosses zero (towards the other side;
                // before the first yield nothing deteriorates). `IMKBilin` takes it without an
                // energy capacity too: it keeps the hardening line above the residual there.
                if g0 < 0.0 && slope > 0.0 && self.yielded {
                    take(x0 - g0 / slope, Mark::Zero);
                }
                match sp.rule {
                    ImkRule::Bilinear => {
                        take(
                            side.bilin_meet(sp, x0, g0, slope, other_failed),
                            Mark::Backbone,
                        );
                        if !self.residual_reached {
                            if let Some(x) = side.bilin_residual_drift(sp, other_failed) {
                                if x > x0 {
                                    take(x, Mark::Residual)
                                }
                            }
                        }
                    }
                    ImkRule::PeakOriented => {
                        // Back out on the side it unloaded from: on to its peaks at the last
                        // reversal point.
                        if g0 > 0.0 || (g0 == 0.0 && side.x_local > x0) {
                            take(side.x_local, Mark::LocalPeak)
                        }
                    }
                }
            }
            Branch::TowardsLocal(s) if s == sign => take(side.x_local, Mark::LocalPeak),
            Branch::TowardsGlobal(s) if s == sign => take(side.x_global, Mark::GlobalPeak),
            Branch::Backbone(s) if s == sign => {
                let (_, _, end, mark) = side.segment(sp, x0, other_failed);
                take(end, mark);
            }
            _ => {}
        }
        (best, rest)
    }

    /// The drift rate turned against a piece that flows one way, at drift `d`.
    fn reverse(&mut self, sp: &ImkSpring, d: f64) {
        let f = self.piece.force(d);
        let sign = if f > 0.0 {
            1.0
        } else if f < 0.0 {
            -1.0
        } else {
            self.piece.heading
        };
        if sp.rule == ImkRule::PeakOriented {
            let side = &mut self.sides[idx(sign)];
            let (x, g) = (sign * d, sign * f);
            side.x_local = x;
            side.g_local = g;
            if x > side.x_global {
                side.x_global = x;
                side.g_global = g;
            }
        }
        // Unloading stiffness deterioration from the energy since the last new excursion,
        // less the energy stored in the unloading spring.
        if let Some(e_t) = sp.e_t {
            let stored = 0.5 * f * f / self.kunload;
            let spent = self.work - stored;
            let since = self.work - self.work_mark - stored;
            match beta(since, e_t - spent) {
                Some(b) => self.kunload *= 1.0 - b,
                None => return self.collapse(d),
            }
        }
        if sp.rule == ImkRule::Bilinear && self.residual_reached {
            self.kunload = 0.5 * sp.k;
        }
        self.set_piece(sp, d, f, self.kunload, Branch::Unloading);
    }

    /// Drift `d` passed the threshold `mark` of side `sign`.
    fn cross(&mut self, sp: &ImkSpring, d: f64, sign: f64, mark: Mark) {
        let f = self.piece.force(d);
        let i = idx(sign);
        let x = sign * d;
        match mark {
            Mark::None => unreachable!("a threshold with nowhere to go is infinite"),
            Mark::Ultimate | Mark::NoStrength => {
                let other = &self.sides[idx(-sign)];
                if sp.rule == ImkRule::PeakOriented || other.failed {
                    return self.collapse(d);
                }
                self.sides[i].failed = true;
                self.residual_reached = true;
                self.on_backbone(sp, d, sign);
            }
            Mark::Backbone | Mark::Break | Mark::GlobalPeak => {
                self.yielded = true;
                self.on_backbone(sp, d, sign);
            }
            Mark::Residual => {
                self.residual_reached = true;
                let (slope, branch) = (self.piece.slope, self.branch);
                self.set_piece(sp, d, f, slope, branch);
            }
            Mark::LocalPeak => {
                let side = &self.sides[i];
                if side.x_global > x {
                    let k = (side.g_global - side.g_local) / (side.x_global - side.x_local);
                    self.set_piece(sp, d, f, k, Branch::TowardsGlobal(sign));
                } else {
                    self.on_backbone(sp, d, sign);
                }
            }
            Mark::Zero => self.new_excursion(sp, d, sign),
        }
    }

    /// Onto side `sign`'s backbone at drift `d` (the force jumps to it where a side has just
    /// lost its strength).
    fn on_backbone(&mut self, sp: &ImkSpring, d: f64, sign: f64) {
        let other_failed = self.sides[idx(-sign)].failed;
        let side = &self.sides[idx(sign)];
        let x = sign * d;
        let (g, slope, _, _) = side.segment(sp, x, other_failed);
        if !side.failed && x > side.ucap {
            self.capped = true;
        }
        if sp.rule == ImkRule::Bilinear && !side.failed && side.in_residual(sp, x) {
            self.residual_reached = true;
        }
        self.set_piece(sp, d, sign * g, slope, Branch::Backbone(sign));
    }

    /// The force crossed zero off the backbone at drift `d`, moving towards side `sign`: that
    /// side's backbone deteriorates by the energy of the half cycle just ended.
    fn new_excursion(&mut self, sp: &ImkSpring, d: f64, sign: f64) {
        let b = match sp.e_t {
            Some(e_t) => {
                let since = (self.work - self.work_mark).max(0.0);
                self.work_mark = self.work;
                match beta(since, e_t - self.work) {
                    Some(b) => b,
                    None => return self.collapse(d),
                }
            }
            None => 0.0,
        };
        if sp.e_t.is_some() || sp.rule == ImkRule::Bilinear {
            self.sides[idx(sign)].deteriorate(sp, b, (sign * d, 0.0, self.kunload));
        }
        let f = self.piece.force(d);
        match sp.rule {
            ImkRule::Bilinear => self.set_piece(sp, d, f, self.kunload, Branch::Unloading),
            ImkRule::PeakOriented => {
                let side = &self.sides[idx(sign)];
                if side.g_global <= 0.0 {
                    return self.collapse(d);
                }
                let u0 = sign * d;
                let k_global = side.g_global / (side.x_global - u0);
                let k_local = side.g_local / (side.x_local - u0);
                let (k, branch) =
                    if u0 < side.x_local && side.g_local < side.g_global && k_local > k_global {
                        (k_local, Branch::TowardsLocal(sign))
                    } else {
                        (k_global, Branch::TowardsGlobal(sign))
                    };
                self.set_piece(sp, d, f, k, branch);
            }
        }
    }

    /// No strength left in either direction, from drift `d` on.
    fn collapse(&mut self, d: f64) {
        for s in &mut self.sides {
            s.failed = true;
        }
        self.branch = Branch::Collapsed;
        self.piece = Piece::line(d, 0.0, 0.0);
        self.marks = [Mark::None; 2];
    }
}

/// The energy rule's factor `E_i / (E_t - sum E)` for the energy `spent` of an excursion and
/// the capacity `left` after it, in `[0, 1]`; None once the capacity is spent (no strength
/// left).
fn beta(spent: f64, left: f64) -> Option<f64> {
    if left <= 0.0 {
        return None;
    }
    let b = spent.max(0.0) / left;
    (b <= 1.0).then_some(b)
}

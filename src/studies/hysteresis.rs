//! `pound hysteresis storey`: one IMK storey (physics.md section 13) driven quasi-statically
//! through a cyclic drift protocol. The spring is piecewise linear, so the points where its
//! piece changes, with the protocol's targets, are its loop exactly: nothing is sampled.
//!
//! In drift ratios the loop does not depend on the storey's stiffness `k` or height `h`: forces
//! scale with `k h`, drifts with `h`, so the work and `E_t = gamma F_y theta_y h` both scale
//! with `k h^2` and the energy rule's factors are the same (`tests/it/hysteresis.rs` checks it).

use crate::physics::imk::{Branch, ImkSpring, ImkState};
use crate::physics::shear::ImkRule;
use crate::studies::plot::{Notes, Panel, Series};

/// One IMK storey in drift ratios, as a `[[building]]`'s keys give it, with its stiffness and
/// height.
#[derive(Debug, Clone, PartialEq)]
pub struct Storey {
    pub rule: ImkRule,
    /// `k`, N/m, and `h`, m.
    pub stiffness: f64,
    pub height: f64,
    /// `yield_drift_ratio` (theta_y), `post_yield_ratio` (b).
    pub yield_drift: f64,
    pub post_yield: f64,
    /// `plastic_drift_ratio` (theta_p), `post_capping_drift_ratio` (theta_pc),
    /// `residual_strength_ratio` (kappa), `ultimate_drift_ratio` (theta_u).
    pub plastic: f64,
    pub post_capping: f64,
    pub residual: f64,
    pub ultimate: f64,
    /// `energy_capacity_ratio` (gamma; None: no cyclic deterioration).
    pub energy: Option<f64>,
}

impl Storey {
    /// The storey of the IMK tests and of OpenSees' cross-check (`benches/opensees_imk.py`):
    /// `k` 2e7 N/m, `h` 3 m, theta_y 0.005, b 0.03, theta_p 0.02, theta_pc 0.08, kappa 0.2,
    /// theta_u 0.15, gamma 50.
    pub fn example(rule: ImkRule) -> Storey {
        Storey {
            rule,
            stiffness: 2.0e7,
            height: 3.0,
            yield_drift: 0.005,
            post_yield: 0.03,
            plastic: 0.02,
            post_capping: 0.08,
            residual: 0.2,
            ultimate: 0.15,
            energy: Some(50.0),
        }
    }

    /// The first value out of its bounds: its config key, the value and what is expected (the
    /// bounds of a `[[building]]`'s IMK keys).
    pub fn check(&self) -> Result<(), (&'static str, f64, String)> {
        let positive = "a positive number".to_string();
        let in_range = |lo: &str, hi: &str| format!("a number in {lo}, {hi}");
        let cap = self.yield_drift + self.plastic;
        let checks: [(&str, f64, bool, String); 9] = [
            ("stiffness", self.stiffness, self.stiffness > 0.0 && self.stiffness.is_finite(), positive.clone()),
            ("height", self.height, self.height > 0.0 && self.height.is_finite(), positive.clone()),
            (
                "yield_drift_ratio",
                self.yield_drift,
                self.yield_drift > 0.0 && self.yield_drift <= 0.2,
                in_range("(0", "0.2]"),
            ),
            (
                "post_yield_ratio",
                self.post_yield,
                (0.0..1.0).contains(&self.post_yield),
                in_range("[0", "1)"),
            ),
            ("plastic_drift_ratio", self.plastic, self.plastic > 0.0 && self.plastic.is_finite(), positive.clone()),
            (
                "post_capping_drift_ratio",
                self.post_capping,
                self.post_capping > 0.0 && self.post_capping.is_finite(),
                positive.clone(),
            ),
            (
                "residual_strength_ratio",
                self.residual,
                (0.0..1.0).contains(&self.residual),
                in_range("[0", "1)"),
            ),
            (
                "ultimate_drift_ratio",
                self.ultimate,
                self.ultimate > cap,
                format!(
                    "a drift ratio beyond the capping point yield_drift_ratio + plastic_drift_ratio = {cap} (inf: no ultimate drift)"
                ),
            ),
            (
                "energy_capacity_ratio",
                self.energy.unwrap_or(1.0),
                self.energy.is_none_or(|g| g > 0.0 && g.is_finite()),
                format!("{positive} (none: no cyclic deterioration)"),
            ),
        ];
        match checks.into_iter().find(|c| !c.2) {
            Some((key, value, _, expected)) => Err((key, value, expected)),
            None => Ok(()),
        }
    }

    /// Its spring in absolute units.
    pub fn spring(&self) -> ImkSpring {
        ImkSpring::from_ratios(
            self.rule,
            self.stiffness,
            self.height,
            self.yield_drift,
            self.post_yield,
            (
                self.plastic,
                self.post_capping,
                self.residual,
                self.ultimate,
            ),
            self.energy,
        )
    }
}

/// A cyclic protocol: each amplitude (a drift ratio) cycled its number of times, a cycle going
/// out to `+a`, then to `-a`; the last cycle comes back to zero drift.
#[derive(Debug, Clone, PartialEq)]
pub struct Protocol {
    pub steps: Vec<(f64, usize)>,
}

impl Protocol {
    /// Each drift ratio the protocol visits, with its cycle (from 1).
    pub fn targets(&self) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        let mut cycle = 0;
        for &(a, n) in &self.steps {
            for _ in 0..n {
                cycle += 1;
                out.push((cycle, a));
                out.push((cycle, -a));
            }
        }
        if cycle > 0 {
            out.push((cycle, 0.0));
        }
        out
    }
}

/// What a loop point is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The origin, where the storey starts at rest.
    Start,
    /// A change of piece on the way to a target.
    Change,
    /// A target of the protocol (a peak, or the last return to zero).
    Target,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Start => "start",
            Kind::Change => "change",
            Kind::Target => "target",
        }
    }
}

/// One vertex of the loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    pub cycle: usize,
    pub kind: Kind,
    /// The drift ratio (at a target, the protocol's own number) and the drift, m.
    pub drift_ratio: f64,
    pub drift_m: f64,
    pub shear_n: f64,
    /// The piece the storey is on from this point (at a target: the one it arrived on).
    pub branch: Branch,
    /// The capping strength left over the initial one (the weaker side's), where the
    /// protocol stops (its start and targets; None at a change of piece on the way).
    pub strength_ratio: Option<f64>,
}

/// A storey's loops under a protocol.
#[derive(Debug, Clone, PartialEq)]
pub struct Loops {
    pub storey: Storey,
    pub protocol: Protocol,
    pub points: Vec<Point>,
    /// The undeteriorated backbone from the largest negative amplitude to the largest positive
    /// one (drift m, shear N), its vertices.
    pub backbone: Vec<(f64, f64)>,
}

/// The storey `storey` (checked: [`Storey::check`]) through `protocol`.
pub fn loops(storey: &Storey, protocol: &Protocol) -> Loops {
    let sp = storey.spring();
    let h = storey.height;
    let mut st = ImkState::new(&sp);
    let mut points = vec![Point {
        cycle: 1,
        kind: Kind::Start,
        drift_ratio: 0.0,
        drift_m: 0.0,
        shear_n: 0.0,
        branch: st.branch,
        strength_ratio: Some(st.strength_ratio(&sp)),
    }];
    let mut at = 0.0;
    for (cycle, ratio) in protocol.targets() {
        let to = ratio * h;
        let mut changes = Vec::new();
        let f = st.follow(&sp, at, to, &mut |d, f, branch| {
            changes.push((d, f, branch));
        });
        points.extend(changes.into_iter().map(|(d, f, branch)| Point {
            cycle,
            kind: Kind::Change,
            drift_ratio: d / h,
            drift_m: d,
            shear_n: f,
            branch,
            strength_ratio: None,
        }));
        points.push(Point {
            cycle,
            kind: Kind::Target,
            drift_ratio: ratio,
            drift_m: to,
            shear_n: f,
            branch: st.branch,
            strength_ratio: Some(st.strength_ratio(&sp)),
        });
        at = to;
    }
    let reach = protocol.steps.iter().map(|s| s.0).fold(0.0, f64::max) * h;
    let backbone = backbone(storey, reach);
    Loops {
        storey: storey.clone(),
        protocol: protocol.clone(),
        points,
        backbone,
    }
}

/// The undeteriorated backbone's vertices from `-reach` to `reach` (drift m, shear N): a
/// fresh spring pushed monotonically each way.
fn backbone(storey: &Storey, reach: f64) -> Vec<(f64, f64)> {
    let sp = storey.spring();
    let side = |to: f64| {
        let mut st = ImkState::new(&sp);
        let mut out = vec![(0.0, 0.0)];
        let f = st.follow(&sp, 0.0, to, &mut |d, f, _| out.push((d, f)));
        out.push((to, f));
        out
    };
    let mut neg = side(-reach);
    neg.reverse();
    let pos = side(reach);
    neg.extend(pos.into_iter().skip(1));
    neg
}

impl Loops {
    /// Every vertex as CSV: cycle, point (start, change, target), drift ratio, drift m, shear
    /// N, shear over `F_y`, branch, the strength left (over the initial capping strength; at
    /// the start and the targets, empty at a change of piece).
    pub fn csv(&self) -> String {
        let fy = self.storey.spring().fy;
        let mut csv = String::from(
            "cycle,point,drift_ratio,drift_m,shear_n,shear_over_fy,branch,strength_ratio\n",
        );
        for p in &self.points {
            let left = p.strength_ratio.map_or(String::new(), |r| r.to_string());
            csv.push_str(&format!(
                "{},{},{},{},{},{},{},{}\n",
                p.cycle,
                p.kind.name(),
                p.drift_ratio,
                p.drift_m,
                p.shear_n,
                p.shear_n / fy,
                p.branch.name(),
                left
            ));
        }
        csv
    }

    /// A markdown table: per cycle its amplitude, the shear over `F_y` at its positive and
    /// negative peaks, and the strength left at its end.
    pub fn markdown(&self) -> String {
        let fy = self.storey.spring().fy;
        let mut s = String::from(
            "| cycle | amplitude (drift ratio) | shear/F_y at +a | shear/F_y at -a | strength left |\n|---:|---:|---:|---:|---:|\n",
        );
        let cycles = self.points.last().map_or(0, |p| p.cycle);
        for c in 1..=cycles {
            let peaks: Vec<&Point> = self
                .points
                .iter()
                .filter(|p| p.cycle == c && p.kind == Kind::Target && p.drift_ratio != 0.0)
                .collect();
            let [pos, neg] = peaks[..] else { continue };
            s.push_str(&format!(
                "| {c} | {} | {:.4} | {:.4} | {:.4} |\n",
                pos.drift_ratio,
                pos.shear_n / fy,
                neg.shear_n / fy,
                neg.strength_ratio.unwrap_or(f64::NAN)
            ));
        }
        s
    }

    /// Shear over `F_y` against the drift ratio: the undeteriorated backbone dashed (thin grey,
    /// drawn first), then one series per cycle.
    pub fn panel(&self) -> Panel {
        let s = &self.storey;
        let h = s.height;
        let fy = s.spring().fy;
        let ratio = |&(d, f): &(f64, f64)| (d / h, f / fy);
        let backbone: Vec<(f64, f64)> = self.backbone.iter().map(ratio).collect();
        let mut series: Vec<Series> = dashes(&backbone)
            .into_iter()
            .map(|points| Series {
                name: String::new(),
                points,
                scatter: false,
                style: None,
            })
            .collect();
        let cycles = self.points.last().map_or(0, |p| p.cycle);
        let amplitude = |c: usize| {
            self.protocol
                .targets()
                .into_iter()
                .find(|t| t.0 == c)
                .map_or(0.0, |t| t.1)
        };
        for c in 1..=cycles {
            // From the previous cycle's last point, so that the loops join.
            let first = self.points.iter().position(|p| p.cycle == c).unwrap_or(0);
            let from = first.saturating_sub(1);
            let points = self.points[from..]
                .iter()
                .take_while(|p| p.cycle <= c)
                .map(|p| (p.drift_ratio, p.shear_n / fy))
                .collect();
            series.push(Series {
                name: format!("cycle {c} (±{})", amplitude(c)),
                points,
                scatter: false,
                style: None,
            });
        }
        let gamma = s.energy.map_or("none".to_string(), |g| g.to_string());
        Panel {
            title: format!(
                "{} storey: theta_y {}, b {}, theta_p {}, theta_pc {}, kappa {}, theta_u {}, gamma {}",
                s.rule.key(),
                s.yield_drift,
                s.post_yield,
                s.plastic,
                s.post_capping,
                s.residual,
                s.ultimate,
                gamma
            ),
            x_label: "storey drift ratio (m/m)".into(),
            y_label: "storey shear / F_y".into(),
            series,
            notes: Notes {
                caption: vec!["Dashed grey: the backbone before any deterioration.".into()],
                ..Notes::default()
            },
            ..Panel::default()
        }
    }
}

/// The dashes of a dashed line along `line`: pieces `DASH` long with gaps as long, lengths
/// measured with each axis scaled to its span, so the dashes look alike along any slope.
fn dashes(line: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    const DASH: f64 = 0.012;
    let span = |f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = line
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(v), h.max(v))
            });
        if hi > lo {
            hi - lo
        } else {
            1.0
        }
    };
    let (sx, sy) = (span(|p| p.0), span(|p| p.1));
    let mut out = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    // Where along the pattern (dash then gap, 2 DASH long) the walk is.
    let mut phase = 0.0;
    for w in line.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        let len = (((x1 - x0) / sx).powi(2) + ((y1 - y0) / sy).powi(2)).sqrt();
        let at = |t: f64| (x0 + (x1 - x0) * t, y0 + (y1 - y0) * t);
        let mut done = 0.0;
        while done < len {
            let on = phase < DASH;
            let room = if on { DASH - phase } else { 2.0 * DASH - phase };
            let step = room.min(len - done);
            if on {
                if current.is_empty() {
                    current.push(at(done / len));
                }
                current.push(at((done + step) / len));
            }
            done += step;
            phase += step;
            if phase >= DASH && on && !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
            if phase >= 2.0 * DASH {
                phase = 0.0;
            }
        }
    }
    if current.len() > 1 {
        out.push(current);
    }
    out
}

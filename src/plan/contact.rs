//! The axes every scene shares, below which each scene adds its buildings' and gaps' axes: the
//! contact (law, formula, `e`, stiffness), the record and the intensity, with the scheme and the
//! tail. A pair's plan ([`crate::plan::PairPlan`]) and a row's ([`crate::plan::row::RowPlan`])
//! each hold one [`ContactPlan`]; run `i` of either is contact run `i / per_scene` with scene
//! values `i % per_scene`, so both number runs in the same order.
//!
//! Contact runs are grouped by law. Within a law's block only the axes that law uses vary
//! (elastic laws ignore `e` and the formula; linear laws take `k`, Hertz-type laws `beta`), so
//! no run is a duplicate of another. Axis order, outermost first: law, formula, e, stiffness,
//! record, intensity.

use crate::physics::contact::LawKind;
use crate::physics::model::Forcing;
use crate::physics::restitution::{damping_for, Formula};
use crate::physics::solver::Scheme;
use crate::plan::axes::{check_axis, err, PlanError, POSITIVE};
use crate::plan::intensity::{self, Intensity};
use crate::record::{Record, G};
use std::collections::HashMap;
use std::sync::Arc;

/// The axes every scene shares (engine types; the config layer fills it).
#[derive(Debug, Clone)]
pub struct ContactSpec {
    pub laws: Vec<LawKind>,
    pub formulas: Vec<Formula>,
    pub e: Vec<f64>,
    /// N/m, for linear laws
    pub k_linear: Vec<f64>,
    /// N/m^1.5, for Hertz-type laws
    pub beta: Vec<f64>,
    pub records: Vec<Arc<Record>>,
    /// Each record's metadata where it came from a record set (`[[record]] set = "DIR"`):
    /// its runs' [`crate::plan::columns::RECORD_META`] columns.
    pub record_meta: Vec<Option<crate::record::set::RecordMeta>>,
    /// Each record's own factor under an `[intensity] scale` (a set's search scale factor with
    /// `search_scale`; else 1): its runs' `scale_factor` is the product.
    pub record_factor: Vec<f64>,
    pub intensities: Vec<Intensity>,
    pub scheme: Scheme,
    /// Free vibration after each record, s.
    pub tail: f64,
    /// A record scaled by more than this is named before the first run (no run depends on it).
    pub warn_scale: f64,
}

impl ContactSpec {
    /// Why none of the laws given takes the contact key `key` (`contact.e`,
    /// `contact.formula`, `contact.k_n_per_m`, `contact.beta_n_per_m1_5`); None where one does.
    pub(crate) fn unused(&self, key: &str) -> Option<String> {
        let laws = self
            .laws
            .iter()
            .map(|l| l.key())
            .collect::<Vec<_>>()
            .join(", ");
        let takers = |f: fn(LawKind) -> bool| {
            (LawKind::ALL.into_iter())
                .filter(|l| f(*l))
                .map(|l| l.key())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (used, what, who) = match key {
            "contact.e" => (
                self.laws.iter().any(|l| l.is_damped()),
                "a coefficient of restitution e",
                takers(LawKind::is_damped),
            ),
            "contact.formula" => (
                self.laws.iter().any(|l| l.uses_zeta()),
                "a restitution formula",
                takers(LawKind::uses_zeta),
            ),
            "contact.k_n_per_m" => (
                self.laws.iter().any(|l| !l.is_hertzian()),
                "k",
                takers(|l| !l.is_hertzian()),
            ),
            "contact.beta_n_per_m1_5" => (
                self.laws.iter().any(|l| l.is_hertzian()),
                "beta",
                takers(LawKind::is_hertzian),
            ),
            _ => return None,
        };
        (!used).then(|| format!("none of the laws given ({laws}) takes {what} (only {who} do)"))
    }

    /// Refuse a contact axis of two values or more that none of the laws given takes: it
    /// cannot change a run, and its values would be dropped without a word.
    pub(crate) fn refuse_unused(&self) -> Result<(), PlanError> {
        for (key, n) in [
            ("contact.formula", self.formulas.len()),
            ("contact.e", self.e.len()),
            ("contact.k_n_per_m", self.k_linear.len()),
            ("contact.beta_n_per_m1_5", self.beta.len()),
        ] {
            if let (true, Some(why)) = (n > 1, self.unused(key)) {
                return Err(err(
                    key,
                    format!("{n} values, but {why}: this axis cannot change a run (its values would be dropped); remove it or add a law that takes it"),
                ));
            }
        }
        Ok(())
    }

    /// Refuse sampled stiffness `key` (`sample.axis[j]`) that none of the laws given takes:
    /// its draws cannot change a run (where nothing else is sampled, each run would be
    /// repeated `n` times with the same physics).
    pub(crate) fn refuse_unused_sample(&self, j: usize, key: &str) -> Result<(), PlanError> {
        match self.unused(key) {
            Some(why) => Err(err(
                format!("sample.axis[{j}] ({key})"),
                format!("is sampled, but {why}: its draws cannot change a run; remove it from [sample] or add a law that takes it"),
            )),
            None => Ok(()),
        }
    }
}

/// Axes of a contact block, outermost first: formula, e, stiffness, record, intensity.
const NAXES: usize = 5;

#[derive(Debug, Clone)]
struct Block {
    law: LawKind,
    start: u64,
    len: u64,
    dims: [usize; NAXES],
}

/// The sizes of the contact axes below `law`: only the axes the law uses vary.
pub(crate) fn block_dims(law: LawKind, s: &ContactSpec) -> [usize; NAXES] {
    [
        if law.uses_zeta() { s.formulas.len() } else { 1 },
        if law.is_damped() { s.e.len() } else { 1 },
        if law.is_hertzian() {
            s.beta.len()
        } else {
            s.k_linear.len()
        },
        s.records.len(),
        s.intensities.len(),
    ]
}

/// The contact axes of a sweep, validated and numbered.
#[derive(Debug, Clone)]
pub struct ContactPlan {
    pub spec: ContactSpec,
    blocks: Vec<Block>,
    total: u64,
    /// Dimensionless damping per (law, formula, e index).
    damping: HashMap<(LawKind, Formula, usize), f64>,
    /// PGA of each record as read, m/s^2.
    pgas: Vec<f64>,
    /// Spectral measures of the records, as runs ask for them.
    ims: intensity::ImCache,
    /// The intensity measures each run writes of its record ([`ContactPlan::record_ims`],
    /// [`ContactPlan::sa_g`]), computed once per record (and period) as runs ask for them.
    motion_ims: Arc<intensity::MotionIms>,
}

/// One contact run, decoded: what a run holds but its buildings and gaps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRun {
    /// The run's number (a contact run's own, until a scene's run sets it).
    pub index: u64,
    pub law: LawKind,
    /// None for laws without a formula (elastic and Hunt-Crossley).
    pub formula: Option<Formula>,
    /// None for elastic laws.
    pub e: Option<f64>,
    /// zeta, or `a` in `chi = a / v0` for Hunt-Crossley laws; 0 for elastic laws.
    pub damping: f64,
    /// k (N/m) or beta (N/m^1.5).
    pub stiffness: f64,
    pub record: usize,
    pub intensity: Intensity,
    /// NaN until the buildings' periods are known ([`ContactPlan::scale`]).
    pub scale: f64,
    /// For a spectral target, the periods it was read at (s, from and to).
    pub im_periods: Option<[f64; 2]>,
    /// PGA of the scaled record, g.
    pub pga_g: f64,
}

impl ContactPlan {
    /// Did any record come from a record set (its runs then carry
    /// [`crate::plan::columns::RECORD_META`])?
    pub fn has_record_meta(&self) -> bool {
        self.spec.record_meta.iter().any(Option::is_some)
    }

    /// Validate the shared axes (the buildings' periods that a spectral target reads are the
    /// scene's to check: [`intensity::check_periods`]).
    pub(crate) fn new(spec: ContactSpec) -> Result<ContactPlan, PlanError> {
        let pos = POSITIVE.0;
        if spec.laws.is_empty() {
            return Err(err(
                "contact.law",
                format!("is empty: give one or more of {}", LawKind::keys()),
            ));
        }
        if spec.records.is_empty() {
            return Err(err("record", "no records: add at least one [[record]]"));
        }
        if spec.intensities.is_empty() {
            return Err(err("intensity", "is empty"));
        }
        for (i, v) in spec.intensities.iter().enumerate() {
            let (value, expected) = match v {
                Intensity::PgaG(_) => (v.value(), "a PGA > 0 g"),
                Intensity::Scale(_) => (v.value(), "a factor > 0"),
                Intensity::Spectral { im, .. } if im.average => (v.value(), "an Sa_avg > 0 g"),
                Intensity::Spectral { .. } => (v.value(), "an Sa > 0 g"),
            };
            if !pos(value) {
                return Err(err(
                    format!("{}[{i}]", v.key()),
                    format!(
                        "{} is out of range: expected {expected}",
                        crate::plan::limits::show(value)
                    ),
                ));
            }
        }
        if !(spec.tail.is_finite() && (0.0..=crate::plan::limits::MAX_TAIL_S).contains(&spec.tail))
        {
            return Err(err(
                "run.tail_s",
                format!(
                    "{} is out of range: expected 0 to {} s ({})",
                    crate::plan::limits::show(spec.tail),
                    crate::plan::limits::MAX_TAIL_S,
                    crate::plan::limits::WHY_TAIL
                ),
            ));
        }
        for (r, rec) in spec.records.iter().enumerate() {
            let n = rec.forcing(1.0, spec.tail).intervals() as u64;
            if n > crate::plan::limits::MAX_INTERVALS {
                return Err(err(
                    format!("record[{r}]"),
                    format!(
                        "`{}` with a tail of {} s is {n} steps of {} s: expected at most 1e8 per run ({})",
                        rec.name,
                        spec.tail,
                        rec.dt,
                        crate::plan::limits::WHY_INTERVALS
                    ),
                ));
            }
        }
        let damped = spec.laws.iter().any(|l| l.is_damped());
        let uses_formula = spec.laws.iter().any(|l| l.uses_zeta());
        if damped {
            check_axis(
                "contact.e",
                &spec.e,
                crate::physics::restitution::e_in_range,
                &format!(
                    "a coefficient of restitution {}",
                    crate::physics::restitution::E_EXPECTED
                ),
            )?;
        }
        if uses_formula && spec.formulas.is_empty() {
            return Err(err(
                "contact.formula",
                format!(
                    "is empty: the laws given need one or more of {}",
                    Formula::keys()
                ),
            ));
        }
        if spec.laws.iter().any(|l| !l.is_hertzian()) {
            check_axis(
                "contact.k_n_per_m",
                &spec.k_linear,
                pos,
                "a stiffness > 0 N/m",
            )?;
        }
        if spec.laws.iter().any(|l| l.is_hertzian()) {
            check_axis(
                "contact.beta_n_per_m1_5",
                &spec.beta,
                pos,
                "a stiffness > 0 N/m^1.5",
            )?;
        }
        let mut pgas = Vec::with_capacity(spec.records.len());
        // A target scales the part of a record that is simulated (its window): of zeros, it
        // has none of the measure the target names.
        let target = spec.intensities.iter().find_map(|i| match i {
            Intensity::Scale(_) => None,
            Intensity::PgaG(_) => Some(("PGA", i.key())),
            Intensity::Spectral { im, .. } if im.average => Some(("Sa_avg", i.key())),
            Intensity::Spectral { .. } => Some(("Sa", i.key())),
        });
        for (r, rec) in spec.records.iter().enumerate() {
            let pga = rec.pga().value;
            if let (Some((measure, key)), true) = (target, pga <= 0.0) {
                return Err(err(
                    format!("record[{r}]"),
                    format!(
                        "{}: all zeros from {} s to {} s (the part simulated): no {measure} to scale to {key}",
                        rec.name,
                        crate::plan::limits::show(rec.t0),
                        crate::show_derived(rec.t0 + (rec.npts() - 1) as f64 * rec.dt),
                    ),
                ));
            }
            pgas.push(pga);
        }
        // Damping per (law, formula, e): printed formulas are cheap, `exact` root-finds once here.
        let mut damping = HashMap::new();
        for &law in &spec.laws {
            if !law.is_damped() {
                continue;
            }
            let formulas: &[Formula] = if law.uses_zeta() {
                &spec.formulas
            } else {
                &[Formula::Exact]
            };
            for &f in formulas {
                for (i, &e) in spec.e.iter().enumerate() {
                    let d = damping_for(law, f, e)
                        .map_err(|x| err(format!("contact.e[{i}]"), x.to_string()))?;
                    damping.insert((law, f, i), d);
                }
            }
        }
        let mut blocks = Vec::with_capacity(spec.laws.len());
        let mut total: u64 = 0;
        for &law in &spec.laws {
            let dims = block_dims(law, &spec);
            // Bounded by the scene's check of its whole run count.
            let len = dims
                .iter()
                .try_fold(1u64, |p, &d| p.checked_mul(d as u64))
                .ok_or_else(|| err("contact", "more than 2^64 contact runs"))?;
            blocks.push(Block {
                law,
                start: total,
                len,
                dims,
            });
            total = total
                .checked_add(len)
                .ok_or_else(|| err("contact", "more than 2^64 contact runs"))?;
        }
        let records = spec.records.len();
        Ok(ContactPlan {
            spec,
            blocks,
            total,
            damping,
            motion_ims: Arc::new(intensity::MotionIms::new(records, [])),
            pgas,
            ims: intensity::ImCache::default(),
        })
    }

    /// Number of contact runs.
    pub fn len(&self) -> u64 {
        self.total
    }

    pub fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// Decode contact run `index` (< `len()`), its scale left unset (NaN) until its buildings'
    /// periods are known ([`ContactPlan::scale`]).
    pub fn decode(&self, index: u64) -> ContactRun {
        assert!(
            index < self.total,
            "contact run {index} out of range (plan has {})",
            self.total
        );
        let block = self
            .blocks
            .iter()
            .find(|b| index < b.start + b.len)
            .expect("index within total");
        let mut rem = index - block.start;
        let mut ix = [0usize; NAXES];
        for a in (0..NAXES).rev() {
            let d = block.dims[a] as u64;
            ix[a] = (rem % d) as usize;
            rem /= d;
        }
        let s = &self.spec;
        let law = block.law;
        let formula = law.uses_zeta().then(|| s.formulas[ix[0]]);
        let e = law.is_damped().then(|| s.e[ix[1]]);
        let damping = if law.is_damped() {
            self.damping[&(law, formula.unwrap_or(Formula::Exact), ix[1])]
        } else {
            0.0
        };
        let stiffness = if law.is_hertzian() {
            s.beta[ix[2]]
        } else {
            s.k_linear[ix[2]]
        };
        ContactRun {
            index,
            law,
            formula,
            e,
            damping,
            stiffness,
            record: ix[3],
            intensity: s.intensities[ix[4]],
            scale: f64::NAN,
            im_periods: None,
            pga_g: f64::NAN,
        }
    }

    /// Set `run`'s scale factor, the periods its intensity read and its PGA, for buildings of
    /// these fundamental periods (left to right).
    pub fn scale(&self, run: &mut ContactRun, periods: &[f64]) {
        let r = run.record;
        let s = self.scaling(r, &run.intensity, periods);
        run.scale = s.scale;
        run.im_periods = s.periods;
        run.pga_g = self.pgas[r] * s.scale / G;
    }

    /// List the fundamental periods (s) the scene's buildings take (`periods[b]`: every value
    /// of building `b`, its axis or its samples), whose `Sa` runs write: each is computed once
    /// per record.
    pub(crate) fn list_periods(&mut self, periods: &[Vec<f64>]) {
        self.motion_ims = Arc::new(intensity::MotionIms::new(
            self.spec.records.len(),
            periods.iter().flatten().copied(),
        ));
    }

    /// PGV, Arias intensity and CAV (m/s) of `run`'s scaled record, in
    /// [`intensity::IM_COLUMNS`] order.
    pub fn record_ims(&self, run: &ContactRun) -> [f64; 3] {
        let r = run.record;
        self.motion_ims
            .record(r, &self.spec.records[r])
            .scaled(run.scale)
    }

    /// `Sa(period, 5 %)` of `run`'s scaled record, g.
    pub fn sa_g(&self, run: &ContactRun, period: f64) -> f64 {
        let r = run.record;
        self.motion_ims.sa(r, &self.spec.records[r], period) * run.scale / G
    }

    /// Record `r`'s factor under intensity `i` for buildings of these periods: a target's, or
    /// `[intensity] scale` times the record's own factor (a set's search scale factor).
    fn scaling(&self, r: usize, i: &Intensity, periods: &[f64]) -> intensity::Scaling {
        let rec = &self.spec.records[r];
        let mut s = i.scaling(r, rec, self.pgas[r], periods, &self.ims);
        if matches!(i, Intensity::Scale(_)) {
            s.scale *= self.spec.record_factor[r];
        }
        s
    }

    /// The records scaled past a PGA no earthquake reaches, or by more than the config's
    /// bound on the scale factor, for buildings of these fundamental periods (a spectral target
    /// at a building's period scales by the first run's).
    pub fn pga_warnings(&self, periods: &[f64]) -> Vec<String> {
        let mut w = Vec::new();
        for (r, rec) in self.spec.records.iter().enumerate() {
            let scale = self
                .spec
                .intensities
                .iter()
                .map(|i| self.scaling(r, i, periods).scale)
                .fold(0.0, f64::max);
            if scale > self.spec.warn_scale {
                let at = if self.spec.intensities.iter().any(|i| i.follows_a_building()) {
                    " (at the first run's building periods)"
                } else {
                    ""
                };
                w.push(format!(
                    "record `{}` is scaled by up to {}{at}, above {} ([intensity] warn_scale_factor): scaled this far, a record keeps its own duration and spectral shape, not those of an earthquake of that intensity; choose records nearer the target",
                    rec.name,
                    crate::plan::limits::show((scale * 100.0).round() / 100.0),
                    crate::plan::limits::show(self.spec.warn_scale)
                ));
            }
            let pga = self.pgas[r] * scale / G;
            if pga > crate::plan::limits::WARN_PGA_G {
                w.push(format!(
                    "record `{}` reaches a PGA of {pga:.3} g, above {} g where no recorded earthquake reaches: check its units and the intensity",
                    rec.name,
                    crate::plan::limits::WARN_PGA_G
                ));
            }
        }
        w
    }

    /// The contact run of the first law's first contact values with record and intensity
    /// `ri` (`record x intensities + intensity`): where a scene's motion `m` lives.
    pub(crate) fn motion_index(&self, ri: u64) -> u64 {
        // The record and intensity are the innermost contact axes.
        ri
    }

    /// The summed cost of contact runs `0..end`, each repeated `per_scene` times, when a run
    /// costs `record_cost[r]` for its record `r`: then the scene's runs `0..end_run`
    /// ([`ContactPlan::scene_cost_before`]). In closed form per law block (the record axis
    /// repeats with a fixed stride), so O(blocks x records), never O(runs).
    fn cost_before(&self, end: u64, record_cost: &[u64]) -> u128 {
        let mut acc: u128 = 0;
        for b in &self.blocks {
            if end <= b.start {
                break;
            }
            let rem = (end - b.start).min(b.len) as u128;
            let inner = b.dims[4] as u128;
            let nrec = b.dims[3] as u128;
            let cost = |r: usize| record_cost[r] as u128;
            let cycle: u128 = inner * (0..b.dims[3]).map(cost).sum::<u128>();
            let (q, r_rem) = (rem / (inner * nrec), rem % (inner * nrec));
            let (full, part) = ((r_rem / inner) as usize, r_rem % inner);
            acc += q * cycle + inner * (0..full).map(cost).sum::<u128>();
            if part > 0 {
                acc += part * cost(full);
            }
        }
        acc
    }

    /// The summed cost of a scene's runs `0..end`, `per_scene` runs per contact run, when a
    /// run costs `record_cost[r]` for its record `r`.
    pub(crate) fn scene_cost_before(&self, end: u64, per_scene: u64, record_cost: &[u64]) -> u128 {
        let (whole, part) = (end / per_scene, end % per_scene);
        let mut cost = self.cost_before(whole, record_cost) * per_scene as u128;
        if part > 0 {
            cost += part as u128 * record_cost[self.decode(whole).record] as u128;
        }
        cost
    }

    /// Each record's accelerations as read (unscaled): what the GPU uploads once per sweep.
    pub fn accels(&self) -> Vec<&[f64]> {
        self.spec.records.iter().map(|r| &r.accel[..]).collect()
    }

    pub fn forcing(&self, run: &ContactRun) -> Forcing<'_> {
        self.spec.records[run.record].forcing(run.scale, self.spec.tail)
    }
}

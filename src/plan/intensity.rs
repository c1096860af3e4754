//! The intensity axis: what each record is scaled to (`[intensity]`, `shared/docs/physics.md`
//! section 9). A target PGA or a plain factor scales a record the same way in every run; a
//! spectral target (`sa_g`, `sa_avg_g`) at a period that follows a building's fundamental
//! period scales it per run, so its factor is resolved where the run's periods are known
//! ([`crate::plan::pair::PairPlan::run`], [`crate::plan::row::RowPlan::run`]).

use crate::record::intensity::{arias_cav, log_periods, pgv_pgd, sa, sa_avg, DEFAULT_DAMPING};
use crate::record::{Record, G};
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

/// The longest period a spectral target reads (s); the shortest is a building's
/// ([`crate::plan::limits::MIN_PERIOD_S`]).
pub const MAX_SPECTRAL_PERIOD_S: f64 = 100.0;

/// A value of the intensity axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Intensity {
    /// Scale each record to this PGA, g.
    PgaG(f64),
    /// Multiply each record by this factor.
    Scale(f64),
    /// Scale each record so that its spectral measure `im` equals `g` (g).
    Spectral { g: f64, im: SpectralIm },
}

/// Which spectral measure, at which periods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectralIm {
    /// `Sa(T)` (`from` is `to`, one period) or `Sa_avg` over `n` log-spaced periods.
    pub average: bool,
    pub from: PeriodRef,
    pub to: PeriodRef,
    pub n: usize,
    /// Damping ratio of the oscillator.
    pub damping: f64,
}

/// A period: in seconds, or a multiple of a building's fundamental period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PeriodRef {
    Seconds(f64),
    /// `factor` times the fundamental period of building `building` (0-based, left to right).
    Building {
        building: usize,
        factor: f64,
    },
}

impl PeriodRef {
    /// Parse `"building1"` (1-based, as the columns `b1_...`), `"building[0]"` (0-based, as the
    /// `[[building]]` entries) or either with a factor, `"0.2*building1"`.
    pub fn parse(text: &str) -> Result<PeriodRef, String> {
        let bad = || {
            format!("`{text}`: expected a period in s, or \"building1\", \"building[0]\", \"0.2*building1\" (a multiple of a building's fundamental period)")
        };
        let t = text.trim();
        let (factor, name) = match t.split_once('*') {
            Some((f, n)) => (f.trim().parse::<f64>().map_err(|_| bad())?, n.trim()),
            None => (1.0, t),
        };
        let rest = name.strip_prefix("building").ok_or_else(bad)?;
        let building = match rest.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            Some(i) => i.trim().parse::<usize>().map_err(|_| bad())?,
            None => match rest.parse::<usize>() {
                Ok(n) if n >= 1 => n - 1,
                _ => return Err(bad()),
            },
        };
        if !(factor.is_finite() && factor > 0.0) {
            return Err(format!("`{text}`: the factor must be > 0"));
        }
        Ok(PeriodRef::Building { building, factor })
    }

    /// The period in s, given the buildings' fundamental periods.
    pub fn resolve(&self, periods: &[f64]) -> f64 {
        match *self {
            PeriodRef::Seconds(t) => t,
            // NaN where the scene has no such building (the config refuses it): a failed run.
            PeriodRef::Building { building, factor } => {
                factor * periods.get(building).copied().unwrap_or(f64::NAN)
            }
        }
    }

    /// The building it follows, if any.
    pub fn building(&self) -> Option<usize> {
        match *self {
            PeriodRef::Seconds(_) => None,
            PeriodRef::Building { building, .. } => Some(building),
        }
    }
}

impl SpectralIm {
    /// The periods it reads from and to (s), in order, for these fundamental periods.
    pub fn range(&self, periods: &[f64]) -> [f64; 2] {
        let (a, b) = (self.from.resolve(periods), self.to.resolve(periods));
        [a.min(b), a.max(b)]
    }

    /// The config key of its periods.
    pub fn periods_key(&self) -> &'static str {
        if self.average {
            "intensity.sa_avg_periods_s"
        } else {
            "intensity.sa_period_s"
        }
    }

    /// The buildings whose periods it follows.
    pub fn buildings(&self) -> impl Iterator<Item = usize> {
        self.from.building().into_iter().chain(self.to.building())
    }

    /// Its value (m/s^2) for the unscaled record `rec` over `range`.
    pub fn of(&self, rec: &Record, range: [f64; 2]) -> f64 {
        let n = if self.average { self.n } else { 1 };
        sa_avg(rec, &log_periods(range[0], range[1], n), self.damping)
    }

    /// Why the periods `range` cannot be read, if they cannot.
    pub fn check_range(range: [f64; 2]) -> Result<(), String> {
        let lo = crate::plan::limits::MIN_PERIOD_S;
        match range
            .iter()
            .find(|t| !(**t >= lo && **t <= MAX_SPECTRAL_PERIOD_S))
        {
            Some(t) => Err(format!(
                "reads Sa at {} s: expected periods from {lo} to {MAX_SPECTRAL_PERIOD_S} s",
                crate::plan::limits::show(*t)
            )),
            None => Ok(()),
        }
    }
}

/// What the intensity gave a run: its factor and, for a spectral target, the periods read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    pub scale: f64,
    /// s, from and to (equal for `Sa(T)`).
    pub periods: Option<[f64; 2]>,
}

/// The columns that say what a run's record was scaled to, in file order (units in the names).
pub const TARGET_COLUMNS: [&str; 6] = [
    "target_pga_g",
    "target_sa_g",
    "sa_period_s",
    "target_sa_avg_g",
    "sa_avg_from_s",
    "sa_avg_to_s",
];

/// The values of [`TARGET_COLUMNS`] for a run of `intensity` whose spectral target read
/// `periods` (None where a column does not apply).
pub fn target_values(intensity: &Intensity, periods: Option<[f64; 2]>) -> [Option<f64>; 6] {
    let mut v = [None; 6];
    match *intensity {
        Intensity::PgaG(g) => v[0] = Some(g),
        Intensity::Scale(_) => {}
        Intensity::Spectral { g, im } => {
            let p = periods.unwrap_or([f64::NAN; 2]);
            if im.average {
                v[3..6].copy_from_slice(&[Some(g), Some(p[0]), Some(p[1])]);
            } else {
                v[1..3].copy_from_slice(&[Some(g), Some(p[0])]);
            }
        }
    }
    v
}

/// Spectral measures of the unscaled records, computed once per record and periods: runs that
/// share them share one computation whichever thread asks first.
#[derive(Debug, Clone, Default)]
pub struct ImCache {
    values: Arc<Mutex<HashMap<ImKey, f64>>>,
}

/// A record's index and the bits of the periods read from and to.
type ImKey = (usize, u64, u64);

impl ImCache {
    /// `im` of record `r` (`rec`) over `range`, m/s^2.
    pub fn get(&self, r: usize, rec: &Record, im: &SpectralIm, range: [f64; 2]) -> f64 {
        let key = (r, range[0].to_bits(), range[1].to_bits());
        if let Some(v) = self.values.lock().expect("cache lock").get(&key) {
            return *v;
        }
        // Computed outside the lock: other records and periods go on meanwhile.
        let v = im.of(rec, range);
        self.values.lock().expect("cache lock").insert(key, v);
        v
    }
}

/// The intensity measures every run writes of its scaled record, whatever it was scaled to,
/// that do not depend on the buildings (units in the names), in file order after `pga_g`; each
/// building's `Sa(T1)` follows them ([`MotionIms::sa_g`]).
pub const IM_COLUMNS: [&str; 3] = ["pgv_m_s", "arias_m_s", "cav_m_s"];

/// The suffix of a building's `Sa(T1)` column in a row (`b2_sa_t1_g`); a pair's are `sa_t1_g` and
/// `sa_t2_g`.
pub const SA_T1_COLUMN: &str = "sa_t1_g";

/// PGV, Arias intensity and CAV of an unscaled record (m/s), over its samples as simulated (its
/// window, not the free tail): [`crate::record::intensity`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordIms {
    pub pgv: f64,
    pub arias: f64,
    pub cav: f64,
}

impl RecordIms {
    pub fn of(rec: &Record) -> RecordIms {
        let (arias, cav) = arias_cav(rec);
        RecordIms {
            pgv: pgv_pgd(rec).0,
            arias,
            cav,
        }
    }

    /// The values of [`IM_COLUMNS`] for the record scaled by `scale` (> 0): PGV and CAV scale
    /// with it, Arias intensity with its square.
    pub fn scaled(&self, scale: f64) -> [f64; 3] {
        [
            self.pgv * scale,
            self.arias * scale * scale,
            self.cav * scale,
        ]
    }
}

/// Sentinel of a value not yet computed in [`MotionIms`]' table (a NaN no arithmetic makes).
const NOT_YET: u64 = u64::MAX;

/// The intensity measures of a sweep's unscaled records that its runs write: PGV, Arias and CAV
/// once per record, and `Sa(T, 5 %)` once per record and fundamental period a building takes
/// (every period is known when the plan is built: an axis's values or a sample's), each
/// computed when a run first asks and read lock-free after. A period the plan did not list
/// (a run built by hand) is computed when asked.
#[derive(Debug, Default)]
pub struct MotionIms {
    records: Vec<OnceLock<RecordIms>>,
    /// Each listed period's bits, and its index in a record's row of `sa`.
    periods: HashMap<u64, usize>,
    /// Per record, lazily: `Sa` (m/s^2) at each listed period, as bits (`NOT_YET` until asked).
    sa: Vec<OnceLock<Box<[AtomicU64]>>>,
}

impl MotionIms {
    /// For `records` records and the fundamental periods `periods` (s) the buildings take.
    pub fn new(records: usize, periods: impl IntoIterator<Item = f64>) -> MotionIms {
        let mut index = HashMap::new();
        for t in periods {
            let next = index.len();
            index.entry(t.to_bits()).or_insert(next);
        }
        MotionIms {
            records: (0..records).map(|_| OnceLock::new()).collect(),
            periods: index,
            sa: (0..records).map(|_| OnceLock::new()).collect(),
        }
    }

    /// PGV, Arias and CAV of record `r` (`rec`), unscaled.
    pub fn record(&self, r: usize, rec: &Record) -> RecordIms {
        match self.records.get(r) {
            Some(cell) => *cell.get_or_init(|| RecordIms::of(rec)),
            None => RecordIms::of(rec),
        }
    }

    /// `Sa(period, 5 %)` of record `r` (`rec`), unscaled, m/s^2.
    pub fn sa(&self, r: usize, rec: &Record, period: f64) -> f64 {
        let compute = || sa(rec, period, DEFAULT_DAMPING);
        let (Some(&i), Some(row)) = (self.periods.get(&period.to_bits()), self.sa.get(r)) else {
            return compute();
        };
        let row = row.get_or_init(|| {
            (0..self.periods.len())
                .map(|_| AtomicU64::new(NOT_YET))
                .collect()
        });
        match row[i].load(Ordering::Relaxed) {
            NOT_YET => {
                // Two threads asking at once both compute it: the same value.
                let v = compute();
                row[i].store(v.to_bits(), Ordering::Relaxed);
                v
            }
            bits => f64::from_bits(bits),
        }
    }
}

impl Intensity {
    /// A spectral target at a period that follows a building's (so its scale factor varies
    /// with the run's buildings).
    pub fn follows_a_building(&self) -> bool {
        matches!(self, Intensity::Spectral { im, .. }
            if matches!(im.from, PeriodRef::Building { .. }) || matches!(im.to, PeriodRef::Building { .. }))
    }

    /// The factor for record `r` (`rec`, whose PGA is `pga` m/s^2) in a run whose buildings
    /// have these fundamental periods.
    pub fn scaling(
        &self,
        r: usize,
        rec: &Record,
        pga: f64,
        periods: &[f64],
        cache: &ImCache,
    ) -> Scaling {
        match *self {
            Intensity::PgaG(g) => Scaling {
                scale: g * G / pga,
                periods: None,
            },
            Intensity::Scale(s) => Scaling {
                scale: s,
                periods: None,
            },
            Intensity::Spectral { g, im } => {
                let range = im.range(periods);
                Scaling {
                    scale: g * G / cache.get(r, rec, &im, range),
                    periods: Some(range),
                }
            }
        }
    }

    /// The spectral measure it targets, if any.
    pub fn spectral(&self) -> Option<&SpectralIm> {
        match self {
            Intensity::Spectral { im, .. } => Some(im),
            _ => None,
        }
    }

    /// Its config key (`intensity.pga_g`, ...).
    pub fn key(&self) -> &'static str {
        match self {
            Intensity::PgaG(_) => "intensity.pga_g",
            Intensity::Scale(_) => "intensity.scale",
            Intensity::Spectral { im, .. } if im.average => "intensity.sa_avg_g",
            Intensity::Spectral { .. } => "intensity.sa_g",
        }
    }

    /// Its target value (g or a factor).
    pub fn value(&self) -> f64 {
        match *self {
            Intensity::PgaG(g) | Intensity::Scale(g) | Intensity::Spectral { g, .. } => g,
        }
    }
}

/// The shortest and longest of `periods`.
pub fn span(periods: impl Iterator<Item = f64>) -> (f64, f64) {
    periods.fold((f64::INFINITY, 0.0), |(lo, hi), t| (lo.min(t), hi.max(t)))
}

/// Check a spectral target's periods against every value the buildings' periods take:
/// `periods[b]` holds every fundamental period building `b` takes in the sweep (its axis and
/// its samples). Each period read grows with the building's, so the extremes bound them all;
/// and an `Sa_avg` is refused where its two ends are one period in a run, as it is where they
/// are written alike (`["0.5*building[0]", 0.5]` with building[0] at 1 s read one period).
pub fn check_periods(
    intensities: &[Intensity],
    periods: &[Vec<f64>],
) -> Result<(), (String, String)> {
    let Some(im) = intensities.iter().find_map(|i| i.spectral()) else {
        return Ok(());
    };
    let key = || im.periods_key().to_string();
    for b in im.buildings() {
        if b >= periods.len() {
            return Err((
                key(),
                format!(
                    "follows building{} (building[{b}]), but the scene has {} buildings",
                    b + 1,
                    periods.len()
                ),
            ));
        }
    }
    let (lo, hi): (Vec<f64>, Vec<f64>) = periods.iter().map(|p| span(p.iter().copied())).unzip();
    for ends in [&lo, &hi] {
        SpectralIm::check_range(im.range(ends)).map_err(|m| (key(), m))?;
    }
    // Ends on one building (at two factors) are never one period; on two, or a building and
    // seconds, they are where the values they take meet.
    if im.average && !(im.from.building().is_some() && im.from.building() == im.to.building()) {
        let values = |p: PeriodRef| -> Vec<(f64, f64)> {
            match p {
                PeriodRef::Seconds(t) => vec![(t, f64::NAN)],
                PeriodRef::Building { building, factor } => {
                    periods[building].iter().map(|&t| (factor * t, t)).collect()
                }
            }
        };
        let mut to = values(im.to);
        to.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (t, own) in values(im.from) {
            if let Ok(j) = to.binary_search_by(|x| x.0.total_cmp(&t)) {
                let at = |p: PeriodRef, own: f64| match p.building() {
                    Some(b) => format!(" (building[{b}] at {} s)", crate::plan::limits::show(own)),
                    None => String::new(),
                };
                return Err((
                    key(),
                    format!(
                        "from{} and to{} are the same period, {} s: give a range in every run (or sa_g for one period)",
                        at(im.from, own),
                        at(im.to, to[j].1),
                        crate::plan::limits::show(t)
                    ),
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A listed period's Sa is computed once per record and read back the same; an unlisted one
    /// is computed when asked, to the same value; PGV, Arias and CAV scale as their units do.
    #[test]
    fn motion_ims_are_the_records_own() {
        let rec = |seed: f64| Record {
            name: "r".into(),
            dt: 0.01,
            t0: 0.0,
            accel: (0..500).map(|i| (i as f64 * 0.05 * seed).sin()).collect(),
        };
        let (r0, r1) = (rec(1.0), rec(1.7));
        let ims = MotionIms::new(2, [0.5, 1.0, 0.5]);
        assert_eq!(ims.periods.len(), 2);
        for (r, x) in [(0, &r0), (1, &r1)] {
            for t in [0.5, 1.0, 0.75] {
                let want = sa(x, t, DEFAULT_DAMPING);
                assert_eq!(ims.sa(r, x, t), want);
                assert_eq!(ims.sa(r, x, t), want, "read back");
            }
            assert_eq!(ims.record(r, x), RecordIms::of(x));
        }
        let one = RecordIms::of(&r0);
        let [pgv, arias, cav] = one.scaled(3.0);
        assert_eq!(
            [pgv, arias, cav],
            [3.0 * one.pgv, 9.0 * one.arias, 3.0 * one.cav]
        );
    }

    #[test]
    fn period_references_parse_and_resolve() {
        let b = |building, factor| PeriodRef::Building { building, factor };
        assert_eq!(PeriodRef::parse("building1"), Ok(b(0, 1.0)));
        assert_eq!(PeriodRef::parse("building[2]"), Ok(b(2, 1.0)));
        assert_eq!(PeriodRef::parse(" 0.2 * building2"), Ok(b(1, 0.2)));
        for bad in [
            "building0",
            "buildin1",
            "building",
            "x*building1",
            "-1*building1",
        ] {
            assert!(PeriodRef::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(b(1, 3.0).resolve(&[0.5, 0.4]), 3.0 * 0.4);
        let im = SpectralIm {
            average: true,
            from: b(0, 3.0),
            to: b(1, 0.2),
            n: 10,
            damping: 0.05,
        };
        assert_eq!(im.range(&[1.0, 2.0]), [0.4, 3.0]);
    }
}

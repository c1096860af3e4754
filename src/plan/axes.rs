//! What every plan's values must be, and the errors that say why one is not; the motions of a
//! sweep (the runs that differ before any contact).

/// A plan value that is out of range; `key` is the config key (with index).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key}: {message}")]
pub struct PlanError {
    pub key: String,
    pub message: String,
}

pub(crate) fn err(key: impl Into<String>, message: impl Into<String>) -> PlanError {
    PlanError {
        key: key.into(),
        message: message.into(),
    }
}

/// The motions of a sweep ([`PairPlan::motions`]): `records x intensities x inner`, the record
/// outermost, then the intensity; `inner` counts the samples and building values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Motions {
    pub records: usize,
    pub intensities: usize,
    pub inner: u64,
}

impl Motions {
    pub fn len(&self) -> u64 {
        (self.records * self.intensities) as u64 * self.inner
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Motion `m`'s record and intensity indices.
    pub fn record_and_intensity(&self, m: u64) -> (usize, usize) {
        let ri = (m / self.inner) as usize;
        (ri / self.intensities, ri % self.intensities)
    }

    /// The motions that differ only in intensity share one response at unit scale: motion
    /// `m`'s index among those `records x inner` responses.
    pub fn response(&self, m: u64) -> u64 {
        let (r, _) = self.record_and_intensity(m);
        r as u64 * self.inner + m % self.inner
    }
}

fn period_ok(v: f64) -> bool {
    v.is_finite() && v >= crate::plan::limits::MIN_PERIOD_S
}

const PERIOD_EXPECTED: &str = "a period >= 1e-4 s (stiffer is a rigid body, not a building: contact substeps resolve the structure's period, so runs would crawl)";

/// What a swept or sampled value must be, and the words an error gives for it: shared by the
/// pair's plan and the row's ([`crate::plan::row`]).
pub(crate) type Check = (fn(f64) -> bool, &'static str);
pub(crate) const PERIOD: Check = (period_ok, PERIOD_EXPECTED);
pub(crate) const DAMPING: Check = (|v| (0.0..1.0).contains(&v), "0 <= damping ratio < 1");
pub(crate) const GAP: Check = (|v| v.is_finite() && v >= 0.0, "a gap >= 0 m");
pub(crate) const MASS: Check = (
    |v| v.is_finite() && v > 0.0 && v <= crate::plan::limits::MAX_MASS_KG,
    "a mass > 0 kg and at most 1e12 kg (the heaviest floors weigh about 1e7 kg)",
);
pub(crate) const POSITIVE: Check = (|v| v.is_finite() && v > 0.0, "a value > 0");

/// `values` of the axis `key`: not empty, each passing `ok` (else an error naming the value and
/// its index, `expected` saying what it must be).
pub(crate) fn check_axis(
    key: &str,
    values: &[f64],
    ok: impl Fn(f64) -> bool,
    expected: &str,
) -> Result<(), PlanError> {
    if values.is_empty() {
        return Err(err(key, "is missing or empty: give at least one value"));
    }
    for (i, &v) in values.iter().enumerate() {
        if !ok(v) {
            return Err(err(
                format!("{key}[{i}]"),
                format!(
                    "{} is out of range: expected {expected}",
                    crate::plan::limits::show(v)
                ),
            ));
        }
    }
    Ok(())
}

//! Ground-motion records: the `Record` type, file readers (`read`), and the seeded synthetic
//! generator (`synthetic`). Accelerations are stored in m/s^2 whatever the file's units.
//!
//! May import the physics only (a record makes a `Forcing`); never plans, engines, io or studies.

pub mod intensity;
mod read;
pub mod rng;
pub mod set;
mod synthetic;

pub use read::{read_record, Format, ReadOptions, Units};
pub use synthetic::{synthetic, SyntheticSpec};

use std::path::PathBuf;

/// Standard gravity, m/s^2 (the factor used by PEER files).
pub use crate::physics::model::G;

/// A uniformly sampled ground acceleration history.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Label used in outputs (file stem or `synthetic-seedN`).
    pub name: String,
    /// Sample interval, s.
    pub dt: f64,
    /// Time of the first sample, s (two-column files may start at `dt`, not 0).
    pub t0: f64,
    /// Ground acceleration samples, m/s^2.
    pub accel: Vec<f64>,
}

/// Peak ground acceleration and where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    /// max |a|, m/s^2
    pub value: f64,
    /// Index of the sample.
    pub index: usize,
    /// Time of the sample, s.
    pub time: f64,
}

impl Record {
    pub fn npts(&self) -> usize {
        self.accel.len()
    }

    /// Duration as PEER quotes it: `npts * dt`.
    pub fn duration(&self) -> f64 {
        self.accel.len() as f64 * self.dt
    }

    /// Peak |a| (first occurrence on ties).
    pub fn pga(&self) -> Peak {
        let mut best = Peak {
            value: 0.0,
            index: 0,
            time: self.t0,
        };
        for (i, a) in self.accel.iter().enumerate() {
            if a.abs() > best.value {
                best = Peak {
                    value: a.abs(),
                    index: i,
                    time: self.t0 + i as f64 * self.dt,
                };
            }
        }
        best
    }

    /// The samples at times `start <= t <= end` (a strong-motion window); times keep the
    /// record's clock, so onsets in outputs read against the full record. `None` if the window
    /// holds fewer than two samples.
    pub fn window(&self, start: f64, end: f64) -> Option<Record> {
        let tol = 1e-9 * self.dt;
        // Sample indices in f64 first: a window far past the record (1e300 s) is no index.
        let first = ((start - self.t0 - tol) / self.dt).ceil().max(0.0);
        let last = ((end - self.t0 + tol) / self.dt)
            .floor()
            .min(self.npts().checked_sub(1)? as f64);
        if !(end >= start && last >= first + 1.0) {
            return None;
        }
        let (first, last) = (first as usize, last as usize);
        Some(Record {
            name: self.name.clone(),
            dt: self.dt,
            t0: self.t0 + first as f64 * self.dt,
            accel: self.accel[first..=last].to_vec(),
        })
    }

    /// [`Record::window`], or why not: the one reading of a window, for a config's `window_s`
    /// and the record commands' `--window` alike (each names its own spelling before it).
    pub fn windowed(&self, [start, end]: [f64; 2]) -> Result<Record, String> {
        let last = self.t0 + (self.npts().max(1) - 1) as f64 * self.dt;
        let span = || {
            format!(
                "the record runs from {} s to {} s, dt {} s",
                crate::show(self.t0),
                crate::show(last),
                crate::show(self.dt)
            )
        };
        // A window reaching past the record would be cut to it without a word: the window
        // simulated would not be the one asked for. A step before the first sample is the
        // ground at rest (an AT2 record's first sample is at dt, windowed from 0), and half a
        // step either side is rounding.
        let slack = 0.5 * self.dt;
        if start < self.t0 - self.dt - slack || end > last + slack {
            return Err(format!(
                "[{}, {}] reaches outside the record: {}; give a window within it",
                crate::show(start),
                crate::show(end),
                span()
            ));
        }
        self.window(start, end).ok_or_else(|| {
            format!(
                "expected start < end holding at least two samples of the record ({})",
                span()
            )
        })
    }

    /// This record as the ground motion of a run: multiplied by `scale`, followed by `tail`
    /// seconds of free vibration.
    pub fn forcing(&self, scale: f64, tail: f64) -> crate::physics::model::Forcing<'_> {
        crate::physics::model::Forcing {
            accel: &self.accel,
            dt: self.dt,
            t0: self.t0,
            scale,
            tail,
        }
    }

    /// Factor that scales this record to the target PGA (m/s^2).
    pub fn scale_to_pga(&self, target: f64) -> Result<f64, RecordError> {
        let pga = self.pga().value;
        if pga <= 0.0 {
            return Err(RecordError::Invalid {
                path: PathBuf::from(&self.name),
                message: "record is all zeros: it cannot be scaled to a target PGA".into(),
            });
        }
        Ok(target / pga)
    }
}

/// Errors from reading or generating records. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error("{}: cannot read: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
}

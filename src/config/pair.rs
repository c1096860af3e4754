//! A pair's config as written: `[building1]` and `[building2]`, one storey each.

use crate::config::axis::Axis;
use crate::config::sections::{RawContact, RawIntensity, RawRecord, RawRun, RawSample};
use serde::Deserialize;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBuilding {
    /// Each may be left out when `[[sample.axis]]` samples it.
    pub mass_kg: Option<Axis>,
    pub period_s: Option<Axis>,
    pub damping_ratio: Option<Axis>,
}

/// A config file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawConfig {
    #[serde(default)]
    pub run: RawRun,
    pub building1: RawBuilding,
    pub building2: RawBuilding,
    /// Required by a sweep; a gap study leaves the contact out ([`load_text_for_gaps`]).
    pub contact: Option<RawContact>,
    #[serde(rename = "record", default)]
    pub records: Vec<RawRecord>,
    #[serde(default)]
    pub intensity: RawIntensity,
    pub sample: Option<RawSample>,
}

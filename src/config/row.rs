//! A row's config as written: `[[building]]` entries, left to right, of 1..N storeys each,
//! and `[levels]`.

use crate::config::axis::{Axis, RangeSpec};
use crate::config::forms::{elements, forms};
use crate::config::sections::{RawContact, RawIntensity, RawRecord, RawRun, RawSample};
use serde::Deserialize;

/// One value for every storey, or one per storey (bottom to top).
#[derive(Debug, Clone, PartialEq)]
pub enum PerStorey {
    One(f64),
    Each(Vec<f64>),
}

forms!(PerStorey, "a number (every storey) or a list of numbers (one per storey, bottom to top)", {
    number: Some(PerStorey::One),
    text: None,
    list: Some(|s| elements(s).map(PerStorey::Each)),
    table: None,
});
/// `[levels]` as written: which contact levels a row has.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLevels {
    /// Floors this close are one floor/floor level, m (default 0.01).
    pub same_level_m: Option<f64>,
    /// A floor that faces a neighbour's storey strikes its columns (default true).
    pub floor_column: Option<bool>,
}

/// A storey stability coefficient `P/(k h)` above which a sweep warns before any run: up to it
/// One `[[building]]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawShearBuilding {
    pub storeys: usize,
    pub storey_height_m: PerStorey,
    /// Every floor's mass (an axis), or `floor_masses_kg`.
    pub mass_kg: Option<Axis>,
    pub floor_masses_kg: Option<Vec<f64>>,
    /// Relative storey stiffnesses, bottom to top (default uniform), scaled to `period_s`.
    pub stiffness_profile: Option<Vec<f64>>,
    /// May be left out when sampled, as may `mass_kg`.
    pub period_s: Option<Axis>,
    pub damping_ratio: Option<Axis>,
    /// `rayleigh` (the ratio on modes 1 and 2, the default) or `modal` (on every mode).
    pub damping: Option<String>,
    /// The gap to the next building (default `contact.gap_m`).
    pub gap_right_m: Option<Axis>,
    /// Yielding storeys (physics.md section 8): one of `yield_drift_ratio` (`F_y = k theta_y
    /// h`), `yield_force_n` (per storey) or `yield_base_shear_coefficient` (`C_y`: base shear
    /// strength `C_y W`, `W` the weight, storey strengths from `yield_shear_distribution`);
    /// `post_yield_ratio` (`b`, default 0: elastic-perfectly-plastic). Absent: elastic.
    pub yield_drift_ratio: Option<YieldDrift>,
    pub yield_force_n: Option<PerStorey>,
    pub yield_base_shear_coefficient: Option<Axis>,
    /// `inverted_triangular` (lateral forces `~ m_i z_i`, the default) or `uniform` (`~ m_i`).
    pub yield_shear_distribution: Option<String>,
    pub post_yield_ratio: Option<PerStorey>,
    /// The storeys' hysteresis (physics.md section 13): `bilinear` (the default),
    /// `imk_bilinear` or `imk_peak_oriented` (capped, deteriorating: the keys below).
    pub hysteresis: Option<String>,
    /// IMK storeys, per storey in drift ratios: `theta_p` (yield to capping) and `theta_pc`
    /// (capping to zero strength), both required; `kappa` (residual strength over the yield
    /// strength, default 0); `theta_u` (no strength beyond it; absent: none); `gamma` (energy
    /// capacity `E_t = gamma F_y theta_y h`; absent: no cyclic deterioration).
    pub plastic_drift_ratio: Option<StoreyValues>,
    pub post_capping_drift_ratio: Option<StoreyValues>,
    pub residual_strength_ratio: Option<StoreyValues>,
    pub ultimate_drift_ratio: Option<StoreyValues>,
    pub energy_capacity_ratio: Option<StoreyValues>,
    /// Which stiffness the Rayleigh or modal damping is built on: `initial` (the only choice;
    /// tangent-stiffness damping can create spurious damping forces after yielding).
    pub damping_stiffness: Option<String>,
    /// P-Delta (physics.md section 10): storey `j`'s force gains `-P_j d_j / h_j`.
    pub p_delta: Option<bool>,
    /// With `p_delta`: floor `j` carries the gravity load `g m_j gravity_mass_ratio` (default
    /// 1; 2 or 3 where a leaning column carries gravity the frame does not resist).
    pub gravity_mass_ratio: Option<f64>,
    /// The share `alpha` (0 < alpha <= 1) of each storey's stiffness and strength that the
    /// columns a neighbour's slab can strike carry (physics.md section 11): their local
    /// flexibility at the struck point acts in series with the contact.
    pub struck_column_share: Option<f64>,
}

/// `yield_drift_ratio` as written: one value for every storey, one per storey, or a range
/// table (`{ from, to, n }`): an axis of values each for every storey.
#[derive(Debug, Clone, PartialEq)]
pub enum YieldDrift {
    One(f64),
    Each(Vec<f64>),
    Axis(RangeSpec),
}

forms!(YieldDrift, "a drift ratio (every storey), a list of them (one per storey, bottom to top), or a range table { from, to, n } / { from, to, step } (an axis of values each for every storey)", {
    number: Some(YieldDrift::One),
    text: None,
    list: Some(|s| elements(s).map(YieldDrift::Each)),
    table: Some(|m| {
        RangeSpec::deserialize(serde::de::value::MapAccessDeserializer::new(m))
            .map(YieldDrift::Axis)
    }),
});

/// A storey value as written: one value for every storey, one per storey, or a range table
/// (`{ from, to, n }`): an axis of values each for every storey.
#[derive(Debug, Clone, PartialEq)]
pub enum StoreyValues {
    One(f64),
    Each(Vec<f64>),
    Axis(RangeSpec),
}

forms!(StoreyValues, "a number (every storey), a list of numbers (one per storey, bottom to top), or a range table { from, to, n } / { from, to, step } (an axis of values each for every storey)", {
    number: Some(StoreyValues::One),
    text: None,
    list: Some(|s| elements(s).map(StoreyValues::Each)),
    table: Some(|m| {
        RangeSpec::deserialize(serde::de::value::MapAccessDeserializer::new(m))
            .map(StoreyValues::Axis)
    }),
});

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRowConfig {
    #[serde(default)]
    pub run: RawRun,
    pub building: Vec<RawShearBuilding>,
    /// May be left out for a building alone (nothing to touch).
    pub contact: Option<RawContact>,
    #[serde(rename = "record", default)]
    pub records: Vec<RawRecord>,
    #[serde(default)]
    pub intensity: RawIntensity,
    pub sample: Option<RawSample>,
    #[serde(default)]
    pub levels: RawLevels,
}

//! A row building's capped, deteriorating (IMK) storeys as the config gives them (physics.md
//! section 13): the keys, their bounds, and the values a run takes where a key is an axis.

use crate::physics::shear::{Deterioration, ImkRule};
use crate::plan::axes::Check;

/// `hysteresis`: the storeys' rule, None for `bilinear` (today's storey).
pub fn hysteresis(word: &str) -> Option<Option<ImkRule>> {
    match word {
        "bilinear" => Some(None),
        "imk_bilinear" => Some(Some(ImkRule::Bilinear)),
        "imk_peak_oriented" => Some(Some(ImkRule::PeakOriented)),
        _ => None,
    }
}

/// The words `hysteresis` takes, for its error.
pub const HYSTERESIS_WORDS: &str = "bilinear (the default), imk_bilinear or imk_peak_oriented";

/// A key of an IMK storey: each takes one value for every storey, one per storey, or an axis
/// (a range table: each run gives every storey one value).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImkKey {
    /// `theta_p`, yield to capping.
    Plastic,
    /// `theta_pc`, capping to zero strength.
    PostCapping,
    /// `kappa`, residual strength over the yield strength.
    Residual,
    /// `theta_u`, the ultimate drift ratio.
    Ultimate,
    /// `gamma`, the energy capacity ratio.
    Energy,
}

impl ImkKey {
    /// Every key, in the order the config lists them (and their columns follow).
    pub const ALL: [ImkKey; 5] = [
        ImkKey::Plastic,
        ImkKey::PostCapping,
        ImkKey::Residual,
        ImkKey::Ultimate,
        ImkKey::Energy,
    ];

    /// The config key (and the parameter column's suffix where it is an axis).
    pub fn key(self) -> &'static str {
        match self {
            ImkKey::Plastic => "plastic_drift_ratio",
            ImkKey::PostCapping => "post_capping_drift_ratio",
            ImkKey::Residual => "residual_strength_ratio",
            ImkKey::Ultimate => "ultimate_drift_ratio",
            ImkKey::Energy => "energy_capacity_ratio",
        }
    }

    /// What each value must be (the ultimate drift's capping bound is checked on its own).
    pub(crate) fn check(self) -> Check {
        match self {
            ImkKey::Plastic | ImkKey::PostCapping | ImkKey::Ultimate => {
                (|x| x > 0.0 && x.is_finite(), "a drift ratio > 0")
            }
            ImkKey::Residual => (
                |x| (0.0..1.0).contains(&x),
                "a ratio >= 0 and < 1 (residual strength over the yield strength)",
            ),
            ImkKey::Energy => (
                |x| x > 0.0 && x.is_finite(),
                "a ratio > 0 (energy capacity E_t = gamma F_y theta_y h)",
            ),
        }
    }

    /// Set every storey of `d` to `v`.
    fn set(self, d: &mut Deterioration, v: f64) {
        let n = d.plastic.len();
        match self {
            ImkKey::Plastic => d.plastic = vec![v; n],
            ImkKey::PostCapping => d.post_capping = vec![v; n],
            ImkKey::Residual => d.residual = vec![v; n],
            ImkKey::Ultimate => d.ultimate = vec![v; n],
            ImkKey::Energy => d.energy = Some(vec![v; n]),
        }
    }
}

/// A building's IMK storeys as the config gives them.
#[derive(Debug, Clone, PartialEq)]
pub struct ImkSpec {
    /// The storeys' parameters, each axis at its first value.
    pub deterioration: Deterioration,
    /// The keys given as an axis, in [`ImkKey::ALL`] order, with their values: a run's value
    /// ([`crate::plan::row::RowRunSpec::imk_value`]) goes to every storey.
    pub axes: Vec<(ImkKey, Vec<f64>)>,
}

impl ImkSpec {
    /// The storeys of a run whose axes take `values` (one per axis, in order).
    pub fn of(&self, values: &[f64]) -> Deterioration {
        let mut d = self.deterioration.clone();
        for ((k, _), &v) in self.axes.iter().zip(values) {
            k.set(&mut d, v);
        }
        d
    }
}

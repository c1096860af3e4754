//! The parameters of a row that `[sample]` can set ([`RowSampled`]): their keys, their
//! checks, and which move the buildings.

use crate::plan::axes::{Check, DAMPING, GAP, PERIOD, POSITIVE};
use crate::plan::deterioration::ImkKey;

/// A yield drift ratio: > 0 and at most 0.2.
pub(crate) const YIELD_DRIFT: Check = (|x| x > 0.0 && x <= 0.2, "a drift ratio > 0 and <= 0.2");
/// A base-shear coefficient (base shear strength over weight): > 0 and at most 10.
pub(crate) const YIELD_SHEAR: Check = (
    |x| x > 0.0 && x <= 10.0,
    "a coefficient > 0 and <= 10 (base shear strength / weight)",
);

/// A parameter of a row that `[sample]` can set (buildings numbered from 0, as in the keys).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowSampled {
    /// `building[b].mass_kg`: every floor of building `b`.
    Mass(usize),
    /// `building[b].period_s`.
    Period(usize),
    /// `building[b].damping_ratio`.
    Damping(usize),
    /// `building[b].gap_right_m`: the gap between buildings `b` and `b + 1`.
    Gap(usize),
    /// `contact.gap_m`: every gap not given per building.
    SharedGap,
    /// `contact.k_n_per_m`, for linear laws.
    KLinear,
    /// `contact.beta_n_per_m1_5`, for Hertz-type laws.
    Beta,
    /// `building[b].yield_drift_ratio`: every storey's yield drift ratio.
    YieldDrift(usize),
    /// `building[b].yield_base_shear_coefficient`.
    YieldShear(usize),
    /// `building[b].<IMK key>`: every IMK storey's value of the key.
    Imk(usize, ImkKey),
}

impl RowSampled {
    /// The config key.
    pub fn key(self) -> String {
        match self {
            RowSampled::Mass(b) => format!("building[{b}].mass_kg"),
            RowSampled::Period(b) => format!("building[{b}].period_s"),
            RowSampled::Damping(b) => format!("building[{b}].damping_ratio"),
            RowSampled::Gap(b) => format!("building[{b}].gap_right_m"),
            RowSampled::SharedGap => "contact.gap_m".into(),
            RowSampled::KLinear => "contact.k_n_per_m".into(),
            RowSampled::Beta => "contact.beta_n_per_m1_5".into(),
            RowSampled::YieldDrift(b) => format!("building[{b}].yield_drift_ratio"),
            RowSampled::YieldShear(b) => format!("building[{b}].yield_base_shear_coefficient"),
            RowSampled::Imk(b, k) => format!("building[{b}].{}", k.key()),
        }
    }

    /// Every key of a row of `nb` buildings.
    pub(crate) fn all(nb: usize) -> Vec<RowSampled> {
        let mut all: Vec<RowSampled> = (0..nb)
            .flat_map(|b| [Self::Mass(b), Self::Period(b), Self::Damping(b)])
            .collect();
        all.extend((0..nb - 1).map(Self::Gap));
        all.extend([Self::SharedGap, Self::KLinear, Self::Beta]);
        all.extend((0..nb).flat_map(|b| [Self::YieldDrift(b), Self::YieldShear(b)]));
        all.extend((0..nb).flat_map(|b| ImkKey::ALL.map(|k| Self::Imk(b, k))));
        all
    }

    /// What a drawn value must be.
    pub(crate) fn check(self) -> Check {
        match self {
            RowSampled::Period(_) => PERIOD,
            RowSampled::Damping(_) => DAMPING,
            RowSampled::Gap(_) | RowSampled::SharedGap => GAP,
            RowSampled::YieldDrift(_) => YIELD_DRIFT,
            RowSampled::YieldShear(_) => YIELD_SHEAR,
            RowSampled::Imk(_, k) => k.check(),
            _ => POSITIVE,
        }
    }
}

impl RowSampled {
    /// Does it set a building's mass, period or damping?
    pub fn moves_buildings(self) -> bool {
        matches!(
            self,
            RowSampled::Mass(_)
                | RowSampled::Period(_)
                | RowSampled::Damping(_)
                | RowSampled::YieldDrift(_)
                | RowSampled::YieldShear(_)
                | RowSampled::Imk(..)
        )
    }
}

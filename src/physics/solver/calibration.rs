//! What accuracy setting a stated error needs (`--target-error`): the fast scheme's measured
//! 99th-percentile relative peak-force error against the reference, per setting, on the
//! accuracy suite (`configs/accuracy.toml`, 1,440 runs: every law, formula, e and gap, three
//! record types). Each value is the largest over the CPU (f64) and GPU (f32 and f64, lavapipe)
//! paths, from
//! `pound accuracy --backend gpu --settings 8,12,16,24,32,48,64,96,128,192,256,384,512`
//! (BENCHMARKS.md, "Choosing the setting from the error"). A suite of other scenes can
//! differ: `pound accuracy --target-error` checks a choice on any config.

/// `(substeps per contact, p99 relative peak-force error)`, increasing in substeps.
pub const PEAK_FORCE_P99: &[(f64, f64)] = &[
    (8.0, 1.92e-2),
    (12.0, 1.02e-2),
    (16.0, 5.47e-3),
    (24.0, 2.87e-3),
    (32.0, 2.25e-3),
    (48.0, 1.27e-3),
    (64.0, 8.45e-4),
    (96.0, 4.85e-4),
    (128.0, 3.27e-4),
    (192.0, 2.20e-4),
    (256.0, 1.65e-4),
    (384.0, 9.34e-5),
    (512.0, 6.47e-5),
];

/// The same for rows of multi-storey buildings: the p99 relative peak-force error of the row
/// fast scheme against the row reference on `configs/accuracy-rows.toml` (140 runs: four laws,
/// two `e`, 2 x 2 periods, five gaps; a 3-storey beside a 6-storey building with a soft first
/// storey), CPU (f64, the 6-storey building's substeps in floor coordinates), rounded up to
/// three digits, from
/// `pound accuracy configs/accuracy-rows.toml --settings 8,12,16,24,32,48,64,96,128,192,256,384,512`
/// (BENCHMARKS.md).
pub const ROW_PEAK_FORCE_P99: &[(f64, f64)] = &[
    (8.0, 4.62e-3),
    (12.0, 4.04e-3),
    (16.0, 1.30e-3),
    (24.0, 8.26e-4),
    (32.0, 6.49e-4),
    (48.0, 4.20e-4),
    (64.0, 2.76e-4),
    (96.0, 1.96e-4),
    (128.0, 1.03e-4),
    (192.0, 6.29e-5),
    (256.0, 6.24e-5),
    (384.0, 3.69e-5),
    (512.0, 2.10e-5),
];

/// Which suite a calibration comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Suite {
    /// Pairs of oscillators: [`PEAK_FORCE_P99`].
    Pairs,
    /// Rows of multi-storey buildings: [`ROW_PEAK_FORCE_P99`].
    Rows,
}

impl Suite {
    pub fn table(self) -> &'static [(f64, f64)] {
        match self {
            Suite::Pairs => PEAK_FORCE_P99,
            Suite::Rows => ROW_PEAK_FORCE_P99,
        }
    }

    /// The config the table was measured on.
    pub fn config(self) -> &'static str {
        match self {
            Suite::Pairs => "configs/accuracy.toml",
            Suite::Rows => "configs/accuracy-rows.toml",
        }
    }
}

/// The setting chosen for a target error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    pub target: f64,
    pub substeps_per_contact: f64,
    /// Its calibrated p99 peak-force error (at most `target`).
    pub calibrated_p99: f64,
}

/// The cheapest calibrated setting whose p99 peak-force error is at most `target`; `Err` with
/// the smallest calibrated error when none is.
pub fn for_target(target: f64) -> Result<Choice, f64> {
    for_target_in(Suite::Pairs, target)
}

/// [`for_target`] from `suite`'s table.
pub fn for_target_in(suite: Suite, target: f64) -> Result<Choice, f64> {
    let table = suite.table();
    table
        .iter()
        .find(|&&(_, e)| e <= target)
        .map(|&(s, e)| Choice {
            target,
            substeps_per_contact: s,
            calibrated_p99: e,
        })
        .ok_or(table[table.len() - 1].1)
}

/// The calibrated p99 peak-force error of a setting (None between or beyond the calibrated
/// ones).
pub fn calibrated_p99(substeps_per_contact: f64) -> Option<f64> {
    PEAK_FORCE_P99
        .iter()
        .find(|&&(s, _)| s == substeps_per_contact)
        .map(|&(_, e)| e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cheapest_setting_that_meets_the_target_is_chosen() {
        let c = for_target(1e-2).unwrap();
        assert_eq!(c.substeps_per_contact, 16.0);
        assert!(c.calibrated_p99 <= 1e-2);
        assert_eq!(for_target(1e-3).unwrap().substeps_per_contact, 64.0);
        assert_eq!(for_target(1e-4).unwrap().substeps_per_contact, 384.0);
        assert_eq!(for_target(1.0).unwrap().substeps_per_contact, 8.0);
        assert_eq!(for_target(1e-5), Err(6.47e-5));
        // More substeps never cost accuracy in the table (the choice is monotone).
        assert!(PEAK_FORCE_P99
            .windows(2)
            .all(|w| w[0].0 < w[1].0 && w[0].1 > w[1].1));
        assert_eq!(calibrated_p99(64.0), Some(8.45e-4));
        assert_eq!(calibrated_p99(65.0), None);
    }

    #[test]
    fn rows_choose_from_their_own_table() {
        assert!(ROW_PEAK_FORCE_P99
            .windows(2)
            .all(|w| w[0].0 < w[1].0 && w[0].1 > w[1].1));
        let c = for_target_in(Suite::Rows, 1e-3).unwrap();
        assert_eq!((c.substeps_per_contact, c.calibrated_p99), (24.0, 8.26e-4));
        assert_eq!(
            for_target_in(Suite::Rows, 1e-2)
                .unwrap()
                .substeps_per_contact,
            8.0
        );
        assert_eq!(for_target_in(Suite::Rows, 1e-5), Err(2.10e-5));
    }
}

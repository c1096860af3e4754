//! The seed paper's cheap checks (`pound paper`, docs/paper-reproduction.md): Table 1 (e from
//! the drop heights) and Fig. 2 (the formulas' zeta(e), and where each crosses zeta = 1).

use crate::physics::restitution::{Formula, RestitutionError};
use crate::record::G;

/// One drop of Table 1: heights before and after (m) and the velocities the seed lists (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drop {
    pub h_before: f64,
    pub h_after: f64,
    pub v_before_stated: f64,
    pub v_after_stated: f64,
}

impl Drop {
    /// Free fall: `v = sqrt(2 g h)`.
    pub fn v_before(&self) -> f64 {
        (2.0 * G * self.h_before).sqrt()
    }
    pub fn v_after(&self) -> f64 {
        (2.0 * G * self.h_after).sqrt()
    }
    /// `e = sqrt(H_after / H_before)` (= v_after / v_before).
    pub fn e(&self) -> f64 {
        (self.h_after / self.h_before).sqrt()
    }
}

/// The seed's Table 1, as printed.
pub const TABLE1: [Drop; 6] = [
    drop(0.5, 0.26, 3.13, 2.23),
    drop(1.0, 0.5, 4.43, 3.15),
    drop(1.5, 0.76, 5.43, 3.86),
    drop(2.0, 1.01, 6.26, 4.46),
    drop(2.5, 1.27, 7.00, 5.00),
    drop(3.0, 1.52, 7.67, 5.46),
];

const fn drop(h_before: f64, h_after: f64, v_before_stated: f64, v_after_stated: f64) -> Drop {
    Drop {
        h_before,
        h_after,
        v_before_stated,
        v_after_stated,
    }
}

/// Mean `e` over Table 1 (the seed: "approximately 0.71").
pub fn table1_mean_e() -> f64 {
    TABLE1.iter().map(Drop::e).sum::<f64>() / TABLE1.len() as f64
}

/// One formula's Fig. 2 facts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curve {
    pub formula: Formula,
    pub zeta_at_0_1: f64,
    pub zeta_at_0_33: f64,
    /// The `e` where `zeta(e) = 1` (zeta <= 1 above it); None if zeta < 1 on all of [0.01, 1].
    pub e_at_zeta_1: Option<f64>,
}

/// Fig. 2's facts for every printed formula.
pub fn fig2() -> Result<Vec<Curve>, RestitutionError> {
    Formula::ALL
        .into_iter()
        .filter(|f| *f != Formula::Exact)
        .map(|f| {
            let z = |e: f64| -> Result<f64, RestitutionError> { Ok(f.zeta(e)?.unwrap_or(0.0)) };
            // Every printed zeta(e) falls with e: bisect for zeta = 1.
            let e_at_zeta_1 = if z(0.01)? < 1.0 {
                None
            } else {
                let (mut lo, mut hi) = (0.01, 1.0);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if z(mid)? > 1.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                Some(0.5 * (lo + hi))
            };
            Ok(Curve {
                formula: f,
                zeta_at_0_1: z(0.1)?,
                zeta_at_0_33: z(0.33)?,
                e_at_zeta_1,
            })
        })
        .collect()
}

/// Both checks as markdown tables.
pub fn report() -> Result<String, RestitutionError> {
    let mut s = String::from(
        "Table 1: e from the drop heights (v = sqrt(2 g H), e = sqrt(H_after / H_before))\n\n\
         | H before (m) | H after (m) | v before: stated / sqrt(2gH) | v after: stated / sqrt(2gH) | e |\n\
         |---:|---:|---|---|---:|\n",
    );
    for d in TABLE1 {
        s.push_str(&format!(
            "| {} | {} | {:.2} / {:.3} | {:.2} / {:.3} | {:.4} |\n",
            d.h_before,
            d.h_after,
            d.v_before_stated,
            d.v_before(),
            d.v_after_stated,
            d.v_after(),
            d.e()
        ));
    }
    s.push_str(&format!("\nmean e = {:.4}\n", table1_mean_e()));
    s.push_str(
        "\nFig. 2: zeta(e) of each printed formula\n\n\
         | formula | zeta(0.1) | zeta(0.33) | zeta <= 1 for e above |\n|---|---:|---:|---:|\n",
    );
    for c in fig2()? {
        s.push_str(&format!(
            "| {} | {:.4} | {:.4} | {} |\n",
            c.formula.key(),
            c.zeta_at_0_1,
            c.zeta_at_0_33,
            c.e_at_zeta_1
                .map_or("every e".to_string(), |e| format!("{e:.4}"))
        ));
    }
    Ok(s)
}

//! `pound formulas`: the impact damping `zeta(e)` of every printed formula, and the `exact`
//! damping of every damped law, as a table and as the seed's Fig. 2.

use crate::physics::contact::LawKind;
use crate::physics::restitution::{exact_damping, Formula, RestitutionError};
use crate::studies::plot::{Panel, Series};

/// The laws whose `exact` zeta the table lists (Hunt-Crossley's `a` comes last, apart).
pub const EXACT_LAWS: [LawKind; 4] = [
    LawKind::KelvinVoigt,
    LawKind::KelvinVoigtNoTension,
    LawKind::ModifiedLinear,
    LawKind::NonlinearViscoelastic,
];

/// The header and one row per `e`: every printed formula's zeta, the exact zeta of each law in
/// [`EXACT_LAWS`], and Hunt-Crossley's exact `a` (6 decimals).
pub fn table(es: &[f64]) -> Result<Vec<Vec<String>>, RestitutionError> {
    let printed = || Formula::ALL.iter().filter(|f| **f != Formula::Exact);
    let mut head: Vec<String> = vec!["e".into()];
    head.extend(printed().map(|f| f.key().to_string()));
    head.extend(EXACT_LAWS.iter().map(|l| format!("exact:{}", l.key())));
    head.push("exact_a:hunt_crossley".into());
    let mut rows = vec![head];
    for &e in es {
        let mut row = vec![format!("{e}")];
        for f in printed() {
            let z = f.zeta(e)?.expect("printed formula");
            row.push(format!("{z:.6}"));
        }
        for l in EXACT_LAWS
            .iter()
            .copied()
            .chain([LawKind::HuntCrossleyExact])
        {
            row.push(format!("{:.6}", exact_damping(l, e)?));
        }
        rows.push(row);
    }
    Ok(rows)
}

/// `zeta(e)` of every printed formula and the exact damping of the seed's law (nonlinear
/// viscoelastic) over `es`, the seed's Fig. 2: one panel on a linear axis, one on a log axis
/// (the formulas span four decades at small e).
pub fn zeta_panels(es: &[f64]) -> Result<Vec<Panel>, RestitutionError> {
    let mut series = Vec::new();
    for f in Formula::ALL {
        let points = es
            .iter()
            .map(|&e| {
                let z = match f.zeta(e)? {
                    Some(z) => z,
                    None => exact_damping(LawKind::NonlinearViscoelastic, e)?,
                };
                Ok((e, z))
            })
            .collect::<Result<Vec<_>, RestitutionError>>()?;
        let name = match f {
            Formula::Exact => "exact (nonlinear viscoelastic)".to_string(),
            _ => f.key().to_string(),
        };
        series.push(Series {
            name,
            points,
            scatter: false,
            style: None,
        });
    }
    let panel = |log_y: bool| Panel {
        title: "impact damping ratio against e".into(),
        x_label: "e".into(),
        y_label: "zeta".into(),
        log_x: false,
        log_y,
        series: series.clone(),
        y_span: None,
        ..Default::default()
    };
    Ok(vec![panel(false), panel(true)])
}

//! Axis labels and their units: engineering units for the values drawn, and a label the user
//! asks for that rescales the data to its unit.

use super::panel::Panel;

/// An axis label in engineering units for values up to `biggest`, and the factor that takes
/// the values there: `(N)` to kN or MN, `(J)` to kJ or MJ, `(N/m)` to kN/m or MN/m, `(m)` below
/// a metre to mm, a drift ratio `(m/m)` to %. Log axes keep their unit (their ticks are powers
/// of ten).
pub(super) fn engineering(label: &str, biggest: f64, log: bool) -> (String, f64) {
    const LARGE: [(&str, [(&str, f64); 2]); 3] = [
        ("(N)", [("(MN)", 1e6), ("(kN)", 1e3)]),
        ("(J)", [("(MJ)", 1e6), ("(kJ)", 1e3)]),
        ("(N/m)", [("(MN/m)", 1e6), ("(kN/m)", 1e3)]),
    ];
    if log || biggest == 0.0 {
        return (label.to_string(), 1.0);
    }
    for (unit, scaled) in LARGE {
        if let Some(stem) = label.strip_suffix(unit) {
            for (to, f) in scaled {
                if biggest >= f {
                    return (format!("{stem}{to}"), 1.0 / f);
                }
            }
        }
    }
    if let Some(stem) = label.strip_suffix("(m/m)") {
        return (format!("{stem}(%)"), 1e2);
    }
    match label.strip_suffix("(m)") {
        Some(stem) if biggest < 1.0 => (format!("{stem}(mm)"), 1e3),
        _ => (label.to_string(), 1.0),
    }
}

/// The units a label may name that are multiples of one another, each with its family (the
/// unit the rest are multiples of) and its size in that unit.
const SCALED_UNITS: [(&str, &str, f64); 16] = [
    ("N", "N", 1.0),
    ("kN", "N", 1e3),
    ("MN", "N", 1e6),
    ("J", "J", 1.0),
    ("kJ", "J", 1e3),
    ("MJ", "J", 1e6),
    ("N/m", "N/m", 1.0),
    ("kN/m", "N/m", 1e3),
    ("MN/m", "N/m", 1e6),
    ("m", "m", 1.0),
    ("cm", "m", 1e-2),
    ("mm", "m", 1e-3),
    ("m/m", "m/m", 1.0),
    ("%", "m/m", 1e-2),
    ("s", "s", 1.0),
    ("ms", "s", 1e-3),
];

/// Units a label may name that are taken as they are (no other unit is a multiple of them).
const OTHER_UNITS: [&str; 5] = ["g", "kg", "m/s", "m/s^2", "N/m^1.5"];

/// The unit in parentheses that ends `label`, where it is one of the units above (`peak force
/// (N)` -> `N`); None for none, or for words in parentheses (`T2 / T1 (fundamental periods)`).
pub fn unit_of(label: &str) -> Option<&str> {
    let inner = label.trim_end().strip_suffix(')')?;
    let unit = inner[inner.rfind('(')? + 1..].trim();
    let known = SCALED_UNITS.iter().any(|u| u.0 == unit) || OTHER_UNITS.contains(&unit);
    known.then_some(unit)
}

/// The factor that takes values of the quantity labelled `quantity` to the unit the label
/// `asked` names (`peak force (N)`, `Force (kN)` -> 1e-3); 1 where `asked` names no unit. Err:
/// why they disagree (a unit of another quantity, a unit on a quantity that has none, or a
/// unit this does not know).
pub fn rescale(quantity: &str, asked: &str) -> Result<f64, String> {
    let words = |l: &str| {
        l.trim_end()
            .strip_suffix(')')
            .and_then(|i| i.rfind('(').map(|k| i[k + 1..].trim().to_string()))
    };
    let family = |u: &str| SCALED_UNITS.iter().find(|s| s.0 == u).map(|s| (s.1, s.2));
    let alike = |q: &str| -> String {
        match family(q) {
            Some((f, _)) => SCALED_UNITS
                .iter()
                .filter(|s| s.1 == f)
                .map(|s| s.0)
                .collect::<Vec<_>>()
                .join(", "),
            None => q.to_string(),
        }
    };
    match (unit_of(quantity), unit_of(asked), words(asked)) {
        (None, Some(a), _) => Err(format!(
            "({a}) is a unit, but the axis holds {quantity}, which has none"
        )),
        (None, None, _) | (Some(_), None, None) => Ok(1.0),
        (Some(q), None, Some(w)) => Err(format!(
            "`{w}` is not a unit the figure knows; the axis holds {quantity}: write its unit as {}",
            alike(q)
        )),
        (Some(q), Some(a), _) if q == a => Ok(1.0),
        (Some(q), Some(a), _) => match (family(q), family(a)) {
            (Some((fq, sq)), Some((fa, sa))) if fq == fa => Ok(sq / sa),
            _ => Err(format!(
                "({a}) is not a unit of {quantity}: write its unit as {}",
                alike(q)
            )),
        },
    }
}

/// Which axis a label is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
}

/// Give `panels` the axis label `asked`, each panel's values on that axis scaled to the unit
/// it names (`Force (kN)` on forces in N divides them by 1000). One panel takes it, or the
/// reason it does not fit. Of several, a label that names a unit goes to the panels whose
/// quantity is in that unit or a multiple of it (others keep theirs); one that names none goes
/// to every panel where all show quantities in one unit. Err: why no panel takes it.
pub fn relabel(panels: &mut [Panel], axis: Axis, asked: &str) -> Result<(), String> {
    let current = |p: &Panel| match axis {
        Axis::X => p.x_label.clone(),
        Axis::Y => p.y_label.clone(),
    };
    let set = |p: &mut Panel, f: f64| {
        let scale = |q: &mut (f64, f64)| match axis {
            Axis::X => q.0 *= f,
            Axis::Y => q.1 *= f,
        };
        p.series
            .iter_mut()
            .flat_map(|s| &mut s.points)
            .for_each(scale);
        p.notes.collapsed.iter_mut().for_each(|(_, q)| scale(q));
        if axis == Axis::X {
            p.notes.x_marks.iter_mut().for_each(|(x, _)| *x *= f);
        }
        match axis {
            Axis::X => p.x_label = asked.to_string(),
            Axis::Y => p.y_label = asked.to_string(),
        }
    };
    if let [only] = panels {
        let f = rescale(&current(only), asked)?;
        set(only, f);
        return Ok(());
    }
    // The panels' quantities, each once, for the messages.
    let mut held: Vec<String> = Vec::new();
    for p in panels.iter() {
        let l = current(p);
        let u = unit_of(&l).map_or_else(|| format!("`{l}`"), |u| format!("({u})"));
        if !held.contains(&u) {
            held.push(u);
        }
    }
    let fits: Vec<Option<f64>> = panels
        .iter()
        .map(|p| {
            let l = current(p);
            match (unit_of(asked), unit_of(&l)) {
                (Some(_), Some(_)) => rescale(&l, asked).ok(),
                (Some(_), None) => None,
                // No unit asked: every panel, where they hold one kind of quantity.
                (None, _) if held.len() == 1 => rescale(&l, asked).ok(),
                (None, _) => None,
            }
        })
        .collect();
    if fits.iter().all(Option::is_none) {
        return Err(match unit_of(asked) {
            Some(_) => format!(
                "its unit fits none of the panels, whose axes hold {}",
                held.join(", ")
            ),
            None => format!(
                "it names no unit, and the panels' axes hold {}: end it with a unit in parentheses, e.g. `{asked} (N)`, and it goes to the panels in that unit",
                held.join(", ")
            ),
        });
    }
    for (p, f) in panels.iter_mut().zip(fits) {
        if let Some(f) = f {
            set(p, f);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::plot::panel::Series;

    #[test]
    fn labels_scale_the_data_to_their_unit_or_are_refused() {
        assert_eq!(rescale("peak force (N)", "Force (kN)"), Ok(1e-3));
        assert_eq!(rescale("peak force (N)", "Force (MN)"), Ok(1e-6));
        assert_eq!(rescale("gap (mm)", "gap (m)"), Ok(1e-3));
        assert_eq!(rescale("drift (m/m)", "drift (%)"), Ok(1e2));
        assert_eq!(
            rescale("PGA (g)", "Peak ground acceleration, PGA (g)"),
            Ok(1.0)
        );
        assert_eq!(rescale("peak force (N)", "Peak force"), Ok(1.0));
        assert_eq!(rescale("impacts", "Number (of impacts)"), Ok(1.0));
        let no = |q: &str, a: &str| rescale(q, a).unwrap_err();
        assert!(no("peak force (N)", "Force (s)").contains("N, kN, MN"));
        assert!(no("peak force (N)", "Force (kip)").contains("`kip`"));
        assert!(no("probability of exceedance", "P (N)").contains("has none"));
        assert_eq!(unit_of("T2 / T1 (fundamental periods)"), None);
        // Several panels: a unit picks the panels it fits; none, all of one unit.
        let panel = |y: &str| Panel {
            y_label: y.into(),
            series: vec![Series {
                name: String::new(),
                points: vec![(1.0, 2000.0)],
                scatter: false,
                style: None,
            }],
            ..Panel::default()
        };
        let mut ps = vec![panel("displacement (m)"), panel("contact force (N)")];
        relabel(&mut ps, Axis::Y, "force (kN)").unwrap();
        assert_eq!(ps[0].y_label, "displacement (m)");
        assert_eq!(ps[0].series[0].points, [(1.0, 2000.0)]);
        assert_eq!(ps[1].y_label, "force (kN)");
        assert_eq!(ps[1].series[0].points, [(1.0, 2.0)]);
        // Again: the panel is in kN by now.
        relabel(&mut ps, Axis::Y, "force (kN)").unwrap();
        assert_eq!(ps[1].series[0].points, [(1.0, 2.0)]);
        assert!(relabel(&mut ps, Axis::Y, "force (s)").is_err());
        assert!(relabel(&mut ps, Axis::Y, "response").is_err());
        let mut same = vec![panel("force (N)"), panel("shear (N)")];
        relabel(&mut same, Axis::Y, "Force").unwrap();
        assert_eq!(same[1].y_label, "Force");
    }

    #[test]
    fn axes_take_engineering_units() {
        let e = |l: &str, m: f64, log: bool| engineering(l, m, log);
        assert_eq!(
            e("peak force (N)", 5.4e6, false),
            ("peak force (MN)".into(), 1e-6)
        );
        assert_eq!(
            e("peak force (N)", 5.4e4, false),
            ("peak force (kN)".into(), 1e-3)
        );
        assert_eq!(
            e("peak force (N)", 540.0, false),
            ("peak force (N)".into(), 1.0)
        );
        assert_eq!(e("gap (m)", 0.055, false), ("gap (mm)".into(), 1e3));
        assert_eq!(e("roof (m)", 1.5, false), ("roof (m)".into(), 1.0));
        assert_eq!(
            e("peak force (N)", 5.4e6, true),
            ("peak force (N)".into(), 1.0)
        );
        assert_eq!(
            e("beta (N/m^1.5)", 3e9, false),
            ("beta (N/m^1.5)".into(), 1.0)
        );
        // Drift ratios in %, as engineers read them (a log axis keeps the ratio).
        assert_eq!(e("drift (m/m)", 0.012, false), ("drift (%)".into(), 1e2));
        assert_eq!(e("drift (m/m)", 0.012, true), ("drift (m/m)".into(), 1.0));
    }
}

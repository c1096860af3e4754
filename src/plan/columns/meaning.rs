//! What every output column holds, in which unit, and its short name: one table for `pound
//! columns`, the docs and every plot's axis labels, legends and titles. A pair's columns are
//! named outright; a row's per-building (`b2_...`), per-gap (`gap_1_2_m`) and per-level
//! (`level_b1f3_b2f3_...`) columns by pattern.

/// A column's meaning, unit (`-` for counts, ratios and text; `m/m` for drift ratios, which
/// plots and legends show in %) and short name (`label`: an axis
/// label without its unit, a legend entry's name, a title's words).
#[derive(Debug, Clone, PartialEq)]
pub struct Meaning {
    pub unit: &'static str,
    pub label: String,
    pub text: String,
}

/// The columns of one run that do not depend on the scene: name, unit, short name, meaning.
const FIXED: [(&str, &str, &str, &str); 51] = [
    ("run", "-", "run", "run number"),
    ("law", "-", "contact law", "contact law"),
    (
        "formula",
        "-",
        "restitution formula",
        "restitution formula (empty where the law takes none)",
    ),
    (
        "e",
        "-",
        "coefficient of restitution",
        "coefficient of restitution (empty for elastic laws)",
    ),
    (
        "impact_damping",
        "-",
        "impact damping",
        "the damping used: zeta, or a in chi = a / v0 (Hunt-Crossley laws)",
    ),
    (
        "k_n_per_m",
        "N/m",
        "contact stiffness k",
        "contact stiffness of a linear law",
    ),
    (
        "beta_n_per_m1_5",
        "N/m^1.5",
        "contact stiffness beta",
        "contact stiffness of a Hertz-type law",
    ),
    ("record", "-", "record", "record label"),
    (
        "record_rsn",
        "-",
        "RSN",
        "the record's PEER record sequence number (a record set's search results)",
    ),
    (
        "record_component",
        "-",
        "component",
        "the record's component: H1, H2 (horizontal) or V (vertical)",
    ),
    ("record_event", "-", "event", "the record's earthquake, as its search names it"),
    ("record_magnitude", "-", "magnitude", "the earthquake's moment magnitude"),
    (
        "record_rjb_km",
        "km",
        "Rjb",
        "the station's Joyner-Boore distance to the rupture",
    ),
    (
        "record_rrup_km",
        "km",
        "Rrup",
        "the station's closest distance to the rupture",
    ),
    (
        "record_vs30_m_s",
        "m/s",
        "Vs30",
        "the station's time-averaged shear-wave speed over the top 30 m",
    ),
    (
        "target_pga_g",
        "g",
        "target PGA",
        "target PGA the record was scaled to (empty for other targets)",
    ),
    (
        "target_sa_g",
        "g",
        "target Sa(T)",
        "target Sa(T) the record was scaled to (empty for other targets)",
    ),
    (
        "sa_period_s",
        "s",
        "period of Sa(T)",
        "the period T of target_sa_g (the run's own where it follows a building)",
    ),
    (
        "target_sa_avg_g",
        "g",
        "target Sa_avg",
        "target Sa_avg the record was scaled to (empty for other targets)",
    ),
    (
        "sa_avg_from_s",
        "s",
        "shortest period of Sa_avg",
        "the shortest period of target_sa_avg_g",
    ),
    (
        "sa_avg_to_s",
        "s",
        "longest period of Sa_avg",
        "the longest period of target_sa_avg_g",
    ),
    (
        "scale_factor",
        "-",
        "scale factor",
        "factor applied to the record",
    ),
    ("pga_g", "g", "PGA", "PGA of the scaled record"),
    (
        "pgv_m_s",
        "m/s",
        "PGV",
        "PGV of the scaled record, whatever it was scaled to: the largest magnitude of the ground velocity, the integral of its acceleration from rest over the record as simulated (its window if any, not the free tail), the acceleration linear between samples (so the trapezoid rule is exact, and peaks between samples count), no baseline correction",
    ),
    (
        "arias_m_s",
        "m/s",
        "Arias intensity",
        "Arias intensity of the scaled record, pi / (2 g) * integral of ag^2 dt over the record as simulated (its window if any, not the free tail), the acceleration linear between samples and integrated exactly (it grows as the square of the scale factor)",
    ),
    (
        "cav_m_s",
        "m/s",
        "CAV",
        "cumulative absolute velocity of the scaled record, integral of abs(ag) dt over the record as simulated (its window if any, not the free tail), the acceleration linear between samples and integrated exactly (a step that changes sign split at its zero), no threshold",
    ),
    (
        "sa_t1_g",
        "g",
        "Sa(T1), building 1",
        "Sa(T1, 5 %) of the scaled record at building 1's period t1_s, whatever it was scaled to: pseudo-spectral acceleration (w^2 times the peak displacement) of a linear oscillator from rest, exact for the acceleration linear between samples, over the record as simulated (its window if any, not the free tail)",
    ),
    (
        "sa_t2_g",
        "g",
        "Sa(T2), building 2",
        "Sa(T2, 5 %) of the scaled record at building 2's period t2_s, whatever it was scaled to: pseudo-spectral acceleration (w^2 times the peak displacement) of a linear oscillator from rest, exact for the acceleration linear between samples, over the record as simulated (its window if any, not the free tail)",
    ),
    ("m1_kg", "kg", "mass, building 1", "mass of building 1"),
    ("t1_s", "s", "period, building 1", "period of building 1"),
    (
        "xi1",
        "-",
        "damping ratio, building 1",
        "damping ratio of building 1",
    ),
    ("m2_kg", "kg", "mass, building 2", "mass of building 2"),
    ("t2_s", "s", "period, building 2", "period of building 2"),
    (
        "xi2",
        "-",
        "damping ratio, building 2",
        "damping ratio of building 2",
    ),
    ("gap_m", "m", "gap", "gap between the buildings"),
    (
        "sample",
        "-",
        "sample",
        "the sample that set the sampled parameters (empty without [sample])",
    ),
    (
        "status",
        "-",
        "status",
        "ok; collapsed (rows with a collapse limit: a storey reached [run] collapse_drift_ratio, a result, not a failure); or a failure: non_finite (the state became NaN or infinite) or step_limit (the step budget ran out)",
    ),
    (
        "impacts",
        "-",
        "impacts",
        "number of impacts (summed over the contact levels)",
    ),
    ("peak_force_n", "N", "peak force", "largest pounding force"),
    (
        "peak_penetration_m",
        "m",
        "peak penetration",
        "largest penetration",
    ),
    (
        "peak_u1_m",
        "m",
        "peak displacement, building 1",
        "largest displacement of building 1 relative to the ground",
    ),
    (
        "peak_u2_m",
        "m",
        "peak displacement, building 2",
        "largest displacement of building 2 relative to the ground",
    ),
    (
        "impact_velocity_m_s",
        "m/s",
        "impact velocity",
        "approach speed v0 of the impact with the largest force",
    ),
    (
        "first_impact_s",
        "s",
        "first impact",
        "onset of the first impact (empty if none)",
    ),
    (
        "contact_time_s",
        "s",
        "contact time",
        "total time in contact",
    ),
    (
        "dissipated_energy_j",
        "J",
        "dissipated energy",
        "net work of the contact force on the relative motion",
    ),
    (
        "substeps",
        "-",
        "substeps",
        "integration work beyond the exact free steps (RK4 substeps or trial steps)",
    ),
    (
        "collapse_time_s",
        "s",
        "collapse time",
        "when a storey's drift ratio first reached the collapse limit in any building ([run] collapse_drift_ratio; the run's first collapse: that building left the scene, the others went on, each has its own bK_collapse_time_s; empty where no building collapsed)",
    ),
    (
        "collapse_building",
        "-",
        "collapsed building",
        "the building of that first collapse (from 1; empty where no building collapsed)",
    ),
    (
        "collapse_storey",
        "-",
        "collapsed storey",
        "the storey of that first collapse (from 1; empty where no building collapsed)",
    ),
    (
        "input_energy_j",
        "J",
        "input energy",
        "input work of the ground motion (with --energy or the reference scheme)",
    ),
];

/// The energy balance's last two columns.
const ENERGY: [(&str, &str, &str, &str); 2] = [
    (
        "damping_energy_j",
        "J",
        "damping energy",
        "structural damping work (with --energy or the reference scheme)",
    ),
    (
        "energy_residual",
        "-",
        "energy residual",
        "(input - kinetic - strain - damping - contact work) / largest input",
    ),
];

/// Per building `k`: suffix, unit, short name, meaning.
const PER_BUILDING: [(&str, &str, &str, &str); 29] = [
    ("sa_t1_g", "g", "Sa(T1), building {k}", "Sa(T1, 5 %) of the scaled record at building {k}'s fundamental period b{k}_t1_s, whatever it was scaled to: pseudo-spectral acceleration (w^2 times the peak displacement) of a linear oscillator from rest, exact for the acceleration linear between samples, over the record as simulated (its window if any, not the free tail)"),
    ("storeys", "-", "storeys, building {k}", "storeys of building {k}"),
    ("mass_kg", "kg", "floor mass, building {k}", "floor mass of building {k} (empty where floor masses are given)"),
    ("t1_s", "s", "period T1, building {k}", "fundamental period of building {k}"),
    ("xi", "-", "damping ratio, building {k}", "damping ratio of building {k}"),
    ("yield_drift_ratio", "m/m", "yield drift ratio, building {k}", "yield drift ratio of every storey of building {k} (swept or sampled)"),
    ("yield_base_shear_coefficient", "-", "base shear strength, building {k}", "base shear strength of building {k} over its weight (swept or sampled)"),
    ("plastic_drift_ratio", "m/m", "plastic drift ratio, building {k}", "IMK theta_p, yield to capping, of every storey of building {k} (swept or sampled)"),
    ("post_capping_drift_ratio", "m/m", "post-capping drift ratio, building {k}", "IMK theta_pc, capping to zero strength, of every storey of building {k} (swept or sampled)"),
    ("residual_strength_ratio", "-", "residual strength ratio, building {k}", "IMK kappa, residual strength over the yield strength, of every storey of building {k} (swept or sampled)"),
    ("ultimate_drift_ratio", "m/m", "ultimate drift ratio, building {k}", "IMK theta_u, no strength beyond it, of every storey of building {k} (swept or sampled)"),
    ("energy_capacity_ratio", "-", "energy capacity ratio, building {k}", "IMK gamma, energy capacity E_t = gamma F_y theta_y h, of every storey of building {k} (swept or sampled)"),
    ("peak_roof_m", "m", "peak roof displacement, building {k}", "largest roof displacement of building {k} relative to the ground"),
    ("peak_drift_ratio", "m/m", "peak drift ratio, building {k}", "largest interstorey drift ratio of building {k}"),
    ("drift_storey", "-", "storey of peak drift, building {k}", "the storey of that drift (from 1)"),
    ("peak_accel_m_s2", "m/s^2", "peak floor acceleration, building {k}", "largest absolute floor acceleration of building {k}"),
    ("accel_floor", "-", "floor of peak acceleration, building {k}", "the floor of that acceleration (from 1)"),
    ("residual_drift_ratio", "m/m", "residual drift ratio, building {k}", "largest residual interstorey drift ratio of building {k} at rest after the motion (yielding storeys; empty where the run did not settle)"),
    ("residual_storey", "-", "storey of residual drift, building {k}", "the storey of that residual drift (from 1)"),
    ("peak_ductility", "-", "peak ductility, building {k}", "largest storey ductility demand of building {k}: peak drift / yield drift"),
    ("ductility_storey", "-", "storey of peak ductility, building {k}", "the storey of that ductility (from 1)"),
    ("hysteretic_energy_j", "J", "hysteretic energy, building {k}", "hysteretic energy of building {k}'s storeys: their work less the elastic energy they hold at the end"),
    ("yielded_storeys", "-", "yielded storeys, building {k}", "storeys of building {k} that yielded"),
    ("strength_ratio", "-", "strength left, building {k}", "smallest strength ratio over the IMK storeys of building {k} at the end: a storey's capping strength left (its weaker side's) over its initial one, in [0, 1] (1: none lost, 0: no strength left)"),
    ("capped_storeys", "-", "capped storeys, building {k}", "IMK storeys of building {k} that passed their capping point (0 to its storeys)"),
    ("stability_coefficient", "-", "stability coefficient, building {k}", "largest storey stability coefficient P/(k h) of building {k} (P-Delta): gravity load over storey stiffness times height"),
    ("collapsed", "-", "collapsed, building {k}", "1 where a storey of building {k} reached the collapse limit ([run] collapse_drift_ratio), else 0; the building left the scene there and the others went on"),
    ("collapse_time_s", "s", "collapse time, building {k}", "when building {k} collapsed (empty where it did not); its peaks are over the time before it"),
    ("collapse_storey", "-", "collapsed storey, building {k}", "the storey of building {k} that reached the collapse limit (from 1; empty where it did not collapse)"),
];

/// Per contact level: suffix, unit, short name, meaning.
const PER_LEVEL: [(&str, &str, &str, &str); 6] = [
    ("impacts", "-", "impacts, {level}", "impacts at {level}"),
    (
        "peak_force_n",
        "N",
        "peak force, {level}",
        "largest force at {level}",
    ),
    (
        "peak_penetration_m",
        "m",
        "peak penetration, {level}",
        "largest penetration at {level}",
    ),
    (
        "impact_velocity_m_s",
        "m/s",
        "impact velocity, {level}",
        "approach speed of the largest impact at {level}",
    ),
    (
        "column_shear_n",
        "N",
        "column shear, {level}",
        "largest shear in the struck storey's columns while in contact at {level}: the storey's spring force V with the shares of every contact force on that storey's columns at that instant (floors of both neighbours, this level's among them) on the worst segment between the points: above them all V - sum s_i F_i, below a point F_i more for each point at or above it (one point: max(|V - s F|, |V + (1 - s) F|)), s = 3 xi^2 - 2 xi^3 at the height xi up the storey; with the struck building's struck_column_share alpha, the struck columns' own: alpha V in place of V (0 if never in contact)",
    ),
    (
        "column_shear_ratio",
        "-",
        "column shear / yield force, {level}",
        "that largest column shear at {level} over the struck storey's yield force, alpha of it with struck_column_share (storeys that yield)",
    ),
];

fn number(s: &str) -> Option<usize> {
    (!s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()))
        .then(|| s.parse().ok())
        .flatten()
}

impl Meaning {
    /// Why a cell of this column may be empty, in the table's words (`where the run did not
    /// settle`, `if none`), or None where the meaning gives no reason.
    pub fn when_empty(&self) -> Option<&str> {
        // The reason is a parenthetical clause: `(empty ...)` or `(...; empty ...)`.
        let at = ["(empty ", "; empty "]
            .iter()
            .find_map(|k| self.text.find(k).map(|i| i + k.len()))?;
        let end = self.text[at..].find([')', ';'])? + at;
        Some(&self.text[at..end])
    }
}

/// What `column` holds, or None for a name no sweep writes.
pub fn meaning(column: &str) -> Option<Meaning> {
    let of = |(_, unit, label, text): &(&str, &'static str, &str, &str)| Meaning {
        unit,
        label: label.to_string(),
        text: text.to_string(),
    };
    if let Some(m) = FIXED.iter().chain(&ENERGY).find(|m| m.0 == column) {
        return Some(of(m));
    }
    // gap_A_B_m
    if let Some(rest) = column
        .strip_prefix("gap_")
        .and_then(|r| r.strip_suffix("_m"))
    {
        if let Some((a, b)) = rest.split_once('_') {
            if let (Some(a), Some(b)) = (number(a), number(b)) {
                return Some(Meaning {
                    unit: "m",
                    label: format!("gap {a}-{b}"),
                    text: format!("gap between buildings {a} and {b}"),
                });
            }
        }
    }
    // level_bIfJ_bKfL_<output>, or a floor against a storey's columns: bKcL
    if let Some(rest) = column.strip_prefix("level_") {
        let parts: Vec<&str> = rest.splitn(3, '_').collect();
        if let [left, right, output] = parts[..] {
            // (building, floor or storey, on a column)
            let side = |p: &str| -> Option<(usize, usize, bool)> {
                let p = p.strip_prefix('b')?;
                let (b, f, column) = match p.split_once('f') {
                    Some((b, f)) => (b, f, false),
                    None => p.split_once('c').map(|(b, c)| (b, c, true))?,
                };
                Some((number(b)?, number(f)?, column))
            };
            let sides = (side(left), side(right));
            if let ((Some(l), Some(r)), Some(m)) = (sides, PER_LEVEL.iter().find(|m| m.0 == output))
            {
                let level = match (l.2, r.2) {
                    (false, false) => format!(
                        "the level where floor {} of building {} meets floor {} of building {}",
                        l.1, l.0, r.1, r.0
                    ),
                    (false, true) => format!(
                        "the level where floor {} of building {} strikes the columns of storey {} of building {}",
                        l.1, l.0, r.1, r.0
                    ),
                    (true, false) => format!(
                        "the level where floor {} of building {} strikes the columns of storey {} of building {}",
                        r.1, r.0, l.1, l.0
                    ),
                    (true, true) => return None,
                };
                return Some(Meaning {
                    unit: m.1,
                    label: m.2.replace("{level}", &format!("level {left}-{right}")),
                    text: m.3.replace("{level}", &level),
                });
            }
        }
    }
    // bK_sJ_<output>: a yielding storey's own columns
    if let Some((k, rest)) = column.strip_prefix('b').and_then(|r| r.split_once("_s")) {
        if let Some((j, suffix)) = rest.split_once('_') {
            let text = match suffix {
                "residual_drift_ratio" => Some(("m/m", "residual drift ratio, building {k} storey {j}", "residual drift ratio of storey {j} of building {k} at rest after the motion, signed (empty where the run did not settle; 0 where the building is elastic)")),
                "peak_drift_ratio" => Some(("m/m", "peak drift ratio, building {k} storey {j}", "largest interstorey drift ratio, abs(u_j - u_(j-1)) / h_j, of storey {j} of building {k} (--columns +storeys; at the collapse limit in the storey that collapsed)")),
                "peak_ductility" => Some(("-", "ductility, building {k} storey {j}", "ductility demand of storey {j} of building {k}: its peak drift / its yield drift")),
                "hysteretic_energy_j" => Some(("J", "hysteretic energy, building {k} storey {j}", "hysteretic energy of storey {j} of building {k}")),
                "strength_ratio" => Some(("-", "strength left, building {k} storey {j}", "strength ratio of IMK storey {j} of building {k} at the end: its capping strength left (its weaker side's) over its initial one, in [0, 1] (1: none lost, 0: no strength left)")),
                "capped" => Some(("-", "capped, building {k} storey {j}", "1 where IMK storey {j} of building {k} passed its capping point, else 0")),
                _ => None,
            };
            if let (Some(k), Some(j), Some((unit, label, text))) = (number(k), number(j), text) {
                let fill = |t: &str| {
                    t.replace("{j}", &j.to_string())
                        .replace("{k}", &k.to_string())
                };
                return Some(Meaning {
                    unit,
                    label: fill(label),
                    text: fill(text),
                });
            }
        }
    }
    // bK_fJ_peak_accel_m_s2: a floor's peak acceleration (floor 0: the ground)
    if let Some((k, rest)) = column.strip_prefix('b').and_then(|r| r.split_once("_f")) {
        if let Some((j, "peak_accel_m_s2")) = rest.split_once('_') {
            if let (Some(k), Some(j)) = (number(k), number(j)) {
                let (label, text) = if j == 0 {
                    (
                        format!("peak ground acceleration, building {k}"),
                        format!("floor 0 of building {k}, the ground: the scaled record's PGA (--columns +floors)"),
                    )
                } else {
                    (
                        format!("peak acceleration, building {k} floor {j}"),
                        format!("largest absolute acceleration of floor {j} of building {k}, relative acceleration plus the ground's (--columns +floors; floors 1 and up are those of bK_peak_accel_m_s2)"),
                    )
                };
                return Some(Meaning {
                    unit: "m/s^2",
                    label,
                    text,
                });
            }
        }
    }
    // bK_<output>
    if let Some((k, suffix)) = column.strip_prefix('b').and_then(|r| r.split_once('_')) {
        if let (Some(k), Some(m)) = (number(k), PER_BUILDING.iter().find(|m| m.0 == suffix)) {
            return Some(Meaning {
                unit: m.1,
                label: m.2.replace("{k}", &k.to_string()),
                text: m.3.replace("{k}", &k.to_string()),
            });
        }
    }
    None
}

/// A markdown table of `columns`: name, unit, meaning, and the name plots give it.
pub fn table<S: AsRef<str>>(columns: &[S]) -> String {
    let mut s = String::from("| column | unit | meaning | in plots |\n|---|---|---|---|\n");
    for c in columns {
        let c = c.as_ref();
        let m = meaning(c).expect("every written column has a meaning");
        s.push_str(&format!(
            "| `{c}` | {} | {} | {} |\n",
            m.unit, m.text, m.label
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pair_column_and_row_pattern_has_a_meaning() {
        for c in crate::plan::columns::pair::HEADER {
            assert!(meaning(c).is_some(), "{c}");
        }
        let m = meaning("level_b1f3_b2f2_peak_force_n").unwrap();
        assert_eq!(m.unit, "N");
        assert!(m
            .text
            .contains("floor 3 of building 1 meets floor 2 of building 2"));
        let m = meaning("level_b1c2_b2f1_impacts").unwrap();
        assert!(m
            .text
            .contains("floor 1 of building 2 strikes the columns of storey 2 of building 1"));
        assert_eq!(meaning("b12_peak_drift_ratio").unwrap().unit, "m/m");
        for c in crate::plan::columns::row::BUILDING_OUTPUTS
            .iter()
            .chain(&crate::plan::columns::row::INELASTIC_OUTPUTS)
            .chain(&crate::plan::columns::row::IMK_OUTPUTS)
        {
            assert!(meaning(&format!("b3_{c}")).is_some(), "{c}");
        }
        assert_eq!(meaning("b2_hysteretic_energy_j").unwrap().unit, "J");
        for c in (crate::plan::columns::row::STOREY_OUTPUTS.iter())
            .chain(&crate::plan::columns::row::IMK_STOREY_OUTPUTS)
        {
            assert!(meaning(&format!("b2_s14_{c}")).is_some(), "{c}");
            assert!(crate::plan::row::RowPlan::asks_storey_columns(&format!(
                "b2_s14_{c}"
            )));
        }
        assert!(!crate::plan::row::RowPlan::asks_storey_columns(
            "b2_peak_ductility"
        ));
        assert!(meaning("b2_s_peak_ductility").is_none());
        assert_eq!(
            meaning("gap_2_3_m").unwrap().text,
            "gap between buildings 2 and 3"
        );
        for bad in [
            "b_peak_roof_m",
            "gap_a_2_m",
            "level_b1f3_peak_force_n",
            "level_b1c3_b2c2_peak_force_n",
            "nope",
            "b1_nope",
        ] {
            assert!(meaning(bad).is_none(), "{bad}");
        }
    }
}

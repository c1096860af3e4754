//! One run, whole (`pound trace`): the time history of one run of a sweep from the integrator
//! the sweep uses, at every accepted record step and located event (touch, turn, separation),
//! with the run's output, whose cells are the sweep's row for that run.
//!
//! The CPU fast scheme may settle a pair's free stretches from a response shared between runs;
//! the trace integrates the run alone, which gives the same output (`solver::simulate_shared`).
//! A row's trace runs as the sweep does, buildings that no contact can reach standing still;
//! such a building is sampled at its exact motion without changing the run, so the output is
//! the sweep's to the last digit (`solver::row::simulate_row_observed`). A row of two
//! one-storey buildings that the sweep runs on the pair's kernel is traced there too (its
//! samples in the row's form), unless it nears the collapse limit, where the sweep runs it on
//! the row's.

use crate::physics::model::Pair;
use crate::physics::row::RowOutput;
use crate::physics::solver::row::{
    near_collapse, simulate_row_observed, RowModel, RowSample, RowScheme, StoreySample,
};
use crate::physics::solver::{simulate_observed, simulate_tracking_accel, Mode, Sample};
use crate::plan::row::{RowPlan, RowRunSpec};
use crate::plan::{PairPlan, Plan, RunSpec};
use crate::studies::plot::{Panel, Series};

#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    #[error("--run {run}: the sweep has {runs} runs (0 to {})", runs.saturating_sub(1))]
    NoSuchRun { run: u64, runs: u64 },
}

/// The time history of one run.
#[derive(Debug, Clone)]
pub struct Trace {
    /// The sweep's header, and the run's cells as the sweep writes them.
    pub header: Vec<String>,
    pub row: Vec<String>,
    pub history: History,
}

/// A pair's or a row's samples.
#[derive(Debug, Clone)]
pub enum History {
    Pair {
        spec: Box<RunSpec>,
        samples: Vec<Sample>,
    },
    Row {
        index: u64,
        /// Each level's column prefix (`level_b1f3_b2f3`), in the samples' order.
        levels: Vec<String>,
        samples: Vec<RowSample>,
    },
}

/// Run `run` of `plan`, observed.
pub fn trace(plan: &Plan, run: u64) -> Result<Trace, TraceError> {
    let runs = match plan {
        Plan::Pair(p) => p.len(),
        Plan::Row(r) => r.len(),
    };
    if run >= runs {
        return Err(TraceError::NoSuchRun { run, runs });
    }
    Ok(match plan {
        Plan::Pair(p) => trace_pair(p, run),
        Plan::Row(r) => trace_row(r, run),
    })
}

fn trace_pair(pair: &PairPlan, run: u64) -> Trace {
    let spec = pair.run(run);
    let mut samples = Vec::new();
    let output = simulate_observed(
        &spec.pair(),
        &pair.forcing(&spec),
        &Default::default(),
        &pair.contact.spec.scheme,
        Some(&mut |s: &Sample| samples.push(*s)),
    );
    Trace {
        header: crate::plan::columns::pair_header(pair),
        row: crate::plan::columns::row(pair, &spec, &output),
        history: History::Pair {
            spec: Box::new(spec),
            samples,
        },
    }
}

fn trace_row(plan: &RowPlan, run: u64) -> Trace {
    let spec = plan.run(run);
    let (output, samples) = on_the_pair_kernel(plan, &spec).unwrap_or_else(|| {
        let model = RowModel::new(&plan.row(&spec));
        let mut samples = Vec::new();
        let output = simulate_row_observed(
            &model,
            &plan.forcing(&spec),
            model.at_rest(),
            &plan.scheme(),
            &mut |s: &RowSample| samples.push(s.clone()),
        );
        (output, samples)
    });
    Trace {
        header: plan.header(),
        row: plan.cells(&spec, &output),
        history: History::Row {
            index: spec.index,
            levels: plan.level_names(),
            samples,
        },
    }
}

/// Run `spec` observed on the pair's kernel where the sweep runs it there (a row of two
/// one-storey buildings that does not near the collapse limit): its output and samples.
fn on_the_pair_kernel(plan: &RowPlan, spec: &RowRunSpec) -> Option<(RowOutput, Vec<RowSample>)> {
    let RowScheme::Fast(o) = plan.scheme() else {
        return None;
    };
    if !plan.runs_as_pair() {
        return None;
    }
    let pair = plan.pair_run(spec).pair();
    let mut samples = Vec::new();
    let mut observe = |s: &Sample| samples.push(row_sample(&pair, s));
    let forcing = plan.forcing(spec);
    let out = simulate_tracking_accel(&pair, &forcing, &o, None, Some(&mut observe));
    let output = RowOutput::of_pair(&out, plan.pair_heights());
    (!near_collapse(&output, plan.collapse_drift_ratio)).then_some((output, samples))
}

/// A pair's sample as the row of its two one-storey buildings gives it.
fn row_sample(pair: &Pair, s: &Sample) -> RowSample {
    RowSample {
        t: s.t,
        floors: vec![vec![s.z[0]], vec![s.z[2]]],
        penetrations: vec![(s.z[0] - s.z[2] - pair.gap).max(0.0)],
        forces: vec![s.force],
        modes: vec![s.mode],
        storeys: Vec::new(),
    }
}

impl Trace {
    /// How many samples (record steps and located events) the history holds.
    pub fn len(&self) -> usize {
        match &self.history {
            History::Pair { samples, .. } => samples.len(),
            History::Row { samples, .. } => samples.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The samples as CSV: a pair's [`HEADER`], or a row's [`row_header`].
    pub fn csv(&self) -> String {
        match &self.history {
            History::Pair { spec, samples, .. } => pair_csv(spec, samples),
            History::Row {
                levels, samples, ..
            } => row_csv(levels, samples),
        }
    }

    /// Displacements and contact force against time, force against penetration.
    pub fn panels(&self) -> Vec<Panel> {
        match &self.history {
            History::Pair { spec, samples, .. } => pair_panels(spec, samples),
            History::Row {
                index,
                levels,
                samples,
            } => row_panels(*index, levels, samples),
        }
    }
}

fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::Free => "free",
        Mode::Approach => "approach",
        Mode::Restitution => "restitution",
    }
}

/// A yielding storey's trace columns, after its `b2_s1_` prefix.
pub const STOREY_COLUMNS: [&str; 4] = [
    "drift_ratio",
    "plastic_drift_ratio",
    "shear_n",
    "hysteretic_energy_j",
];

/// An IMK storey's further trace columns, after its [`STOREY_COLUMNS`]: its drift, the force
/// its law gives there and the branch that force is on ([`crate::physics::imk::Branch::name`]).
pub const IMK_STOREY_COLUMNS: [&str; 3] = ["drift_m", "force_n", "branch"];

/// A yielding storey's column prefix (`b2_s1`, both from 1).
fn storey_prefix(s: &StoreySample) -> String {
    format!("b{}_s{}", s.building + 1, s.storey + 1)
}

/// A row trace's columns: the time, each building's floor displacements (`b1_f1_u_m`, floors
/// from 1 at the lowest), each level's penetration, force and mode, then each yielding
/// storey's drift and plastic drift ratios, shear and hysteretic energy (`b1_s1_shear_n`), an
/// IMK storey's with its drift, force and branch (`b1_s1_branch`).
pub fn row_header(levels: &[String], floors: &[usize], storeys: &[StoreySample]) -> Vec<String> {
    let mut h = vec!["t_s".to_string()];
    for (b, &n) in floors.iter().enumerate() {
        h.extend((1..=n).map(|f| format!("b{}_f{f}_u_m", b + 1)));
    }
    for l in levels {
        for c in ["penetration_m", "force_n", "mode"] {
            h.push(format!("{l}_{c}"));
        }
    }
    for s in storeys {
        let prefix = storey_prefix(s);
        h.extend(STOREY_COLUMNS.iter().map(|c| format!("{prefix}_{c}")));
        if s.imk.is_some() {
            h.extend(IMK_STOREY_COLUMNS.iter().map(|c| format!("{prefix}_{c}")));
        }
    }
    h
}

fn row_csv(levels: &[String], samples: &[RowSample]) -> String {
    let num = crate::plan::columns::num;
    let floors: Vec<usize> = samples
        .first()
        .map(|s| s.floors.iter().map(Vec::len).collect())
        .unwrap_or_default();
    let storeys = samples.first().map_or(&[][..], |s| &s.storeys[..]);
    let mut s = row_header(levels, &floors, storeys).join(",");
    s.push('\n');
    for x in samples {
        let mut cells = vec![num(x.t)];
        cells.extend(x.floors.iter().flatten().map(|&u| num(u)));
        for l in 0..x.forces.len() {
            cells.push(num(x.penetrations[l]));
            cells.push(num(x.forces[l]));
            cells.push(mode_name(x.modes[l]).into());
        }
        for st in &x.storeys {
            cells.extend(
                [
                    st.drift_ratio,
                    st.plastic_drift_ratio,
                    st.shear_n,
                    st.hysteretic_energy_j,
                ]
                .map(num),
            );
            if let Some(imk) = &st.imk {
                cells.extend([num(imk.drift_m), num(imk.force_n), imk.branch.name().into()]);
            }
        }
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

fn line(name: &str, points: Vec<(f64, f64)>) -> Series {
    Series {
        name: name.into(),
        points,
        scatter: false,
        style: None,
    }
}

/// A level's column prefix in words: `level_b1f3_b2f3` is "building 1 floor 3 / building 2
/// floor 3".
fn level_label(prefix: &str) -> String {
    let words = |side: &str| {
        side.strip_prefix('b')
            .and_then(|r| r.split_once('f'))
            .map(|(b, f)| format!("building {b} floor {f}"))
    };
    prefix
        .strip_prefix("level_")
        .and_then(|r| r.split_once('_'))
        .and_then(|(a, b)| Some(format!("{} / {}", words(a)?, words(b)?)))
        .unwrap_or_else(|| prefix.to_string())
}

/// A level's point of a sample (None: not drawn).
type LevelPoint = dyn Fn(&RowSample, usize) -> Option<(f64, f64)>;

/// Each building's roof displacement and each level's force against time; each level's force
/// against its penetration; where storeys yield, each yielding building's hysteresis loop (its
/// storey that dissipates most) and its hysteretic energy against time.
fn row_panels(index: u64, levels: &[String], samples: &[RowSample]) -> Vec<Panel> {
    let buildings = samples.first().map_or(0, |s| s.floors.len());
    let roofs = (0..buildings)
        .map(|b| {
            line(
                &format!("building {} roof", b + 1),
                samples
                    .iter()
                    .map(|s| (s.t, *s.floors[b].last().unwrap_or(&0.0)))
                    .collect(),
            )
        })
        .collect();
    let per_level = |f: &LevelPoint| -> Vec<Series> {
        levels
            .iter()
            .enumerate()
            .map(|(l, name)| {
                let label = level_label(name);
                line(&label, samples.iter().filter_map(|s| f(s, l)).collect())
            })
            .filter(|s| s.points.iter().any(|p| p.1 > 0.0))
            .collect()
    };
    let mut panels = vec![
        Panel {
            title: format!("Run {index}: roof displacements"),
            x_label: "t (s)".into(),
            y_label: "displacement (m)".into(),
            series: roofs,
            ..Panel::default()
        },
        Panel {
            title: "Contact force per level".into(),
            x_label: "t (s)".into(),
            y_label: "contact force (N)".into(),
            series: per_level(&|s, l| Some((s.t, s.forces[l]))),
            ..Panel::default()
        },
        Panel {
            title: "Force against penetration".into(),
            x_label: "penetration (m)".into(),
            y_label: "contact force (N)".into(),
            series: per_level(&|s, l| {
                (s.modes[l] != Mode::Free).then(|| (s.penetrations[l], s.forces[l]))
            }),
            ..Panel::default()
        },
    ];
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
        return panels;
    };
    // The yielding buildings, each with its storeys' indices in the samples.
    let mut yielding: Vec<(usize, Vec<usize>)> = Vec::new();
    for (i, st) in first.storeys.iter().enumerate() {
        match yielding.last_mut() {
            Some((b, storeys)) if *b == st.building => storeys.push(i),
            _ => yielding.push((st.building, vec![i])),
        }
    }
    if yielding.is_empty() {
        return panels;
    }
    let loops = yielding
        .iter()
        .map(|(b, storeys)| {
            let most = *storeys
                .iter()
                .max_by(|&&i, &&j| {
                    let e = |k: usize| last.storeys[k].hysteretic_energy_j;
                    e(i).total_cmp(&e(j))
                })
                .expect("a yielding building has storeys");
            line(
                &format!(
                    "building {} storey {}",
                    b + 1,
                    first.storeys[most].storey + 1
                ),
                samples
                    .iter()
                    .map(|s| (s.storeys[most].drift_ratio, s.storeys[most].shear_n))
                    .collect(),
            )
        })
        .collect();
    let energies = yielding
        .iter()
        .map(|(b, storeys)| {
            line(
                &format!("building {}", b + 1),
                samples
                    .iter()
                    .map(|s| {
                        (
                            s.t,
                            storeys
                                .iter()
                                .map(|&i| s.storeys[i].hysteretic_energy_j)
                                .sum(),
                        )
                    })
                    .collect(),
            )
        })
        .collect();
    panels.push(Panel {
        title: "Storey shear against drift (the storey that dissipates most)".into(),
        x_label: "storey drift ratio".into(),
        y_label: "storey shear (N)".into(),
        series: loops,
        ..Panel::default()
    });
    panels.push(Panel {
        title: "Hysteretic energy of the storeys".into(),
        x_label: "t (s)".into(),
        y_label: "hysteretic energy (J)".into(),
        series: energies,
        ..Panel::default()
    });
    panels
}

/// The trace's columns.
pub const HEADER: [&str; 10] = [
    "t_s",
    "u1_m",
    "v1_m_s",
    "u2_m",
    "v2_m_s",
    "a1_abs_m_s2",
    "a2_abs_m_s2",
    "penetration_m",
    "force_n",
    "mode",
];

/// A sample's absolute floor accelerations in the pair `p`, from the equations of motion
/// `m (u'' + ag) + c u' + k u = -+F` (the contact pushes building 1 back, building 2 on).
fn accelerations(p: &crate::physics::model::Pair, s: &Sample) -> [f64; 2] {
    let z = &s.z;
    [
        0.0 - (p.b1.c * z[1] + p.b1.k * z[0] + s.force) / p.b1.m,
        0.0 - (p.b2.c * z[3] + p.b2.k * z[2] - s.force) / p.b2.m,
    ]
}

/// A pair's samples as CSV ([`HEADER`]).
fn pair_csv(spec: &RunSpec, samples: &[Sample]) -> String {
    let num = crate::plan::columns::num;
    let pair = spec.pair();
    let mut s = HEADER.join(",");
    s.push('\n');
    for x in samples {
        let z = &x.z;
        let [a1, a2] = accelerations(&pair, x);
        let penetration = (z[0] - z[2] - spec.gap).max(0.0);
        let mut cells: Vec<String> = [x.t, z[0], z[1], z[2], z[3], a1, a2, penetration, x.force]
            .map(num)
            .to_vec();
        cells.push(mode_name(x.mode).into());
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

/// A pair's displacements and contact force against time, and force against penetration.
fn pair_panels(spec: &RunSpec, samples: &[Sample]) -> Vec<Panel> {
    let gap = spec.gap;
    let at = |f: &dyn Fn(&Sample) -> f64| -> Vec<(f64, f64)> {
        samples.iter().map(|s| (s.t, f(s))).collect()
    };
    vec![
        Panel {
            title: format!("Run {}: displacements", spec.index),
            x_label: "t (s)".into(),
            y_label: "displacement (m)".into(),
            series: vec![
                line("building 1", at(&|s| s.z[0])),
                line("building 2", at(&|s| s.z[2])),
            ],
            ..Panel::default()
        },
        Panel {
            title: "Contact force".into(),
            x_label: "t (s)".into(),
            y_label: "contact force (N)".into(),
            series: vec![line("contact force", at(&|s| s.force))],
            ..Panel::default()
        },
        Panel {
            title: "Force against penetration".into(),
            x_label: "penetration (m)".into(),
            y_label: "contact force (N)".into(),
            series: vec![line(
                "force against penetration",
                samples
                    .iter()
                    .filter(|s| s.mode != Mode::Free)
                    .map(|s| ((s.z[0] - s.z[2] - gap).max(0.0), s.force))
                    .collect(),
            )],
            ..Panel::default()
        },
    ]
}

#[cfg(test)]
mod tests {
    #[test]
    fn levels_are_named_in_words() {
        assert_eq!(
            super::level_label("level_b1f3_b2f12"),
            "building 1 floor 3 / building 2 floor 12"
        );
        assert_eq!(super::level_label("odd"), "odd");
    }
}

//! One run, whole (`pound trace`): the time history of one run of a sweep from the integrator
//! the sweep uses, at every accepted record step and located event (touch, turn, separation),
//! with the run's output, whose cells are the sweep's row for that run.
//!
//! The CPU fast scheme may settle free stretches from a response shared between runs; the
//! trace integrates the run alone, which gives the same output (`solver::simulate_shared`).
//! Pairs only so far: the row scheme has no observer yet.

use crate::physics::model::RunOutput;
use crate::physics::solver::{simulate_observed, Mode, Sample};
use crate::plan::{PairPlan, Plan, RunSpec};
use crate::studies::plot::{Panel, Series};

#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    #[error("--run {run}: the sweep has {runs} runs (0 to {})", runs.saturating_sub(1))]
    NoSuchRun { run: u64, runs: u64 },
    #[error("rows of [[building]] configs are not traced yet (the row scheme has no observer); a [building1]/[building2] pair is")]
    Rows,
}

/// The time history of one run.
#[derive(Debug, Clone)]
pub struct Trace {
    pub spec: RunSpec,
    pub output: RunOutput,
    /// The run's cells as the sweep writes them ([`crate::plan::columns::header`] order).
    pub row: Vec<String>,
    pub samples: Vec<Sample>,
}

/// Run `run` of `plan`, observed.
pub fn trace(plan: &Plan, run: u64) -> Result<Trace, TraceError> {
    let pair: &PairPlan = match plan {
        Plan::Pair(p) => p,
        Plan::Row(_) => return Err(TraceError::Rows),
    };
    if run >= pair.len() {
        return Err(TraceError::NoSuchRun {
            run,
            runs: pair.len(),
        });
    }
    let spec = pair.run(run);
    let mut samples = Vec::new();
    let output = simulate_observed(
        &spec.pair(),
        &pair.forcing(&spec),
        &Default::default(),
        &pair.contact.spec.scheme,
        Some(&mut |s: &Sample| samples.push(*s)),
    );
    Ok(Trace {
        row: crate::plan::columns::row(pair, &spec, &output),
        spec,
        output,
        samples,
    })
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

impl Trace {
    /// A sample's absolute floor accelerations in the pair `p`, from the equations of motion
    /// `m (u'' + ag) + c u' + k u = -+F` (the contact pushes building 1 back, building 2 on).
    fn accelerations(p: &crate::physics::model::Pair, s: &Sample) -> [f64; 2] {
        let z = &s.z;
        [
            0.0 - (p.b1.c * z[1] + p.b1.k * z[0] + s.force) / p.b1.m,
            0.0 - (p.b2.c * z[3] + p.b2.k * z[2] - s.force) / p.b2.m,
        ]
    }

    /// The samples as CSV ([`HEADER`]).
    pub fn csv(&self) -> String {
        let num = crate::plan::columns::num;
        let pair = self.spec.pair();
        let mut s = HEADER.join(",");
        s.push('\n');
        for x in &self.samples {
            let z = &x.z;
            let [a1, a2] = Self::accelerations(&pair, x);
            let penetration = (z[0] - z[2] - self.spec.gap).max(0.0);
            let mut cells: Vec<String> =
                [x.t, z[0], z[1], z[2], z[3], a1, a2, penetration, x.force]
                    .map(num)
                    .to_vec();
            cells.push(
                match x.mode {
                    Mode::Free => "free",
                    Mode::Approach => "approach",
                    Mode::Restitution => "restitution",
                }
                .into(),
            );
            s.push_str(&cells.join(","));
            s.push('\n');
        }
        s
    }

    /// Displacements and the contact force against time, and force against penetration.
    pub fn panels(&self) -> Vec<Panel> {
        let gap = self.spec.gap;
        let at = |f: &dyn Fn(&Sample) -> f64| -> Vec<(f64, f64)> {
            self.samples.iter().map(|s| (s.t, f(s))).collect()
        };
        let line = |name: &str, points| Series {
            name: name.into(),
            points,
            scatter: false,
            style: None,
        };
        vec![
            Panel {
                title: format!("Run {}: displacements", self.spec.index),
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
                    self.samples
                        .iter()
                        .filter(|s| s.mode != Mode::Free)
                        .map(|s| ((s.z[0] - s.z[2] - gap).max(0.0), s.force))
                        .collect(),
                )],
                ..Panel::default()
            },
        ]
    }
}

//! The pair path of the accuracy study: one pair sweep, its errors against the reference, its
//! table and panels.

use crate::engine::gpu::{GpuContext, GpuError, GpuOptions, Precision};
use crate::engine::quantile::{quantile, Interpolation::Nearest};
use crate::engine::{Engine, EngineError};
use crate::physics::model::{RunOutput, Status};
use crate::physics::solver::{FastOptions, ReferenceOptions, Scheme};
use crate::plan::PairPlan;
use crate::studies::plot::{Panel, Series};

/// One path at one setting.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// `reference` (errors 0 by definition; its speed and energy residual), `cpu-fast-f64`,
    /// `gpu-f32`, `gpu-f64`.
    pub path: String,
    pub substeps_per_contact: f64,
    pub runs_per_second: f64,
    /// The work: integration steps per run, averaged over the runs (RK4 substeps on the fast
    /// paths, accepted and rejected steps on the reference).
    pub substeps_per_run: f64,
    pub errors: Errors,
}

/// Mean integration steps per run of `outs` (NaN for no runs).
pub(super) fn substeps_per_run(outs: &[RunOutput]) -> f64 {
    outs.iter().map(|o| o.substeps as f64).sum::<f64>() / outs.len() as f64
}

/// Relative errors against the reference over the runs both end `ok` with equal impact counts
/// (medians and 99th percentiles; NaN where no run was compared: a statistic over zero runs is
/// no figure), and the fraction of runs whose impact count differs.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Errors {
    pub force_median: f64,
    pub force_p99: f64,
    pub displacement_median: f64,
    pub displacement_p99: f64,
    pub energy_median: f64,
    pub energy_p99: f64,
    pub impact_count_differs: f64,
    /// The runs whose impact count differs (of which `impact_count_differs` is the share).
    pub impacts_differ: u64,
    /// Runs that failed (`status` not `ok`) on this path or in the reference: evidence against
    /// any accuracy claim, never left out silently.
    pub failed: u64,
    /// Runs that pounded and were compared (both `ok`, equal impact counts): the peak-force
    /// statistics are over these.
    pub compared: u64,
    /// `|energy residual|` over the runs that end `ok` (`model::EnergyBalance`).
    pub residual_median: f64,
    pub residual_p99: f64,
}

pub(super) fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// The median and the 99th percentile of `v` (sorted here), each a value of the data (nearest
/// rank); NaN for no values (statistics over zero runs are not zeros).
pub(super) fn median_p99(v: &mut [f64]) -> [f64; 2] {
    v.sort_by(f64::total_cmp);
    [0.5, 0.99].map(|p| quantile(v, p, Nearest))
}

/// Errors of `out` against `truth`, run by run.
pub fn errors(truth: &[RunOutput], out: &[RunOutput]) -> Errors {
    let (mut f, mut u, mut w) = (Vec::new(), Vec::new(), Vec::new());
    let (mut differ, mut failed) = (0usize, 0u64);
    let mut r = Vec::new();
    for (t, o) in truth.iter().zip(out) {
        if o.status == Status::Ok {
            r.extend(o.energy.map(|e| e.residual.abs()));
        }
        if t.status != Status::Ok || o.status != Status::Ok {
            failed += 1;
            continue;
        }
        if t.impacts != o.impacts {
            differ += 1;
            continue;
        }
        if t.peak_force > 0.0 {
            f.push(rel(o.peak_force, t.peak_force));
        }
        u.push(rel(o.peak_u1, t.peak_u1).max(rel(o.peak_u2, t.peak_u2)));
        // Elastic laws dissipate only rounding.
        if t.dissipated_energy > 1e-9 * t.peak_force * t.peak_penetration.max(1e-300) {
            w.push(rel(o.dissipated_energy, t.dissipated_energy));
        }
    }
    let [force_median, force_p99] = median_p99(&mut f);
    let [displacement_median, displacement_p99] = median_p99(&mut u);
    let [energy_median, energy_p99] = median_p99(&mut w);
    let [residual_median, residual_p99] = median_p99(&mut r);
    Errors {
        compared: f.len() as u64,
        force_median,
        force_p99,
        displacement_median,
        displacement_p99,
        energy_median,
        energy_p99,
        impact_count_differs: differ as f64 / truth.len().max(1) as f64,
        impacts_differ: differ as u64,
        failed,
        residual_median,
        residual_p99,
    }
}

/// Every run of `plan` on `engine`: outputs in run order and runs per second.
pub(super) fn collect(plan: &PairPlan, engine: Engine) -> Result<(Vec<RunOutput>, f64), GpuError> {
    let (outs, report) = engine.collect(plan)?;
    Ok((outs, report.summary.runs_per_second()))
}

/// Runs per CPU task here: the benchmark sweep is small, so smaller tasks balance the threads.
pub(super) const CPU_CHUNK: usize = 16;

/// The CPU engine with `scheme`.
pub(super) fn cpu<'c>(scheme: Scheme) -> Engine<'c> {
    Engine::cpu(scheme, Some(CPU_CHUNK)).expect("a chunk in range")
}

/// The reference at `tol`, then every path at every setting. `progress` hears each point.
pub fn study(
    plan: &PairPlan,
    ctx: Option<&GpuContext>,
    settings: &[f64],
    tol: f64,
    mut progress: impl FnMut(&Point),
) -> Result<Vec<Point>, EngineError> {
    let (truth, rps) = collect(
        plan,
        cpu(Scheme::Reference(ReferenceOptions::with_tol(tol))),
    )?;
    let reference = Point {
        path: "reference".into(),
        substeps_per_contact: f64::NAN,
        runs_per_second: rps,
        substeps_per_run: substeps_per_run(&truth),
        errors: errors(&truth, &truth),
    };
    progress(&reference);
    let mut points = vec![reference];
    for &spc in settings {
        let fast = FastOptions {
            substeps_per_contact: spc,
            energy: true,
            ..Default::default()
        };
        let mut runs = vec![(
            "cpu-fast-f64".to_string(),
            collect(plan, cpu(Scheme::Fast(fast)))?,
        )];
        if let Some(ctx) = ctx {
            for precision in [Precision::F32, Precision::F64] {
                if precision == Precision::F64 && !ctx.supports_f64() {
                    continue;
                }
                let opts = GpuOptions {
                    precision,
                    fast,
                    ..Default::default()
                };
                let engine = Engine::gpu(ctx, opts, None)?;
                runs.push((format!("gpu-{}", precision.key()), collect(plan, engine)?));
            }
        }
        for (path, (outs, rps)) in runs {
            let p = Point {
                path,
                substeps_per_contact: spc,
                runs_per_second: rps,
                substeps_per_run: substeps_per_run(&outs),
                errors: errors(&truth, &outs),
            };
            progress(&p);
            points.push(p);
        }
    }
    Ok(points)
}

impl Errors {
    /// Medians and 99th percentiles: force, displacement, energy, energy residual.
    pub fn quantiles(&self) -> [f64; 8] {
        [
            self.force_median,
            self.force_p99,
            self.displacement_median,
            self.displacement_p99,
            self.energy_median,
            self.energy_p99,
            self.residual_median,
            self.residual_p99,
        ]
    }
}

/// The points as CSV.
pub fn csv(points: &[Point]) -> String {
    let mut s = String::from("path,substeps_per_contact,runs_per_second,substeps_per_run,force_median,force_p99,displacement_median,displacement_p99,energy_median,energy_p99,residual_median,residual_p99,impact_count_differs,failed\n");
    for p in points {
        let q = p
            .errors
            .quantiles()
            .map(|x| shown(x, "", |x| format!("{x:e}")));
        s.push_str(&format!(
            "{},{},{:.1},{:.1},{},{},{}\n",
            p.path,
            shown(p.substeps_per_contact, "", |x| x.to_string()),
            p.runs_per_second,
            p.substeps_per_run,
            q.join(","),
            p.errors.impact_count_differs,
            p.errors.failed
        ));
    }
    s
}

/// The settings among `settings`, each once, in increasing order.
pub(super) fn distinct_settings(settings: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut s: Vec<f64> = settings.filter(|s| !s.is_nan()).collect();
    s.sort_by(f64::total_cmp);
    s.dedup();
    s
}

/// A setting's marks: a scatter series named for it (`16 substeps per contact`), so that a
/// point on any line reads as its setting.
pub(super) fn setting_marks(setting: f64, points: Vec<(f64, f64)>) -> Series {
    Series {
        name: format!("{setting} substeps per contact"),
        points,
        scatter: true,
        style: None,
    }
}

/// Work-precision panels: runs/s against the median and the 99th percentile of the peak-force
/// error, one line per path through its settings, and each setting's points marked and named
/// in the legend (`16 substeps per contact`), so a point reads as its setting on every path.
pub fn panels(points: &[Point]) -> Vec<Panel> {
    let mut paths: Vec<&str> = points
        .iter()
        .map(|p| p.path.as_str())
        .filter(|p| *p != "reference")
        .collect();
    paths.sort();
    paths.dedup();
    let settings = distinct_settings(
        points
            .iter()
            .filter(|p| p.path != "reference")
            .map(|p| p.substeps_per_contact),
    );
    let panel = |title: &str, err: fn(&Errors) -> f64| {
        let at = |p: &Point| (err(&p.errors), p.runs_per_second);
        let lines = paths.iter().map(|path| Series {
            name: path.to_string(),
            points: points.iter().filter(|p| p.path == *path).map(at).collect(),
            scatter: false,
            style: None,
        });
        let marks = settings.iter().map(|&s| {
            setting_marks(
                s,
                points
                    .iter()
                    .filter(|p| p.path != "reference" && p.substeps_per_contact == s)
                    .map(at)
                    .collect(),
            )
        });
        Panel {
            title: title.into(),
            x_label: "peak-force relative error".into(),
            y_label: "runs/s".into(),
            log_x: true,
            log_y: true,
            series: lines.chain(marks).collect(),
            y_span: None,
            ..Default::default()
        }
    };
    vec![
        panel("median error", |e| e.force_median),
        panel("99th percentile error", |e| e.force_p99),
    ]
}

/// A markdown table header for [`markdown_row`].
pub const MARKDOWN_HEADER: &str = "| path | substeps/contact | runs/s | substeps/run | peak force median / p99 | peak u median / p99 | energy median / p99 | energy residual median / p99 | impact counts differ | failed |\n|---|---:|---:|---:|---|---|---|---|---:|---:|";

/// One point as a markdown table row.
pub fn markdown_row(p: &Point) -> String {
    let q = p.errors.quantiles().map(figure);
    format!(
        "| {} | {} | {:.0} | {:.0} | {} | {:.2} % | {} |",
        p.path,
        shown(p.substeps_per_contact, "-", |x| x.to_string()),
        p.runs_per_second,
        p.substeps_per_run,
        [&q[0..2], &q[2..4], &q[4..6], &q[6..8]]
            .map(|pair| pair.join(" / "))
            .join(" | "),
        100.0 * p.errors.impact_count_differs,
        p.errors.failed
    )
}

/// A number for a table or CSV cell, `none` where there is none (NaN: a statistic over zero
/// runs, or the reference's setting).
pub(super) fn shown(x: f64, none: &str, show: impl Fn(f64) -> String) -> String {
    if x.is_nan() {
        none.into()
    } else {
        show(x)
    }
}

/// A statistic in a table: `-` where it is over no runs.
pub(super) fn figure(x: f64) -> String {
    shown(x, "-", |x| format!("{x:.1e}"))
}

//! The row path of the accuracy study: a row sweep's errors against the reference, per
//! output, its collapses, where the error rises with the setting, its table and panels.

use crate::physics::model::Status;
use crate::physics::row::{Collapse, RowOutput};
use crate::physics::solver::{FastOptions, ReferenceOptions, Scheme};
use crate::studies::plot::{Panel, Series};

use super::pair::*;

/// A row sweep's outputs at one setting (the multi-storey work-precision table).
#[derive(Debug, Clone, PartialEq)]
pub struct RowPoint {
    /// `reference` or `cpu-fast-f64`.
    pub path: String,
    pub substeps_per_contact: f64,
    pub runs_per_second: f64,
    /// Median and p99 relative errors against the reference, over the runs both end `ok` with
    /// equal impact counts: peak force (runs that pound), and each building's peak roof
    /// displacement, drift ratio and absolute floor acceleration.
    pub force: [f64; 2],
    pub roof: [f64; 2],
    pub drift: [f64; 2],
    pub accel: [f64; 2],
    pub impact_count_differs: f64,
    /// Runs that failed on this path or in the reference.
    pub failed: u64,
    /// Runs that pounded and were compared (the peak-force statistics are over these).
    pub compared: u64,
    /// |energy residual|, median and p99, over the runs that end `ok`.
    pub residual: [f64; 2],
    /// Over the runs whose impact count differs from the reference's (left out of the errors
    /// above): the largest count difference, and the largest relative peak-force error.
    pub count_gap_max: u32,
    pub differing_force_max: f64,
    /// The runs whose error rose with this setting: above [`SLACK`] times the larger of
    /// their errors at the two settings before (and the floor, [`rise_floor`]; two, so that
    /// an error that one setting left small by chance, its parts cancelling, is not taken
    /// for the trend), each with the error it rose from. A run's error is its worst relative
    /// error over the quantities compared ([`run_error`]).
    pub not_converging: Vec<Rise>,
    /// Where storeys yield: median and p99 of the residual drift ratio's error against the
    /// building's peak drift ratio (a residual near 0 has no relative error of its own), then
    /// of the peak ductility's relative error, over the yielding buildings of the runs
    /// compared; a run whose residual is not settled on either side is left out.
    pub yielding: Option<[f64; 4]>,
    /// Runs whose impact counts differ from the reference's (left out of the errors).
    pub impacts_differ: u64,
    /// Runs compared: neither failed, their collapses agree and so do their impact counts
    /// (the errors but the peak force's, which is over those that pound, are over these).
    pub runs_compared: u64,
    /// The buildings' collapses against the reference's, where a run collapsed on either
    /// side (None where none did: the point is what it was before collapses were compared).
    pub collapse: Option<Collapses>,
}

/// A point's collapses against the reference's, building by building
/// ([`building_collapses`]). Agreement is a collapse on both sides in the same storey; its
/// time's error, `|t - t_ref| / t_ref` (relative to the reference's collapse time, as the
/// convergence check takes it), enters the run's error. A collapse on one side only, or in
/// another storey, is a named difference, and the run fails `--target-error`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Collapses {
    /// Collapses compared (both sides, the same building and storey).
    pub compared: u64,
    /// Median and p99 of the collapse time's relative error over them (NaN where none).
    pub time: [f64; 2],
    /// The collapses the two sides disagree on, by run and building.
    pub differs: Vec<CollapseDiff>,
}

/// One building of one run that collapsed on one side only, or in another storey.
#[derive(Debug, Clone, PartialEq)]
pub struct CollapseDiff {
    /// The run's number, as in the sweep's `run` column.
    pub run: u64,
    pub record: String,
    /// The run's intensity in words (`Sa(T) 1.25 g`).
    pub intensity: String,
    /// From 1.
    pub building: u32,
    /// This path's collapse and the reference's.
    pub here: Option<Collapse>,
    pub reference: Option<Collapse>,
}

impl CollapseDiff {
    /// The difference in words, for `path` at `setting` substeps per contact.
    pub fn words(&self, path: &str, setting: f64) -> String {
        let at = |c: &Collapse| format!("storey {} at {:.4} s", c.storey, c.time);
        let what = match (&self.here, &self.reference) {
            (Some(h), None) => format!("collapsed on {path} only ({})", at(h)),
            (None, Some(r)) => format!("collapsed in the reference only ({})", at(r)),
            (Some(h), Some(r)) => format!(
                "collapsed in another storey: {} on {path}, {} in the reference",
                at(h),
                at(r)
            ),
            (None, None) => "no collapse on either side".into(),
        };
        format!(
            "collapse differs at {setting} substeps per contact: run {} (record {}, {}), building {}: {what}",
            self.run, self.record, self.intensity, self.building
        )
    }
}

/// Each building's collapse (None where it stood): the building's own where the run gives
/// them, else the run's first collapse on its building (a run that ended at its first collapse
/// gives no building's own).
pub fn building_collapses(o: &RowOutput) -> Vec<Option<Collapse>> {
    let mut each: Vec<Option<Collapse>> = o.buildings.iter().map(|b| b.collapse).collect();
    if each.iter().all(Option::is_none) {
        if let Some(c) = o.collapse {
            if let Some(slot) = (c.building as usize)
                .checked_sub(1)
                .and_then(|k| each.get_mut(k))
            {
                *slot = Some(c);
            }
        }
    }
    each
}

/// The collapses of `o` against the reference's `t`: the relative time errors of those they
/// agree on, and the buildings (from 1) they disagree on, with each side's collapse.
#[allow(clippy::type_complexity)]
pub(super) fn compare_collapses(
    t: &RowOutput,
    o: &RowOutput,
) -> (Vec<f64>, Vec<(u32, Option<Collapse>, Option<Collapse>)>) {
    let (mut times, mut differ) = (Vec::new(), Vec::new());
    let (ct, co) = (building_collapses(t), building_collapses(o));
    for (k, (a, b)) in co.iter().zip(&ct).enumerate() {
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) if a.storey == b.storey => times.push(rel(a.time, b.time)),
            _ => differ.push((k as u32 + 1, *a, *b)),
        }
    }
    (times, differ)
}

/// An intensity in words: `PGA 0.3 g`, `scale factor 2`, `Sa(T) 1.25 g`, `Sa_avg 0.8 g`.
fn intensity_words(i: &crate::plan::intensity::Intensity) -> String {
    use crate::plan::intensity::Intensity;
    match i {
        Intensity::PgaG(g) => format!("PGA {g} g"),
        Intensity::Scale(s) => format!("scale factor {s}"),
        Intensity::Spectral { g, im } if im.average => format!("Sa_avg {g} g"),
        Intensity::Spectral { g, .. } => format!("Sa(T) {g} g"),
    }
}

/// A run whose error rose from one setting to the next (`pound accuracy` names each).
#[derive(Debug, Clone, PartialEq)]
pub struct Rise {
    /// The run's number, as in the sweep's `run` column.
    pub run: u64,
    pub previous_setting: f64,
    pub previous_error: f64,
    pub error: f64,
}

/// How much a run's error may grow from one setting to the next before it is reported as not
/// converging: the fast scheme's error falls at order 3 to 4, so a rise of 3x is no wobble
/// of an error that converges (the CI check, `tests/it/convergence.rs`, holds every run of its
/// yielding scenes to it).
pub const SLACK: f64 = 3.0;

/// The error below which settings are not told apart against a reference at tolerance `tol`:
/// `100 tol`, and no less than 1e-6 (where the peaks of free record steps, interpolated by a
/// quintic Hermite, the same at every setting, leave the error).
pub fn rise_floor(tol: f64) -> f64 {
    (100.0 * tol).max(1e-6)
}

/// A run's worst relative error against the reference's run: peak force (where it pounds),
/// each building's peak roof displacement, drift ratio and, where storeys yield, ductility
/// and residual drift (against the peak drift), and each collapse's time (relative to the
/// reference's). None where it cannot be compared: either run failed, their collapses differ
/// ([`Collapses`]), or their impact counts do.
pub fn run_error(t: &RowOutput, o: &RowOutput) -> Option<f64> {
    if o.status.failed() || t.status.failed() || t.impacts != o.impacts {
        return None;
    }
    let (times, differ) = compare_collapses(t, o);
    if !differ.is_empty() {
        return None;
    }
    let mut e = if t.impacts > 0 {
        rel(o.peak_force, t.peak_force)
    } else {
        0.0
    };
    e = times.into_iter().fold(e, f64::max);
    for (bt, bo) in t.buildings.iter().zip(&o.buildings) {
        e = e
            .max(rel(bo.peak_roof, bt.peak_roof))
            .max(rel(bo.peak_drift_ratio, bt.peak_drift_ratio));
        if let (Some(yt), Some(yo)) = (bt.inelastic, bo.inelastic) {
            e = e.max(rel(yo.peak_ductility, yt.peak_ductility));
            if yt.residual_drift_ratio.is_finite() && yo.residual_drift_ratio.is_finite() {
                e = e.max(
                    (yo.residual_drift_ratio - yt.residual_drift_ratio).abs()
                        / bt.peak_drift_ratio.max(f64::MIN_POSITIVE),
                );
            }
        }
    }
    Some(e)
}

/// The runs whose error `errors` (per run; None where not compared) rose above [`SLACK`] times
/// the larger of their errors at the last two settings of `before` (each a setting and its
/// errors) and above `floor`.
pub fn rises(before: &[(f64, Vec<Option<f64>>)], errors: &[Option<f64>], floor: f64) -> Vec<Rise> {
    let mut out = Vec::new();
    for (run, e1) in errors.iter().enumerate() {
        let Some(e1) = *e1 else { continue };
        // The larger error of the two settings before, where compared there.
        let Some((previous_setting, e0)) = (before.iter().rev().take(2))
            .filter_map(|(s, e)| e.get(run).copied().flatten().map(|e| (*s, e)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
        else {
            continue;
        };
        if e1 > SLACK * e0.max(floor) {
            out.push(Rise {
                run: run as u64,
                previous_setting,
                previous_error: e0,
                error: e1,
            });
        }
    }
    out
}

/// The further columns of [`row_markdown`] where storeys yield.
pub(super) const YIELDING_COLUMNS: &str =
    " residual drift med | residual drift p99 | ductility med | ductility p99 |";

/// The columns of [`row_markdown`].
pub const ROW_MARKDOWN_HEADER: &str = "| path | substeps/contact | runs/s | force med | force p99 | roof med | roof p99 | drift med | drift p99 | accel med | accel p99 | impacts differ | failed | residual med | residual p99 | count gap max | differing force max | not converging |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";

impl RowPoint {
    /// The p99 that `--target-error` calibrates on rows: the peak force's, and where storeys
    /// yield the largest of the peak force's, drift's, residual drift's and ductility's
    /// (`calibration::Suite::YieldingRows`); where collapses were compared, and the collapse
    /// time's.
    pub fn calibrated_p99(&self) -> f64 {
        let p99s = self.calibrated();
        // NaN (a statistic over no run) wins: no evidence is not a small error.
        if p99s.iter().any(|(_, x)| x.is_nan()) {
            f64::NAN
        } else {
            p99s.into_iter()
                .map(|(_, x)| x)
                .fold(f64::NEG_INFINITY, f64::max)
        }
    }

    /// The statistics [`RowPoint::calibrated_p99`] takes, each named.
    fn calibrated(&self) -> Vec<(&'static str, f64)> {
        let mut p99s = vec![("peak force", self.force[1])];
        if let Some([_, residual, _, ductility]) = self.yielding {
            p99s.extend([
                ("drift", self.drift[1]),
                ("residual drift", residual),
                ("ductility", ductility),
            ]);
        }
        if let Some(c) = self.collapse.as_ref().filter(|c| c.compared > 0) {
            p99s.push(("collapse time", c.time[1]));
        }
        p99s
    }

    /// The statistics of [`RowPoint::calibrated_p99`] over zero runs (no run compared pounded,
    /// or none's residual drift settled), by name.
    pub fn over_no_run(&self) -> Vec<&'static str> {
        (self.calibrated().into_iter())
            .filter(|(_, x)| x.is_nan())
            .map(|(name, _)| name)
            .collect()
    }

    /// The numbers of a table line and a CSV line, in column order after the path.
    fn numbers(&self) -> [f64; 17] {
        [
            self.substeps_per_contact,
            self.runs_per_second,
            self.force[0],
            self.force[1],
            self.roof[0],
            self.roof[1],
            self.drift[0],
            self.drift[1],
            self.accel[0],
            self.accel[1],
            self.impact_count_differs,
            self.failed as f64,
            self.residual[0],
            self.residual[1],
            self.count_gap_max as f64,
            self.differing_force_max,
            self.not_converging.len() as f64,
        ]
    }
}

/// One line of the multi-storey work-precision table.
pub fn row_markdown(p: &RowPoint) -> String {
    let cells: Vec<String> = p
        .numbers()
        .iter()
        .enumerate()
        .map(|(i, x)| match i {
            0 | 11 | 14 | 16 => format!("{x}"),
            1 => format!("{x:.0}"),
            10 => format!("{:.2} %", 100.0 * x),
            _ => figure(*x),
        })
        .collect();
    let mut line = format!("| {} | {} |", p.path, cells.join(" | "));
    for x in p.yielding.iter().flatten() {
        line.push_str(&format!(" {} |", figure(*x)));
    }
    line
}

/// The multi-storey work-precision study: the row sweep `plan` by the reference at `tol`, then
/// by the fast scheme (CPU, energy balance on) at each setting, on the current rayon pool;
/// `each` gets every point as it is measured.
pub fn row_study(
    plan: &crate::plan::row::RowPlan,
    settings: &[f64],
    tol: f64,
    mut each: impl FnMut(&RowPoint),
) -> Vec<RowPoint> {
    use crate::physics::row::RowOutput;
    let solve = |scheme: Scheme| -> (Vec<RowOutput>, f64) {
        let mut p = plan.clone();
        p.contact.spec.scheme = scheme;
        let mut outs = Vec::with_capacity(plan.len() as usize);
        let s = crate::engine::cpu::run_rows(
            &p,
            0..p.len(),
            crate::engine::CPU_CHUNK,
            |rows| -> Result<(), std::convert::Infallible> {
                outs.extend(rows.iter().map(|(_, o)| o.clone()));
                Ok(())
            },
            |_| {},
        )
        .unwrap_or_else(|e| match e {});
        (outs, s.runs_per_second())
    };
    let med_p99 = |mut v: Vec<f64>| median_p99(&mut v);
    let yields = plan.yielding.iter().any(Option::is_some);
    let point = |path: &str, setting: f64, rate: f64, truth: &[RowOutput], out: &[RowOutput]| {
        let (mut f, mut u, mut d, mut a, mut r) = (vec![], vec![], vec![], vec![], vec![]);
        let (mut res, mut mu) = (vec![], vec![]);
        let (mut differ, mut failed) = (0usize, 0u64);
        let (mut gap_max, mut differing_force) = (0u32, 0.0f64);
        let (mut collapse_times, mut collapse_differs) = (Vec::new(), Vec::new());
        let (mut any_collapse, mut runs_compared) = (false, 0u64);
        for (i, (t, o)) in truth.iter().zip(out).enumerate() {
            if o.status == Status::Ok {
                r.extend(o.energy.map(|e| e.residual.abs()));
            }
            if o.status.failed() || t.status.failed() {
                failed += 1;
                continue;
            }
            // Collapses first: one on one side only is a difference whatever the impacts.
            any_collapse |= o.status == Status::Collapsed || t.status == Status::Collapsed;
            let (times, differs) = compare_collapses(t, o);
            if !differs.is_empty() {
                let run = plan.run(i as u64);
                let c = &run.contact;
                collapse_differs.extend(differs.into_iter().map(|(building, here, reference)| {
                    CollapseDiff {
                        run: i as u64,
                        record: plan.contact.spec.records[c.record].name.clone(),
                        intensity: intensity_words(&c.intensity),
                        building,
                        here,
                        reference,
                    }
                }));
                continue;
            }
            collapse_times.extend(times);
            if t.impacts != o.impacts {
                differ += 1;
                gap_max = gap_max.max(t.impacts.abs_diff(o.impacts));
                if t.impacts > 0 && o.impacts > 0 {
                    differing_force = differing_force.max(rel(o.peak_force, t.peak_force));
                }
                continue;
            }
            if t.impacts > 0 {
                f.push(rel(o.peak_force, t.peak_force));
            }
            for (bt, bo) in t.buildings.iter().zip(&o.buildings) {
                u.push(rel(bo.peak_roof, bt.peak_roof));
                d.push(rel(bo.peak_drift_ratio, bt.peak_drift_ratio));
                a.push(rel(bo.peak_accel, bt.peak_accel));
                if let (Some(yt), Some(yo)) = (bt.inelastic, bo.inelastic) {
                    mu.push(rel(yo.peak_ductility, yt.peak_ductility));
                    if yt.residual_drift_ratio.is_finite() && yo.residual_drift_ratio.is_finite() {
                        res.push(
                            (yo.residual_drift_ratio - yt.residual_drift_ratio).abs()
                                / bt.peak_drift_ratio.max(f64::MIN_POSITIVE),
                        );
                    }
                }
            }
            runs_compared += 1;
        }
        let compared = f.len() as u64;
        RowPoint {
            path: path.into(),
            substeps_per_contact: setting,
            runs_per_second: rate,
            force: med_p99(f),
            roof: med_p99(u),
            drift: med_p99(d),
            accel: med_p99(a),
            impact_count_differs: differ as f64 / truth.len().max(1) as f64,
            failed,
            compared,
            residual: med_p99(r),
            count_gap_max: gap_max,
            differing_force_max: differing_force,
            not_converging: Vec::new(),
            yielding: yields.then(|| {
                let ([r0, r1], [m0, m1]) = (med_p99(res), med_p99(mu));
                [r0, r1, m0, m1]
            }),
            impacts_differ: differ as u64,
            runs_compared,
            collapse: any_collapse.then(|| Collapses {
                compared: collapse_times.len() as u64,
                time: med_p99(collapse_times),
                differs: collapse_differs,
            }),
        }
    };
    let (truth, rate) = solve(Scheme::Reference(ReferenceOptions::with_tol(tol)));
    let mut points = vec![point("reference", 0.0, rate, &truth, &truth)];
    each(&points[0]);
    // Each run's errors at the two settings before, to find the runs whose error rises.
    let mut before: Vec<(f64, Vec<Option<f64>>)> = Vec::new();
    let floor = rise_floor(tol);
    for &s in settings {
        let (out, rate) = solve(Scheme::Fast(FastOptions {
            substeps_per_contact: s,
            energy: true,
            ..FastOptions::default()
        }));
        let mut p = point("cpu-fast-f64", s, rate, &truth, &out);
        let errors: Vec<Option<f64>> = (truth.iter().zip(&out))
            .map(|(t, o)| run_error(t, o))
            .collect();
        p.not_converging = rises(&before, &errors, floor);
        before.push((s, errors));
        points.push(p);
        each(points.last().expect("pushed"));
    }
    points
}

/// The multi-storey work-precision plot: runs/s against the median (left) and p99 (right)
/// relative error of each quantity, one line per quantity over the fast scheme's settings and
/// each setting's points marked and named, as the pairs' plot does (errors of 0, which a log
/// axis cannot show, are left out).
pub fn row_panels(points: &[RowPoint]) -> Vec<Panel> {
    type Pick = fn(&RowPoint) -> [f64; 2];
    let quantities: [(&str, Pick); 4] = [
        ("peak force", |p| p.force),
        ("roof displacement", |p| p.roof),
        ("drift ratio", |p| p.drift),
        ("floor acceleration", |p| p.accel),
    ];
    let yielding: [(&str, Pick); 2] = [
        ("residual drift (of the peak drift)", |p| {
            let y = p.yielding.unwrap_or([f64::NAN; 4]);
            [y[0], y[1]]
        }),
        ("ductility", |p| {
            let y = p.yielding.unwrap_or([f64::NAN; 4]);
            [y[2], y[3]]
        }),
    ];
    let extra = if points.iter().any(|p| p.yielding.is_some()) {
        &yielding[..]
    } else {
        &[]
    };
    let settings = distinct_settings(
        points
            .iter()
            .filter(|p| p.path != "reference")
            .map(|p| p.substeps_per_contact),
    );
    let panel = |title: &str, at: usize| {
        // Each quantity's point of `p`.
        let of = |p: &RowPoint, pick: &Pick| (pick(p)[at], p.runs_per_second);
        let fast = || points.iter().filter(|p| p.path != "reference");
        let lines = quantities.iter().chain(extra).map(|(name, pick)| Series {
            name: name.to_string(),
            points: fast()
                .map(|p| of(p, pick))
                .filter(|&(e, _)| e > 0.0)
                .collect(),
            scatter: false,
            style: None,
        });
        let marks = settings.iter().map(|&s| {
            setting_marks(
                s,
                fast()
                    .filter(|p| p.substeps_per_contact == s)
                    .flat_map(|p| {
                        quantities
                            .iter()
                            .chain(extra)
                            .map(move |(_, pick)| of(p, pick))
                    })
                    .filter(|&(e, _)| e > 0.0)
                    .collect(),
            )
        });
        Panel {
            title: title.into(),
            x_label: "relative error".into(),
            y_label: "runs/s".into(),
            log_x: true,
            log_y: true,
            series: lines.chain(marks).collect(),
            y_span: None,
            ..Default::default()
        }
    };
    vec![panel("median error", 0), panel("99th percentile error", 1)]
}

/// The multi-storey study's points as CSV.
pub fn row_csv(points: &[RowPoint]) -> String {
    let mut s = String::from("path,substeps_per_contact,runs_per_s,force_median,force_p99,roof_median,roof_p99,drift_median,drift_p99,accel_median,accel_p99,impact_count_differs,failed,residual_median,residual_p99,count_gap_max,differing_force_max,not_converging");
    if points.iter().any(|p| p.yielding.is_some()) {
        s.push_str(",residual_drift_median,residual_drift_p99,ductility_median,ductility_p99");
    }
    // Where a run collapsed on either side: the collapses compared, their time's relative
    // error (median, p99) and the collapses that differ.
    let collapses = points.iter().any(|p| p.collapse.is_some());
    if collapses {
        s.push_str(",collapses_compared,collapse_time_median,collapse_time_p99,collapses_differ");
    }
    s.push('\n');
    for p in points {
        let mut cells: Vec<String> = p
            .numbers()
            .iter()
            .chain(p.yielding.iter().flatten())
            .map(|x| shown(*x, "", |x| x.to_string()))
            .collect();
        if collapses {
            let c = p.collapse.clone().unwrap_or(Collapses {
                time: [f64::NAN; 2],
                ..Collapses::default()
            });
            cells.push(c.compared.to_string());
            cells.extend(c.time.map(|x| shown(x, "", |x| x.to_string())));
            cells.push(c.differs.len().to_string());
        }
        s.push_str(&format!("{},{}\n", p.path, cells.join(",")));
    }
    s
}

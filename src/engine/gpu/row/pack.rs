//! A chunk of row runs packed for the kernel: each run's parameter and meta blocks, the
//! building models it uses (each stored once), and what its yielding storeys' outputs need
//! beside the kernel's state.

use super::shape::{may_couple, RowShape, P_COLLAPSE};
use crate::engine::gpu::precision::Precision;
use crate::engine::gpu::run::GpuRecords;
use crate::physics::contact::LawKind;
use crate::physics::imk::ImkSpring;
use crate::physics::model::{Forcing, Oscillator};
use crate::physics::propagator::{CoupledPropagator, Propagator};
use crate::physics::shear::ImkRule;
use crate::physics::solver::row::yielding::settle_intervals;
use crate::physics::solver::row::RowModel;
use crate::physics::solver::FastOptions;
use std::collections::HashMap;

/// The building models of a chunk, each stored once.
#[derive(Debug, Default)]
pub(super) struct ModelTable {
    pub(super) reals: Vec<f64>,
    index: HashMap<Vec<u64>, u32>,
}

impl ModelTable {
    fn add(&mut self, block: Vec<f64>) -> u32 {
        let key: Vec<u64> = block.iter().map(|x| x.to_bits()).collect();
        let reals = &mut self.reals;
        *self.index.entry(key).or_insert_with(|| {
            let at = reals.len() as u32;
            reals.extend_from_slice(&block);
            at
        })
    }
}

/// What a yielding storey's outputs need beside the kernel's state: its height and yield
/// drift, and where gravity leans on it (P-Delta) its drift at rest as a combination of its
/// building's plastic drifts (`RowModel::residual_row`).
#[derive(Debug, Clone)]
pub(super) struct StoreyReadout {
    /// Its index among the run's yielding storeys.
    index: usize,
    pub(super) height: f64,
    pub(super) d_y: f64,
    /// Its yield force `k d_y`, N.
    pub(super) yield_force: f64,
    /// The share of it the columns a neighbour's floor strikes carry (1 without
    /// `struck_column_share`): their shear is read against that share of the yield force.
    pub(super) column_share: f64,
    /// An IMK storey's capping strength before any deterioration, N (None: bilinear).
    pub(super) fcap0: Option<f64>,
    leaning: Option<(usize, Vec<f64>)>,
}

impl StoreyReadout {
    fn of(m: &RowModel, s: usize) -> StoreyReadout {
        let sm = &m.storeys[s];
        StoreyReadout {
            index: s,
            height: sm.height,
            d_y: sm.d_y,
            yield_force: sm.k * sm.d_y,
            column_share: (m.levels.iter().filter_map(|l| l.column))
                .find(|c| c.yielding == Some(s))
                .map_or(1.0, |c| c.share),
            fcap0: sm.imk.as_ref().map(ImkSpring::fcap0),
            leaning: (sm.geometric != 0.0).then(|| m.residual_row(s)),
        }
    }

    /// Its drift at rest from the run's plastic drifts `p` (every yielding storey's).
    pub(super) fn residual(&self, p: &[f64]) -> f64 {
        match &self.leaning {
            Some((first, c)) => c.iter().zip(&p[*first..]).map(|(c, p)| c * p).sum(),
            None => p[self.index],
        }
    }
}

/// A chunk of row runs packed for the kernel.
#[derive(Debug)]
pub struct PackedRows {
    pub shape: RowShape,
    params: Vec<f64>,
    pub(super) meta: Vec<u32>,
    pub(super) models: ModelTable,
    pub(super) runs: usize,
    /// Each run's yielding storeys, for their outputs.
    pub(super) storey_readouts: Vec<StoreyReadout>,
}

fn law_code(l: LawKind) -> u32 {
    LawKind::ALL.iter().position(|&k| k == l).unwrap() as u32
}

impl PackedRows {
    pub fn new(shape: RowShape) -> PackedRows {
        PackedRows {
            shape,
            params: Vec::new(),
            meta: Vec::new(),
            models: ModelTable::default(),
            runs: 0,
            storey_readouts: Vec::new(),
        }
    }

    pub fn len(&self) -> usize {
        self.runs
    }

    pub fn is_empty(&self) -> bool {
        self.runs == 0
    }

    /// The runs' parameters for a kernel in `precision` (each collapse limit as
    /// [`collapse_param`] gives it).
    pub(super) fn params_in(&self, precision: Precision) -> Vec<f64> {
        let mut params = self.params.clone();
        for run in params.chunks_mut(self.shape.p_stride()) {
            run[P_COLLAPSE] = collapse_param(run[P_COLLAPSE], precision);
        }
        params
    }

    /// Add one run of model `m` (of this chunk's shape) on `forcing`, the `record`-th of `recs`.
    pub fn push(
        &mut self,
        m: &RowModel,
        forcing: &Forcing,
        record: usize,
        recs: &GpuRecords,
        fast: &FastOptions,
    ) {
        let blocks = model_blocks(m, forcing.dt);
        self.push_with_blocks(m, forcing, record, recs, fast, blocks);
    }

    /// [`PackedRows::push`] with the run's model blocks already computed ([`model_blocks`]:
    /// every mode's propagator, the part of packing worth doing on every thread).
    pub(super) fn push_with_blocks(
        &mut self,
        m: &RowModel,
        forcing: &Forcing,
        record: usize,
        recs: &GpuRecords,
        fast: &FastOptions,
        blocks: Vec<Vec<f64>>,
    ) {
        assert_eq!(
            RowShape::of(m),
            self.shape,
            "a chunk holds rows of one shape"
        );
        let dt = forcing.dt;
        let first = m.levels.first().map(|l| l.contact);
        self.params.extend([
            dt,
            forcing.t0,
            forcing.scale,
            fast.substeps_per_contact,
            first.map_or(0.0, |c| c.stiffness),
            first.map_or(0.0, |c| c.damping_ratio),
            m.structural_rate(),
            m.collapse_limit,
        ]);
        let mut gaps = vec![0.0; self.shape.storeys.len() - 1];
        for l in &m.levels {
            gaps[l.buildings.0] = l.gap;
        }
        self.params.extend(gaps);
        // Each level's own stiffness: two points about to become one level take shares of it.
        for l in &m.levels {
            let c = &l.contact;
            self.params
                .extend([c.stiffness, c.damping, c.m_eff, c.tc_coef()]);
        }
        // Each struck storey's stiffness, where a floor strikes a column.
        self.params
            .extend(m.levels.iter().filter_map(|l| l.column.map(|c| c.k)));
        let (offset, len) = recs.record(record);
        debug_assert_eq!(forcing.accel.len(), len as usize);
        self.meta.extend([
            first.map_or(0, |c| law_code(c.kind)),
            offset,
            len,
            forcing.intervals() as u32,
        ]);
        for block in blocks {
            let at = self.models.add(block);
            self.meta.push(at);
        }
        if !m.storeys.is_empty() {
            self.meta.push(settle_intervals(m, forcing) as u32);
            self.storey_readouts
                .extend((0..m.storeys.len()).map(|s| StoreyReadout::of(m, s)));
        }
        self.runs += 1;
    }
}

/// The collapse limit `limit` as the kernel in `precision` compares with it: in f32 the least
/// f32 not below it, so that an f32 peak `d` is below it exactly where `d as f64 < limit` (the
/// host's test of a run's output); round to nearest, it could fall below the limit and end a
/// run at a peak the host keeps.
pub fn collapse_param(limit: f64, precision: Precision) -> f64 {
    match precision {
        Precision::F64 => limit,
        Precision::F32 => {
            let x = limit as f32;
            if (x as f64) < limit {
                x.next_up() as f64
            } else {
                x as f64
            }
        }
    }
}

/// Each building's model block for the kernel at record step `dt`: per mode `w^2`, `2 xi w`,
/// the participation and the exact propagator; the mode shapes, floor masses, storey heights.
pub(super) fn model_blocks(m: &RowModel, dt: f64) -> Vec<Vec<f64>> {
    m.buildings
        .iter()
        .map(|b| {
            let n = b.n();
            let coupled = may_couple(b);
            let springs: Vec<&ImkSpring> = match b.first_storey {
                Some(first) => (m.storeys[first..first + n].iter())
                    .filter_map(|s| s.imk.as_ref())
                    .collect(),
                None => Vec::new(),
            };
            let mut block = Vec::with_capacity(RowShape::model_len(
                n,
                b.first_storey.is_some(),
                coupled,
                !springs.is_empty(),
            ));
            for i in 0..n {
                let k = b.off + i;
                let osc = Oscillator {
                    m: 1.0,
                    k: m.w2[k],
                    c: m.two_xi_w[k],
                };
                let p = Propagator::new(&osc, dt);
                block.extend([
                    m.w2[k],
                    m.two_xi_w[k],
                    m.part[k],
                    p.uu,
                    p.uv,
                    p.ua0,
                    p.ua1,
                    p.vu,
                    p.vv,
                    p.va0,
                    p.va1,
                ]);
            }
            for row in &b.modes.shape {
                block.extend_from_slice(row);
            }
            block.extend_from_slice(&b.masses);
            block.extend_from_slice(&b.heights);
            if let Some(first) = b.first_storey {
                for s in &m.storeys[first..first + n] {
                    block.extend([s.k, s.d_y, s.b, s.geometric]);
                    block.extend_from_slice(&s.modal_row);
                }
            }
            if coupled {
                // The coupling (zero where this run's storeys lean alike) and the exact step of
                // the building's modes over dt with it, as the CPU's CoupledStep takes it.
                let r = b.off..b.off + n;
                let zero = vec![vec![0.0; n]; n];
                block.push(b.modes.coupling.is_some() as u8 as f64);
                let e = b.modes.coupling.as_ref().unwrap_or(&zero);
                for row in e {
                    block.extend_from_slice(row);
                }
                let p = CoupledPropagator::new(
                    &m.w2[r.clone()],
                    &m.two_xi_w[r.clone()],
                    e,
                    &m.part[r],
                    dt,
                );
                let (step, f0, f1) = p.coefficients();
                block.extend_from_slice(step);
                block.extend_from_slice(f0);
                block.extend_from_slice(f1);
            }
            for sp in &springs {
                let rule = match sp.rule {
                    ImkRule::Bilinear => 0.0,
                    ImkRule::PeakOriented => 1.0,
                };
                let (has_et, e_t) = sp.e_t.map_or((0.0, 0.0), |e| (1.0, e));
                block.extend([
                    rule, sp.k, sp.fy, sp.kp, sp.up, sp.upc, sp.fres, sp.uu, has_et, e_t,
                ]);
            }
            debug_assert_eq!(
                block.len(),
                RowShape::model_len(n, b.first_storey.is_some(), coupled, !springs.is_empty())
            );
            block
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In f32 the kernel's limit is the least f32 not below the collapse limit, so an f32
    /// peak is below it exactly where the host finds the peak below the limit; in f64 (or
    /// with no limit) it is the limit.
    #[test]
    fn an_f32_peak_is_below_the_kernels_limit_where_the_host_finds_it_below() {
        // f32 rounds 0.12 down and 0.1 up.
        for limit in [0.1, 0.12, 0.3, 0.04, 1.0] {
            assert_eq!(collapse_param(limit, Precision::F64), limit);
            let x = collapse_param(limit, Precision::F32);
            assert_eq!(x as f32 as f64, x, "{limit}: an f32");
            let x = x as f32;
            let mut d = x.next_down().next_down();
            for _ in 0..5 {
                assert_eq!(d < x, (d as f64) < limit, "{limit}: peak {d}");
                d = d.next_up();
            }
        }
        let none = collapse_param(f64::INFINITY, Precision::F32);
        assert_eq!(none, f64::INFINITY);
    }
}

//! Packing runs into buffers, dispatching the kernel in windows of record intervals, reading
//! back. The work functions take a [`GpuContext`], so tests can pass their own device.

use super::buffers::{bind_group, map_read, read, storage, wait, zeroed};
use super::context::{check_stop, GpuContext, GpuError, Kernel, Stop};
use super::layout::{
    self, Counters, Dispatch, Meta, Params32, Params64, State32, State64, MODE_FREE, NO_RESPONSE,
    STATUS_HANDOFF, STATUS_NON_FINITE, STATUS_OK,
};
use super::precision::Precision;
use super::shared::Start;
use crate::physics::contact::LawKind;
use crate::physics::model::{EnergyBalance, Forcing, Oscillator, Pair, RunOutput, Status};
use crate::physics::propagator::{EnergyForms, Propagator};
use crate::physics::solver::FastOptions;
use std::time::{Duration, Instant};

/// While a stop is watched, the time one dispatch is sized to take, s: a software adapter runs
/// a chunk's dispatch of the whole budget for seconds (lavapipe: about 4 s on
/// `configs/fragility-sa.toml`), and the flag is looked at between dispatches. The budget only
/// splits a run's work between dispatches (the kernels save and resume every state: tests
/// `gpu_chunking_does_not_change_results`, `row_kernel_resumes_between_dispatches`), so the
/// results do not change.
const WATCHED_DISPATCH_S: f64 = 0.2;
/// While a stop is watched, the first dispatch's budget (then sized by the time the last took).
const WATCHED_FIRST_BUDGET: u32 = 4;

/// Settings of the GPU path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuOptions {
    pub precision: Precision,
    /// The scheme's settings (the same as the CPU `fast` path's).
    pub fast: FastOptions,
    /// Units of work (a free record interval, or one piece of an RK4 substep) per run and
    /// dispatch: keeps each dispatch short (drivers reset a GPU that runs one dispatch for
    /// about 2 s). Capped at [`CPU_ADAPTER_BUDGET`] on a software adapter.
    pub units_per_dispatch: u32,
    /// A run whose record step needs more RK4 substeps than this is handed back and finished
    /// on the CPU in f64 (None: [`F32_HANDOFF_SUBSTEPS_PER_STEP`] in f32, never in f64).
    pub handoff_substeps_per_step: Option<u32>,
    /// Runs that differ only in gap and contact law share one free response
    /// ([`super::shared`]), as on the CPU (not with the energy balance).
    pub share_free_response: bool,
}

impl Default for GpuOptions {
    fn default() -> Self {
        GpuOptions {
            precision: Precision::F32,
            fast: FastOptions::default(),
            units_per_dispatch: 4096,
            handoff_substeps_per_step: None,
            share_free_response: true,
        }
    }
}

/// In f32, a state updated `m` times within one record step keeps about `m * 6e-8` of relative
/// rounding per step; past 4,096 substeps per step (stiff, heavily damped contacts such as
/// `zeta` = 125 at e = 0.1) the measured peak errors grow from 1e-3 to 10 %, so such runs go to
/// the CPU (see tests/it/gpu.rs).
pub const F32_HANDOFF_SUBSTEPS_PER_STEP: u32 = 4096;

impl GpuOptions {
    pub fn handoff(&self) -> u32 {
        self.handoff_substeps_per_step
            .unwrap_or(match self.precision {
                Precision::F32 => F32_HANDOFF_SUBSTEPS_PER_STEP,
                Precision::F64 => u32::MAX,
            })
    }
}

/// Bytes of the kernel's tally (`Tally` in fast.wgsl): three u32.
const TALLY_BYTES: usize = 12;

/// Budget cap on CPU (software) adapters: lavapipe ends any loop after about 65,535
/// iterations per invocation without an error, and one unit runs at most 17 loop iterations.
pub const CPU_ADAPTER_BUDGET: u32 = 1024;

/// Where time went in one chunk.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ChunkTimes {
    pub upload: Duration,
    pub kernel: Duration,
    pub readback: Duration,
    /// The kernel's lane tally, summed over dispatches: loop trips that did work (a free
    /// interval or an RK4 piece) and the trips lanes were held for (each workgroup's longest
    /// lane times its size).
    pub lane_units: u64,
    pub lane_slots: u64,
}

/// Every record of a sweep in one buffer, converted to the kernel's precision.
pub struct GpuRecords {
    buffer: wgpu::Buffer,
    offsets: Vec<u32>,
    lens: Vec<u32>,
}

impl GpuRecords {
    /// Offset and length of record `i` in the buffer.
    pub(super) fn record(&self, i: usize) -> (u32, u32) {
        (self.offsets[i], self.lens[i])
    }

    pub(super) fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    pub fn upload(
        ctx: &GpuContext,
        precision: Precision,
        records: &[&[f64]],
    ) -> Result<GpuRecords, GpuError> {
        let mut offsets = Vec::with_capacity(records.len());
        let mut lens = Vec::with_capacity(records.len());
        let mut all: Vec<f64> = Vec::new();
        for r in records {
            offsets.push(all.len() as u32);
            lens.push(r.len() as u32);
            all.extend_from_slice(r);
        }
        if all.is_empty() {
            all.push(0.0);
        }
        let buffer = storage(
            ctx,
            "records",
            &precision.reals(&all),
            wgpu::BufferUsages::empty(),
        )?;
        Ok(GpuRecords {
            buffer,
            offsets,
            lens,
        })
    }
}

fn law_code(l: LawKind) -> u32 {
    LawKind::ALL.iter().position(|&k| k == l).unwrap() as u32
}

/// One run, packed for the kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Packed {
    pub params: Params64,
    pub meta: Meta,
    /// The free-step energy integrals, when the energy balance is asked for.
    pub forms: Option<[f64; layout::FORMS_PER_RUN]>,
    /// Where the run starts when it shares a free response (`meta.response` says which); None:
    /// from rest at the record's start.
    pub start: Option<Start>,
}

/// A chunk's packed runs, and the tables of the free responses some of them share
/// (`share` in `sweep.rs`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PackedChunk {
    pub runs: Vec<Packed>,
    pub shared: Vec<f64>,
    /// The runs track their buildings' peak accelerations (the kernel's `ACCEL` variant).
    pub accel: bool,
}

/// Pack one run: `record` is the index of its record in the [`GpuRecords`] it will run with.
pub fn pack(
    pair: &Pair,
    forcing: &Forcing,
    record: usize,
    recs: &GpuRecords,
    fast: &FastOptions,
) -> Packed {
    let (p1, p2) = (
        Propagator::new(&pair.b1, forcing.dt),
        Propagator::new(&pair.b2, forcing.dt),
    );
    let c = &pair.contact;
    let params = Params64 {
        m1: pair.b1.m,
        c1: pair.b1.c,
        k1: pair.b1.k,
        m2: pair.b2.m,
        c2: pair.b2.c,
        k2: pair.b2.k,
        gap: pair.gap,
        stiffness: c.stiffness,
        damping: c.damping,
        damping_ratio: c.damping_ratio,
        m_eff: c.m_eff,
        tc_coef: c.tc_coef(),
        dt: forcing.dt,
        t0: forcing.t0,
        scale: forcing.scale,
        substeps_per_contact: fast.substeps_per_contact,
        p1_uu: p1.uu,
        p1_uv: p1.uv,
        p1_ua0: p1.ua0,
        p1_ua1: p1.ua1,
        p1_vu: p1.vu,
        p1_vv: p1.vv,
        p1_va0: p1.va0,
        p1_va1: p1.va1,
        p2_uu: p2.uu,
        p2_uv: p2.uv,
        p2_ua0: p2.ua0,
        p2_ua1: p2.ua1,
        p2_vu: p2.vu,
        p2_vv: p2.vv,
        p2_va0: p2.va0,
        p2_va1: p2.va1,
    };
    debug_assert_eq!(forcing.accel.len(), recs.lens[record] as usize);
    let meta = Meta {
        law: law_code(c.kind),
        rec_offset: recs.offsets[record],
        rec_len: recs.lens[record],
        intervals: forcing.intervals() as u32,
        response: NO_RESPONSE,
    };
    let forms = fast.energy.then(|| {
        layout::forms(
            &EnergyForms::new(&pair.b1, forcing.dt),
            &EnergyForms::new(&pair.b2, forcing.dt),
        )
    });
    Packed {
        params,
        meta,
        forms,
        start: None,
    }
}

/// A run's results from its final state (what `Tracker::finish` and `Tracker::energy` do on
/// the CPU; GPU runs start at rest, or on their shared free response); None for a run handed
/// back to the host (`STATUS_HANDOFF`).
pub fn output(
    s: &State64,
    c: &Counters,
    p: &Params64,
    energy: bool,
    accel: bool,
) -> Option<RunOutput> {
    if c.status == STATUS_HANDOFF {
        return None;
    }
    let (mut peak_force, mut impact_velocity) = (s.peak_force, s.impact_velocity);
    if c.mode != MODE_FREE && s.imp_peak > peak_force {
        peak_force = s.imp_peak;
        impact_velocity = s.v0;
    }
    Some(RunOutput {
        status: match c.status {
            STATUS_OK => Status::Ok,
            STATUS_NON_FINITE => Status::NonFinite,
            _ => Status::StepLimit,
        },
        impacts: c.impacts,
        peak_force,
        peak_penetration: s.peak_penetration,
        peak_u1: s.peak_u1,
        peak_u2: s.peak_u2,
        peak_accel: if accel {
            [s.peak_a1, s.peak_a2]
        } else {
            [0.0; 2]
        },
        impact_velocity,
        first_impact: (c.impacts > 0).then_some(s.first_impact),
        contact_time: s.contact_time,
        dissipated_energy: s.dissipated,
        substeps: c.substeps as u64,
        free_steps: c.free_steps as u64,
        shared_steps: c.shared_steps as u64,
        energy: energy.then(|| {
            let b1 = Oscillator {
                m: p.m1,
                k: p.k1,
                c: p.c1,
            };
            let b2 = Oscillator {
                m: p.m2,
                k: p.k2,
                c: p.c2,
            };
            let held = b1.energy(s.u1, s.v1) + b2.energy(s.u2, s.v2);
            EnergyBalance::close(0.0, s.e_in, s.e_damp, s.w, held, s.e_peak)
        }),
    })
}

/// Integrate packed runs over their whole records; results in input order, None for runs
/// handed back to the host (see [`GpuOptions::handoff_substeps_per_step`]).
pub fn run_chunk(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedChunk,
    opts: &GpuOptions,
) -> Result<(Vec<Option<RunOutput>>, ChunkTimes), GpuError> {
    run_chunk_until(ctx, recs, chunk, opts, None)
}

/// [`run_chunk`] watching `stop` ([`integrate_until`]).
pub fn run_chunk_until(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedChunk,
    opts: &GpuOptions,
    stop: Stop<'_>,
) -> Result<(Vec<Option<RunOutput>>, ChunkTimes), GpuError> {
    let runs = &chunk.runs[..];
    if runs.is_empty() {
        return Ok((Vec::new(), ChunkTimes::default()));
    }
    let (done, mut times) = integrate_until(ctx, recs, chunk, opts, stop)?;
    let t = Instant::now();
    let out = read_outputs(ctx, &done, runs, opts, chunk.accel)?;
    times.readback = t.elapsed();
    Ok((out, times))
}

/// A chunk's final states and counters, still on the device.
pub struct Integrated {
    pub states: wgpu::Buffer,
    pub counters: wgpu::Buffer,
    pub runs: u32,
}

/// Integrate packed runs (at least one) over their whole records, leaving the final states on
/// the device.
pub fn integrate(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedChunk,
    opts: &GpuOptions,
) -> Result<(Integrated, ChunkTimes), GpuError> {
    integrate_until(ctx, recs, chunk, opts, None)
}

/// [`integrate`] watching `stop`: looked at before each dispatch, each dispatch then sized to
/// take about [`WATCHED_DISPATCH_S`]; `Err(Interrupted)` once it is raised.
pub fn integrate_until(
    ctx: &GpuContext,
    recs: &GpuRecords,
    chunk: &PackedChunk,
    opts: &GpuOptions,
    stop: Stop<'_>,
) -> Result<(Integrated, ChunkTimes), GpuError> {
    let runs = &chunk.runs[..];
    let mut times = ChunkTimes::default();
    let kernel = ctx.kernel(opts.precision, opts.fast.energy, chunk.accel, stop)?;
    let n = runs.len();
    let t = Instant::now();
    let params: Vec<u8> = match opts.precision {
        Precision::F64 => {
            let v: Vec<Params64> = runs.iter().map(|r| r.params).collect();
            bytemuck::cast_slice(&v).to_vec()
        }
        Precision::F32 => {
            let v: Vec<Params32> = runs.iter().map(|r| Params32::from_f64(&r.params)).collect();
            bytemuck::cast_slice(&v).to_vec()
        }
    };
    let metas: Vec<Meta> = runs.iter().map(|r| r.meta).collect();
    let energy = opts.fast.energy;
    let forms: Vec<f64> = if energy {
        runs.iter()
            .flat_map(|r| r.forms.expect("packed with the energy forms"))
            .collect()
    } else {
        vec![0.0]
    };
    let forms = storage(
        ctx,
        "energy forms",
        &opts.precision.reals(&forms),
        wgpu::BufferUsages::empty(),
    )?;
    let params = storage(ctx, "params", &params, wgpu::BufferUsages::empty())?;
    let metas_buf = storage(
        ctx,
        "metas",
        bytemuck::cast_slice(&metas),
        wgpu::BufferUsages::empty(),
    )?;
    // Runs start from rest (a new buffer is zeroed, which is the zero state and `Counters`),
    // or where their shared free response puts them.
    let (states, counters) = if runs.iter().all(|r| r.start.is_none()) {
        (
            zeroed(
                ctx,
                "states",
                (n * layout::state_bytes(opts.precision)) as u64,
                wgpu::BufferUsages::COPY_SRC,
            )?,
            zeroed(
                ctx,
                "counters",
                (n * size_of::<Counters>()) as u64,
                wgpu::BufferUsages::COPY_SRC,
            )?,
        )
    } else {
        let (states, counters) = initial_states(runs, opts.precision);
        (
            storage(ctx, "states", &states, wgpu::BufferUsages::COPY_SRC)?,
            storage(
                ctx,
                "counters",
                bytemuck::cast_slice(&counters),
                wgpu::BufferUsages::COPY_SRC,
            )?,
        )
    };
    let responses = storage(
        ctx,
        "shared free responses",
        &opts.precision.reals(if chunk.shared.is_empty() {
            &[0.0]
        } else {
            &chunk.shared
        }),
        wgpu::BufferUsages::empty(),
    )?;
    let lists = WorkLists::new(ctx, n)?;
    let bind = |from: &wgpu::Buffer, to: &wgpu::Buffer, label| {
        let buffers = [
            &lists.uniform,
            &params,
            &metas_buf,
            &recs.buffer,
            &states,
            &counters,
            &lists.tally,
            from,
            to,
            &forms,
            &responses,
        ];
        bind_group(ctx, &kernel.layout, label, &buffers)
    };
    let binds = [
        bind(&lists.ids[0], &lists.ids[1], "fast bind group a->b"),
        bind(&lists.ids[1], &lists.ids[0], "fast bind group b->a"),
    ];
    wait(ctx)?;
    times.upload = t.elapsed();
    let budget = opts
        .units_per_dispatch
        .max(1)
        .min(unit_cap(ctx, CPU_ADAPTER_BUDGET));
    let intervals = runs.iter().map(|r| r.meta.intervals as u64).max();
    let max_units = pair_units(intervals.unwrap_or(0), &opts.fast);
    lists.run(
        "fast", ctx, &kernel, &binds, budget, max_units, opts, stop, &mut times,
    )?;
    Ok((
        Integrated {
            states,
            counters,
            runs: n as u32,
        },
        times,
    ))
}

/// On a software adapter, the most units one dispatch may do per run when one unit runs at most
/// `cap` loop trips' worth (see [`CPU_ADAPTER_BUDGET`]); no cap on a real GPU.
pub(super) fn unit_cap(ctx: &GpuContext, cap: u32) -> u32 {
    if ctx.info.device_type == wgpu::DeviceType::Cpu {
        cap.max(1)
    } else {
        u32::MAX
    }
}

/// The buffers of the dispatch loop both integrating stages share: the uniform [`Dispatch`],
/// the tally (runs still active, lane units, lane slots) and the two run-id lists, ping-ponged:
/// a dispatch reads one list and appends the runs it leaves unfinished to the other.
pub(super) struct WorkLists {
    pub uniform: wgpu::Buffer,
    pub tally: wgpu::Buffer,
    pub ids: [wgpu::Buffer; 2],
}

impl WorkLists {
    pub fn new(ctx: &GpuContext, n: usize) -> Result<WorkLists, GpuError> {
        let tally = storage(
            ctx,
            "active runs and lane tally",
            &[0; TALLY_BYTES],
            wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        )?;
        let all: Vec<u32> = (0..n as u32).collect();
        let ids = [
            storage(
                ctx,
                "run ids a",
                bytemuck::cast_slice(&all),
                wgpu::BufferUsages::empty(),
            )?,
            // Written by the first dispatch before any dispatch reads it.
            zeroed(
                ctx,
                "run ids b",
                (n * 4) as u64,
                wgpu::BufferUsages::empty(),
            )?,
        ];
        let uniform = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dispatch"),
            size: size_of::<Dispatch>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(WorkLists {
            uniform,
            tally,
            ids,
        })
    }

    /// Dispatch `kernel` over the active runs, `budget` units each, until none is left; `binds`
    /// read list a (b) and write list b (a). Adds the kernel time and lane tally to `times`.
    /// With a `stop` watched, it is looked at before each dispatch (`Err(Interrupted)`), and
    /// each dispatch's budget (at most `budget`) is sized to take [`WATCHED_DISPATCH_S`].
    /// `max_units`: the most units any run of the chunk can take ([`pair_units`],
    /// `RowShape::max_units`); a device that reports runs active past it is refused
    /// ([`endless`]).
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        label: &str,
        ctx: &GpuContext,
        kernel: &Kernel,
        binds: &[wgpu::BindGroup; 2],
        budget: u32,
        max_units: u64,
        opts: &GpuOptions,
        stop: Stop<'_>,
        times: &mut ChunkTimes,
    ) -> Result<(), GpuError> {
        let t = Instant::now();
        let n = (self.ids[0].size() / 4) as u32;
        let budget = budget.max(1);
        let mut d = Dispatch {
            budget: match stop {
                Some(_) => budget.min(WATCHED_FIRST_BUDGET),
                None => budget,
            },
            nactive: n,
            max_substeps_per_step: opts.fast.max_substeps_per_step,
            max_substeps: opts.fast.max_substeps,
            handoff_substeps_per_step: opts.handoff(),
            ..Default::default()
        };
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tally readback"),
            size: TALLY_BYTES as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // The budgets of the dispatches that left runs active.
        let mut spent = 0u64;
        for parity in (0..2).cycle() {
            check_stop(stop)?;
            let td = Instant::now();
            ctx.queue
                .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&d));
            ctx.queue.write_buffer(&self.tally, 0, &[0; TALLY_BYTES]);
            let groups = (layout::workgroups(d.nactive), 1);
            ctx.dispatch(label, kernel, &binds[parity], groups, |enc| {
                enc.copy_buffer_to_buffer(&self.tally, 0, &staging, 0, TALLY_BYTES as u64)
            });
            let v = map_read(ctx, &staging)?;
            let word =
                |i: usize| u32::from_le_bytes([v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]]);
            ran(label, d.nactive, word(1), word(0))?;
            d.nactive = word(0);
            times.lane_units += word(1) as u64;
            times.lane_slots += word(2) as u64;
            if d.nactive == 0 {
                break;
            }
            spent += d.budget as u64;
            endless(label, spent, max_units)?;
            if stop.is_some() {
                // The next dispatch's budget in proportion to the time this one's took, grown
                // at most 4x at a time (its units may cost more: contacts, substeps).
                let took = td.elapsed().as_secs_f64().max(1e-6);
                let scale = (WATCHED_DISPATCH_S / took).min(4.0);
                d.budget = ((d.budget as f64 * scale) as u32).clamp(1, budget);
            }
        }
        times.kernel += t.elapsed();
        Ok(())
    }
}

/// Check a dispatch's tally: every run it was given does at least one unit of work (its budget
/// is at least 1 and only unfinished runs are listed), and leaves at most as many runs active.
/// A tally of no work (a device that did not run the kernel and left the tally as it was
/// cleared) would otherwise read as "no run active" and end the chunk with unfinished runs
/// taken for finished ones, and more runs than it was given is not a tally at all.
pub(super) fn ran(label: &str, given: u32, units: u32, active: u32) -> Result<(), GpuError> {
    if given > 0 && units == 0 {
        return Err(GpuError::Other {
            message: format!(
                "the {label} kernel did no work in a dispatch of {given} unfinished runs (the device did not run it); its results cannot be trusted"
            ),
        });
    }
    if active > given {
        return Err(GpuError::Other {
            message: format!(
                "the {label} kernel reported {active} runs still active of the {given} it was given; its results cannot be trusted"
            ),
        });
    }
    Ok(())
}

/// Check that runs still active have not done more work than any run can: a lane leaves its
/// run early only where the run ends, so a run active after a dispatch did that dispatch's
/// whole budget, and one active after all of them did `spent` units in all. A device that
/// reports runs active forever would otherwise be dispatched forever.
pub(super) fn endless(label: &str, spent: u64, max_units: u64) -> Result<(), GpuError> {
    match spent > max_units {
        true => Err(GpuError::Other {
            message: format!(
                "the {label} kernel reported runs still active after {spent} units of work each, more than any run of the chunk can take ({max_units}); its results cannot be trusted"
            ),
        }),
        false => Ok(()),
    }
}

/// The most units of work a pair run of at most `intervals` record intervals can take with
/// `fast`'s caps (`shaders/fast.wgsl`, `integrate_run`), doubled for what a count by hand may
/// miss: each interval is begun once (one unit: a free step, its substeps set up, or the end);
/// a piece's unit either takes an RK4 substep (the run ends at `max_substeps + 1`) or only
/// moves to the next substep (at most `max_substeps_per_step` per interval).
pub(super) fn pair_units(intervals: u64, fast: &FastOptions) -> u64 {
    let moves = intervals.saturating_mul(fast.max_substeps_per_step as u64);
    let count = intervals
        .saturating_add(moves)
        .saturating_add(fast.max_substeps as u64 + 1);
    count.saturating_mul(2)
}

/// Each run's state and counters before the first dispatch, the state in `precision`'s bytes:
/// at rest, or at the start its shared free response gives it.
fn initial_states(runs: &[Packed], precision: Precision) -> (Vec<u8>, Vec<Counters>) {
    let (states, counters): (Vec<State64>, Vec<Counters>) = runs
        .iter()
        .map(|r| match r.start {
            None => Default::default(),
            Some(s) => (
                State64 {
                    u1: s.state[0],
                    v1: s.state[1],
                    u2: s.state[2],
                    v2: s.state[3],
                    peak_u1: s.peaks[0],
                    peak_u2: s.peaks[1],
                    peak_a1: s.peaks[2],
                    peak_a2: s.peaks[3],
                    ..Default::default()
                },
                Counters {
                    i: s.i,
                    shared_steps: s.i,
                    ..Default::default()
                },
            ),
        })
        .unzip();
    let bytes = match precision {
        Precision::F64 => bytemuck::cast_slice(&states).to_vec(),
        Precision::F32 => {
            let v: Vec<State32> = states.iter().map(State32::from_f64).collect();
            bytemuck::cast_slice(&v).to_vec()
        }
    };
    (bytes, counters)
}

/// Every run of a chunk read back must have ended (its record integrated, or a status that
/// ends it): one still running would be written as a finished run with part of its record.
pub(super) fn unfinished(cs: &[Counters], runs: &[Packed]) -> Result<(), GpuError> {
    came_back_ended(runs.len(), |k| {
        let (c, end) = (&cs[k], runs[k].meta.intervals);
        (c.status == STATUS_OK && c.i < end).then_some((c.i, end))
    })
}

/// `Err` naming the runs of a chunk of `runs` that came back unfinished (the pair's and the
/// row's checks): `left(k)` is run `k`'s record interval and the one it runs to where it has
/// not ended, `None` where it has.
pub(super) fn came_back_ended(
    runs: usize,
    left: impl Fn(usize) -> Option<(u32, u32)>,
) -> Result<(), GpuError> {
    let mut unended = (0..runs).filter_map(|k| left(k).map(|at| (k, at)));
    let Some((k, (i, end))) = unended.next() else {
        return Ok(());
    };
    Err(GpuError::Other {
        message: format!(
            "{} runs of a chunk of {runs} came back from the device unfinished (the first, chunk run {k}, at record interval {i} of {end}); their results cannot be trusted",
            1 + unended.count()
        ),
    })
}

/// Each run's results from its final state, in input order (None: handed back); `accel`: the
/// runs tracked their peak accelerations.
pub fn read_outputs(
    ctx: &GpuContext,
    done: &Integrated,
    runs: &[Packed],
    opts: &GpuOptions,
    accel: bool,
) -> Result<Vec<Option<RunOutput>>, GpuError> {
    let energy = opts.fast.energy;
    let sbytes = read(ctx, &done.states)?;
    let cbytes = read(ctx, &done.counters)?;
    let cs: &[Counters] = bytemuck::cast_slice(&cbytes);
    unfinished(cs, runs)?;
    let out: Vec<Option<RunOutput>> = match opts.precision {
        Precision::F64 => {
            let ss: &[State64] = bytemuck::cast_slice(&sbytes);
            ss.iter()
                .zip(cs)
                .zip(runs)
                .map(|((s, c), r)| output(s, c, &r.params, energy, accel))
                .collect()
        }
        Precision::F32 => {
            let ss: &[State32] = bytemuck::cast_slice(&sbytes);
            ss.iter()
                .zip(cs)
                .zip(runs)
                .map(|((s, c), r)| output(&s.to_f64(), c, &r.params, energy, accel))
                .collect()
        }
    };
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dispatch that did no work for runs it was given, or a tally of more active runs than
    /// given, is an error, not "every run finished".
    #[test]
    fn a_tally_of_no_work_is_an_error() {
        ran("fast", 5, 5, 3).unwrap();
        ran("fast", 5, 40, 0).unwrap();
        ran("fast", 0, 0, 0).unwrap();
        let e = ran("fast", 5, 0, 0).unwrap_err().to_string();
        assert!(
            e.contains("did no work") && e.contains("--backend cpu"),
            "{e}"
        );
        let e = ran("row", 5, 9, 6).unwrap_err().to_string();
        assert!(e.contains("6 runs still active of the 5"), "{e}");
    }

    /// Runs still active after more units than any run can take are an error, not a dispatch
    /// more; the bound holds a pair run's units.
    #[test]
    fn runs_active_past_every_runs_units_are_an_error() {
        endless("fast", 100, 100).unwrap();
        let e = endless("row", 101, 100).unwrap_err().to_string();
        assert!(
            e.contains("still active after 101 units") && e.contains("(100)"),
            "{e}"
        );
        let fast = FastOptions::default();
        let (i, m) = (1000, fast.max_substeps_per_step as u64);
        assert!(pair_units(i, &fast) > i + i * m + fast.max_substeps as u64);
        assert_eq!(pair_units(u64::MAX, &fast), u64::MAX);
    }

    /// A run read back with its status OK before its record's end is refused, named.
    #[test]
    fn a_run_read_back_unfinished_is_an_error() {
        let run = |intervals| Packed {
            params: Params64::default(),
            meta: Meta {
                intervals,
                ..Meta::default()
            },
            forms: None,
            start: None,
        };
        let c = |status, i| Counters {
            status,
            i,
            ..Counters::default()
        };
        let runs = [run(10), run(10), run(10)];
        unfinished(
            &[
                c(STATUS_OK, 10),
                c(STATUS_NON_FINITE, 3),
                c(STATUS_HANDOFF, 0),
            ],
            &runs,
        )
        .unwrap();
        let e = unfinished(&[c(STATUS_OK, 10), c(STATUS_OK, 4), c(STATUS_OK, 0)], &runs)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("2 runs of a chunk of 3")
                && e.contains("chunk run 1, at record interval 4 of 10"),
            "{e}"
        );
    }
}

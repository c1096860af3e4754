//! `--aggregate` on the device (`shaders/aggregate.wgsl`): a chunk's final states are folded
//! into per-group partials and histograms where they were computed, so a sweep reads back
//! kilobytes per chunk instead of a state per run.

use super::buffers::{bind_group, read, read_prefix, storage, zeroed};
use super::context::{GpuContext, GpuError};
use super::layout::{self, AggConfig, Segment, PART_R, PART_U, SLOT_WORDS};
use super::precision::Precision;
use super::run::Integrated;
use crate::engine::aggregate::{Aggregator, Partial, MAX_EXCEED};
use std::collections::HashMap;

/// Histogram slots the device keeps by default (one per group; 89 kB each). More groups than
/// this since the last flush flush the slots to the host; a chunk with more groups than this
/// is folded on the host.
pub const DEFAULT_SLOTS: u32 = 1024;

const SLOT_BYTES: u64 = (SLOT_WORDS * 4) as u64;

/// The groups' histograms on the device: a slot per group seen since the last flush. Allocated
/// as groups appear (doubling), up to a cap.
pub struct Slots {
    buffer: Option<wgpu::Buffer>,
    capacity: u32,
    max: u32,
    slot_of: HashMap<u32, u32>,
    /// The group of each slot in use.
    owner: Vec<u32>,
    /// Times the slots were read back and cleared before the end.
    pub flushes: u32,
}

impl Slots {
    /// At most `max_slots`, and no more than one buffer binding holds.
    pub fn new(ctx: &GpuContext, max_slots: u32) -> Slots {
        let l = ctx.device.limits();
        let by_binding = l.max_storage_buffer_binding_size.min(l.max_buffer_size) / SLOT_BYTES;
        Slots {
            buffer: None,
            capacity: 0,
            max: max_slots.clamp(1, by_binding.min(u32::MAX as u64) as u32),
            slot_of: HashMap::new(),
            owner: Vec::new(),
            flushes: 0,
        }
    }

    pub fn max(&self) -> u32 {
        self.max
    }

    /// Slots for the distinct `groups` of a chunk, flushing the slots into `agg` first when
    /// the new groups do not fit; None when the chunk alone has more groups than slots.
    pub fn assign(
        &mut self,
        ctx: &GpuContext,
        groups: &[u32],
        agg: &mut Aggregator,
    ) -> Result<Option<Vec<u32>>, GpuError> {
        if groups.len() > self.max as usize {
            return Ok(None);
        }
        let fresh = |s: &Slots| groups.iter().filter(|g| !s.slot_of.contains_key(g)).count();
        if self.owner.len() + fresh(self) > self.max as usize {
            self.flush(ctx, agg)?;
        }
        let need = (self.owner.len() + fresh(self)) as u32;
        if need > self.capacity {
            self.grow(ctx, need)?;
        }
        let (slot_of, owner) = (&mut self.slot_of, &mut self.owner);
        Ok(Some(
            groups
                .iter()
                .map(|&g| {
                    *slot_of.entry(g).or_insert_with(|| {
                        owner.push(g);
                        owner.len() as u32 - 1
                    })
                })
                .collect(),
        ))
    }

    fn grow(&mut self, ctx: &GpuContext, need: u32) -> Result<(), GpuError> {
        let capacity = need.max(2 * self.capacity).max(16).min(self.max);
        let bytes = capacity as u64 * SLOT_BYTES;
        let buffer = zeroed(
            ctx,
            "aggregate histograms",
            bytes,
            wgpu::BufferUsages::COPY_SRC,
        )?;
        if let (Some(old), used) = (&self.buffer, self.owner.len() as u64 * SLOT_BYTES) {
            if used > 0 {
                ctx.submit("aggregate histograms grow", |enc| {
                    enc.copy_buffer_to_buffer(old, 0, &buffer, 0, used)
                });
            }
        }
        self.buffer = Some(buffer);
        self.capacity = capacity;
        Ok(())
    }

    /// Read every slot in use back into `agg`, and clear them.
    pub fn flush(&mut self, ctx: &GpuContext, agg: &mut Aggregator) -> Result<(), GpuError> {
        let (Some(buffer), false) = (&self.buffer, self.owner.is_empty()) else {
            return Ok(());
        };
        let used = self.owner.len() as u64 * SLOT_BYTES;
        let bytes = read_prefix(ctx, buffer, used)?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        for (slot, &g) in self.owner.iter().enumerate() {
            agg.group(g)
                .add_histogram(&words[slot * SLOT_WORDS..(slot + 1) * SLOT_WORDS]);
        }
        ctx.submit("aggregate histograms clear", |enc| {
            enc.clear_buffer(buffer, 0, Some(used))
        });
        self.slot_of.clear();
        self.owner.clear();
        self.flushes += 1;
        Ok(())
    }
}

/// Fold an integrated chunk on the device: `segments` cover its runs (packed sorted by group),
/// their slots assigned by [`Slots::assign`]; `thresholds` are the `--exceed` (output index,
/// threshold) pairs. Returns each segment's partial (the histograms stay in the slots) and the
/// chunk indices of the runs handed back, to finish on the CPU.
pub fn reduce(
    ctx: &GpuContext,
    done: &Integrated,
    precision: Precision,
    segments: &[Segment],
    thresholds: &[(usize, f64)],
    slots: &Slots,
) -> Result<(Vec<Partial>, Vec<u32>), GpuError> {
    assert!(thresholds.len() <= MAX_EXCEED, "checked by Aggregator::new");
    let (Some(hist), false) = (&slots.buffer, segments.is_empty()) else {
        return Ok((Vec::new(), Vec::new()));
    };
    let kernel = ctx.aggregator(precision)?;
    let nseg = segments.len();
    let mut cfg = AggConfig {
        nseg: nseg as u32,
        nexceed: thresholds.len() as u32,
        ..Default::default()
    };
    let mut limits = vec![0.0; MAX_EXCEED];
    for (k, &(o, t)) in thresholds.iter().enumerate() {
        cfg.exceed_output[k] = o as u32;
        limits[k] = t;
    }
    let none = wgpu::BufferUsages::empty();
    let src = wgpu::BufferUsages::COPY_SRC;
    let cfg_buf = storage(ctx, "aggregate config", bytemuck::bytes_of(&cfg), none)?;
    let limits = storage(ctx, "aggregate thresholds", &precision.reals(&limits), none)?;
    let segs = storage(ctx, "segments", bytemuck::cast_slice(segments), none)?;
    let part_u = zeroed(ctx, "partial counts", (nseg * PART_U * 4) as u64, src)?;
    let part_r = zeroed(
        ctx,
        "partial reals",
        (nseg * PART_R * precision.bytes()) as u64,
        src,
    )?;
    let handoffs = zeroed(ctx, "handed-back runs", (done.runs as u64 + 1) * 4, src)?;
    let buffers = [
        &cfg_buf,
        &limits,
        &segs,
        &done.states,
        &done.counters,
        &part_u,
        &part_r,
        hist,
        &handoffs,
    ];
    let bind = bind_group(ctx, &kernel.layout, "aggregate bind group", &buffers);
    let (x, y) = layout::segment_grid(
        nseg as u32,
        ctx.device.limits().max_compute_workgroups_per_dimension,
    );
    ctx.dispatch("aggregate", &kernel, &bind, (x, y), |_| {});
    let ubytes = read(ctx, &part_u)?;
    let rbytes = read(ctx, &part_r)?;
    let r: Vec<f64> = match precision {
        Precision::F64 => bytemuck::cast_slice(&rbytes).to_vec(),
        Precision::F32 => bytemuck::cast_slice::<u8, f32>(&rbytes)
            .iter()
            .map(|&v| v as f64)
            .collect(),
    };
    let u: &[u32] = bytemuck::cast_slice(&ubytes);
    let partials = (0..nseg).map(|k| layout::partial(u, &r, k)).collect();
    let n = read_prefix(ctx, &handoffs, 4)?;
    let n = u32::from_le_bytes([n[0], n[1], n[2], n[3]]) as u64;
    let handed = if n == 0 {
        Vec::new()
    } else {
        let list = read_prefix(ctx, &handoffs, 4 * (n + 1))?;
        bytemuck::cast_slice::<u8, u32>(&list)[1..].to_vec()
    };
    Ok((partials, handed))
}

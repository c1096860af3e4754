//! Device buffers: storage buffers made zeroed or from bytes, bind groups of whole buffers,
//! waiting on the queue and reading buffers back; shared by every kernel's host side.

use super::context::{GpuContext, GpuError};

/// A storage buffer of `size` bytes left as wgpu creates it: zeroed (no upload).
pub(super) fn zeroed(
    ctx: &GpuContext,
    label: &str,
    size: u64,
    extra: wgpu::BufferUsages,
) -> Result<wgpu::Buffer, GpuError> {
    buffer(ctx, label, size.max(4), extra, &[])
}

pub(super) fn storage(
    ctx: &GpuContext,
    label: &str,
    bytes: &[u8],
    extra: wgpu::BufferUsages,
) -> Result<wgpu::Buffer, GpuError> {
    buffer(ctx, label, bytes.len() as u64, extra, bytes)
}

/// A storage buffer of `size` bytes holding `contents` (its first bytes; the rest zero), out of
/// memory reported as an error.
fn buffer(
    ctx: &GpuContext,
    label: &str,
    size: u64,
    extra: wgpu::BufferUsages,
    contents: &[u8],
) -> Result<wgpu::Buffer, GpuError> {
    let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    // Not `create_buffer_init`: a buffer mapped at creation panics on a lost device, and a
    // lost device must come back as an error.
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
        mapped_at_creation: false,
    });
    if !contents.is_empty() {
        ctx.queue.write_buffer(&buffer, 0, contents);
    }
    if pollster::block_on(scope.pop()).is_some() {
        return Err(GpuError::OutOfMemory {
            what: label.to_string(),
            bytes: size,
        });
    }
    Ok(buffer)
}

/// A bind group of whole buffers, bound in order (binding `i` is `buffers[i]`).
pub(super) fn bind_group(
    ctx: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

pub(super) fn wait(ctx: &GpuContext) -> Result<(), GpuError> {
    ctx.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Other {
            message: e.to_string(),
        })?;
    match ctx.take_error() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Map a MAP_READ buffer whose copy has been submitted, wait, and return its bytes.
pub(super) fn map_read(ctx: &GpuContext, staging: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let failed = |e: String| GpuError::Other {
        message: format!("reading results back: {e}"),
    };
    let (tx, rx) = std::sync::mpsc::channel();
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, move |r| drop(tx.send(r)));
    wait(ctx)?;
    rx.recv()
        .map_err(|e| failed(e.to_string()))?
        .map_err(|e| failed(e.to_string()))?;
    let data = staging
        .slice(..)
        .get_mapped_range()
        .map_err(|e| failed(e.to_string()))?
        .to_vec();
    staging.unmap();
    Ok(data)
}

pub(super) fn read(ctx: &GpuContext, src: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    read_prefix(ctx, src, src.size())
}

/// The first `size` bytes of a buffer (a multiple of 4).
pub(super) fn read_prefix(
    ctx: &GpuContext,
    src: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>, GpuError> {
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    ctx.submit("readback copy", |enc| {
        enc.copy_buffer_to_buffer(src, 0, &staging, 0, size)
    });
    map_read(ctx, &staging)
}

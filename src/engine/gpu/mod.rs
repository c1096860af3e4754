//! The GPU engine, host side: the `fast` scheme as a WGSL compute shader (`shaders/fast.wgsl`),
//! one invocation per run, and the `--aggregate` fold on the device (`shaders/aggregate.wgsl`).
//!
//! - [`buffers`]: storage buffers, bind groups, waiting and reading back;
//! - [`context`]: adapter, device, queue and compiled pipelines, acquired apart from the work;
//! - [`layout`]: the `#[repr(C)]` buffer types both sides share (checked against the WGSL by naga);
//! - [`precision`]: f32 or f64 on the device;
//! - [`shader`]: the WGSL text with its constants filled in from Rust;
//! - [`run`]: packing runs, dispatching, reading back one chunk;
//! - [`row`]: rows of multi-storey buildings (`shaders/row.wgsl`), packed, dispatched, read back;
//! - [`shared`]: the free responses runs of a chunk share, packed for the kernel;
//! - [`sweep`]: a range of runs chunk after chunk; [`fold`] and [`reduce`]: the device fold.
//!
//! May import the physics, the plan and [`crate::engine::aggregate`]; never io or studies.

pub mod buffers;
pub mod context;
pub mod fold;
pub mod layout;
pub mod precision;
pub mod reduce;
pub mod row;
pub mod run;
pub mod shader;
pub mod shared;
pub mod sweep;

pub use context::{GpuContext, GpuError, Stop};
pub use precision::Precision;
pub use run::{
    integrate, integrate_until, output, pack, read_outputs, run_chunk, run_chunk_until, ChunkTimes,
    GpuOptions, GpuRecords, Integrated, PackedChunk,
};
pub use sweep::GpuTimes;

//! The GPU path: the `fast` scheme as a WGSL compute shader (`shaders/fast.wgsl`), one
//! invocation per run.

pub mod context;
pub mod layout;
pub mod reduce;
pub mod run;
pub mod shader;

pub use context::{GpuContext, GpuError};
pub use run::{
    integrate, output, pack, read_outputs, run_chunk, ChunkTimes, GpuOptions, GpuRecords,
    Integrated,
};
pub use shader::Precision;

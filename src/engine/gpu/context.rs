//! Device acquisition and the long-lived GPU objects (device, queue, pipelines), kept apart from
//! the work functions so tests can bring their own device.

use super::layout::{Counters, Dispatch, Meta};
use super::precision::Precision;
use super::shader::{aggregate_source, fast_source};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

/// What went wrong on the GPU path; each message says what to do next.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter found ({detail}); install a Vulkan driver (for a software one: apt-get install mesa-vulkan-drivers libvulkan1) or run with --backend cpu")]
    NoAdapter { detail: String },
    #[error("GPU adapter `{adapter}` refused a device: {source}; run with --backend cpu")]
    RequestDevice {
        adapter: String,
        source: wgpu::RequestDeviceError,
    },
    #[error("GPU adapter `{adapter}` has no f64 shader support (SHADER_F64); use --precision f32 or --backend cpu")]
    NoF64 { adapter: String },
    #[error("the {precision} shader failed to compile on `{adapter}`: {message}; run with --backend cpu and report this")]
    Shader {
        adapter: String,
        precision: &'static str,
        message: String,
    },
    #[error("GPU out of memory allocating {what} ({bytes} bytes); use a smaller --chunk or --backend cpu")]
    OutOfMemory { what: String, bytes: u64 },
    #[error("the GPU device was lost ({reason}); rows already written are kept; rerun with --backend cpu or a smaller --chunk")]
    DeviceLost { reason: String },
    #[error("GPU error: {message}; run with --backend cpu")]
    Other { message: String },
    /// The caller raised the stop flag it watches ([`crate::engine::Engine::sweep_until`]):
    /// not a fault; the command line never raises it.
    #[error("stopped: the sweep's stop flag was raised")]
    Interrupted,
}

/// A stop flag a GPU path watches (between dispatches, while a kernel is built, and between the
/// runs it finishes on the host), or None: never stopped, dispatches of the whole budget (the
/// command line).
pub type Stop<'a> = Option<&'a AtomicBool>;

/// Has the watched flag been raised?
pub(crate) fn stopped(stop: Stop<'_>) -> bool {
    stop.is_some_and(|s| s.load(Ordering::Relaxed))
}

/// `Err(Interrupted)` once the watched flag is raised.
pub(crate) fn check_stop(stop: Stop<'_>) -> Result<(), GpuError> {
    match stopped(stop) {
        true => Err(GpuError::Interrupted),
        false => Ok(()),
    }
}

/// How often a watched kernel build looks at the stop flag.
const BUILD_POLL: Duration = Duration::from_millis(15);

/// One adapter as `pound gpu info` lists it.
#[derive(Debug, Clone)]
pub struct AdapterSummary {
    pub info: wgpu::AdapterInfo,
    pub f64: bool,
    pub limits: wgpu::Limits,
}

fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    wgpu::Instance::new(desc)
}

/// Every adapter the instance finds.
pub fn adapters() -> Vec<AdapterSummary> {
    let inst = instance();
    pollster::block_on(inst.enumerate_adapters(wgpu::Backends::all()))
        .into_iter()
        .map(|a| AdapterSummary {
            info: a.get_info(),
            f64: a.features().contains(wgpu::Features::SHADER_F64),
            limits: a.limits(),
        })
        .collect()
}

/// A compiled kernel with its bind-group layout.
pub struct Kernel {
    pub pipeline: wgpu::ComputePipeline,
    pub layout: wgpu::BindGroupLayout,
}

/// A compiled stage and variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Stage {
    /// `fast.wgsl`, with or without the energy balance and the peak accelerations.
    Fast { energy: bool, accel: bool },
    /// `aggregate.wgsl`.
    Aggregate,
    /// `row.wgsl` for one row shape (a hash of its WGSL constants); `loops`: the shape's
    /// functions as loops (`shaders/row_loops.wgsl`), not written out.
    Row { hash: u64, loops: bool },
}

type KernelKey = (Stage, Precision);
/// The kernels built, each with its key.
type Kernels = Vec<(KernelKey, Arc<Kernel>)>;

/// Device, queue and compiled kernels, created once per process (or per test).
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Errors reported outside an explicit check (validation, out of memory, device loss).
    errors: Arc<Mutex<Option<GpuError>>>,
    /// Shared with the threads that build kernels for a watched call ([`GpuContext::stage`]).
    kernels: Arc<Mutex<Kernels>>,
}

impl GpuContext {
    /// The default adapter (high performance), with f64 enabled where it is supported.
    pub fn new() -> Result<GpuContext, GpuError> {
        let inst = instance();
        let adapter = pollster::block_on(inst.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| GpuError::NoAdapter {
            detail: e.to_string(),
        })?;
        let info = adapter.get_info();
        let features = adapter.features() & wgpu::Features::SHADER_F64;
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pounding"),
            required_features: features,
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|source| GpuError::RequestDevice {
            adapter: info.name.clone(),
            source,
        })?;
        Ok(GpuContext::from_device(device, queue, info))
    }

    /// A software adapter (Mesa's lavapipe, type Cpu): it runs the shader on the CPU's own
    /// cores, slower than the CPU path there, so `--backend auto` passes it by.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Wrap a device the caller created (tests, embedding applications).
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let errors: Arc<Mutex<Option<GpuError>>> = Arc::default();
        let slot = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            let err = match e {
                wgpu::Error::OutOfMemory { .. } => GpuError::OutOfMemory {
                    what: "a buffer".into(),
                    bytes: 0,
                },
                other => GpuError::Other {
                    message: other.to_string(),
                },
            };
            slot.lock().unwrap().get_or_insert(err);
        }));
        let slot = errors.clone();
        // A loss explains any validation errors that follow it, so it replaces them.
        device.set_device_lost_callback(move |reason, message| {
            *slot.lock().unwrap() = Some(GpuError::DeviceLost {
                reason: format!("{reason:?}: {message}"),
            });
        });
        GpuContext {
            device,
            queue,
            info,
            errors,
            kernels: Arc::default(),
        }
    }

    pub fn supports_f64(&self) -> bool {
        self.device.features().contains(wgpu::Features::SHADER_F64)
    }

    /// A one-line description: name, backend, type.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// The first error reported since the last check, if any.
    pub fn take_error(&self) -> Option<GpuError> {
        self.errors.lock().unwrap().take()
    }

    /// Record commands into one encoder named `label` and submit them.
    pub fn submit(&self, label: &str, record: impl FnOnce(&mut wgpu::CommandEncoder)) {
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        record(&mut enc);
        self.queue.submit([enc.finish()]);
    }

    /// Submit one pass of `kernel` over `groups` workgroups (x, y) with `bind`, followed by
    /// whatever `then` records (copies of its results).
    pub fn dispatch(
        &self,
        label: &str,
        kernel: &Kernel,
        bind: &wgpu::BindGroup,
        (x, y): (u32, u32),
        then: impl FnOnce(&mut wgpu::CommandEncoder),
    ) {
        self.submit(label, |enc| {
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(label),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&kernel.pipeline);
                pass.set_bind_group(0, bind, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
            then(enc);
        });
    }

    /// The fast-scheme kernel in `precision`, with or without the energy balance and the
    /// buildings' peak accelerations, compiled on first use; `stop` watched while it is built
    /// ([`GpuContext::stage`]).
    pub fn kernel(
        &self,
        precision: Precision,
        energy: bool,
        accel: bool,
        stop: Stop<'_>,
    ) -> Result<Arc<Kernel>, GpuError> {
        let stage = Stage::Fast { energy, accel };
        self.stage(
            stage,
            precision,
            || fast_source(precision, energy, accel),
            stop,
        )
    }

    /// The aggregation stage in `precision`, compiled on first use.
    pub fn aggregator(&self, precision: Precision) -> Result<Arc<Kernel>, GpuError> {
        self.stage(
            Stage::Aggregate,
            precision,
            || aggregate_source(precision),
            None,
        )
    }

    /// Kernels built so far and kept for reuse.
    pub fn kernels_built(&self) -> usize {
        self.kernels.lock().unwrap().len()
    }

    /// The kernel of `stage` in `precision`: kept from an earlier call, or built from
    /// `source()`. Unwatched, it is built here, holding the cache, so that calls at once build
    /// it once. Watched, it is built on a thread of its own while this one looks at `stop`
    /// every [`BUILD_POLL`]: a build is one driver call no flag can cut short (lavapipe builds a
    /// row of five's kernel for about 3 s), so once the flag is raised this returns
    /// `Err(Interrupted)` and the build goes on alone; it adds its kernel to the cache whole
    /// when it is done (a later call finds it) and nothing if it fails.
    pub(super) fn stage(
        &self,
        stage: Stage,
        precision: Precision,
        source: impl FnOnce() -> String,
        stop: Stop<'_>,
    ) -> Result<Arc<Kernel>, GpuError> {
        let key = (stage, precision);
        let mut ks = self.kernels.lock().unwrap();
        if let Some(k) = cached(&ks, key) {
            return Ok(k);
        }
        if precision == Precision::F64 && !self.supports_f64() {
            return Err(GpuError::NoF64 {
                adapter: self.info.name.clone(),
            });
        }
        if stop.is_none() {
            let k = Arc::new(compile(
                &self.device,
                &self.info.name,
                stage,
                precision,
                source(),
            )?);
            ks.push((key, k.clone()));
            return Ok(k);
        }
        drop(ks);
        check_stop(stop)?;
        let (tx, rx) = mpsc::channel();
        let (device, adapter) = (self.device.clone(), self.info.name.clone());
        let (kernels, source) = (self.kernels.clone(), source());
        std::thread::Builder::new()
            .name("pound kernel build".into())
            .spawn(move || {
                let built = compile(&device, &adapter, stage, precision, source).map(|k| {
                    let mut ks = kernels.lock().unwrap();
                    // Another call may have built it meanwhile: one kernel per key.
                    cached(&ks, key).unwrap_or_else(|| {
                        let k = Arc::new(k);
                        ks.push((key, k.clone()));
                        k
                    })
                });
                // The caller may have left (stopped): then no one reads it.
                let _ = tx.send(built);
            })
            .map_err(|e| GpuError::Other {
                message: format!("starting a thread to build a kernel: {e}"),
            })?;
        loop {
            match rx.recv_timeout(BUILD_POLL) {
                Ok(built) => return built,
                Err(mpsc::RecvTimeoutError::Timeout) => check_stop(stop)?,
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(GpuError::Other {
                        message: "the thread building a kernel ended without one".into(),
                    })
                }
            }
        }
    }

    /// Most reals of `precision` one storage buffer may hold on this device (the shared free
    /// responses of a chunk, [`super::shared`]).
    pub fn max_buffer_reals(&self, precision: Precision) -> usize {
        let l = self.device.limits();
        let binding = l.max_storage_buffer_binding_size.min(l.max_buffer_size);
        (binding / precision.bytes() as u64) as usize
    }

    /// Largest number of runs one chunk may hold on this device at `precision`.
    pub fn max_runs_per_chunk(&self, precision: Precision) -> u64 {
        let largest = (super::layout::params_bytes(precision))
            .max(super::layout::state_bytes(precision))
            .max(size_of::<Meta>())
            .max(size_of::<Counters>());
        self.runs_fitting(largest)
    }

    /// Largest number of runs one chunk may hold on this device when a run takes at most
    /// `largest` bytes of any one per-run buffer: every such buffer must fit one binding, and
    /// one invocation per run must fit the dispatch grid.
    pub fn runs_fitting(&self, largest: usize) -> u64 {
        let l = self.device.limits();
        let binding = l.max_storage_buffer_binding_size.min(l.max_buffer_size);
        let by_binding = binding / largest.max(1) as u64;
        let by_groups =
            l.max_compute_workgroups_per_dimension as u64 * super::layout::WORKGROUP_SIZE as u64;
        by_binding.min(by_groups)
    }
}

/// The kernel `cached` keeps for `key`.
fn cached(kernels: &[(KernelKey, Arc<Kernel>)], key: KernelKey) -> Option<Arc<Kernel>> {
    kernels
        .iter()
        .find(|(k, _)| *k == key)
        .map(|(_, k)| k.clone())
}

/// Build `stage` in `precision` from `source` on `device` (of `adapter`, named in errors).
fn compile(
    device: &wgpu::Device,
    adapter: &str,
    stage: Stage,
    precision: Precision,
    source: String,
) -> Result<Kernel, GpuError> {
    let d = device;
    let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
    let name = match stage {
        Stage::Fast { .. } => "fast",
        Stage::Aggregate => "aggregate",
        Stage::Row { .. } => "row",
    };
    let label = format!("{name}.wgsl {}", precision.key());
    let desc = wgpu::ShaderModuleDescriptor {
        label: Some(&label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    };
    // Every loop in these shaders counts (a `for` that steps its counter, or a `loop` that
    // spends a budget each pass: `shader::tests::every_loop_counts`), so naga's forced loop
    // bounding (a second counter and exit test in every loop) is left out: on lavapipe it
    // kept loops from unrolling and cost a third of a row sweep's time (BENCHMARKS.md,
    // "Rows on lavapipe: the shape written out"). Except for a row kernel whose shape runs
    // as loops: without the bounding, a 6-storey pair did not finish one run in 50 s on an
    // H200 where it had run with it (BENCHMARKS.md, "Rows on an H200"); on lavapipe the
    // bounding leaves those rows' runs/s as they were, so every adapter builds it alike.
    // Bounds and division checks stay.
    let checks = wgpu::ShaderRuntimeChecks {
        force_loop_bounding: matches!(stage, Stage::Row { loops: true, .. }),
        ..wgpu::ShaderRuntimeChecks::checked()
    };
    // SAFETY: wgpu asks that a shader built without loop bounding never loops forever;
    // every loop of ours ends after a count (above).
    let module = unsafe { d.create_shader_module_trusted(desc, checks) };
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    };
    let storage = |read_only| wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    // Binding order as declared in each shader.
    let entries: Vec<wgpu::BindGroupLayoutEntry> = match stage {
        // row.wgsl binds as fast.wgsl, its building models (read only) at 9, no 10.
        Stage::Fast { .. } | Stage::Row { .. } => vec![
            entry(
                0,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(size_of::<Dispatch>() as u64),
                },
            ),
            entry(1, storage(true)),
            entry(2, storage(true)),
            entry(3, storage(true)),
            entry(4, storage(false)),
            entry(5, storage(false)),
            entry(6, storage(false)),
            entry(7, storage(true)),
            entry(8, storage(false)),
            entry(9, storage(true)),
            entry(10, storage(true)),
        ]
        .into_iter()
        .take(if matches!(stage, Stage::Row { .. }) {
            10
        } else {
            11
        })
        .collect(),
        Stage::Aggregate => (0..9).map(|b| entry(b, storage(b < 5))).collect(),
    };
    let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(&format!("{name} bind group layout")),
        entries: &entries,
    });
    let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&format!("{name} pipeline layout")),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(&format!("{name} pipeline")),
        layout: Some(&pl),
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(GpuError::Shader {
            adapter: adapter.to_string(),
            precision: precision.key(),
            message: e.to_string(),
        });
    }
    Ok(Kernel { pipeline, layout })
}

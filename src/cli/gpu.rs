//! `pound gpu info`: the adapters found.

use anyhow::{bail, Result};

#[derive(clap::Subcommand)]
pub enum Cmd {
    /// List the adapters found: backend, type, f64 support, limits.
    Info,
}

pub fn run(cmd: Cmd) -> Result<()> {
    let Cmd::Info = cmd;
    let all = pounding::engine::gpu::context::adapters();
    if all.is_empty() {
        bail!("no GPU adapters found; install a Vulkan driver (software: apt-get install mesa-vulkan-drivers libvulkan1) or use --backend cpu");
    }
    for a in all {
        let l = &a.limits;
        say!(
            "{} | backend {:?} | type {:?} | driver {} {} | f64 {} | max storage binding {} MiB | max buffer {} MiB | workgroups/dim {}",
            a.info.name,
            a.info.backend,
            a.info.device_type,
            a.info.driver,
            a.info.driver_info,
            if a.f64 { "yes" } else { "no" },
            l.max_storage_buffer_binding_size >> 20,
            l.max_buffer_size >> 20,
            l.max_compute_workgroups_per_dimension
        );
    }
    Ok(())
}

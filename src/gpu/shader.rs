//! WGSL sources and their per-precision prelude.

use super::layout::{FORMS_PER_RUN, WORKGROUP_SIZE};

/// Floating-point precision of the GPU path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Precision {
    F32,
    F64,
}

impl Precision {
    pub fn key(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }

    pub fn from_key(s: &str) -> Option<Precision> {
        match s {
            "f32" => Some(Precision::F32),
            "f64" => Some(Precision::F64),
            _ => None,
        }
    }

    /// Bytes per real.
    pub fn bytes(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }
}

/// The fast-scheme kernel, one file per stage as in `shaders/`.
pub const FAST_WGSL: &str = include_str!("../../shaders/fast.wgsl");

/// `shaders/fast.wgsl` with the prelude for `precision`: the `real` alias, its epsilon, a tiny
/// and a huge number (for degenerate-cubic and finiteness tests), the workgroup size, the reals
/// per run of the `forms` buffer, and `ENERGY`: whether this variant integrates the energy
/// balance. Two variants rather than a uniform branch, because lavapipe compiled the untaken
/// energy code into the free step and lost 30 % of its runs/s (measured with `pound bench`).
pub fn fast_source(precision: Precision, energy: bool) -> String {
    let prelude = match precision {
        Precision::F32 => "alias real = f32;\nconst EPS: real = 1.1920929e-7;\nconst TINY: real = 1e-30;\nconst BIG: real = 1e37;\n",
        Precision::F64 => "alias real = f64;\nconst EPS: real = 2.220446049250313e-16;\nconst TINY: real = 1e-300;\nconst BIG: real = 1e300;\n",
    };
    format!("{prelude}const WG: u32 = {WORKGROUP_SIZE}u;\nconst FORMS: u32 = {FORMS_PER_RUN}u;\nconst ENERGY: bool = {energy};\n{FAST_WGSL}")
}

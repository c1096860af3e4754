//! The GPU path's floating-point precision: its name, its bytes, and reals converted to it.

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

    /// `x` as this precision's reals, in bytes (as the shaders' `array<real>` reads them).
    pub fn reals(self, x: &[f64]) -> Vec<u8> {
        match self {
            Precision::F64 => bytemuck::cast_slice(x).to_vec(),
            Precision::F32 => {
                let v: Vec<f32> = x.iter().map(|&y| y as f32).collect();
                bytemuck::cast_slice(&v).to_vec()
            }
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

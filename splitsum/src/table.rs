//! The BRDF table as a constant. It depends on no environment (only on its size, its
//! method and its masking), so a bake never integrates it twice: the defaults' table
//! (256², quadrature, height-correlated Smith) is embedded, computed by the CPU backend
//! from the shared `lut` functions and written by `bash scripts/dev.sh table`; any other is
//! computed once per process on first use and kept. `tests/lut.rs` checks that the embedded
//! bytes equal a fresh computation bit for bit, and the tables' accuracy against the f64
//! reference as before. On the GPU the table is uploaded, not recomputed, so the GPU's
//! table is the CPU's exactly (the kernels stay for the report's and the tests' GPU-vs-CPU
//! checks). The sheen tables are constants too, embedded the same way.

use crate::backend::Kernels;
use crate::backend::cpu::Cpu;
use crate::error::Result;
use crate::settings::{Job, TableMethod};
use splitsum_shaders::brdf::microfacet::Masking;
use splitsum_shaders::glam::Vec4;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// What a table is a function of.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct TableKey {
    /// Texels per side.
    pub size: u32,
    /// How it is integrated.
    pub method: TableMethod,
    /// Hammersley points per texel (`TableMethod::Sampled` only; 0 otherwise).
    pub samples: u32,
    /// The masking term (`TableMethod::Quadrature`; the sampled table is Smith–Schlick).
    pub masking: Masking,
}

impl TableKey {
    /// The table `job` reads.
    pub fn of(job: &Job) -> Self {
        let samples = if job.lut_method == TableMethod::Sampled { job.lut_samples } else { 0 };
        Self { size: job.lut_size, method: job.lut_method, samples, masking: job.lut_masking }
    }

    /// The table embedded in the library: the defaults'.
    pub const EMBEDDED: TableKey = TableKey { size: 256, method: TableMethod::Quadrature, samples: 0, masking: Masking::SmithCorrelated };
}

impl std::hash::Hash for TableKey {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        (self.size, self.method == TableMethod::Quadrature, self.samples, self.masking as u32).hash(h);
    }
}

/// `(A, B)` per texel of [`TableKey::EMBEDDED`], row by row, as little-endian f32 pairs.
static EMBEDDED_BYTES: &[u8] = include_bytes!("../assets/brdf_table_256_quadrature_correlated.f32");

/// The texels `(A, B, 0, 0)` of the table `key`, computed afresh on the CPU.
pub fn compute(key: TableKey) -> Result<Vec<Vec4>> {
    match key.method {
        TableMethod::Quadrature => Cpu.brdf_table(key.size, key.masking),
        TableMethod::Sampled => Cpu.brdf_lut(key.size, key.samples),
    }
}

/// The embedded table's texels, decoded.
pub fn embedded() -> Vec<Vec4> {
    decode(EMBEDDED_BYTES)
}

/// Texels `(a, b, 0, 0)` from little-endian f32 pairs.
fn decode(bytes: &[u8]) -> Vec<Vec4> {
    bytes
        .chunks_exact(8)
        .map(|p| {
            let a = f32::from_le_bytes([p[0], p[1], p[2], p[3]]);
            let b = f32::from_le_bytes([p[4], p[5], p[6], p[7]]);
            Vec4::new(a, b, 0.0, 0.0)
        })
        .collect()
}

/// `texels` as the embedded file stores them (`(A, B)` as little-endian f32 pairs).
pub fn encode(texels: &[Vec4]) -> Vec<u8> {
    texels.iter().flat_map(|t| [t.x.to_le_bytes(), t.y.to_le_bytes()]).flatten().collect()
}

/// The texels of the table `key`: embedded, already computed in this process, or computed
/// now (once; callers asking for the same table meanwhile wait for it).
pub fn texels(key: TableKey) -> Result<Arc<Vec<Vec4>>> {
    static TABLES: OnceLock<Mutex<HashMap<TableKey, Arc<Vec<Vec4>>>>> = OnceLock::new();
    let mut tables = TABLES.get_or_init(Default::default).lock().unwrap_or_else(|e| e.into_inner());
    if let Some(t) = tables.get(&key) {
        return Ok(t.clone());
    }
    let t = Arc::new(if key == TableKey::EMBEDDED { embedded() } else { compute(key)? });
    tables.insert(key, t.clone());
    Ok(t)
}

pub use crate::product::SHEEN_TABLE_SIZE;

/// The sheen tables as `(Charlie table, sheen albedo)` little-endian f32 pairs per texel,
/// written by `bash scripts/dev.sh table` (a fresh CPU computation takes 3 s on 2 cores).
static SHEEN_BYTES: &[u8] = include_bytes!("../assets/sheen_tables_64.f32");

/// The sheen tables computed afresh on the CPU: `(Charlie table, sheen albedo, 0, 0)` per
/// texel of a [`SHEEN_TABLE_SIZE`]² table (`lut::sheen_texel`).
pub fn compute_sheen() -> Vec<Vec4> {
    Cpu.sheen_tables(SHEEN_TABLE_SIZE)
}

/// The sheen tables a bake uploads: the embedded ones, decoded once per process (`tests/sheen.rs`
/// checks them bit for bit against [`compute_sheen`] and against the f64 reference).
pub fn sheen_texels() -> Arc<Vec<Vec4>> {
    static TABLE: OnceLock<Arc<Vec<Vec4>>> = OnceLock::new();
    TABLE.get_or_init(|| Arc::new(decode(SHEEN_BYTES))).clone()
}

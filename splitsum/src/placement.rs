//! Where each step of a bake runs: one pass over the job before anything runs
//! ([`place`]). A step runs on the backend's device unless a buffer it binds is larger
//! than one storage binding of that device holds (`Kernels::max_binding`); then it runs on
//! the host's CPU with the same shared functions (so the results agree within the
//! GPU-vs-CPU bounds), its input read back and its result uploaded by the bake sequence
//! (`crate::bake`). The executors run what they are given: neither checks or falls back.

use crate::environment::InputShape;
use crate::settings::{Job, Product};
use splitsum_shaders::cubemap::CubeLayout;

/// Where a step runs.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Place {
    /// On the backend's device (the CPU backend's is the CPU).
    Device,
    /// On the host's CPU: a buffer of the step is larger than the device binds.
    Host {
        /// The step's largest buffer, in bytes.
        needs: u64,
        /// What the device binds, in bytes.
        binds: u64,
    },
}

/// Bytes of `texels` RGBA f32 texels.
pub const fn texel_bytes(texels: u64) -> u64 {
    texels * 16
}

/// The largest buffer of resampling a `width`×`height` equirect to a cube of `layout`: its
/// row pyramid, or the cube.
pub fn resampling_buffer(width: u32, height: u32, layout: CubeLayout) -> u64 {
    texel_bytes(splitsum_shaders::equirect::pyramid_len(width, height) as u64).max(texel_bytes(layout.texel_count() as u64))
}

/// The largest buffer of a sum over a source of `source_texels` texels into a cube of
/// `out` (a prefiltered cube, the irradiance): the source, or the partial sums (three
/// texels per texel).
pub fn sums_buffer(source_texels: u64, out: CubeLayout) -> u64 {
    texel_bytes(source_texels).max(3 * texel_bytes(out.texel_count() as u64))
}

/// The largest buffer of `probes` probes over `texels` texels: their input, or their
/// partial sums (three texels per probe).
pub fn probes_buffer(texels: u64, probes: u64) -> u64 {
    texel_bytes(texels + probes).max(3 * texel_bytes(probes))
}

/// The largest storage buffer step `p` of `job` binds on a device, in bytes: the source
/// cube (every step after it reads it whole), a prefiltered cube's or the irradiance's
/// partial sums, the equirect's row pyramid, a table.
pub fn largest_buffer(p: Product, job: &Job) -> u64 {
    let source = job.source_layout();
    let cube = |l: CubeLayout| texel_bytes(l.texel_count() as u64);
    match p {
        Product::SourceCube => match job.input {
            InputShape::Equirect { width, height } => resampling_buffer(width, height, source),
            InputShape::Cube { size } => cube(source).max(cube(CubeLayout::new(size, CubeLayout::full_chain(size)))),
            InputShape::Unknown => cube(source),
        },
        p if p.lobe().is_some() => sums_buffer(source.texel_count() as u64, job.specular_layout()),
        Product::Irradiance => sums_buffer(source.texel_count() as u64, job.irradiance_layout()),
        Product::Sh9 => cube(source),
        Product::BrdfTable => texel_bytes((job.lut_size as u64).pow(2)),
        Product::SheenTables => texel_bytes((crate::product::SHEEN_TABLE_SIZE as u64).pow(2)),
        _ => unreachable!("{p} is a prefiltered cube, matched above"),
    }
}

/// Where a step whose largest buffer is `needs` bytes runs on a device that binds
/// `binds` bytes (`None`: no limit, the CPU).
pub fn place_buffer(needs: u64, binds: Option<u64>) -> Place {
    match binds {
        Some(binds) if needs > binds => Place::Host { needs, binds },
        _ => Place::Device,
    }
}

/// Where step `p` of `job` runs on a device that binds `binds` bytes.
pub fn place(p: Product, job: &Job, binds: Option<u64>) -> Place {
    place_buffer(largest_buffer(p, job), binds)
}

/// Runs `on_device` where `place` says the device, otherwise `on_host`, with a note that
/// `what()` runs on the CPU and why.
pub fn run<T>(place: Place, what: impl FnOnce() -> String, on_device: impl FnOnce() -> T, on_host: impl FnOnce() -> T) -> T {
    match place {
        Place::Device => on_device(),
        Place::Host { .. } => {
            note(&what(), place);
            on_host()
        }
    }
}

/// A note that `what` runs on the CPU and why, for a step placed on the host.
pub fn note(what: &str, place: Place) {
    if let Place::Host { needs, binds } = place {
        crate::progress::note(&format!(
            "note: {what} needs a {:.0} MiB buffer, more than the device binds ({:.0} MiB): running this step on the CPU",
            needs as f64 / 1048576.0,
            binds as f64 / 1048576.0
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::{Products, Settings};

    /// With no limit every step runs on the device; under a limit, exactly the steps whose
    /// largest buffer exceeds it run on the host: the row pyramid of a 4096×2048 equirect
    /// (2 · 4096 · 2048 texels of 16 bytes, 256 MiB) does not fit wgpu's default 128 MiB
    /// binding, while the sums of the default 256², 6-mip specular and sheen cubes
    /// (3 · 6 · (256² + 128² + …) texels, 24 MiB) do; the 64² sheen tables are 64 KiB.
    #[test]
    fn a_step_runs_on_the_host_exactly_where_a_buffer_exceeds_the_binding() {
        let job = Settings::default().resolve(InputShape::Equirect { width: 4096, height: 2048 }, Products::ALL).unwrap();
        for p in Product::ALL {
            assert_eq!(place(p, &job, None), Place::Device, "{p}");
        }
        let mib = 1u64 << 20;
        assert!(matches!(place(Product::SourceCube, &job, Some(128 * mib)), Place::Host { .. }));
        assert_eq!(place(Product::Specular, &job, Some(128 * mib)), Place::Device);
        assert_eq!(place(Product::Sheen, &job, Some(128 * mib)), Place::Device);
        let tiny = Some(1 << 16);
        assert!(Product::ALL.iter().filter(|p| job.products.has(**p)).all(|p| place(*p, &job, tiny) != Place::Device || largest_buffer(*p, &job) <= 1 << 16));
        assert_eq!(place(Product::SheenTables, &job, tiny), Place::Device, "64² texels of 16 bytes: exactly 64 KiB");
    }
}

//! Typed kernel handles: each compute entry point of the generated linkage
//! (`splitsum_spirv::KERNELS`) with the parameter block its shader reads
//! (`splitsum_shaders::kernels`), declared once in `kernels!`. A dispatch is made only
//! through [`Kernel::dispatch`], which takes that block by type: a kernel cannot be handed
//! another kernel's parameters, and the host never spells an entry name, a binding or a
//! workgroup size. Whether a pipeline is built at start-up or on first use is declared here
//! too (`on_demand`: the kernels only tools run). A test checks that every compute entry
//! point of the linkage has exactly one handle.

use super::Dispatch;
use splitsum_shaders::kernels::{
    CalibrateParams, DownsampleParams, EquirectParams, IrradianceParams, LutParams, PrefilterParams, ProbeParams, ReadCubeParams, ResolveParams, RowsParams,
    TableParams,
};
use splitsum_spirv::{self as spirv, EntryPoint};
use std::marker::PhantomData;

/// A compute kernel and the parameter block `P` it reads.
pub struct Kernel<P> {
    /// Its entry point in the linkage.
    pub entry: &'static EntryPoint,
    /// Whether its pipeline is built on first use (`Gpu::ensure`) rather than at start-up.
    pub on_demand: bool,
    params: PhantomData<fn(&P)>,
}

impl<P: bytemuck::Pod> Kernel<P> {
    const fn new(entry: &'static EntryPoint, on_demand: bool) -> Self {
        Self { entry, on_demand, params: PhantomData }
    }

    /// A dispatch of this kernel with `params`, reading `input` (if it reads one) and
    /// writing `output`, over `invocations` (rounded up to whole workgroups).
    pub fn dispatch<'a>(&self, params: &'a P, input: Option<&'a wgpu::Buffer>, output: &'a wgpu::Buffer, invocations: [u32; 3]) -> Dispatch<'a> {
        Dispatch { kernel: self.entry, params: bytemuck::bytes_of(params), input, output, invocations }
    }
}

/// Declares the handles, and [`ALL`]: every kernel's entry point and whether it is built
/// on demand.
macro_rules! kernels {
    ($($(#[$meta:meta])* $name:ident = $entry:ident($params:ty) $(, $on_demand:ident)?;)*) => {
        $(
            $(#[$meta])*
            pub const $name: Kernel<$params> = Kernel::new(&spirv::$entry, kernels!(@demand $($on_demand)?));
        )*
        /// Every kernel: its entry point, and whether its pipeline is built on demand.
        pub const ALL: &[(&EntryPoint, bool)] = &[$(($name.entry, $name.on_demand)),*];
    };
    (@demand on_demand) => { true };
    (@demand) => { false };
}

kernels! {
    /// One level of an equirect's row pyramid.
    EQUIRECT_PYRAMID = KERNELS_EQUIRECT_PYRAMID(EquirectParams);
    /// The source cube's level 0 from the pyramid.
    EQUIRECT_TO_CUBE = KERNELS_EQUIRECT_TO_CUBE(EquirectParams);
    /// One mip of a cube from the one above.
    DOWNSAMPLE = KERNELS_DOWNSAMPLE(DownsampleParams);
    /// A prefiltered level that is the mirror: the source along each texel's direction.
    PREFILTER_MIRROR = KERNELS_PREFILTER_MIRROR(PrefilterParams);
    /// A chunk of a prefiltered level's samples.
    PREFILTER_SAMPLED = KERNELS_PREFILTER_SPECULAR(PrefilterParams);
    /// A chunk of a prefiltered level's exact sum over a source level.
    PREFILTER_EXACT = KERNELS_PREFILTER_EXACT(PrefilterParams);
    /// The excess list of a split source added to a prefiltered cube's sums.
    PREFILTER_BRIGHT = KERNELS_PREFILTER_BRIGHT(PrefilterParams);
    /// The sheen ring of a split source, read from the residual's ring and the excess.
    PREFILTER_TRACED = KERNELS_PREFILTER_TRACED(PrefilterParams);
    /// Means from chunks' partial sums.
    RESOLVE_MEANS = KERNELS_RESOLVE_MEANS(ResolveParams);
    /// A chunk of the irradiance convolution.
    IRRADIANCE_CUBE = KERNELS_IRRADIANCE_CUBE(IrradianceParams);
    /// SH9 partial sums per row of a source level.
    IRRADIANCE_SH9_PROJECT = KERNELS_IRRADIANCE_SH9_PROJECT(IrradianceParams);
    /// Texels packed into halves, row by row (textures on the caller's device).
    PACK_HALF = KERNELS_PACK_HALF(RowsParams);
    /// Rows of a caller's texture unpacked into texels.
    UNPACK_ROWS = KERNELS_UNPACK_ROWS(RowsParams);
    /// Every mip of a caller's cube texture read into texels (`CubeReader`: it binds a
    /// texture and a sampler of the texture's format, so its pipeline is its own).
    READ_CUBE = KERNELS_READ_CUBE(ReadCubeParams), on_demand;
    /// A chunk of the sampled BRDF table's samples.
    BRDF_LUT = KERNELS_BRDF_LUT(LutParams), on_demand;
    /// The sampled table's means.
    RESOLVE_LUT = KERNELS_RESOLVE_LUT(ResolveParams), on_demand;
    /// Rows of the BRDF table by quadrature.
    BRDF_TABLE = KERNELS_BRDF_TABLE(TableParams), on_demand;
    /// The cost model's calibration.
    CALIBRATE = KERNELS_CALIBRATE(CalibrateParams), on_demand;
    /// Probes of the shading for reports and tests.
    PROBE = KERNELS_PROBE(ProbeParams), on_demand;
}

#[cfg(test)]
mod tests {
    /// Every compute entry point of the linkage has exactly one handle, and no handle
    /// names anything else: a kernel added to `shaders/` cannot be dispatched untyped, and
    /// one removed cannot linger here.
    #[test]
    fn every_kernel_of_the_linkage_has_one_typed_handle() {
        let mut handled: Vec<&str> = super::ALL.iter().map(|(e, _)| e.name).collect();
        let mut linked: Vec<&str> = splitsum_spirv::KERNELS.iter().map(|e| e.name).collect();
        handled.sort_unstable();
        linked.sort_unstable();
        assert_eq!(handled, linked);
    }
}

use spirv_builder::{ShaderPanicStrategy, SpirvBuilder};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let shaders: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", "shaders"].iter().collect();
    let mut builder = SpirvBuilder::new(shaders, "spirv-unknown-vulkan1.1");
    builder.build_script.defaults = true;
    builder.shader_panic_strategy = ShaderPanicStrategy::SilentExit;
    let result = builder.build()?;
    let spv = result.module.unwrap_single();
    println!("cargo::rustc-env=SPLITSUM_SPV={}", spv.display());
    Ok(())
}

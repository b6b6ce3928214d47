//! A bake written as a folder: for the `splitsum` target, KTX2 cubes, EXR and PNG views of
//! each product, the SH9 coefficients; for an engine target, the files its engine loads,
//! named and encoded as its own baker writes them (`engine_files`); and always
//! `bake.json` (what was baked, how, from what, and how long it took).

use crate::adjustment::Adjustment;
use crate::bake::{Baked, Timing};
use crate::environment::InputReport;
use crate::error::Result;
use crate::files::{self, Sink};
use crate::ktx1;
use crate::ktx2;
use crate::ktx2::Supercompression;
use crate::preview;
use crate::settings::{Job, Product, Target};
use crate::texture::{Cube, Sh9};
use serde::Serialize;
use splitsum_shaders::choice::Choice;
use splitsum_shaders::half::UFLOAT11_MAX;
use splitsum_shaders::irradiance::{SH9, SH9_COSINE, sh9_polynomial};
use splitsum_shaders::tonemap::Tonemapper;
use std::path::Path;

/// One written file.
#[derive(Clone, Debug, Serialize)]
pub struct OutputFile {
    /// Name inside the output folder.
    pub name: String,
    /// What it holds.
    pub what: String,
    /// How writing it changed values (KTX2 and KTX 1.1 only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub written: Option<ktx2::Written>,
}

/// Where a bake came from, for its `bake.json`: the caller says (`Default` for none).
#[derive(Clone, Debug, Default)]
pub struct About {
    /// The environment, as the caller names it.
    pub environment: String,
    /// The backend it was baked on.
    pub backend: String,
    /// What reading the environment found, if it was read from a file.
    pub input: Option<InputReport>,
}

/// `bake.json`: what was baked, how, from what, and how long it took.
#[derive(Clone, Debug, Serialize)]
pub struct Manifest {
    /// The environment file.
    pub environment: String,
    /// The backend.
    pub backend: String,
    /// Every setting, resolved: the values the bake used.
    pub settings: Job,
    /// Roughness of each specular mip.
    pub roughness_per_mip: Vec<f32>,
    /// GGX samples per texel of each specular mip (mip 0, the mirror, is copied).
    pub samples_per_mip: Vec<u32>,
    /// What the default settings measure end to end (`runner report`), for reference.
    pub accuracy: &'static str,
    /// What reading the environment found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<InputSummary>,
    /// What the bake changed from what it was given (an input reduced or upsampled, a
    /// sample count capped, texels cleaned), each also stated when it ran.
    pub adjustments: Vec<Adjustment>,
    /// Wall time per product.
    pub timings: Vec<Timing>,
    /// How far SH9 irradiance is from the convolution, over the irradiance cube's texels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sh9_vs_convolution: Option<ShError>,
    /// The files.
    pub files: Vec<OutputFile>,
    /// Conventions of the outputs.
    pub conventions: Vec<&'static str>,
}

/// Relative error of SH9 irradiance against the convolution (luminance), over every texel
/// of the irradiance cube.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ShError {
    /// Largest relative error.
    pub max_relative: f64,
    /// Root-mean-square relative error.
    pub rms_relative: f64,
}

/// Compares SH9 irradiance with the irradiance cube texel by texel.
pub(crate) fn sh9_error(sh: &Sh9, irradiance: &Cube) -> ShError {
    use splitsum_shaders::{cubemap, irradiance::sh9_irradiance, tonemap::luminance};
    let coeffs = sh.as_vec4();
    let s = irradiance.layout.size;
    let (mut max, mut sum2, mut n) = (0.0f64, 0.0f64, 0usize);
    for face in 0..6 {
        for y in 0..s {
            for x in 0..s {
                let want = luminance(irradiance.texels[irradiance.layout.index(0, face, x, y) as usize].truncate()) as f64;
                let got = luminance(sh9_irradiance(&coeffs, cubemap::texel_dir(face, x, y, s))) as f64;
                if want > 0.0 {
                    let r = (got - want).abs() / want;
                    max = max.max(r);
                    sum2 += r * r;
                    n += 1;
                }
            }
        }
    }
    ShError { max_relative: max, rms_relative: (sum2 / n.max(1) as f64).sqrt() }
}

/// [`InputReport`] for the manifest.
#[derive(Clone, Debug, Serialize)]
pub struct InputSummary {
    /// Negative values set to 0.
    pub negative_texels: u64,
    /// Values above 10²⁰ clamped.
    pub clamped_texels: u64,
    /// NaN texels (replaced when sanitised).
    pub nan_texels: u64,
    /// Infinite texels (replaced when sanitised).
    pub infinite_texels: u64,
    /// Largest finite value.
    pub max_value: f32,
    /// Width and height of the file (of one face, for a cube).
    pub file_size: (u32, u32),
}

impl From<&InputReport> for InputSummary {
    fn from(r: &InputReport) -> Self {
        Self {
            negative_texels: r.negative,
            clamped_texels: r.clamped,
            nan_texels: r.nan,
            infinite_texels: r.infinite,
            max_value: r.max_value,
            file_size: r.original,
        }
    }
}

/// The SH9 file: radiance coefficients and the `E/π` coefficients derived from them.
#[derive(Serialize)]
struct ShFile<'a> {
    convention: &'a str,
    order: [&'a str; 9],
    radiance: [[f64; 3]; 9],
    irradiance_over_pi: [[f64; 3]; 9],
}

/// Writes the baked products of `job` as the folder `out` (replaced as a unit, and only
/// if everything in it is what splitsum wrote there: `files::OutputDir`), in the files of
/// `job.target`, with `bake.json`. The folder's name names the bake where a target's file
/// names carry it (Filament's `NAME_ibl.ktx`), as cmgen's `--deploy` folder.
pub fn write(out: &Path, baked: &Baked, job: &Job, about: About) -> Result<Manifest> {
    let folder = files::OutputDir::begin(out, "the output folder")?;
    let name = out.file_name().map_or_else(|| "ibl".into(), |n| n.to_string_lossy().into_owned());
    let manifest = write_into(folder.path(), &name, baked, job, about)?;
    folder.commit()?;
    Ok(manifest)
}

internal! {
    /// [`write()`] into the folder `dir` as it is (created if missing), each file atomically and
    /// `bake.json` last.
    pub fn write_into(dir: &Path, name: &str, baked: &Baked, job: &Job, about: About) -> Result<Manifest> {
        files::create_folder(dir)?;
        write_to(&files::Folder(dir), name, baked, job, about)
    }
}

pub use crate::files::Files;

/// The files [`write()`] writes for a folder called `name`, in memory (where there is no
/// file system: a web page), by name, with the manifest. They are the same bytes.
pub fn in_memory(name: &str, baked: &Baked, job: &Job, about: About) -> Result<(Manifest, Files)> {
    let sink = files::Memory::default();
    let manifest = write_to(&sink, name, baked, job, about)?;
    Ok((manifest, sink.into_files()))
}

internal! {
    /// [`write()`] through `sink`, `bake.json` last.
    pub fn write_to(sink: &dyn Sink, name: &str, baked: &Baked, job: &Job, about: About) -> Result<Manifest> {
        let _step = crate::progress::step("writing the files", None);
        let mut manifest = Manifest {
            environment: about.environment,
            backend: about.backend,
            settings: job.clone(),
            roughness_per_mip: job.roughness_per_mip().to_vec(),
            samples_per_mip: job.samples_per_mip.clone(),
            accuracy: DEFAULTS_ACCURACY,
            input: about.input.as_ref().map(InputSummary::from),
            adjustments: Vec::new(),
            timings: baked.timings.clone(),
            sh9_vs_convolution: None,
            files: Vec::new(),
            conventions: target_conventions(job.target).to_vec(),
        };
        manifest.adjustments = about.input.as_ref().map_or_else(Vec::new, |input| input.adjustments_for(job.input));
        manifest.adjustments.extend(job.adjustments());
        if job.target != Target::Splitsum {
            manifest.files = engine_files(sink, name, baked, job)?;
            return write_manifest(sink, manifest);
        }
        // Each file is a job of its own, run on every core at once; the manifest lists them
        // in this order.
        let sky = baked.cube(Product::SourceCube).or(baked.cube(Product::Specular));
        let exposure = sky.map_or(1.0, preview::auto_exposure);
        let jobs: Vec<FileJob<'_>> = baked.products().flat_map(|p| splitsum_files(p, sink, baked, job, exposure)).collect();
        let files_out: Vec<OutputFile> = {
            use rayon::prelude::*;
            jobs.into_par_iter().map(|j| j()).collect::<Result<Vec<_>>>()?.into_iter().flatten().collect()
        };
        manifest.files = files_out;
        if let (Some(sh), Some(irr)) = (baked.sh9(), baked.cube(Product::Irradiance)) {
            manifest.sh9_vs_convolution = Some(sh9_error(sh, irr));
        }
        write_manifest(sink, manifest)
    }
}

/// One file (or a few) of the splitsum folder, written on a core of its own.
type FileJob<'a> = Box<dyn FnOnce() -> Result<Vec<OutputFile>> + Send + 'a>;

/// The files of product `p` in splitsum's folder (`sink`): a prefiltered cube (any lobe) as
/// `KEY.ktx2` with a preview of its mips (and the specular cube's mips as EXR), the
/// irradiance as KTX2, EXR and a preview, SH9 as JSON, each table as EXR (with a preview
/// of the BRDF table), the source cube as a preview; previews at `exposure`.
fn splitsum_files<'a>(p: Product, sink: &'a dyn Sink, baked: &'a Baked, job: &'a Job, exposure: f32) -> Vec<FileJob<'a>> {
    let file = |name: &str, what: String, written: Option<ktx2::Written>| OutputFile { name: name.to_string(), what, written };
    let save_png =
        move |name: &str, pic: &preview::Picture| -> Result<()> { put_png(sink, name, pic.width, pic.height, &pic.to_rgb8(exposure, Tonemapper::Aces)) };
    let mut jobs: Vec<FileJob<'a>> = Vec::new();
    if p.lobe().is_some() {
        let Some(cube) = baked.cube(p) else { return jobs };
        let key = p.key();
        let mapping = job.prefiltered[&p].mapping;
        jobs.push(Box::new(move || {
            let name = format!("{key}.ktx2");
            let w = put_ktx2(sink, &name, cube, job.format, Supercompression::None)?;
            report_clamp(&name, &w);
            Ok(vec![file(
                &name,
                format!("{}, one roughness per mip ({} mapping: settings.prefiltered.{key}.roughness_per_mip)", p.about(), mapping.name()),
                Some(w),
            )])
        }));
        if p == Product::Specular {
            for m in 0..cube.layout.levels {
                jobs.push(Box::new(move || {
                    let name = format!("specular_mip{m}.exr");
                    let what = format!("prefiltered radiance at roughness {}", job.roughness_per_mip()[m as usize]);
                    sink.put(&name, &files::encode_cube_level_exr(Path::new(&name), cube, m, &what)?)?;
                    Ok(vec![file(&name, format!("mip {m} as EXR for inspection"), None)])
                }));
            }
        }
        jobs.push(Box::new(move || {
            let name = format!("preview_{key}.png");
            save_png(&name, &preview::mip_strip(cube, 64))?;
            Ok(vec![file(&name, format!("every {p} mip as a cross, roughness rising to the right"), None)])
        }));
        return jobs;
    }
    match p {
        Product::SourceCube => {
            let Some(source) = baked.cube(p) else { return jobs };
            jobs.push(Box::new(move || {
                save_png("preview_source.png", &preview::cross(source, 0, job.source_size.min(256)))?;
                Ok(vec![file("preview_source.png", "the source cube, tonemapped (ACES, auto exposure), as a cross".into(), None)])
            }));
        }
        Product::Irradiance => {
            let Some(irr) = baked.cube(p) else { return jobs };
            jobs.push(Box::new(move || {
                let w = put_ktx2(sink, "irradiance.ktx2", irr, job.format, Supercompression::None)?;
                report_clamp("irradiance.ktx2", &w);
                sink.put("irradiance.exr", &files::encode_cube_level_exr(Path::new("irradiance.exr"), irr, 0, "irradiance / pi")?)?;
                save_png("preview_irradiance.png", &preview::cross(irr, 0, 64))?;
                Ok(vec![
                    file("irradiance.ktx2", "irradiance divided by π (cosine-weighted mean radiance)".into(), Some(w)),
                    file("irradiance.exr", "the irradiance cube as EXR for inspection".into(), None),
                    file("preview_irradiance.png", "the irradiance cube as a cross".into(), None),
                ])
            }));
        }
        Product::Sh9 => {
            let Some(sh) = baked.sh9() else { return jobs };
            jobs.push(Box::new(move || {
                let file_contents = ShFile {
                    convention: "real SH (Sloan 2008), radiance L_lm = sum L Y_lm dOmega; E(n)/pi = sum (A_l/pi) L_lm Y_lm(n), A_l/pi = 1, 2/3, 1/4",
                    order: ["0,0", "1,-1", "1,0", "1,1", "2,-2", "2,-1", "2,0", "2,1", "2,2"],
                    radiance: sh.radiance,
                    irradiance_over_pi: std::array::from_fn(|k| sh.radiance[k].map(|v| v * SH9_COSINE[k] as f64)),
                };
                let json = serde_json::to_string_pretty(&file_contents).expect("serialisable");
                sink.put("sh9.json", json.as_bytes())?;
                Ok(vec![file("sh9.json", format!("{SH9} spherical-harmonic coefficients of radiance and of E/π"), None)])
            }));
        }
        Product::BrdfTable => {
            let Some(lut) = baked.table(p) else { return jobs };
            jobs.push(Box::new(move || {
                sink.put("brdf_lut.exr", &files::encode_lut_exr(Path::new("brdf_lut.exr"), lut)?)?;
                put_png(sink, "brdf_lut.png", lut.size, lut.size, &files::lut_preview(lut))?;
                Ok(vec![
                    file("brdf_lut.exr", "split-sum BRDF table: R = scale, G = bias; x = n·v, y = roughness".into(), None),
                    file("brdf_lut.png", "its 8-bit preview".into(), None),
                ])
            }));
        }
        Product::SheenTables => {
            let Some(tables) = baked.table(p) else { return jobs };
            jobs.push(Box::new(move || {
                sink.put("sheen_tables.exr", &files::encode_lut_exr(Path::new("sheen_tables.exr"), tables)?)?;
                Ok(vec![file(
                    "sheen_tables.exr",
                    "sheen tables: R = Charlie table (Neubelt visibility; the glTF Sample Viewer's lut_charlie), G = sheen albedo (Charlie visibility; lut_sheen_E); x = n·v, y = sheen roughness".into(),
                    None,
                )])
            }));
        }
        _ => unreachable!("{p} is a prefiltered cube, written above"),
    }
    jobs
}

fn write_manifest(sink: &dyn Sink, manifest: Manifest) -> Result<Manifest> {
    let json = serde_json::to_string_pretty(&manifest).expect("serialisable");
    sink.put("bake.json", json.as_bytes())?;
    Ok(manifest)
}

/// `cube` as KTX2 (`ktx2::encode_with`) stored as `name`, with what writing it changed.
fn put_ktx2(sink: &dyn Sink, name: &str, cube: &Cube, format: crate::texture::Format, sc: Supercompression) -> Result<ktx2::Written> {
    let (bytes, written) = ktx2::encode_with(cube, format, sc);
    sink.put(name, &bytes)?;
    Ok(written)
}

/// 8-bit RGB pixels as a PNG stored as `name`.
fn put_png(sink: &dyn Sink, name: &str, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    sink.put(name, &files::encode_rgb8(Path::new(name), width, height, rgb, files::FileKind::Png)?)
}

/// The files an engine target's loader reads, stored in `sink`: only those (a
/// product the engine does not read is neither baked, see `Target::products`, nor
/// written). The README cites the engine lines that load each.
///
/// - `khronos`: `ggx/specular.ktx2` (RGBA16F, or RGBA32F past 65504 with format `auto`),
///   `lambertian/diffuse.ktx2` (E/π), `charlie/sheen.ktx2`, `lut_ggx.png` (8-bit, R = A,
///   G = B, rows from roughness 0 at the top), `lut_charlie.png` and `lut_sheen_E.png`
///   (8-bit), the names and layout of the glTF Sample Viewer's environments
///   (glTF-Sample-Environments) and its look-up tables.
/// - `bevy`: `specular.ktx2`, `diffuse.ktx2` and `dfg.ktx2` (`R16G16_SFLOAT`, R = A,
///   G = B, Bevy's `DfgLut` layout), every one Zstandard-supercompressed as Bevy's own
///   environment maps.
/// - `filament`: `NAME_ibl.ktx` (specular mips, KTX 1.1 `R11F_G11F_B10F`, SH in its `sh`
///   metadata), `NAME_skybox.ktx` (the source cube's level 0) and `sh.txt`: cmgen
///   `--format=ktx --deploy`.
pub(crate) fn engine_files(sink: &dyn Sink, name: &str, baked: &Baked, job: &Job) -> Result<Vec<OutputFile>> {
    let mut out = Vec::new();
    let mut add = |name: String, what: &str, written: Option<ktx2::Written>| {
        out.push(OutputFile { name, what: what.into(), written });
    };
    let missing = |what: &str| crate::error::Error::Invalid(format!("the {} target needs the {what}, which was not baked", job.target.name()));
    match job.target {
        Target::Splitsum => unreachable!("the splitsum folder is written by output::write"),
        Target::Khronos | Target::Bevy => {
            let khronos = job.target == Target::Khronos;
            let (spec_name, diffuse_name, sc) = if khronos {
                ("ggx/specular.ktx2", "lambertian/diffuse.ktx2", Supercompression::None)
            } else {
                ("specular.ktx2", "diffuse.ktx2", Supercompression::Zstd)
            };
            let spec = baked.cube(Product::Specular).ok_or_else(|| missing("specular cube"))?;
            let w = put_ktx2(sink, spec_name, spec, job.format, sc)?;
            report_clamp(spec_name, &w);
            add(spec_name.into(), "GGX-prefiltered radiance, mip m at perceptual roughness m/(mips-1)", Some(w));
            let irr = baked.cube(Product::Irradiance).ok_or_else(|| missing("irradiance cube"))?;
            let w = put_ktx2(sink, diffuse_name, irr, job.format, sc)?;
            report_clamp(diffuse_name, &w);
            add(diffuse_name.into(), "irradiance divided by pi (Lambertian-filtered radiance)", Some(w));
            let lut = baked.table(Product::BrdfTable).ok_or_else(|| missing("BRDF table"))?;
            if khronos {
                put_png(sink, "lut_ggx.png", lut.size, lut.size, &files::lut_preview(lut))?;
                add("lut_ggx.png".into(), "split-sum table, height-correlated Smith: R = A, G = B (8-bit), x = n.v, y = roughness", None);
                if let Some(sheen) = baked.cube(Product::Sheen) {
                    let w = put_ktx2(sink, "charlie/sheen.ktx2", sheen, job.format, sc)?;
                    report_clamp("charlie/sheen.ktx2", &w);
                    add("charlie/sheen.ktx2".into(), "Charlie-prefiltered radiance (sheen), mip m at sheen roughness m/(mips-1)", Some(w));
                    let t = baked.table(Product::SheenTables).ok_or_else(|| missing("sheen tables"))?;
                    put_png(sink, "lut_charlie.png", t.size, t.size, &files::table_channel_png(t, |v| v.x))?;
                    add(
                        "lut_charlie.png".into(),
                        "Charlie table (sheen albedo with Neubelt's visibility) in every channel (the viewer reads B), 8-bit, values above 1 written as 1; x = n.v, y = sheen roughness",
                        None,
                    );
                    put_png(sink, "lut_sheen_E.png", t.size, t.size, &files::table_channel_png(t, |v| v.y))?;
                    add(
                        "lut_sheen_E.png".into(),
                        "sheen albedo with the Charlie visibility (albedo scaling) in every channel (the viewer reads R), 8-bit, values above 1 written as 1; x = n.v, y = sheen roughness",
                        None,
                    );
                }
            } else {
                sink.put("dfg.ktx2", &ktx2::encode_table(lut, sc))?;
                add(
                    "dfg.ktx2".into(),
                    "split-sum table, height-correlated Smith, R16G16_SFLOAT: R = A, G = B, x = n.v, y = perceptual roughness (Bevy's DfgLut)",
                    None,
                );
            }
        }
        Target::Filament => {
            let sh = baked.sh9().ok_or_else(|| missing("SH9 coefficients"))?;
            let c = sh9_polynomial(&sh.as_vec4());
            let metadata: String = c.iter().map(|v| format!("{} {} {}\n", v.x, v.y, v.z)).collect();
            const NAMES: [&str; SH9] = ["L00", "L1-1", "L10", "L11", "L2-2", "L2-1", "L20", "L21", "L22"];
            let text: String =
                c.iter().zip(NAMES).map(|(v, n)| format!("({:18.15}, {:18.15}, {:18.15}); // {n}, irradiance, pre-scaled base\n", v.x, v.y, v.z)).collect();
            let spec = baked.cube(Product::Specular).ok_or_else(|| missing("specular cube"))?;
            let ibl = format!("{name}_ibl.ktx");
            let (bytes, w) = ktx1::encode(spec, &[("sh", &metadata)]);
            sink.put(&ibl, &bytes)?;
            report_clamp(&ibl, &w);
            add(
                ibl,
                "GGX-prefiltered radiance (KTX 1.1, R11F_G11F_B10F), mip m at perceptual roughness 1 - sqrt(1 - m/(mips-1)); 'sh' metadata: E/pi SH for the shader",
                Some(w),
            );
            let sky = baked.cube(Product::SourceCube).ok_or_else(|| missing("source cube (the skybox)"))?.levels(0, 0);
            let skybox = format!("{name}_skybox.ktx");
            let (bytes, w) = ktx1::encode(&sky, &[]);
            sink.put(&skybox, &bytes)?;
            report_clamp(&skybox, &w);
            add(skybox, "the environment as a cube (KTX 1.1, R11F_G11F_B10F)", Some(w));
            sink.put("sh.txt", text.as_bytes())?;
            add("sh.txt".into(), "E/pi as 9 RGB coefficients of 1, y, z, x, xy, yz, 3z^2-1, xz, x^2-y^2 (cmgen --sh-shader)", None);
        }
    }
    Ok(out)
}

/// The conventions of `target`'s files, stated in its manifest.
pub(crate) fn target_conventions(target: Target) -> &'static [&'static str] {
    match target {
        Target::Splitsum => &CONVENTIONS,
        Target::Khronos | Target::Bevy => &[
            "cube faces +X -X +Y -Y +Z -Z, Vulkan/KTX2 orientation; the equirect's centre faces +X (glTF-IBL-Sampler): splitsum's (x, y, z) is this cube's (-z, y, x)",
            "specular mip m holds perceptual roughness m/(mips-1) (alpha = roughness^2); mips = floor(log2(size)), down to 2x2",
            "diffuse values are E/pi",
            "BRDF table: height-correlated Smith (V_SmithGGXCorrelated), F = f0*A + B",
            "khronos sheen: charlie/sheen.ktx2 mip m holds sheen roughness m/(mips-1) (alpha = roughness^2, Charlie distribution, v = n, weight D(h)(n.l)); lut_charlie.png = the sheen albedo with Neubelt's visibility, lut_sheen_E.png = with the Charlie visibility, both clamped to 1",
            "bevy: every KTX2 Zstandard-supercompressed; Bevy samples the cube at (x, y, -z) of its world direction",
        ],
        Target::Filament => &[
            "cube faces +X -X +Y -Y +Z -Z; the equirect's centre faces +Z (cmgen, mirrored by default): splitsum's (x, y, z) is this cube's (-x, y, -z)",
            "specular mip m holds perceptual roughness 1 - sqrt(1 - m/(mips-1)); Filament reads lod = (mips-1)*r*(2-r); mips from size down to 16x16",
            "SH: E/pi = max(0, sum c_k P_k(n)), P = 1, y, z, x, xy, yz, 3z^2-1, xz, x^2-y^2 (Irradiance_SphericalHarmonics)",
            "R11F_G11F_B10F: values above 65024 (blue: 64512) are written as that maximum and counted",
        ],
    }
}

fn report_clamp(name: &str, w: &ktx2::Written) {
    if w.clamped > 0 {
        let (format, max, keep) = match w.vk_format {
            ktx2::VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 => ("RGB9E5", ktx2::RGB9E5_MAX, "; the rgba32f format keeps them"),
            ktx2::VK_FORMAT_B10G11R11_UFLOAT_PACK32 => ("R11F_G11F_B10F", UFLOAT11_MAX, " (blue: 64512), the most Filament's format holds"),
            _ => ("half-float", ktx2::HALF_MAX, "; the rgba32f format keeps them"),
        };
        crate::progress::note(&format!(
            "warning: {name}: {} values above the {format} maximum {max} (largest {:.4e}) were clamped to {max}{keep}",
            w.clamped, w.max_value
        ));
    } else if w.vk_format == ktx2::VK_FORMAT_R32G32B32A32_SFLOAT && w.max_value > ktx2::HALF_MAX {
        crate::progress::note(&format!("note: {name}: values reach {:.4e}, beyond half floats: written as RGBA32F", w.max_value));
    }
}

/// What `runner report` measured for the default settings (city.exr, 1024×512 with a
/// 34 000 sun; the figures the README quotes), stated in every manifest.
pub(crate) const DEFAULTS_ACCURACY: &str = "defaults (256² cube, 6 mips, geometric roughness, 64 GGX samples at mip 1 doubling per mip, the r = 1 mip summed exactly, dominant-direction lookup lifted above the horizon and blended between mips in log luminance, table by quadrature with exact Smith, the glTF BRDF's exact image-based weights) on city.exr: shaded colour against the full reflectance integral of the glTF 2.0 BRDF (exact Smith, f64), mean relative error 13.2 % over roughness 0.02-1 and all views (the seed method: 32 %), of which the bake adds 2-3.5 % per view band and the split-sum approximation 6.6-26 %; prefiltered lookup at any roughness 5.7 % mean (seed 12.7 %); over 8 held-out environments 17.3 % with one fetch, 10.8 % with 16 (runner report --sets, --fetches); BRDF table max error 6.2e-6; bake 0.85 s on lavapipe, 1.58 s on 2 CPU cores (runner report, runner bench)";

/// The conventions stated in every manifest.
pub(crate) const CONVENTIONS: [&str; 5] = [
    "cube faces +X -X +Y -Y +Z -Z, Vulkan/KTX2 orientation (OpenGL 4.6 table 8.19)",
    "equirect: image centre looks down -Z, +Y up; u = 0.5 + atan2(x, -z)/2pi, v = polar angle/pi",
    "specular mip m holds roughness roughness_per_mip[m] (alpha = roughness^2), GGX with n = v = r; sheen mip m holds sheen roughness prefiltered.sheen.roughness_per_mip[m], Charlie with n = v",
    "irradiance values are E/pi: a Lambert surface of albedo rho reflects rho times the value",
    "half-float overflow: values above 65504 are clamped and counted (format rgba16f) or kept in rgba32f (format auto)",
];

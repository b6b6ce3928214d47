//! `runner report` end to end, quickly: every product and backend is measured, the
//! errors are finite and fall as the knobs rise, and the three files are written.

#[test]
fn quick_report_writes_tables_csv_and_plot() {
    let dir = std::env::temp_dir().join(format!("splitsum-report-{}", std::process::id()));
    let env = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/environments/studio.exr");
    runner::cli::run(["runner", "report", env, "--quick", "--out", dir.to_str().unwrap()]).expect("report");
    let csv = std::fs::read_to_string(dir.join("report.csv")).unwrap();
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let png = image::open(dir.join("error_vs_time.png")).expect("a PNG").to_rgb8();
    assert!(png.width() > 500 && png.height() > 300);
    let rows: Vec<Vec<String>> = csv::Reader::from_reader(csv.as_bytes()).records().map(|r| r.unwrap().iter().map(str::to_string).collect()).collect();
    for product in ["brdf lut", "prefilter r=0.33", "irradiance (convolution)", "irradiance (SH9)", "shaded colour (n.v >= 0.6)"] {
        for backend in ["gpu", "cpu"] {
            assert!(rows.iter().any(|r| r[0] == product && r[1].starts_with(backend)), "no {product} on {backend}");
        }
        assert!(md.contains(&format!("## {product}")), "{product} missing from report.md");
    }
    assert!(rows.iter().any(|r| r[0].contains("split-sum approximation")));
    // The end-to-end measure: every method on both backends, decomposed by band.
    for product in ["shaded colour, end to end", "prefiltered lookup, any roughness"] {
        for backend in ["gpu", "cpu"] {
            for method in ["seed", "defaults"] {
                assert!(
                    rows.iter().any(|r| r[0].starts_with(product) && r[1].starts_with(backend) && r[2].starts_with(method)),
                    "no {product} of {method} on {backend}"
                );
            }
        }
    }
    assert!(rows.iter().any(|r| r[0].ends_with("(b) split sum")) && rows.iter().any(|r| r[0].ends_with("(c) model")));
    for r in &rows {
        let mean: f64 = r[4].parse().unwrap();
        assert!(mean.is_finite() && mean >= 0.0, "{r:?}");
    }
    // The table's error falls with its sample count (4 → 64) on both backends.
    for backend in ["gpu", "cpu"] {
        let errs: Vec<f64> = rows.iter().filter(|r| r[0] == "brdf lut" && r[1].starts_with(backend)).map(|r| r[4].parse().unwrap()).collect();
        assert!(errs.first() > errs.last(), "{backend}: {errs:?}");
    }
    assert!(md.contains("Best error per millisecond"));
}

/// The end-to-end measure on a constant sky, where the prefiltered and irradiance products
/// are exact: the prefiltered lookup's error is rounding (f32 sums of a constant are exact
/// to a few ULP), and the bake's share (a) of the shaded colour's error is what is left,
/// the bilinear interpolation of the 256² BRDF table between texel centres where it is
/// steepest (grazing n·v at low roughness; measured 1.2·10⁻³ relative, bound 5·10⁻³). The
/// split sum (b) is not zero on a constant sky (the display's roughness-aware Fresnel at
/// n·v stands in for the table's F₀) but finite.
#[test]
fn end_to_end_measure_of_a_constant_sky() {
    use splitsum::environment::Environment;
    use splitsum::settings::Settings;
    use splitsum::texture::Equirect;
    use splitsum_report::accuracy::{Method, Points};
    use splitsum_shaders::glam::Vec4;
    let env = Environment::Equirect(Equirect { width: 64, height: 32, texels: vec![Vec4::new(0.5, 1.0, 2.0, 1.0); 64 * 32] });
    let settings = Settings { size: 16, source_size: Some(16), ..Settings::default() };
    let source = splitsum::bake::host_source_cube(&splitsum::Backend::Cpu, &env, &settings).unwrap();
    let points = Points::new(&source, 48, 32);
    let methods = [Method { label: "defaults".into(), family: "defaults", settings, flags: splitsum_shaders::shade::ShadeOptions::DEFAULT.flags }];
    let rows = splitsum_report::accuracy::measure(&splitsum::Backend::Cpu, &env, &methods, &points).unwrap();
    let worst = |pred: &dyn Fn(&str) -> bool| rows.iter().filter(|r| pred(&r.product)).map(|r| r.max_error).fold(0.0f64, f64::max);
    let bake = worst(&|p| p.ends_with("(a) bake"));
    let lookup = worst(&|p| p.starts_with("prefiltered lookup"));
    let split = worst(&|p| p.ends_with("(b) split sum"));
    println!("constant sky: bake share max {bake:.2e}, lookup max {lookup:.2e}, split sum max {split:.2e}");
    assert!(bake < 5e-3 && lookup < 1e-5, "bake {bake:e}, lookup {lookup:e}");
    assert!(split.is_finite() && split > 0.0);
    assert!(rows.iter().any(|r| r.product.starts_with("shaded colour, end to end") && r.time_ms.is_finite()));
}

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
    let rows: Vec<Vec<String>> = csv.lines().skip(1).map(runner::report::csv_fields).collect();
    for product in ["brdf lut", "prefilter r=0.33", "irradiance (convolution)", "irradiance (SH9)", "shaded colour (n.v >= 0.6)"] {
        for backend in ["gpu", "cpu"] {
            assert!(rows.iter().any(|r| r[0] == product && r[1].starts_with(backend)), "no {product} on {backend}");
        }
        assert!(md.contains(&format!("## {product}")), "{product} missing from report.md");
    }
    assert!(rows.iter().any(|r| r[0].contains("split-sum approximation")));
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

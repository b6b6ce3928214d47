//! The files of a report: `report.html` (the headline first: the sets' table where
//! measured, this environment's, and the end-to-end figure, all on one screen; the rest
//! collapsed below), `report.md`, `report.csv`, the figures ([`crate::plot`],
//! [`crate::surface`]) and the figure files the guide includes ([`crate::figures`]). What
//! they show is [`crate::pages`]'.

use crate::measurement::{Measurement, Method};
use crate::pages::{BUDGET_NOTE, LADDER_NOTE, SETS_NOTE, best_per_ms, budget_panels, budget_table, headline_panels, ladder_panels, ladder_table, panels, set_tables, tables};
use crate::surface::ErrorMap;
use crate::sweep::Sweep;
use splitsum::backend::Backend;
use splitsum::error::Result;
use splitsum::files;
use splitsum::settings::Settings;
use std::fmt::Write as _;
use std::path::Path;

/// What the headline figure shows.
const HEADLINE_CAPTION: &str = "End to end, what a renderer shows: mean relative error of the shaded colour (against the full integral of the glTF BRDF) and of the prefiltered lookup, against bake time. The defaults (blue) at 16, 64 (the default) and 256 samples at mip 1; the seed's method (orange) at 64, 256 and 1024 samples, 1024 being the Khronos glTF-IBL-Sampler's setting. The GPU solid, the CPU dashed; ringed points are the Pareto front.";

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

pub(crate) fn write_outputs(dir: &Path, name: &str, backends: &[Backend], sweep: &Sweep, rows: &[Measurement], maps: &[(String, ErrorMap)]) -> Result<()> {
    files::write_atomic(&dir.join("report.csv"), |w| splitsum::measured::write_csv(w, rows).map_err(std::io::Error::other))?;
    let svg = |w: &mut dyn std::io::Write, drawn: std::result::Result<String, Box<dyn std::error::Error>>| -> std::io::Result<()> {
        w.write_all(drawn.map_err(|e| std::io::Error::other(e.to_string()))?.as_bytes())
    };
    files::write_atomic(&dir.join("error_vs_time.svg"), |w| svg(w, crate::plot::small_multiples(&panels(rows), 3)))?;
    files::write_atomic(&dir.join("headline.svg"), |w| svg(w, crate::plot::small_multiples(&headline_panels(rows), 2)))?;
    // surface{k}_splitsum.png, surface{k}_exact.png, surface{k}_error.png for each map.
    let picture = |k: usize, kind: &str| format!("surface{k}_{kind}.png");
    for (k, (_, map)) in maps.iter().enumerate() {
        for (kind, rgb) in [("splitsum", &map.splitsum), ("exact", &map.exact), ("error", &map.error)] {
            files::write_png(&dir.join(picture(k, kind)), map.width, map.height, rgb)?;
        }
    }
    let ladder = ladder_table(rows);
    if ladder.is_some() {
        files::write_atomic(&dir.join("ladder.svg"), |w| svg(w, crate::plot::ladder(&ladder_panels(rows))))?;
    }
    let budget = budget_table(rows);
    if budget.is_some() {
        files::write_atomic(&dir.join("budget.svg"), |w| svg(w, crate::plot::ladder(&budget_panels(rows))))?;
    }
    files::write_atomic(&dir.join("surface_scale.svg"), |w| {
        svg(w, crate::plot::colour_scale("relative luminance error", crate::surface::false_colour, &crate::surface::scale_ticks()))
    })?;

    let devices = backends.iter().map(|b| b.describe()).collect::<Vec<_>>().join("; ");
    // The figure files the guide includes (`crate::figures`).
    let (command, first) = (crate::figures::command_line(name), backends[0].describe());
    let mut figure_files: Vec<(&str, String)> = Vec::new();
    if let Some(headline) = crate::figures::headline(rows, &command, &first) {
        figure_files.push(("figures.md", headline));
    }
    if let Some(t) = crate::figures::environment_table(rows) {
        let note = format!("Environment: {name}. Bake times as the report took them on each backend (uploads and readbacks included); errors against the full integral of the glTF BRDF, mean relative luminance error (the largest point in brackets).");
        figure_files.push(("figures-environment.md", crate::figures::figure_file(&command, &devices, &note, &[t])));
    }
    let set_tables_now = set_tables(rows);
    if !set_tables_now.is_empty() {
        figure_files.push(("figures-sets.md", crate::figures::figure_file(&command, &first, SETS_NOTE, &set_tables_now)));
    }
    if let Some(t) = ladder_table(rows) {
        figure_files.push(("figures-ladder.md", crate::figures::figure_file(&command, &devices, LADDER_NOTE, &[t])));
    }
    for (file, text) in figure_files {
        files::write_atomic(&dir.join(file), |w| std::io::Write::write_all(w, text.as_bytes()))?;
    }
    let levels = sweep.level_job()?;
    let setup = format!(
        "Environment: {name}; source cube {0}x{0}; prefiltered cube at the defaults' levels: {1}x{1}, {2} mips, roughness {3} ({4} mapping), {5} samples at mip 1. Backends: {devices}.",
        sweep.source_size,
        levels.size,
        levels.mips,
        levels.roughness_per_mip().iter().map(|r| format!("{r:.2}")).collect::<Vec<_>>().join(", "),
        format!("{:?}", levels.prefiltered[&splitsum::Product::Specular].mapping).to_lowercase(),
        levels.samples_per_mip.get(1).copied().unwrap_or(levels.samples),
    );
    let references = "References (f64, independent of the code under test): adaptive Gauss-Kronrod quadrature for the BRDF table; exact sums over every texel of the source for the prefilter and the irradiance; the full reflectance integral (exact Smith, no split) for the shaded colour. Errors are relative: of the luminance, and for the table of the directional albedo F0*A + B (the larger of F0 = 0.04 and 1). Times are wall-clock, uploads and readbacks included.";
    let grid = format!(
        "Sphere grid (metal above, dielectric below; roughness {} across), orthographic view, shaded by splitsum from the default bake on {} against the exact integral (exact Smith, no split), with their relative luminance error.",
        crate::surface::ROUGHNESS.iter().map(|r| format!("{r}")).collect::<Vec<_>>().join(", "),
        backends[0].describe()
    );
    let caption = |what: &str, map: &ErrorMap| format!("{what}: mean relative error {:.2} %, max {:.0} %.", 100.0 * map.mean, 100.0 * map.max);
    let tables = tables(rows);
    let set_tables = set_tables(rows);
    let best = best_per_ms(rows);

    // Markdown.
    let mut md = String::new();
    let _ = writeln!(md, "# splitsum: error against run time\n\n{setup}\n\n{references}\n");
    let _ = writeln!(md, "![the defaults against the seed's method, end to end](headline.svg)\n\n{HEADLINE_CAPTION}\n");
    let _ = writeln!(md, "![error against run time](error_vs_time.svg)\n\n{grid}\n\n| environment | splitsum | exact | error |\n|---|---|---|---|");
    for (k, (what, map)) in maps.iter().enumerate() {
        let _ = writeln!(md, "| {} | ![]({}) | ![]({}) | ![]({}) |", caption(what, map), picture(k, "splitsum"), picture(k, "exact"), picture(k, "error"));
    }
    let _ = writeln!(md, "\n![scale](surface_scale.svg)");
    let figures = [
        (&ladder, LADDER_NOTE, "ladder", "the shading ladder", "error against ns per shaded pixel, one point per rung"),
        (&budget, BUDGET_NOTE, "budget", "the budget curve", "error against the time budget, one point per budget"),
    ];
    for (table, note, id, alt, _) in figures {
        if let Some((title, header, cells)) = table {
            let _ = writeln!(md, "\n## {title}\n\n{note}\n\n![{alt}]({id}.svg)\n");
            md += &crate::figures::markdown_table(header, cells);
        }
    }
    if !set_tables.is_empty() {
        let _ = writeln!(md, "\n## Tuning and held-out sets\n\n{SETS_NOTE}");
    }
    for (title, header, cells) in set_tables.iter().chain(&tables) {
        let _ = writeln!(md, "\n## {title}\n");
        md += &crate::figures::markdown_table(header, cells);
    }
    let _ = writeln!(
        md,
        "\n## Best error per millisecond (smallest mean error x time)\n\n| panel | backend | setting | time (ms) | mean error |\n|---|---|---|---:|---:|"
    );
    for (p, r) in &best {
        let _ = writeln!(md, "| {p} | {} | {} | {:.1} | {:.2e} |", r.backend, r.setting(), r.time_ms.unwrap_or(f64::NAN), r.mean_error);
    }
    files::write_atomic(&dir.join("report.md"), |w| std::io::Write::write_all(w, md.as_bytes()))?;

    // HTML: the same, every figure inline beside its caption.
    let mut html = String::new();
    let _ = writeln!(
        html,
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>splitsum: error against run time, {}</title>\n<style>body{{font-family:sans-serif;max-width:1120px;margin:2em auto;color:#222}} table{{border-collapse:collapse;font-size:13px;margin:0.5em 0 1.5em}} td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}} td:nth-child(-n+5),th:nth-child(-n+5){{text-align:left}} figure{{margin:1em 0}} .maps img{{image-rendering:pixelated;border:1px solid #ddd;margin-right:8px}}</style></head><body>",
        html_escape(name)
    );
    let _ = writeln!(html, "<h1>splitsum: error against run time</h1>\n<p>{}</p>", html_escape(&setup));
    // The headline first: the sets' figures (where measured) and the error against time;
    // the details below it, collapsed.
    if let Some((header, cells)) = crate::figures::headline_table(rows) {
        let _ = writeln!(
            html,
            "<h2 id=\"headline\">Accuracy on the tuning and held-out sets</h2>\n<p>{}</p>\n<table><tr>{}</tr>",
            html_escape(&crate::figures::provenance(&backends[0].describe())),
            header.iter().map(|h| format!("<th>{}</th>", html_escape(h))).collect::<String>()
        );
        for c in cells {
            // A cell's Markdown code span (a flag) as HTML code.
            let cell = |v: &String| html_escape(v).split('`').enumerate().map(|(k, p)| if k % 2 == 1 { format!("<code>{p}</code>") } else { p.to_string() }).collect::<String>();
            let _ = writeln!(html, "<tr>{}</tr>", c.iter().map(|v| format!("<td>{}</td>", cell(v))).collect::<String>());
        }
        let _ = writeln!(html, "</table>");
    }
    // This environment's headline: the defaults, 16 fetches and the seed's settings.
    if let Some((_, header, cells)) = crate::figures::environment_table(rows) {
        let n = Settings::default().samples;
        let keep = [format!("{}, {n} samples", Method::Defaults.title()), format!("{}, {n} samples, 16 fetches", Method::Ladder.title()), format!("{}, 1024 samples", Method::Seed.title())];
        let _ = writeln!(
            html,
            "<h2 id=\"headline-environment\">Accuracy and bake time on {}</h2>\n<table><tr>{}</tr>",
            html_escape(name),
            header.iter().map(|h| format!("<th>{}</th>", html_escape(h))).collect::<String>()
        );
        for c in cells.iter().filter(|c| keep.contains(&c[0])) {
            let _ = writeln!(html, "<tr>{}</tr>", c.iter().map(|v| format!("<td>{}</td>", html_escape(v))).collect::<String>());
        }
        let _ = writeln!(html, "</table>");
    }
    let _ = writeln!(
        html,
        "<figure id=\"headline-figure\"><img src=\"headline.svg\" alt=\"the defaults against the seed's method, end to end\"><figcaption>{}</figcaption></figure>\n<hr id=\"headline-end\" style=\"border:0;border-top:4px solid rgb(120,30,160)\">",
        html_escape(HEADLINE_CAPTION)
    );
    let _ = writeln!(
        html,
        "<details><summary>Details: every product's error against time, the references, the error on surfaces, the shading ladder, the budgets, the sets per environment and every product's table</summary>\n<p>{}</p>",
        html_escape(references)
    );
    let _ = writeln!(
        html,
        "<figure id=\"error-vs-time\"><img src=\"error_vs_time.svg\" alt=\"error against run time, one panel per product\"><figcaption>Mean relative error against bake time, one panel per product: one colour per method, the GPU solid and the CPU dashed; ringed points are each panel's Pareto front. The prefiltered cube's panels sweep the samples of each mip of the default bake's levels.</figcaption></figure>"
    );
    let _ = writeln!(html, "<h2>The error on surfaces</h2>\n<p>{}</p>", html_escape(&grid));
    for (k, (what, map)) in maps.iter().enumerate() {
        let _ = writeln!(
            html,
            "<figure class=\"maps\"><img src=\"{}\" alt=\"splitsum\"><img src=\"{}\" alt=\"exact\"><img src=\"{}\" alt=\"error\"><figcaption>Left to right: splitsum, the exact integral, their relative error. {}</figcaption></figure>",
            picture(k, "splitsum"),
            picture(k, "exact"),
            picture(k, "error"),
            html_escape(&caption(what, map))
        );
    }
    let _ = writeln!(html, "<img src=\"surface_scale.svg\" alt=\"error scale\">");
    for (table, note, id, _, alt) in figures {
        if let Some((title, header, cells)) = table {
            let _ = writeln!(
                html,
                "<h2 id=\"{id}\">{}</h2>\n<p>{}</p>\n<figure><img src=\"{id}.svg\" alt=\"{alt}\"></figure>\n<table><tr>{}</tr>",
                html_escape(title),
                html_escape(note),
                header.iter().map(|h| format!("<th>{}</th>", html_escape(h))).collect::<String>()
            );
            for c in cells {
                let _ = writeln!(html, "<tr>{}</tr>", c.iter().map(|v| format!("<td>{}</td>", html_escape(v))).collect::<String>());
            }
            let _ = writeln!(html, "</table>");
        }
    }
    if !set_tables.is_empty() {
        let _ = writeln!(html, "<h2>Tuning and held-out sets</h2>\n<p>{}</p>", html_escape(SETS_NOTE));
    }
    for (title, header, cells) in set_tables.iter().chain(&tables) {
        let _ = writeln!(
            html,
            "<h2>{}</h2>\n<table><tr>{}</tr>",
            html_escape(title),
            header.iter().map(|h| format!("<th>{}</th>", html_escape(h))).collect::<String>()
        );
        for c in cells {
            let _ = writeln!(html, "<tr>{}</tr>", c.iter().map(|v| format!("<td>{}</td>", html_escape(v))).collect::<String>());
        }
        let _ = writeln!(html, "</table>");
    }
    let _ = writeln!(
        html,
        "<h2>Best error per millisecond</h2>\n<table><tr><th>panel</th><th>backend</th><th>setting</th><th>time (ms)</th><th>mean error</th></tr>"
    );
    for (p, r) in &best {
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.2e}</td></tr>",
            html_escape(p),
            r.backend,
            html_escape(&r.setting()),
            r.time_ms.unwrap_or(f64::NAN),
            r.mean_error
        );
    }
    let _ = writeln!(html, "</table></details></body></html>");
    files::write_atomic(&dir.join("report.html"), |w| std::io::Write::write_all(w, html.as_bytes()))?;
    Ok(())
}

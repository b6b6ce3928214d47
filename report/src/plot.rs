//! The report's pictures, drawn with `plotters` as SVG (text stays text, set by the
//! browser): small multiples of error against run time, one panel per product, and the
//! false-colour scale of the error maps ([`crate::surface`]).
//!
//! One colour per method ([`method_colour`]) and one line style per backend (the GPU
//! solid, the CPU dashed) in every panel; relative errors only, on labelled log axes;
//! each panel's Pareto front (no point both faster and more accurate) ringed and joined.

use plotters::prelude::*;
use splitsum::measured::Method;

/// One curve: a method on a backend, its points (a cost, mean relative error).
#[derive(Clone, Debug)]
pub struct Series {
    /// The method (the colour).
    pub method: Method,
    /// `gpu` or `cpu` (the line style).
    pub backend: String,
    /// (cost: time in ms, or ns per pixel; mean relative error), in sweep order.
    pub points: Vec<(f64, f64)>,
}

/// One panel: a product's curves.
#[derive(Clone, Debug)]
pub struct Panel {
    /// The product (and, where it has several, which one).
    pub title: String,
    /// What its horizontal axis measures.
    pub x_label: String,
    /// Its curves.
    pub series: Vec<Series>,
}

/// Every method's colour (a colour-blind-safe qualitative palette, Okabe & Ito 2008).
pub fn method_colour(m: Method) -> RGBColor {
    match m {
        Method::Seed => RGBColor(213, 94, 0),
        Method::Defaults => RGBColor(0, 114, 178),
        Method::MirrorDirection => RGBColor(0, 158, 115),
        Method::MultipleScattering => RGBColor(204, 121, 167),
        Method::FilteredSampling => RGBColor(86, 180, 233),
        Method::SmithSchlickTable => RGBColor(230, 159, 0),
        Method::LinearMipBlend => RGBColor(0, 0, 0),
        Method::RoughnessFresnel => RGBColor(240, 228, 66),
        Method::NoHorizonLift => RGBColor(160, 110, 60),
        Method::Ladder => RGBColor(170, 0, 90),
        Method::KhronosBevyLookup => RGBColor(120, 120, 0),
        Method::FilamentLookup => RGBColor(0, 120, 120),
        Method::Sh9 => RGBColor(120, 94, 240),
        Method::ExactIngredients => RGBColor(90, 90, 90),
        Method::TimeBudget => RGBColor(0, 60, 140),
    }
}

/// The points of `points` on the Pareto front: none other is both no slower and more
/// accurate. Sorted by time.
pub fn pareto(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points.iter().copied().filter(|(t, e)| t.is_finite() && e.is_finite() && *t > 0.0 && *e > 0.0).collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for q in p {
        if front.last().is_none_or(|l| q.1 < l.1) {
            front.push(q);
        }
    }
    front
}

fn decade_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.filter(|v| v.is_finite() && *v > 0.0).fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return 1e-3..1.0;
    }
    10f64.powf(lo.log10().floor())..10f64.powf(hi.log10().ceil().max(lo.log10().floor() + 1.0))
}

/// A log axis's label at `v`: powers of ten always, and 2 and 5 of each decade, so that a
/// panel spanning one decade still reads.
fn sci(v: f64) -> String {
    let e = v.log10().floor() as i32;
    let m = v / 10f64.powi(e);
    let Some(&k) = [1.0f64, 2.0, 5.0].iter().find(|k| (m - **k).abs() < 1e-6 * **k) else { return String::new() };
    if (-2..=3).contains(&e) { format!("{}", k * 10f64.powi(e)).trim_end_matches(".0").to_string() } else { format!("{k}e{e}") }
}

/// 1, 2 and 5 of every decade in `range` (the powers of ten alone past three decades): the
/// error axis's ticks, so that a panel spanning one decade still has values to read
/// (plotters' own log ticks give only the decade's ends below 1).
fn one_two_five(range: std::ops::Range<f64>) -> Vec<f64> {
    let (lo, hi) = (range.start.log10().floor() as i32, range.end.log10().ceil() as i32);
    let steps: &[f64] = if hi - lo > 3 { &[1.0] } else { &[1.0, 2.0, 5.0] };
    (lo..=hi)
        .flat_map(|e| steps.iter().map(move |k| k * 10f64.powi(e)))
        .filter(|v| *v >= range.start * (1.0 - 1e-9) && *v <= range.end * (1.0 + 1e-9))
        .collect()
}

type Error = Box<dyn std::error::Error>;

/// The small multiples as an SVG document: `columns` panels a row, a legend on top.
pub fn small_multiples(panels: &[Panel], columns: usize) -> Result<String, Error> {
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns).max(1);
    let (panel_w, panel_h) = (360u32, 280u32);
    let (entries, legend_h) = legend_layout(panels, panel_w * columns as u32);
    let size = (panel_w * columns as u32, legend_h + panel_h * rows as u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        let (legend, grid) = root.split_vertically(legend_h);
        draw_legend(&legend, &entries, legend_h)?;
        let areas = grid.split_evenly((rows, columns));
        for (panel, area) in panels.iter().zip(areas) {
            draw_panel(&area, panel)?;
        }
        root.present()?;
    }
    Ok(svg)
}

/// Where each method's legend entry goes: entries left to right, wrapped before they would
/// pass the width (a 14 px sans-serif character taken as 8.5 px wide, wider than most), and
/// the legend's height: a 20 px line per row of methods and one for the line styles.
fn legend_layout(panels: &[Panel], width: u32) -> (Vec<(Method, i32, i32)>, u32) {
    let mut methods: Vec<Method> = panels.iter().flat_map(|p| p.series.iter().map(|s| s.method)).collect();
    methods.sort();
    methods.dedup();
    let (mut x, mut y) = (10i32, 8i32);
    let mut out = Vec::new();
    for m in methods {
        let w = 40 + (8.5 * m.title().chars().count() as f64) as i32;
        if x > 10 && x + w > width as i32 - 10 {
            x = 10;
            y += 20;
        }
        out.push((m, x, y));
        x += w;
    }
    let styles = if out.is_empty() { 8 } else { y + 24 };
    (out, (styles + 28) as u32)
}

fn draw_legend(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, entries: &[(Method, i32, i32)], height: u32) -> Result<(), Error> {
    let font = ("sans-serif", 14).into_font();
    for &(m, x, y) in entries {
        let c = method_colour(m);
        area.draw(&Rectangle::new([(x, y + 3), (x + 22, y + 13)], c.filled()))?;
        area.draw(&Text::new(m.title(), (x + 28, y), font.clone()))?;
    }
    let y = height as i32 - 26;
    let black = RGBColor(40, 40, 40);
    area.draw(&PathElement::new(vec![(10, y + 8), (40, y + 8)], black.stroke_width(2)))?;
    area.draw(&Text::new("GPU backend", (46, y), font.clone()))?;
    for x in [160, 170, 180] {
        area.draw(&PathElement::new(vec![(x, y + 8), (x + 6, y + 8)], black.stroke_width(2)))?;
    }
    area.draw(&Text::new("CPU backend", (196, y), font.clone()))?;
    area.draw(&Circle::new((316, y + 8), 6, black.stroke_width(1)))?;
    area.draw(&Text::new("Pareto front (none faster and more accurate)", (328, y), font))?;
    Ok(())
}

fn draw_panel(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, panel: &Panel) -> Result<(), Error> {
    let all: Vec<(f64, f64)> = panel.series.iter().flat_map(|s| s.points.iter().copied()).collect();
    let xr = decade_range(all.iter().map(|p| p.0));
    let yr = decade_range(all.iter().map(|p| p.1));
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(52)
        .build_cartesian_2d(xr.log_scale(), yr.clone().log_scale().with_key_points(one_two_five(yr)))?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc("mean relative error")
        .x_label_formatter(&|v| sci(*v))
        .y_label_formatter(&|v| sci(*v))
        .light_line_style(RGBColor(235, 235, 235))
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 12))
        .draw()?;
    for s in &panel.series {
        let c = method_colour(s.method);
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|(t, e)| t.is_finite() && e.is_finite() && *t > 0.0 && *e > 0.0).collect();
        if s.backend == "gpu" {
            chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?;
        } else {
            chart.draw_series(DashedLineSeries::new(pts.clone(), 5, 4, c.stroke_width(2)))?;
        }
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
    }
    let front = pareto(&all);
    let grey = RGBColor(60, 60, 60);
    chart.draw_series(LineSeries::new(front.clone(), grey.mix(0.5).stroke_width(1)))?;
    chart.draw_series(front.iter().map(|&p| Circle::new(p, 6, grey.stroke_width(1))))?;
    Ok(())
}

/// One curve of the shading ladder's figure: an environment or a set, its rungs.
#[derive(Clone, Debug)]
pub struct LadderCurve {
    /// What it measures (the legend).
    pub label: String,
    /// (ns per shaded pixel, mean relative error, fetches), one per rung.
    pub points: Vec<(f64, f64, u32)>,
}

/// One panel of the ladder's figure: its curves on one backend's costs.
#[derive(Clone, Debug)]
pub struct LadderPanel {
    /// Which backend's costs.
    pub title: String,
    /// What the horizontal axis (logarithmic) measures.
    pub x_label: String,
    /// Its curves.
    pub curves: Vec<LadderCurve>,
}

/// Error against a cost as an SVG document (the shading ladder's against ns per shaded
/// pixel, each rung's point labelled with its fetches; the budget curve's against the
/// budget, labelled with the samples chosen): a panel per backend.
pub fn ladder(panels: &[LadderPanel]) -> Result<String, Error> {
    const PALETTE: [RGBColor; 5] = [RGBColor(0, 114, 178), RGBColor(86, 180, 233), RGBColor(0, 158, 115), RGBColor(213, 94, 0), RGBColor(230, 159, 0)];
    let (panel_w, panel_h) = (460u32, 340u32);
    let size = (panel_w * panels.len().max(1) as u32, panel_h);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        for (panel, area) in panels.iter().zip(root.split_evenly((1, panels.len().max(1)))) {
            let all: Vec<(f64, f64)> = panel.curves.iter().flat_map(|c| c.points.iter().map(|p| (p.0, p.1))).collect();
            let xr = decade_range(all.iter().map(|p| p.0));
            let top = all.iter().map(|p| p.1).filter(|e| e.is_finite()).fold(0.0f64, f64::max).max(1e-3) * 1.15;
            let mut chart = ChartBuilder::on(&area)
                .caption(&panel.title, ("sans-serif", 15))
                .margin(8)
                .x_label_area_size(34)
                .y_label_area_size(52)
                .build_cartesian_2d(xr.log_scale(), 0.0..top)?;
            chart
                .configure_mesh()
                .x_desc(panel.x_label.as_str())
                .y_desc("mean relative error")
                .x_label_formatter(&|v| sci(*v))
                .y_label_formatter(&|v| format!("{:.0} %", 100.0 * v))
                .light_line_style(RGBColor(235, 235, 235))
                .label_style(("sans-serif", 12))
                .axis_desc_style(("sans-serif", 12))
                .draw()?;
            for (i, curve) in panel.curves.iter().enumerate() {
                let c = PALETTE[i % PALETTE.len()];
                let pts: Vec<(f64, f64)> =
                    curve.points.iter().map(|p| (p.0, p.1)).filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite()).collect();
                chart
                    .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
                    .label(curve.label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2)));
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
                chart.draw_series(
                    curve.points.iter().filter(|p| p.0 > 0.0 && p.1 > 0.0).map(|&(x, y, k)| Text::new(format!("{k}"), (x, y), ("sans-serif", 11).into_font())),
                )?;
            }
            chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(RGBColor(200, 200, 200)).label_font(("sans-serif", 11)).draw()?;
        }
        root.present()?;
    }
    Ok(svg)
}

/// A horizontal false-colour scale (`colour(t)` for `t` in 0..1) labelled `ticks`
/// (position in 0..1, text), titled `title`, as an SVG document.
pub fn colour_scale(title: &str, colour: impl Fn(f64) -> [u8; 3], ticks: &[(f64, String)]) -> Result<String, Error> {
    let (w, h) = (520u32, 70u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (x0, x1, y0, y1) = (20i32, w as i32 - 20, 24i32, 42i32);
        for x in x0..x1 {
            let [r, g, b] = colour((x - x0) as f64 / (x1 - x0 - 1) as f64);
            root.draw(&Rectangle::new([(x, y0), (x + 1, y1)], RGBColor(r, g, b).filled()))?;
        }
        root.draw(&Text::new(title.to_string(), (x0, 4), ("sans-serif", 14).into_font()))?;
        for (t, label) in ticks {
            let x = x0 + ((x1 - x0) as f64 * t) as i32;
            root.draw(&PathElement::new(vec![(x, y1), (x, y1 + 4)], BLACK))?;
            root.draw(&Text::new(label.clone(), (x - 12, y1 + 8), ("sans-serif", 12).into_font()))?;
        }
        root.present()?;
    }
    Ok(svg)
}

//! What a report shows, from its typed rows: the panels of the error-against-time figure
//! (and the best result per millisecond the command line prints) and the tables (sweeps,
//! the tuning and held-out sets, the shading ladder, the time budgets). Measuring is
//! [`crate::report`]'s; writing the files is `write.rs`'s (`report::run` calls it).

use crate::measurement::{Knob, Measurement, Method, Part, Quantity};
use splitsum::settings::Settings;

/// The panel of the error-against-time figure a row belongs to, if any: every sample or
/// size sweep and every end-to-end method (the bias and cube-size sweeps, and the bands,
/// are in the tables only).
pub fn panel(r: &Measurement) -> Option<String> {
    if r.time_ms.is_none() || r.part != Part::Total || r.backend.is_empty() || r.set.is_some() {
        return None;
    }
    match (r.product, r.knob) {
        (Quantity::Prefilter, Knob::Samples) => Some(format!("prefiltered cube, r = {:.2}", r.roughness_lo?)),
        (Quantity::Prefilter, _) => None,
        (Quantity::ShadedColour, Knob::Quality) => Some(format!("shaded colour, quality levels, n·v in ({}, {}]", r.nv_lo?, r.nv_hi?)),
        (Quantity::ShadedColour | Quantity::PrefilteredLookup, _) => Some(format!("{}, end to end", r.product.title())),
        (p, _) => Some(p.title().to_string()),
    }
}

/// For each panel and backend, the measurement with the smallest mean error × time.
pub fn best_per_ms(rows: &[Measurement]) -> Vec<(String, &Measurement)> {
    let mut best: Vec<(String, &Measurement)> = Vec::new();
    for r in rows {
        let Some(p) = panel(r) else { continue };
        let score = |m: &Measurement| m.mean_error * m.time_ms.unwrap_or(f64::INFINITY);
        match best.iter_mut().find(|(q, b)| *q == p && b.backend == r.backend) {
            Some(slot) if score(r) < score(slot.1) => slot.1 = r,
            Some(_) => {}
            None => best.push((p, r)),
        }
    }
    best
}

/// The small multiples of every panel: one series per method and backend.
pub fn panels(rows: &[Measurement]) -> Vec<crate::plot::Panel> {
    let mut panels: Vec<crate::plot::Panel> = Vec::new();
    for r in rows {
        let Some(title) = panel(r) else { continue };
        let k = match panels.iter().position(|p| p.title == title) {
            Some(k) => k,
            None => {
                panels.push(crate::plot::Panel { title, x_label: "bake time (ms)".into(), series: vec![] });
                panels.len() - 1
            }
        };
        let series = &mut panels[k].series;
        let point = (r.time_ms.unwrap_or(f64::NAN), r.mean_error);
        match series.iter_mut().find(|s| s.method == r.method && s.backend == r.backend) {
            Some(s) => s.points.push(point),
            None => series.push(crate::plot::Series { method: r.method, backend: r.backend.clone(), points: vec![point] }),
        }
    }
    panels
}

/// The headline figure's panels: the end-to-end measures (the shaded colour and the
/// prefiltered lookup) of the defaults at their sample counts beside the seed's method at
/// its (the seed at 1024 samples is the Khronos glTF-IBL-Sampler's setting), over all
/// points. The other methods are in [`panels`]' figure, below the headline.
pub fn headline_panels(rows: &[Measurement]) -> Vec<crate::plot::Panel> {
    let headline = |r: &&Measurement| {
        matches!(r.product, Quantity::ShadedColour | Quantity::PrefilteredLookup)
            && r.knob != Knob::Quality
            && matches!(r.method, Method::Seed | Method::Defaults)
            && r.fetches.is_none_or(|f| f == 1)
            && r.nv_lo.is_none()
            && r.roughness_lo.is_none()
            && r.near_sun.is_none()
    };
    let kept: Vec<Measurement> = rows.iter().filter(headline).cloned().collect();
    panels(&kept)
}

/// A row's band, in words: roughness, `n·v`, near the sun.
fn band(r: &Measurement) -> String {
    let mut parts = Vec::new();
    if let (Some(lo), Some(hi)) = (r.roughness_lo, r.roughness_hi) {
        parts.push(if lo == hi { format!("r = {lo:.2}") } else { format!("r in [{lo}, {hi})") });
    }
    if let (Some(lo), Some(hi)) = (r.nv_lo, r.nv_hi) {
        parts.push(format!("n·v in ({lo}, {hi}]"));
    }
    match r.near_sun {
        Some(true) => parts.push("near the sun".into()),
        Some(false) => parts.push("away from the sun".into()),
        None => {}
    }
    if parts.is_empty() { "all".into() } else { parts.join(", ") }
}

fn part_name(p: Part) -> &'static str {
    match p {
        Part::Total => "total",
        Part::Bake => "(a) bake",
        Part::SplitSum => "(b) split sum",
        Part::Model => "(c) model",
    }
}

/// One of the report's tables: its title, header and cells.
pub(crate) type Table = crate::figures::Table<8>;

/// The report's tables: one per product, rows in measurement order.
pub(crate) fn tables(rows: &[Measurement]) -> Vec<Table> {
    let mut products: Vec<Quantity> = rows.iter().filter(|r| r.set.is_none() && r.product != Quantity::ShadingCost).map(|r| r.product).collect();
    products.sort();
    products.dedup();
    let header = ["method", "backend", "setting", "band", "part", "time (ms)", "mean error", "max error"];
    products
        .into_iter()
        .map(|p| {
            let cells = rows
                .iter()
                .filter(|r| r.product == p && r.set.is_none())
                .map(|r| {
                    [
                        r.method.title().to_string(),
                        if r.backend.is_empty() { "-".into() } else { r.backend.clone() },
                        r.setting(),
                        band(r),
                        part_name(r.part).into(),
                        r.time_ms.map_or("-".into(), |t| format!("{t:.1}")),
                        format!("{:.2e}", r.mean_error),
                        format!("{:.2e}", r.max_error),
                    ]
                })
                .collect();
            (p.title().to_string(), header, cells)
        })
        .collect()
}

/// What the measure over sets is, in the report.
pub(crate) const SETS_NOTE: &str = "The end-to-end measure (shaded colour against the full reflectance integral, exact Smith, no split) over environments of every kind. Design choices may look at the tuning set only; the held-out set confirms them. Mean relative luminance error over each set's environments (the largest point in brackets).";

/// `mean (max)` over the environments of a set: the mean of their means, the largest of
/// their maxima; `-` where no row matches.
pub(crate) fn over_environments<'a>(rows: impl Iterator<Item = &'a Measurement>) -> String {
    let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0f64);
    for r in rows {
        sum += r.mean_error;
        n += 1;
        max = max.max(r.max_error);
    }
    if n == 0 { "-".into() } else { format!("{:.1} % ({:.0} %)", 100.0 * sum / n as f64, 100.0 * max) }
}

/// The measure over sets: per set, each method's shaded colour over every point and per
/// `n·v` band, the bake's share and the prefiltered lookup (mean over the set's
/// environments, max in brackets); then each environment's figures for the defaults.
pub(crate) fn set_tables(rows: &[Measurement]) -> Vec<Table> {
    use crate::measurement::Set;
    let set_rows: Vec<&Measurement> = rows.iter().filter(|r| r.set.is_some()).collect();
    if set_rows.is_empty() {
        return vec![];
    }
    let no_band = |r: &Measurement| r.roughness_lo.is_none() && r.nv_lo.is_none() && r.near_sun.is_none();
    // A method is its kind, its sample count and its fetches (the ladder's rungs apart).
    type Key = (Method, u32, u32);
    let key = |r: &Measurement| -> Key { (r.method, r.samples.unwrap_or(0), r.fetches.unwrap_or(1)) };
    let mut methods: Vec<Key> = set_rows.iter().map(|r| key(r)).collect();
    methods.sort();
    methods.dedup();
    let mut tables = Vec::new();
    for set in [Set::Tuning, Set::HeldOut] {
        let mut envs: Vec<&str> = set_rows.iter().filter(|r| r.set == Some(set)).map(|r| r.environment.as_str()).collect();
        envs.dedup();
        let of = |m: Key| set_rows.iter().copied().filter(move |r| r.set == Some(set) && key(r) == m);
        let cells = methods
            .iter()
            .map(|&m| {
                let shaded = |part: Part| over_environments(of(m).filter(|r| r.product == Quantity::ShadedColour && r.part == part && no_band(r)));
                let view = |hi: f32| over_environments(of(m).filter(|r| r.product == Quantity::ShadedColour && r.part == Part::Total && r.nv_hi == Some(hi)));
                [
                    match m.2 {
                        1 => format!("{}, {} samples", m.0.title(), m.1),
                        k => format!("{}, {k} fetches", m.0.title()),
                    },
                    shaded(Part::Total),
                    view(0.1),
                    view(0.3),
                    view(0.6),
                    view(1.0),
                    shaded(Part::Bake),
                    over_environments(of(m).filter(|r| r.product == Quantity::PrefilteredLookup && no_band(r))),
                ]
            })
            .collect();
        let header = ["method", "shaded colour", "n·v ≤ 0.1", "0.1–0.3", "0.3–0.6", "0.6–1", "(a) bake's share", "prefiltered lookup"];
        tables.push((format!("{}: {}", set.title(), envs.join(", ")), header, cells));
    }
    let defaults: Key = (Method::Defaults, Settings::default().samples, 1);
    let mut envs: Vec<(&str, Set)> = set_rows.iter().map(|r| (r.environment.as_str(), r.set.expect("set rows"))).collect();
    envs.dedup();
    let cells = envs
        .iter()
        .map(|&(env, set)| {
            let of = |m: Key| set_rows.iter().copied().filter(move |r| r.environment == env && key(r) == m);
            let shaded = |m, part: Part| over_environments(of(m).filter(|r| r.product == Quantity::ShadedColour && r.part == part && no_band(r)));
            let view =
                |hi: f32| over_environments(of(defaults).filter(|r| r.product == Quantity::ShadedColour && r.part == Part::Total && r.nv_hi == Some(hi)));
            [
                env.to_string(),
                set.title().to_string(),
                shaded(defaults, Part::Total),
                view(0.3),
                view(0.1),
                shaded(defaults, Part::Bake),
                shaded(defaults, Part::SplitSum),
                shaded((Method::Seed, 1024, 1), Part::Total),
            ]
        })
        .collect();
    let header = ["environment", "set", "defaults", "n·v 0.1–0.3", "n·v ≤ 0.1", "(a) bake", "(b) split sum", "seed, 1024 samples"];
    tables.push(("each environment (shaded colour, defaults unless named)".to_string(), header, cells));
    tables
}

/// What the shading ladder is, in the report.
pub(crate) const BUDGET_NOTE: &str = "For each time budget per bake, the settings splitsum::estimate::for_budget chooses on this backend (by this backend's estimator, as runner bake --budget chooses: its rates measured now, the built-in error model): the sample count at mip 1 and the irradiance source. Each is baked, timed (the bake as run here, not the estimate) and measured end to end like the methods below: shaded colour against the full reflectance integral over this environment's points.";

pub(crate) const LADDER_NOTE: &str = "The shading ladder: the split sum's one prefiltered fetch, then 2 to 16 fetches of filtered importance sampling of the true GGX lobe over the prefiltered mips (shade::lobe_radiance), used below n·v 0.7. Shaded colour against the full reflectance integral (mean relative luminance error, the largest point in brackets), against what a shaded pixel costs: ns per pixel of a sphere in the default view, direct lights included (a frame with the spheres less one without, best of three).";

/// The method of the ladder's rung with `fetches`: the defaults' one fetch, the ladder above.
pub fn rung_method(fetches: u32) -> Method {
    if fetches == 1 { Method::Defaults } else { Method::Ladder }
}

/// The rungs of the ladder present in `rows`, in order.
fn rungs(rows: &[Measurement]) -> Vec<u32> {
    let mut k: Vec<u32> =
        rows.iter().filter(|r| r.product == Quantity::ShadingCost).filter_map(|r| r.fetches.filter(|&k| r.method == rung_method(k))).collect();
    k.sort();
    k.dedup();
    k
}

/// The cost per shaded pixel of `method` with `fetches` on the backend `engine`.
fn cost_of(rows: &[Measurement], method: Method, fetches: u32, engine: &str) -> Option<f64> {
    rows.iter()
        .find(|r| r.product == Quantity::ShadingCost && r.method == method && r.fetches == Some(fetches) && r.backend == engine)
        .and_then(|r| r.ns_per_pixel)
}

/// The shaded colour's rows of `method` with `fetches` at the default sample count, part
/// total.
fn method_rows(rows: &[Measurement], method: Method, fetches: u32) -> impl Iterator<Item = &Measurement> {
    let samples = Settings::default().samples;
    rows.iter().filter(move |r| {
        r.product == Quantity::ShadedColour
            && r.part == Part::Total
            && r.method == method
            && r.fetches == Some(fetches)
            && r.samples == Some(samples)
            && r.knob != Knob::Quality
            && r.roughness_lo.is_none()
            && r.near_sun.is_none()
    })
}

/// The shaded colour's rows of the rung with `fetches`, part total.
fn rung_rows(rows: &[Measurement], fetches: u32) -> impl Iterator<Item = &Measurement> {
    method_rows(rows, rung_method(fetches), fetches)
}

/// The ladder's table: per rung, its cost on each backend and its error on the report's
/// environment and over each set, all points and per `n·v` band.
pub(crate) fn ladder_table(rows: &[Measurement]) -> Option<Table> {
    let rungs = rungs(rows);
    if rungs.is_empty() {
        return None;
    }
    let first = rows.iter().find(|r| r.product == Quantity::ShadedColour && r.set.is_none() && !r.backend.is_empty()).map(|r| r.backend.clone());
    // The rungs, then the quality mode below mip 1 (`--filtered`, one fetch but sixteen
    // samples where it applies) for its cost beside theirs.
    let mut lines: Vec<(String, Method, u32)> = rungs.iter().map(|&k| (format!("{k}"), rung_method(k), k)).collect();
    if cost_of(rows, Method::FilteredSampling, 1, "gpu").or(cost_of(rows, Method::FilteredSampling, 1, "cpu")).is_some() {
        lines.push(("1, --filtered".into(), Method::FilteredSampling, 1));
    }
    let cells = lines
        .into_iter()
        .map(|(label, method, k)| {
            let cost = |engine: &str| cost_of(rows, method, k, engine).map_or("-".into(), |ns| format!("{ns:.0}"));
            let own = |band: Option<f32>| {
                over_environments(method_rows(rows, method, k).filter(|r| r.set.is_none() && Some(&r.backend) == first.as_ref() && r.nv_hi == band))
            };
            let set =
                |s: crate::measurement::Set, band: Option<f32>| over_environments(method_rows(rows, method, k).filter(|r| r.set == Some(s) && r.nv_hi == band));
            [
                label,
                cost("gpu"),
                cost("cpu"),
                own(None),
                own(Some(0.1)),
                set(crate::measurement::Set::Tuning, None),
                set(crate::measurement::Set::HeldOut, None),
                set(crate::measurement::Set::HeldOut, Some(0.1)),
            ]
        })
        .collect();
    let header = ["fetches", "ns/pixel, GPU", "ns/pixel, CPU", "this environment", "its n·v ≤ 0.1", "tuning set", "held-out set", "held-out n·v ≤ 0.1"];
    Some(("shading ladder: shaded colour against cost".to_string(), header, cells))
}

/// The ladder's figure: error against ns per pixel, a panel per backend's cost, a curve
/// per environment or set (its points the rungs, 1 to 16 fetches).
pub fn ladder_panels(rows: &[Measurement]) -> Vec<crate::plot::LadderPanel> {
    use crate::measurement::Set;
    let rungs = rungs(rows);
    let mut panels = Vec::new();
    for engine in ["gpu", "cpu"] {
        let ns = |k: u32| cost_of(rows, rung_method(k), k, engine);
        if rungs.iter().all(|&k| ns(k).is_none()) {
            continue;
        }
        let mut curves = Vec::new();
        for (label, set, band) in [
            ("this environment", None, None),
            ("this environment, n·v ≤ 0.1", None, Some(0.1)),
            ("tuning set", Some(Set::Tuning), None),
            ("held-out set", Some(Set::HeldOut), None),
            ("held-out set, n·v ≤ 0.1", Some(Set::HeldOut), Some(0.1)),
        ] {
            let points: Vec<(f64, f64, u32)> = rungs
                .iter()
                .filter_map(|&k| {
                    let errs: Vec<f64> = rung_rows(rows, k)
                        .filter(|r| r.set == set && r.nv_hi == band && (set.is_some() || r.backend == engine))
                        .map(|r| r.mean_error)
                        .collect();
                    (!errs.is_empty()).then(|| Some((ns(k)?, errs.iter().sum::<f64>() / errs.len() as f64, k)))?
                })
                .collect();
            if !points.is_empty() {
                curves.push(crate::plot::LadderCurve { label: label.to_string(), points });
            }
        }
        panels.push(crate::plot::LadderPanel {
            title: format!("shading ladder, cost on the {}", if engine == "gpu" { "GPU" } else { "CPU" }),
            x_label: "ns per shaded pixel".into(),
            curves,
        });
    }
    panels
}

/// The budget curve's rows: the shaded colour's total over all points of the report's
/// environment (or its `n·v ≤ 0.1` band), per backend and budget.
fn budget_rows(rows: &[Measurement], band: Option<f32>) -> impl Iterator<Item = &Measurement> {
    rows.iter().filter(move |r| {
        r.method == Method::TimeBudget
            && r.product == Quantity::ShadedColour
            && r.part == Part::Total
            && r.set.is_none()
            && r.roughness_lo.is_none()
            && r.near_sun.is_none()
            && r.nv_hi == band
    })
}

/// The budget curve's table: per backend and budget, the settings chosen, their estimated
/// and measured bake time, and their error end to end.
pub(crate) fn budget_table(rows: &[Measurement]) -> Option<Table> {
    let cells: Vec<[String; 8]> = budget_rows(rows, None)
        .map(|r| {
            let grazing = budget_rows(rows, Some(0.1))
                .find(|g| g.backend == r.backend && g.budget_s == r.budget_s)
                .map_or("-".into(), |g| format!("{:.1} %", 100.0 * g.mean_error));
            [
                r.backend.clone(),
                format!("{}", r.budget_s.unwrap_or(f64::NAN)),
                r.samples.map_or("-".into(), |n| n.to_string()),
                r.source_size.map_or("-".into(), |s| format!("{s}²")),
                r.estimate_s.map_or("-".into(), |e| format!("{e:.3}")),
                r.time_ms.map_or("-".into(), |t| format!("{:.3}", t * 1e-3)),
                format!("{:.1} %", 100.0 * r.mean_error),
                grazing,
            ]
        })
        .collect();
    (!cells.is_empty()).then(|| {
        let header = ["backend", "budget (s)", "samples at mip 1", "irradiance from", "estimate (s)", "bake (s)", "error, this environment", "its n·v ≤ 0.1"];
        ("time budget: the settings chosen and their error".to_string(), header, cells)
    })
}

/// The budget curve's figure: the error end to end against the budget, a panel per backend.
pub fn budget_panels(rows: &[Measurement]) -> Vec<crate::plot::LadderPanel> {
    let mut panels = Vec::new();
    for engine in ["gpu", "cpu"] {
        let curve = |band: Option<f32>| -> Vec<(f64, f64, u32)> {
            budget_rows(rows, band).filter(|r| r.backend == engine).filter_map(|r| Some((r.budget_s?, r.mean_error, r.samples?))).collect()
        };
        let curves: Vec<crate::plot::LadderCurve> = [("this environment", None), ("its n·v ≤ 0.1", Some(0.1))]
            .into_iter()
            .map(|(label, band)| crate::plot::LadderCurve { label: label.to_string(), points: curve(band) })
            .filter(|c| !c.points.is_empty())
            .collect();
        if !curves.is_empty() {
            panels.push(crate::plot::LadderPanel {
                title: format!("time budget on the {}", if engine == "gpu" { "GPU" } else { "CPU" }),
                x_label: "budget per bake (s)".into(),
                curves,
            });
        }
    }
    panels
}

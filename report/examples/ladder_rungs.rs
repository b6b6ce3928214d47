//! The shading ladder's rungs alone, over both sets, outside CI: the defaults' one fetch
//! and 2, 4, 8 and 16 fetches, each set's mean error of the shaded colour over every point
//! and per `n·v` band, as `runner report --sets` measures them (`splitsum_report::sets`),
//! in a fraction of its time.
//!
//! `cargo run --release -p splitsum-report --example ladder_rungs -- [tuning|held-out]`
//! (both sets without an argument; `bash scripts/dev.sh environments` fetches the files).
use splitsum::backend::Backend;
use splitsum::measured::{Method, Set};
use splitsum_report::figures::set_mean;
use splitsum_report::sets::{self, MEMBERS};
use splitsum_report::sweep::Sweep;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let only = match std::env::args().nth(1).as_deref() {
        None => None,
        Some("tuning") => Some(Set::Tuning),
        Some("held-out") => Some(Set::HeldOut),
        Some(other) => return Err(format!("usage: ladder_rungs [tuning|held-out], not {other}").into()),
    };
    let sweep = Sweep::full();
    let dir = Path::new("target/environments");
    let methods = |n: u32| sweep.set_methods(n).into_iter().filter(|m| matches!(m.kind, Method::Defaults | Method::Ladder)).collect();
    let rows = sets::run(&Backend::Cpu, dir, sweep.accuracy_source, sweep.accuracy_points, methods, |m| only.is_none_or(|s| m.set == s))?;
    // Columns as the rung table's, by each band's lower end: all points, then n·v ≤ 0.1,
    // 0.1–0.3, 0.3–0.6, 0.6–1.
    let bands: [Option<f32>; 5] = [None, Some(0.0), Some(0.1), Some(0.3), Some(0.6)];
    for set in [Set::Tuning, Set::HeldOut].into_iter().filter(|s| only.is_none_or(|o| o == *s)) {
        println!("{} ({} environments)", set.title(), MEMBERS.iter().filter(|m| m.set == set).count());
        for fetches in [1, 2, 4, 8, 16] {
            let method = if fetches == 1 { Method::Defaults } else { Method::Ladder };
            let cells: Vec<String> =
                bands.iter().map(|&lo| set_mean(&rows, set, method, fetches, None, lo).map_or("    -".into(), |e| format!("{:5.1}", 100.0 * e))).collect();
            println!("  {fetches:2} fetches: {}", cells.join(" "));
        }
    }
    Ok(())
}

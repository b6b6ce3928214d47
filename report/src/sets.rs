//! Accuracy that holds on environments nobody tuned on: the end-to-end measure
//! ([`crate::accuracy`]) over two sets of environments of every kind, a **tuning set** that
//! design choices may look at and a **held-out set** that no choice looked at.
//!
//! The real environments are Blender's CC0 studio lights (`blender-data`,
//! `usr/share/blender/datafiles/studiolights/world/`; `bash scripts/dev.sh environments`
//! fetches them): city.exr and courtyard.exr, on which the defaults before this measure
//! were chosen, are in the tuning set with forest.exr; studio, interior, night, sunrise and
//! sunset are held out. Skies generated in code ([`crate::skies`]) give suns of 10³ to 10⁶
//! and an overcast sky, split between the sets in the same way.

use crate::accuracy::{Method, Points, measure};
use crate::measurement::{Measurement, Set};
use splitsum::backend::Backend;
use splitsum::bake;
use splitsum::environment::{self, Environment};
use splitsum::error::{Error, Result};
use splitsum::settings::Settings;
use std::path::Path;

/// Where an environment of a set comes from.
#[derive(Clone, Copy, Debug)]
pub enum Source {
    /// A file of Blender's studio lights, by name.
    File(&'static str),
    /// [`crate::skies::sunny`]: a sun of this radiance at this elevation (degrees).
    Sunny {
        /// Radiance of the sun's disc.
        sun: f32,
        /// Degrees above the horizon.
        elevation: f32,
    },
    /// [`crate::skies::overcast`].
    Overcast,
}

/// One environment of a set.
#[derive(Clone, Copy, Debug)]
pub struct Member {
    /// Its name in the report.
    pub name: &'static str,
    /// What kind of light it is.
    pub kind: &'static str,
    /// Its set.
    pub set: Set,
    /// Where it comes from.
    pub source: Source,
}

/// The two sets: 6 environments to tune on, 8 held out, of every kind in both.
pub const MEMBERS: [Member; 14] = [
    Member { name: "city", kind: "outdoor, sun", set: Set::Tuning, source: Source::File("city.exr") },
    Member { name: "courtyard", kind: "outdoor, soft sun", set: Set::Tuning, source: Source::File("courtyard.exr") },
    Member { name: "forest", kind: "outdoor, under trees", set: Set::Tuning, source: Source::File("forest.exr") },
    Member { name: "sky, sun 10^4 at 35°", kind: "generated, sun", set: Set::Tuning, source: Source::Sunny { sun: 1e4, elevation: 35.0 } },
    Member { name: "sky, sun 10^5 at 50°", kind: "generated, sun", set: Set::Tuning, source: Source::Sunny { sun: 1e5, elevation: 50.0 } },
    Member { name: "overcast sky", kind: "generated, overcast", set: Set::Tuning, source: Source::Overcast },
    Member { name: "studio", kind: "studio", set: Set::HeldOut, source: Source::File("studio.exr") },
    Member { name: "interior", kind: "indoor", set: Set::HeldOut, source: Source::File("interior.exr") },
    Member { name: "night", kind: "outdoor, night", set: Set::HeldOut, source: Source::File("night.exr") },
    Member { name: "sunrise", kind: "outdoor, low sun", set: Set::HeldOut, source: Source::File("sunrise.exr") },
    Member { name: "sunset", kind: "outdoor, low sun", set: Set::HeldOut, source: Source::File("sunset.exr") },
    Member { name: "sky, sun 10^3 at 15°", kind: "generated, low sun", set: Set::HeldOut, source: Source::Sunny { sun: 1e3, elevation: 15.0 } },
    Member { name: "sky, sun 10^6 at 65°", kind: "generated, high sun", set: Set::HeldOut, source: Source::Sunny { sun: 1e6, elevation: 65.0 } },
    Member { name: "sky, sun 10^4 at 5°", kind: "generated, sun at the horizon", set: Set::HeldOut, source: Source::Sunny { sun: 1e4, elevation: 5.0 } },
];

/// Checks that `dir` holds every file of the sets, before a report spends minutes on its
/// other measurements.
pub fn check(dir: &Path) -> Result<()> {
    for m in &MEMBERS {
        if let Source::File(file) = m.source
            && !dir.join(file).exists()
        {
            return Err(missing(&dir.join(file), dir));
        }
    }
    Ok(())
}

fn missing(path: &Path, dir: &Path) -> Error {
    Error::Invalid(format!(
        "{} is missing: the sets need Blender's CC0 studio lights in {} (bash scripts/dev.sh environments fetches them)",
        path.display(),
        dir.display()
    ))
}

/// Loads `member`: a file from `dir` (its full resolution, up to the display's cap), or a
/// generated sky `width` texels wide.
pub fn load(member: &Member, dir: &Path, width: u32) -> Result<Environment> {
    Ok(match member.source {
        Source::File(file) => {
            let path = dir.join(file);
            if !path.exists() {
                return Err(missing(&path, dir));
            }
            environment::load(&path, false)?.0
        }
        Source::Sunny { sun, elevation } => crate::skies::sunny(width, sun, elevation),
        Source::Overcast => crate::skies::overcast(width),
    })
}

/// The end-to-end measure of `methods(native face size)` on every member of both sets
/// (those `keep` accepts), on `backend`, with `points` (shading points, lookups) and a
/// source cube of at most `source` texels a side; rows carry their set and environment.
pub fn run(
    backend: &Backend,
    dir: &Path,
    source: u32,
    points: (u32, u32),
    methods: impl Fn(u32) -> Vec<Method>,
    keep: impl Fn(&Member) -> bool,
) -> Result<Vec<Measurement>> {
    let mut rows = Vec::new();
    for member in MEMBERS.iter().filter(|m| keep(m)) {
        let _step = splitsum::progress::step(&format!("sets: {} ({}, {})", member.name, member.kind, member.set.title()), None);
        let env = load(member, dir, 4 * source)?;
        let methods = methods(env.native_face_size());
        let src = methods[0].settings.source_size.unwrap_or(methods[0].settings.size).min(source);
        let cube = bake::host_source_cube(&Backend::Cpu, &env, &Settings { source_size: Some(src), size: src, ..Settings::default() })?;
        let p = Points::new(&cube, points.0, points.1);
        for r in measure(backend, &env, &methods, &p)? {
            rows.push(Measurement { environment: member.name.to_string(), set: Some(member.set), ..r });
        }
    }
    Ok(rows)
}

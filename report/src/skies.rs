//! Analytic skies generated in code, for measurements on environments nobody tuned on:
//! a clear sky (a zenith-to-horizon gradient over a dim ground) with a sun disc of a
//! given radiance, `10³`–`10⁶` times the sky's, as real suns are.

use splitsum::environment::Environment;
use splitsum::texture::Equirect;
use splitsum_shaders::equirect::uv_to_dir;
use splitsum_shaders::glam::{Vec2, Vec3, Vec4};

/// The sun's direction at `elevation` degrees above the horizon.
pub fn sun_direction(elevation: f32) -> Vec3 {
    let (elevation, azimuth) = (elevation.to_radians(), 40f32.to_radians());
    Vec3::new(elevation.cos() * azimuth.sin(), elevation.sin(), -elevation.cos() * azimuth.cos())
}

/// The sun's angular radius (a little wider than the real 0.27°, so that a 1024-wide
/// equirect resolves its disc).
pub const SUN_RADIUS_DEGREES: f32 = 0.5;

/// A clear sky `width`×`width/2` with a sun of radiance `sun` (white) at `elevation`
/// degrees, its disc supersampled 4×4 per texel so that its edge is area-weighted.
pub fn sunny(width: u32, sun: f32, elevation: f32) -> Environment {
    let height = width / 2;
    let s = sun_direction(elevation);
    let cos_radius = SUN_RADIUS_DEGREES.to_radians().cos();
    let sky = |d: Vec3| -> Vec3 {
        if d.y < 0.0 {
            // Ground: a dim, warm grey lit by sky and sun.
            Vec3::new(0.16, 0.14, 0.11)
        } else {
            let t = d.y.sqrt();
            Vec3::new(0.75, 0.85, 1.0).lerp(Vec3::new(0.2, 0.4, 0.9), t)
        }
    };
    let texels = (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let centre = uv_to_dir(Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32));
            let mut c = sky(centre);
            // Only texels near the sun need their disc coverage.
            if centre.dot(s) > (2.0 * SUN_RADIUS_DEGREES).to_radians().cos() - 0.01 {
                let n = 4;
                let mut covered = 0;
                for j in 0..n {
                    for k in 0..n {
                        let uv = Vec2::new((x as f32 + (k as f32 + 0.5) / n as f32) / width as f32, (y as f32 + (j as f32 + 0.5) / n as f32) / height as f32);
                        covered += u32::from(uv_to_dir(uv).dot(s) >= cos_radius);
                    }
                }
                c += Vec3::splat(sun * covered as f32 / (n * n) as f32);
            }
            c.extend(1.0)
        })
        .collect::<Vec<Vec4>>();
    Environment::Equirect(Equirect { width, height, texels })
}

/// An overcast sky `width`×`width/2`: the CIE standard overcast sky, radiance
/// `(1 + 2 cos θ)/3` of its zenith's (Moon & Spencer 1942), over a ground of albedo 0.2 lit
/// by it (`E = 7π/9` of the zenith radiance, reflected as `0.2·E/π`).
pub fn overcast(width: u32) -> Environment {
    let height = width / 2;
    let zenith = Vec3::new(0.9, 0.92, 1.0);
    let texels = (0..width * height)
        .map(|i| {
            let d = uv_to_dir(Vec2::new(((i % width) as f32 + 0.5) / width as f32, ((i / width) as f32 + 0.5) / height as f32));
            let c = if d.y >= 0.0 { zenith * (1.0 + 2.0 * d.y) / 3.0 } else { zenith * (0.2 * 7.0 / 9.0) };
            c.extend(1.0)
        })
        .collect();
    Environment::Equirect(Equirect { width, height, texels })
}

//! The display: the GPU renderer against the CPU reference renderer, which evaluates the
//! same `scene::pixel` per pixel.

use splitsum::Backend;
use splitsum_display::render::{GpuScene, ViewState, render_cpu};
use splitsum_shaders::choice::Choice;
use splitsum_shaders::glam::Vec4;
use splitsum_shaders::shade::{DiffuseModel, FresnelForm, ShadeOptions, SpecularModel};

fn diff(a: &[Vec4], b: &[Vec4]) -> (f32, usize) {
    let mut worst = 0.0f32;
    let mut over = 0;
    for (x, y) in a.iter().zip(b) {
        assert!(x.is_finite() && y.is_finite());
        let d = (*x - *y).abs().max_element();
        worst = worst.max(d);
        if d > 0.5 / 255.0 {
            over += 1;
        }
    }
    (worst, over)
}

/// Renders each of `views` (96×64) on the GPU and with the CPU reference renderer from one
/// small bake; no pixel may differ by half an 8-bit step. The largest difference.
/// The GPU-vs-CPU bound on display values: the float rounding of the shading
/// (`support::gpu_bound`), plus, where frames render into RGBA16F (wgpu's GL backend on
/// llvmpipe renders to no 32-bit float format), one step of a half below 1: 2⁻¹¹.
fn frame_bound() -> f32 {
    let Backend::Gpu(gpu) = support::gpu() else { unreachable!() };
    let half = GpuScene::offscreen_format(gpu) == wgpu::TextureFormat::Rgba16Float;
    support::gpu_bound(1e-5, 2e-4) as f32 + if half { 2f32.powi(-11) } else { 0.0 }
}

fn worst_gpu_vs_cpu(views: impl IntoIterator<Item = ViewState>) -> f32 {
    let env = support::small_display_bake();
    let gpu = match support::gpu() {
        Backend::Gpu(g) => g,
        Backend::Cpu => unreachable!(),
    };
    let scene = GpuScene::new(gpu, &env);
    let mut worst_all = 0.0f32;
    for view in views {
        let frame = view.frame(scene.shape, 96, 64, true);
        let g = scene.render_offscreen(gpu, &frame, None).unwrap();
        let c = render_cpu(&env, &frame);
        let (worst, over) = diff(&g, &c);
        worst_all = worst_all.max(worst);
        assert_eq!(over, 0, "{}: {over} pixels differ by more than half an 8-bit step (max {worst:e})", view.summary());
    }
    worst_all
}

/// Every shading model, GPU against CPU, in display values (sRGB-encoded, [0, 1]): the
/// geometry is ray-cast and every texture read is software filtering in `splitsum_shaders`,
/// so only float rounding differs.
#[test]
fn gpu_matches_the_cpu_reference() {
    let mut views = Vec::new();
    for diffuse in 0..(DiffuseModel::ALL.len() as u32) {
        for specular in 0..(SpecularModel::ALL.len() as u32) {
            for fresnel in 0..(FresnelForm::ALL.len() as u32) {
                views.push(ViewState {
                    options: ShadeOptions { diffuse, specular, fresnel, flags: ShadeOptions::IBL | ShadeOptions::DIRECT },
                    sky_blur: 1.3,
                    ..ViewState::default()
                });
            }
        }
    }
    let worst_all = worst_gpu_vs_cpu(views);
    println!(
        "scene 96×64, all {} model combinations: GPU vs CPU max |Δ| = {worst_all:.2e} (display values)",
        (DiffuseModel::ALL.len() as u32) * (SpecularModel::ALL.len() as u32) * (FresnelForm::ALL.len() as u32)
    );
    // lavapipe 2.4e-7; an H100 5.4e-5 (sphere silhouettes, where shading is steep in the
    // hit point; see `support::gpu_bound`), 1.4e-3 before the ray–sphere discriminant was
    // made cancellation-free; plus the render target's rounding (`frame_bound`).
    let bound = frame_bound();
    assert!(worst_all < bound, "{worst_all:e} (bound {bound:e})");
}

/// Every shading option of the image-based and direct light (dominant direction, the lift
/// above the horizon, multiple
/// scattering, exact Smith for direct light, filtered sampling below mip 1, the common
/// roughness-aware Fresnel weights, the shading ladder's 2 to 16 fetches), alone and all together, GPU
/// against CPU, under the same bound as the models.
#[test]
fn shading_options_gpu_match_the_cpu_reference() {
    let base = ShadeOptions::IBL | ShadeOptions::DIRECT;
    let all = ShadeOptions::DOMINANT_DIRECTION
        | ShadeOptions::LIFT_ABOVE_HORIZON
        | ShadeOptions::MULTISCATTER
        | ShadeOptions::CORRELATED_SMITH
        | ShadeOptions::FILTERED_SAMPLING;
    let extras = [
        0,
        ShadeOptions::DOMINANT_DIRECTION,
        ShadeOptions::LIFT_ABOVE_HORIZON,
        ShadeOptions::MULTISCATTER,
        ShadeOptions::CORRELATED_SMITH,
        ShadeOptions::FILTERED_SAMPLING,
        ShadeOptions::LOG_MIP_BLEND,
        all,
        all & !ShadeOptions::FILTERED_SAMPLING | ShadeOptions::LOG_MIP_BLEND,
        ShadeOptions::ROUGHNESS_FRESNEL,
    ];
    let mut views: Vec<ViewState> =
        extras.iter().map(|&extra| ViewState { options: ShadeOptions { flags: base | extra, ..ShadeOptions::DEFAULT }, ..ViewState::default() }).collect();
    // The shading ladder's rungs: 2 to 16 fetches, seen from a low camera so that the
    // grid's spheres show grazing views (where the ladder is used).
    for fetches in [2, 4, 8, 16] {
        views.push(ViewState { options: ShadeOptions::DEFAULT.with_fetches(fetches), pitch: 0.3, ..ViewState::default() });
    }
    let worst_all = worst_gpu_vs_cpu(views);
    println!("scene 96×64, shading options: GPU vs CPU max |Δ| = {worst_all:.2e} (display values)");
    let bound = frame_bound();
    assert!(worst_all < bound, "{worst_all:e} (bound {bound:e})");
}

/// The frame's projection (glam's right-handed, depth in [0, 1]) against its closed form:
/// a point on the view axis at the near plane has depth 0, at the far plane 1; a point on
/// the top edge of the field of view maps to y = +1 (wgpu's NDC is y-up), one on the right
/// edge to x = +1: the edges of the field of view the ray-cast scene builds from
/// `Frame::forward`, `right`, `up` and `tan_half_fov`. Tolerance 1e-4: f32 rounding of a
/// matrix product over distances up to 500 (the far plane).
#[test]
fn the_projection_is_right_handed_with_depth_zero_to_one() {
    use splitsum_shaders::glam::Vec3;
    let state = ViewState { pitch: 0.3, yaw: 0.7, ..ViewState::default() };
    let (w, h) = (320u32, 200u32);
    let f = state.frame(bytemuck::Zeroable::zeroed(), w, h, true);
    let (eye, fwd, right, up) = (f.eye.truncate(), f.forward.truncate(), f.right.truncate(), f.up.truncate());
    let ndc = |p: Vec3| {
        let c = f.view_proj * p.extend(1.0);
        c.truncate() / c.w
    };
    let tol = 1e-4;
    assert!(ndc(eye + fwd * f.near).z.abs() < tol, "near → 0");
    assert!((ndc(eye + fwd * f.far).z - 1.0).abs() < tol, "far → 1");
    let top = ndc(eye + (fwd + up * f.tan_half_fov) * 10.0);
    assert!((top.y - 1.0).abs() < tol && top.x.abs() < tol, "top edge: {top}");
    let aspect = w as f32 / h as f32;
    let side = ndc(eye + (fwd + right * f.tan_half_fov * aspect) * 10.0);
    assert!((side.x - 1.0).abs() < tol && side.y.abs() < tol, "right edge: {side}");
}

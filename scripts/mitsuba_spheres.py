"""Mitsuba 3 renders of single spheres, r 0.3 to 1, of white metal (F0 = 1) and of a coloured
dielectric, with the glTF 2.0 BRDF itself (`mitsuba_gltf.py`: height-correlated Smith,
`fresnel_mix` of Lambert and GGX), under each sunny environment that `mitsuba_spheres envs
DIR` wrote, and their comparison with splitsum's shading of the same pixels (`mitsuba_spheres
shade DIR`). Run by scripts/mitsuba.sh, in Mitsuba's `llvm_ad_rgb` variant (a Python BSDF
runs once per wavefront there).

  python3 mitsuba_spheres.py render DIR SPP RES
  python3 mitsuba_spheres.py compare DIR SPP RES [FIGURE]
"""
import math
import struct
import sys
from pathlib import Path

import numpy as np

ROUGHNESS = [0.3, 0.5, 0.65, 0.8, 1.0]
FETCHES = [1, 4, 16]
# The materials: name, metallic, base colour (mitsuba_spheres.rs's MATERIALS, the same).
MATERIALS = [("metal", 1.0, (1.0, 1.0, 1.0)), ("dielectric", 0.0, (0.9, 0.6, 0.3))]
# The pixels compared: the sphere's interior, n.v >= 0.15 (at the rim a pixel's footprint
# spans normals its averaged normal does not stand for).
MIN_NV = 0.15
# Every how many pixels `mitsuba_spheres shade` computes the exact integrals (its STRIDE).
STRIDE = 16


def splitsum_dir(u, v):
    """splitsum's equirect direction at (u, v) (shaders/src/equirect.rs, uv_to_dir)."""
    phi = 2 * math.pi * (u - 0.5)
    theta = math.pi * v
    return np.array([math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi)])


def environment_transform(mi, exr):
    """The rotation about +y (and mirror) that makes Mitsuba's envmap give, for a direction,
    the radiance splitsum reads there: found on six texels, not assumed. (Mitsuba's
    bilinear read sits a fraction of a texel from splitsum's texel centres, hence the 10 %
    tolerance; a wrong orientation is off by tens of percent, and must be at least three
    times further off than the right one.)"""
    bitmap = np.array(mi.Bitmap(str(exr)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False))
    h, w, _ = bitmap.shape
    lum = bitmap @ np.array([0.2126, 0.7152, 0.0722])
    # The brightest texel tells rotations apart where the sky alone is the same at every
    # azimuth (the generated skies).
    picks = [np.unravel_index(np.argmax(lum), lum.shape), (h // 3, w // 5), (h // 2 + 7, 3 * w // 4), (h // 5, w // 2 + 11), (2 * h // 3, w // 7), (h // 4, 5 * w // 8)]
    scores = []
    best = None
    for angle in [0, 90, 180, 270]:
        for flip in [1, -1]:
            to_world = mi.ScalarTransform4f().rotate([0, 1, 0], angle) @ mi.ScalarTransform4f().scale([flip, 1, 1])
            emitter = mi.load_dict({"type": "envmap", "filename": str(exr), "to_world": to_world})
            err = 0.0
            for (y, x) in picks:
                d = splitsum_dir((x + 0.5) / w, (y + 0.5) / h)
                si = mi.SurfaceInteraction3f()
                si.wi = mi.Vector3f(-d)
                got = np.array(emitter.eval(si)).reshape(-1)[:3]
                want = bitmap[y, x]
                err += float(np.abs(got - want).sum() / (np.abs(want).sum() + 1e-9)) / len(picks)
            scores.append(err)
            if best is None or err < best[0]:
                best = (err, to_world, angle, flip)
    runner_up = sorted(scores)[1]
    if best[0] > 0.1 or runner_up < 3 * best[0]:
        raise SystemExit(f"{exr}: no one rotation of Mitsuba's envmap matches splitsum's directions (best {best[0]:.3g}, next {runner_up:.3g})")
    return best[1], best[2], best[3]


def render(directory, spp, res):
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    import mitsuba_gltf
    mitsuba_gltf.register()
    directory = Path(directory)
    for line in (directory / "envs.txt").read_text().splitlines():
        slug = line.split("\t")[0]
        exr = directory / f"{slug}.exr"
        to_world, angle, flip = environment_transform(mi, exr)
        sensor = {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 4], target=[0, 0, 0], up=[0, 1, 0]) @ mi.ScalarTransform4f().scale([1.05, 1.05, 1]),
            "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        }
        emitter = {"type": "envmap", "filename": str(exr), "to_world": to_world}
        normals = mi.render(mi.load_dict({"type": "scene", "integrator": {"type": "aov", "aovs": "nn:sh_normal"}, "sensor": dict(sensor, sampler={"type": "independent", "sample_count": 16}), "sphere": {"type": "sphere"}}))
        normals = np.array(normals)[:, :, :3].reshape(-1, 3)
        length = np.linalg.norm(normals, axis=1)
        view = np.array([0.0, 0.0, 1.0])
        inside = (length > 0.999) & (normals @ view / np.maximum(length, 1e-9) >= MIN_NV)
        n = normals[inside] / length[inside, None]
        v = np.broadcast_to(view, n.shape)
        np.concatenate([n, v], axis=1).astype("<f4").tofile(directory / f"{slug}_points.f32")
        for material, metallic, base in MATERIALS:
            for r in ROUGHNESS:
                bsdf = {"type": "gltf", "base_r": base[0], "base_g": base[1], "base_b": base[2], "metallic": metallic, "roughness": r}
                scene = mi.load_dict({
                    "type": "scene",
                    # Depth 2: the environment seen in the sphere once (a convex sphere sees
                    # nothing else), the exact reflectance integral, estimated.
                    "integrator": {"type": "path", "max_depth": 2},
                    "sensor": sensor,
                    "emitter": emitter,
                    "sphere": {"type": "sphere", "bsdf": bsdf},
                })
                # Two independent halves of the samples: their mean is the estimate, their
                # difference measures its noise (the floor under any per-pixel comparison).
                halves = [np.array(mi.render(scene, seed=seed, spp=max(spp // 2, 1)))[:, :, :3].reshape(-1, 3)[inside] for seed in (7, 8)]
                np.stack(halves).astype("<f4").tofile(directory / f"{slug}_{material}_r{r:g}_mitsuba.f32")
        print(f"rendered {slug} (envmap rotated {angle} degrees about +y, x scaled {flip}), {inside.sum()} pixels", flush=True)


def luminance(rgb):
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def machine():
    """This machine in the words the report's figures use: cores and CPU model."""
    import os
    model = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name")), "unknown CPU")
    return f"{os.cpu_count()} cores of {' '.join(model.split()[:2])}"


def commit():
    """The commit measured, and whether the work tree differed from it."""
    import subprocess
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True).stdout.strip()
    return head + (" with uncommitted changes" if dirty else "")


def compare(directory, spp, res, figure=None):
    """Prints the per-sphere table and the means over each set and material; with `figure`,
    writes them there too, as a generated figure of the guide (its command, date, machine
    and commit)."""
    import datetime
    directory = Path(directory)
    lines = []

    def say(text=""):
        lines.append(text)
        print(text)

    rows = []
    exact_rows = []
    say("| environment | set | material | r | Mitsuba's noise per pixel | " + " | ".join(f"{k} fetch{'es' if k > 1 else ''}: mean per pixel (sphere's mean)" for k in FETCHES) + " | n·v 0.15–0.7, 1 fetch (signed) | exact glTF integral against Mitsuba | 16 fetches against the exact integral |")
    say("|---|---|---|---|---|" + "---|" * (len(FETCHES) + 3))
    for line in (directory / "envs.txt").read_text().splitlines():
        slug, which, name = line.split("\t")
        points = np.fromfile(directory / f"{slug}_points.f32", dtype="<f4").reshape(-1, 6)
        nv = points[:, 2]
        for material, _, _ in MATERIALS:
            for r in ROUGHNESS:
                stem = f"{slug}_{material}_r{r:g}"
                halves = luminance(np.fromfile(directory / f"{stem}_mitsuba.f32", dtype="<f4").reshape(2, -1, 3))
                truth = halves.mean(axis=0)
                # The standard error of the two halves' mean, per pixel, relative.
                noise = np.abs(halves[0] - halves[1]) / 2 / np.maximum(truth, 1e-6)
                cells = [f"{100 * noise.mean():.1f} %"]
                signed = None
                for k in FETCHES:
                    got = luminance(np.fromfile(directory / f"{stem}_k{k}.f32", dtype="<f4").reshape(-1, 3))
                    rel = np.abs(got - truth) / np.maximum(truth, 1e-6)
                    whole = abs(got.mean() - truth.mean()) / truth.mean()
                    cells.append(f"{100 * rel.mean():.1f} % ({100 * whole:.1f} %)")
                    rows.append((which, material, r, k, rel.mean(), whole, noise.mean()))
                    if k == 1:
                        band = nv <= 0.7
                        signed = (got[band] - truth[band]).mean() / truth[band].mean()
                # The exact integral at every STRIDE-th pixel (mitsuba_spheres shade): against
                # Mitsuba (the witness checked), and the 16 fetches against it.
                pick = np.arange(len(points))[::STRIDE]
                exact = luminance(np.fromfile(directory / f"{stem}_exact.f32", dtype="<f4").reshape(-1, 3))
                sixteen = luminance(np.fromfile(directory / f"{stem}_k16.f32", dtype="<f4").reshape(-1, 3))[pick]

                def against(got, want):
                    return np.mean(np.abs(got - want) / np.maximum(want, 1e-6)), (got.mean() - want.mean()) / want.mean()

                pairs = [against(exact, truth[pick]), against(sixteen, exact)]
                exact_rows.append((which, material, r, pairs))
                more = " | ".join(f"{100 * p:.1f} % ({100 * w:+.1f} %)" for p, w in pairs)
                say(f"| {name} | {which} | {material} | {r} | " + " | ".join(cells) + f" | {100 * signed:+.1f} % | {more} |")
    say()
    for which in ["tuning", "held-out"]:
        for material, _, _ in MATERIALS:
            for k in FETCHES:
                sel = [row for row in rows if row[0] == which and row[1] == material and row[3] == k]
                worst = max(sel, key=lambda s: s[4])
                say(f"- {which}, {material}, {k} fetch(es): mean over spheres of the mean per-pixel error {100 * np.mean([s[4] for s in sel]):.1f} % (Mitsuba's noise {100 * np.mean([s[6] for s in sel]):.1f} %), worst sphere {100 * worst[4]:.1f} % (r {worst[2]}); error of the sphere's mean {100 * np.mean([s[5] for s in sel]):.1f} %")
    for which in ["tuning", "held-out"]:
        for material, _, _ in MATERIALS:
            sel = [row for row in exact_rows if row[0] == which and row[1] == material]
            for i, what in enumerate(["the exact glTF integral against Mitsuba", "16 fetches against the exact glTF integral"]):
                say(f"- {which}, {material}, {what}: mean per-pixel error {100 * np.mean([s[3][i][0] for s in sel]):.1f} %, worst sphere {100 * max(s[3][i][0] for s in sel):.1f} %; sphere's mean {100 * np.mean([s[3][i][1] for s in sel]):+.1f} % (worst {100 * max((s[3][i][1] for s in sel), key=abs):+.1f} %)")
    if figure:
        head = f"<!-- Written by `bash scripts/mitsuba.sh --figure {figure} {spp} {res}` (scripts/mitsuba_spheres.py); regenerate it, do not edit it. -->\n\n"
        tail = (
            f"\nSpheres of white metal (F₀ = 1) and of a dielectric (base colour 0.9, 0.6, 0.3), GGX with α = r², rendered by Mitsuba 3's path tracer with the glTF BRDF "
            f"(scripts/mitsuba_gltf.py) at {spp} samples per pixel, {res}×{res}, "
            "against splitsum's shading of the same pixels (defaults, n·v ≥ 0.15): mean relative luminance error per pixel, the error of the sphere's mean luminance in brackets. "
            f"The last two columns, at every {STRIDE}th pixel: the exact reflectance integral of the glTF BRDF over the baked source cube (splitsum-reference) against Mitsuba (the sphere's mean signed), and splitsum's 16 fetches against it. "
            f"Measured {datetime.date.today().isoformat()}, {machine()}, commit {commit()}.\n"
        )
        Path(figure).write_text(head + "\n".join(lines) + "\n" + tail)


if __name__ == "__main__":
    if sys.argv[1] == "render":
        render(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
    else:
        compare(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5] if len(sys.argv) > 5 else None)

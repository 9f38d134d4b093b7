#!/usr/bin/env python3
"""Cross-check the harness's image-based lighting against Mitsuba 3, a path tracer with no code in
common with it.

A row of five spheres lit only by an environment (no lights, no ambient) is rendered twice:

- by the harness (`harness render --pass light`, the linear light buffer, exposure 1, on gl);
- by Mitsuba 3 (llvm_ad_rgb), direct environment light only (the `direct` integrator), each
  sphere alone in its own render, since the harness models neither light bouncing between
  spheres nor one sphere hiding part of the sky from another.

Spheres, left to right: Lambert (albedo 0.8, the harness's `lambert` model), then white metals
(base colour 1, so Fresnel is exactly 1 in both renderers) of GGX roughness 0.2, 0.5 and 0.8
(alpha = roughness^2), and a mirror (roughness 0; Mitsuba `conductor`). The metals' BRDF on
Mitsuba's side is the harness's own (`--metal filament`, the default): GGX D and the
height-correlated Smith visibility of Filament, written here as a Mitsuba BSDF plugin. Mitsuba's
`roughconductor` (`--metal roughconductor`) uses Smith's separable masking-shadowing instead,
which is darker at grazing angles on rough metals (white furnace, alpha 0.64: 5-11% at N.V
0.2-0.4); that difference is the BRDF's, not the image-based lighting's. Environments: the two
the project ships (scenes/assets/sunset.exr and interior.exr) or `--environment FILE`, with
negative texels clamped to 0 as the harness's precompute does (Mitsuba drops samples with
negative values). Mitsuba's envmap needs to_world = rotate(Y, 180 +
rotation) to match the harness's equirectangular convention.

Per sphere, over the pixels where both renders see the sphere away from its silhouette (N.V >=
0.3), it prints harness mean / Mitsuba mean, and the mean and 95th percentile of the per-pixel
relative error |harness - mitsuba| / mitsuba (luminance). The per-pixel figures include
Mitsuba's own noise, about 1/sqrt(spp) of the pixel value; the ratio of means does not.

    pip install mitsuba          # 3.x
    apt-get install libllvm19    # llvm_ad_rgb needs a libLLVM newer than Debian 12's 15; the
                                 # newest one found is used unless DRJIT_LIBLLVM_PATH is set
    python3 scripts/mitsuba_crosscheck.py [--spp 1024] [--out target/mitsuba] [--min-n-dot-v 0.3]
                                          [--harness target/debug/harness] [--rotation 0]
                                          [--ibl runtime_samples=256 --ibl specular_size=256]
                                          [--metal filament|roughconductor] [--environment FILE]

Not part of `cargo test`: it needs Mitsuba and a recent libLLVM (about 10 s for both skies). The README's "IBL against a
path tracer" section records its table.
"""

import argparse
import glob
import os
import re
import shutil
import subprocess
import sys


def newest_libllvm():
    """The newest libLLVM of major version 16 or later on this machine, or None (Dr.Jit's LLVM
    back end fails to select some intrinsics on LLVM 15, Debian 12's default)."""
    found = []
    for path in glob.glob("/usr/lib/*/libLLVM*.so*") + glob.glob("/usr/lib/llvm-*/lib/libLLVM*.so*"):
        match = re.search(r"libLLVM[-.](?:so\.)?(\d+)", os.path.basename(path))
        if match and int(match.group(1)) >= 16:
            found.append((int(match.group(1)), path))
    return max(found)[1] if found else None


if "DRJIT_LIBLLVM_PATH" not in os.environ:
    LIBLLVM = newest_libllvm()
    if LIBLLVM:
        os.environ["DRJIT_LIBLLVM_PATH"] = LIBLLVM

try:
    import numpy as np
    import mitsuba as mi
except ImportError as missing:  # pragma: no cover
    sys.exit(f"error: {missing.name} is missing: pip install mitsuba numpy")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

WIDTH, HEIGHT = 640, 140
FOV_Y = 12.0
CAMERA = (0.0, 0.0, 12.0)
RADIUS = 0.8
# (label, harness material and model, Mitsuba BSDF)
SPHERES = [
    ("Lambert 0.8", {"lighting": "lambert", "base_color": 0.8}, {"type": "diffuse", "reflectance": 0.8}),
    ("metal r 0.2", {"roughness": 0.2}, None),
    ("metal r 0.5", {"roughness": 0.5}, None),
    ("metal r 0.8", {"roughness": 0.8}, None),
    ("mirror r 0", {"roughness": 0.0}, {"type": "conductor", "material": "none"}),
]
ENVIRONMENTS = ["sunset.exr", "interior.exr"]
# N.V bands of the second table (within the pixels compared).
N_DOT_V_BANDS = [(0.0, 0.2), (0.2, 0.4), (0.4, 0.6), (0.6, 0.8), (0.8, 1.01)]


def sphere_x(index):
    return (index - (len(SPHERES) - 1) / 2) * 2.2


def harness_scene(environment, rotation, ibl=()):
    """The scene file the harness renders (in the folder that holds a copy of the environment),
    with `ibl`'s `key = value` lines under [quality.ibl]."""
    lines = [
        "# Written by scripts/mitsuba_crosscheck.py.",
        'description = "Spheres lit by the environment only, for the Mitsuba cross-check"',
        "[camera]",
        f"position = [{CAMERA[0]}, {CAMERA[1]}, {CAMERA[2]}]",
        "target = [0.0, 0.0, 0.0]",
        f"fov_y = {FOV_Y}",
        "near = 0.1",
        "far = 100.0",
        "[quality]",
        f"width = {WIDTH}",
        f"height = {HEIGHT}",
        "exposure = 1.0",
        "[quality.ibl]",
        *ibl,
        "[environment]",
        f'path = "{environment}"',
        f"rotation = {rotation}",
        "intensity = 1.0",
    ]
    for index, (label, material, _) in enumerate(SPHERES):
        lighting = material.get("lighting", "pbr")
        if lighting == "lambert":
            c = material["base_color"]
            body = f"base_color = [{c}, {c}, {c}]"
        else:
            body = f'roughness = {material["roughness"]}, metallic = 1.0, base_color = [1.0, 1.0, 1.0]'
        lines += [
            "[[objects]]",
            f'name = "{label.replace(" ", "_").replace(".", "")}"',
            'mesh = "builtin:sphere"',
            f"position = [{sphere_x(index)}, 0.0, 0.0]",
            f"scale = {RADIUS}",
            f'lighting = "{lighting}"',
            f"material = {{ {body} }}",
        ]
    return "\n".join(lines) + "\n"


def register_filament_ggx():
    """Registers `filament_ggx`: a white GGX metal as the harness shades it (GGX D, Filament's
    height-correlated Smith visibility, Fresnel 1), sampled by visible normals."""
    import drjit as dr

    class FilamentGGX(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.alpha = props["alpha"]
            self.distribution = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.alpha, True)
            flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            self.m_components = [flags]
            self.m_flags = flags

        def f_cos(self, wi, wo):
            """BRDF x cos(theta_o): D V n.l, V = 0.5 / (n.l sqrt(n.v^2 (1 - a^2) + a^2)
            + n.v sqrt(n.l^2 (1 - a^2) + a^2)) (Filament's V_SmithGGXCorrelated)."""
            a2 = self.alpha * self.alpha
            nv, nl = mi.Frame3f.cos_theta(wi), mi.Frame3f.cos_theta(wo)
            d = self.distribution.eval(dr.normalize(wi + wo))
            vis = 0.5 / (nl * dr.sqrt(nv * nv * (1 - a2) + a2) + nv * dr.sqrt(nl * nl * (1 - a2) + a2))
            return dr.select((nv > 0) & (nl > 0), d * vis * nl, 0.0)

        def pdf_of(self, wi, wo):
            h = dr.normalize(wi + wo)
            wo_h = dr.dot(wo, h)
            valid = (mi.Frame3f.cos_theta(wi) > 0) & (mi.Frame3f.cos_theta(wo) > 0) & (wo_h > 0)
            return dr.select(valid, self.distribution.pdf(wi, h) / (4 * wo_h), 0.0)

        def sample(self, ctx, si, sample1, sample2, active=True):
            m, _ = self.distribution.sample(si.wi, sample2)
            bs = mi.BSDFSample3f()
            bs.wo = mi.reflect(si.wi, m)
            bs.pdf = self.pdf_of(si.wi, bs.wo)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = mi.UInt32(0)
            ok = active & (bs.pdf > 0)
            value = dr.select(ok, self.f_cos(si.wi, bs.wo) / dr.select(ok, bs.pdf, 1.0), 0.0)
            return bs, mi.Spectrum(value)

        def eval(self, ctx, si, wo, active=True):
            return mi.Spectrum(dr.select(active, self.f_cos(si.wi, wo), 0.0))

        def pdf(self, ctx, si, wo, active=True):
            return dr.select(active, self.pdf_of(si.wi, wo), 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"FilamentGGX[alpha={self.alpha}]"

    mi.register_bsdf("filament_ggx", lambda props: FilamentGGX(props))


def mitsuba_sphere(environment_bitmap, rotation, spp, index, crop, metal):
    """Mitsuba's render of sphere `index` alone (the harness does not model one sphere hiding
    the sky from another), over the pixel rectangle `crop` = (x, y, width, height); the metals
    with the BSDF `metal` (`filament` or `roughconductor`)."""
    label, material, bsdf = SPHERES[index]
    if bsdf is None:
        alpha = material["roughness"] ** 2
        if metal == "filament":
            bsdf = {"type": "filament_ggx", "alpha": alpha}
        else:
            bsdf = {"type": "roughconductor", "distribution": "ggx", "alpha": alpha, "material": "none"}
    x, y, w, h = crop
    scene = {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 1},
        "sensor": {
            "type": "perspective",
            "fov": FOV_Y,
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=CAMERA, target=[0, 0, 0], up=[0, 1, 0]),
            "sampler": {"type": "independent", "sample_count": spp, "seed": 7 + index},
            "film": {
                "type": "hdrfilm",
                "width": WIDTH,
                "height": HEIGHT,
                "crop_offset_x": x,
                "crop_offset_y": y,
                "crop_width": w,
                "crop_height": h,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
        },
        "environment": {
            "type": "envmap",
            "bitmap": environment_bitmap,
            "scale": 1.0,
            "to_world": mi.ScalarTransform4f().rotate(axis=[0, 1, 0], angle=180.0 + rotation),
        },
        "sphere": {
            "type": "sphere",
            "center": [sphere_x(index), 0.0, 0.0],
            "radius": RADIUS,
            "bsdf": bsdf,
        },
    }
    return np.array(mi.render(mi.load_dict(scene)), dtype=np.float64)[..., :3]


def mitsuba_render(environment_bitmap, rotation, spp, masks, metal):
    """The five spheres' pixels from Mitsuba, each sphere rendered alone; zero elsewhere."""
    image = np.zeros((HEIGHT, WIDTH, 3))
    for index, mask in enumerate(masks):
        ys, xs = np.nonzero(mask)
        x0, y0, x1, y1 = xs.min(), ys.min(), xs.max() + 1, ys.max() + 1
        crop = mitsuba_sphere(
            environment_bitmap, rotation, spp, index, (int(x0), int(y0), int(x1 - x0), int(y1 - y0)), metal
        )
        image[y0:y1, x0:x1] = crop
    return image


def luminance(rgb):
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


def sphere_pixels(min_n_dot_v):
    """Per sphere, a boolean mask of the pixels whose ray hits it with N.V >= `min_n_dot_v`, and
    N.V at every pixel, from the camera model both renderers share (pixel centres)."""
    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH]
    tan_half = np.tan(np.radians(FOV_Y) / 2)
    aspect = WIDTH / HEIGHT
    # Camera at CAMERA looking down -Z, +Y up, +X right.
    dx = ((xs + 0.5) / WIDTH * 2 - 1) * tan_half * aspect
    dy = (1 - (ys + 0.5) / HEIGHT * 2) * tan_half
    directions = np.stack([dx, dy, -np.ones_like(dx)], axis=-1)
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    origin = np.array(CAMERA)
    masks = []
    n_dot_vs = []
    for index in range(len(SPHERES)):
        center = np.array([sphere_x(index), 0.0, 0.0])
        oc = origin - center
        b = directions @ oc
        c = oc @ oc - RADIUS**2
        disc = b * b - c
        hit = disc > 0
        t = -b - np.sqrt(np.maximum(disc, 0))
        points = origin + directions * t[..., None]
        normals = (points - center) / RADIUS
        n_dot_v = -(normals * directions).sum(axis=-1)
        masks.append(hit & (n_dot_v >= min_n_dot_v))
        n_dot_vs.append(np.where(hit, n_dot_v, -1.0))
    return masks, n_dot_vs


def run_harness(scene_path, light_path, harness_binary):
    """The harness's light buffer of the scene, rendered on gl into `light_path` (EXR), by
    `harness_binary` or, without one, by `cargo run --release`."""
    launcher = [harness_binary] if harness_binary else ["cargo", "run", "--release", "-q", "-p", "harness", "--"]
    command = launcher + [
        "render", "--scene", scene_path, "--backend", "gl", "--pass", "light", "--out", light_path,
    ]
    subprocess.run(command, cwd=ROOT, check=True)
    return np.array(mi.Bitmap(light_path), dtype=np.float64)[..., :3]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spp", type=int, default=1024, help="Mitsuba samples per pixel (default 1024)")
    parser.add_argument("--out", default=os.path.join(ROOT, "target", "mitsuba"), help="working folder")
    parser.add_argument(
        "--min-n-dot-v", type=float, default=0.3,
        help="pixels compared: N.V at least this (default 0.3; 0 takes the silhouettes too)",
    )
    parser.add_argument(
        "--harness", default=None,
        help="a built harness binary (e.g. target/debug/harness) instead of `cargo run --release`",
    )
    parser.add_argument(
        "--ibl", action="append", default=[], metavar="KEY=VALUE",
        help="a [quality.ibl] setting of the harness's scene (repeatable), e.g. --ibl "
        "runtime_samples=256 --ibl specular_size=256; default: the defaults (the split sum)",
    )
    parser.add_argument(
        "--rotation", type=float, default=0.0,
        help="environment rotation about +Y in degrees, in both renderers (default 0); the camera "
        "looks down -Z, so this turns which part of the sky each sphere reflects",
    )
    parser.add_argument(
        "--environment", action="append", default=[], metavar="FILE",
        help="an equirectangular EXR to light the spheres with (repeatable; default: the two "
        "shipped skies, scenes/assets/sunset.exr and interior.exr)",
    )
    parser.add_argument(
        "--metal", choices=["filament", "roughconductor"], default="filament",
        help="Mitsuba's BSDF for the metals: the harness's own (GGX, height-correlated Smith; "
        "default) or Mitsuba's roughconductor (separable Smith)",
    )
    args = parser.parse_args()
    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception as e:  # pragma: no cover
        sys.exit(
            f"error: Mitsuba's llvm_ad_rgb variant does not start ({e}): install libllvm19 (or any "
            "libLLVM 16+) or point DRJIT_LIBLLVM_PATH at one"
        )
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        print("warning: no libLLVM 16+ found; Dr.Jit may abort on Debian 12's LLVM 15 "
              "(install libllvm19)", file=sys.stderr)
    register_filament_ggx()
    os.makedirs(args.out, exist_ok=True)
    masks, n_dot_vs = sphere_pixels(args.min_n_dot_v)
    rows = []
    bands = []
    sources = args.environment or [os.path.join(ROOT, "scenes", "assets", e) for e in ENVIRONMENTS]
    for source in sources:
        if not os.path.isfile(source):
            sys.exit(f"error: {source}: no such environment file")
        environment = os.path.basename(source)
        work = os.path.join(args.out, os.path.splitext(environment)[0])
        os.makedirs(work, exist_ok=True)
        shutil.copyfile(source, os.path.join(work, environment))
        scene_path = os.path.join(work, "spheres.toml")
        with open(scene_path, "w") as f:
            f.write(harness_scene(environment, args.rotation, [kv.replace("=", " = ", 1) for kv in args.ibl]))
        print(f"{environment}: harness ...", file=sys.stderr)
        harness = run_harness(scene_path, os.path.join(work, "light.exr"), args.harness)
        texels = np.array(mi.Bitmap(source), dtype=np.float32)[..., :3]
        clamped = mi.Bitmap(np.ascontiguousarray(np.maximum(texels, 0.0)))
        print(f"{environment}: Mitsuba, {args.spp} spp, metals {args.metal} ...", file=sys.stderr)
        reference = mitsuba_render(clamped, args.rotation, args.spp, masks, args.metal)
        mi.Bitmap(reference.astype(np.float32)).write(os.path.join(work, "mitsuba.exr"))
        for (label, _, _), mask, n_dot_v in zip(SPHERES, masks, n_dot_vs):
            h = luminance(harness[mask])
            m = luminance(reference[mask])
            relative = np.abs(h - m) / np.maximum(m, 1e-6)
            rows.append((environment, label, h.mean() / m.mean(), relative.mean(), np.percentile(relative, 95), int(mask.sum())))
            ratios = []
            for low, high in N_DOT_V_BANDS:
                band = mask & (n_dot_v >= low) & (n_dot_v < high)
                hb, mb = luminance(harness[band]), luminance(reference[band])
                ratios.append(hb.mean() / mb.mean() if band.any() and mb.mean() > 0 else float("nan"))
            bands.append((environment, label, ratios))
    print(f"| environment | sphere | harness / Mitsuba (means) | per-pixel error, mean | p95 | pixels |")
    print("|---|---|---|---|---|---|")
    for environment, label, ratio, mean, p95, pixels in rows:
        print(f"| {environment} | {label} | {ratio:.4f} | {mean * 100:.1f}% | {p95 * 100:.1f}% | {pixels} |")
    print()
    print("harness / Mitsuba (means) by N.V band:")
    print("| environment | sphere | " + " | ".join(f"N.V {low:.1f}-{min(high, 1.0):.1f}" for low, high in N_DOT_V_BANDS) + " |")
    print("|---|---|" + "---|" * len(N_DOT_V_BANDS))
    for environment, label, ratios in bands:
        print(f"| {environment} | {label} | " + " | ".join(f"{r:.3f}" for r in ratios) + " |")


if __name__ == "__main__":
    main()

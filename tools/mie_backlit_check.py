#!/usr/bin/env python3
"""The back-lit check in closed form: a homogeneous slab lit from behind
by a sun a few degrees off the view axis, single scattering, the phase
function integrated in f64.

Seen along the slab's normal, with the sun's direction at `theta0` off
the view axis, a slab of optical depth `tau` and albedo `a` under a sun
of irradiance `E` sends toward the camera

    L = a E <p> mu0 / (1 - mu0) * (exp(-tau) - exp(-tau / mu0))   (mu0 < 1)
      -> a E <p> tau exp(-tau)                                      (mu0 = 1)

where `<p>` is the phase function averaged over the sun's disc (a
uniform disc of angular diameter `angle` about `theta0`). Every renderer
difference other than the phase function cancels in the ratio of two
`L`s, so the ratio cirrus/Cycles is the ratio of their `<p>`.

Both sides fit Mie scattering by droplets of diameter `d` with the same
Jendersie-d'Eon blend `(1 - w) HG(g_HG) + w Draine(g_D, alpha)` (eqs.
7-10): cirrus takes the parameters in f64 (crates/kernel/src/phase/mie.rs),
Cycles in f32 through its `fast_expf` (kernel/closure/volume_util.h,
`phase_mie_fitted_parameters`). This prints both parameter sets, each
phase function's normalisation, `<p>` at the check's angle for each (and
evaluated as each renderer does it in f32), and the slab's L ratio.

With `--render cirrus` (the cirrus module importable) or `--render
cycles` (PyPI's bpy 5.2.3, as target/venv-blender has) it also renders
the slab, `data/tile_box.vdb` (128 voxels of density 0.5) at optical
depth `tau`, seen along its normal from 20000 units with a 0.05 degree
field of view (rays within 0.025 degrees of the normal), single
scattering, and prints the image mean against the closed form.

Usage: python3 tools/mie_backlit_check.py [--diameter 20] [--theta 3]
       [--angle 0.526] [--tau 2] [--render cirrus|cycles] [--spp 1024]
       (needs numpy)
"""

from __future__ import annotations

import argparse
import math

import numpy as np

F = np.float32


def cycles_fast_expf(x: float) -> np.float32:
    """Cycles' `fast_expf` (util/math_fast.h), op by op in f32."""
    x = F(F(x) / F(math.log(2.0)))
    x = min(max(x, F(-126.0)), F(126.0))
    m = int(x)  # truncates toward zero, as the C cast
    x = F(x - F(m))
    x = F(F(1.0) - F(F(1.0) - x))
    r = F(1.33336498402e-3)
    for c in (9.810352697968e-3, 5.551834031939e-2, 0.2401793301105, 0.693144857883, 1.0):
        r = F(F(x * r) + F(c))
    return F(r * F(2.0) ** m)


def fit_f64(d: float) -> dict:
    return dict(
        g_hg=math.exp(-0.0990567 / (d - 1.67154)),
        g_d=math.exp(-2.20679 / (d + 3.91029) - 0.428934),
        alpha=math.exp(3.62489 - 8.29288 / (d + 5.52825)),
        w=math.exp(-0.599085 / (d - 0.641583) - 0.665888),
    )


def fit_cycles(d: float) -> dict:
    d = F(d)
    return dict(
        g_hg=float(cycles_fast_expf(F(-0.0990567) / (d - F(1.67154)))),
        g_d=float(cycles_fast_expf(F(-2.20679) / (d + F(3.91029)) - F(0.428934))),
        alpha=float(cycles_fast_expf(F(3.62489) - F(8.29288) / (d + F(5.52825)))),
        w=float(cycles_fast_expf(F(-0.599085) / (d - F(0.641583)) - F(0.665888))),
    )


def hg(mu, g):
    """Henyey-Greenstein in f64, in the cancellation-free form."""
    denom = (1.0 - g) ** 2 + 2.0 * g * (1.0 - mu)
    return (1.0 - g * g) / (4.0 * math.pi * denom ** 1.5)


def draine(mu, g, alpha):
    norm = 1.0 / (1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0)
    return hg(mu, g) * (1.0 + alpha * mu * mu) * norm


def blend(mu, p: dict):
    return (1.0 - p["w"]) * hg(mu, p["g_hg"]) + p["w"] * draine(mu, p["g_d"], p["alpha"])


def cycles_f32(mu, p: dict):
    """Cycles' `phase_henyey_greenstein` and `phase_draine`, in f32."""
    mu = mu.astype(F)
    g, gd, a, w = (F(p[k]) for k in ("g_hg", "g_d", "alpha", "w"))
    fac = F(1) + g * (g - F(2) * mu)
    h = (F(1) - g * g) / (F(4 * math.pi) * fac * np.sqrt(fac))
    g2 = gd * gd
    fac = F(1) + g2 - F(2) * gd * mu
    dr = ((F(1) - g2) * (F(1) + a * mu * mu)) / (
        (F(1) + (a * (F(1) + F(2) * g2)) * F(1 / 3)) * F(4 * math.pi) * fac * np.sqrt(fac))
    return (F(1) - w) * h + w * dr


def cirrus_f32(mu, p: dict):
    """cirrus's `HenyeyGreenstein::eval_cos` and `Draine::eval_cos`, in f32."""
    mu = mu.astype(F)

    def hg32(g):
        g = F(g)
        denom = (F(1) - g) * (F(1) - g) + F(2) * g * (F(1) - mu)
        return (F(1) - g) * (F(1) + g) / (F(4 * math.pi) * denom * np.sqrt(denom))

    gd, a = p["g_d"], p["alpha"]
    norm = F(1.0 / (1.0 + a * (1.0 + 2.0 * gd * gd) / 3.0))
    dr = hg32(gd) * (F(1) + F(a) * mu * mu) * norm
    w = F(p["w"])
    return (F(1) - w) * hg32(p["g_hg"]) + w * dr


def normalisation(p: dict, n: int = 400_000) -> float:
    """2 pi times the integral of the phase over mu in [-1, 1], in f64: on a
    grid in log(1 - mu) (the forward peak) and a plain one elsewhere."""
    t = np.linspace(math.log(1e-12), math.log(1e-2), n)
    x = np.exp(t)  # 1 - mu
    peak = np.trapezoid(blend(1.0 - x, p) * x, t)
    mu = np.linspace(-1.0, 1.0 - 1e-2, n)
    rest = np.trapezoid(blend(mu, p), mu)
    return 2.0 * math.pi * (peak + rest)


def disc_mean(phase, p: dict, theta0: float, angle: float, n: int = 801) -> float:
    """The phase averaged over a uniform disc of angular diameter `angle`
    whose centre is `theta0` off the forward direction (radians), by a
    midpoint rule over the disc in its tangent plane (polar, uniform in
    solid angle to second order in the disc's 0.26 degrees)."""
    half = 0.5 * angle
    r = (np.arange(n) + 0.5) / n * half
    phi = (np.arange(n) + 0.5) / n * 2.0 * math.pi
    rr, pp = np.meshgrid(r, phi, indexing="ij")
    # The direction at (r, phi) about the centre: the angle off forward.
    cos_off = (math.cos(theta0) * np.cos(rr)
               - math.sin(theta0) * np.sin(rr) * np.cos(pp))
    weight = np.sin(rr)
    vals = np.asarray(phase(cos_off, p), dtype=np.float64)
    return float((vals * weight).sum() / weight.sum())


def slab(mean_phase: float, theta0: float, tau: float, albedo: float = 1.0) -> float:
    mu0 = math.cos(theta0)
    return albedo * mean_phase * mu0 / (1.0 - mu0) * (math.exp(-tau) - math.exp(-tau / mu0))


REPO = __import__("pathlib").Path(__file__).resolve().parents[1]
BOX = REPO / "data" / "tile_box.vdb"
BOX_SIDE, BOX_DENSITY = 128.0, 0.5


def render_cirrus(a, seeds=(1, 2, 3, 4)) -> list[float]:
    """The slab's image mean by cirrus, one per seed."""
    import cirrus

    th = math.radians(a.theta)
    means = []
    for seed in seeds:
        img, _ = cirrus.render({
            "render": {"spp": a.spp, "seed": seed, "max_depth": 1},
            "camera": {"res": "64x64", "from": [64.0, 64.0, 20000.0], "to": [64.0, 64.0, 64.0],
                       "fov": 0.05},
            "sun": {"direction": [math.sin(th), 0.0, math.cos(th)], "irradiance": [1.0] * 3,
                    "angle": a.angle},
            "environment": {"radiance": [0.0] * 3},
            "volume": [{"file": str(BOX), "albedo": 1.0, "phase": "mie",
                        "droplet_diameter": a.diameter,
                        "density_scale": a.tau / (BOX_DENSITY * BOX_SIDE)}],
        })
        means.append(float(img[..., :3].astype(np.float64).mean()))
    return means


def render_cycles(a, seeds=(1, 2)) -> list[float]:
    """The slab's image mean by Cycles (Volume Scatter, Mie phase, the
    density attribute scaled to `tau`), one per seed."""
    import os
    import tempfile

    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp())
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    vol = bpy.data.volumes.new("box")
    vol.filepath = str(BOX)
    vol.render.precision, vol.render.clipping = "FULL", 0.0
    vol.grids.load()
    obj = bpy.data.objects.new("Box", vol)
    scene.collection.objects.link(obj)
    mat = bpy.data.materials.new("Fog")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.phase = "MIE"
    sc.inputs["Diameter"].default_value = a.diameter
    sc.inputs["Color"].default_value = (1, 1, 1, 1)
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "density"
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = a.tau / (BOX_DENSITY * BOX_SIDE)
    nt.links.new(attr.outputs["Fac"], mul.inputs[0])
    nt.links.new(mul.outputs["Value"], sc.inputs["Density"])
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(sc.outputs["Volume"], out.inputs["Volume"])
    vol.materials.append(mat)
    cam_data = bpy.data.cameras.new("Cam")
    cam_data.sensor_fit, cam_data.angle_y = "VERTICAL", math.radians(0.05)
    cam_data.clip_start, cam_data.clip_end = 1.0, 1e6
    cam = bpy.data.objects.new("Cam", cam_data)
    cam.location = (63.5, 63.5, 20000.0)  # Blender's box: voxel centres at 0..127
    scene.collection.objects.link(cam)
    scene.camera = cam
    sun_data = bpy.data.lights.new("Sun", "SUN")
    sun_data.energy, sun_data.angle, sun_data.normalize = 1.0, math.radians(a.angle), True
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = (0.0, math.pi - math.radians(a.theta), 0.0)  # travelling up, tilted
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("W")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    r = scene.render
    r.resolution_x = r.resolution_y = 64
    r.resolution_percentage = 100
    r.use_compositing = r.use_sequencer = False
    r.film_transparent = False
    r.image_settings.file_format, r.image_settings.color_depth = "OPEN_EXR", "32"
    r.image_settings.color_mode = "RGBA"
    scene.view_settings.view_transform, scene.view_settings.look = "Standard", "None"
    scene.view_settings.exposure = 0.0
    r.engine = "CYCLES"
    cy = scene.cycles
    cy.device, cy.samples = "CPU", a.spp
    cy.use_adaptive_sampling = cy.use_denoising = cy.use_guiding = False
    cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.volume_biased = False
    cy.pixel_filter_type, cy.filter_width = "BOX", 1.0
    cy.sampling_pattern, cy.film_exposure = "TABULATED_SOBOL", 1.0
    cy.max_bounces, cy.volume_bounces = 1, 0  # single scattering
    means = []
    for seed in seeds:
        cy.seed = seed
        path = os.path.join(tempfile.mkdtemp(), "slab.exr")
        r.filepath = path
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(path, check_existing=False)
        px = np.array(img.pixels[:], dtype=np.float64).reshape(64, 64, 4)
        bpy.data.images.remove(img)
        means.append(float(px[..., :3].mean()))
    return means


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--diameter", type=float, default=20.0, help="droplet diameter, um")
    ap.add_argument("--theta", type=float, default=3.0, help="sun off the view axis, degrees")
    ap.add_argument("--angle", type=float, default=0.526, help="sun's angular diameter, degrees")
    ap.add_argument("--tau", type=float, default=2.0, help="slab optical depth")
    ap.add_argument("--render", choices=["cirrus", "cycles"], help="render the slab as well")
    ap.add_argument("--spp", type=int, default=1024, help="samples per pixel of --render")
    a = ap.parse_args()
    theta0, angle = math.radians(a.theta), math.radians(a.angle)
    ours, theirs = fit_f64(a.diameter), fit_cycles(a.diameter)
    print(f"Mie fit, d = {a.diameter} um (cirrus f64 | Cycles f32 fast_expf | relative):")
    for k in ours:
        print(f"  {k:6s} {ours[k]:.9f} | {theirs[k]:.9f} | {theirs[k] / ours[k] - 1:+.2e}")
    print("normalisation, 2 pi int p dmu (f64):"
          f" cirrus {normalisation(ours):.6f}, Cycles' parameters {normalisation(theirs):.6f}")
    centre = float(blend(math.cos(theta0), ours))
    rows = [
        ("cirrus, f64", disc_mean(blend, ours, theta0, angle)),
        ("Cycles' parameters, f64", disc_mean(blend, theirs, theta0, angle)),
        ("cirrus's eval, f32", disc_mean(cirrus_f32, ours, theta0, angle)),
        ("Cycles' eval, f32", disc_mean(cycles_f32, theirs, theta0, angle)),
    ]
    base = rows[0][1]
    print(f"phase at {a.theta} deg: at the sun's centre {centre:.6f} /sr; over its"
          f" {a.angle} deg disc:")
    for name, v in rows:
        print(f"  {name:26s} {v:.6f} /sr  ({v / base - 1:+.2e} against cirrus f64)")
    print(f"  the disc's mean over its centre's value: {base / centre - 1:+.4%}")
    l_ours, l_theirs = slab(rows[0][1], theta0, a.tau), slab(rows[3][1], theta0, a.tau)
    print(f"slab tau {a.tau}, albedo 1, E 1: L cirrus {l_ours:.6f}, Cycles {l_theirs:.6f},"
          f" ratio cirrus/Cycles {l_ours / l_theirs:.5f}")
    l_delta = slab(centre, theta0, a.tau)
    print(f"  a sun taken as a delta at its centre: ratio to the disc's {l_delta / l_ours:.5f}")
    if a.render:
        means = (render_cirrus if a.render == "cirrus" else render_cycles)(a)
        m = float(np.mean(means))
        err = float(np.std(means, ddof=1) / math.sqrt(len(means)))
        print(f"{a.render} render, {a.spp} spp x {len(means)} seeds: {m:.6f} +- {err:.6f}"
              f" (seeds {', '.join(f'{x:.6f}' for x in means)}),"
              f" over the closed form {m / l_ours:.5f} +- {err / l_ours:.5f}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Render a .vdb density grid with Blender Cycles (PyPI `bpy`) the way `cirrus render` does.

A peer renderer for cirrus, like tools/mitsuba_render.py for Mitsuba 3.  It takes the scene
flags of `cirrus render` with the same meanings and builds the same scene in Cycles:

    camera   perspective, sensor fit VERTICAL, vertical fov = --fov, looking from --camera-from
             to --camera-to with --camera-up (camera right = forward x up, as cirrus)
    volume   the .vdb as a Volume object (its world space is the file's world space), full
             float precision (not Blender's default half), clipping 0 (Blender's default 0.001
             drops thin voxels), trilinear interpolation; material Volume Scatter (white,
             density a*s*density) + Volume Absorption (black, density (1-a)*s*density), so
             sigma_t = s*density with albedo a; the phase is Volume Scatter's `phase`
             (HG, Draine, Rayleigh, Mie = Jendersie-d'Eon's HG+Draine fit by droplet diameter)
    sun      a Sun light, energy = max(--sun-irradiance) and colour = irradiance / max:
             Cycles' sun strength is the irradiance on a surface facing it (W/m^2; radiance
             strength / (pi sin^2(angle/2)) over the disk), the same unit as cirrus and
             Mitsuba's `directional`; its -Z axis is --sun-dir (the direction the light travels);
             angle = --sun-angle (angular diameter; 0 = a delta light)
    sky      the World's Background colour = --env-radiance, strength 1
    render   CPU, a fixed thread count, null-scattering volumes (volume_biased False), no clamping,
             adaptive sampling off, light-sampling threshold 0, box pixel filter of 1 px,
             max_bounces and volume_bounces = cirrus --max-depth - 1 (one scattering event is
             Cycles' volume bounce 0) or 1024 for unlimited, film not transparent (the sky is
             seen through the volume, as in cirrus's RGB), view transform Standard, exposure 0,
             denoising off unless --denoise (OIDN, albedo-guided like cirrus --denoise), path
             guiding off unless --guiding (OpenPGL, volume guiding on, surface guiding off)
    output   EXR float32 linear RGBA (alpha is 1: compare RGB; cirrus's alpha is 1 - T)

Needs Blender's `bpy` module (PyPI bpy 5.2.3 is for CPython 3.13):

    ~/.pyenv/versions/3.13.0/bin/python -m venv /work/peer/bpy-venv
    /work/peer/bpy-venv/bin/pip install bpy==5.2.3 numpy OpenEXR
    /work/peer/bpy-venv/bin/python tools/cycles_peer.py data/cloud.vdb -o /tmp/cy.exr --res 128x128 \\
        --spp 256 --camera-from 150,83,-250 --camera-to 150,83,100 --fov 40 --sun-dir -0.45,-0.6,-0.66 \\
        --sun-angle 0 --albedo 0.9 --g 0.5 --threads 2

`--seeds 1,2,3,4` renders one image per seed in one process (the scene is built once; each
render still pays Cycles' scene sync): `-o` must then contain `{seed}`.  `--json` writes the
wall and process CPU seconds of every render and the scene.  Every parameter should be passed
explicitly when comparing (defaults mirror cirrus's but cirrus's have changed before).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import resource
import sys
import time
from pathlib import Path

DEFAULT_DENSITY_PER_VOXEL = 0.5
UNLIMITED_BOUNCES = 1024
PHASES = ("hg", "draine", "mie", "rayleigh")


def vec3(s: str) -> tuple[float, float, float]:
    parts = [float(c) for c in s.split(",")]
    if len(parts) != 3 or not all(math.isfinite(c) for c in parts):
        raise argparse.ArgumentTypeError(f"expected three finite numbers x,y,z, got {s!r}")
    return tuple(parts)


def resolution(s: str) -> tuple[int, int]:
    w, _, h = s.lower().partition("x")
    try:
        w, h = int(w), int(h)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH, got {s!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise argparse.ArgumentTypeError(f"resolution {w}x{h} must be between 1 and 16384 a side")
    return w, h


def join_negative_values(argv: list[str]) -> list[str]:
    """`--camera-from -150,200,-200` -> `--camera-from=-150,200,-200` (argparse would take the
    value for an option; cirrus's clap accepts it)."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        tok = argv[i]
        if (tok.startswith("--") and "=" not in tok and i + 1 < len(argv)
                and re.match(r"^-[0-9.]", argv[i + 1])):
            out.append(f"{tok}={argv[i + 1]}")
            i += 2
        else:
            out.append(tok)
            i += 1
    return out


def parse_args(argv=None):
    ap = argparse.ArgumentParser(
        description="Render a VDB density grid with Blender Cycles using cirrus render's scene flags "
                    "(run with the python that has PyPI's bpy, e.g. /work/peer/bpy-venv/bin/python).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    ap.add_argument("file", help="a .vdb file")
    ap.add_argument("--grid", default="density", help="density grid name")
    ap.add_argument("-o", "--output", required=True,
                    help="output EXR (RGBA float32, linear); with --seeds it must contain {seed}")
    ap.add_argument("--res", type=resolution, default=(512, 512))
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel")
    ap.add_argument("--time", type=float, default=None,
                    help="Cycles' time_limit in seconds (render time excluding scene sync); --spp is then the cap")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--seeds", default=None, help="comma-separated seeds: one render each (output pattern {seed})")
    ap.add_argument("--camera-from", type=vec3, required=True)
    ap.add_argument("--camera-to", type=vec3, required=True)
    ap.add_argument("--camera-up", type=vec3, default=(0.0, 1.0, 0.0))
    ap.add_argument("--fov", type=float, default=40.0, help="vertical field of view, degrees")
    ap.add_argument("--sun-dir", type=vec3, default=(0.7, -0.5, 0.5),
                    help="direction the sunlight travels (from the sun toward the scene)")
    ap.add_argument("--sun-irradiance", type=vec3, default=(2.6, 2.5, 2.3),
                    help="irradiance on a surface facing the sun, per channel")
    ap.add_argument("--sun-angle", type=float, default=0.53, help="angular diameter of the sun, degrees (0: delta)")
    ap.add_argument("--no-sun", action="store_true")
    ap.add_argument("--env-radiance", type=vec3, default=(0.16, 0.22, 0.34))
    ap.add_argument("--density-scale", type=float, default=None,
                    help="extinction per unit density in 1/world units (default 0.5 / voxel size)")
    ap.add_argument("--albedo", type=float, default=0.99)
    ap.add_argument("--g", type=float, default=0.6, help="HG g, or Draine's g")
    ap.add_argument("--phase", choices=PHASES, default="hg",
                    help="Volume Scatter phase: HENYEY_GREENSTEIN, DRAINE (Anisotropy = --g, Alpha = --draine-alpha), "
                         "RAYLEIGH, MIE (Diameter = --droplet-diameter, micrometres)")
    ap.add_argument("--draine-alpha", type=float, default=1.0)
    ap.add_argument("--droplet-diameter", type=float, default=20.0, help="Mie droplet diameter, micrometres")
    ap.add_argument("--max-depth", type=int, default=None,
                    help="real scattering events per path as cirrus counts them (1 = single scattering; default "
                         "unlimited). Cycles gets volume_bounces = this - 1")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--sampling-pattern", default="TABULATED_SOBOL",
                    help="Cycles sampling pattern (AUTOMATIC, TABULATED_SOBOL, BLUE_NOISE); the default keeps "
                         "pixels' errors independent (blue noise correlates neighbours)")
    ap.add_argument("--denoise", action="store_true",
                    help="Cycles' OIDN denoiser with the albedo pass as guide (prefilter ACCURATE)")
    ap.add_argument("--denoise-passes", default="RGB_ALBEDO", help="denoising_input_passes")
    ap.add_argument("--guiding", action="store_true",
                    help="Cycles' OpenPGL path guiding for volumes (use_guiding, use_volume_guiding; surface "
                         "guiding off, training samples and the rest at Blender's defaults)")
    ap.add_argument("--keep-half", action="store_true",
                    help="keep Blender's default half-float volume precision (default: FULL)")
    ap.add_argument("--json", default=None, help="write per-render timings and the scene as JSON")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(join_negative_values(list(sys.argv[1:] if argv is None else argv)))
    if args.max_depth is not None and args.max_depth < 1:
        ap.error("--max-depth must be >= 1: Cycles always scatters once when its volume bounces are 0 "
                 "(cirrus --max-depth 0, the sky through the volume only, has no Cycles equivalent here)")
    if args.seeds:
        args.seed_list = [int(s) for s in args.seeds.split(",") if s.strip()]
        if "{seed}" not in args.output and len(args.seed_list) > 1:
            ap.error("with several --seeds, -o must contain {seed}")
    else:
        args.seed_list = [args.seed]
    if args.spp < 1:
        ap.error("--spp must be >= 1")
    if not (0.0 <= args.albedo <= 1.0):
        ap.error("--albedo must be in [0, 1]")
    return args


def log(args, msg: str) -> None:
    if not args.quiet:
        print(msg, file=sys.stderr, flush=True)


def cpu_seconds() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def look_at_matrix(mathutils, origin, target, up):
    """Camera-to-world: Blender cameras look along local -Z with +Y up and +X to the right."""
    o = mathutils.Vector(origin)
    f = (mathutils.Vector(target) - o).normalized()
    r = f.cross(mathutils.Vector(up))
    if r.length < 1e-9:
        raise SystemExit("--camera-up is parallel to the view direction")
    r.normalize()
    u = r.cross(f)
    m = mathutils.Matrix.Identity(4)
    for i in range(3):
        m[i][0], m[i][1], m[i][2], m[i][3] = r[i], u[i], -f[i], o[i]
    return m


def direction_matrix(mathutils, d):
    """Rotation whose -Z axis is d (a Sun light emits along its local -Z)."""
    z = -mathutils.Vector(d).normalized()
    helper = mathutils.Vector((0.0, 1.0, 0.0)) if abs(z[1]) < 0.9 else mathutils.Vector((1.0, 0.0, 0.0))
    x = helper.cross(z).normalized()
    y = z.cross(x)
    m = mathutils.Matrix.Identity(4)
    for i in range(3):
        m[i][0], m[i][1], m[i][2] = x[i], y[i], z[i]
    return m


def voxel_size_of(path: str, grid: str) -> float | None:
    """Voxel size of a uniform-scale grid, read from the VDB through Blender itself."""
    import bpy

    vol = bpy.data.volumes.new("probe")
    vol.filepath = path
    vol.grids.load()
    try:
        g = vol.grids[grid]
    except KeyError:
        names = [x.name for x in vol.grids]
        raise SystemExit(f"{path}: no grid {grid!r} (grids: {names})") from None
    m = g.matrix_object
    sx, sy, sz = (math.sqrt(sum(m[r][c] ** 2 for r in range(3))) for c in range(3))
    bpy.data.volumes.remove(vol)
    if max(sx, sy, sz) - min(sx, sy, sz) > 1e-6 * max(sx, sy, sz):
        return None
    return sx


def build_scene(args):
    import bpy
    import mathutils

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    w, h = args.res

    # --- render settings (the defaults a fair comparison must change are marked) ---
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.use_border = False
    scene.render.film_transparent = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.render.use_persistent_data = False
    cy.samples = args.spp
    cy.time_limit = float(args.time or 0.0)
    cy.use_adaptive_sampling = False  # default on
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0  # default 10: biased
    cy.light_sampling_threshold = 0.0  # default 0.01 culls dim lights: biased
    cy.use_light_tree = True
    cy.use_animated_seed = False
    cy.sample_offset = 0
    cy.sampling_pattern = args.sampling_pattern
    cy.volume_biased = False  # null-scattering (unbiased) volumes; True is ray marching
    cy.pixel_filter_type = "BOX"  # default Blackman-Harris 1.5 px
    cy.filter_width = 1.0
    # OpenPGL guiding learns from the render's first samples (guiding_training_samples, Blender's
    # default kept) and guides volume scattering directions: the second Cycles configuration a
    # thick bright cloud is measured against (the better of the two is the peer).
    cy.use_guiding = bool(args.guiding)
    if args.guiding:
        cy.use_volume_guiding = True
        cy.use_surface_guiding = False
    if args.max_depth is None:
        bounces = UNLIMITED_BOUNCES
    else:
        bounces = args.max_depth - 1
    cy.max_bounces = UNLIMITED_BOUNCES if args.max_depth is None else max(bounces, 1)
    cy.volume_bounces = bounces  # default 0 = single scattering only
    cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 0
    cy.transparent_max_bounces = UNLIMITED_BOUNCES
    cy.min_light_bounces = 0
    cy.min_transparent_bounces = 0
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    cy.use_denoising = bool(args.denoise)  # default on
    if args.denoise:
        cy.denoiser = "OPENIMAGEDENOISE"
        cy.denoising_input_passes = args.denoise_passes
        cy.denoising_prefilter = "ACCURATE"
        cy.denoising_use_gpu = False
    scene.view_settings.view_transform = "Standard"  # default AgX (only affects display; EXR is linear)
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    cy.film_exposure = 1.0
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR"
    img.color_depth = "32"
    img.color_mode = "RGBA"
    img.exr_codec = "ZIP"

    # --- camera ---
    cam_data = bpy.data.cameras.new("cam")
    cam_data.type = "PERSP"
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(args.fov)
    cam_data.shift_x = cam_data.shift_y = 0.0
    cam_data.clip_start = 1e-3
    cam_data.clip_end = 1e7
    cam = bpy.data.objects.new("cam", cam_data)
    cam.matrix_world = look_at_matrix(mathutils, args.camera_from, args.camera_to, args.camera_up)
    scene.collection.objects.link(cam)
    scene.camera = cam

    # --- volume ---
    vol = bpy.data.volumes.new("cloud")
    vol.filepath = str(Path(args.file).resolve())
    vol.render.precision = "HALF" if args.keep_half else "FULL"  # default HALF
    vol.render.clipping = 0.0  # default 0.001
    vol.render.space = "OBJECT"
    vol.grids.load()
    if args.grid not in [g.name for g in vol.grids]:
        raise SystemExit(f"{args.file}: no grid {args.grid!r} (grids: {[g.name for g in vol.grids]})")
    vol_obj = bpy.data.objects.new("cloud", vol)
    vol_obj.matrix_world = mathutils.Matrix.Identity(4)
    scene.collection.objects.link(vol_obj)

    density_scale = args.density_scale
    if density_scale is None:
        vs = voxel_size_of(str(Path(args.file).resolve()), args.grid)
        if vs is None:
            raise SystemExit("pass --density-scale (the default 0.5 / voxel size needs a uniform voxel size)")
        density_scale = DEFAULT_DENSITY_PER_VOXEL / vs

    mat = bpy.data.materials.new("medium")
    mat.cycles.volume_interpolation = "LINEAR"
    nt = mat.node_tree
    nt.nodes.clear()
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_type = "GEOMETRY"
    attr.attribute_name = args.grid
    scat_den = nt.nodes.new("ShaderNodeMath")
    scat_den.operation = "MULTIPLY"
    scat_den.inputs[1].default_value = args.albedo * density_scale
    nt.links.new(attr.outputs["Factor"], scat_den.inputs[0])
    abs_den = nt.nodes.new("ShaderNodeMath")
    abs_den.operation = "MULTIPLY"
    abs_den.inputs[1].default_value = (1.0 - args.albedo) * density_scale
    nt.links.new(attr.outputs["Factor"], abs_den.inputs[0])
    scat = nt.nodes.new("ShaderNodeVolumeScatter")
    scat.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    phase = {"hg": "HENYEY_GREENSTEIN", "draine": "DRAINE", "mie": "MIE", "rayleigh": "RAYLEIGH"}[args.phase]
    scat.phase = phase
    # Look sockets up by identifier: `inputs[name]` skips the ones the phase leaves unused.
    sockets = {s.identifier: s for s in scat.inputs}
    sockets["Anisotropy"].default_value = args.g
    sockets["Alpha"].default_value = args.draine_alpha
    sockets["Diameter"].default_value = args.droplet_diameter
    nt.links.new(scat_den.outputs[0], scat.inputs["Density"])
    absorb = nt.nodes.new("ShaderNodeVolumeAbsorption")
    absorb.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    nt.links.new(abs_den.outputs[0], absorb.inputs["Density"])
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(scat.outputs[0], add.inputs[0])
    nt.links.new(absorb.outputs[0], add.inputs[1])
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "ALL"
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    vol.materials.append(mat)

    # --- sky ---
    world = bpy.data.worlds.new("sky")
    scene.world = world
    wnt = world.node_tree
    wnt.nodes.clear()
    bg = wnt.nodes.new("ShaderNodeBackground")
    bg.inputs["Color"].default_value = (*args.env_radiance, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    wout = wnt.nodes.new("ShaderNodeOutputWorld")
    wnt.links.new(bg.outputs[0], wout.inputs["Surface"])
    world.cycles.sampling_method = "AUTOMATIC"

    # --- sun ---
    if not args.no_sun and max(args.sun_irradiance) > 0:
        peak = max(args.sun_irradiance)
        sun_data = bpy.data.lights.new("sun", "SUN")
        sun_data.energy = peak
        sun_data.color = tuple(c / peak for c in args.sun_irradiance)
        sun_data.angle = math.radians(args.sun_angle)
        sun_data.use_temperature = False
        sun_data.exposure = 0.0
        sun_data.normalize = True  # strength / disk area: the irradiance stays `energy`
        sun_data.use_shadow = True
        sun_data.volume_factor = 1.0
        sun_data.cycles.use_multiple_importance_sampling = True
        sun_data.cycles.max_bounces = UNLIMITED_BOUNCES
        sun = bpy.data.objects.new("sun", sun_data)
        sun.matrix_world = direction_matrix(mathutils, args.sun_dir)
        scene.collection.objects.link(sun)

    return scene, density_scale


def render_one(args, scene, seed: int, path: str) -> dict:
    import bpy

    scene.cycles.seed = seed
    stats: list[str] = []

    def on_stats(s):
        stats.append(s)

    bpy.app.handlers.render_stats.append(on_stats)
    c0, t0 = cpu_seconds(), time.perf_counter()
    bpy.ops.render.render(write_still=False)
    wall, cpu = time.perf_counter() - t0, cpu_seconds() - c0
    bpy.app.handlers.render_stats.remove(on_stats)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    bpy.data.images["Render Result"].save_render(filepath=str(path), scene=scene)
    last = stats[-1] if stats else ""
    m = re.search(r"Sample (\d+)/(\d+)", " ".join(stats[-5:]))
    return {"seed": seed, "output": str(path), "wall_seconds": wall, "cpu_seconds": cpu,
            "samples_reported": int(m.group(1)) if m else None, "last_stats": last}


def main(argv=None) -> int:
    args = parse_args(argv)
    try:
        import bpy
    except ImportError as e:
        sys.exit(f"cycles_peer.py: cannot import bpy with {sys.executable} ({e}).\n"
                 "  ~/.pyenv/versions/3.13.0/bin/python -m venv /work/peer/bpy-venv\n"
                 "  /work/peer/bpy-venv/bin/pip install bpy==5.2.3 numpy OpenEXR\n"
                 "and run this script with /work/peer/bpy-venv/bin/python")
    t_start = time.perf_counter()
    scene, density_scale = build_scene(args)
    build_s = time.perf_counter() - t_start
    renders = []
    for seed in args.seed_list:
        out = args.output.replace("{seed}", str(seed))
        r = render_one(args, scene, seed, out)
        renders.append(r)
        print(f"{out}: {args.res[0]}x{args.res[1]} at {args.spp} spp (seed {seed}) in {r['wall_seconds']:.2f} s wall, "
              f"{r['cpu_seconds']:.2f} s CPU (Cycles {bpy.app.version_string}, {args.threads} threads, "
              f"load {os.getloadavg()[0]:.1f})", flush=True)
    if args.json:
        report = {
            "renderer": "cycles",
            "blender": bpy.app.version_string,
            "threads": args.threads,
            "width": args.res[0], "height": args.res[1], "spp": args.spp, "time_limit": args.time,
            "density_scale": density_scale,
            "phase": args.phase, "g": args.g, "draine_alpha": args.draine_alpha,
            "droplet_diameter": args.droplet_diameter, "albedo": args.albedo,
            "volume_bounces": scene.cycles.volume_bounces, "max_bounces": scene.cycles.max_bounces,
            "sampling_pattern": scene.cycles.sampling_pattern, "denoise": bool(args.denoise),
            "working_space": bpy.data.colorspace.working_space,
            "build_seconds": build_s, "renders": renders,
            "load_avg": os.getloadavg(),
        }
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Render a .vdb density grid with Mitsuba 3 the way `cirrus render` does: a peer renderer.

Usage (Debian's /usr/bin/python3, which has both pyopenvdb and mitsuba; see tools/README.md):

    /usr/bin/python3 tools/mitsuba_render.py data/cloud.vdb -o /tmp/m.exr --res 128x128 --spp 256 \\
        --camera-from 150,83,-250 --camera-to 150,83,100 --fov 40 --sun-dir -0.45,-0.6,-0.66 \\
        --sun-angle 0 --albedo 0.99 --g 0.8 --threads 2

Takes the scene flags of `cirrus render` (the subset Mitsuba can express) with the same
meaning and the same defaults, builds the scene

    sensor     perspective, fov_axis 'y', to_world look_at(from, to, up), hdrfilm with a box
               reconstruction filter (each sample lands in its own pixel, like cirrus), independent sampler
    medium     heterogeneous: sigma_t = gridvolume(.vol from tools/vdb_to_mitsuba_vol.py,
               use_grid_bbox), scale = density scale, albedo, hg(g)
    boundary   cube with a null BSDF, the medium as interior, on the padded grid bbox
    lights     directional(direction = --sun-dir, irradiance), constant(--env-radiance)
    integrator volpath, max_depth = cirrus max depth + 1 (-1 = unlimited)

Chromatic media (`--density-scale R,G,B` with unequal channels, cirrus's extinction per RGB
channel): sigma_t is a 3-channel gridvolume holding density x scale_c per channel (derived
from the 1-channel .vol by vdb_to_mitsuba_vol.scale_channels, same bbox bytes), `scale` 1,
`has_spectral_extinction` true, and the integrator is `volpathmis` (Miller et al. 2019's
spectral MIS over the channels; same max_depth and rr_depth conventions as volpath).
`--albedo R,G,B` is a constvolume of that RGB value (with grey extinction volpath handles it).

and writes an RGBA float32 EXR.  Mitsuba's film alpha is only "the path hit something
or an environment exists" (always 1 with a constant sky), so alpha = 1 - T of the camera
ray is rendered by a second, cheap pass of the same geometry: albedo 0, no sun, a
constant sky of radiance 1, max_depth 1, where every sample's value is the indicator that
delta tracking let the camera ray through (the same binary estimator cirrus uses).

`--batches K` renders the spp as K independent batches (different seeds) and, with
`--stderr-out`, writes the per-pixel standard error of the mean (RGBA) estimated from
the spread of the batch means, for tools/compare_images.py.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import tempfile
import time
from pathlib import Path

try:
    import numpy as np
except ImportError:
    sys.exit(f"{__file__}: numpy is missing for {sys.executable}; run the peer tools with Debian's "
             "/usr/bin/python3 (apt-get install -y python3-numpy python3-openvdb; see tools/README.md)")

sys.dont_write_bytecode = True
sys.path.insert(0, str(Path(__file__).resolve().parent))
import mitsuba_setup  # noqa: E402

# Largest number of samples (pixels x spp) in one Mitsuba launch; larger budgets are split
# into more batches so memory stays bounded.
MAX_SAMPLES_PER_LAUNCH = 1 << 24

# The scene defaults mirror `cirrus render --help` of the working tree on top of commit
# b441864 (sun 0.7,-0.5,0.5, density scale 0.5 / voxel size, g 0.6).  cirrus's defaults
# have changed before; pass every parameter explicitly when comparing (peer_compare.py does).
DEFAULT_DENSITY_PER_VOXEL = 0.5


def vec3(s: str) -> tuple[float, float, float]:
    parts = [float(c) for c in s.split(",")]
    if len(parts) != 3 or not all(math.isfinite(c) for c in parts):
        raise argparse.ArgumentTypeError(f"expected three finite numbers x,y,z, got {s!r}")
    return tuple(parts)


def scalar_or_rgb(s: str) -> tuple[float, ...]:
    """'0.5' -> (0.5,); '0.8,0.5,0.25' -> (0.8, 0.5, 0.25), like cirrus's flags."""
    try:
        parts = tuple(float(c) for c in s.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number or R,G,B, got {s!r}") from None
    if len(parts) not in (1, 3) or not all(math.isfinite(c) and c >= 0 for c in parts):
        raise argparse.ArgumentTypeError(f"expected one number or R,G,B (finite, >= 0), got {s!r}")
    return parts


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
    """`--camera-from -150,200,-200` -> `--camera-from=-150,200,-200`: argparse would
    otherwise take a value starting with '-' for an option (cirrus's clap accepts it)."""
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
        description="Render a VDB density grid with Mitsuba 3 using cirrus render's scene flags.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    ap.add_argument("file", help="a .vdb file (converted on the fly) or a .vol written by vdb_to_mitsuba_vol.py")
    ap.add_argument("--grid", default=None, help="density grid (default: density, else the first float grid)")
    ap.add_argument("-o", "--output", required=True, help="output EXR (RGBA float32, linear)")
    ap.add_argument("--png", default=None, help="also write a tone-mapped sRGB PNG preview (cirrus's curve)")
    ap.add_argument("--exposure", type=float, default=0.0, help="PNG exposure in stops")
    ap.add_argument("--res", type=resolution, default=(512, 512))
    budget = ap.add_mutually_exclusive_group()
    budget.add_argument("--spp", type=int, default=None, help="samples per pixel (default 64)")
    budget.add_argument("--time", type=float, default=None,
                        help="seconds for the main pass, spent like cirrus: passes of 1, 2, 4, ... spp accumulated "
                             "until the budget is used (kernel compilation not counted)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--camera-from", type=vec3, default=None)
    ap.add_argument("--camera-to", type=vec3, default=None)
    ap.add_argument("--camera-up", type=vec3, default=(0.0, 1.0, 0.0))
    ap.add_argument("--fov", type=float, default=40.0, help="vertical field of view, degrees")
    ap.add_argument("--sun-dir", type=vec3, default=(0.7, -0.5, 0.5),
                    help="direction the sunlight travels (from the sun toward the scene)")
    ap.add_argument("--sun-irradiance", type=vec3, default=(2.6, 2.5, 2.3))
    ap.add_argument("--sun-angle", type=float, default=0.0,
                    help="must be 0: Mitsuba's directional emitter is a delta light (cirrus's default is 0.53; pass "
                         "--sun-angle 0 to cirrus for comparisons)")
    ap.add_argument("--no-sun", action="store_true")
    ap.add_argument("--env-radiance", type=vec3, default=(0.16, 0.22, 0.34))
    ap.add_argument("--density-scale", type=scalar_or_rgb, default=None,
                    help="extinction per unit density in 1/world units: one number, or R,G,B for a chromatic "
                         "medium (a 3-channel sigma_t grid, volpathmis) (default 0.5 / voxel size)")
    ap.add_argument("--albedo", type=scalar_or_rgb, default=(0.99,), help="one number or R,G,B")
    ap.add_argument("--integrator", choices=["auto", "volpath", "volpathmis"], default="auto",
                    help="auto: volpathmis for a chromatic medium (unequal --density-scale channels), else volpath")
    ap.add_argument("--g", type=float, default=0.6, help="HG g (of the first lobe of hg2)")
    ap.add_argument("--phase", choices=["hg", "hg2", "rayleigh"], default="hg",
                    help="hg: Mitsuba's hg(g); hg2: blendphase of hg(g) and hg(g2), cirrus's two-lobe HG; "
                         "rayleigh: Mitsuba's rayleigh")
    ap.add_argument("--g2", type=float, default=-0.3, help="the second lobe of hg2")
    ap.add_argument("--lobe-weight", type=float, default=0.8,
                    help="weight of hg2's FIRST lobe, as cirrus's flag (Mitsuba's blendphase `weight` is the "
                         "second phase's, so it gets 1 - this)")
    ap.add_argument("--max-depth", type=int, default=None,
                    help="real scattering events per path as cirrus counts them (0 = sky through the volume only, "
                         "1 = single scattering; default unlimited). Mitsuba gets max_depth = this + 1")
    ap.add_argument("--rr-depth", type=int, default=256,
                    help="Mitsuba's rr_depth: scattering events before Russian roulette starts. Mitsuba's own default "
                         "(5) gives fireflies with albedo ~1: its survival probability is min(throughput, 0.95), so "
                         "a path of throughput ~1 is divided by 0.95 at every event and long paths carry weights of "
                         "1.04^n. 256 keeps the per-pixel noise light-tailed (reference quality); 64 is faster per "
                         "unit error on the cloud but still has occasional fireflies")
    ap.add_argument("--threads", type=int, default=None, help="Dr.Jit worker threads (default: all cores)")
    ap.add_argument("--variant", default=None, help="Mitsuba variant (default llvm_ad_rgb, else scalar_rgb)")
    ap.add_argument("--batches", type=int, default=1,
                    help="render the spp as this many independent batches (needed for --stderr-out)")
    ap.add_argument("--stderr-out", default=None,
                    help="write the per-pixel standard error of the mean (RGBA EXR, from the batch spread)")
    ap.add_argument("--alpha", choices=["pass", "none"], default="pass",
                    help="'pass': alpha = 1 - camera-ray transmittance from a second pass; 'none': alpha = 1")
    ap.add_argument("--alpha-spp", type=int, default=None, help="spp of the alpha pass (default: the main spp)")
    ap.add_argument("--vol", default=None, help="where to write/keep the converted .vol (default: a temp dir)")
    ap.add_argument("--json", default=None, help="write timings, spp, versions and the scene as JSON")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(join_negative_values(list(sys.argv[1:] if argv is None else argv)))
    if args.sun_angle != 0.0 and not args.no_sun:
        ap.error("--sun-angle must be 0: Mitsuba's directional emitter is a delta light")
    if (args.camera_from is None) != (args.camera_to is None):
        ap.error("--camera-from and --camera-to go together")
    if args.camera_from is None:
        ap.error("pass --camera-from and --camera-to (this peer does not reproduce cirrus's automatic framing)")
    if args.batches < 1:
        ap.error("--batches must be >= 1")
    if args.stderr_out and args.batches < 2:
        ap.error("--stderr-out needs --batches >= 2")
    if args.time is not None and (args.batches > 1 or args.stderr_out):
        ap.error("--time renders one progressive image: no --batches / --stderr-out")
    if args.max_depth is not None and args.max_depth < 0:
        ap.error("--max-depth must be >= 0")
    if not (0.0 <= args.lobe_weight <= 1.0):
        ap.error("--lobe-weight must be in [0, 1]")
    if max(args.albedo) > 1.0:
        ap.error("--albedo must be in [0, 1]")
    # Equal channels are a grey medium (the 1-channel grid and its scalar scale).
    if args.density_scale is not None and len(set(args.density_scale)) == 1:
        args.density_scale = args.density_scale[:1]
    args.chromatic = args.density_scale is not None and len(args.density_scale) == 3
    if args.integrator == "auto":
        args.integrator = "volpathmis" if args.chromatic else "volpath"
    return args


def log(args, msg):
    if not args.quiet:
        print(msg, file=sys.stderr, flush=True)


def volume_file(args) -> tuple[str, dict]:
    """The .vol to render and its header; converts a .vdb first."""
    import vdb_to_mitsuba_vol as conv

    path = Path(args.file)
    if path.suffix == ".vol":
        hdr = conv.read_vol_header(path)
        # vdb_to_mitsuba_vol.py's bbox spans exactly res voxels.
        hdr["voxel_size"] = [(b - a) / n for a, b, n in zip(hdr["bbox_min"], hdr["bbox_max"], hdr["res"])]
        return str(path), hdr
    out = args.vol or str(Path(tempfile.mkdtemp(prefix="mitsuba_vol_")) / (path.stem + ".vol"))
    t0 = time.time()
    info = conv.convert(str(path), out, args.grid)
    log(args, f"converted {path} grid {info['grid']!r} -> {out} ({info['res']}, {time.time() - t0:.2f} s)")
    hdr = conv.read_vol_header(out)
    hdr["voxel_size"] = info["voxel_size"]
    return out, hdr


def mitsuba_max_depth(cirrus_max_depth: int | None) -> int:
    """cirrus counts real scattering events (0 = no scattering); Mitsuba's volpath counts
    path vertices including the camera segment's end (1 = emitters seen directly through
    the medium, 2 = single scattering)."""
    return -1 if cirrus_max_depth is None else cirrus_max_depth + 1


def mitsuba_phase(args) -> dict:
    """cirrus --phase as a Mitsuba phase plugin.  cirrus's hg2 is w1 HG(g) + (1 - w1) HG(g2) with
    w1 = --lobe-weight; Mitsuba's blendphase is (1 - weight) phase_0 + weight phase_1, so
    weight = 1 - w1 with phase_0 = hg(g), phase_1 = hg(g2)."""
    if args.phase == "hg":
        return {"type": "hg", "g": float(args.g)}
    if args.phase == "hg2":
        return {"type": "blendphase", "weight": 1.0 - float(args.lobe_weight),
                "phase_0": {"type": "hg", "g": float(args.g)},
                "phase_1": {"type": "hg", "g": float(args.g2)}}
    if args.phase == "rayleigh":
        return {"type": "rayleigh"}
    raise SystemExit(f"unsupported --phase {args.phase!r}")


def albedo_value(args, alpha_pass: bool):
    if alpha_pass:
        return 0.0
    if len(args.albedo) == 1:
        return float(args.albedo[0])
    return {"type": "constvolume", "value": {"type": "rgb", "value": [float(v) for v in args.albedo]}}


def build_scene(mi, args, vol_path: str, hdr: dict, *, alpha_pass: bool, spp: int, rgb_vol: str | None = None):
    """`rgb_vol`: for a chromatic medium, the 3-channel sigma_t .vol (density x scale_c)."""
    w, h = args.res
    bmin = np.array(hdr["bbox_min"], dtype=np.float64)
    bmax = np.array(hdr["bbox_max"], dtype=np.float64)
    centre, half = 0.5 * (bmin + bmax), 0.5 * (bmax - bmin)
    origin = np.array(args.camera_from, dtype=np.float64)
    if np.all(origin > bmin) and np.all(origin < bmax):
        raise SystemExit("the camera is inside the volume's bounding box; this peer needs it outside")
    corners = np.array([[bmin[0] if i & 1 == 0 else bmax[0], bmin[1] if i & 2 == 0 else bmax[1],
                         bmin[2] if i & 4 == 0 else bmax[2]] for i in range(8)])
    far = float(np.max(np.linalg.norm(corners - origin, axis=1))) * 2.0 + 1.0
    sensor = {
        "type": "perspective",
        "fov": args.fov,
        "fov_axis": "y",
        "near_clip": min(1e-2, far * 1e-6),
        "far_clip": far,
        "to_world": mi.ScalarTransform4f().look_at(
            origin=list(args.camera_from), target=list(args.camera_to), up=list(args.camera_up)
        ),
        "film": {
            "type": "hdrfilm",
            "width": w,
            "height": h,
            "rfilter": {"type": "box"},
            "pixel_format": "rgb",
            "sample_border": False,
        },
        "sampler": {"type": "independent", "sample_count": spp},
    }
    density_scale = args.density_scale
    if density_scale is None:
        vs = hdr.get("voxel_size")
        if vs is None or max(vs) - min(vs) > 1e-9 * max(vs):
            raise SystemExit("pass --density-scale (the default 1/voxel size needs a uniform voxel size)")
        density_scale = DEFAULT_DENSITY_PER_VOXEL / vs[0]
    else:
        density_scale = density_scale[0] if len(density_scale) == 1 else tuple(density_scale)
    if args.chromatic:
        if rgb_vol is None:
            raise SystemExit("internal: a chromatic medium needs the 3-channel .vol")
        medium = {
            "type": "heterogeneous",
            # sigma_t per channel = density x scale_c, baked into the 3 channels; `scale` 1.
            "sigma_t": {"type": "gridvolume", "filename": rgb_vol, "use_grid_bbox": True},
            "scale": 1.0,
            "albedo": albedo_value(args, alpha_pass),
            "phase": mitsuba_phase(args),
            "has_spectral_extinction": True,
        }
    else:
        medium = {
            "type": "heterogeneous",
            "sigma_t": {"type": "gridvolume", "filename": vol_path, "use_grid_bbox": True},
            "scale": float(density_scale),
            "albedo": albedo_value(args, alpha_pass),
            "phase": mitsuba_phase(args),
            # Grey extinction: no per-channel free-flight reweighting needed.
            "has_spectral_extinction": False,
        }
    scene = {
        "type": "scene",
        "integrator": {
            "type": args.integrator,
            "max_depth": 1 if alpha_pass else mitsuba_max_depth(args.max_depth),
            "rr_depth": args.rr_depth,
        },
        "sensor": sensor,
        "boundary": {
            "type": "cube",
            "to_world": mi.ScalarTransform4f().translate(centre.tolist()).scale(half.tolist()),
            "bsdf": {"type": "null"},
            "interior": medium,
        },
    }
    if alpha_pass:
        scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    else:
        if not args.no_sun and max(args.sun_irradiance) > 0:
            scene["sun"] = {
                "type": "directional",
                "direction": list(args.sun_dir),  # Mitsuba: the direction the light travels, like cirrus
                "irradiance": {"type": "rgb", "value": list(args.sun_irradiance)},
            }
        if max(args.env_radiance) > 0:
            scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": list(args.env_radiance)}}
    return mi.load_dict(scene), density_scale


def render_batches(mi, dr, scene, spp_total: int, batches: int, seed: int, npix: int):
    """Renders spp_total samples as >= `batches` launches of equal spp; returns
    (mean image, per-pixel variance of the mean or None, seconds, spp actually rendered)."""
    n = max(batches, math.ceil(spp_total * npix / MAX_SAMPLES_PER_LAUNCH))
    per = max(1, math.ceil(spp_total / n))
    if batches > 1:
        n = max(batches, math.ceil(spp_total / per))
    images = []
    t0 = time.time()
    for b in range(n):
        s = (seed * 1021 + b) & 0xFFFFFFFF
        img = mi.render(scene, seed=s, spp=per)
        images.append(np.array(img, dtype=np.float64))
    seconds = time.time() - t0
    stack = np.stack(images)
    mean = stack.mean(axis=0)
    var_mean = stack.var(axis=0, ddof=1) / n if n > 1 else None
    return mean, var_mean, seconds, per * n, n


def render_timed(mi, scene, seconds: float, seed: int, npix: int):
    """cirrus's --time loop: passes of 1, 2, 4, ... spp (each at most what the measured
    rate says still fits, at most twice the previous pass), all accumulated, until the
    budget is spent. Returns (mean image, seconds, spp)."""
    acc, spp, size, n = None, 0, 1, 0
    t0 = time.time()
    while size > 0:
        img = np.array(mi.render(scene, seed=(seed * 1021 + 512 + n) & 0xFFFFFFFF, spp=size), dtype=np.float64)
        acc = img * size if acc is None else acc + img * size
        spp += size
        n += 1
        per_spp = (time.time() - t0) / spp
        remaining = seconds - (time.time() - t0)
        fit = int(max(remaining, 0.0) / max(per_spp, 1e-9))
        size = min(fit, 2 * size, max(1, MAX_SAMPLES_PER_LAUNCH // npix))
    return acc / spp, time.time() - t0, spp


def write_exr(mi, path: str, rgba: np.ndarray) -> None:
    bmp = mi.Bitmap(np.ascontiguousarray(rgba, dtype=np.float32), pixel_format=mi.Bitmap.PixelFormat.RGBA)
    bmp.write(str(path))


def tonemap_srgb(rgb: np.ndarray, exposure: float) -> np.ndarray:
    """cirrus's PNG preview: ACES fit (Narkowicz 2015), then the sRGB transfer curve."""
    x = np.nan_to_num(np.maximum(rgb * 2.0 ** exposure, 0.0), nan=0.0, posinf=1e30)
    a, b, c, d, e = 2.51, 0.03, 2.43, 0.59, 0.14
    y = np.clip((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0)
    s = np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1.0 / 2.4) - 0.055)
    return (np.clip(s, 0, 1) * 255.0 + 0.5).astype(np.uint8)


def main(argv=None) -> int:
    args = parse_args(argv)
    t_start = time.time()
    mi, dr = mitsuba_setup.mitsuba(args.variant)
    if args.threads:
        dr.set_thread_count(args.threads)
    try:
        vol_path, hdr = volume_file(args)
    except Exception as e:  # ConversionError and I/O errors: one clear line
        raise SystemExit(f"mitsuba_render.py: {args.file}: {e}") from None
    w, h = args.res
    npix = w * h
    rgb_vol, rgb_dir = None, None
    if args.chromatic:
        import vdb_to_mitsuba_vol as conv

        if hdr.get("channels", 1) != 1:
            raise SystemExit(f"mitsuba_render.py: {vol_path}: pass the 1-channel density .vol (or the .vdb)")
        rgb_dir = tempfile.TemporaryDirectory(prefix="mitsuba_rgbvol_")
        rgb_vol = str(Path(rgb_dir.name) / "sigma_t_rgb.vol")
        info = conv.scale_channels(vol_path, rgb_vol, args.density_scale)
        log(args, f"chromatic: {rgb_vol} = density x {list(args.density_scale)}, max per channel "
                  f"{info['max_per_channel']}")
    scene, density_scale = build_scene(mi, args, vol_path, hdr, alpha_pass=False, spp=1, rgb_vol=rgb_vol)
    setup_s = time.time() - t_start

    # Warm-up launch so the timed render excludes Dr.Jit's kernel compilation.
    t0 = time.time()
    np.array(mi.render(scene, seed=args.seed ^ 0x5A5A, spp=1))
    compile_s = time.time() - t0
    if args.time is not None:
        rgb, render_s, spp_done = render_timed(mi, scene, args.time, args.seed, npix)
        var_rgb, nb = None, 1
        log(args, f"--time {args.time}: {spp_done} spp in {render_s:.2f} s")
    else:
        spp = args.spp if args.spp is not None else 64
        if spp < 1:
            raise SystemExit("--spp must be >= 1")
        rgb, var_rgb, render_s, spp_done, nb = render_batches(mi, dr, scene, spp, args.batches, args.seed, npix)
        log(args, f"main pass: {spp_done} spp in {nb} launch(es), {render_s:.2f} s")

    alpha = np.ones((h, w), dtype=np.float64)
    var_a = np.zeros((h, w), dtype=np.float64) if var_rgb is not None else None
    alpha_s = 0.0
    if args.alpha == "pass":
        ascene, _ = build_scene(mi, args, vol_path, hdr, alpha_pass=True, spp=1, rgb_vol=rgb_vol)
        np.array(mi.render(ascene, seed=1, spp=1))  # compile
        aspp = args.alpha_spp or spp_done
        t_img, t_var, alpha_s, _, _ = render_batches(mi, dr, ascene, aspp, args.batches, args.seed + 7919, npix)
        # Chromatic: the channels' mean 1 - T, as cirrus's alpha for chromatic media.
        alpha = 1.0 - (t_img[..., :3].mean(axis=-1) if args.chromatic else t_img[..., 0])
        if t_var is not None:
            # Chromatic: the channels are correlated; the mean of their variances bounds the variance of their mean.
            var_a = t_var[..., :3].mean(axis=-1) if args.chromatic else t_var[..., 0]
        log(args, f"alpha pass: {aspp} spp, {alpha_s:.2f} s")

    rgba = np.concatenate([rgb[..., :3], alpha[..., None]], axis=-1)
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    write_exr(mi, args.output, rgba)
    if args.stderr_out:
        se = np.sqrt(np.concatenate([var_rgb[..., :3], var_a[..., None]], axis=-1))
        write_exr(mi, args.stderr_out, se)
    if args.png:
        png = tonemap_srgb(rgb[..., :3], args.exposure)
        mi.Bitmap(png, pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(args.png))

    total_s = time.time() - t_start
    report = {
        "renderer": "mitsuba3",
        "versions": mitsuba_setup.versions(),
        "threads": dr.thread_count(),
        "output": args.output,
        "width": w,
        "height": h,
        "spp": spp_done,
        "launches": nb,
        "render_seconds": render_s,
        "alpha_seconds": alpha_s,
        "first_launch_seconds": compile_s,
        "setup_seconds": setup_s,
        "total_seconds": total_s,
        "mitsuba_max_depth": mitsuba_max_depth(args.max_depth),
        "integrator": args.integrator,
        "chromatic": args.chromatic,
        "albedo": list(args.albedo),
        "phase": mitsuba_phase(args),
        "density_scale": density_scale,
        "vol": vol_path,
        "vol_bbox": [list(hdr["bbox_min"]), list(hdr["bbox_max"])],
        "mean_rgba": rgba.reshape(-1, 4).mean(axis=0).tolist(),
    }
    print(
        f"{args.output}: {w}x{h} at {spp_done} spp in {render_s:.2f} s "
        f"(+ alpha pass {alpha_s:.2f} s, first launch/compile {compile_s:.2f} s, total {total_s:.2f} s; "
        f"{report['versions']['variant']}, {report['threads']} threads)"
    )
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    if rgb_dir is not None:
        rgb_dir.cleanup()
    return 0


if __name__ == "__main__":
    sys.exit(main())

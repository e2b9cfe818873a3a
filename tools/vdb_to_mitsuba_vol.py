#!/usr/bin/python3
"""Convert a float grid of a .vdb file to Mitsuba 3's binary `.vol` grid format.

Usage (Debian's own interpreter, the only one that can import pyopenvdb):

    /usr/bin/python3 tools/vdb_to_mitsuba_vol.py data/cloud.vdb /tmp/cloud.vol [--grid density]
    /usr/bin/python3 tools/vdb_to_mitsuba_vol.py data/cloud.vdb /tmp/cloud.vol --check 4000
    /usr/bin/python3 tools/vdb_to_mitsuba_vol.py data/cloud.vdb /tmp/rgb.vol --channel-scales 0.8,0.5,0.25 --check 4000

`--channel-scales R,G,B` writes 3 channels (channel c = density x scale_c, interleaved per
voxel as Mitsuba reads them) for a chromatic medium's `sigma_t` with `scale` 1.

The written grid reproduces cirrus's density field exactly (up to float32 rounding):
OpenVDB trilinear interpolation between voxel centres (BoxSampler), 0 outside the
active set.  Mitsuba's `gridvolume` is cell-centred with clamp-to-edge filtering
(texel k of N sits at local coordinate (k + 0.5) / N), so the dense copy of the
active bounding box [i0, i1] is padded with one layer of zeros on every side
(N = i1 - i0 + 3 samples, sample k = index i0 - 1 + k) and its bounding box is
index [i0 - 1.5, i1 + 1.5] mapped to world space: then texel centres land on voxel
centres, Mitsuba's lerp between them is OpenVDB's trilinear, the last half texel
lerps toward the zero layer exactly as OpenVDB lerps toward background voxels, and
clamp-to-edge beyond the bbox returns the zero layer.  Use it with
`'use_grid_bbox': True` (tools/mitsuba_render.py does).

Only axis-aligned index-to-world transforms (UniformScaleMap, UniformScaleTranslateMap,
ScaleMap, ScaleTranslateMap, or any linear map whose matrix is diagonal with positive
entries) are supported.

`--check N` evaluates the written volume with Mitsuba (`gridvolume.eval_1`) at N random
world points (plus voxel centres and points around the bbox faces) and compares it with
an independent OpenVDB-BoxSampler trilinear computed from pyopenvdb accessor look-ups;
it prints the maximum absolute difference and fails if it exceeds `--tolerance`.
"""

from __future__ import annotations

import argparse
import struct
import sys
import time
from pathlib import Path

try:
    import numpy as np
except ImportError:
    sys.exit(f"{__file__}: numpy is missing for {sys.executable}; run the peer tools with Debian's "
             "/usr/bin/python3 (apt-get install -y python3-numpy python3-openvdb; see tools/README.md)")

sys.dont_write_bytecode = True

try:
    import pyopenvdb as vdb
except ImportError:  # the .vol helpers below work without it
    vdb = None

PYOPENVDB_HINT = (
    "cannot import pyopenvdb. Run with Debian's /usr/bin/python3 after "
    "`apt-get install -y python3-openvdb python3-numpy` (a pyenv python3 cannot import it)."
)

AXIS_ALIGNED_MAPS = {"UniformScaleMap", "UniformScaleTranslateMap", "ScaleMap", "ScaleTranslateMap"}


class ConversionError(Exception):
    pass


def choose_grid(path: str, name: str | None):
    """The named grid, else `density`, else the first float grid (cirrus's rule)."""
    metas = vdb.readAllGridMetadata(path)
    names = [m.name for m in metas]
    if name is not None:
        if name not in names:
            raise ConversionError(f"{path}: no grid named {name!r} (grids: {names})")
        grid = vdb.read(path, name)
    elif "density" in names:
        grid = vdb.read(path, "density")
    else:
        grid = None
        for n in names:
            g = vdb.read(path, n)
            if g.valueTypeName == "float":
                grid = g
                break
        if grid is None:
            raise ConversionError(f"{path}: no float grid (grids: {names})")
    if grid.valueTypeName != "float":
        raise ConversionError(f"{path}: grid {grid.name!r} is {grid.valueTypeName}, not float")
    return grid


def axis_aligned_map(grid):
    """(scale[3], translation[3]) of an axis-aligned index->world map, in float64."""
    xf = grid.transform
    t = np.array(xf.indexToWorld((0, 0, 0)), dtype=np.float64)
    cols = [np.array(xf.indexToWorld(e), dtype=np.float64) - t for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    m = np.stack(cols, axis=1)  # world = m @ ijk + t
    scale = np.diag(m).copy()
    off = m - np.diag(scale)
    ok = xf.typeName in AXIS_ALIGNED_MAPS or (
        xf.isLinear and np.all(np.abs(off) <= 1e-12 * np.abs(scale).max())
    )
    if not ok or np.any(np.abs(off) > 1e-12 * np.abs(scale).max()):
        raise ConversionError(
            f"grid {grid.name!r}: unsupported transform {xf.typeName} (only axis-aligned "
            "uniform/scale/translate maps can be written as a Mitsuba grid bbox)"
        )
    if np.any(scale <= 0):
        raise ConversionError(f"grid {grid.name!r}: transform has a non-positive scale {scale.tolist()}")
    # Verify affinity at a far point (the map must be linear + translation).
    p = np.array([123.25, -77.5, 1001.0])
    if not np.allclose(xf.indexToWorld(tuple(p)), m @ p + t, rtol=1e-12, atol=1e-9 * max(1.0, np.abs(t).max())):
        raise ConversionError(f"grid {grid.name!r}: transform {xf.typeName} is not affine")
    return scale, t


def dense_padded(grid):
    """float32 array [x, y, z] of the active bbox padded by one zero voxel per side,
    with every inactive value (inside the bbox) replaced by 0, and the index of
    sample [0, 0, 0]."""
    bbox = grid.evalActiveVoxelBoundingBox()
    if grid.activeVoxelCount() == 0:
        raise ConversionError(f"grid {grid.name!r} has no active voxels")
    lo = np.array(bbox[0], dtype=np.int64)
    hi = np.array(bbox[1], dtype=np.int64)
    dims = hi - lo + 1
    if np.prod(dims.astype(np.float64)) > 2**31:
        raise ConversionError(f"active bbox {dims.tolist()} is too large to densify")
    values = np.zeros(tuple(dims), dtype=np.float32)
    grid.copyToArray(values, ijk=tuple(int(v) for v in lo))
    # Active mask: a copy with every active value 1 and every inactive value 0.
    mask_grid = grid.deepCopy()
    mask_grid.background = 0.0
    mask_grid.mapOn(lambda _v: 1.0)
    mask_grid.mapOff(lambda _v: 0.0)
    mask = np.zeros(tuple(dims), dtype=np.float32)
    mask_grid.copyToArray(mask, ijk=tuple(int(v) for v in lo))
    values = np.where(mask == 1.0, values, np.float32(0.0)).astype(np.float32)
    if not np.all(np.isfinite(values)):
        raise ConversionError(f"grid {grid.name!r} has non-finite active values; Mitsuba cannot render them")
    padded = np.zeros(tuple(dims + 2), dtype=np.float32)
    padded[1:-1, 1:-1, 1:-1] = values
    return padded, lo - 1, int(mask.sum())


def write_vol(path: str | Path, data_xyz: np.ndarray, bbox_min, bbox_max, *, bbox_raw: bytes | None = None) -> None:
    """Mitsuba's .vol: 'VOL', version 3, encoding 1 (float32), xres, yres, zres,
    channels, bbox (6 float32), then float32 data with x fastest.  `data_xyz` is
    [x, y, z] (1 channel) or [x, y, z, c] (c channels, interleaved per voxel as
    Mitsuba reads them: data[((z * yres + y) * xres + x) * channels + c]).
    `bbox_raw`: the 24 bbox bytes to write verbatim (copying another file's bbox bit for bit)."""
    if data_xyz.ndim == 3:
        data_xyz = data_xyz[..., None]
    nx, ny, nz, nc = data_xyz.shape
    if nc not in (1, 3):
        raise ConversionError(f"{nc} channels: Mitsuba's gridvolume takes 1 or 3 here")
    header = b"VOL" + bytes([3]) + struct.pack("<iiiii", 1, nx, ny, nz, nc)
    if bbox_raw is not None:
        assert len(bbox_raw) == 24
        header += bbox_raw
    else:
        header += struct.pack("<6f", *[float(v) for v in bbox_min], *[float(v) for v in bbox_max])
    body = np.ascontiguousarray(np.transpose(data_xyz, (2, 1, 0, 3)), dtype="<f4").tobytes()
    tmp = Path(str(path) + ".tmp")
    with open(tmp, "wb") as f:
        f.write(header)
        f.write(body)
    tmp.replace(path)


def read_vol(path: str | Path) -> tuple[dict, np.ndarray, bytes]:
    """(header, data [x, y, z, c] float32, the 24 raw bbox bytes) of a float32 .vol."""
    hdr = read_vol_header(path)
    if hdr["encoding"] != 1:
        raise ConversionError(f"{path}: encoding {hdr['encoding']}, only float32 (1) is read")
    nx, ny, nz = hdr["res"]
    nc = hdr["channels"]
    with open(path, "rb") as f:
        raw = f.read()
    body = np.frombuffer(raw, dtype="<f4", offset=48)
    if body.size != nx * ny * nz * nc:
        raise ConversionError(f"{path}: {body.size} values, header says {nx}x{ny}x{nz}x{nc}")
    data = np.transpose(body.reshape(nz, ny, nx, nc), (2, 1, 0, 3))
    return hdr, data, raw[24:48]


def scale_channels(in_vol: str | Path, out_vol: str | Path, scales) -> dict:
    """A 1-channel density .vol -> a 3-channel .vol whose channel c is density x scales[c]
    (sigma_t per channel, for a chromatic medium rendered with `scale` 1); the bbox bytes
    are copied verbatim, so the texel placement is exactly the 1-channel file's."""
    hdr, data, bbox_raw = read_vol(in_vol)
    if hdr["channels"] != 1:
        raise ConversionError(f"{in_vol}: {hdr['channels']} channels, expected a 1-channel density .vol")
    s = np.asarray([float(v) for v in scales], dtype=np.float64)
    if s.shape != (3,) or not np.all(np.isfinite(s)) or np.any(s < 0):
        raise ConversionError(f"channel scales must be three finite numbers >= 0, got {scales!r}")
    rgb = (data.astype(np.float64) * s).astype(np.float32)  # [x, y, z, 1] * [3] -> [x, y, z, 3]
    write_vol(out_vol, rgb, None, None, bbox_raw=bbox_raw)
    return {**hdr, "channels": 3, "scales": s.tolist(), "max_per_channel": rgb.reshape(-1, 3).max(axis=0).tolist()}


def read_vol_header(path: str | Path) -> dict:
    with open(path, "rb") as f:
        h = f.read(48)
    if len(h) < 48 or h[:3] != b"VOL" or h[3] != 3:
        raise ConversionError(f"{path}: not a Mitsuba .vol (version 3) file")
    enc, nx, ny, nz, ch = struct.unpack("<iiiii", h[4:24])
    bb = struct.unpack("<6f", h[24:48])
    return {"encoding": enc, "res": (nx, ny, nz), "channels": ch, "bbox_min": bb[:3], "bbox_max": bb[3:]}


def convert(vdb_path: str, vol_path: str, grid_name: str | None = None) -> dict:
    if vdb is None:
        raise ConversionError(PYOPENVDB_HINT)
    grid = choose_grid(vdb_path, grid_name)
    scale, trans = axis_aligned_map(grid)
    data, origin, n_active = dense_padded(grid)
    n = np.array(data.shape, dtype=np.float64)
    idx_min = origin.astype(np.float64) - 0.5           # = i0 - 1.5
    idx_max = origin.astype(np.float64) + n - 0.5       # = i1 + 1.5
    bbox_min = scale * idx_min + trans
    bbox_max = scale * idx_max + trans
    write_vol(vol_path, data, bbox_min, bbox_max)
    return {
        "grid": grid.name,
        "transform": grid.transform.typeName,
        "voxel_size": scale.tolist(),
        "translation": trans.tolist(),
        "index_bbox_active": [(origin + 1).tolist(), (origin + n.astype(np.int64) - 2).tolist()],
        "res": list(data.shape),
        "bbox_min": bbox_min.tolist(),
        "bbox_max": bbox_max.tolist(),
        "max": float(data.max()),
        "active_voxels": n_active,
        "_grid": grid,
        "_scale": scale,
        "_trans": trans,
    }


# --------------------------------------------------------------------------- check

def reference_trilinear(grid, scale, trans, pts_world: np.ndarray) -> np.ndarray:
    """OpenVDB BoxSampler trilinear in index space, from accessor look-ups, with
    inactive voxels (and everything outside the tree) taken as 0."""
    acc = grid.getConstAccessor()
    cache: dict = {}

    def val(ijk):
        v = cache.get(ijk)
        if v is None:
            value, active = acc.probeValue(ijk)
            v = float(value) if active else 0.0
            cache[ijk] = v
        return v

    out = np.empty(len(pts_world))
    idx = (pts_world - trans) / scale
    for n, x in enumerate(idx):
        b = np.floor(x)
        f = x - b
        i, j, k = (int(c) for c in b)
        acc_v = 0.0
        for dx in (0, 1):
            wx = f[0] if dx else 1.0 - f[0]
            for dy in (0, 1):
                wy = f[1] if dy else 1.0 - f[1]
                for dz in (0, 1):
                    wz = f[2] if dz else 1.0 - f[2]
                    w = wx * wy * wz
                    if w != 0.0:
                        acc_v += w * val((i + dx, j + dy, k + dz))
        out[n] = acc_v
    return out


def mitsuba_eval(vol_path: str, pts_world: np.ndarray, variant: str | None = None) -> np.ndarray:
    """Mitsuba's gridvolume at the points: shape (N,) for a 1-channel .vol (`eval_1`),
    (N, 3) for a 3-channel one (`eval`, RGB variants: the channels as stored)."""
    import mitsuba_setup

    mi, dr = mitsuba_setup.mitsuba(variant)
    vol = mi.load_dict({"type": "gridvolume", "filename": str(vol_path), "use_grid_bbox": True})
    it = dr.zeros(mi.Interaction3f, len(pts_world))
    p = pts_world.astype(np.float32)
    it.p = mi.Point3f(mi.Float(p[:, 0]), mi.Float(p[:, 1]), mi.Float(p[:, 2]))
    if read_vol_header(vol_path)["channels"] == 3:
        if not mi.variant().endswith("_rgb"):
            raise ConversionError(f"--check of a 3-channel .vol needs an RGB variant, not {mi.variant()}")
        return np.array(vol.eval(it), dtype=np.float64).reshape(3, -1).T
    return np.array(vol.eval_1(it), dtype=np.float64).reshape(-1)


def check_points(info: dict, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    scale, trans = info["_scale"], info["_trans"]
    lo_i = np.array(info["index_bbox_active"][0], dtype=np.float64)
    hi_i = np.array(info["index_bbox_active"][1], dtype=np.float64)
    # Uniform over the active bbox grown by 3 voxels (so the padding, the
    # clamp region and the outside are all hit).
    u = rng.uniform(lo_i - 3.0, hi_i + 3.0, size=(n, 3))
    # Near the faces of the active bbox (within 1.5 voxels), on every side.
    m = max(n // 4, 1)
    near = rng.uniform(lo_i - 1.0, hi_i + 1.0, size=(m, 3))
    axis = rng.integers(0, 3, size=m)
    side = rng.integers(0, 2, size=m)
    for r in range(m):
        a = axis[r]
        edge = lo_i[a] if side[r] == 0 else hi_i[a]
        near[r, a] = edge + rng.uniform(-1.5, 1.5)
    # Exactly at random voxel centres (no interpolation).
    centres = np.floor(rng.uniform(lo_i, hi_i + 1.0, size=(m, 3)))
    idx = np.concatenate([u, near, centres])
    return idx * scale + trans


def run_check(info: dict, vol_path: str, n: int, seed: int, variant: str | None, scales=None) -> dict:
    """`scales`: the .vol holds density x scales[c] in channel c (written by --channel-scales)."""
    # Both sides get the same float32 points (Mitsuba's positions are float32).
    pts = check_points(info, n, seed).astype(np.float32).astype(np.float64)
    t0 = time.time()
    ref = reference_trilinear(info["_grid"], info["_scale"], info["_trans"], pts)
    t1 = time.time()
    got = mitsuba_eval(vol_path, pts, variant)
    if scales is not None:
        ref = ref[:, None] * np.asarray(scales, dtype=np.float64)[None, :]
    diff = np.abs(got - ref)
    worst = np.unravel_index(int(np.argmax(diff)), diff.shape)
    return {
        "points": len(pts),
        "max_abs_diff": float(diff.max()),
        "mean_abs_diff": float(diff.mean()),
        "max_abs_diff_per_channel": diff.max(axis=0).tolist() if diff.ndim == 2 else None,
        "max_value": float(np.abs(ref).max()),
        "nonzero_reference_points": int(np.count_nonzero(ref.reshape(len(pts), -1).max(axis=1))),
        "worst_point": pts[worst[0]].tolist(),
        "worst_reference": float(ref[worst]),
        "worst_mitsuba": float(got[worst]),
        "reference_seconds": t1 - t0,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("vdb")
    ap.add_argument("vol")
    ap.add_argument("--grid", default=None, help="grid name (default: density, else the first float grid)")
    ap.add_argument("--check", type=int, default=0, metavar="N",
                    help="evaluate the written grid with Mitsuba at ~1.5N points against OpenVDB trilinear")
    ap.add_argument("--channel-scales", default=None, metavar="R,G,B",
                    help="write a 3-channel .vol, channel c = density x this (sigma_t per channel of a chromatic "
                         "medium, for `scale` 1); --check then compares every channel")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--tolerance", type=float, default=1e-4,
                    help="--check fails when max |mitsuba - openvdb| exceeds this times max(1, max density)")
    ap.add_argument("--variant", default=None, help="Mitsuba variant for --check (default: llvm_ad_rgb, else scalar_rgb)")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    try:
        t0 = time.time()
        scales = None
        if args.channel_scales is not None:
            scales = [float(v) for v in args.channel_scales.split(",")]
            if len(scales) != 3:
                raise ConversionError(f"--channel-scales needs R,G,B, got {args.channel_scales!r}")
            grey = args.vol + ".grey.tmp"
            info = convert(args.vdb, grey, args.grid)
            rgb = scale_channels(grey, args.vol, scales)
            Path(grey).unlink()
            print(f"{args.vol}: 3 channels = density x {scales}, max per channel "
                  f"{[round(v, 6) for v in rgb['max_per_channel']]}")
        else:
            info = convert(args.vdb, args.vol, args.grid)
        print(
            f"{args.vol}: grid {info['grid']!r} ({info['transform']}, voxel size {info['voxel_size']}), "
            f"{info['res'][0]}x{info['res'][1]}x{info['res'][2]} samples (active bbox + 1 zero voxel per side), "
            f"bbox {[round(v, 6) for v in info['bbox_min']]} - {[round(v, 6) for v in info['bbox_max']]}, "
            f"max {info['max']:.6g}, {time.time() - t0:.2f} s"
        )
        if args.check:
            r = run_check(info, args.vol, args.check, args.seed, args.variant, scales)
            limit = args.tolerance * max(1.0, r["max_value"])
            print(
                f"check: {r['points']} points ({r['nonzero_reference_points']} with density > 0): "
                f"max |mitsuba - openvdb trilinear| = {r['max_abs_diff']:.3g}, mean {r['mean_abs_diff']:.3g} "
                f"(max density {r['max_value']:.4g}); worst at world {[round(v, 4) for v in r['worst_point']]}: "
                f"openvdb {r['worst_reference']:.7g} mitsuba {r['worst_mitsuba']:.7g}"
                + (f"; max per channel R G B {[float(f'{v:.3g}') for v in r['max_abs_diff_per_channel']]}"
                   if r["max_abs_diff_per_channel"] else "")
            )
            if r["max_abs_diff"] > limit:
                print(f"check FAILED: difference above {limit:.3g}", file=sys.stderr)
                return 1
            print("check passed")
    except ConversionError as e:
        print(f"vdb_to_mitsuba_vol.py: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

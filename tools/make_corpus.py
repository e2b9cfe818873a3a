#!/usr/bin/python3
"""Generate the cirrus test corpus of OpenVDB (.vdb) and NanoVDB (.nvdb) files.

Usage (Debian's own interpreter, the only one that can import pyopenvdb):

    /usr/bin/python3 tools/make_corpus.py data

Every file is written with Debian's OpenVDB 10.0.1 stack (pyopenvdb, vdb_tool,
nanovdb_convert), read back, described in OUTDIR/manifest.json and cross-checked
against vdb_print / nanovdb_print / nanovdb_validate.  Content is deterministic
(seeded numpy RNGs, no clocks); only the random UUID that OpenVDB puts in every
.vdb header changes between runs.  See tools/README.md for the manifest schema.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyopenvdb as vdb

sys.dont_write_bytecode = True  # keep tools/ free of __pycache__
sys.path.insert(0, str(Path(__file__).resolve().parent))
import procedural  # noqa: E402
import vdbfile  # noqa: E402

SEED = 20240611
ACTIVE_SAMPLES = 160       # random active leaf voxels per grid
INACTIVE_SAMPLES = 80      # random inactive voxels inside leaves per grid
TILE_SAMPLES = 40          # tiles sampled per grid (one random voxel each, plus corners)
FOG, UNKNOWN = vdb.GridClass.FOG_VOLUME, vdb.GridClass.UNKNOWN


# --------------------------------------------------------------------------- plumbing

@dataclass
class Product:
    """One corpus file plus what its manifest entry needs beyond the generic description."""
    file: str
    format: str = "vdb"                       # "vdb" | "nvdb"
    source: str | None = None                 # nvdb: the .vdb it was converted from
    extra_samples: dict[str, list] = field(default_factory=dict)   # grid name -> ijk list
    extra: dict = field(default_factory=dict)  # extra top-level keys (e.g. expect_error)
    substitutes: dict[str, "Substitute"] = field(default_factory=dict)  # by grid name
    check: object = None                      # callable(entry, VdbFile) run after describing


@dataclass
class Substitute:
    """Stand-in for a grid type pyopenvdb cannot load (see case_other_types)."""
    grid: object                   # pyopenvdb grid read back from the unpatched file
    value_type: str
    convert: object                # float value -> value of the real type


class Ctx:
    def __init__(self, out: Path, tmp: Path):
        self.out, self.tmp = out, tmp
        self.products: list[Product] = []

    def path(self, name: str) -> str:
        return str(self.out / name)

    def add(self, product: Product) -> Product:
        self.products.append(product)
        return product


def run(*cmd: str) -> str:
    """Run a tool, fail loudly on a non-zero exit, return stdout."""
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
    return p.stdout


def vdb_tool_rewrite(src: str, dst: str, codec: str, bits: int = 32) -> None:
    """Rewrite every grid of `src` with vdb_tool's chosen codec (drops file metadata)."""
    if os.path.exists(dst):
        os.remove(dst)
    args = ["vdb_tool", "-quiet", "-read", src, "-write", f"codec={codec}"]
    if bits != 32:
        args.append(f"bits={bits}")
    run(*args, dst)


def rng_for(*keys) -> np.random.Generator:
    """A generator seeded from SEED and stable string/int keys (independent of case order)."""
    return np.random.default_rng([SEED] + [zlib.crc32(str(k).encode()) for k in keys])


# --------------------------------------------------------------------------- grid builders

def fog_sphere(centre, radius: float, name: str = "density", peak: float = 1.0) -> vdb.FloatGrid:
    """Fog sphere: density peak*(1 - (r/R)^2), zero (inactive) outside radius R."""
    r = int(math.ceil(radius))
    ax = np.arange(-r, r + 1, dtype=np.float32)
    d2 = (ax[:, None, None] ** 2 + ax[None, :, None] ** 2 + ax[None, None, :] ** 2) / radius ** 2
    dens = np.clip(1.0 - d2, 0.0, 1.0).astype(np.float32) * np.float32(peak)
    g = vdb.FloatGrid()
    g.copyFromArray(dens, ijk=tuple(int(c) - r for c in centre))
    g.name, g.gridClass = name, FOG
    return g


def cloud_grid(size, seed: int, offset, name: str = "density") -> vdb.FloatGrid:
    dens = procedural.cumulus_density(size, seed)
    g = vdb.FloatGrid()
    g.copyFromArray(dens, ijk=offset)
    g.name, g.gridClass = name, FOG
    return g


# --------------------------------------------------------------------------- cases

def case_sphere_fog(ctx: Ctx) -> None:
    """sphere_fog.vdb: the simplest fog volume, a radius-20 sphere of density 1-(r/R)^2.

    Exercises: reading a single blosc+active-mask float grid, leaf values, bbox,
    UniformScaleMap.  It is also the source of the .nvdb files.
    """
    g = fog_sphere((24, 24, 24), 20.0)
    vdb.write(ctx.path("sphere_fog.vdb"), [g])
    line = [[x, 24, 24] for x in range(0, 50)]
    ctx.add(Product("sphere_fog.vdb", extra_samples={"density": line}))


def case_cloud(ctx: Ctx) -> None:
    """cloud.vdb: the default cumulus cloud (about 1.3 M active voxels, 3,000+ leaves).

    Exercises: realistic sparsity, soft noisy edges, many leaves, blosc+active mask.
    Voxel size 1, grid "density", class fog volume, positive octant.
    """
    g = cloud_grid((296, 148, 224), seed=7, offset=(0, 0, 0))
    vdb.write(ctx.path("cloud.vdb"), [g])
    ctx.add(Product("cloud.vdb"))


def case_level_set_sphere(ctx: Ctx) -> None:
    """level_set_sphere.vdb: openvdb.createLevelSetSphere (radius 10, voxel 0.5, half width 3).

    Exercises: class level set, background = half width * voxel size = 1.5, inactive
    interior values of -background (leaf mode bytes 1 and 3), narrow band only.
    """
    g = vdb.createLevelSetSphere(radius=10.0, center=(12.0, 12.0, 12.0), voxelSize=0.5,
                                 halfWidth=3.0)
    g.name = "surface"
    vdb.write(ctx.path("level_set_sphere.vdb"), [g])
    line = [[x, 24, 24] for x in range(-2, 52)]
    ctx.add(Product("level_set_sphere.vdb", extra_samples={"surface": line}))


def case_tile_box(ctx: Ctx) -> None:
    """tile_box.vdb: constant 0.5 over [0,127]^3 stored as ONE active 128^3 tile, zero leaves.

    Exercises: readers that only walk leaves see nothing; tile values and tile
    activity must be honoured.
    """
    g = vdb.FloatGrid()
    g.name, g.gridClass = "density", FOG
    g.fill((0, 0, 0), (127, 127, 127), 0.5)
    vdb.write(ctx.path("tile_box.vdb"), [g])
    pts = [[0, 0, 0], [127, 127, 127], [64, 64, 64], [128, 0, 0], [-1, 0, 0], [0, 127, 128]]
    ctx.add(Product("tile_box.vdb", extra_samples={"density": pts}, check=check_tiles([0, 1, 0], leaves=0)))


def case_leaf_tiles(ctx: Ctx) -> None:
    """leaf_tiles.vdb: active tiles at every level plus leaves at a soft border.

    A fog box [122,293]^3 with a 3-voxel ramp at its faces is copied from a dense
    array and pruned: its constant interior becomes 8^3 (leaf-level) tiles and one
    128^3 tile at [128,255]^3, the ramp stays in leaves.  A fill of
    [4096,8191]x[0,4095]x[0,4095] adds one 4096^3 root-level tile (68.7 G voxels, so
    active-voxel counts exceed 2^32).
    """
    lo, hi, ramp = 122, 293, 3
    n = 176  # dense block [120, 295]
    ax = np.arange(120, 120 + n)
    d = np.minimum(ax - lo, hi - ax).astype(np.float32)  # distance inside, per axis
    dmin = np.minimum(np.minimum(d[:, None, None], d[None, :, None]), d[None, None, :])
    dens = np.where(dmin < 0, 0.0, np.minimum(1.0, (dmin + 1.0) / (ramp + 1.0))).astype(np.float32)
    g = vdb.FloatGrid()
    g.copyFromArray(dens, ijk=(120, 120, 120))
    g.prune()
    g.fill((4096, 0, 0), (8191, 4095, 4095), 0.25)
    g.name, g.gridClass = "density", FOG
    vdb.write(ctx.path("leaf_tiles.vdb"), [g])
    pts = [[128, 128, 128], [255, 255, 255], [200, 130, 250], [124, 124, 124], [122, 150, 150],
           [121, 150, 150], [294, 150, 150], [293, 293, 293], [260, 200, 140], [270, 280, 130],
           [4096, 0, 0], [8191, 4095, 4095],
           [6000, 2000, 3000], [8192, 0, 0], [4095, 0, 0], [5000, 4096, 10]]
    ctx.add(Product("leaf_tiles.vdb", extra_samples={"density": pts}, check=check_tiles_everywhere))


def multi_grid_grids() -> list:
    """The four grids of multi_grid.vdb in file order (see case_multi_grid)."""
    density = cloud_grid((128, 64, 96), seed=11, offset=(8, 4, 8))

    # temperature: background 293 K (ambient), a warm core that fades back to 293.
    temperature = vdb.FloatGrid(293.0)
    temperature.name, temperature.gridClass = "temperature", UNKNOWN
    r = 20
    ax = np.arange(-r, r + 1, dtype=np.float32)
    rr = np.sqrt(ax[:, None, None] ** 2 + ax[None, :, None] ** 2 + ax[None, None, :] ** 2) / r
    temp = (293.0 + 40.0 * np.clip(1.0 - rr, 0.0, 1.0) ** 1.5).astype(np.float32)
    temperature.copyFromArray(temp, ijk=(72 - r, 34 - r, 56 - r))

    # velocity: a swirl around the vertical axis with a small updraft, inside a sphere.
    velocity = vdb.Vec3SGrid()
    velocity.name, velocity.vectorType = "velocity", vdb.VectorType.CONTRAVARIANT_RELATIVE
    r = 12
    ax = np.arange(-r, r + 1, dtype=np.float32)
    x, y, z = np.meshgrid(ax, ax, ax, indexing="ij")
    inside = (x * x + y * y + z * z) <= r * r
    vel = np.stack([-z * 0.1, 0.5 + 0.02 * y, x * 0.1], axis=-1).astype(np.float32)
    vel[~inside] = 0.0
    velocity.copyFromArray(vel, ijk=(70 - r, 40 - r, 60 - r))

    # mask: a bool slab stored as 8^3 tiles, a sphere of single voxels, and some
    # inactive voxels whose value bit is true.
    mask = vdb.BoolGrid(False)
    mask.name = "mask"
    mask.fill((0, 0, 0), (95, 7, 95), True)
    acc = mask.getAccessor()
    for i in range(-6, 7):
        for j in range(-6, 7):
            for k in range(-6, 7):
                if i * i + j * j + k * k <= 36:
                    acc.setValueOn((60 + i, 30 + j, 40 + k), True)
    for i in range(0, 8):
        acc.setValueOff((100 + i, 3, 3), True)
    return [velocity, density, temperature, mask]


def case_multi_grid(ctx: Ctx) -> None:
    """multi_grid.vdb: four grids (float fog "density", float "temperature" with
    background 293, Vec3S "velocity", bool "mask") written in the non-alphabetical
    order velocity, density, temperature, mask, plus file metadata of four types.

    Exercises: grid selection by name, file order vs the sorted order OpenVDB tools
    report, vec3 and bool trees, non-zero background, file-level metadata.  The grids
    differ a lot in size so reading one grid is distinguishable from reading all.

    density_only.vdb: the same "density" grid alone (identical voxels).
    """
    grids = multi_grid_grids()
    meta = {"description": "cirrus multi-grid test file", "frame": 42,
            "time_step": 0.041666666666666664, "wind": (1.5, 0.0, -0.5)}
    vdb.write(ctx.path("multi_grid.vdb"), grids, metadata=meta)
    vdb.write(ctx.path("density_only.vdb"), [grids[1]])
    ctx.add(Product("multi_grid.vdb", extra_samples={
        "mask": [[100 + i, 3, 3] for i in range(8)] + [[0, 0, 0], [95, 7, 95], [96, 7, 95]]}))
    ctx.add(Product("density_only.vdb"))


def codec_source_grid() -> vdb.FloatGrid:
    """A lumpy noise ball with an active tile and a few odd inactive values."""
    noise = procedural.GradientNoise(SEED + 3)
    r = 16
    ax = np.arange(-r - 4, r + 5, dtype=np.float32)
    rr = np.sqrt(ax[:, None, None] ** 2 + ax[None, :, None] ** 2 + ax[None, None, :] ** 2) / r
    n = noise.fbm(ax, ax, ax, freq=1 / 8, octaves=3)
    dens = np.clip(1.0 - rr + 0.35 * n, 0.0, None).astype(np.float32)
    g = vdb.FloatGrid()
    g.copyFromArray(dens, ijk=(12, 12, 12))
    g.fill((64, 0, 0), (71, 7, 7), 0.75)                # an active 8^3 tile
    acc = g.getAccessor()
    for i in range(8):
        acc.setValueOff((80 + i, 0, 0), 0.125 * i)       # inactive non-background values
    g.name, g.gridClass = "density", UNKNOWN            # class unknown so ZIP is kept
    return g


def case_codecs(ctx: Ctx) -> None:
    """codec_{none,zip,blosc,active}.vdb: one float grid (class unknown) rewritten by
    vdb_tool with each codec.

    Exercises: every per-grid compression flag combination vdb_tool can produce.
    The manifest's "compression" is the u32 read from each file (vdb_tool's zip
    also sets the active-mask bit).
    """
    src = str(ctx.tmp / "codec_src.vdb")
    vdb.write(src, [codec_source_grid()])
    expected = {"none": 0, "zip": 3, "blosc": 6, "active": 2}
    for codec in ("none", "zip", "blosc", "active"):
        name = f"codec_{codec}.vdb"
        vdb_tool_rewrite(src, ctx.path(name), codec)
        ctx.add(Product(name, extra_samples={"density": [[80 + i, 0, 0] for i in range(8)]},
                        check=check_compression(expected[codec])))


# Leaves of inactive_modes.vdb: (expected mode byte, recipe).  Leaf k has its origin at
# (16*k, 0, 0), so that every recipe gets a leaf of its own.
MODE_LEAVES = [
    (0, "mode 0: inactive values are all +background"),
    (1, "mode 1: inactive values are all -background"),
    (2, "mode 2: inactive values are all 7.5"),
    (3, "mode 3: mask selects -bg / +bg, first inactive value -bg"),
    (3, "mode 3: mask selects -bg / +bg, first inactive value +bg"),
    (4, "mode 4: mask selects bg / 7.5, first inactive value 7.5"),
    (4, "mode 4: mask selects bg / 7.5, first inactive value bg"),
    (5, "mode 5: mask selects 7.5 / -3.25"),
    (5, "mode 5: mask selects -3.25 / 7.5, first inactive value -3.25"),
    (6, "mode 6: three or more distinct inactive values"),
    (2, "mode 2 with zero active voxels (empty value chunk)"),
    (0, "mode 0 with zero active voxels (leaf kept although all +background)"),
    (1, "mode 1 with zero active voxels"),
    (0, "mode 0 with all 512 voxels active"),
]


def inactive_modes_grid() -> vdb.FloatGrid:
    bg, other, other2 = 2.0, 7.5, -3.25
    g = vdb.FloatGrid(bg)
    g.name, g.gridClass = "modes", UNKNOWN
    acc = g.getAccessor()
    for k, (_mode, _doc) in enumerate(MODE_LEAVES):
        ox = 16 * k
        inactive_index = 0
        for n in range(512):
            x, y, z = n >> 6, (n >> 3) & 7, n & 7
            ijk = (ox + x, y, z)
            all_off = k in (10, 11, 12)
            all_on = k == 13
            if all_on or (not all_off and (x + 2 * y + 3 * z) % 3 == 0):
                acc.setValueOn(ijk, 0.01 * n + k)
                continue
            i, inactive_index = inactive_index, inactive_index + 1
            alt = i % 2 == 0
            value = {
                0: bg, 1: -bg, 2: other,
                3: -bg if alt else bg,
                4: bg if alt else -bg,
                5: other if alt else bg,
                6: bg if alt else other,
                7: other if alt else other2,
                8: other2 if alt else other,
                9: (other, other2, 0.0, 1.0 + 0.001 * i)[i % 4],
                10: 4.0,
                11: bg,
                12: -bg,
            }[k]
            if k == 11:
                acc.setValueOff(ijk, 3.0)  # creates the leaf ...
            acc.setValueOff(ijk, value)    # ... and this puts the background back
    # Inactive tiles with non-background values, and one active tile.
    g.fill((1024, 0, 0), (1031, 7, 7), 5.0, False)      # inactive 8^3 tile, value 5
    g.fill((1280, 0, 0), (1407, 127, 127), -2.0, False)  # inactive 128^3 tile, value -bg
    g.fill((1040, 0, 0), (1047, 7, 7), 9.0, True)       # active 8^3 tile
    return g


def case_inactive_modes(ctx: Ctx) -> None:
    """inactive_modes.vdb (blosc+active mask, background 2.0) and
    inactive_modes_active.vdb (active mask only, via vdb_tool codec=active).

    One leaf per per-node metadata mode 0-6 (several in two orderings, and leaves
    with zero active voxels), plus inactive tiles with non-background values.
    Every voxel of the designed leaves is sampled, so a reader that restores
    inactive values wrongly fails.  The mode bytes actually found in the file are
    checked against the recipe and listed under "mode_leaves".
    """
    g = inactive_modes_grid()
    vdb.write(ctx.path("inactive_modes.vdb"), [g])
    vdb_tool_rewrite(ctx.path("inactive_modes.vdb"), ctx.path("inactive_modes_active.vdb"), "active")
    pts = [[16 * k + (n >> 6), (n >> 3) & 7, n & 7] for k in range(len(MODE_LEAVES))
           for n in range(512)]
    pts += [[1024, 0, 0], [1031, 7, 7], [1032, 0, 0], [1300, 50, 60], [1407, 127, 127],
            [1408, 0, 0], [1040, 0, 0], [1047, 7, 7]]
    for name, codec in (("inactive_modes.vdb", 6), ("inactive_modes_active.vdb", 2)):
        ctx.add(Product(name, extra_samples={"modes": pts}, check=check_modes(codec)))


def half_grids() -> list:
    """A float fog grid and a Vec3S grid flagged saveFloatAsHalf."""
    dens = fog_sphere((20, 20, 20), 14.0, peak=0.9)
    acc = dens.getAccessor()
    acc.setValueOn((20, 20, 20), 0.1)        # not representable in half
    acc.setValueOn((21, 20, 20), 1.0e-5)     # a half subnormal
    acc.setValueOn((22, 20, 20), 70000.0)    # overflows half -> inf
    for i in range(8):                       # a leaf with zero active voxels (mode 2)
        for j in range(8):
            acc.setValueOff((48 + i, j, 0), 0.3)
    dens.fill((64, 0, 0), (71, 7, 7), 0.3)   # an active 8^3 tile (tile values are halved too)
    dens.saveFloatAsHalf = True
    vel = vdb.Vec3SGrid()
    vel.name = "velocity"
    va = vel.getAccessor()
    for i in range(12):
        for j in range(12):
            va.setValueOn((i, j, 2 * i % 8), (0.1 * i, -0.3 * j, 1.0 / (1 + i + j)))
    vel.saveFloatAsHalf = True
    # Tiles at every level of a half grid.  RootNode::writeTopology writes root tile
    # values at full float size (only the background is truncated to half), internal
    # node tile values go through the half writer.
    tiles = vdb.FloatGrid()
    tiles.name = "tiles"
    tiles.fill((4096, 0, 0), (8191, 4095, 4095), 0.1)   # root-level tile
    tiles.fill((0, 0, 0), (127, 127, 127), 0.2)         # 128^3 tile
    tiles.fill((128, 0, 0), (135, 7, 7), 0.3)           # 8^3 tile
    tiles.getAccessor().setValueOn((140, 0, 0), 0.4)    # one leaf voxel
    tiles.saveFloatAsHalf = True
    return [dens, vel, tiles]


def case_half(ctx: Ctx) -> None:
    """half_blosc.vdb (pyopenvdb, blosc+active), half_none.vdb and half_active.vdb
    (vdb_tool codec=none / codec=active with bits=16): float and Vec3S grids saved as
    half floats (type names end in _HalfFloat).

    Exercises: half decoding (values in the manifest are the half-rounded values
    read back), half subnormals and overflow to inf, leaves with zero active voxels
    whose value chunk is absent altogether when the active mask is on, and a grid
    "tiles" with tiles at all three levels (root tile values are stored as full
    floats even in a half grid; compare its samples).
    """
    vdb.write(ctx.path("half_blosc.vdb"), half_grids())
    extra = {"density": [[48 + i, j, 0] for i in range(8) for j in range(8)]
             + [[20, 20, 20], [21, 20, 20], [22, 20, 20], [64, 0, 0]],
             "tiles": [[4096, 0, 0], [5000, 100, 100], [0, 0, 0], [127, 127, 127],
                       [128, 0, 0], [135, 7, 7], [140, 0, 0], [141, 0, 0]]}
    ctx.add(Product("half_blosc.vdb", extra_samples=extra, check=check_half(6)))
    for codec, flags in (("none", 0), ("active", 2)):
        name = f"half_{codec}.vdb"
        vdb_tool_rewrite(ctx.path("half_blosc.vdb"), ctx.path(name), codec, bits=16)
        ctx.add(Product(name, extra_samples=extra, check=check_half(flags)))


def transform_grid() -> vdb.FloatGrid:
    return fog_sphere((14, 14, 14), 12.0)


def case_transforms(ctx: Ctx) -> None:
    """xform_*.vdb: the same small fog sphere under different index-to-world maps.

    uniform: voxel size 0.5 (UniformScaleMap); far: voxel 0.05 translated ~10,000
    units away (UniformScaleTranslateMap); scale: non-uniform scale (ScaleMap);
    scale_translate: ScaleTranslateMap; affine: a rotation (AffineMap); frustum:
    a NonlinearFrustumMap, which cirrus is expected to refuse.
    """
    def write(name, xform, expect_map, extra=None):
        g = transform_grid()
        g.transform = xform
        vdb.write(ctx.path(name), [g])
        ctx.add(Product(name, extra=extra or {}, check=check_map(expect_map)))

    write("xform_uniform.vdb", vdb.createLinearTransform(0.5), "UniformScaleMap")
    t = vdb.createLinearTransform(0.05)
    t.translate((9995.5, 120.25, 1003.0))
    write("xform_far.vdb", t, "UniformScaleTranslateMap")
    t = vdb.createLinearTransform(1.0)
    t.scale((0.5, 1.0, 2.0))
    write("xform_scale.vdb", t, "ScaleMap")
    write("xform_scale_translate.vdb", vdb.createLinearTransform(
        [[0.25, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1.0, 0], [-3.0, 4.5, 100.0, 1]]),
        "ScaleTranslateMap")
    t = vdb.createLinearTransform(0.5)
    t.rotate(0.5, vdb.Axis.Y)
    t.rotate(0.25, vdb.Axis.X)
    t.translate((10.0, -2.0, 3.0))
    write("xform_affine.vdb", t, "AffineMap")
    t = vdb.createFrustumTransform((0, 0, 0), (28, 28, 28), 0.5, 2.0, 0.1)
    write("xform_frustum.vdb", t, "NonlinearFrustumMap",
          extra={"expect_error": "unsupported transform"})


def case_edge_files(ctx: Ctx) -> None:
    """empty_grid.vdb: one float grid without active voxels or nodes.
    no_grids.vdb: a valid file holding zero grids (but one file metadata entry).
    duplicate_names.vdb: two grids both named "density" (stored as "density\\x1e0"
    and "density\\x1e1"); the manifest lists them in file order with "unique_name".
    """
    g = vdb.FloatGrid()
    g.name, g.gridClass = "density", FOG
    vdb.write(ctx.path("empty_grid.vdb"), [g])
    ctx.add(Product("empty_grid.vdb"))

    vdb.write(ctx.path("no_grids.vdb"), [], metadata={"note": "this file has no grids"})
    ctx.add(Product("no_grids.vdb"))

    a = fog_sphere((10, 10, 10), 8.0)
    b = vdb.FloatGrid()
    b.name, b.gridClass = "density", FOG
    b.fill((0, 0, 0), (20, 20, 20), 0.25)
    vdb.write(ctx.path("duplicate_names.vdb"), [a, b])
    ctx.add(Product("duplicate_names.vdb"))


SPECIALS = [float("nan"), float("inf"), float("-inf"), -5.5, 1e30, 1e-40, -0.0,
            3.4028234663852886e38, 1.1754943508222875e-38, -1.401298464324817e-45, 0.0, 1.0]


def case_special_values(ctx: Ctx) -> None:
    """special_values.vdb: active NaN, +inf, -inf, negatives, 1e30, denormals, -0.0,
    FLT_MAX, FLT_MIN and exact 0 (active, equal to the background) in one leaf; an
    inactive NaN in another leaf; an active tile whose value is +inf.

    NaN is set through an accessor (copyFromArray would make it inactive).
    """
    g = vdb.FloatGrid()
    g.name, g.gridClass = "values", UNKNOWN
    acc = g.getAccessor()
    pts = []
    for i, v in enumerate(SPECIALS):
        acc.setValueOn((i, 1, 2), v)
        pts.append([i, 1, 2])
    for i in range(8):
        acc.setValueOn((16 + i, 0, 0), 0.5 * i)
        pts.append([16 + i, 0, 0])
    acc.setValueOff((16, 1, 0), float("nan"))
    acc.setValueOff((17, 1, 0), -1.0)
    acc.setValueOff((18, 1, 0), 3.0)
    pts += [[16, 1, 0], [17, 1, 0], [18, 1, 0], [19, 1, 0]]
    g.fill((32, 0, 0), (39, 7, 7), float("inf"))
    pts += [[32, 0, 0], [39, 7, 7]]
    vdb.write(ctx.path("special_values.vdb"), [g])
    ctx.add(Product("special_values.vdb", extra_samples={"values": pts}))


def as_int32(x: float) -> int:
    return struct.unpack("<i", struct.pack("<f", x))[0]


def int_as_float(i: int) -> float:
    return struct.unpack("<f", struct.pack("<i", i))[0]


def case_other_types(ctx: Ctx) -> None:
    """other_types.vdb: an Int32Grid "ids" (background 7).

    pyopenvdb 10 only binds FloatGrid, BoolGrid and Vec3SGrid, so the int32 grid is
    made by writing a FloatGrid whose float32 bit patterns ARE the wanted int32
    values and renaming its tree type "Tree_float_5_4_3" -> "Tree_int32_5_4_3" in the
    grid descriptor (same length, so no offset moves; both types are 4 bytes).
    Inactive values are only +background or other values, never the float -bg bit
    pattern, so the mode bytes chosen by the float writer stay valid for int32.
    vdb_print reads the result as int32 and its min/max/counts are cross-checked.
    A DoubleGrid cannot be made this way (8-byte values), so there is none.
    """
    g = vdb.FloatGrid(int_as_float(7))
    g.name, g.gridClass = "ids", UNKNOWN
    acc = g.getAccessor()
    pts = []
    for x in range(24):
        for y in range(12):
            for z in range(0, 10, 3):
                acc.setValueOn((x, y, z), int_as_float(x * 1000 + y * 10 + z - 5000))
                pts.append([x, y, z])
    acc.setValueOn((30, 0, 0), int_as_float(2_000_000_000))
    acc.setValueOn((31, 0, 0), int_as_float(-2_000_000_000))
    acc.setValueOn((32, 0, 0), int_as_float(0))
    acc.setValueOff((33, 0, 0), int_as_float(-1))
    acc.setValueOff((34, 0, 0), int_as_float(99))
    pts += [[30 + i, 0, 0] for i in range(6)]
    g.fill((64, 0, 0), (71, 7, 7), int_as_float(123456))
    pts += [[64, 0, 0], [71, 7, 7]]
    float_path = str(ctx.tmp / "other_types_float.vdb")
    vdb.write(float_path, [g])
    data = bytearray(Path(float_path).read_bytes())
    old, new = b"Tree_float_5_4_3", b"Tree_int32_5_4_3"
    if data.count(old) != 1:
        raise RuntimeError("expected exactly one tree type name to patch")
    i = data.index(old)
    data[i:i + len(old)] = new
    Path(ctx.path("other_types.vdb")).write_bytes(bytes(data))
    readback = vdb.read(float_path, "ids")
    ctx.add(Product("other_types.vdb", extra_samples={"ids": pts},
                    substitutes={"ids": Substitute(readback, "int32", as_int32)}))


def case_nanovdb(ctx: Ctx) -> None:
    """sphere_fog{,_fp16,_zip,_blosc}.nvdb and multi_grid.nvdb via nanovdb_convert.

    Exercises: NanoVDB float grids uncompressed, Fp16-quantised, and ZIP/BLOSC
    file codecs; several grids (float, Vec3f, bool) in one file, which
    nanovdb_convert writes as one segment per grid, in name order.
    """
    for name, flags in (("sphere_fog.nvdb", []), ("sphere_fog_fp16.nvdb", ["--fp16"]),
                        ("sphere_fog_zip.nvdb", ["-z"]), ("sphere_fog_blosc.nvdb", ["-b"])):
        run("nanovdb_convert", "-f", *flags, ctx.path("sphere_fog.vdb"), ctx.path(name))
        ctx.add(Product(name, format="nvdb", source="sphere_fog.vdb"))
    run("nanovdb_convert", "-f", ctx.path("multi_grid.vdb"), ctx.path("multi_grid.nvdb"))
    ctx.add(Product("multi_grid.nvdb", format="nvdb", source="multi_grid.vdb"))


CASES = [case_sphere_fog, case_cloud, case_level_set_sphere, case_tile_box, case_leaf_tiles,
         case_multi_grid, case_codecs, case_inactive_modes, case_half, case_transforms,
         case_edge_files, case_special_values, case_other_types, case_nanovdb]


# --------------------------------------------------------------------------- checks

class CorpusError(RuntimeError):
    pass


def require(cond: bool, msg: str) -> None:
    if not cond:
        raise CorpusError(msg)


def check_tiles(expected, leaves):
    def check(entry, vf):
        g = entry["grids"][0]
        require(g["active_tile_count"] == expected, f"{entry['file']}: tiles {g['active_tile_count']}")
        require(g["leaf_count"] == leaves, f"{entry['file']}: leaves {g['leaf_count']}")
    return check


def check_tiles_everywhere(entry, vf):
    tiles = entry["grids"][0]["active_tile_count"]
    require(all(t > 0 for t in tiles), f"{entry['file']}: expected tiles at all levels, got {tiles}")


def check_compression(flags):
    def check(entry, vf):
        for g in entry["grids"]:
            require(g["compression"] == flags, f"{entry['file']}: compression {g['compression']}")
    return check


def check_modes(flags):
    def check(entry, vf):
        check_compression(flags)(entry, vf)
        tree = next(g for g in vf.grids if g.name == "modes").tree
        found = dict(zip(tree.leaf_origins, tree.leaf_modes))
        for k, (mode, doc) in enumerate(MODE_LEAVES):
            got = found.get((16 * k, 0, 0))
            require(got == mode, f"{entry['file']}: leaf {k} ({doc}) has mode {got}")
        require(sorted(set(tree.leaf_modes)) == list(range(7)), "not all seven modes present")
    return check


def check_half(flags):
    def check(entry, vf):
        check_compression(flags)(entry, vf)
        for rec, g in zip(vf.grids, entry["grids"]):
            require(rec.type_name.endswith("_HalfFloat") and g["half_float"],
                    f"{entry['file']}: {rec.type_name} not half")
        if flags & vdbfile.COMPRESS_ACTIVE_MASK:
            density = next(g for g in vf.grids if g.name == "density")
            require(density.tree.leaf_active.count(0) > 0, "no zero-count leaf chunk")
    return check


def check_map(name):
    def check(entry, vf):
        for g in entry["grids"]:
            require(g["transform"] == name, f"{entry['file']}: map {g['transform']} != {name}")
    return check


# --------------------------------------------------------------------------- description

def jnum(x):
    """JSON-safe number: NaN/inf become strings, numpy scalars become Python numbers."""
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def jval(v):
    if isinstance(v, (tuple, list)):
        return [jval(c) for c in v]
    return jnum(v)


def same(a, b) -> bool:
    return json.dumps(jval(a)) == json.dumps(jval(b))


def jmeta(value):
    """File metadata value -> JSON, or None when JSON cannot express it."""
    if isinstance(value, (str, bool, int, float)):
        return jnum(value) if not isinstance(value, str) else value
    if isinstance(value, (tuple, list)) and all(isinstance(c, (int, float)) for c in value):
        return [jnum(c) for c in value]
    return None


class GridView:
    """Uniform access to a read-back grid (or a Substitute for a type pyopenvdb lacks)."""

    def __init__(self, grid, sub: Substitute | None = None):
        self.grid = grid if sub is None else sub.grid
        self.convert = (lambda v: v) if sub is None else sub.convert
        self.value_type = grid.valueTypeName if sub is None else sub.value_type

    def value(self, v):
        return self.convert(v)


def sample_points(view: GridView, rng, bbox, extra) -> tuple[list, list]:
    """Pick sample coordinates; also count active tiles per level.

    Returns (coords, [tiles at 8^3, 128^3, 4096^3]).
    """
    g = view.grid
    bg = g.background
    n_leaf_on = g.activeLeafVoxelCount()
    chosen = set(rng.choice(n_leaf_on, min(ACTIVE_SAMPLES, n_leaf_on), replace=False).tolist()) \
        if n_leaf_on else set()
    active, tiles, tile_counts = [], [], [0, 0, 0]
    i = 0
    for it in g.citerOnValues():
        if it["depth"] == 3:
            if i in chosen:
                active.append(list(it["min"]))
            i += 1
        else:
            tile_counts[2 - it["depth"]] += 1
            tiles.append((it["min"], it["max"]))
    # Reservoir samples of inactive voxels inside leaves; inactive tiles that are
    # not background are all interesting.
    reservoir, seen, odd_tiles = [], 0, []
    for it in g.citerOffValues():
        if it["depth"] == 3:
            if len(reservoir) < INACTIVE_SAMPLES:
                reservoir.append(list(it["min"]))
            else:
                j = int(rng.integers(seen + 1))
                if j < INACTIVE_SAMPLES:
                    reservoir[j] = list(it["min"])
            seen += 1
        elif not same(it["value"], bg) and len(odd_tiles) < 1000:
            odd_tiles.append((it["min"], it["max"]))
    tile_pts = []
    for group in (tiles, odd_tiles):
        picks = rng.choice(len(group), min(TILE_SAMPLES, len(group)), replace=False) if group else []
        for p in sorted(int(p) for p in picks):
            lo, hi = group[p]
            tile_pts.append(list(lo))
            tile_pts.append([int(rng.integers(a, b + 1)) for a, b in zip(lo, hi)])
            tile_pts.append(list(hi))
    outside = [[-1, -1, -1], [-100000, 3, 7], [1 << 20, 0, 0], [0, -(1 << 20), 5],
               [-(1 << 31), 0, 0], [(1 << 31) - 1, (1 << 31) - 1, (1 << 31) - 1],
               [-4096, -4096, -4096], [4095, 4095, 4095]]
    if bbox:
        lo, hi = bbox
        outside += [[c + 1 for c in hi], [c - 1 for c in lo], [hi[0] + 200, lo[1], lo[2]],
                    [lo[0], hi[1] + 4096, lo[2]]]
    coords, keys = [], set()
    for p in active + reservoir + tile_pts + outside + [list(map(int, q)) for q in extra]:
        t = tuple(p)
        if t not in keys:
            keys.add(t)
            coords.append(p)
    return coords, tile_counts


def index_to_world(xform, bbox) -> list:
    pts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 2, 3), (0.5, -1.25, 2.75),
           (-7, 100, 1000)]
    if bbox:
        pts += [tuple(bbox[0]), tuple(bbox[1])]
    return [{"ijk": list(p), "world": [float(c) for c in xform.indexToWorld(p)]} for p in pts]


def describe_grid(view: GridView, rec: vdbfile.GridRecord | None, rng, extra) -> dict:
    g = view.grid
    lo, hi = g.evalActiveVoxelBoundingBox()
    empty = g.activeVoxelCount() == 0
    bbox = None if empty else [list(lo), list(hi)]
    coords, tile_counts = sample_points(view, rng, bbox, extra)
    acc = g.getConstAccessor()
    samples = [{"ijk": p, "value": jval(view.value(acc.getValue(tuple(p)))),
                "active": bool(acc.isValueOn(tuple(p)))} for p in coords]
    if empty:
        vmin = vmax = None
    elif view.value_type == "int32":
        vals = [view.value(it["value"]) for it in g.citerOnValues()]
        vmin, vmax = min(vals), max(vals)
    else:
        vmin, vmax = g.evalMinMax()
    d = {"name": g.name}
    if rec is not None and rec.unique_name != rec.name:
        d["unique_name"] = rec.unique_name
    d.update({
        "value_type": view.value_type,
        "class": g.gridClass,
        "half_float": bool(rec.half_float) if rec else bool(g.saveFloatAsHalf),
    })
    if rec is not None:
        d["compression"] = rec.compression
    d.update({
        "background": jval(view.value(g.background)),
        "active_voxels": int(g.activeVoxelCount()),
        "leaf_count": int(g.leafCount()),
        "active_tile_count": tile_counts,
        "index_bbox": bbox,
        "voxel_size": [float(c) for c in g.transform.voxelSize()],
        "transform": g.transform.typeName,
        "index_to_world": index_to_world(g.transform, bbox),
        "min": None if vmin is None else jval(vmin),
        "max": None if vmax is None else jval(vmax),
    })
    if g.valueTypeName == "vec3s":
        d["vector_type"] = g.vectorType
        if not empty:
            # evalMinMax orders vectors lexicographically; also give per-component
            # extremes over all active values (voxels and tiles), NaN excluded.
            vals = np.array([it["value"] for it in g.citerOnValues()], dtype=np.float64)
            d["min_components"] = jval(np.nanmin(vals, axis=0).tolist())
            d["max_components"] = jval(np.nanmax(vals, axis=0).tolist())
    if rec is not None and rec.tree is not None:
        t = rec.tree
        d["layout"] = {
            "leaf_modes": [t.leaf_modes.count(m) for m in range(7)],
            "internal_modes": [t.internal_modes.count(m) for m in range(7)],
            "zero_count_chunks": t.zero_count_chunks,
        }
    d["samples"] = samples
    return d


def compression_from_string(text: str) -> int:
    """Invert io::compressionToString ("blosc + active values" -> 6, "none" -> 0)."""
    bits = {"zip": 0x1, "active values": 0x2, "blosc": 0x4, "none": 0}
    return sum(bits[part.strip()] for part in text.split("+"))


def grid_request_name(rec: vdbfile.GridRecord) -> str:
    """Name pyopenvdb.read accepts for this descriptor ("density[1]" for "density\\x1e1")."""
    if "\x1e" in rec.unique_name:
        base, _, n = rec.unique_name.partition("\x1e")
        return f"{base}[{n}]"
    return rec.unique_name


def describe_vdb(prod: Product, path: str) -> tuple[dict, vdbfile.VdbFile]:
    vf = vdbfile.read_vdb(path)
    entry = {"file": prod.file, "format": "vdb", "file_version": vf.file_version}
    entry.update(prod.extra)
    meta = vdb.readMetadata(path)
    entry["file_metadata"] = {k: jmeta(v) for k, v in sorted(meta.items()) if jmeta(v) is not None}
    entry["file_metadata_types"] = {name: type_name for name, type_name, _ in vf.metadata}
    entry["library_version"] = list(vf.library_version)
    grids = []
    for idx, rec in enumerate(vf.grids):
        sub = prod.substitutes.get(rec.unique_name)
        if sub is None:
            grid = vdb.read(path, grid_request_name(rec))
            require(grid.name == rec.name, f"{path}: read {grid.name!r} for {rec.unique_name!r}")
            require(grid.valueTypeName == rec.value_type,
                    f"{path}: {grid.valueTypeName} vs {rec.type_name}")
            view = GridView(grid)
        else:
            view = GridView(None, sub)
            require(rec.value_type == sub.value_type, f"{path}: {rec.type_name}")
        require(rec.map_type == view.grid.transform.typeName,
                f"{path}: stored map {rec.map_type} vs {view.grid.transform.typeName}")
        stored = dict((n, v) for n, _, v in rec.metadata).get("file_compression")
        require(stored is None or compression_from_string(stored) == rec.compression,
                f"{path}: file_compression {stored!r} vs flags {rec.compression}")
        rng = rng_for(prod.file, idx)
        d = describe_grid(view, rec, rng, prod.extra_samples.get(rec.unique_name, []))
        if rec.tree is not None:
            require(len(rec.tree.leaf_origins) == d["leaf_count"],
                    f"{path}:{rec.name}: walker leaves {len(rec.tree.leaf_origins)}")
            require(rec.tree.active_tiles == d["active_tile_count"],
                    f"{path}:{rec.name}: walker tiles {rec.tree.active_tiles}")
        if rec.tree is not None and prod.file.startswith("inactive_modes"):
            d["mode_leaves"] = [{"origin": list(o), "mode": m, "active": a} for o, m, a in
                                zip(rec.tree.leaf_origins, rec.tree.leaf_modes,
                                    rec.tree.leaf_active)]
        grids.append(d)
    entry["grids"] = grids
    return entry, vf


# --------------------------------------------------------------------------- vdb_print

def parse_vdb_print(text: str) -> list[dict]:
    """Per-grid facts from `vdb_print -l` (grids appear in name order)."""
    out = []
    for block in re.split(r"^Name: ", text, flags=re.M)[1:]:
        name = block.split("\n", 1)[0]
        info = {"name": name}
        m = re.search(r"Type: (\S+)", block)
        info["type"] = m.group(1) if m else None
        m = re.search(r"Leaf\(([\d,]+) x 8\^3\)", block)
        info["leaves"] = int(m.group(1).replace(",", "")) if m else 0
        m = re.search(r"Number of active voxels:\s+([\d,]+)", block)
        info["voxels"] = int(m.group(1).replace(",", "")) if m else 0
        m = re.search(r"Number of active tiles:\s+([\d,]+)", block)
        info["tiles"] = int(m.group(1).replace(",", "")) if m else 0
        m = re.search(r"Bounding box of active voxels: \[(-?\d+), (-?\d+), (-?\d+)\] -> "
                      r"\[(-?\d+), (-?\d+), (-?\d+)\]", block)
        info["bbox"] = [list(map(int, m.groups()[:3])), list(map(int, m.groups()[3:]))] if m else None
        for key in ("Min", "Max"):
            m = re.search(rf"{key} value: (\S+)", block)
            info[key.lower()] = m.group(1) if m else None
        out.append(info)
    return out


def cross_check_vdb_print(entry: dict, path: str) -> None:
    """Assert that vdb_print -l agrees with the manifest for every grid of a .vdb file."""
    printed = parse_vdb_print(run("vdb_print", "-l", path))
    require(len(printed) == len(entry["grids"]),
            f"{path}: vdb_print lists {len(printed)} grids, manifest {len(entry['grids'])}")

    def key(d):
        return (d["name"], d["voxels"], d["leaves"], d["tiles"], json.dumps(d["bbox"]))

    mine = sorted(key({"name": g["name"], "voxels": g["active_voxels"], "leaves": g["leaf_count"],
                       "tiles": sum(g["active_tile_count"]), "bbox": g["index_bbox"]})
                  for g in entry["grids"])
    theirs = sorted(key(p) for p in printed)
    require(mine == theirs, f"{path}: vdb_print disagrees:\n  manifest {mine}\n  vdb_print {theirs}")
    # Min/max: vdb_print prints 6 significant digits; compare finite scalars only.
    by_name = {}
    for p in printed:
        by_name.setdefault(p["name"], []).append(p)
    for g in entry["grids"]:
        if g["value_type"] not in ("float", "int32") or g["min"] is None:
            continue
        for p in by_name[g["name"]]:
            if p["voxels"] != g["active_voxels"]:
                continue
            for k in ("min", "max"):
                try:
                    theirs_v = float(p[k])
                except (TypeError, ValueError):
                    continue
                mine_v = g[k]
                if isinstance(mine_v, str) or not math.isfinite(theirs_v):
                    continue
                require(abs(theirs_v - mine_v) <= 1e-5 * max(1.0, abs(mine_v)),
                        f"{path}:{g['name']}: vdb_print {k} {p[k]} vs {mine_v}")


# --------------------------------------------------------------------------- NanoVDB

def parse_nanovdb_print(text: str) -> list[dict]:
    """Rows of the fixed-width table printed by `nanovdb_print -l`, keyed by header."""
    lines = [l for l in text.splitlines() if l.strip()]
    hi = next(i for i, l in enumerate(lines) if l.startswith("#  Name"))
    header = lines[hi]
    cols = [m.start() for m in re.finditer(r"(?:(?<=  )|^)\S", header)]
    names = [header[a:b].strip() for a, b in zip(cols, cols[1:] + [None])]
    rows = []
    for line in lines[hi + 1:]:
        if not re.match(r"^\d+\s", line):
            continue
        rows.append({n: line[a:b].strip() for n, a, b in zip(names, cols, cols[1:] + [None])})
    return rows


def _bbox(text: str):
    nums = list(map(int, re.findall(r"-?\d+", text)))
    return [nums[:3], nums[3:]]


QUANTISED_NVDB_TYPES = {"Fp4", "Fp8", "Fp16", "FpN", "Float4", "Float8", "Float16", "FloatN"}


def verify_nvdb_values(path: str, tmp: Path, entry: dict) -> None:
    """Convert the .nvdb back to .vdb with nanovdb_convert and check every sample.

    This proves that the NanoVDB file holds the manifest's values (exactly, or
    within value_tolerance for quantised grids) and activity states.
    """
    back = str(tmp / (Path(path).stem + "_roundtrip.vdb"))
    run("nanovdb_convert", "-f", path, back)
    for g in entry["grids"]:
        acc = vdb.read(back, g["name"]).getConstAccessor()
        tol = g["value_tolerance"]
        for s in g["samples"]:
            ijk = tuple(s["ijk"])
            got, want = jval(acc.getValue(ijk)), s["value"]
            require(bool(acc.isValueOn(ijk)) == s["active"], f"{path}:{g['name']} {ijk} activity")
            if got == want or same(got, want):
                continue
            require(tol > 0 and isinstance(got, float) and isinstance(want, float)
                    and abs(got - want) <= tol,
                    f"{path}:{g['name']} {ijk}: nvdb {got} vs vdb {want} (tolerance {tol})")


def describe_nvdb(prod: Product, path: str, manifest_by_file: dict, tmp: Path) -> dict:
    rows = parse_nanovdb_print(run("nanovdb_print", "-l", path))
    validate = run("nanovdb_validate", "-v", path)
    segments = vdbfile.read_nvdb_segments(path)
    source = manifest_by_file[prod.source]
    src_path = str(Path(path).parent / prod.source)
    seg_names = [n for s in segments for n in s.grid_names]
    require([r["Name"] for r in rows] == seg_names, f"{path}: print order {rows} vs {seg_names}")
    entry = {"file": prod.file, "format": "nvdb", "source": prod.source,
             "segments": [{"magic": s.magic.decode("ascii", "replace"),
                           "version": ".".join(map(str, s.version)), "codec": s.codec,
                           "grids": s.grid_names} for s in segments],
             "grids": []}
    for row in rows:
        name = row["Name"]
        require(re.search(rf'Grid named "{re.escape(name)}": passed', validate) is not None,
                f"{path}: nanovdb_validate did not pass {name}:\n{validate}")
        src = [g for g in source["grids"] if g["name"] == name]
        require(len(src) == 1, f"{path}: no unique source grid {name}")
        src = src[0]
        upper, lower, leaves = map(int, row["32^3->16^3->8^3"].split("->"))
        root_t, upper_t, lower_t = map(int, row["# Active tiles"].split("->"))
        d = {
            "name": name,
            "value_type": src["value_type"],
            "nvdb_grid_type": row["Type"],
            "class": src["class"],
            "codec": row["Codec"],
            "background": src["background"],
            "active_voxels": int(row["# Voxels"]),
            "leaf_count": leaves,
            "node_count": [leaves, lower, upper],
            "active_tile_count": [lower_t, upper_t, root_t],
            "index_bbox": _bbox(row["Index Bounding Box"]),
            "world_bbox_printed": row["World Bounding Box"],
            "voxel_size": src["voxel_size"],
            "source_transform": src["transform"],  # NanoVDB stores a matrix, not a map type
            "index_to_world": src["index_to_world"],
            "min": src["min"], "max": src["max"],
        }
        for k in ("min_components", "max_components"):
            if k in src:
                d[k] = src[k]
        for k in ("active_voxels", "leaf_count", "active_tile_count", "index_bbox"):
            require(d[k] == src[k], f"{path}:{name}: {k} {d[k]} (nanovdb_print) vs {src[k]} (vdb)")
        if row["Type"] in QUANTISED_NVDB_TYPES:
            grid = vdb.read(src_path, name)
            lo = hi = None
            for it in grid.citerAllValues():
                if it["depth"] == 3:
                    v = it["value"]
                    lo = v if lo is None else min(lo, v)
                    hi = v if hi is None else max(hi, v)
            ulp = float(np.spacing(np.float32(max(abs(lo), abs(hi)))))
            d["value_tolerance"] = (hi - lo) / 65535.0 + 4.0 * ulp
        else:
            d["value_tolerance"] = 0.0
        d["samples"] = src["samples"]
        entry["grids"].append(d)
    verify_nvdb_values(path, tmp, entry)
    return entry


# --------------------------------------------------------------------------- output

def dump_json(obj, indent: int = 0, width: int = 110) -> str:
    """Pretty JSON that keeps small objects/arrays (e.g. each sample) on one line."""
    flat = json.dumps(obj, separators=(", ", ": "))
    if len(flat) + indent <= width or not isinstance(obj, (dict, list)) or not obj:
        return flat
    pad, inner = " " * indent, " " * (indent + 2)
    if isinstance(obj, dict):
        items = [f"{inner}{json.dumps(k)}: {dump_json(v, indent + 2, width).lstrip()}"
                 for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    items = [inner + dump_json(v, indent + 2, width).lstrip() for v in obj]
    return "[\n" + ",\n".join(items) + "\n" + pad + "]"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outdir")
    args = ap.parse_args()
    t0 = time.time()
    out = Path(args.outdir)
    out.mkdir(parents=True, exist_ok=True)
    old = out / "manifest.json"
    if old.exists():  # remove what a previous run generated, nothing else
        for f in json.loads(old.read_text()).get("files", []):
            (out / f["file"]).unlink(missing_ok=True)
        old.unlink()
    vdb.setLoggingLevel("error")  # silence "more than one grid named" warnings

    with tempfile.TemporaryDirectory(prefix="cirrus_corpus_") as tmp:
        ctx = Ctx(out, Path(tmp))
        for case in CASES:
            t = time.time()
            case(ctx)
            print(f"  {case.__name__:<24} {time.time() - t:6.2f} s", flush=True)

        files, by_file = [], {}
        for prod in ctx.products:
            path = ctx.path(prod.file)
            if prod.format == "vdb":
                entry, vf = describe_vdb(prod, path)
                cross_check_vdb_print(entry, path)
                if prod.check:
                    prod.check(entry, vf)
            else:
                entry = describe_nvdb(prod, path, by_file, ctx.tmp)
            by_file[prod.file] = entry
            files.append(entry)

    manifest = {
        "generator": "tools/make_corpus.py",
        "openvdb_version": ".".join(map(str, vdb.LIBRARY_VERSION)),
        "file_format_version": vdb.FILE_FORMAT_VERSION,
        "seed": SEED,
        "files": files,
    }
    (out / "manifest.json").write_text(dump_json(manifest) + "\n")

    total = 0
    for f in files + [{"file": "manifest.json"}]:
        size = (out / f["file"]).stat().st_size
        total += size
        print(f"  {size:>10,}  {f['file']}")
    print(f"  {total:>10,}  total, {len(files)} corpus files, {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

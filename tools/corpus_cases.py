"""The cases of tools/make_corpus.py: each writes one or more corpus files.

Every case_* function builds grids with pyopenvdb (or rewrites them with
vdb_tool / nanovdb_convert), writes them into the output directory and
records each file as a Product (corpus_plumbing.py), optionally with a check
that make_corpus.py runs on the file's manifest entry and vdbfile walk.  The
checks are here, beside the cases that attach them, because they test what a
case meant to produce (e.g. the mode byte of each MODE_LEAVES leaf).
CASES lists the cases in the order make_corpus.py runs them.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np
import pyopenvdb as vdb

import procedural
import vdbfile
from corpus_plumbing import SEED, Ctx, Product, Substitute, require, run, vdb_tool_rewrite

FOG, UNKNOWN = vdb.GridClass.FOG_VOLUME, vdb.GridClass.UNKNOWN


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

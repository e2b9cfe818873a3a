#!/usr/bin/python3
"""Write a large cumulus fog volume for benchmarks (not committed).

Usage:

    /usr/bin/python3 tools/make_large.py OUT.vdb [--scale 1.0] [--seed 7] [--jobs N]
                                         [--stride S] [--tmp DIR]

The cloud is the procedural cumulus of data/cloud.vdb (tools/procedural.py: the
same spheres, the same billowy and fine noise, the same flat base and soft edge)
on a box of about (768 x 384 x 576) * scale voxels: 22.2 million active voxels
at scale 1 (3 s on 2 cores), 0.35e9 at 2.5 (22 s), 1.04e9 at 3.6 (51 s), 4.12e9
at 5.7 (3 min, 10.9 GB).  Grid "density",
class fog volume, voxel size 1, blosc + active mask, as pyopenvdb writes it.

How it is fast.  The noise, the sphere distances and the base cut are smooth at
the scale of the finest noise octave (about h/48 voxels, h the box height), so
they are evaluated on a lattice `stride` voxels apart (the largest power of two
at most h/96, 8 at most: 4 at scale 1, where the active voxel count stays within
0.05% of the exact evaluation's; 1 below scale 0.5) and interpolated
trilinearly; the edge ramp, the height falloff and the cut-off at 1e-3 are
evaluated at every voxel.  The box is cut into 128^3 blocks (OpenVDB's
lower internal nodes); blocks no sphere can reach are skipped, the others are
computed in parallel processes, each written by Debian's OpenVDB (pyopenvdb
copyFromArray, then write) to its own small file.  The merge splices those files
into one grid without decoding anything: every lower node's topology record and
leaf buffers are OpenVDB's own bytes, copied; the root, the upper internal nodes
(masks only: a cloud has no upper-level tiles) and the grid metadata
(file_bbox_min/max, file_voxel_count, file_mem_bytes; the per-leaf
file_delayed_load record is left out, as older OpenVDB files do) are written
here.  Memory stays under 200 MB whatever the scale; vdb_print -l reads the
result, and its counts, box and memory equal the metadata written.
Deterministic for a given seed, scale and stride (but for the header's UUID).
"""

from __future__ import annotations

import argparse
import os
import shutil
import struct
import sys
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np

sys.dont_write_bytecode = True  # keep tools/ free of __pycache__
sys.path.insert(0, str(Path(__file__).resolve().parent))
import procedural  # noqa: E402
import vdbfile  # noqa: E402

BASE_SIZE = (768, 384, 576)
BLOCK = 128  # voxels per side of a lower internal node
UPPER = 4096  # voxels per side of an upper internal node
COMPRESS_ZIP, COMPRESS_ACTIVE_MASK, COMPRESS_BLOSC = 0x1, 0x2, 0x4


def box_size(scale: float) -> tuple[int, int, int]:
    return tuple(max(16, int(round(n * scale / 8)) * 8) for n in BASE_SIZE)


def default_stride(size) -> int:
    """The largest power of two at most h/96 (h the box height), 8 at most."""
    h = size[1]
    s = 1
    while s * 2 <= min(8, h / 96):
        s *= 2
    return s


# ---------------------------------------------------------------- the cloud

def candidate_blocks(size, seed):
    """Origins of the 128^3 blocks some sphere's reach (procedural.py) touches."""
    h = float(size[1])
    pad = 0.25 * h + 0.06 * h
    blobs = procedural.cumulus_blobs(size, seed)
    out = []
    for x0 in range(0, size[0], BLOCK):
        for y0 in range(0, size[1], BLOCK):
            for z0 in range(0, size[2], BLOCK):
                lo, hi = (x0, y0, z0), (x0 + BLOCK - 1, y0 + BLOCK - 1, z0 + BLOCK - 1)
                for b in blobs:
                    reach = b.radius + pad
                    if all(lo[a] <= b.centre[a] + reach and hi[a] >= b.centre[a] - reach
                           for a in range(3)):
                        out.append((x0, y0, z0))
                        break
    return out


def upsample(a: np.ndarray, stride: int) -> np.ndarray:
    """Trilinear interpolation of a lattice `stride` apart to every voxel of a block."""
    if stride == 1:
        return a[:BLOCK, :BLOCK, :BLOCK]
    t = np.arange(BLOCK, dtype=np.float32) / stride
    i0 = t.astype(np.int64)
    w = (t - i0).astype(np.float32)
    for axis in range(3):
        shape = [1, 1, 1]
        shape[axis] = BLOCK
        wa = w.reshape(shape)
        a = np.take(a, i0, axis=axis) * (1 - wa) + np.take(a, i0 + 1, axis=axis) * wa
    return a.astype(np.float32)


def block_density(size, seed, stride, origin):
    """Density of one 128^3 block (zero outside the box), or None when empty."""
    h = float(size[1])
    n = BLOCK // stride + 1
    x0, y0, z0 = origin
    cx, cy, cz = (np.float32(o) + stride * np.arange(n, dtype=np.float32) for o in origin)
    # Coarse shape: smooth union of the spheres, each within its reach (procedural.py).
    sdf = np.full((n, n, n), 1e9, dtype=np.float32)
    k = 0.06 * h
    pad = 0.25 * h + k
    for b in procedural.cumulus_blobs(size, seed):
        px, py, pz = b.centre
        reach = b.radius + pad
        ix = np.nonzero(np.abs(cx - px) <= reach)[0]
        iy = np.nonzero(np.abs(cy - py) <= reach)[0]
        iz = np.nonzero(np.abs(cz - pz) <= reach)[0]
        if not (len(ix) and len(iy) and len(iz)):
            continue
        sub = (slice(ix[0], ix[-1] + 1), slice(iy[0], iy[-1] + 1), slice(iz[0], iz[-1] + 1))
        dx = (cx[sub[0]] - px)[:, None, None]
        dy = (cy[sub[1]] - py)[None, :, None]
        dz = (cz[sub[2]] - pz)[None, None, :]
        d = np.sqrt(dx * dx + dy * dy + dz * dz, dtype=np.float32) - np.float32(b.radius)
        sdf[sub] = procedural._smooth_min(d, sdf[sub], k)
    if sdf.min() > 0.16 * h + 2 * stride:
        return None  # the noise cannot bring the surface here
    noise = procedural.GradientNoise(seed + 1)
    # The displaced surface and the interior variation, as _cumulus_shade.
    billow = noise.fbm(cx, cy, cz, freq=3.0 / h, octaves=5, gain=0.5, billow=True)
    sdf = sdf - np.float32(0.16 * h) * (billow - np.float32(0.25))
    sdf += np.float32(0.025 * h) * noise.fbm(cx, cy, cz, freq=12.0 / h, octaves=3, gain=0.5)
    wave = noise.block(cx, np.zeros(1, np.float32), cz, 4.0 / h, octave=9)
    base_y = np.float32(0.17 * h) + np.float32(0.01 * h) * wave
    below = (base_y - cy[None, :, None]).astype(np.float32)
    sdf = -procedural._smooth_min(-sdf, -below, 0.02 * h)
    if sdf.min() >= 0:
        return None  # outside everywhere: interpolation cannot go below the lattice
    inner = noise.fbm(cx, cy, cz, freq=6.0 / h, octaves=4, gain=0.55)
    sdf, inner = upsample(sdf, stride), upsample(inner, stride)
    edge = np.float32(0.045 * h)
    t = np.clip(-sdf / edge, 0.0, 1.0)
    density = t * t * (3.0 - 2.0 * t)
    ys = np.float32(y0) + np.arange(BLOCK, dtype=np.float32)
    height = np.clip((ys[None, :, None] - 0.15 * h) / (0.25 * h), 0.0, 1.0)
    density *= (0.72 + 0.2 * inner) * (0.75 + 0.25 * height)
    density = np.clip(density, 0.0, 1.0).astype(np.float32)
    density[density < 1e-3] = 0.0
    # The box ends inside the last blocks.
    density[max(0, size[0] - x0):, :, :] = 0.0
    density[:, max(0, size[1] - y0):, :] = 0.0
    density[:, :, max(0, size[2] - z0):] = 0.0
    return density if density.any() else None


# ---------------------------------------------------------------- one block file

def skip_values(r: vdbfile.Reader, compression: int, num: int, active: int) -> None:
    """Skip one writeCompressedValues record of float values (io/Compression.h)."""
    mode = r.unpack("<b")
    mask = bool(compression & COMPRESS_ACTIVE_MASK)
    if mask:
        if mode in (2, 4, 5):
            r.take(4)
        if mode == 5:
            r.take(4)
        if mode in (3, 4, 5):
            r.take(num // 8)
    count = active if (mask and mode != 6) else num
    if compression & (COMPRESS_BLOSC | COMPRESS_ZIP):
        r.take(abs(r.unpack("<q")))
    else:
        r.take(4 * count)


def popcount(b: bytes) -> int:
    return int(np.unpackbits(np.frombuffer(b, np.uint8)).sum())


def parse_block(path: str) -> dict:
    """Where the parts of a one-block file written by pyopenvdb lie."""
    data = open(path, "rb").read()
    r = vdbfile.Reader(data)
    r.take(8 + 4 + 8 + 1 + 36)
    vdbfile.read_metamap(r)
    assert r.unpack("<I") == 1
    r.string(), r.string(), r.string()
    gpos, bpos, epos = r.unpack("<3q")
    r.pos = gpos
    compression = r.unpack("<I")
    meta_start = r.pos
    meta = vdbfile.read_metamap(r)
    meta_end = r.pos
    map_name = r.string()
    r.take(vdbfile.MAP_BYTES[map_name])
    transform = data[meta_end:r.pos]
    assert r.unpack("<i") == 1  # buffer count
    background = r.take(4)
    tiles, children = r.unpack("<II")
    assert tiles == 0 and children == 1, (path, tiles, children)
    upper_origin = r.unpack("<3i")
    child_mask = r.take(4096)
    value_mask = r.take(4096)
    assert popcount(child_mask) == 1 and popcount(value_mask) == 0, path
    v0 = r.pos
    skip_values(r, compression, 32768, 0)
    upper_values = data[v0:r.pos]
    lower_start = r.pos
    lchild, lvalue = r.take(512), r.take(512)
    skip_values(r, compression, 4096, popcount(lvalue))
    leaves = popcount(lchild)
    r.take(64 * leaves)
    assert r.pos == bpos, (path, r.pos, bpos)
    slot = int(np.nonzero(np.unpackbits(np.frombuffer(child_mask, np.uint8),
                                         bitorder="little"))[0][0])
    values = {name: value for name, _, value in meta}
    return dict(path=path, compression=compression, header=data[:gpos - 0],
                meta_raw=data[meta_start:meta_end], meta=meta, transform=transform,
                background=background, upper=tuple(upper_origin), slot=slot,
                upper_values=upper_values, lower=(lower_start, bpos), buffers=(bpos, epos),
                leaves=leaves, lower_tiles=popcount(lvalue),
                voxels=values["file_voxel_count"], mem=values["file_mem_bytes"],
                bbox=(values["file_bbox_min"], values["file_bbox_max"]))


def make_block(args):
    size, seed, stride, origin, tmp = args
    import pyopenvdb as vdb
    density = block_density(size, seed, stride, origin)
    if density is None:
        return None
    grid = vdb.FloatGrid()
    grid.name, grid.gridClass = "density", vdb.GridClass.FOG_VOLUME
    grid.copyFromArray(density, ijk=origin)
    path = os.path.join(tmp, "b_{}_{}_{}.vdb".format(*origin))
    vdb.write(path, [grid])
    b = parse_block(path)
    for key in ("header", "meta_raw", "meta"):  # the merge reads these from one block
        del b[key]
    return b


# ---------------------------------------------------------------- the merge

def node_sizes():
    """OpenVDB's memUsage of a tree: base + per upper, lower and leaf node."""
    import pyopenvdb as vdb

    def mem(coords):
        g = vdb.FloatGrid()
        acc = g.getAccessor()
        for c in coords:
            acc.setValueOn(c, 1.0)
        return g.memUsage()
    m1, m2 = mem([(0, 0, 0)]), mem([(0, 0, 0), (UPPER + 8, 0, 0)])
    m3, m4 = mem([(0, 0, 0), (BLOCK + 8, 0, 0)]), mem([(0, 0, 0), (8, 0, 0)])
    leaf, lower, upper = m4 - m1, m3 - m4, m2 - m3
    return m1 - upper - lower - leaf, upper, lower, leaf


def meta_entry(name: str, type_name: str, raw: bytes) -> bytes:
    enc = lambda s: struct.pack("<I", len(s)) + s  # noqa: E731
    return enc(name.encode()) + enc(type_name.encode()) + enc(raw)


def merge(blocks: list[dict], out: str) -> dict:
    first = parse_block(blocks[0]["path"])
    uppers: dict[tuple, list[dict]] = {}
    for b in blocks:
        assert b["upper_values"] == first["upper_values"], "upper node records differ"
        assert b["transform"] == first["transform"] and b["compression"] == first["compression"]
        uppers.setdefault(b["upper"], []).append(b)
    order = sorted(uppers)  # RootNode's std::map: x, then y, then z
    for u in order:
        uppers[u].sort(key=lambda b: b["slot"])  # x-major slots
    base, upper_mem, lower_mem, leaf_mem = node_sizes()
    leaves = sum(b["leaves"] for b in blocks)
    voxels = sum(b["voxels"] for b in blocks)
    lo = [min(b["bbox"][0][a] for b in blocks) for a in range(3)]
    hi = [max(b["bbox"][1][a] for b in blocks) for a in range(3)]
    mem = base + upper_mem * len(order) + lower_mem * len(blocks) + leaf_mem * leaves
    patched = {
        "file_bbox_min": ("vec3i", struct.pack("<3i", *lo)),
        "file_bbox_max": ("vec3i", struct.pack("<3i", *hi)),
        "file_voxel_count": ("int64", struct.pack("<q", voxels)),
        "file_mem_bytes": ("int64", struct.pack("<q", mem)),
    }
    r = vdbfile.Reader(first["meta_raw"])
    entries = []
    for _ in range(r.unpack("<I")):
        name, type_name = r.string(), r.string()
        raw = r.take(r.unpack("<I"))
        if name == "file_delayed_load":
            continue
        if name in patched:
            type_name, raw = patched[name]
        entries.append(meta_entry(name, type_name, raw))
    # The file header, file metadata and grid count of a one-block file, as written.
    hr = vdbfile.Reader(first["header"])
    hr.take(8 + 4 + 8 + 1 + 36)
    vdbfile.read_metamap(hr)
    hr.unpack("<I")
    header = first["header"][:hr.pos]
    enc = lambda s: struct.pack("<I", len(s)) + s  # noqa: E731
    descriptor = enc(b"density") + enc(b"Tree_float_5_4_3") + enc(b"")
    with open(out + ".tmp", "wb") as f:
        f.write(header + descriptor)
        offsets_at = f.tell()
        f.write(struct.pack("<3q", 0, 0, 0))
        grid_pos = f.tell()
        f.write(struct.pack("<I", first["compression"]))
        f.write(struct.pack("<I", len(entries)) + b"".join(entries))
        f.write(first["transform"])
        f.write(struct.pack("<i", 1) + first["background"] + struct.pack("<II", 0, len(order)))
        for u in order:
            child = np.zeros(32768, dtype=bool)
            for b in uppers[u]:
                child[b["slot"]] = True
            f.write(struct.pack("<3i", *u))
            f.write(np.packbits(child, bitorder="little").tobytes())
            f.write(bytes(4096))
            f.write(first["upper_values"])
            for b in uppers[u]:
                with open(b["path"], "rb") as src:
                    src.seek(b["lower"][0])
                    f.write(src.read(b["lower"][1] - b["lower"][0]))
        block_pos = f.tell()
        for u in order:
            for b in uppers[u]:
                with open(b["path"], "rb") as src:
                    src.seek(b["buffers"][0])
                    shutil.copyfileobj(src, f, length=b["buffers"][1] - b["buffers"][0])
        end_pos = f.tell()
        f.seek(offsets_at)
        f.write(struct.pack("<3q", grid_pos, block_pos, end_pos))
    os.replace(out + ".tmp", out)
    return dict(voxels=voxels, leaves=leaves, bbox=(lo, hi), mem=mem,
                uppers=len(order), lowers=len(blocks))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="output .vdb path")
    ap.add_argument("--scale", type=float, default=1.0, help="linear size factor (default 1)")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--stride", type=int, default=0,
                    help="noise lattice spacing in voxels, a power of two up to 128 "
                         "(default: the largest at most h/96, 8 at most)")
    ap.add_argument("--tmp", help="folder for the block files (default: next to OUT)")
    args = ap.parse_args()

    t0 = time.time()
    size = box_size(args.scale)
    stride = args.stride or default_stride(size)
    if stride < 1 or BLOCK % stride:
        ap.error("--stride must be a power of two from 1 to 128")
    tmp = Path(args.tmp or (Path(args.out).resolve().parent / f".make_large.{os.getpid()}"))
    tmp.mkdir(parents=True, exist_ok=True)
    work = [(size, args.seed, stride, origin, str(tmp))
            for origin in candidate_blocks(size, args.seed)]
    print(f"{args.out}: box {size}, stride {stride}, {len(work)} candidate blocks "
          f"of {BLOCK}^3, {args.jobs} processes", flush=True)
    blocks = []
    try:
        with Pool(max(1, args.jobs)) as pool:
            for i, b in enumerate(pool.imap_unordered(make_block, work, chunksize=2)):
                if b is not None:
                    blocks.append(b)
                if (i + 1) % 200 == 0 or i + 1 == len(work):
                    print(f"  {i + 1:6d}/{len(work)} blocks, {len(blocks)} with voxels, "
                          f"{time.time() - t0:7.1f} s", flush=True)
        t1 = time.time()
        if not blocks:
            raise SystemExit("the cloud is empty")
        s = merge(blocks, args.out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{args.out}: box {size}, {s['voxels']:,} active voxels, {s['leaves']:,} leaves, "
          f"{s['lowers']} lower and {s['uppers']} upper nodes, bbox {tuple(s['bbox'][0])} -> "
          f"{tuple(s['bbox'][1])}, {os.path.getsize(args.out) / 1e6:.1f} MB; blocks "
          f"{t1 - t0:.1f} s, merge {time.time() - t1:.1f} s, total {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

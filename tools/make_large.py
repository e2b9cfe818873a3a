#!/usr/bin/python3
"""Write a large cumulus fog volume for benchmarks (not committed).

Usage:

    /usr/bin/python3 tools/make_large.py OUT.vdb [--scale 1.0] [--seed 7] [--jobs N]

The cloud is the same procedural cumulus as data/cloud.vdb (tools/procedural.py),
evaluated on a box of about (768 x 384 x 576) * scale voxels.  At scale 1 it has
about 20-25 million active voxels in roughly 50,000 leaves and the file is
roughly 90 MB; it takes on the order of a minute or two on 2 cores.
The box is computed in slabs of 64 voxels along x (one process per core) so memory
stays around a few hundred MB.  Grid "density", class fog volume, voxel size 1,
written with pyopenvdb (blosc + active mask).  Deterministic for a given seed/scale.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pyopenvdb as vdb

sys.dont_write_bytecode = True  # keep tools/ free of __pycache__
sys.path.insert(0, str(Path(__file__).resolve().parent))
import procedural  # noqa: E402

BASE_SIZE = (768, 384, 576)
SLAB = 64  # voxels along x per work item (a multiple of 8, so leaves never straddle slabs)


def _slab(args):
    size, seed, x0 = args
    x1 = min(x0 + SLAB, size[0])
    block = (slice(x0, x1), slice(0, size[1]), slice(0, size[2]))
    return x0, procedural.cumulus_density(size, seed, block=block)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="output .vdb path")
    ap.add_argument("--scale", type=float, default=1.0, help="linear size factor (default 1)")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()

    t0 = time.time()
    size = tuple(max(16, int(round(n * args.scale / 8)) * 8) for n in BASE_SIZE)
    grid = vdb.FloatGrid()
    grid.name, grid.gridClass = "density", vdb.GridClass.FOG_VOLUME
    work = [(size, args.seed, x0) for x0 in range(0, size[0], SLAB)]
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for x0, dens in pool.map(_slab, work):
            if dens.any():
                grid.copyFromArray(dens, ijk=(x0, 0, 0))
            print(f"  slab x={x0:4d}  {time.time() - t0:6.1f} s", flush=True)
    vdb.write(args.out, [grid])
    lo, hi = grid.evalActiveVoxelBoundingBox()
    print(f"{args.out}: box {size}, {grid.activeVoxelCount():,} active voxels, "
          f"{grid.leafCount():,} leaves, bbox {lo} -> {hi}, "
          f"{os.path.getsize(args.out) / 1e6:.1f} MB, {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

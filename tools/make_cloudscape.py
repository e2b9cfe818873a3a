#!/usr/bin/python3
"""Write a cloudscape: several cumulus puffs in one sparse grid (not committed).

Usage:

    /usr/bin/python3 tools/make_cloudscape.py OUT.vdb [--seed 3]

Production skies often come as one grid holding many clouds (a Houdini cloud
field). Most of such a grid's bounding box is empty and its clouds differ in
density, which is where one global majorant wastes the most null
collisions and a local hierarchy the fewest. Six puffs of the procedural
cumulus of data/cloud.vdb (tools/procedural.py), each scaled by its own
peak density, spread over about 1100 x 260 x 900 voxels; about 2 M active
voxels, 15-20 MB, a minute or less on 2 cores. Grid "density", class fog
volume, voxel size 1, written with pyopenvdb. Deterministic for a seed.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pyopenvdb as vdb

sys.dont_write_bytecode = True  # keep tools/ free of __pycache__
sys.path.insert(0, str(Path(__file__).resolve().parent))
import procedural  # noqa: E402

# (size, offset, peak density): a large cloud, mid-sized ones, small puffs.
PUFFS = [
    ((296, 148, 224), (0, 40, 0), 1.0),
    ((200, 100, 152), (420, 0, 120), 0.6),
    ((160, 80, 120), (820, 90, 40), 0.35),
    ((240, 120, 176), (700, 20, 560), 0.8),
    ((128, 64, 96), (250, 160, 640), 0.25),
    ((96, 48, 72), (60, 10, 520), 0.15),
]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="output .vdb path")
    ap.add_argument("--seed", type=int, default=3)
    args = ap.parse_args()
    t0 = time.time()
    grid = vdb.FloatGrid()
    grid.name, grid.gridClass = "density", vdb.GridClass.FOG_VOLUME
    for k, (size, offset, peak) in enumerate(PUFFS):
        dens = procedural.cumulus_density(size, args.seed + k) * np.float32(peak)
        # copyFromArray overwrites: add each puff into its own grid and merge.
        puff = vdb.FloatGrid()
        puff.copyFromArray(dens.astype(np.float32), ijk=offset)
        grid.combine(puff, lambda a, b: max(a, b))
        print(f"  puff {k}: {size} at {offset}, peak {peak}  {time.time() - t0:6.1f} s", flush=True)
    vdb.write(args.out, grids=[grid])
    print(f"{args.out}: {grid.activeVoxelCount()} active voxels, {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

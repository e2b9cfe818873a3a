#!/usr/bin/python3
"""Write data/fireball.vdb: a small explosion with "density" and "temperature" grids.

Usage (Debian's own interpreter, the only one that can import pyopenvdb):

    /usr/bin/python3 tools/make_fireball.py data/fireball.vdb

The shape: a turbulent ball of smoke rising into a mushroom cap, with a hot
core whose temperature (in kelvin, stored directly) falls from about
2600 K at the centre to below 900 K at the edge of the core, broken up by
noise so the flames show structure. Smoke density is higher at the rim
than in the burning core, as in a real fireball. The temperature grid is
active only where it is above 500 K, so it is much smaller than the
density grid and cirrus looks emission up only there.

Render it with blackbody emission (pbrt-v4's definition; cirrus reads the
grid named in the scene file):

    [[volume]]
    file = "fireball.vdb"
    temperature = "temperature"
    albedo = 0.5
    blackbody = { scale = 40.0 }

Deterministic: seeded noise, no clocks (OpenVDB's header UUID aside).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pyopenvdb as vdb

sys.dont_write_bytecode = True
sys.path.insert(0, str(Path(__file__).resolve().parent))
import procedural  # noqa: E402

SEED = 20261122
N = 72  # voxels per axis
VOXEL = 0.05  # world units per voxel: the fireball is about 3.6 units across


def fields(n: int = N, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """Density and temperature arrays, indexed [x, y, z] with y up."""
    noise = procedural.GradientNoise(seed)
    ax = np.arange(n, dtype=np.float32)
    turb = noise.fbm(ax, ax, ax, freq=0.09, octaves=4, billow=True)
    fine = noise.fbm(ax, ax, ax, freq=0.2, octaves=3)
    c = (n - 1) / 2.0
    x = (ax[:, None, None] - c) / c
    y = (ax[None, :, None] - c) / c
    z = (ax[None, None, :] - c) / c
    # Ball below, cap above: the radius grows with height.
    r_ball = np.sqrt(x * x + (y + 0.25) ** 2 + z * z)
    r_cap = np.sqrt(x * x + 2.2 * (y - 0.35) ** 2 + z * z)
    shape = np.minimum(r_ball / 0.62, r_cap / 0.78)
    shape = shape - 0.35 * (turb - 0.5)  # turbulent surface
    density = np.clip(1.0 - shape, 0.0, None) ** 0.7
    # Thinner inside (burnt), thicker smoke at the rim.
    density *= 0.6 + 0.6 * np.clip(shape, 0.0, 1.0)
    density = np.where(shape < 1.0, density, 0.0).astype(np.float32)
    # Hot core, off-centre toward the bottom, broken up by noise.
    r_core = np.sqrt(x * x + (y + 0.2) ** 2 + z * z) / 0.5 - 0.45 * fine
    heat = np.clip(1.0 - r_core, 0.0, 1.0)
    temperature = np.where(density > 0.0, 500.0 + 2100.0 * heat ** 1.2, 0.0)
    temperature = np.where(temperature > 500.0, temperature, 0.0).astype(np.float32)
    return density, temperature


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "data/fireball.vdb")
    density, temperature = fields()
    transform = vdb.createLinearTransform(voxelSize=VOXEL)
    grids = []
    for name, data, cls in (
        ("density", density, vdb.GridClass.FOG_VOLUME),
        ("temperature", temperature, vdb.GridClass.UNKNOWN),
    ):
        g = vdb.FloatGrid()
        g.copyFromArray(data, ijk=(-N // 2, 0, -N // 2), tolerance=0.0)
        g.prune(0.0)
        g.transform = transform
        g.name, g.gridClass = name, cls
        grids.append(g)
        print(f"{name}: {g.activeVoxelCount()} active voxels, max {data.max():.1f}")
    vdb.write(str(out), grids)
    print(f"{out}: {out.stat().st_size} bytes")


if __name__ == "__main__":
    main()

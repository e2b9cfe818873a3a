#!/usr/bin/env python3
"""Equi-angular sampling against free flights alone, at equal time: a
spot light's beam through thin fog (`data/tile_box.vdb`, optical depth
0.5 across) and a point light inside the corpus cloud. Prints, per scene
and distance sampling (`auto` choosing by how thick the media are), the render time, the error against a long
reference (root mean square over the image's mean) and the efficiency
1 / (MSE x time) relative to free flights.

    python3 tools/equiangular.py [CIRRUS] [--spp N] [--ref-spp N]

Needs numpy and OpenEXR (`pip install numpy OpenEXR`).
"""

from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

import numpy as np

from cirrus_runs import render_rgb

REPO = Path(__file__).resolve().parents[1]


def lamp_in_cloud(density_scale: float) -> str:
    """A point light inside the corpus cloud at `density_scale`."""
    return f"""
[camera]
res = "128x96"
from = [150, 83, -250]
to = [150, 83, 100]
fov = 40
[[light]]
type = "point"
position = [150, 90, 100]
intensity = 30000
[[volume]]
file = "{REPO / 'data' / 'cloud.vdb'}"
density_scale = {density_scale}
albedo = 0.9
g = 0.5
"""


SCENES = {
    # A spot light high in a box of thin fog, its beam crossing the view.
    "beam in fog": f"""
[camera]
res = "128x96"
from = [64, 64, -150]
to = [64, 64, 64]
fov = 50
[[light]]
type = "spot"
position = [30, 120, 64]
direction = [0.5, -1, 0]
cone_angle = 10
cone_softness = 0.2
intensity = 20000
[[volume]]
file = "{REPO / 'data' / 'tile_box.vdb'}"
density_scale = 0.004
albedo = 0.9
g = 0.3
""",
    # A lamp inside the corpus cloud, thin and thick.
    "point in thin cloud": lamp_in_cloud(0.02),
    "point in cloud": lamp_in_cloud(0.2),
}


def with_render(text: str, spp: int, seed: int, sampling: str) -> str:
    return text + f"\n[render]\nspp = {spp}\nseed = {seed}\ndistance_sampling = \"{sampling}\"\n"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cirrus", nargs="?", default=str(REPO / "target" / "release" / "cirrus"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    a = ap.parse_args()
    d = Path(tempfile.mkdtemp(prefix="cirrus-ea-"))
    for name, text in SCENES.items():
        ref, _ = render_rgb(a.cirrus, with_render(text, a.ref_spp, 1000, "equiangular"), d, "ref")
        rows = {}
        for sampling in ("free-flight", "equiangular", "auto"):
            errs, times = [], []
            for seed in (1, 2, 3):
                img, t = render_rgb(a.cirrus, with_render(text, a.spp, seed, sampling), d, "run")
                errs.append(np.mean((img - ref) ** 2))
                times.append(t)
            rows[sampling] = (float(np.mean(errs)), float(np.mean(times)))
        base = 1.0 / (rows["free-flight"][0] * rows["free-flight"][1])
        for sampling, (mse, t) in rows.items():
            print(f"{name:20s} {sampling:12s} time {t:6.2f} s  relative RMSE "
                  f"{math.sqrt(mse) / ref.mean():7.4f}  efficiency {1.0 / (mse * t) / base:6.2f}x free flights")


if __name__ == "__main__":
    main()

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
import json
import math
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import OpenEXR

REPO = Path(__file__).resolve().parents[1]

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
    # A lamp inside the corpus cloud (its default density).
    "point in cloud": f"""
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
density_scale = 0.2
albedo = 0.9
g = 0.5
""",

    # The same, its density a tenth.
        "point in thin cloud": f"""
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
density_scale = 0.02
albedo = 0.9
g = 0.5
""",
}


def render(cirrus: str, text: str, spp: int, seed: int, sampling: str, d: Path) -> tuple[np.ndarray, float]:
    toml = d / "scene.toml"
    toml.write_text(text + f"\n[render]\nspp = {spp}\nseed = {seed}\ndistance_sampling = \"{sampling}\"\n")
    out, stats = d / "out.exr", d / "stats.json"
    subprocess.run([cirrus, "render", str(toml), "-o", str(out), "--stats", str(stats)],
                   check=True, capture_output=True)
    rgba = OpenEXR.File(str(out)).parts[0].channels["RGBA"].pixels
    return rgba[..., :3].astype(np.float64), json.loads(stats.read_text())["wall_seconds"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cirrus", nargs="?", default=str(REPO / "target" / "release" / "cirrus"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    a = ap.parse_args()
    d = Path(tempfile.mkdtemp(prefix="cirrus-ea-"))
    for name, text in SCENES.items():
        ref, _ = render(a.cirrus, text, a.ref_spp, 1000, "equiangular", d)
        rows = {}
        for sampling in ("free-flight", "equiangular", "auto"):
            errs, times = [], []
            for seed in (1, 2, 3):
                img, t = render(a.cirrus, text, a.spp, seed, sampling, d)
                errs.append(np.mean((img - ref) ** 2))
                times.append(t)
            rows[sampling] = (float(np.mean(errs)), float(np.mean(times)))
        base = 1.0 / (rows["free-flight"][0] * rows["free-flight"][1])
        for sampling, (mse, t) in rows.items():
            print(f"{name:20s} {sampling:12s} time {t:6.2f} s  relative RMSE "
                  f"{math.sqrt(mse) / ref.mean():7.4f}  efficiency {1.0 / (mse * t) / base:6.2f}x free flights")


if __name__ == "__main__":
    main()

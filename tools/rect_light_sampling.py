#!/usr/bin/env python3
"""A rect light's sampling, two builds against each other: the corpus cloud
as thin fog (density scale 0.1, albedo 0.8) under a large rect light
inside its box (200 x 120 and 40 x 24 units, facing down), rendered by
OLD and NEW at equal samples; prints each build's time, error against a
long reference by NEW (root mean square over the image's mean) and
efficiency 1 / (MSE x time). Written to measure solid-angle sampling of
rectangles against sampling their area.

    python3 tools/rect_light_sampling.py OLD_CIRRUS NEW_CIRRUS [--spp N] [--ref-spp N]

Needs numpy and OpenEXR (`pip install numpy OpenEXR`).
"""

from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

import numpy as np

from cirrus_runs import CLOUD_FOG, render_rgb



def scene(spp: int, seed: int, width: float) -> str:
    return f"""[camera]
res = "320x200"
from = [150, 83, -250]
to = [150, 83, 100]
[render]
spp = {spp}
seed = {seed}
[[light]]
type = "rect"
position = [150, 120, 100]
direction = [0, -1, 0]
width = {width}
height = {width * 0.6}
color = [1, 0.9, 0.8]
intensity = 2
{CLOUD_FOG}"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=2048)
    a = ap.parse_args()
    d = Path(tempfile.mkdtemp(prefix="cirrus-rect-"))
    for width in (200.0, 40.0):
        ref, _ = render_rgb(a.new, scene(a.ref_spp, 1000, width), d, "ref")
        for name, cirrus in (("old", a.old), ("new", a.new)):
            errs, times = [], []
            for seed in (1, 2, 3):
                img, t = render_rgb(cirrus, scene(a.spp, seed, width), d, name)
                errs.append(np.mean((img - ref) ** 2))
                times.append(t)
            mse, t = float(np.mean(errs)), float(np.mean(times))
            print(f"width {width:5.0f}  {name}  time {t:6.2f} s  relative RMSE "
                  f"{math.sqrt(mse) / ref.mean():7.4f}  1/(MSE t) {1 / (mse * t):.4g}")


if __name__ == "__main__":
    main()

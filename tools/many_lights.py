#!/usr/bin/env python3
"""Many lights: the corpus cloud as thin fog lit by 1, 10 and 100 sphere
lights (a lattice of lamps through and around it, intensities spread over
a factor of ten), rendered with each light sampling: `all` (every light at
every vertex), `uniform` (one light picked uniformly) and the weighed pick
(`auto`: one light by what each sends toward the vertex past 8 lights,
the few-light pick below). Prints, per scene and strategy, the time, the
error against a long weighed reference (root mean square over the
image's mean), and the efficiency 1 / (MSE x time) relative to `uniform`.

    python3 tools/many_lights.py [CIRRUS] [--spp N] [--ref-spp N]

Needs numpy and OpenEXR (`pip install numpy OpenEXR`).
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from pathlib import Path

import numpy as np

from cirrus_runs import CLOUD_FOG, render_rgb

REPO = Path(__file__).resolve().parents[1]
# The cloud's world box (index bbox of data/cloud.vdb, voxel size 1).
LO, HI = np.array([33.0, 25.0, 32.0]), np.array([266.0, 140.0, 167.0])


def lamps(n: int) -> list[dict]:
    """`n` point lamps at random over the cloud's box, grown by a fifth,
    their powers spread over a factor of ten (points, so that no pixel
    sees a lamp's ball, whose edge would decide the error)."""
    rng = np.random.default_rng(n)
    lo, hi = LO - 0.1 * (HI - LO), HI + 0.1 * (HI - LO)
    out = []
    for k in range(n):
        p = lo + rng.random(3) * (hi - lo)
        power = 10.0 ** rng.uniform(0.0, 1.0)
        out.append({
            "type": "point",
            "name": "lamp",
            "position": [float(x) for x in p],
            # Total intensity about the same whatever n: the image's scale.
            "color": [c * 3000.0 * power / math.sqrt(n) for c in (1.0, 0.85, 0.7)],
        })
    return out


def scene(n: int, spp: int, sampling: str, seed: int) -> str:
    lights = "".join(
        "[[light]]\n" + "".join(f"{k} = {json.dumps(v)}\n" for k, v in l.items()) for l in lamps(n)
    )
    return f"""[camera]
res = "160x100"
from = [150, 83, -250]
to = [150, 83, 100]
[render]
spp = {spp}
seed = {seed}
light_sampling = "{sampling}"
[environment]
radiance = [0.002, 0.003, 0.005]
{lights}
{CLOUD_FOG}"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cirrus", nargs="?", default=str(REPO / "target" / "release" / "cirrus"))
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--lights", default="1,10,100")
    a = ap.parse_args()
    d = Path(tempfile.mkdtemp(prefix="cirrus-many-"))
    for n in (int(x) for x in a.lights.split(",")):
        ref, _ = render_rgb(a.cirrus, scene(n, a.ref_spp, "auto", 1000), d, f"ref{n}")
        rows = {}
        for sampling in ("uniform", "auto", "all"):
            errs, times = [], []
            for seed in (1, 2, 3):
                img, t = render_rgb(a.cirrus, scene(n, a.spp, sampling, seed), d, f"{sampling}{n}")
                errs.append(np.mean((img - ref) ** 2))
                times.append(t)
            rows[sampling] = (float(np.mean(errs)), float(np.mean(times)))
        base = 1.0 / (rows["uniform"][0] * rows["uniform"][1])
        mean = float(ref.mean())
        for sampling, (mse, t) in rows.items():
            eff = 1.0 / (mse * t) / base
            print(f"{n:4d} lights  {sampling:8s} time {t:6.2f} s  relative RMSE {math.sqrt(mse) / mean:7.4f}"
                  f"  efficiency {eff:6.2f}x uniform")


if __name__ == "__main__":
    main()

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

With `--embers`, the light tree's benchmark instead: embers in smoke (the
same fog lit by 10 and by 10,000 point lights in the lower part of the
cloud, their total power fixed), printing the time per sample with 10,000
lights over that with 10, and at 10,000 lights the error of the weighed
pick (the light tree) against the uniform pick at equal time; with
`--baseline OTHER_CIRRUS` the same figures for another build (today's
pick) beside them, the two builds run alternately.

    python3 tools/many_lights.py [CIRRUS] --embers [--baseline CIRRUS] [--spp N] [--ref-spp N]
        [--seeds N] [--distance auto|equiangular]

The embers' error is printed two ways: against the reference, and by the
spread of the `--seeds` images (each strategy is unbiased, so its MSE is
its variance; no reference noise enters it).

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


def lit_fog(lights: list[dict], spp: int, sampling: str, seed: int, render: str = "",
            sky: str = "") -> str:
    """The scene file of the cloud's fog lit by `lights` (dicts of
    `[[light]]` keys), seen by the benchmark's camera; `render` and `sky`
    are extra lines for `[render]` and the top level."""
    tables = "".join(
        "[[light]]\n" + "".join(f"{k} = {json.dumps(v)}\n" for k, v in l.items()) for l in lights
    )
    return f"""[camera]
res = "160x100"
from = [150, 83, -250]
to = [150, 83, 100]
[render]
spp = {spp}
seed = {seed}
light_sampling = "{sampling}"
{render}{sky}{tables}
{CLOUD_FOG}"""


def scene(n: int, spp: int, sampling: str, seed: int) -> str:
    return lit_fog(lamps(n), spp, sampling, seed,
                   sky="[environment]\nradiance = [0.002, 0.003, 0.005]\n")


def embers(n: int) -> list[dict]:
    """`n` point lamps (embers) at random in the lower third of the
    cloud's box, orange, their powers spread over a factor of ten and
    their total fixed."""
    rng = np.random.default_rng(7 + n)
    lo, hi = LO.copy(), HI.copy()
    hi[1] = lo[1] + (hi[1] - lo[1]) / 3.0
    powers = 10.0 ** rng.uniform(0.0, 1.0, n)
    powers *= 40000.0 / powers.sum()
    return [{
        "type": "point",
        "name": "ember",
        "position": [float(x) for x in lo + rng.random(3) * (hi - lo)],
        "color": [c * float(w) for c in (1.0, 0.45, 0.12)],
    } for w in powers]


def ember_scene(n: int, spp: int, sampling: str, seed: int, distance: str = "auto") -> str:
    return lit_fog(embers(n), spp, sampling, seed, render=f'distance_sampling = "{distance}"\n')


def ember_benchmark(a: argparse.Namespace) -> None:
    d = Path(tempfile.mkdtemp(prefix="cirrus-embers-"))
    builds = [("this build", a.cirrus)] + ([("baseline", a.baseline)] if a.baseline else [])
    pixels = 160 * 100
    # Time per sample: 10 and 10,000 lights, the builds alternating, the
    # least of three runs each (the render's wall time over its samples).
    per_sample = {}
    for rep in range(3):
        for label, exe in builds:
            for n in (10, 10000):
                _, t = render_rgb(exe, ember_scene(n, a.spp, "auto", 1, a.distance), d, f"t{n}")
                key = (label, n)
                per_sample[key] = min(per_sample.get(key, math.inf), t / (a.spp * pixels))
    for label, _ in builds:
        t10, t10k = per_sample[(label, 10)], per_sample[(label, 10000)]
        print(f"{label:10s} time per sample: 10 lights {t10 * 1e9:7.1f} ns, 10,000 lights "
              f"{t10k * 1e9:7.1f} ns: {t10k / t10:5.2f}x")
    # Error at equal time, 10,000 lights: the weighed pick (the light
    # tree) against the uniform pick, two ways. Against a reference (this
    # build's weighed pick at --ref-spp): the reference's own noise adds
    # to both strategies' error and, where the estimator's variance is
    # heavy-tailed (points in a medium), its fireflies dominate both and
    # pull the ratio toward one. And by the spread over seeds: each
    # estimator is unbiased, so its mean squared error is its variance,
    # estimated per pixel from --seeds independent images (no reference
    # noise in it); both are normalised by the reference's mean.
    ref, _ = render_rgb(a.cirrus, ember_scene(10000, a.ref_spp, "auto", 1000, a.distance), d, "ref")
    mean = float(ref.mean())
    seeds = range(1, a.seeds + 1)
    for label, exe in builds:
        rows = {}
        for sampling in ("uniform", "auto"):
            imgs, times = [], []
            for seed in seeds:
                img, t = render_rgb(exe, ember_scene(10000, a.spp, sampling, seed, a.distance), d, f"e{sampling}")
                imgs.append(img)
                times.append(t)
            stack = np.stack(imgs)
            mse = float(np.mean((stack - ref) ** 2))
            var = float(np.mean(stack.var(axis=0, ddof=1)))
            rows[sampling] = (mse, var, float(np.mean(times)), float(stack.mean()))
        (mse_u, var_u, t_u, _), (mse_w, var_w, t_w, _) = rows["uniform"], rows["auto"]
        # At equal time the MSE scales as 1 / time.
        ratio = (mse_u * t_u) / (mse_w * t_w)
        ratio_var = (var_u * t_u) / (var_w * t_w)
        for sampling, (mse, var, t, m) in rows.items():
            print(f"{label:10s} 10,000 lights {sampling:8s} time {t:6.2f} s  relative RMSE "
                  f"{math.sqrt(mse) / mean:7.4f} (vs reference), {math.sqrt(var) / mean:7.4f} "
                  f"(seed spread); image mean / reference mean {m / mean:6.3f}")
        print(f"{label:10s} at equal time the weighed pick's MSE is {ratio:6.1f}x lower than "
              f"the uniform pick's (RMSE {math.sqrt(ratio):5.2f}x) against the reference, "
              f"{ratio_var:6.1f}x (RMSE {math.sqrt(ratio_var):5.2f}x) by the seed spread")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cirrus", nargs="?", default=str(REPO / "target" / "release" / "cirrus"))
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--lights", default="1,10,100")
    ap.add_argument("--embers", action="store_true", help="the light tree's benchmark")
    ap.add_argument("--baseline", help="another build, measured beside (with --embers)")
    ap.add_argument("--seeds", type=int, default=3,
                    help="independent images per strategy (with --embers)")
    ap.add_argument("--distance", default="auto",
                    help="distance sampling of the embers' renders (auto, equiangular)")
    a = ap.parse_args()
    if a.embers:
        ember_benchmark(a)
        return
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

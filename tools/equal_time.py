#!/usr/bin/env python3
"""Equal-time efficiency of cirrus configurations on one scene, in one run.

    python tools/equal_time.py SCENE [--seeds 1-8] [--cirrus BIN] [--out DIR] LABEL:FLAGS ...

Each configuration (`auto:` for the defaults, `all:--light-sampling all`, ...) renders the scene
once per seed, the configurations alternated seed by seed so that the machine's drift falls on
all alike. Per configuration: the image mean, the per-pixel variance across seeds (unbiased, of
the pixel's luminance, averaged over the image: every estimator here is unbiased, so this is
its mean squared error), the CPU seconds of a render (user + sys of the process: the machine is
shared, CPU time is the steadier measure), and the efficiency 1 / (variance x time), also as a
ratio to the first configuration's. Heavy-tailed estimators need many seeds: a firefly in one
render of few moves the variance by orders of magnitude.

Needs numpy and PyPI's `OpenEXR` (e.g. `target/venv/bin/pip install numpy OpenEXR`).
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent

VIEW = ["--res", "128x128", "--camera-from", "150,83,-250", "--camera-to", "150,83,100",
        "--camera-up", "0,1,0", "--fov", "40", "--density-scale", "0.5", "--albedo", "0.9"]
SUN = ["--sun-irradiance", "2.6,2.5,2.3", "--sun-angle", "0.53"]
SKY = ["--env-radiance", "0.16,0.22,0.34"]
# The sun 3 degrees off the view axis, behind the cloud; a sky a tenth of SKY's.
BACKLIT = VIEW + SUN + ["--sun-dir", "0.05,0,-1", "--env-radiance", "0.016,0.022,0.034",
                        "--phase", "mie", "--droplet-diameter", "20"]

SCENES = {
    # Albedo 0.999, HG g 0.8, a delta sun and the default sky, on the default view.
    "thick": ["--res", "128x128", "--albedo", "0.999", "--g", "0.8", "--sun-angle", "0", "--spp", "64"],
    "default": ["--res", "128x128", "--spp", "64"],
    "backlit-ss": BACKLIT + ["--max-depth", "1", "--spp", "128"],
    "backlit-ms": BACKLIT + ["--spp", "64"],
    # The sun 4.6 degrees above the horizon, from behind the camera's right.
    "grazing": VIEW + SUN + SKY + ["--sun-dir", "0.3,-0.08,0.95", "--phase", "hg", "--g", "0.5",
                                   "--spp", "64"],
    "sky": VIEW + SKY + ["--no-sun", "--phase", "hg", "--g", "0.5", "--spp", "64"],
}


def seeds(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def read_luminance(path: Path):
    import numpy as np
    import OpenEXR
    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        rgb = (ch["RGBA"] if "RGBA" in ch else ch["RGB"]).pixels[..., :3].astype(np.float64)
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", choices=list(SCENES))
    ap.add_argument("configs", nargs="+", metavar="LABEL:FLAGS")
    ap.add_argument("--seeds", default="1-8", help="first-last (default 1-8)")
    ap.add_argument("--cirrus", default=str(REPO / "target" / "release" / "cirrus"))
    ap.add_argument("--out", default=str(REPO / "target" / "equal_time"))
    args = ap.parse_args(argv)
    import numpy as np

    configs = [c.partition(":")[::2] for c in args.configs]
    out = Path(args.out) / args.scene
    out.mkdir(parents=True, exist_ok=True)
    images = {label: [] for label, _ in configs}
    cpu = {label: 0.0 for label, _ in configs}
    for seed in seeds(args.seeds):
        for label, flags in configs:
            path = out / f"{label}_{seed}.exr"
            cmd = [args.cirrus, "render", str(REPO / "data" / "cloud.vdb"), "-o", str(path),
                   "--seed", str(seed)] + SCENES[args.scene] + flags.split()
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu[label] += (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
            images[label].append(read_luminance(path))
    n = len(seeds(args.seeds))
    base = None
    print(f"{args.scene}, seeds {args.seeds}: {' '.join(SCENES[args.scene])}")
    for label, flags in configs:
        stack = np.stack(images[label])
        variance = stack.var(axis=0, ddof=1).mean()
        seconds = cpu[label] / n
        eff = 1.0 / (variance * seconds)
        base = base or eff
        print(f"  {label:12s} mean {stack.mean():.5f}  variance {variance:.4e}  "
              f"cpu {seconds:.2f} s  efficiency {eff:.4e}  ({eff / base:.2f}x)  [{flags}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())

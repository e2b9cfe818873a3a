#!/usr/bin/env python3
"""The denoiser's error against the noisy image's over a sweep of sample counts.

    python tools/denoise_sweep.py --scene sky|thick|default --ref DIR [--spp 16 64 ...]
                                  [--seeds 7 8] [--cirrus BIN] [--out DIR]

Each render is `cirrus render ... --denoise` of the scene of `tools/phase_peers.py` (the
same flags); its EXR holds the three images being compared: the blend (RGB), the noisy image
(`noisy.R/G/B`) and the plain denoised one (`denoised.R/G/B`), with the blend's weight of the
noisy image (`blend.weight`). The reference is the mean of the two converged renders
`DIR/ref_1001.exr` and `DIR/ref_1002.exr` that `phase_peers.py efficiency --refs-only` makes;
its own noise (a quarter of the two renders' mean squared difference) is subtracted from every
MSE. Per spp and seed: the three MSEs over all RGB pixels, the mean blend weight and the
denoiser's seconds; then per spp their means over the seeds and the blend's MSE against the
better of the other two. Needs numpy and PyPI's `OpenEXR`, and `CIRRUS_OIDN` (tools/oidn.sh).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

TOOLS = Path(__file__).resolve().parent
sys.path.insert(0, str(TOOLS))
sys.dont_write_bytecode = True

import phase_peers  # noqa: E402  (the scenes' flags)


def read_layers(path: Path) -> dict:
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = {k: np.asarray(v.pixels, dtype=np.float64) for k, v in f.channels().items()}

    def rgb(prefix: str) -> np.ndarray:
        return np.stack([ch[prefix + c] for c in "RGB"], axis=-1)

    return {"blend": rgb(""), "noisy": rgb("noisy."), "denoised": rgb("denoised."),
            "weight": ch["blend.weight"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", choices=list(phase_peers.SCENES), required=True)
    ap.add_argument("--ref", required=True, help="folder with ref_1001.exr and ref_1002.exr")
    ap.add_argument("--spp", type=int, nargs="+", default=[16, 64, 256, 1024, 2048])
    ap.add_argument("--seeds", type=int, nargs="+", default=[7, 8])
    ap.add_argument("--cirrus", default=str(TOOLS.parent / "target" / "release" / "cirrus"))
    ap.add_argument("--out", default=None, help="where the renders go (default: REF/sweep)")
    ap.add_argument("--extra", default="", help="more cirrus flags, one string")
    args = ap.parse_args(argv)
    ref_dir = Path(args.ref)
    refs = [read_layers_rgb(ref_dir / f"ref_{s}.exr") for s in (1001, 1002)]
    ref = 0.5 * (refs[0] + refs[1])
    ref_noise = float(np.mean((refs[0] - refs[1]) ** 2) / 4.0)
    out = Path(args.out) if args.out else ref_dir / "sweep"
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for spp in args.spp:
        for seed in args.seeds:
            f = out / f"dn_{spp}_{seed}.exr"
            stats = f.with_suffix(".stats.json")
            cmd = [args.cirrus, "render", phase_peers.CLOUD, "-o", str(f), "--spp", str(spp),
                   "--seed", str(seed), "--stats", str(stats), "--denoise",
                   *phase_peers.SCENES[args.scene], *args.extra.split()]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            img = read_layers(f)
            s = json.loads(stats.read_text())
            row = {"spp": spp, "seed": seed, "weight": float(img["weight"].mean()),
                   "denoise_seconds": s.get("denoise_seconds"), "render_seconds": s.get("wall_seconds")}
            for k in ("noisy", "denoised", "blend"):
                row[k] = float(np.mean((img[k] - ref) ** 2)) - ref_noise
            rows.append(row)
            print(f"{args.scene} {spp:5d} spp seed {seed}: noisy {row['noisy']:.3e}  denoised "
                  f"{row['denoised']:.3e}  blend {row['blend']:.3e}  weight {row['weight']:.3f}", flush=True)
    (out / "sweep.json").write_text(json.dumps({"ref_noise": ref_noise, "rows": rows}, indent=2) + "\n")
    print(f"\n{args.scene}: reference noise {ref_noise:.2e} (subtracted); means over seeds {args.seeds}\n")
    print("| spp | noisy MSE | denoised MSE | blend MSE | blend / better | mean weight of noisy | denoise s |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for spp in args.spp:
        r = [x for x in rows if x["spp"] == spp]
        m = {k: float(np.mean([x[k] for x in r])) for k in ("noisy", "denoised", "blend", "weight", "denoise_seconds")}
        print(f"| {spp} | {m['noisy']:.3e} | {m['denoised']:.3e} | {m['blend']:.3e} | "
              f"{m['blend'] / min(m['noisy'], m['denoised']):.2f} | {m['weight']:.3f} | {m['denoise_seconds']:.2f} |")
    return 0


def read_layers_rgb(path: Path) -> np.ndarray:
    import compare_images

    return compare_images.read_exr(str(path))[..., :3]


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""cirrus against Blender Cycles 5.2 and Mitsuba 3 on phase functions, and against Cycles on
efficiency: the figures of BENCHMARKS.md, "Peers: Cycles 5.2 and Mitsuba 3 on phases and efficiency".

    python tools/phase_peers.py agree --out /work/peer/agree [--cases hg_sunsky_ms mie10_ss ...] [--quick]
    python tools/phase_peers.py efficiency --out /work/peer/eff [--quick]
    python tools/phase_peers.py list

Run it with a python that has numpy and either mitsuba or the `OpenEXR` module (to read EXRs),
e.g. /work/peer/bpy-venv/bin/python, or /work/peer/mi-venv/bin/python for the Mitsuba-only
cases (`--cases rgb_ss rgb_ms`: chromatic media, extinction per RGB channel, against
Mitsuba's volpathmis; see mitsuba_render.py).  It starts the renderers as subprocesses, one at a time,
under `nice -n 5`:

    cirrus   --cirrus (default /tmp/cirrus-peer/cirrus, else target/release/cirrus)
    Cycles   --bpy-python (default /work/peer/bpy-venv/bin/python) tools/cycles_peer.py
    Mitsuba  --mi-python (default /work/peer/mi-venv/bin/python, a venv of Debian's python3 with
             --system-site-packages for pyopenvdb, plus mitsuba==3.9.1) tools/mitsuba_render.py

`agree`: for every case, K independent renders per renderer (seeds 1..K); per pixel the mean
and the variance of the mean from the K runs, the variance smoothed over 3x3 pixels (so each
pixel's noise estimate has ~9 (K - 1) degrees of freedom instead of K - 1).  Reported per
channel: the image means, their ratio peer / cirrus with its standard error (the pixels'
variances summed: pixels are independent), the fraction of pixels with |z| > 3 and > 4
against the fraction Student's t predicts from noise alone, and 8x8-block z-scores.
Pixels with no noise in either renderer (sky beside the cloud) must agree to 1e-4.

`efficiency`: one scene (`--scene sunsky`: HG g 0.5, albedo 0.9, sun 0.53 deg + sky, unlimited
depth; `--scene thick`: albedo 0.999, HG g 0.8, a delta sun + sky; `--scene sky`: as sunsky without
the sun), cirrus in one or more labelled
configurations (`--cirrus-config`), Cycles unguided and, with `--cycles-guiding`, guided; a
converged reference from two long cirrus renders with other seeds (its own noise, estimated
from their difference, is subtracted from every MSE); each renderer at several spp, unbiased
and with OIDN (cirrus --denoise, Cycles' OIDN with the albedo and normal passes); MSE, wall and CPU
seconds (user + sys of the renderer process: the machine is shared, CPU time is the steadier
measure), efficiency 1 / (MSE x time), and Cycles' fixed cost (a 1-spp render).
Everything lands in OUT/ as EXRs, `results.json` and `summary.md`; finished renders are
reused when rerun (delete OUT to start over).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
sys.dont_write_bytecode = True
sys.path.insert(0, str(TOOLS))

try:
    import numpy as np
except ImportError:  # `list` and --help work without it; the renders' statistics do not
    np = None

CLOUD = str(REPO / "data" / "cloud.vdb")
# Every scene parameter explicit, for all renderers.
VIEW = ["--res", "128x128", "--camera-from", "150,83,-250", "--camera-to", "150,83,100", "--camera-up", "0,1,0",
        "--fov", "40", "--density-scale", "0.5", "--albedo", "0.9", "--env-radiance", "0.16,0.22,0.34"]
SUN = ["--sun-dir", "-0.45,-0.6,-0.66", "--sun-irradiance", "2.6,2.5,2.3"]

# name: peer, scene flags (all renderers), spp per run for cirrus and for the peer
CASES: dict[str, dict] = {}


def _case(name, peer, flags, cirrus_spp, peer_spp, split=False):
    """split: the peer renders each RGB channel as its own grey medium (that channel's density scale
    and albedo; the channels of a chromatic medium are independent), composed into one image per seed."""
    CASES[name] = {"peer": peer, "flags": flags, "cirrus_spp": cirrus_spp, "peer_spp": peer_spp, "split": split}


# Mitsuba (one global majorant, rr_depth 256) is ~6x slower per sample than Cycles here: fewer spp.
for depth, suffix, cs, ps, ms in (([], "ms", 256, 64, 32), (["--max-depth", "1"], "ss", 512, 256, 128)):
    _case(f"hg_sunsky_{suffix}", "cycles", VIEW + SUN + ["--sun-angle", "0.53", "--phase", "hg", "--g", "0.5"] + depth,
          cs, ps)
    _case(f"hg_sky_{suffix}", "cycles", VIEW + ["--no-sun", "--phase", "hg", "--g", "0.5"] + depth, cs, ps)
    _case(f"mie10_{suffix}", "cycles",
          VIEW + SUN + ["--sun-angle", "0", "--phase", "mie", "--droplet-diameter", "10"] + depth, cs, ps)
    _case(f"mie20_{suffix}", "cycles",
          VIEW + SUN + ["--sun-angle", "0", "--phase", "mie", "--droplet-diameter", "20"] + depth, cs, ps)
    _case(f"draine_{suffix}", "cycles",
          VIEW + SUN + ["--sun-angle", "0", "--phase", "draine", "--g", "0.5", "--draine-alpha", "1"] + depth, cs, ps)
    _case(f"hg2_{suffix}", "mitsuba",
          VIEW + SUN + ["--sun-angle", "0", "--phase", "hg2", "--g", "0.8", "--g2", "-0.3", "--lobe-weight", "0.8"]
          + depth, cs, ms)
    _case(f"rayleigh_{suffix}", "mitsuba", VIEW + SUN + ["--sun-angle", "0", "--phase", "rayleigh"] + depth, cs, ms)
    # Forward enough (g 0.8) that `--sunward auto` scatters toward the sun at every vertex.
    _case(f"hg08_sunsky_{suffix}", "cycles", VIEW + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.8"] + depth,
          cs, ps)

# Diagnostics: the sun alone (no sky), single scattering, delta sun, HG against Mie: the sun's
# single scattering at one fixed scattering angle per pixel isolates the phase function's value.
NOSKY = [f if f != "0.16,0.22,0.34" else "0,0,0" for f in VIEW]
_case("hg_sunonly_ss", "cycles", NOSKY + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.5", "--max-depth", "1"],
      256, 128)
_case("mie10_sunonly_ss", "cycles",
      NOSKY + SUN + ["--sun-angle", "0", "--phase", "mie", "--droplet-diameter", "10", "--max-depth", "1"], 256, 128)
_case("draine_sunonly_ss", "cycles",
      NOSKY + SUN + ["--sun-angle", "0", "--phase", "draine", "--g", "0.5", "--draine-alpha", "1", "--max-depth", "1"],
      256, 128)

# Chromatic media (extinction per RGB channel) against Mitsuba's volpathmis (spectral MIS), HG g 0.5,
# delta sun + sky.  Density scale 0.8,0.5,0.25 (channels 3.2x apart; the grey cases use 0.5) and
# albedo 0.95,0.9,0.8.  Mitsuba's single global majorant makes it ~15x slower per sample than
# cirrus on this cloud: few spp per run (the ratios' standard errors come from all pixels).
RGB_VIEW = [{"0.5": "0.8,0.5,0.25", "0.9": "0.95,0.9,0.8"}.get(f, f) if i > 0 and VIEW[i - 1] in
            ("--density-scale", "--albedo") else f for i, f in enumerate(VIEW)]
_case("rgb_ms", "mitsuba", RGB_VIEW + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.5"], 128, 16)
_case("rgb_ss", "mitsuba", RGB_VIEW + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.5", "--max-depth", "1"],
      1024, 128)
# The same chromatic image against three grey renders (channel c: density scale and albedo of channel c):
# Mitsuba's plain volpath per channel (no spectral MIS, so none of volpathmis's heavy tails), and cirrus's own
# grey (delta tracking) code per channel (other seeds, 101..), which tests spectral tracking directly.
_case("rgb_ms_split", "mitsuba", RGB_VIEW + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.5"], 128, 16,
      split=True)
_case("rgb_ms_cgrey", "cirrus", RGB_VIEW + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.5"], 128, 64,
      split=True)
_case("rgb_ss_split", "mitsuba",
      RGB_VIEW + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.5", "--max-depth", "1"], 1024, 128, split=True)
_case("rgb_ss_cgrey", "cirrus",
      RGB_VIEW + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.5", "--max-depth", "1"], 1024, 512, split=True)


def channel_flags(flags: list, c: int) -> list:
    """A chromatic case's flags with --density-scale and --albedo reduced to channel c (grey)."""
    out = list(flags)
    for i, f in enumerate(out[:-1]):
        if f in ("--density-scale", "--albedo") and "," in out[i + 1]:
            out[i + 1] = out[i + 1].split(",")[c]
    return out


def log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", flush=True)


def loadavg() -> float:
    return os.getloadavg()[0]


def run(cmd: list, env=None) -> dict:
    """Runs a renderer under nice; returns wall and CPU (user + sys of the child) seconds and
    the load average before and after."""
    cmd = ["nice", "-n", "5"] + [str(c) for c in cmd]
    log("$ " + " ".join(cmd))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    l0, t0 = loadavg(), time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.stderr.write(p.stdout[-4000:] + p.stderr[-4000:])
        raise RuntimeError(f"command failed ({p.returncode}): {' '.join(cmd)}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall": wall, "cpu": cpu, "load_before": l0, "load_after": loadavg(), "stdout": p.stdout[-2000:]}


def read_rgb(path) -> np.ndarray:
    import compare_images

    return compare_images.read_exr(str(path))[..., :3]


# --------------------------------------------------------------------------- renderers

class Renderers:
    def __init__(self, args):
        self.cirrus = args.cirrus
        self.bpy_python = args.bpy_python
        self.mi_python = args.mi_python
        self.threads = args.threads

    def cirrus_run(self, flags, out: Path, spp: int, seed: int, extra=(), env=None) -> dict:
        stats = out.with_suffix(".stats.json")
        r = run([self.cirrus, "render", CLOUD, "-o", out, "--spp", spp, "--seed", seed, "--stats", stats,
                 *flags, *extra], env=env)
        s = json.loads(stats.read_text())
        r.update({"render_seconds": s.get("wall_seconds"), "load_seconds": s.get("load_seconds"),
                  "denoise_seconds": s.get("denoise_seconds")})
        return r

    def cycles_runs(self, flags, pattern: Path, spp: int, seeds, extra=()) -> dict:
        js = Path(str(pattern).replace("{seed}", "x")).with_suffix(".json")
        r = run([self.bpy_python, TOOLS / "cycles_peer.py", CLOUD, "-o", pattern, "--spp", spp,
                 "--seeds", ",".join(str(s) for s in seeds), "--threads", self.threads, "--json", js,
                 "--quiet", *flags, *extra])
        r["cycles"] = json.loads(js.read_text())
        return r

    def mitsuba_run(self, flags, vol: Path, out: Path, spp: int, seed: int) -> dict:
        js = out.with_suffix(".json")
        r = run([self.mi_python, TOOLS / "mitsuba_render.py", vol, "-o", out, "--spp", spp, "--seed", seed,
                 "--threads", self.threads, "--alpha", "none", "--json", js, "--quiet", *flags])
        r["mitsuba"] = json.loads(js.read_text())
        return r


# --------------------------------------------------------------------------- statistics

def box3(x: np.ndarray) -> np.ndarray:
    """3x3 box mean over the first two axes, edges reflected."""
    p = np.pad(x, ((1, 1), (1, 1)) + ((0, 0),) * (x.ndim - 2), mode="reflect")
    h, w = x.shape[:2]
    return sum(p[i:i + h, j:j + w] for i in range(3) for j in range(3)) / 9.0


def side_stats(runs: np.ndarray) -> dict:
    """runs: (K, H, W, 3).  Mean, variance of the mean (raw and 3x3-smoothed), dof."""
    k = runs.shape[0]
    mean = runs.mean(axis=0)
    var = runs.var(axis=0, ddof=1) / k
    return {"k": k, "mean": mean, "var": var, "var_s": box3(var), "dof": 9 * (k - 1)}


def t_tail(x: float, dof: float) -> float:
    import compare_images

    return compare_images.t_two_sided_tail(x, dof)


def compare_sides(a: dict, b: dict) -> dict:
    """b is the peer, a is cirrus."""
    out = {"channels": {}}
    for c, name in enumerate("RGB"):
        ma, mb = a["mean"][..., c], b["mean"][..., c]
        va, vb = a["var"][..., c], b["var"][..., c]
        vsa, vsb = a["var_s"][..., c], b["var_s"][..., c]
        n = ma.size
        Ma, Mb = ma.mean(), mb.mean()
        sea, seb = math.sqrt(va.sum()) / n, math.sqrt(vb.sum()) / n
        ratio = Mb / Ma
        se_ratio = ratio * math.sqrt((sea / Ma) ** 2 + (seb / Mb) ** 2)
        # Float rounding floor: Cycles' film accumulates the plain sky to 0.15999992 where cirrus writes
        # 0.16 (a 5e-7 relative difference with a "variance" of 1e-16): not noise, not bias.
        floor = (2e-6 * np.maximum(np.abs(ma), 1e-3)) ** 2
        noisy = (va + vb) > floor
        exact_bad = int((np.abs(mb - ma)[~noisy] > 1e-4 * np.maximum(np.abs(ma[~noisy]), 1e-3)).sum())
        var = vsa + vsb + floor
        # The same ratio over the cloud's pixels only (noisy in either renderer), undiluted by the sky.
        m = noisy
        Ca, Cb = ma[m].mean(), mb[m].mean()
        csa, csb = math.sqrt(va[m].sum()) / m.sum(), math.sqrt(vb[m].sum()) / m.sum()
        cratio = Cb / Ca
        cratio_se = cratio * math.sqrt((csa / Ca) ** 2 + (csb / Cb) ** 2)
        ok = noisy & (var > 0)
        z = np.zeros_like(ma)
        z[ok] = (mb - ma)[ok] / np.sqrt(var[ok])
        # Welch dof of the smoothed variances.
        dof = (var[ok] ** 2) / (vsa[ok] ** 2 / a["dof"] + vsb[ok] ** 2 / b["dof"])
        dof_med = float(np.median(dof)) if ok.any() else float("inf")
        exp3, exp4 = t_tail(3.0, dof_med), t_tail(4.0, dof_med)
        zz = z[ok]
        # 8x8 blocks: mean difference over the block against its raw-variance standard error.
        hb, wb = ma.shape[0] // 8, ma.shape[1] // 8

        def blocks(x):
            return x[:hb * 8, :wb * 8].reshape(hb, 8, wb, 8).mean(axis=(1, 3))

        bd = blocks(mb - ma)
        bv = blocks(va + vb) / 64.0
        bok = blocks((va + vb) > floor) > 0.5  # blocks mostly of noisy pixels
        bv = bv + blocks(floor)
        bz = bd[bok] / np.sqrt(bv[bok])
        out["channels"][name] = {
            "mean_cirrus": float(Ma), "mean_peer": float(Mb), "se_cirrus": sea, "se_peer": seb,
            "ratio": float(ratio), "ratio_se": float(se_ratio), "ratio_z": float((ratio - 1) / se_ratio),
            "cloud_mean_cirrus": float(Ca), "cloud_mean_peer": float(Cb), "cloud_ratio": float(cratio),
            "cloud_ratio_se": float(cratio_se), "cloud_ratio_z": float((cratio - 1) / cratio_se),
            "noisy_pixels": int(ok.sum()), "noiseless_pixels": int((~noisy).sum()), "noiseless_mismatch": exact_bad,
            "frac_z3": float((np.abs(zz) > 3).mean()), "frac_z4": float((np.abs(zz) > 4).mean()),
            "expected_z3": exp3, "expected_z4": exp4, "dof_median": dof_med,
            "mean_z": float(zz.mean()), "mean_z2": float((zz * zz).mean()),
            "blocks": int(bok.sum()), "blocks_z4": int((np.abs(bz) > 4).sum()),
            "block_mean_z2": float((bz * bz).mean()) if bz.size else 0.0,
            "rel_rmse_of_means": float(np.sqrt(np.mean((mb - ma) ** 2)) / Ma),
        }
        out.setdefault("z_map", []).append(z)
    zmap = np.mean(out.pop("z_map"), axis=0)
    out["z_rgb_mean_map"] = zmap
    ch = out["channels"].values()
    agree = all(abs(c["ratio_z"]) <= 5 and abs(c["cloud_ratio_z"]) <= 5 and c["frac_z4"] <= max(3 * c["expected_z4"], 0.005)
                and c["blocks_z4"] <= max(2, 0.02 * c["blocks"]) and c["noiseless_mismatch"] == 0 for c in ch)
    out["verdict"] = "AGREE" if agree else "DIFFER"
    return out


def write_z_png(path: Path, z: np.ndarray) -> None:
    import compare_images

    compare_images.write_png_rgb(str(path), compare_images.z_to_rgb(z, 4.0))


# --------------------------------------------------------------------------- agree

def agree(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    R = Renderers(args)
    names = args.cases or list(CASES)
    results_path = out / "results.json"
    results = json.loads(results_path.read_text()) if results_path.exists() else {}
    vol = out / "cloud.vol"
    if any(CASES[n]["peer"] == "mitsuba" for n in names) and not vol.exists():
        run([args.mi_python, TOOLS / "vdb_to_mitsuba_vol.py", CLOUD, vol])
    k = args.runs
    for name in names:
        case = CASES[name]
        flags = case["flags"]
        scale = 0.25 if args.quick else 1.0
        cspp = max(1, int(case["cirrus_spp"] * scale))
        pspp = max(1, int(case["peer_spp"] * scale))
        seeds = list(range(1, k + 1))
        timing = {"cirrus": [], "peer": []}
        cfiles = []
        for s in seeds:
            f = out / f"{name}_cirrus_{s}.exr"
            if not f.exists():
                timing["cirrus"].append(R.cirrus_run(flags, f, cspp, s))
            cfiles.append(f)
        if case.get("split"):
            # One grey render per channel and seed; the peer image of seed s takes channel c from render c.
            pfiles = []
            for s in seeds:
                per = []
                for c, ch in enumerate("RGB"):
                    f = out / f"{name}_{case['peer']}_{s}_{ch}.exr"
                    if not f.exists():
                        cf = channel_flags(flags, c)
                        if case["peer"] == "mitsuba":
                            timing["peer"].append(R.mitsuba_run(cf, vol, f, pspp, s))
                        else:  # cirrus's grey code, seeds independent of the chromatic side's
                            timing["peer"].append(R.cirrus_run(cf, f, pspp, 100 + s))
                    per.append(f)
                pfiles.append(per)
        elif case["peer"] == "cycles":
            pattern = out / f"{name}_cycles_{{seed}}.exr"
            pfiles = [Path(str(pattern).replace("{seed}", str(s))) for s in seeds]
            if not all(f.exists() for f in pfiles):
                timing["peer"].append(R.cycles_runs(flags, pattern, pspp, seeds))
        else:
            pfiles = []
            for s in seeds:
                f = out / f"{name}_mitsuba_{s}.exr"
                if not f.exists():
                    timing["peer"].append(R.mitsuba_run(flags, vol, f, pspp, s))
                pfiles.append(f)
        a = side_stats(np.stack([read_rgb(f) for f in cfiles]))
        b = side_stats(np.stack([np.stack([read_rgb(f[c])[..., c] for c in range(3)], axis=-1)
                                 if isinstance(f, list) else read_rgb(f) for f in pfiles]))
        cmp = compare_sides(a, b)
        write_z_png(out / f"{name}_z.png", cmp.pop("z_rgb_mean_map"))
        prev = results.get(name, {})
        cmp.update({"peer": case["peer"] + (" (grey per channel)" if case.get("split") else ""), "flags": flags, "cirrus_spp": cspp, "peer_spp": pspp, "runs": k,
                    "timing": {kk: [{x: y for x, y in t.items() if x not in ("stdout", "cycles", "mitsuba")}
                                    for t in v] for kk, v in timing.items()} if any(timing.values())
                    else prev.get("timing")})
        results[name] = cmp
        results_path.write_text(json.dumps(results, indent=2) + "\n")
        c = cmp["channels"]
        log(f"{name}: {case['peer']}/cirrus on the cloud R {c['R']['cloud_ratio']:.4f}+-{c['R']['cloud_ratio_se']:.4f} "
            f"G {c['G']['cloud_ratio']:.4f} B {c['B']['cloud_ratio']:.4f}; |z|>4 {100 * c['G']['frac_z4']:.2f}% "
            f"(noise {100 * c['G']['expected_z4']:.2f}%), blocks {c['G']['blocks_z4']}/{c['G']['blocks']} -> "
            f"{cmp['verdict']}")
    table = agree_table(results) + "\nPer channel:\n\n" + channel_table(results)
    (out / "summary.md").write_text(table)
    print(table)
    return 0


def agree_table(results: dict) -> str:
    lines = ["| case | peer | spp x runs (cirrus / peer) | peer / cirrus, cloud pixels' mean, R G B (+- 1 s.e. of G) | "
             "z of G | pixels |z|>3 (noise) | pixels |z|>4 (noise) | 8x8 blocks |z|>4 | verdict |",
             "|---|---|---|---|---:|---|---|---|---|"]
    for name, r in results.items():
        c = r["channels"]
        rat = " ".join(f"{c[ch]['cloud_ratio']:.4f}" for ch in "RGB")
        g = c["G"]
        lines.append(
            f"| {name} | {r['peer']} | {r['cirrus_spp']}x{r['runs']} / {r['peer_spp']}x{r['runs']} | {rat} "
            f"(+- {g['cloud_ratio_se']:.4f}) | {g['cloud_ratio_z']:+.1f} | "
            f"{100 * g['frac_z3']:.2f}% ({100 * g['expected_z3']:.2f}%) | "
            f"{100 * g['frac_z4']:.3f}% ({100 * g['expected_z4']:.3f}%) | {g['blocks_z4']}/{g['blocks']} | "
            f"{r['verdict']} |")
    return "\n".join(lines) + "\n"


def channel_table(results: dict) -> str:
    """Every channel's ratio with its own standard error and z (chromatic cases differ per channel)."""
    lines = ["| case | peer | spp x runs (cirrus / peer) | R: peer / cirrus +- s.e. (z) | G | B | "
             "pixels |z|>4 R/G/B (noise) | 8x8 blocks |z|>4 R/G/B | verdict |", "|---|---|---|---|---|---|---|---|---|"]
    for name, r in results.items():
        c = r["channels"]
        rat = [f"{c[ch]['cloud_ratio']:.4f} +- {c[ch]['cloud_ratio_se']:.4f} ({c[ch]['cloud_ratio_z']:+.1f})" for ch in "RGB"]
        z4 = "/".join(f"{100 * c[ch]['frac_z4']:.2f}%" for ch in "RGB")
        bl = "/".join(str(c[ch]["blocks_z4"]) for ch in "RGB")
        lines.append(f"| {name} | {r['peer']} | {r['cirrus_spp']}x{r['runs']} / {r['peer_spp']}x{r['runs']} | "
                     f"{' | '.join(rat)} | {z4} ({100 * c['G']['expected_z4']:.2f}%) | {bl} of {c['G']['blocks']} | "
                     f"{r['verdict']} |")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- efficiency

EFF_FLAGS = VIEW + SUN + ["--sun-angle", "0.53", "--phase", "hg", "--g", "0.5"]
# A thick, bright cloud, the regime of production cumulus: the same cloud (optical depth ~24
# through its core), albedo 0.999, HG g 0.8, a delta sun and the sky.
THICK_FLAGS = [f for f in VIEW] + SUN + ["--sun-angle", "0", "--phase", "hg", "--g", "0.8"]
THICK_FLAGS[THICK_FLAGS.index("--albedo") + 1] = "0.999"
# The same thin cloud under the constant sky alone (the agreement case hg_sky_ms).
SKY_FLAGS = VIEW + ["--no-sun", "--phase", "hg", "--g", "0.5"]
# The README's default cloud (its own camera, sun and sky) at 128x128: cirrus only, its lights
# are not mapped to Cycles here.
DEFAULT_FLAGS = ["--res", "128x128"]
SCENES = {"sunsky": EFF_FLAGS, "thick": THICK_FLAGS, "sky": SKY_FLAGS, "default": DEFAULT_FLAGS}


def efficiency(args) -> int:
    flags = SCENES[args.scene]
    # Labelled configurations: cirrus's (label=extra flags) and Cycles' (unguided, and guided
    # with --cycles-guiding: the better of the two is the peer).
    cirrus_configs = [c.split("=", 1) for c in args.cirrus_config] or [["cirrus", ""]]
    cycles_configs = [["cycles", []]] + ([["cycles-guided", ["--guiding"]]] if args.cycles_guiding else [])
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    R = Renderers(args)
    results_path = out / "results.json"
    res = json.loads(results_path.read_text()) if results_path.exists() else {"runs": []}
    done = {(r["renderer"], r["spp"], r["denoise"]) for r in res["runs"]}

    def save():
        results_path.write_text(json.dumps(res, indent=2) + "\n")

    # Reference: two long cirrus renders (seeds 1001, 1002).
    ref_spp = args.ref_spp
    refs = []
    for s in (1001, 1002):
        f = out / f"ref_{s}.exr"
        if not f.exists():
            t = R.cirrus_run(flags, f, ref_spp, s)
            res.setdefault("reference_timing", []).append({x: y for x, y in t.items() if x != "stdout"})
            save()
        refs.append(read_rgb(f))
    ref = 0.5 * (refs[0] + refs[1])
    # MSE(A, B) = 2 var(one ref) per pixel; var of the mean of the two = MSE(A, B) / 4.
    ref_var = float(np.mean((refs[0] - refs[1]) ** 2) / 4.0)
    res["reference"] = {"spp_each": ref_spp, "seeds": [1001, 1002], "mean_rgb": ref.reshape(-1, 3).mean(0).tolist(),
                        "noise_mse": ref_var}
    save()
    if args.refs_only:
        log(f"reference done: noise MSE {ref_var:.3e}")
        return 0
    env = dict(os.environ)
    oidn = os.environ.get("CIRRUS_OIDN")

    def record(renderer, spp, denoise, f, t, cycles_render=None):
        img = read_rgb(f)
        mse_raw = float(np.mean((img - ref) ** 2))
        mse = mse_raw - ref_var
        if cycles_render is not None:
            wall, cpu = cycles_render["wall_seconds"], cycles_render["cpu_seconds"]
        else:
            wall, cpu = t["wall"], t["cpu"]
        row = {"renderer": renderer, "spp": spp, "denoise": denoise, "file": str(f), "mse_raw": mse_raw,
               "mse": mse, "rel_rmse": math.sqrt(max(mse, 0)) / float(ref.mean()), "wall": wall, "cpu": cpu,
               "process_wall": t["wall"], "process_cpu": t["cpu"], "load_before": t["load_before"],
               "load_after": t["load_after"], "render_seconds": t.get("render_seconds"),
               "denoise_seconds": t.get("denoise_seconds")}
        row["eff_cpu"] = 1.0 / (mse * cpu) if mse > 0 else None
        row["eff_wall"] = 1.0 / (mse * wall) if mse > 0 else None
        res["runs"].append(row)
        save()
        log(f"{renderer} spp {spp} denoise {denoise}: MSE {mse:.3e} (raw {mse_raw:.3e}), {cpu:.1f} s CPU, "
            f"{wall:.1f} s wall, load {t['load_before']:.1f}->{t['load_after']:.1f}")

    for denoise in ([False, True] if not args.no_denoise else [False]):
        for label, extra_flags in cirrus_configs:
            for spp in args.cirrus_spp:
                if (label, spp, denoise) in done:
                    continue
                f = out / f"{label}_{spp}{'_dn' if denoise else ''}.exr"
                extra = extra_flags.split() + (["--denoise"] if denoise else [])
                if denoise and not oidn:
                    raise SystemExit("set CIRRUS_OIDN=$(bash tools/oidn.sh /work/peer/oidn-venv/bin/python) for --denoise")
                t = R.cirrus_run(flags, f, spp, 7, extra=extra, env=env)
                record(label, spp, denoise, f, t)
        for label, extra_flags in cycles_configs:
            for spp in args.cycles_spp:
                if (label, spp, denoise) in done:
                    continue
                pattern = out / f"{label}_{spp}{'_dn' if denoise else ''}_{{seed}}.exr"
                extra = extra_flags + (["--denoise", "--denoise-passes", args.cycles_denoise_passes] if denoise else [])
                t = R.cycles_runs(flags, pattern, spp, [7], extra=extra)
                record(label, spp, denoise, Path(str(pattern).replace("{seed}", "7")), t,
                       cycles_render=t["cycles"]["renders"][0])
    # Fixed costs: a 1-spp render of each.
    if "fixed" not in res:
        f = out / "cycles_fixed_{seed}.exr"
        t = R.cycles_runs(flags, f, 1, [7, 8, 9])
        rr = t["cycles"]["renders"]
        fc = out / "cirrus_fixed.exr"
        tc = R.cirrus_run(flags, fc, 1, 7)
        res["fixed"] = {"cycles_1spp_wall": [r["wall_seconds"] for r in rr],
                        "cycles_1spp_cpu": [r["cpu_seconds"] for r in rr],
                        "cycles_process_wall": t["wall"], "cycles_build_seconds": t["cycles"]["build_seconds"],
                        "cirrus_1spp_wall": tc["wall"], "cirrus_1spp_cpu": tc["cpu"],
                        "cirrus_load_seconds": tc.get("load_seconds"), "load": [t["load_before"], tc["load_after"]]}
        save()
    (out / "summary.md").write_text(efficiency_table(res))
    print(efficiency_table(res))
    return 0


def efficiency_table(res: dict) -> str:
    lines = ["| renderer | OIDN | spp | MSE (ref. noise subtracted) | rel. RMSE | CPU s | wall s | load before/after | "
             "1/(MSE x CPU s) | 1/(MSE x wall s) |", "|---|---|---:|---:|---:|---:|---:|---|---:|---:|"]
    for r in sorted(res["runs"], key=lambda r: (r["denoise"], r["renderer"], r["spp"])):
        e1 = f"{r['eff_cpu']:.3g}" if r["eff_cpu"] else "-"
        e2 = f"{r['eff_wall']:.3g}" if r["eff_wall"] else "-"
        lines.append(f"| {r['renderer']} | {'on' if r['denoise'] else 'off'} | {r['spp']} | {r['mse']:.3e} | "
                     f"{100 * r['rel_rmse']:.2f}% | {r['cpu']:.1f} | {r['wall']:.1f} | "
                     f"{r['load_before']:.1f}/{r['load_after']:.1f} | {e1} | {e2} |")
    ref = res.get("reference", {})
    lines.append("")
    lines.append(f"Reference: 2 x {ref.get('spp_each')} spp cirrus (seeds 1001, 1002); its own noise "
                 f"(MSE of the mean of the two) {ref.get('noise_mse', float('nan')):.3e}, subtracted above.")
    if "fixed" in res:
        fx = res["fixed"]
        lines.append(f"Fixed cost: Cycles 1-spp render {min(fx['cycles_1spp_wall']):.2f}-{max(fx['cycles_1spp_wall']):.2f} s "
                     f"wall, {min(fx['cycles_1spp_cpu']):.2f}-{max(fx['cycles_1spp_cpu']):.2f} s CPU (after "
                     f"{fx['cycles_build_seconds']:.2f} s building the scene in bpy); cirrus 1-spp process "
                     f"{fx['cirrus_1spp_wall']:.2f} s wall, {fx['cirrus_1spp_cpu']:.2f} s CPU.")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- main

def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    default_cirrus = "/tmp/cirrus-peer/cirrus" if Path("/tmp/cirrus-peer/cirrus").exists() else \
        str(REPO / "target" / "release" / "cirrus")
    ap.add_argument("--cirrus", default=default_cirrus)
    ap.add_argument("--bpy-python", default="/work/peer/bpy-venv/bin/python")
    ap.add_argument("--mi-python", default="/work/peer/mi-venv/bin/python")
    ap.add_argument("--threads", type=int, default=2)
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("agree", help="agreement within noise, per case")
    a.add_argument("--out", required=True)
    a.add_argument("--cases", nargs="*", choices=list(CASES), default=None)
    a.add_argument("--runs", type=int, default=4, help="independent renders (seeds 1..K) per renderer")
    a.add_argument("--quick", action="store_true", help="a quarter of the samples")
    e = sub.add_parser("efficiency", help="MSE x time against a converged reference, unbiased and with OIDN")
    e.add_argument("--out", required=True)
    e.add_argument("--ref-spp", type=int, default=2048)
    e.add_argument("--cirrus-spp", type=int, nargs="+", default=[64, 256, 1024])
    e.add_argument("--cycles-spp", type=int, nargs="+", default=[16, 64, 256])
    e.add_argument("--no-denoise", action="store_true")
    e.add_argument("--cycles-denoise-passes", default="RGB_ALBEDO_NORMAL",
                   help="Cycles' denoising_input_passes (RGB_ALBEDO_NORMAL: albedo and normal, as a user sets it)")
    e.add_argument("--scene", choices=list(SCENES), default="sunsky",
                   help="sunsky: HG g 0.5, albedo 0.9, sun 0.53 deg + sky; thick: albedo 0.999, HG g 0.8, delta sun + sky")
    e.add_argument("--cirrus-config", action="append", default=[], metavar="LABEL=FLAGS",
                   help="a cirrus configuration to measure (repeatable), e.g. 'cirrus-one=--light-sampling one'; "
                        "default: cirrus with its defaults")
    e.add_argument("--cycles-guiding", action="store_true",
                   help="also measure Cycles with its OpenPGL volume guiding (cycles_peer.py --guiding)")
    e.add_argument("--refs-only", action="store_true", help="render the reference only (not timing-sensitive)")
    sub.add_parser("list", help="print the cases")
    args = ap.parse_args(argv)
    if args.cmd == "list":
        for n, c in CASES.items():
            print(f"{n:16s} {c['peer']:8s} cirrus {c['cirrus_spp']} spp, peer {c['peer_spp']} spp: {' '.join(c['flags'])}")
        return 0
    if np is None:
        sys.exit(f"{__file__}: numpy is missing for {sys.executable}; run with /work/peer/bpy-venv/bin/python")
    if not shutil.which(args.cirrus) and not Path(args.cirrus).exists():
        sys.exit(f"no cirrus binary at {args.cirrus}")
    return agree(args) if args.cmd == "agree" else efficiency(args)


if __name__ == "__main__":
    sys.exit(main())

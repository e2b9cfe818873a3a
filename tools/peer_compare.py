#!/usr/bin/python3
"""End-to-end peer comparison: the same scenes rendered by Mitsuba 3 and by `cirrus render`.

Usage (Debian's /usr/bin/python3 with pyopenvdb + mitsuba; see tools/README.md):

    /usr/bin/python3 tools/peer_compare.py --out /tmp/peer            # everything, ~15 min on 2 idle cores
    /usr/bin/python3 tools/peer_compare.py --out /tmp/peer --quick    # 1/8 of the samples, ~3 min
    /usr/bin/python3 tools/peer_compare.py --cases box cloud --skip-series
    /usr/bin/python3 tools/peer_compare.py --skip-cirrus              # the Mitsuba half only

For every case it converts the .vdb to a .vol (tools/vdb_to_mitsuba_vol.py, checked by
sampling), renders it with tools/mitsuba_render.py (K batches: mean + per-pixel standard
error) and with cirrus (K runs with seeds 1..K: mean and standard error from the spread),
one renderer at a time, then runs tools/compare_images.py.  Then an error-vs-time series:
each renderer at spp 1, 2, 4, ... timed, RMSE against the converged Mitsuba image of the
case (with the reference's own noise subtracted as well as raw), written to
OUT/error_vs_time.csv.  OUT/summary.md and OUT/summary.json collect the results.

cirrus: target/release/cirrus if it exists and has the `render` subcommand, else
`cargo run --release -p cirrus-cli --`; or --cirrus PATH.  The two renderers never run
at the same time.  Each renderer's threads: --threads (default 2).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

try:
    import numpy as np
except ImportError:
    sys.exit(f"{__file__}: numpy is missing for {sys.executable}; run the peer tools with Debian's "
             "/usr/bin/python3 (apt-get install -y python3-numpy python3-openvdb; see tools/README.md)")

sys.dont_write_bytecode = True
TOOLS = Path(__file__).resolve().parent
REPO = TOOLS.parent
sys.path.insert(0, str(TOOLS))
import compare_images  # noqa: E402

# Every scene parameter is passed explicitly to both renderers, so a change of cirrus's
# defaults cannot make the two renders silently differ.
COMMON = ["--camera-up", "0,1,0", "--fov", "40", "--sun-angle", "0", "--sun-irradiance", "2.6,2.5,2.3",
          "--env-radiance", "0.16,0.22,0.34", "--albedo", "0.99", "--g", "0.8"]
BOX_VIEW = ["--res", "64x64", "--camera-from", "-150,200,-200", "--camera-to", "64,64,64", "--sun-dir", "-0.5,-0.6,0.62"]
CLOUD_VIEW = ["--res", "64x64", "--camera-from", "150,83,-250", "--camera-to", "150,83,100",
              "--sun-dir", "-0.45,-0.6,-0.66"]

# name: (file, scene flags for both renderers, mitsuba spp, mitsuba batches, cirrus spp per run, cirrus runs)
CASES = {
    # The constant box (density 0.5, optical depth 64 across), seen from above-left-front so three
    # faces and their edges show; sun from behind the camera's right shoulder.
    "box": ("data/tile_box.vdb", BOX_VIEW + COMMON + ["--density-scale", "1"], 2048, 16, 128, 8),
    # The same box thinned 50x (optical depth 1.28 across) with --max-depth 0: the sky through the
    # volume's transmittance only (checks transmittance, the density at the edges and the depth mapping).
    "box_md0": ("data/tile_box.vdb", BOX_VIEW + COMMON + ["--density-scale", "0.02", "--max-depth", "0"],
                1024, 8, 64, 8),
    # The production-like cloud, backlit (the sun travels toward -z, the camera looks along +z).
    "cloud": ("data/cloud.vdb", CLOUD_VIEW + COMMON + ["--density-scale", "1"], 192, 8, 128, 8),
    # Single scattering of the same cloud (checks the max-depth mapping with the sun).
    "cloud_md1": ("data/cloud.vdb", CLOUD_VIEW + COMMON + ["--density-scale", "1", "--max-depth", "1"], 512, 8, 64, 8),
}
# Mitsuba's Russian roulette (survival min(throughput, 0.95) from rr_depth on) multiplies the
# weight of paths of throughput ~1 by 1/0.95 per scattering event: with albedo 0.99 its default
# rr_depth 5 gives fireflies of 100x the pixel mean.  The references use 256 (light tails, so the
# batch standard errors mean something); the series shows both Mitsuba as shipped and rr_depth 64.
REFERENCE_RR_DEPTH = 256
SERIES_MITSUBA = {"mitsuba_rr5_default": 5, "mitsuba_rr64": 64}
SERIES_CASES = ("box", "cloud")
SERIES_MAX_SPP = {"box": 1024, "cloud": 256}


def log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", flush=True)


def run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    log("$ " + " ".join(str(c) for c in cmd))
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if p.returncode != 0:
        sys.stderr.write(p.stdout + p.stderr)
        raise RuntimeError(f"command failed ({p.returncode}): {' '.join(str(c) for c in cmd)}")
    return p


def find_cirrus(explicit: str | None) -> list[str] | None:
    if explicit:
        return [explicit]
    exe = REPO / "target" / "release" / "cirrus"
    if exe.exists():
        p = subprocess.run([str(exe), "render", "--help"], capture_output=True, text=True)
        if p.returncode == 0:
            return [str(exe)]
    if shutil.which("cargo"):
        return ["cargo", "run", "--quiet", "--release", "-p", "cirrus-cli", "--"]
    return None


def mitsuba_case(out: Path, name: str, vol: Path, flags, spp, batches, threads, rr_depth, seed=1) -> dict:
    exr, se, js = out / f"{name}_mitsuba.exr", out / f"{name}_mitsuba_se.exr", out / f"{name}_mitsuba.json"
    run([sys.executable, TOOLS / "mitsuba_render.py", vol, "-o", exr, "--png", out / f"{name}_mitsuba.png",
         "--stderr-out", se, "--spp", str(spp), "--batches", str(batches), "--threads", str(threads),
         "--seed", str(seed), "--rr-depth", str(rr_depth), "--json", js, "--quiet", *flags])
    r = json.loads(js.read_text())
    log(f"{name}: mitsuba {r['spp']} spp in {r['render_seconds']:.1f} s (+ alpha {r['alpha_seconds']:.1f} s)")
    return {"exr": str(exr), "stderr": str(se), "dof": batches - 1, "load_avg_1min": load_avg(), **r}


def cirrus_case(out: Path, name: str, cirrus: list[str], file: str, flags, spp, runs) -> dict:
    files, seconds = [], 0.0
    for k in range(1, runs + 1):
        exr, st = out / f"{name}_cirrus_{k}.exr", out / f"{name}_cirrus_{k}.stats.json"
        extra = ["--png", out / f"{name}_cirrus.png"] if k == 1 else []
        run([*cirrus, "render", REPO / file, "-o", exr, "--spp", str(spp), "--seed", str(k), "--stats", st,
             *extra, *flags], cwd=REPO)
        s = json.loads(st.read_text())
        seconds += float(s.get("wall_seconds", math.nan))
        files.append(str(exr))
    log(f"{name}: cirrus {runs} x {spp} spp in {seconds:.1f} s")
    return {"files": files, "spp": spp * runs, "render_seconds": seconds, "runs": runs, "load_avg_1min": load_avg()}


def rmse_against(img: np.ndarray, ref: np.ndarray, ref_se: np.ndarray) -> tuple[float, float, float]:
    """RMSE over R, G, B; the same with the reference's own variance subtracted; relMSE."""
    d = img[..., :3] - ref[..., :3]
    mse = float(np.mean(d * d))
    mse_corr = max(mse - float(np.mean(ref_se[..., :3] ** 2)), 0.0)
    rel = float(np.mean(d * d / (ref[..., :3] ** 2 + 1e-2)))
    return math.sqrt(mse), math.sqrt(mse_corr), rel


def load_avg() -> float:
    """1-minute load average: timings taken while other jobs run are not comparable."""
    try:
        return os.getloadavg()[0]
    except OSError:
        return math.nan


def spp_ladder(max_spp: int) -> list[int]:
    out, n = [], 1
    while n <= max_spp:
        out.append(n)
        n *= 2
    return out


def mitsuba_series(name, vol, flags, max_spp, ref, ref_se, threads, rows, rr_depth, label):
    import mitsuba_render as mr
    import mitsuba_setup

    mi, dr = mitsuba_setup.mitsuba()
    dr.set_thread_count(threads)
    args = mr.parse_args([str(vol), "-o", "/dev/null", "--rr-depth", str(rr_depth), *flags])
    vol_path, hdr = mr.volume_file(args)
    scene, _ = mr.build_scene(mi, args, vol_path, hdr, alpha_pass=False, spp=1)
    np.array(mi.render(scene, seed=999, spp=1))  # warm-up: kernel compilation is not timed
    for spp in spp_ladder(max_spp):
        t0 = time.time()
        img = np.array(mi.render(scene, seed=100_000 + spp, spp=spp), dtype=np.float64)
        sec = time.time() - t0
        rmse, rmse_c, rel = rmse_against(img, ref, ref_se)
        rows.append({"renderer": label, "case": name, "spp": spp, "seconds": sec, "rmse": rmse,
                     "rmse_minus_ref_noise": rmse_c, "rel_mse": rel, "load_avg_1min": load_avg()})
        log(f"series {name} {label} {spp} spp {sec:.2f} s RMSE {rmse:.4g}")


def cirrus_series(out, name, cirrus, file, flags, max_spp, ref, ref_se, rows):
    for spp in spp_ladder(max_spp):
        exr, st = out / f"series_{name}_cirrus.exr", out / f"series_{name}_cirrus.stats.json"
        run([*cirrus, "render", REPO / file, "-o", exr, "--spp", str(spp), "--seed", str(100_000 + spp),
             "--stats", st, *flags], cwd=REPO)
        sec = float(json.loads(st.read_text()).get("wall_seconds", math.nan))
        img = compare_images.read_exr(str(exr))
        rmse, rmse_c, rel = rmse_against(img, ref, ref_se)
        rows.append({"renderer": "cirrus", "case": name, "spp": spp, "seconds": sec, "rmse": rmse,
                     "rmse_minus_ref_noise": rmse_c, "rel_mse": rel, "load_avg_1min": load_avg()})
        log(f"series {name} cirrus {spp} spp {sec:.2f} s RMSE {rmse:.4g}")


def summary_md(results: dict, versions: dict) -> str:
    lines = ["# Mitsuba 3 vs cirrus", "",
             f"Mitsuba {versions.get('mitsuba')} / Dr.Jit {versions.get('drjit')} ({versions.get('variant')}, "
             f"LLVM {versions.get('libllvm')})", "",
             "| case | channel | mitsuba mean | cirrus mean | diff (z) | pixels |z|>4 (noise alone) | "
             "blocks |z|>4 | verdict |",
             "|---|---|---|---|---|---|---|---|"]
    for name, r in results.items():
        cmp = r.get("compare")
        if not cmp:
            continue
        for c, s in cmp["channels"].items():
            b = s.get("blocks", {})
            lines.append(
                f"| {name} | {c} | {s['mean_a']:.5g} | {s['mean_b']:.5g} | "
                f"{100 * (s['rel_mean_diff'] or 0):+.2f}% ({s.get('mean_diff_z', float('nan')):+.1f}) | "
                f"{100 * s.get('exceed_fraction', float('nan')):.2f}% "
                f"({100 * s.get('expected_exceed_fraction', float('nan')):.2f}%) | "
                f"{b.get('exceed_blocks', '-')}/{b.get('blocks', '-')} | {s['verdict']} |")
    lines += ["", f"Wall times on {os.cpu_count()} cores; the load average after each render shows whether "
              "other jobs shared the machine (timings are only comparable near load = threads).", "",
              "| case | mitsuba spp (rr_depth %d) | mitsuba s | load | cirrus spp | cirrus s | load |" % REFERENCE_RR_DEPTH,
              "|---|---|---|---|---|---|---|"]
    for name, r in results.items():
        m, c = r.get("mitsuba", {}), r.get("cirrus", {})
        lines.append(f"| {name} | {m.get('spp', '-')} | {m.get('render_seconds', float('nan')):.1f} | "
                     f"{m.get('load_avg_1min', float('nan')):.1f} | "
                     f"{c.get('spp', '-')} | {c.get('render_seconds', float('nan')):.1f} | "
                     f"{c.get('load_avg_1min', float('nan')):.1f} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="/tmp/cirrus_peer")
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--cirrus", default=None, help="cirrus executable (default: target/release/cirrus or cargo run)")
    ap.add_argument("--skip-cirrus", action="store_true")
    ap.add_argument("--skip-mitsuba", action="store_true", help="reuse the Mitsuba renders already in --out")
    ap.add_argument("--skip-series", action="store_true")
    ap.add_argument("--quick", action="store_true", help="1/8 of the samples everywhere")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    div = 8 if args.quick else 1

    cirrus = None
    if not args.skip_cirrus:
        cirrus = find_cirrus(args.cirrus)
        if cirrus is None:
            log("cirrus not found (no target/release/cirrus with `render`, no cargo): Mitsuba half only")

    import mitsuba_setup

    versions = mitsuba_setup.versions()
    log(f"mitsuba {versions}")
    results: dict = {}
    vols: dict = {}
    for name in args.cases:
        file, flags, m_spp, m_batches, c_spp, c_runs = CASES[name]
        r = results.setdefault(name, {"file": file, "flags": flags})
        vol = out / (Path(file).stem + ".vol")
        if file not in vols:
            p = run([sys.executable, TOOLS / "vdb_to_mitsuba_vol.py", REPO / file, vol, "--check", "2000"])
            r["conversion"] = p.stdout.strip()
            vols[file] = vol
        m_json = out / f"{name}_mitsuba.json"
        if args.skip_mitsuba and m_json.exists():
            mj = json.loads(m_json.read_text())
            r["mitsuba"] = {"exr": str(out / f"{name}_mitsuba.exr"), "stderr": str(out / f"{name}_mitsuba_se.exr"),
                            "dof": m_batches - 1, **mj}
        else:
            r["mitsuba"] = mitsuba_case(out, name, vol, flags, max(m_spp // div, m_batches), m_batches, args.threads,
                                        REFERENCE_RR_DEPTH)
        if cirrus:
            r["cirrus"] = cirrus_case(out, name, cirrus, file, flags, max(c_spp // div, 1), c_runs)
            rep, zs = compare_images.compare([r["mitsuba"]["exr"]], r["cirrus"]["files"], r["mitsuba"]["stderr"],
                                             None, 4.0, ("mitsuba", "cirrus"), r["mitsuba"]["dof"], None, 8)
            compare_images.print_report(rep)
            r["compare"] = rep
            (out / f"{name}_compare.json").write_text(json.dumps(rep, indent=2) + "\n")
            rgbz = [zs[c] for c in "RGB" if zs.get(c) is not None]
            compare_images.write_png_rgb(str(out / f"{name}_z.png"),
                                         compare_images.z_to_rgb(np.mean(rgbz, axis=0), 4.0))
        (out / "summary.json").write_text(json.dumps({"versions": versions, "cases": results}, indent=2) + "\n")

    if not args.skip_series:
        rows: list[dict] = []
        for name in [c for c in SERIES_CASES if c in args.cases]:
            file, flags, *_ = CASES[name]
            ref = compare_images.read_exr(results[name]["mitsuba"]["exr"])
            ref_se = compare_images.read_exr(results[name]["mitsuba"]["stderr"])
            max_spp = max(SERIES_MAX_SPP[name] // div, 1)
            for label, rr in SERIES_MITSUBA.items():
                mitsuba_series(name, vols[file], flags, max_spp, ref, ref_se, args.threads, rows, rr, label)
            if cirrus:
                cirrus_series(out, name, cirrus, file, flags, max_spp, ref, ref_se, rows)
        with open(out / "error_vs_time.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["renderer", "case", "spp", "seconds", "rmse", "rmse_minus_ref_noise",
                                              "rel_mse", "load_avg_1min"])
            w.writeheader()
            w.writerows(rows)
        log(f"wrote {out / 'error_vs_time.csv'} ({len(rows)} rows; reference: each case's converged Mitsuba image)")

    (out / "summary.json").write_text(json.dumps({"versions": versions, "cases": results}, indent=2) + "\n")
    md = summary_md(results, versions)
    (out / "summary.md").write_text(md)
    print(md)
    verdicts = [r["compare"]["verdict"] for r in results.values() if r.get("compare")]
    return 1 if "DIFFER" in verdicts else 0


if __name__ == "__main__":
    sys.exit(main())

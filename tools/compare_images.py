#!/usr/bin/python3
"""Compare two Monte Carlo renders of the same scene pixel by pixel, with noise taken into account.

Usage (any python with numpy plus either mitsuba or the `OpenEXR` pip module to read EXRs):

    # single images, standard errors given as EXRs (tools/mitsuba_render.py --stderr-out)
    /usr/bin/python3 tools/compare_images.py --a m.exr --a-stderr m_se.exr --b c.exr --b-stderr c_se.exr
    # several independent batches per side (e.g. cirrus run with --seed 1..K): mean and
    # standard error are estimated from the batches
    /usr/bin/python3 tools/compare_images.py --a m.exr --a-stderr m_se.exr --b c1.exr c2.exr c3.exr c4.exr \\
        --names mitsuba cirrus --json out.json --z-png z.png

Per channel (R, G, B and alpha, reported separately) it prints the means, the mean
difference b - a with its standard error, RMSE, relative MSE (mean of (b-a)^2 / (a^2 + 1e-2)),
and, when both sides have standard errors, the z-score of every pixel's difference
(z = (b - a) / sqrt(se_a^2 + se_b^2)), the fraction of pixels with |z| > --sigma (default 4)
against the fraction expected from noise alone (Student t with Welch's degrees of freedom
from the batch counts), and mean z^2 (about 1 when the images agree).

It also averages both images over --block x --block pixel blocks (default 8) and
reports the z-scores of the block means (closer to normal, more power against smooth
local biases).

Verdict, per channel: AGREE when the image-mean difference is within 5 standard errors,
the per-pixel |z| > sigma fraction is at most max(3 x expected, 0.5%), noiseless pixels
match, and at most max(2, 2%) of the blocks have |z| > sigma; DIFFER otherwise;
NO-NOISE-ESTIMATE when standard errors are missing (only RMSE/relMSE then).
The thresholds are loose on purpose: per-pixel batch means of volume path tracers are
skewed (rare bright paths), so batch standard errors are underestimated in most pixels
and the Student-t tail is optimistic, more so with few batches or few spp.  Give each
side many spp and >= 8 batches; the image-mean z and the block test are the robust ones.  Exit code 0
for AGREE everywhere, 1 for any DIFFER, 2 for usage errors.
"""

from __future__ import annotations

import argparse
import json
import math
import struct
import sys
import zlib
from pathlib import Path

try:
    import numpy as np
except ImportError:
    sys.exit(f"{__file__}: numpy is missing for {sys.executable}; run the peer tools with Debian's "
             "/usr/bin/python3 (apt-get install -y python3-numpy python3-openvdb; see tools/README.md)")

sys.dont_write_bytecode = True

CHANNELS = ("R", "G", "B", "A")
BATCH_DOF_INFINITE = 1e9  # dof used for a standard error given as a file (from many batches)


# --------------------------------------------------------------------------- EXR reading

def read_exr(path: str) -> np.ndarray:
    """float64 array (h, w, 4) RGBA; alpha NaN when the file has none."""
    try:
        import mitsuba as mi

        if mi.variant() is None:
            mi.set_variant("scalar_rgb")
        bmp = mi.Bitmap(str(path))
        arr = np.array(bmp, dtype=np.float64)
        if arr.ndim == 2:
            arr = arr[..., None]
        if arr.shape[2] == 1:
            arr = np.repeat(arr, 3, axis=2)
        if arr.shape[2] == 3:
            arr = np.concatenate([arr, np.full(arr.shape[:2] + (1,), np.nan)], axis=2)
        return arr[..., :4]
    except ImportError:
        pass
    try:
        import OpenEXR  # 3.x API

        with OpenEXR.File(str(path), separate_channels=True) as f:
            ch = f.channels()
            h, w = next(iter(ch.values())).pixels.shape[:2]
            out = np.full((h, w, 4), np.nan)
            for i, c in enumerate(CHANNELS):
                if c in ch:
                    out[..., i] = ch[c].pixels
            return out
    except ImportError:
        sys.exit("compare_images.py: cannot read EXR: install mitsuba (see tools/README.md) or `pip install OpenEXR`")


def load_side(files: list[str], stderr_file: str | None, stderr_dof: float | None = None):
    """(mean, standard error or None, dof) from one image (+ optional stderr EXR) or K batches."""
    if len(files) == 1:
        mean = read_exr(files[0])
        if stderr_file:
            se = read_exr(stderr_file)
            if se.shape != mean.shape:
                raise SystemExit(f"{stderr_file}: shape {se.shape} differs from {files[0]} {mean.shape}")
            return mean, se, stderr_dof or BATCH_DOF_INFINITE
        return mean, None, None
    if stderr_file:
        raise SystemExit("give either several batch files or one file with --*-stderr, not both")
    stack = np.stack([read_exr(f) for f in files])
    k = len(files)
    return stack.mean(axis=0), np.sqrt(stack.var(axis=0, ddof=1) / k), k - 1


# --------------------------------------------------------------------------- statistics

def t_two_sided_tail(x: float, dof: float) -> float:
    """P(|T| > x) for Student's t with `dof` degrees of freedom (normal for huge dof)."""
    if dof >= 1e6:
        return math.erfc(x / math.sqrt(2.0))
    # Integrate the density from x to infinity after substituting t = x / u, u in (0, 1].
    lg = math.lgamma((dof + 1) / 2) - math.lgamma(dof / 2) - 0.5 * math.log(dof * math.pi)
    n = 4000
    total = 0.0
    for i in range(n):
        u = (i + 0.5) / n
        t = x / u
        total += math.exp(lg - (dof + 1) / 2 * math.log1p(t * t / dof)) * x / (u * u)
    return 2.0 * total / n


def block_stats(a, b, sa, sb, block: int, sigma: float) -> dict | None:
    """z-scores of block means (block x block pixels): averaging makes the noise closer
    to normal and gives power against smooth local biases the per-pixel test misses."""
    h, w = a.shape
    hb, wb = h // block, w // block
    if hb == 0 or wb == 0 or sa is None or sb is None:
        return None
    crop = (slice(0, hb * block), slice(0, wb * block))

    def mean_blocks(x):
        return x[crop].reshape(hb, block, wb, block).mean(axis=(1, 3))

    d = mean_blocks(b) - mean_blocks(a)
    var = mean_blocks(sa * sa + sb * sb) / (block * block)
    ok = np.isfinite(d) & (var > 0)
    z = d[ok] / np.sqrt(var[ok])
    mean_a = mean_blocks(a)[ok]
    return {
        "block": block,
        "blocks": int(ok.sum()),
        "exceed_blocks": int((np.abs(z) > sigma).sum()),
        "mean_z2": float(np.mean(z * z)) if z.size else 0.0,
        "max_abs_z": float(np.abs(z).max()) if z.size else 0.0,
        "max_abs_rel_diff": float(np.max(np.abs(d[ok]) / np.maximum(np.abs(mean_a), 1e-6))) if z.size else 0.0,
    }


def channel_stats(a, b, sa, sb, dof_a, dof_b, sigma):
    finite = np.isfinite(a) & np.isfinite(b)
    a, b = a[finite], b[finite]
    d = b - a
    out = {
        "pixels": int(finite.sum()),
        "mean_a": float(a.mean()),
        "mean_b": float(b.mean()),
        "mean_diff": float(d.mean()),
        "rel_mean_diff": float(d.mean() / a.mean()) if a.mean() != 0 else None,
        "rmse": float(np.sqrt(np.mean(d * d))),
        "rel_mse": float(np.mean(d * d / (a * a + 1e-2))),
        "max_abs_diff": float(np.abs(d).max()),
    }
    if sa is None or sb is None:
        out["verdict"] = "NO-NOISE-ESTIMATE"
        return out, None
    sa, sb = sa[finite], sb[finite]
    var = sa * sa + sb * sb
    se_mean = math.sqrt(var.sum()) / len(d)
    out["mean_diff_stderr"] = se_mean
    out["mean_diff_z"] = float(d.mean() / se_mean) if se_mean > 0 else (0.0 if d.mean() == 0 else math.inf)
    noisy = var > 0
    exact = ~noisy
    # Pixels with no noise on either side (e.g. empty sky) must agree to float precision.
    tol = 1e-5 * np.maximum(np.abs(a[exact]), 1e-3)
    out["noiseless_pixels"] = int(exact.sum())
    out["noiseless_mismatches"] = int((np.abs(d[exact]) > tol).sum())
    z = np.zeros_like(d)
    z[noisy] = d[noisy] / np.sqrt(var[noisy])
    n_noisy = int(noisy.sum())
    exceed = int((np.abs(z[noisy]) > sigma).sum())
    # Expected exceedance: Welch-Satterthwaite dof per pixel, averaged over pixels.
    va, vb = sa[noisy] ** 2, sb[noisy] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        dof = (va + vb) ** 2 / (va * va / dof_a + vb * vb / dof_b)
    dof = np.nan_to_num(dof, nan=BATCH_DOF_INFINITE, posinf=BATCH_DOF_INFINITE)
    # Tail probability on a coarse dof grid (cheap, monotone in dof).
    grid = np.unique(np.clip(np.round(np.minimum(dof, 1e6)), 1, 1e6))
    tails = {g: t_two_sided_tail(sigma, g) for g in grid}
    expected = float(np.mean([tails[g] for g in np.clip(np.round(np.minimum(dof, 1e6)), 1, 1e6)])) if n_noisy else 0.0
    out.update(
        {
            "noisy_pixels": n_noisy,
            "sigma": sigma,
            "exceed_pixels": exceed,
            "exceed_fraction": exceed / n_noisy if n_noisy else 0.0,
            "expected_exceed_fraction": expected,
            "mean_z2": float(np.mean(z[noisy] ** 2)) if n_noisy else 0.0,
            "median_dof": float(np.median(dof)) if n_noisy else None,
            "mean_rel_stderr": float(np.mean(np.sqrt(var[noisy]) / np.maximum(np.abs(a[noisy]), 1e-6)))
            if n_noisy else 0.0,
        }
    )
    ok_mean = abs(out["mean_diff_z"]) <= 5.0
    ok_tail = out["exceed_fraction"] <= max(3.0 * expected, 0.005)
    ok_exact = out["noiseless_mismatches"] == 0
    out["verdict"] = "AGREE" if (ok_mean and ok_tail and ok_exact) else "DIFFER"
    full_z = np.full(finite.shape, np.nan)
    full_z[finite] = z
    return out, full_z


# --------------------------------------------------------------------------- PNG of z-scores

def write_png_rgb(path: str, rgb: np.ndarray) -> None:
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].astype(np.uint8).tobytes() for y in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    Path(path).write_bytes(png)


def z_to_rgb(z: np.ndarray, limit: float) -> np.ndarray:
    """blue (b < a) - white (0) - red (b > a), saturating at +-limit; NaN grey."""
    t = np.clip(np.nan_to_num(z, nan=0.0) / limit, -1, 1)
    r = np.where(t > 0, 1.0, 1.0 + t)
    g = 1.0 - np.abs(t)
    bl = np.where(t < 0, 1.0, 1.0 - t)
    rgb = np.stack([r, g, bl], axis=-1) * 255.0
    rgb[np.isnan(z)] = 128
    return rgb


# --------------------------------------------------------------------------- main

def compare(a_files, b_files, a_se=None, b_se=None, sigma=4.0, names=("a", "b"), a_dof=None, b_dof=None, block=8):
    a, sa, dof_a = load_side(a_files, a_se, a_dof)
    b, sb, dof_b = load_side(b_files, b_se, b_dof)
    if a.shape != b.shape:
        raise SystemExit(f"image shapes differ: {names[0]} {a.shape} vs {names[1]} {b.shape}")
    report = {"a": {"name": names[0], "files": a_files, "stderr": a_se, "dof": dof_a},
              "b": {"name": names[1], "files": b_files, "stderr": b_se, "dof": dof_b},
              "width": a.shape[1], "height": a.shape[0], "channels": {}}
    zs = {}
    for i, c in enumerate(CHANNELS):
        if np.all(np.isnan(a[..., i])) or np.all(np.isnan(b[..., i])):
            continue
        ca, cb = a[..., i], b[..., i]
        csa = None if sa is None else sa[..., i]
        csb = None if sb is None else sb[..., i]
        st, z = channel_stats(ca, cb, csa, csb, dof_a, dof_b, sigma)
        bs = block_stats(ca, cb, csa, csb, block, sigma)
        if bs is not None:
            st["blocks"] = bs
            if bs["exceed_blocks"] > max(2, 0.02 * bs["blocks"]):
                st["verdict"] = "DIFFER"
        report["channels"][c] = st
        zs[c] = z
    verdicts = [s["verdict"] for s in report["channels"].values()]
    report["verdict"] = ("DIFFER" if "DIFFER" in verdicts else
                         "NO-NOISE-ESTIMATE" if "NO-NOISE-ESTIMATE" in verdicts else "AGREE")
    return report, zs


def print_report(r: dict) -> None:
    na, nb = r["a"]["name"], r["b"]["name"]
    print(f"{na} vs {nb}: {r['width']}x{r['height']}")
    for c, s in r["channels"].items():
        line = (f"  {c}: mean {na} {s['mean_a']:.6g} {nb} {s['mean_b']:.6g}  diff {s['mean_diff']:+.4g}")
        if "mean_diff_stderr" in s:
            line += f" +- {s['mean_diff_stderr']:.2g} (z {s['mean_diff_z']:+.2f})"
        if s.get("rel_mean_diff") is not None:
            line += f" = {100 * s['rel_mean_diff']:+.3f}%"
        line += f"  RMSE {s['rmse']:.4g} relMSE {s['rel_mse']:.4g}"
        print(line)
        if "exceed_fraction" in s:
            print(f"     |z|>{s['sigma']:g}: {s['exceed_pixels']}/{s['noisy_pixels']} = {100 * s['exceed_fraction']:.3f}% "
                  f"(noise alone: {100 * s['expected_exceed_fraction']:.3f}%), mean z^2 {s['mean_z2']:.3f}, "
                  f"median dof {s['median_dof']:.3g}, mean rel. stderr {100 * s['mean_rel_stderr']:.2f}%, "
                  f"noiseless pixels {s['noiseless_pixels']} ({s['noiseless_mismatches']} mismatched)")
        if "blocks" in s:
            bs = s["blocks"]
            print(f"     {bs['block']}x{bs['block']} blocks: |z|>{s['sigma']:g} in {bs['exceed_blocks']}/{bs['blocks']}, "
                  f"mean z^2 {bs['mean_z2']:.3f}, max |z| {bs['max_abs_z']:.2f}, "
                  f"max |rel diff| {100 * bs['max_abs_rel_diff']:.2f}%")
        print(f"     -> {s['verdict']}")
    print(f"verdict: {r['verdict']}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Compare two Monte Carlo EXR renders with noise estimates.")
    ap.add_argument("--a", nargs="+", required=True, help="image A (or K batch images)")
    ap.add_argument("--b", nargs="+", required=True, help="image B (or K batch images)")
    ap.add_argument("--a-stderr", default=None, help="per-pixel standard error of A (EXR)")
    ap.add_argument("--b-stderr", default=None, help="per-pixel standard error of B (EXR)")
    ap.add_argument("--a-dof", type=float, default=None,
                    help="degrees of freedom of --a-stderr (batches - 1; default: treated as exact)")
    ap.add_argument("--b-dof", type=float, default=None, help="degrees of freedom of --b-stderr")
    ap.add_argument("--names", nargs=2, default=("a", "b"))
    ap.add_argument("--sigma", type=float, default=4.0)
    ap.add_argument("--block", type=int, default=8, help="block size of the block-mean test")
    ap.add_argument("--json", default=None)
    ap.add_argument("--z-png", default=None, help="write the z-score map of the mean of R,G,B as PNG")
    args = ap.parse_args(argv)
    report, zs = compare(args.a, args.b, args.a_stderr, args.b_stderr, args.sigma, tuple(args.names),
                         args.a_dof, args.b_dof, args.block)
    print_report(report)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    if args.z_png:
        rgbz = [zs[c] for c in "RGB" if zs.get(c) is not None]
        if rgbz:
            write_png_rgb(args.z_png, z_to_rgb(np.mean(rgbz, axis=0), args.sigma))
    return 1 if report["verdict"] == "DIFFER" else 0


if __name__ == "__main__":
    sys.exit(main())

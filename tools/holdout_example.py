"""The README's compositing example, made outside cirrus: a sphere's depth
image for a depth holdout, then the cloud's light groups rebalanced and
composited over the shaded sphere.

    python tools/holdout_example.py depth sphere_z.exr
    cirrus render data/cloud.vdb $CAMERA --holdout-depth sphere_z.exr --aov lights -o held.exr
    python tools/holdout_example.py compose held.exr sphere_z.exr docs/holdout.png --sun 1.6 --sky 0.6

The camera is cirrus's pinhole (`CAMERA` below, the same flags on both
sides); the depth is planar (along the view axis), as Blender's Z pass
writes it, with 1e10 where the sphere is not. Needs numpy and PyPI's
OpenEXR; the PNG is written with zlib alone.
"""

from __future__ import annotations

import argparse
import struct
import zlib

import numpy as np
import OpenEXR

# cirrus render ... --camera-from 150,100,-230 --camera-to 150,83,100 --fov 40 --res 384x256
EYE = np.array([150.0, 100.0, -230.0])
TARGET = np.array([150.0, 83.0, 100.0])
FOV, WIDTH, HEIGHT = 40.0, 384, 256
SPHERE_CENTRE, SPHERE_RADIUS = np.array([178.0, 66.0, 70.0]), 34.0
SUN_TO_LIGHT = -np.array([0.7, -0.5, 0.5]) / np.linalg.norm([0.7, -0.5, 0.5])
SUN, SKY = np.array([2.6, 2.5, 2.3]), np.array([0.16, 0.22, 0.34])


def camera_rays() -> tuple[np.ndarray, np.ndarray]:
    """Unit directions through the pixel centres, and the view axis."""
    forward = (TARGET - EYE) / np.linalg.norm(TARGET - EYE)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_half = np.tan(np.radians(FOV) / 2)
    px, py = np.meshgrid(np.arange(WIDTH) + 0.5, np.arange(HEIGHT) + 0.5)
    sx = (2 * px / WIDTH - 1) * tan_half * WIDTH / HEIGHT
    sy = (1 - 2 * py / HEIGHT) * tan_half
    d = forward + sx[..., None] * right + sy[..., None] * up
    return d / np.linalg.norm(d, axis=-1, keepdims=True), forward


def sphere_hit() -> tuple[np.ndarray, np.ndarray]:
    """Distance along each ray to the sphere (inf where missed), and the dirs."""
    d, _ = camera_rays()
    oc = EYE - SPHERE_CENTRE
    b = d @ oc
    disc = b * b - (oc @ oc - SPHERE_RADIUS**2)
    t = np.where(disc > 0, -b - np.sqrt(np.maximum(disc, 0)), np.inf)
    return t, d


def write_depth(path: str) -> None:
    t, d = sphere_hit()
    _, forward = camera_rays()
    depth = np.where(np.isfinite(t), t * (d @ forward), 1e10).astype(np.float32)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"Z": depth}) as f:
        f.write(path)


def plate() -> tuple[np.ndarray, np.ndarray]:
    """The sphere, grey and Lambertian under the same sun and sky, and its mask."""
    t, d = sphere_hit()
    hit = np.isfinite(t)
    p = EYE + np.where(hit, t, 0)[..., None] * d
    n = (p - SPHERE_CENTRE) / SPHERE_RADIUS
    lambert = np.clip(n @ SUN_TO_LIGHT, 0, None)[..., None]
    colour = 0.45 * (SUN * lambert / np.pi + SKY * (0.5 + 0.5 * n[..., 1:2]))
    return np.where(hit[..., None], colour, SKY), hit


def png(path: str, rgb: np.ndarray) -> None:
    """An sRGB 8-bit PNG of linear `rgb` (ACES-like tone curve, as cirrus's)."""
    x = np.clip(rgb, 0, None)
    x = np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0, 1)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    data = (x * 255 + 0.5).astype(np.uint8)
    raw = b"".join(b"\x00" + row.tobytes() for row in data)

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    h, w = data.shape[:2]
    head = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(raw, 9))
                + chunk(b"IEND", b""))


def compose(render: str, out: str, sun: float, sky: float) -> None:
    with OpenEXR.File(render, separate_channels=True) as f:
        ch = {k: np.asarray(v.pixels) for k, v in f.channels().items()}
    group = lambda name: np.stack([ch[f"{name}.{c}"] for c in "RGB"], axis=-1)
    cloud = sun * group("sun") + sky * group("sky") + group("emission")
    alpha = ch["A"][..., None]
    background, hit = plate()
    # Where the sphere holds out, the cloud in front is premultiplied and
    # the plate shows through its transmittance; elsewhere the render
    # already holds the sky it saw.
    out_rgb = np.where(hit[..., None], cloud + (1 - alpha) * background, cloud)
    png(out, out_rgb)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("depth").add_argument("out")
    c = sub.add_parser("compose")
    c.add_argument("render")
    c.add_argument("depth")
    c.add_argument("out")
    c.add_argument("--sun", type=float, default=1.0)
    c.add_argument("--sky", type=float, default=1.0)
    args = ap.parse_args()
    if args.cmd == "depth":
        write_depth(args.out)
    else:
        compose(args.render, args.out, args.sun, args.sky)


if __name__ == "__main__":
    main()

"""Deterministic procedural fields (noise, cumulus clouds) for the cirrus test data.

Everything here is plain numpy and depends only on the seeds passed in, so the
generated volumes are byte-for-byte repeatable.  Coordinates are voxel indices
and arrays are indexed ``a[x, y, z]`` (y is up), which is the layout that
``pyopenvdb.FloatGrid.copyFromArray`` expects.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


class GradientNoise:
    """Seeded 3-D gradient (Perlin-style) noise on an integer lattice, range about [-1, 1].

    Lattice period is 256 cells.  Evaluation works on an axis-aligned block of voxels
    given by three 1-D coordinate vectors, so the lattice hashing is separable.
    """

    def __init__(self, seed: int):
        rng = np.random.default_rng(seed)
        self.perm = rng.permutation(256).astype(np.int32)
        g = rng.normal(size=(256, 3))
        g /= np.linalg.norm(g, axis=1, keepdims=True)
        self.gx, self.gy, self.gz = (g[:, i].astype(np.float32) for i in range(3))
        self.offsets = rng.uniform(0.0, 256.0, (16, 3))

    @staticmethod
    def _axis(coords: np.ndarray, freq: float, offset: float):
        p = coords.astype(np.float64) * freq + offset
        cell = np.floor(p)
        f = (p - cell).astype(np.float32)
        fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0)  # quintic smoothstep
        i0 = cell.astype(np.int64) & 255
        return i0.astype(np.int32), ((i0 + 1) & 255).astype(np.int32), f, fade

    def block(self, xs, ys, zs, freq: float, octave: int = 0) -> np.ndarray:
        """Noise sampled at every (x, y, z) of the block spanned by xs, ys, zs."""
        ox, oy, oz = self.offsets[octave % len(self.offsets)]
        x0, x1, fx, wx = self._axis(np.asarray(xs), freq, ox)
        y0, y1, fy, wy = self._axis(np.asarray(ys), freq, oy)
        z0, z1, fz, wz = self._axis(np.asarray(zs), freq, oz)
        perm = self.perm
        fx, wx = fx[:, None, None], wx[:, None, None]
        fy, wy = fy[None, :, None], wy[None, :, None]
        fz, wz = fz[None, None, :], wz[None, None, :]

        def corner(ix, iy, iz, cx, cy, cz):
            hxy = perm[(perm[ix][:, None] + iy[None, :]) & 255]
            h = perm[(hxy[:, :, None] + iz[None, None, :]) & 255]
            return self.gx[h] * (fx - cx) + self.gy[h] * (fy - cy) + self.gz[h] * (fz - cz)

        c00 = corner(x0, y0, z0, 0, 0, 0) * (1 - wx) + corner(x1, y0, z0, 1, 0, 0) * wx
        c10 = corner(x0, y1, z0, 0, 1, 0) * (1 - wx) + corner(x1, y1, z0, 1, 1, 0) * wx
        c01 = corner(x0, y0, z1, 0, 0, 1) * (1 - wx) + corner(x1, y0, z1, 1, 0, 1) * wx
        c11 = corner(x0, y1, z1, 0, 1, 1) * (1 - wx) + corner(x1, y1, z1, 1, 1, 1) * wx
        c0 = c00 * (1 - wy) + c10 * wy
        c1 = c01 * (1 - wy) + c11 * wy
        return ((c0 * (1 - wz) + c1 * wz) * np.float32(1.6)).astype(np.float32)

    def fbm(self, xs, ys, zs, freq: float, octaves: int, gain: float = 0.5,
            billow: bool = False) -> np.ndarray:
        """Fractal sum of `octaves` noise layers; billow=True sums |noise| (puffy lumps).

        The result is normalised so its range is about [-1, 1] ([0, 1] for billow).
        """
        total = None
        amp, norm = 1.0, 0.0
        for o in range(octaves):
            n = self.block(xs, ys, zs, freq * (2.0 ** o), octave=o)
            if billow:
                n = np.abs(n)
            n *= np.float32(amp)
            total = n if total is None else total + n
            norm += amp
            amp *= gain
        return total / np.float32(norm)


@dataclass(frozen=True)
class Blob:
    """A sphere of the cloud's coarse shape, in voxel units."""
    centre: tuple[float, float, float]
    radius: float


def cumulus_blobs(size: tuple[int, int, int], seed: int) -> list[Blob]:
    """A cumulus-like arrangement of spheres filling a box of `size` voxels (y up).

    A broad row of base puffs, a smaller middle layer and two or three towers on
    top, plus random small puffs on the upper surface.
    """
    nx, ny, nz = size
    rng = np.random.default_rng(seed)
    h = float(ny)
    blobs: list[Blob] = []

    def add(fx, fy, fz, fr):
        blobs.append(Blob((fx * nx, fy * ny, fz * nz), fr * h))

    # Base: a ring of wide puffs sitting on the flat bottom.
    for fx, fz in [(0.26, 0.45), (0.38, 0.58), (0.5, 0.44), (0.62, 0.58), (0.74, 0.47),
                   (0.44, 0.34), (0.58, 0.33)]:
        add(fx + rng.uniform(-0.02, 0.02), 0.32 + rng.uniform(-0.02, 0.03),
            fz + rng.uniform(-0.03, 0.03), 0.22 + rng.uniform(0.0, 0.05))
    # Middle layer, pulled towards the centre.
    for fx, fz in [(0.40, 0.48), (0.55, 0.52), (0.48, 0.40), (0.63, 0.45)]:
        add(fx + rng.uniform(-0.02, 0.02), 0.50 + rng.uniform(-0.03, 0.03),
            fz + rng.uniform(-0.03, 0.03), 0.20 + rng.uniform(0.0, 0.04))
    # Towers: the billowy top.
    add(0.47, 0.68, 0.47, 0.17)
    add(0.56, 0.64, 0.52, 0.15)
    add(0.51, 0.78, 0.49, 0.11)
    # Small puffs scattered over the upper half of the existing spheres.
    big = list(blobs)
    for _ in range(28):
        b = big[rng.integers(len(big))]
        d = rng.normal(size=3)
        d[1] = abs(d[1]) + 0.3
        d /= np.linalg.norm(d)
        c = np.array(b.centre) + d * b.radius * 0.95
        blobs.append(Blob(tuple(c), b.radius * rng.uniform(0.28, 0.45)))
    return blobs


def _smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    h = np.clip(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return b * (1 - h) + a * h - k * h * (1 - h)


def cumulus_density(size: tuple[int, int, int], seed: int,
                    origin: tuple[int, int, int] = (0, 0, 0),
                    block: tuple[slice, slice, slice] | None = None) -> np.ndarray:
    """Density (0..~1, float32) of a cumulus cloud filling a box of `size` voxels.

    The coarse shape is a smooth union of spheres (cumulus_blobs) whose surface is
    displaced by billowy fBm; the base is cut flat by a slightly noisy plane; the
    edge is a soft ramp a few voxels wide and the interior carries low-contrast
    noise so that no two leaves are constant.  Voxels below 1e-3 are set to exactly 0
    (they become inactive background in the VDB grid).

    `block` optionally restricts evaluation to a sub-box (slices into the full box),
    so very large clouds can be produced slab by slab; `origin` only shifts the
    noise lattice.
    """
    nx, ny, nz = size
    if block is None:
        block = (slice(0, nx), slice(0, ny), slice(0, nz))
    xs = np.arange(nx, dtype=np.float32)[block[0]]
    ys = np.arange(ny, dtype=np.float32)[block[1]]
    zs = np.arange(nz, dtype=np.float32)[block[2]]
    h = float(ny)

    blobs = cumulus_blobs(size, seed)
    sdf = np.full((len(xs), len(ys), len(zs)), 1e9, dtype=np.float32)
    k = 0.06 * h
    # Each sphere only matters within `pad` of its surface: further out the noise
    # displacement below can never bring the surface there.
    pad = 0.25 * h + k
    for b in blobs:
        cx, cy, cz = b.centre
        reach = b.radius + pad
        ix = np.nonzero(np.abs(xs - cx) <= reach)[0]
        iy = np.nonzero(np.abs(ys - cy) <= reach)[0]
        iz = np.nonzero(np.abs(zs - cz) <= reach)[0]
        if not (len(ix) and len(iy) and len(iz)):
            continue
        sub = (slice(ix[0], ix[-1] + 1), slice(iy[0], iy[-1] + 1), slice(iz[0], iz[-1] + 1))
        dx = (xs[sub[0]] - cx)[:, None, None]
        dy = (ys[sub[1]] - cy)[None, :, None]
        dz = (zs[sub[2]] - cz)[None, None, :]
        d = np.sqrt(dx * dx + dy * dy + dz * dz, dtype=np.float32) - np.float32(b.radius)
        sdf[sub] = _smooth_min(d, sdf[sub], k)

    noise = GradientNoise(seed + 1)
    density = np.zeros_like(sdf)
    # The noise only matters near the coarse surface, so evaluate it in 32^3 blocks and
    # skip the blocks that are entirely far outside.
    reach = np.float32(0.16 * h)
    step = 32
    for bx in range(0, len(xs), step):
        for by in range(0, len(ys), step):
            for bz in range(0, len(zs), step):
                sub = (slice(bx, bx + step), slice(by, by + step), slice(bz, bz + step))
                s = sdf[sub]
                if s.min() > reach:
                    continue
                density[sub] = _cumulus_shade(
                    s, noise, xs[sub[0]] + origin[0], ys[sub[1]] + origin[1],
                    zs[sub[2]] + origin[2], ys[sub[1]], h)
    return density


def _cumulus_shade(sdf, noise, gx, gy, gz, ys, h):
    """Turn a block of the coarse signed distance into density (see cumulus_density)."""
    # Billowy displacement: pushes the surface out in round lumps at several scales.
    billow = noise.fbm(gx, gy, gz, freq=3.0 / h, octaves=5, gain=0.5, billow=True)
    sdf = sdf - np.float32(0.16 * h) * (billow - np.float32(0.25))
    # Finer, signed detail.
    sdf += np.float32(0.025 * h) * noise.fbm(gx, gy, gz, freq=12.0 / h, octaves=3, gain=0.5)

    # Flat, slightly wavy base (smooth max of the shape and the half-space above it).
    wave = noise.block(gx, np.zeros(1, np.float32), gz, 4.0 / h, octave=9)
    base_y = np.float32(0.17 * h) + np.float32(0.01 * h) * wave
    below = (base_y - ys[None, :, None]).astype(np.float32)
    sdf = -_smooth_min(-sdf, -below, 0.02 * h)

    edge = np.float32(0.045 * h)
    t = np.clip(-sdf / edge, 0.0, 1.0)
    density = t * t * (3.0 - 2.0 * t)
    # Interior variation: noisy, thinner towards the base.
    inner = noise.fbm(gx, gy, gz, freq=6.0 / h, octaves=4, gain=0.55)
    height = np.clip((ys[None, :, None] - 0.15 * h) / (0.25 * h), 0.0, 1.0)
    density *= (0.72 + 0.2 * inner) * (0.75 + 0.25 * height)
    density = np.clip(density, 0.0, 1.0).astype(np.float32)
    density[density < 1e-3] = 0.0
    return density

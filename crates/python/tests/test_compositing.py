"""Compositing outputs read back as compositors read them: Cryptomatte
decoded with the specification's hash (PyPI's mmh3), deep images read and
flattened through OpenEXR's own Python bindings, light groups and depth
holdouts through the keyword arguments."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import mmh3
import numpy as np
import OpenEXR
import pytest

import cirrus

ROOT = Path(__file__).resolve().parents[3]
CLOUD = ROOT / "data" / "cloud.vdb"


def crypto_id(name: str) -> float:
    """The specification's ID: MurmurHash3_32, bit 23 flipped when the
    exponent bits are all 0 or all 1, read as a float32."""
    h = mmh3.hash(name.encode(), 0, signed=False)
    if (h >> 23) & 0xFF in (0, 0xFF):
        h ^= 1 << 23
    return struct.unpack("<f", struct.pack("<I", h))[0]


def read_exr(path: Path) -> tuple[dict, dict[str, np.ndarray]]:
    with OpenEXR.File(str(path), separate_channels=True) as f:
        channels = {name: np.asarray(ch.pixels) for name, ch in f.channels().items()}
        return dict(f.header()), channels


def decode(header: dict, channels: dict, layer: str, name: str) -> np.ndarray:
    """Coverage of `name` in Cryptomatte layer `layer`, as Nuke's decoder
    sums it over the ranks."""
    key = next(k for k, v in header.items() if k.endswith("/name") and v == layer)
    manifest = json.loads(header[key.replace("/name", "/manifest")])
    target = crypto_id(name)
    assert manifest[name] == "%08x" % struct.unpack("<I", struct.pack("<f", target))[0]
    cov = 0.0
    for rank in range(3):
        c = f"{layer}{rank:02d}"
        for id_ch, cov_ch in (("R", "G"), ("B", "A")):
            ids = channels[f"{c}.{id_ch}"]
            cov = cov + np.where(ids == np.float32(target), channels[f"{c}.{cov_ch}"], 0.0)
    return cov


def two_clouds(tmp_path: Path) -> dict:
    info = cirrus.open(CLOUD)["density"]
    lo, hi = np.array(info["index_bbox"][0]), np.array(info["index_bbox"][1])
    width = float((hi - lo)[0] * info["voxel_size"][0])
    return {
        "camera": {"res": "48x32"},
        "render": {"spp": 16, "seed": 2},
        "volume": [
            {"file": str(CLOUD), "name": "left"},
            {"file": str(CLOUD), "name": "right",
             "transform": {"translate": [0.75 * width, 0.1 * width, 0.3 * width]}},
        ],
    }


def test_cryptomatte_selects_each_of_two_overlapping_instances(tmp_path):
    out = tmp_path / "crypto.exr"
    image, _ = cirrus.render(two_clouds(tmp_path), output=out, cryptomatte=True)
    header, ch = read_exr(out)
    left = decode(header, ch, "CryptoObject", "left")
    right = decode(header, ch, "CryptoObject", "right")
    alpha = image[..., 3]
    assert np.abs(left + right - alpha).max() <= 1e-4
    # Each is picked where it alone is seen, and both overlap somewhere.
    only_left, only_right = left > 0.99, right > 0.99
    assert only_left.sum() > 20 and only_right.sum() > 20
    assert np.all(right[only_left] < 0.01) and np.all(left[only_right] < 0.01)
    assert ((left > 0.1) & (right > 0.1)).sum() > 5
    # One file, one asset: its coverage is the sum of the two.
    asset = decode(header, ch, "CryptoAsset", "cloud.vdb")
    assert np.abs(asset - (left + right)).max() <= 1e-4


def flatten(rgba: np.ndarray) -> np.ndarray:
    """OpenEXR's front-to-back "over" of a pixel's sorted deep samples."""
    out, t = np.zeros(4), 1.0
    for r, g, b, a in rgba:
        out += t * np.array([r, g, b, a], dtype=np.float64)
        t *= 1.0 - a
    return out


def test_deep_flattens_to_the_flat_render(tmp_path):
    flat, deep = tmp_path / "flat.exr", tmp_path / "deep.exr"
    image, _ = cirrus.render(CLOUD, res="32x24", spp=16, seed=4, output=flat, deep=deep)
    with OpenEXR.File(str(deep)) as f:
        assert f.header()["type"] == OpenEXR.deepscanline
        ch = f.channels()
        rgba, z, zback = ch["RGBA"].pixels, ch["Z"].pixels, ch["ZBack"].pixels
    worst, samples = 0.0, 0
    for y in range(24):
        for x in range(32):
            s = np.asarray(rgba[y, x]).reshape(-1, 4) if rgba[y, x] is not None else np.zeros((0, 4))
            samples += len(s)
            if len(s):
                assert np.all(np.diff(np.asarray(z[y, x])) >= 0), "sorted front to back"
                assert np.all(np.asarray(zback[y, x]) >= np.asarray(z[y, x]))
                assert len(s) <= 17
            got, want = flatten(s), image[y, x].astype(np.float64)
            worst = max(worst, float(np.max(np.abs(got - want) / np.maximum(np.abs(want), 1e-3))))
    assert samples > 32 * 24
    assert worst <= 1e-5, worst


def write_depth(path: Path, depth: np.ndarray, channel: str = "Z") -> None:
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {channel: depth.astype(np.float32)}) as f:
        f.write(str(path))


def test_light_groups_and_holdout_depth_by_keyword(tmp_path):
    image, stats = cirrus.render(CLOUD, res="32x24", spp=8, seed=1, light_groups=True)
    groups = stats["aovs"]
    total = groups["sun"] + groups["sky"] + groups["emission"]
    assert np.all(np.abs(total - image[..., :3]) <= 1e-5 * np.maximum(image[..., :3], 1e-3))
    # A depth holdout nearer than the cloud: nothing but its own black.
    near = tmp_path / "near.exr"
    write_depth(near, np.full((24, 32), 1e-3))
    held, _ = cirrus.render(CLOUD, res="32x24", spp=2, holdout_depth=near)
    assert np.all(held == 0.0)
    # Wrong size, missing channel, missing file: exceptions naming the file.
    small = tmp_path / "small.exr"
    write_depth(small, np.ones((10, 10)))
    with pytest.raises(ValueError, match="small.exr.*10x10"):
        cirrus.render(CLOUD, res="32x24", spp=1, holdout_depth=small)
    with pytest.raises(ValueError, match="near.exr.*nope"):
        cirrus.render(CLOUD, res="32x24", spp=1, holdout_depth=f"{near}:nope")
    with pytest.raises(OSError, match="absent.exr"):
        cirrus.render(CLOUD, res="32x24", spp=1, holdout_depth=tmp_path / "absent.exr")


def test_denoised_layers_read_back_and_make_up_the_blend(tmp_path):
    """`denoise=True` writes the noisy image, the plain denoised one and the
    noisy image's weight beside the blended RGB; read through OpenEXR's own
    bindings, RGB is `w * noisy + (1 - w) * denoised` per pixel."""
    out = tmp_path / "dn.exr"
    cirrus.render(CLOUD, res="48x32", spp=32, seed=3, denoise=True, output=out)
    _, ch = read_exr(out)
    rgb = np.stack([ch[c] for c in "RGB"], axis=-1).astype(np.float64)
    noisy = np.stack([ch[f"noisy.{c}"] for c in "RGB"], axis=-1).astype(np.float64)
    plain = np.stack([ch[f"denoised.{c}"] for c in "RGB"], axis=-1).astype(np.float64)
    w = ch["blend.weight"].astype(np.float64)[..., None]
    assert np.all((w >= 0.0) & (w <= 1.0))
    assert np.abs(rgb - (w * noisy + (1.0 - w) * plain)).max() <= 1e-5 * max(rgb.max(), 1.0)
    # Both images take part somewhere, and the denoiser did change the image.
    assert (w < 0.5).any() and (w > 0.5).any()
    assert np.abs(plain - noisy).max() > 1e-3


def test_light_groups_named_outside_latin1_read_back_by_openexr(tmp_path):
    """A light group named in Japanese (or any UTF-8) is written as
    OpenEXR's own library reads names, and its layer still sums with the
    others to the beauty; a name past OpenEXR's 255-byte channel names is
    refused by name before the render."""
    scene = {
        "camera": {"res": "24x16"},
        "render": {"spp": 4, "seed": 5},
        "volume": [{"file": str(CLOUD)}],
        "environment": {"radiance": [0.2, 0.2, 0.25]},
        "light": [{"type": "sphere", "name": "ランプ", "position": [0.0, 300.0, 0.0],
                   "intensity": 1000.0, "radius": 10.0}],
    }
    out = tmp_path / "unicode.exr"
    image, _ = cirrus.render(scene, output=out, light_groups=True)
    _, channels = read_exr(out)
    assert "ランプ.R" in channels, sorted(channels)
    lamp = np.stack([channels[f"ランプ.{c}"] for c in "RGB"], axis=-1)
    sky = np.stack([channels[f"sky.{c}"] for c in "RGB"], axis=-1)
    assert lamp.max() > 0.0
    beauty = np.stack([channels[c] for c in "RGB"], axis=-1)
    assert np.all(np.abs(lamp + sky - beauty) <= 1e-5 * np.maximum(beauty, 1e-3) + 1e-6)
    scene["light"][0]["name"] = "x" * 254
    with pytest.raises(ValueError, match="254 bytes"):
        cirrus.render(scene, output=tmp_path / "long.exr", light_groups=True)
    assert not (tmp_path / "long.exr").exists()

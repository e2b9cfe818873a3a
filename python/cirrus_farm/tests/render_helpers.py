"""Making frame inputs, rendering references and comparing EXR pixels."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import OpenEXR

REPO = Path(__file__).resolve().parents[3]
DATA = REPO / "data"

# Small and fast, and three different volumes so a frame rendered from the
# wrong input cannot pass for the right one.
RENDER_FLAGS = ["--res", "33x25", "--spp", "4", "--seed", "7"]
FRAME_VOLUMES = {1: "cloud.vdb", 2: "sphere_fog.vdb", 3: "fireball.vdb"}


def make_frame_inputs(folder: Path, volumes: dict[int, str] = FRAME_VOLUMES) -> str:
    """Copies test volumes to folder/cloud.0001.vdb, ...; returns the pattern."""
    for frame, name in volumes.items():
        shutil.copyfile(DATA / name, folder / f"cloud.{frame:04d}.vdb")
    return str(folder / "cloud.####.vdb")


def render_reference(cirrus: str, input_path: str, output: Path, flags=RENDER_FLAGS,
                     crop: str | None = None) -> Path:
    """The single-machine render the farm's frames must match."""
    args = [cirrus, "render", input_path, "-o", str(output), *flags]
    if crop:
        args += ["--crop", crop]
    subprocess.run(args, check=True, capture_output=True,
                   env={**os.environ, "RAYON_NUM_THREADS": "1"})
    return output


def read_exr(path: Path) -> tuple[dict, dict[str, np.ndarray]]:
    """The windows and every channel's pixels, for comparing two renders
    whose header bytes may differ."""
    exr = OpenEXR.File(str(path), separate_channels=True)
    header = exr.header()
    windows = {k: tuple(np.asarray(header[k]).ravel()) for k in ("dataWindow", "displayWindow")}
    channels = {name: np.array(ch.pixels) for name, ch in exr.channels().items()}
    return windows, channels


def assert_same_pixels(actual: Path, expected: Path) -> None:
    """Bit-identical channels (NaNs included) and the same windows."""
    windows_a, channels_a = read_exr(actual)
    windows_e, channels_e = read_exr(expected)
    assert windows_a == windows_e
    assert sorted(channels_a) == sorted(channels_e) == ["A", "B", "G", "R"]
    for name, expected_pixels in channels_e.items():
        assert channels_a[name].dtype == expected_pixels.dtype
        assert channels_a[name].tobytes() == expected_pixels.tobytes(), f"channel {name}"


def hidden_files(folder: Path) -> list[str]:
    """Tile and temporary files left in `folder`."""
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))

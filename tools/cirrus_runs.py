"""Rendering a scene file with a cirrus binary from the benchmark scripts
(`tools/many_lights.py`, `tools/equiangular.py`): the RGB it wrote and the
render's wall time from its `--stats`."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import OpenEXR


def render_rgb(cirrus: str, text: str, d: Path, name: str) -> tuple[np.ndarray, float]:
    """Writes `text` as `d/name.toml`, renders it, and returns its RGB (f64)
    and the render's wall seconds."""
    toml = d / f"{name}.toml"
    toml.write_text(text)
    out, stats = d / f"{name}.exr", d / f"{name}.json"
    subprocess.run([cirrus, "render", str(toml), "-o", str(out), "--stats", str(stats)],
                   check=True, capture_output=True)
    rgba = OpenEXR.File(str(out)).parts[0].channels["RGBA"].pixels
    return rgba[..., :3].astype(np.float64), json.loads(stats.read_text())["wall_seconds"]

"""Rendering a scene file with a cirrus binary from the benchmark scripts
(`tools/many_lights.py`, `tools/equiangular.py`,
`tools/rect_light_sampling.py`): the RGB it wrote and the render's wall
time from its `--stats`; and the corpus cloud as thin fog they share."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import OpenEXR

CLOUD = Path(__file__).resolve().parents[1] / "data" / "cloud.vdb"

# The corpus cloud as thin fog (a `[[volume]]` table): density scale 0.1,
# albedo 0.8, g 0.3.
CLOUD_FOG = f"""[[volume]]
file = "{CLOUD}"
density_scale = 0.1
albedo = 0.8
g = 0.3
"""


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

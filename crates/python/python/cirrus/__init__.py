"""cirrus: path tracing of sparse production volumes (OpenVDB / NanoVDB).

    import cirrus
    image, stats = cirrus.render("data/cloud.vdb", res="256x256", spp=16)
    image.shape            # (256, 256, 4) float32, alpha = 1 - transmittance

`render` takes a scene file (TOML, or a USD stage: .usd, .usda, .usdc,
.usdz), a volume file or a dict in the scene-file format, and keyword overrides named as the `cirrus render` flags
(`res`, `spp`, `seed`, `camera_from`, `sun_dir`, `albedo`, `aov`, ...).
`open` returns a file's grids as `cirrus info --json` reports them, and
`convert` writes sparse bricks. Errors are `OSError` for files and
`ValueError` for input, with the command line's message.
"""

from __future__ import annotations

import json
import os
import warnings
from typing import Any, Callable, Iterable, Mapping

import numpy as np

from . import _cirrus

__all__ = ["open", "render", "convert", "VolumeFile", "Grid", "SceneWarning"]


class SceneWarning(UserWarning):
    """Something the scene holds that cirrus does not render (a USD stage's
    meshes, a material input it cannot evaluate): listed, never fatal."""


class Grid:
    """One grid of a file: its report fields, and its voxels on request."""

    def __init__(self, path: str, report: Mapping[str, Any]):
        self.path = path
        self.info = dict(report)
        self.name = report["name"]

    def __getitem__(self, key: str) -> Any:
        return self.info[key]

    def __repr__(self) -> str:
        return f"<cirrus.Grid {self.name!r} of {self.path!r}>"

    def read(self, bbox: Iterable[Iterable[int]] | None = None) -> np.ndarray:
        """Voxels over an inclusive index box ``((x0, y0, z0), (x1, y1, z1))``,
        or the active box, as an array indexed ``[x, y, z]`` (and a last axis
        of 3 for vector grids). Inactive voxels hold the background."""
        box = None
        if bbox is not None:
            lo, hi = bbox
            box = (tuple(int(v) for v in lo), tuple(int(v) for v in hi))
        data, shape, dtype = _cirrus.read_dense(os.fspath(self.path), self.name, box)
        return np.frombuffer(data, dtype="<" + dtype).reshape(shape)


class VolumeFile:
    """A .vdb, .nvdb or .cbrk file: ``report`` is ``cirrus info --json``."""

    def __init__(self, path: str | os.PathLike):
        self.path = os.fspath(path)
        self.report = json.loads(_cirrus.file_report(self.path))
        self.grids = [Grid(self.path, g) for g in self.report.get("grids", [])]

    def __getitem__(self, name: str) -> Grid:
        for g in self.grids:
            if g.name == name:
                return g
        raise KeyError(f"{self.path}: no grid named {name!r}")

    def __repr__(self) -> str:
        return f"<cirrus.VolumeFile {self.path!r}: {[g.name for g in self.grids]}>"


def open(path: str | os.PathLike) -> VolumeFile:  # noqa: A001 - the natural name
    """Reads a file's header and grids (statistics are computed from the data)."""
    return VolumeFile(path)


def _flag_value(key: str, value: Any) -> Any:
    """Keyword values in the forms the command line accepts."""
    if key == "res" and isinstance(value, (tuple, list)):
        return f"{int(value[0])}x{int(value[1])}"
    if key in ("output", "png", "stats", "env_map", "deep", "holdout_depth") and value is not None:
        return os.fspath(value)
    if key == "aov" and isinstance(value, str):
        return [a.strip() for a in value.split(",") if a.strip()]
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value


def render(
    scene: str | os.PathLike | Mapping[str, Any],
    *,
    progress: Callable[[int, int], Any] | None = None,
    threads: int | None = None,
    **overrides: Any,
) -> tuple[np.ndarray, dict[str, Any]]:
    """Renders a scene file, a volume file or a scene dict.

    Returns the image as a float32 array (H, W, 4) and the statistics as a
    dict (``"warnings"``: what the scene's reader could not render, also
    issued as :class:`SceneWarning`); with ``aov=[...]`` the statistics hold ``"aovs"``, one float32
    (H, W, C) array per layer, and with ``light_groups=True`` one (H, W, 3)
    array per light group (``sun``, ``sky``, ``emission``). Compositing:
    ``holdout_depth="z.exr[:CHANNEL]"``, ``deep="deep.exr"``,
    ``cryptomatte=True`` (written into ``output``). ``progress(done, total)`` is called about
    every 50 ms once rendering has begun; if it raises, the render stops and the exception
    propagates, as Ctrl-C does. ``threads`` sets the worker count (the
    image is the same on any count). ``device="cpu"|"auto"|"gpu"`` chooses
    where it runs, as ``cirrus render --device`` (a scene file's ``[render]
    device`` otherwise; a GPU render takes no ``progress`` and cannot be
    stopped). Outputs named by the overrides
    (``output``, ``png``, ``stats``) or the scene file are written too.
    """
    flags = {k: _flag_value(k, v) for k, v in overrides.items()}
    path = desc = None
    if isinstance(scene, Mapping):
        desc = json.dumps(scene)
    else:
        path = os.fspath(scene)
    rgba, width, height, stats_json, aovs = _cirrus.render(
        path, desc, os.getcwd(), json.dumps(flags), progress, threads
    )
    image = np.frombuffer(rgba, dtype="<f4").reshape(height, width, 4).copy()
    stats = json.loads(stats_json)
    for message in stats.get("warnings", []):
        warnings.warn(message, SceneWarning, stacklevel=2)
    if aovs:
        stats["aovs"] = {
            name: np.frombuffer(data, dtype="<f4").reshape(height, width, n).copy()
            for name, n, data in aovs
        }
    return image, stats


def convert(
    src: str | os.PathLike,
    dst: str | os.PathLike,
    grid: str | None = None,
    precision: str = "f16",
) -> dict[str, Any]:
    """Converts a float fog-volume grid to sparse bricks (.cbrk); returns
    the report of the written file."""
    return json.loads(_cirrus.convert(os.fspath(src), os.fspath(dst), grid, precision))

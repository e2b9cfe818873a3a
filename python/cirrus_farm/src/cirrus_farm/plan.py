"""What a job will do, worked out on the client before anything runs.

The plan is plain data: for each frame its input, its output and the tile
files to render. Building it checks the patterns, the tile grid and the
pass-through flags, so a mistake in any of them stops the job before a
single task reaches the cluster.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Sequence

from .frames import FrameSpecError, expand_distinct, expand_frame_pattern
from .tiles import Tile, TileSpecError, split_image, parse_size

# cirrus's own default (`--res` in `cirrus render --help`).
DEFAULT_RESOLUTION = (512, 512)

# Flags the farm sets itself on every task; given again they would fight
# over the output file or write the same side file from every tile.
_FLAGS_THE_FARM_OWNS = {
    "-o": "the farm sets each task's output; give the pattern to cirrus-farm -o",
    "--output": "the farm sets each task's output; give the pattern to cirrus-farm -o",
    "--crop": "the farm sets each tile's crop window; use --tiles",
    "--png": "every task would write the same PNG; convert the EXR frames afterwards",
    "--stats": "every task would write the same statistics file",
}


# Where a render runs (`cirrus render --device`).
DEVICES = ("cpu", "auto", "gpu")


class PlanError(ValueError):
    """A job that cannot be planned; the message says what to change."""


def check_device(device: str | None, flags: Sequence[str]) -> None:
    """Rejects a device cirrus does not know, and a device given twice
    (the job's and `--device` among the pass-through flags)."""
    if device is None:
        return
    if device not in DEVICES:
        raise PlanError(f"device {device!r}: use one of {', '.join(DEVICES)}")
    if flag_value(flags, "--device") is not None:
        raise PlanError("the device is given twice: as the job's device and as --device "
                        "after '--'; keep one")


@dataclass(frozen=True)
class TileTask:
    """One `cirrus render` run: the whole frame (`tile` None) or a crop,
    with its deep image when the job writes deep images."""

    tile: Tile | None
    path: str
    deep: str | None = None


@dataclass(frozen=True)
class FramePlan:
    """One frame: its input file, its output file and the renders it needs."""

    frame: int
    input: str
    output: str
    tiles: tuple[TileTask, ...]
    deep: str | None = None

    @property
    def renders_straight_to_output(self) -> bool:
        """One untiled render writes the output itself; nothing to merge."""
        return len(self.tiles) == 1 and self.tiles[0].tile is None


def flag_value(flags: Sequence[str], name: str) -> str | None:
    """The last value of `name` in `flags` ('--res 64x64' or '--res=64x64')."""
    value = None
    for i, flag in enumerate(flags):
        if flag == name and i + 1 < len(flags):
            value = flags[i + 1]
        elif flag.startswith(name + "="):
            value = flag[len(name) + 1 :]
    return value


def without_flag(flags: Sequence[str], name: str) -> list[str]:
    """`flags` less every `name VALUE` and `name=VALUE`."""
    out, skip = [], False
    for i, flag in enumerate(flags):
        if skip:
            skip = False
        elif flag == name and i + 1 < len(flags):
            skip = True
        elif not flag.startswith(name + "="):
            out.append(flag)
    return out


def check_render_flags(flags: Sequence[str]) -> None:
    """Rejects the pass-through flags that would clash with the farm's own."""
    for flag in flags:
        name = flag.split("=", 1)[0]
        if name in _FLAGS_THE_FARM_OWNS:
            raise PlanError(f"{name} cannot be passed through: {_FLAGS_THE_FARM_OWNS[name]}")


def image_resolution(input_pattern: str, flags: Sequence[str]) -> tuple[int, int]:
    """The rendered image's size, needed to cut it into tiles.

    A volume file renders at `--res` or cirrus's default; a scene file may
    set its own `res`, which the farm does not read, so tiling a scene
    needs `--res` given explicitly (it then wins over the file, as in cirrus).
    """
    res = flag_value(flags, "--res")
    if res is not None:
        try:
            return parse_size(res, "--res")
        except TileSpecError as e:
            raise PlanError(str(e)) from None
    if input_pattern.lower().endswith(".toml"):
        raise PlanError(
            "tiling a .toml scene needs its resolution: pass --res WxH after '--' "
            "(the same value as the scene's [camera] res)"
        )
    return DEFAULT_RESOLUTION


def tile_file_path(output: str, tile: Tile) -> str:
    """A hidden file beside `output` for one tile, e.g. '.out.0001.tile-1-0.exr'.

    Beside the output so it is on the shared file system the workers see,
    hidden so it is not mistaken for a frame, and named by the tile so a
    resumed job finds the tiles an earlier run finished.
    """
    folder, name = os.path.split(output)
    stem = name[:-4] if name.lower().endswith(".exr") else name
    return os.path.join(folder, f".{stem}.tile-{tile.column}-{tile.row}.exr")


def deep_tile_path(deep: str, tile: Tile) -> str:
    """The hidden deep tile beside a frame's deep image (`--deep`)."""
    return tile_file_path(deep, tile)


def plan_job(
    input_pattern: str,
    output_pattern: str,
    frames: Sequence[int],
    tile_grid: tuple[int, int],
    render_flags: Sequence[str],
) -> list[FramePlan]:
    """One `FramePlan` per frame, with absolute paths (workers may run elsewhere)."""
    frames = list(dict.fromkeys(frames))  # a frame listed twice is rendered once
    if not frames:
        raise PlanError("no frames to render")
    check_render_flags(render_flags)
    columns, rows = tile_grid
    if columns < 1 or rows < 1:
        raise PlanError(f"the tile grid must be at least 1x1, got {columns}x{rows}")
    tiles: list[Tile] | None = None
    if (columns, rows) != (1, 1):
        width, height = image_resolution(input_pattern, render_flags)
        try:
            tiles = split_image(width, height, columns, rows)
        except TileSpecError as e:
            raise PlanError(str(e)) from None
    deep_pattern = flag_value(render_flags, "--deep")
    try:
        inputs = {f: expand_frame_pattern(os.path.abspath(input_pattern), f) for f in frames}
        outputs = expand_distinct(os.path.abspath(output_pattern), frames)
        deeps = (expand_distinct(os.path.abspath(deep_pattern), frames)
                 if deep_pattern is not None else {})
    except FrameSpecError as e:
        raise PlanError(str(e)) from None
    plans = []
    for frame in frames:
        output, deep = outputs[frame], deeps.get(frame)
        if tiles is None:
            tasks = (TileTask(None, output, deep),)
        else:
            tasks = tuple(
                TileTask(t, tile_file_path(output, t), deep and deep_tile_path(deep, t))
                for t in tiles)
        plans.append(FramePlan(frame, inputs[frame], output, tasks, deep))
    return plans

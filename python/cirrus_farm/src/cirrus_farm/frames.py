"""Frame ranges and frame-number patterns in file names.

The `cirrus` binary renders one file at a time, so the farm turns
`cloud.####.vdb` and `out.%04d.exr` into one concrete path per frame here,
before any task is submitted: a typo in a pattern fails at once on the
client instead of on every worker.
"""

from __future__ import annotations

import re
from typing import Iterable

# A run of '#', '%%', or a printf integer spec: '%d', '%4d', '%04d'.
_FRAME_TOKEN = re.compile(r"#+|%%|%(0?)(\d*)d")


class FrameSpecError(ValueError):
    """A frame range or pattern the farm cannot use; the message says why."""


def parse_frame_range(text: str) -> list[int]:
    """Frames of 'A-B[:STEP]' (both ends included) or of a single 'A'.

    Frames are non-negative because a '-' separates the ends; a range
    whose end lies before its start is an error rather than an empty job,
    since an empty job is almost always a swapped range.
    """
    match = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*(?::\s*(\d+)\s*)?)?", text)
    if not match:
        raise FrameSpecError(f"frames must be A-B[:STEP] or A, got {text!r}")
    first = int(match.group(1))
    last = int(match.group(2)) if match.group(2) is not None else first
    step = int(match.group(3)) if match.group(3) is not None else 1
    if step < 1:
        raise FrameSpecError(f"frame step must be at least 1, got {text!r}")
    if last < first:
        raise FrameSpecError(f"frame range ends before it starts: {text!r}")
    return list(range(first, last + 1, step))


def expand_frame_pattern(pattern: str, frame: int) -> str:
    """`pattern` with every frame token replaced by `frame`.

    '###' pads with zeros to the run's length; '%d', '%4d' and '%04d' pad
    as printf does; '%%' is one literal '%'; any other '%' is kept as is,
    so names such as '50%_cloud.vdb' survive.
    """
    if frame < 0:
        raise FrameSpecError(f"frame numbers must not be negative, got {frame}")

    def substitute(m: re.Match[str]) -> str:
        token = m.group(0)
        if token.startswith("#"):
            return str(frame).zfill(len(token))
        if token == "%%":
            return "%"
        zero, width = m.group(1), m.group(2)
        return format(frame, f"{zero}{width}d")

    return _FRAME_TOKEN.sub(substitute, pattern)


def expand_distinct(pattern: str, frames: Iterable[int]) -> dict[int, str]:
    """One path per frame; an error if two frames would share it (outputs)."""
    paths = {frame: expand_frame_pattern(pattern, frame) for frame in frames}
    if len(set(paths.values())) < len(paths):
        raise FrameSpecError(
            f"pattern {pattern!r} gives the same path for several frames; "
            "add a frame number such as '####' or '%04d'"
        )
    return paths

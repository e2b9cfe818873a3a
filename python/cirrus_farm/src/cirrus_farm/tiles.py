"""Splitting an image into crop windows for `cirrus render --crop`.

cirrus keys its random numbers by the pixel's index in the full image, so
any partition of the image renders to the same pixels; the split only has
to cover every pixel exactly once, which `cirrus merge` checks again.
"""

from __future__ import annotations

import re
from dataclasses import dataclass


class TileSpecError(ValueError):
    """A tile grid or resolution the farm cannot use; the message says why."""


@dataclass(frozen=True)
class Tile:
    """Pixels [x0, x1) x [y0, y1), at `column`, `row` of the tile grid."""

    column: int
    row: int
    x0: int
    y0: int
    x1: int
    y1: int

    @property
    def crop_flag(self) -> str:
        """The value of `cirrus render --crop` for this tile."""
        return f"{self.x0},{self.y0},{self.x1},{self.y1}"


def parse_size(text: str, what: str) -> tuple[int, int]:
    """'WxH' (or 'CxR') as two positive integers; `what` names it in errors."""
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not match or int(match.group(1)) == 0 or int(match.group(2)) == 0:
        raise TileSpecError(f"{what} must be two positive integers AxB, got {text!r}")
    return int(match.group(1)), int(match.group(2))


def split_image(width: int, height: int, columns: int, rows: int) -> list[Tile]:
    """Row-major tiles whose sizes differ by at most one pixel per axis.

    Every tile must hold at least one pixel, because cirrus rejects an
    empty crop window; so there can be no more columns than pixels across.
    """
    if columns > width or rows > height:
        raise TileSpecError(
            f"{columns}x{rows} tiles do not fit a {width}x{height} image"
        )
    xs = [width * i // columns for i in range(columns + 1)]
    ys = [height * j // rows for j in range(rows + 1)]
    return [
        Tile(c, r, xs[c], ys[r], xs[c + 1], ys[r + 1])
        for r in range(rows)
        for c in range(columns)
    ]

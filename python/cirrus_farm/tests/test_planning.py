"""Frame patterns, frame ranges, tile grids and pass-through flags: the
parts of a job worked out on the client, tested without a cluster."""

from __future__ import annotations

import itertools
import os

import pytest

from cirrus_farm import render_job
from cirrus_farm.frames import (
    FrameSpecError,
    expand_distinct,
    expand_frame_pattern,
    parse_frame_range,
)
from cirrus_farm.plan import PlanError, image_resolution, plan_job, tile_file_path
from cirrus_farm.tiles import Tile, TileSpecError, parse_size, split_image


@pytest.mark.parametrize(
    "pattern, frame, expected",
    [
        ("cloud.####.vdb", 12, "cloud.0012.vdb"),
        ("cloud.#.vdb", 12, "cloud.12.vdb"),  # a short run never truncates
        ("cloud.##.vdb", 123, "cloud.123.vdb"),
        ("out.%04d.exr", 7, "out.0007.exr"),
        ("out.%d.exr", 7, "out.7.exr"),
        ("out.%3d.exr", 7, "out.  7.exr"),  # printf pads with spaces without 0
        ("shot##/f.%02d.exr", 5, "shot05/f.05.exr"),  # every token is filled in
        ("50%_cloud.####.vdb", 3, "50%_cloud.0003.vdb"),  # '%' without a spec
        ("a%%d.####", 3, "a%d.0003"),  # '%%' is one literal '%'
        ("a%x%0.#", 3, "a%x%0.3"),
        ("plain.vdb", 3, "plain.vdb"),
    ],
)
def test_expand_frame_pattern(pattern, frame, expected):
    assert expand_frame_pattern(pattern, frame) == expected


def test_negative_frame_is_refused():
    with pytest.raises(FrameSpecError):
        expand_frame_pattern("a.####", -1)


def test_outputs_without_frame_number_collide():
    assert expand_distinct("o.#.exr", [1, 2]) == {1: "o.1.exr", 2: "o.2.exr"}
    assert expand_distinct("o.exr", [5]) == {5: "o.exr"}
    with pytest.raises(FrameSpecError, match="same path"):
        expand_distinct("o.exr", [1, 2])


@pytest.mark.parametrize(
    "text, frames",
    [("1-5", [1, 2, 3, 4, 5]), ("1-10:3", [1, 4, 7, 10]), ("7", [7]),
     ("0-0", [0]), (" 2 - 6 : 2 ", [2, 4, 6]), ("3-4:10", [3])],
)
def test_parse_frame_range(text, frames):
    assert parse_frame_range(text) == frames


@pytest.mark.parametrize("text", ["5-1", "1-5:0", "a-b", "", "1-", "-3", "1,2"])
def test_bad_frame_range(text):
    with pytest.raises(FrameSpecError):
        parse_frame_range(text)


@pytest.mark.parametrize("width, height, columns, rows",
                         [(33, 25, 2, 2), (512, 512, 3, 5), (7, 3, 7, 3), (10, 10, 1, 1)])
def test_tiles_cover_every_pixel_once(width, height, columns, rows):
    tiles = split_image(width, height, columns, rows)
    assert len(tiles) == columns * rows
    assert {(t.column, t.row) for t in tiles} == set(itertools.product(range(columns), range(rows)))
    covered = [0] * (width * height)
    for t in tiles:
        assert t.x1 > t.x0 and t.y1 > t.y0
        for y in range(t.y0, t.y1):
            for x in range(t.x0, t.x1):
                covered[y * width + x] += 1
    assert covered == [1] * (width * height)
    widths = {t.x1 - t.x0 for t in tiles}
    assert max(widths) - min(widths) <= 1


def test_tile_windows_and_crop_flag():
    tiles = split_image(33, 25, 2, 2)
    assert tiles[0] == Tile(0, 0, 0, 0, 16, 12)
    assert tiles[3] == Tile(1, 1, 16, 12, 33, 25)
    assert tiles[3].crop_flag == "16,12,33,25"


def test_more_tiles_than_pixels_is_refused():
    with pytest.raises(TileSpecError, match="do not fit"):
        split_image(4, 4, 5, 1)


@pytest.mark.parametrize("text", ["2x", "0x2", "2x2x2", "two", "-1x2"])
def test_bad_tile_grid(text):
    with pytest.raises(TileSpecError):
        parse_size(text, "--tiles")


def test_resolution_comes_from_the_pass_through_flags():
    assert image_resolution("a.vdb", ["--spp", "4"]) == (512, 512)  # cirrus's default
    assert image_resolution("a.vdb", ["--res", "64x32"]) == (64, 32)
    assert image_resolution("a.vdb", ["--res=64x32", "--res", "8X4"]) == (8, 4)  # the last wins
    assert image_resolution("scene.toml", ["--res", "20x10"]) == (20, 10)
    with pytest.raises(PlanError, match="--res"):
        image_resolution("scene.TOML", ["--spp", "4"])


def test_toml_needs_res_only_when_tiled():
    plans = plan_job("shot.toml", "o.#.exr", [1], (1, 1), [])
    assert plans[0].renders_straight_to_output
    with pytest.raises(PlanError, match="--res WxH"):
        plan_job("shot.toml", "o.#.exr", [1], (2, 1), [])


@pytest.mark.parametrize("flag", ["-o", "--output=x.exr", "--crop", "--png", "--stats=s.json"])
def test_flags_the_farm_sets_are_refused(flag):
    with pytest.raises(PlanError, match="cannot be passed through"):
        plan_job("a.vdb", "o.#.exr", [1], (1, 1), ["--spp", "4", flag, "x"])


def test_tile_files_are_hidden_beside_the_output():
    tile = Tile(1, 0, 16, 0, 33, 12)
    assert tile_file_path("/r/out.0001.exr", tile) == "/r/.out.0001.tile-1-0.exr"
    assert tile_file_path("/r/out.0001", tile) == "/r/.out.0001.tile-1-0.exr"


def test_plan_has_absolute_paths_per_frame(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    plans = plan_job("in/c.####.vdb", "out/f.%02d.exr", [3, 5], (2, 1), ["--res", "8x8"])
    assert [p.frame for p in plans] == [3, 5]
    assert plans[1].input == os.path.join(tmp_path, "in", "c.0005.vdb")
    assert plans[1].output == os.path.join(tmp_path, "out", "f.05.exr")
    assert [t.path for t in plans[1].tiles] == [
        os.path.join(tmp_path, "out", ".f.05.tile-0-0.exr"),
        os.path.join(tmp_path, "out", ".f.05.tile-1-0.exr"),
    ]
    assert [t.tile.crop_flag for t in plans[1].tiles] == ["0,0,4,8", "4,0,8,8"]
    assert not plans[1].renders_straight_to_output


def test_frame_listed_twice_is_planned_once():
    plans = plan_job("a.#.vdb", "o.#.exr", [2, 1, 2], (1, 1), [])
    assert [p.frame for p in plans] == [2, 1]


def test_render_job_refuses_a_bad_plan_before_touching_a_cluster():
    # No client and no cluster: the error must come before one would be started.
    with pytest.raises(PlanError, match="ends before it starts"):
        render_job("a.#.vdb", "o.#.exr", "5-1")
    with pytest.raises(PlanError, match="do not fit"):
        render_job("a.#.vdb", "o.#.exr", "1", tiles=(9, 1), render_flags=["--res", "8x8"])

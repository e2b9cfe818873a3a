"""Jobs on a two-worker local cluster: tiled frames match single-machine
renders bit for bit, finished work is never redone, and broken or missing
inputs fail only their own frame."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from cirrus_farm import render_job
from render_helpers import (
    RENDER_FLAGS,
    assert_same_pixels,
    hidden_files,
    make_frame_inputs,
    read_exr,
    render_reference,
)


@pytest.fixture(scope="module")
def tiled_job(tmp_path_factory, cirrus_bin, client):
    """A finished 3-frame job of 2x2 tiles, shared by the tests that read it."""
    folder = tmp_path_factory.mktemp("tiled")
    pattern = make_frame_inputs(folder)
    reports = []
    result = render_job(
        pattern, str(folder / "out.####.exr"), "1-3", tiles=(2, 2),
        render_flags=RENDER_FLAGS, cirrus=cirrus_bin, client=client,
        threads_per_task=1, on_task_done=reports.append,
    )
    return folder, result, reports


def test_tiled_frames_match_single_machine_renders(tiled_job, cirrus_bin, tmp_path):
    folder, result, reports = tiled_job
    assert [(f.frame, f.status, f.error) for f in result.frames] == [
        (1, "rendered", None), (2, "rendered", None), (3, "rendered", None)]
    assert result.summary() == "3 frames: 3 rendered, 0 skipped, 0 failed"
    assert result.ok and result.tiles_rendered == 12 and result.tiles_reused == 0
    # 12 tiles and 3 merges, each reported once, counting up to the total.
    assert [r.done for r in reports] == list(range(1, 16))
    assert sorted((r.frame, r.kind, r.tile) for r in reports if r.kind == "tile") == sorted(
        (f, "tile", (c, r)) for f in (1, 2, 3) for c in (0, 1) for r in (0, 1))
    assert sorted(r.frame for r in reports if r.kind == "merge") == [1, 2, 3]

    pixels = []
    for frame in (1, 2, 3):
        reference = render_reference(
            cirrus_bin, str(folder / f"cloud.{frame:04d}.vdb"), tmp_path / f"ref{frame}.exr")
        assert_same_pixels(folder / f"out.{frame:04d}.exr", reference)
        pixels.append(read_exr(reference)[1]["R"].tobytes())
    # The three inputs differ, so a frame rendered from another's input would fail above.
    assert len(set(pixels)) == 3
    assert hidden_files(folder) == []  # tiles removed after the merge


def test_rerun_of_finished_job_renders_nothing(tiled_job, cirrus_bin, client):
    folder, _, _ = tiled_job
    outputs = sorted(folder.glob("out.*.exr"))
    assert len(outputs) == 3
    before = {p: p.stat().st_mtime_ns for p in outputs}
    reports = []
    result = render_job(
        str(folder / "cloud.####.vdb"), str(folder / "out.####.exr"), [1, 2, 3],
        tiles=(2, 2), render_flags=RENDER_FLAGS, cirrus=cirrus_bin, client=client,
        on_task_done=reports.append,
    )
    assert [f.status for f in result.frames] == ["skipped"] * 3
    assert result.summary() == "3 frames: 0 rendered, 3 skipped, 0 failed"
    assert result.ok and reports == [] and result.tiles_rendered == 0
    assert {p: p.stat().st_mtime_ns for p in outputs} == before


def test_overwrite_renders_again(tmp_path, cirrus_bin, client):
    pattern = make_frame_inputs(tmp_path, {4: "cloud.vdb"})
    output = tmp_path / "out.0004.exr"
    output.write_bytes(b"stale")
    result = render_job(
        pattern, str(tmp_path / "out.####.exr"), "4", render_flags=RENDER_FLAGS,
        cirrus=cirrus_bin, client=client, overwrite=True,
    )
    assert [(f.status, f.tiles_rendered) for f in result.frames] == [("rendered", 1)]
    reference = render_reference(cirrus_bin, str(tmp_path / "cloud.0004.vdb"), tmp_path / "ref.exr")
    assert_same_pixels(output, reference)


def test_untiled_frames_render_straight_to_output(tmp_path, cirrus_bin, client):
    pattern = make_frame_inputs(tmp_path, {1: "sphere_fog.vdb", 2: "fireball.vdb"})
    reports = []
    result = render_job(
        pattern, str(tmp_path / "out.%02d.exr"), [1, 2], render_flags=RENDER_FLAGS,
        cirrus=cirrus_bin, client=client, on_task_done=reports.append,
    )
    assert [(f.status, f.tiles_rendered) for f in result.frames] == [("rendered", 1)] * 2
    assert sorted((r.frame, r.kind) for r in reports) == [(1, "frame"), (2, "frame")]
    for frame in (1, 2):
        reference = render_reference(
            cirrus_bin, str(tmp_path / f"cloud.{frame:04d}.vdb"), tmp_path / f"ref{frame}.exr")
        assert_same_pixels(tmp_path / f"out.{frame:02d}.exr", reference)
    assert hidden_files(tmp_path) == []


def test_existing_tile_is_reused_not_rendered(tmp_path, cirrus_bin, client):
    """A tile file left by an earlier run goes into the frame as it is.

    It is rendered here with another seed, so the merged frame shows it:
    that tile's pixels differ from the reference and all others match.
    """
    pattern = make_frame_inputs(tmp_path, {1: "cloud.vdb"})
    other_seed = [*RENDER_FLAGS[:-1], "99"]
    render_reference(cirrus_bin, str(tmp_path / "cloud.0001.vdb"),
                     tmp_path / ".out.0001.tile-0-0.exr", flags=other_seed, crop="0,0,16,12")
    result = render_job(
        pattern, str(tmp_path / "out.####.exr"), "1", tiles=(2, 2),
        render_flags=RENDER_FLAGS, cirrus=cirrus_bin, client=client,
    )
    frame = result.frames[0]
    assert (frame.status, frame.tiles_rendered, frame.tiles_reused) == ("rendered", 3, 1)

    reference = render_reference(cirrus_bin, str(tmp_path / "cloud.0001.vdb"), tmp_path / "ref.exr")
    reused = render_reference(cirrus_bin, str(tmp_path / "cloud.0001.vdb"),
                              tmp_path / "seed99.exr", flags=other_seed)
    merged, expected, seed99 = (read_exr(p)[1]["G"] for p in
                                (tmp_path / "out.0001.exr", reference, reused))
    assert (merged[:12, :16] == seed99[:12, :16]).all()
    assert (merged[:12, :16] != expected[:12, :16]).any()
    merged[:12, :16] = expected[:12, :16]
    assert merged.tobytes() == expected.tobytes()
    assert hidden_files(tmp_path) == []


def test_broken_and_missing_inputs_fail_only_their_frames(tmp_path, cirrus_bin, cluster):
    """Through the command line, on the cluster's scheduler: frame 2 is
    garbage, frame 4 does not exist; 1 and 3 still render, exit code 1."""
    make_frame_inputs(tmp_path, {1: "cloud.vdb", 3: "fireball.vdb"})
    (tmp_path / "cloud.0002.vdb").write_bytes(os.urandom(3000))
    proc = subprocess.run(
        [sys.executable, "-m", "cirrus_farm", "render", "cloud.####.vdb",
         "--frames", "1-4", "--tiles", "2x1", "--scheduler", cluster.scheduler_address,
         "--cirrus", cirrus_bin, "-o", "out.####.exr", "--", *RENDER_FLAGS],
        cwd=tmp_path, capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 1, proc.stderr
    assert proc.stdout.splitlines()[-1] == "4 frames: 2 rendered, 0 skipped, 2 failed"
    failures = [line for line in proc.stderr.splitlines() if line.startswith("frame ") and " failed: " in line]
    assert len(failures) == 2
    assert failures[0].startswith(f"frame 2 failed: cirrus: {tmp_path / 'cloud.0002.vdb'}: not an OpenVDB")
    assert failures[1].startswith(f"frame 4 failed: cirrus: {tmp_path / 'cloud.0004.vdb'}: ")
    assert sorted(p.name for p in tmp_path.glob("out.*.exr")) == ["out.0001.exr", "out.0003.exr"]
    for frame in (1, 3):
        reference = render_reference(
            cirrus_bin, str(tmp_path / f"cloud.{frame:04d}.vdb"), tmp_path / f"ref{frame}.exr")
        assert_same_pixels(tmp_path / f"out.{frame:04d}.exr", reference)


def test_deep_images_of_tiled_frames_match_single_machine_renders(tmp_path, cirrus_bin, client):
    """`--deep PATTERN`: each tile writes its own deep tile, the merge
    assembles the frame's deep image, bit for bit the untiled render's."""
    pattern = make_frame_inputs(tmp_path, {1: "cloud.vdb"})
    flags = [*RENDER_FLAGS, "--deep", str(tmp_path / "deep.####.exr")]
    result = render_job(
        pattern, str(tmp_path / "out.####.exr"), "1-1", tiles=(2, 2),
        render_flags=flags, cirrus=cirrus_bin, client=client, threads_per_task=1,
    )
    assert result.ok, result.frames
    reference = tmp_path / "ref.deep.exr"
    render_reference(cirrus_bin, str(tmp_path / "cloud.0001.vdb"), tmp_path / "ref.exr",
                     flags=[*RENDER_FLAGS, "--deep", str(reference)])
    merged = (tmp_path / "deep.0001.exr").read_bytes()
    assert len(merged) > 1000 and merged == reference.read_bytes()
    assert hidden_files(tmp_path) == []

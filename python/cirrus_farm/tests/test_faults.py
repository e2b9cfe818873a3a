"""Failures while a job runs: a worker process killed mid-job, a cirrus
process killed by a signal, cirrus reporting an error."""

from __future__ import annotations

import os
import signal
import stat
from pathlib import Path

import pytest

from cirrus_farm import render_job
from cirrus_farm.worker_tasks import CirrusKilled, merge_tiles, render_tile
from render_helpers import (
    DATA,
    RENDER_FLAGS,
    assert_same_pixels,
    make_frame_inputs,
    render_reference,
)


def write_script(path: Path, body: str) -> str:
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return str(path)


def test_job_survives_a_killed_worker(tmp_path, cirrus_bin, client):
    """SIGKILL one worker process while it has tasks; Dask reruns them on
    the other worker (and the restarted one), and every frame comes out
    identical to the single-machine render."""
    pattern = make_frame_inputs(tmp_path, {1: "cloud.vdb", 2: "sphere_fog.vdb"})
    # Slow each cirrus run down so the other worker is busy when one finishes.
    slow_cirrus = write_script(tmp_path / "slow-cirrus", f'sleep 0.3\nexec "{cirrus_bin}" "$@"\n')
    workers_before = set(client.scheduler_info()["workers"])
    pids = client.run(os.getpid)
    killed = {}

    def kill_a_busy_worker(report):
        if killed:
            return
        busy = {addr: keys for addr, keys in client.processing().items() if keys and addr in pids}
        if busy:
            address, keys = next(iter(busy.items()))
            os.kill(pids[address], signal.SIGKILL)
            killed.update(address=address, keys=list(keys))

    result = render_job(
        pattern, str(tmp_path / "out.####.exr"), "1-2", tiles=(2, 2),
        render_flags=RENDER_FLAGS, cirrus=slow_cirrus, client=client,
        threads_per_task=1, on_task_done=kill_a_busy_worker,
    )
    client.wait_for_workers(2, timeout=60)  # the nanny restarts it for later tests

    assert killed["keys"], "the killed worker was running no task"
    assert killed["address"] in workers_before
    assert killed["address"] not in client.scheduler_info()["workers"]
    assert [(f.frame, f.status, f.error) for f in result.frames] == [
        (1, "rendered", None), (2, "rendered", None)]
    for frame in (1, 2):
        reference = render_reference(
            cirrus_bin, str(tmp_path / f"cloud.{frame:04d}.vdb"), tmp_path / f"ref{frame}.exr")
        assert_same_pixels(tmp_path / f"out.{frame:04d}.exr", reference)


def test_cirrus_killed_by_a_signal_is_retried(tmp_path, cirrus_bin, client):
    """The first cirrus run of the job kills itself; the retry renders."""
    pattern = make_frame_inputs(tmp_path, {1: "cloud.vdb"})
    marker = tmp_path / "killed-once"
    dies_once = write_script(
        tmp_path / "dies-once",
        f'if mkdir "{marker}" 2>/dev/null; then kill -9 $$; fi\nexec "{cirrus_bin}" "$@"\n',
    )
    result = render_job(
        pattern, str(tmp_path / "out.####.exr"), "1", tiles=(2, 1),
        render_flags=RENDER_FLAGS, cirrus=dies_once, client=client, retries=2,
    )
    assert marker.is_dir()
    assert [(f.status, f.tiles_rendered) for f in result.frames] == [("rendered", 2)]
    reference = render_reference(cirrus_bin, str(tmp_path / "cloud.0001.vdb"), tmp_path / "ref.exr")
    assert_same_pixels(tmp_path / "out.0001.exr", reference)


def test_cirrus_killed_every_time_fails_the_frame(tmp_path, client):
    always_dies = write_script(tmp_path / "always-dies", "kill -9 $$\n")
    (tmp_path / "in.vdb").write_bytes(b"")
    result = render_job(
        str(tmp_path / "in.vdb"), str(tmp_path / "out.exr"), "1", cirrus=always_dies,
        client=client, retries=1,
    )
    frame = result.frames[0]
    assert frame.status == "failed"
    assert "CirrusKilled" in frame.error and "signal 9" in frame.error
    assert result.summary() == "1 frame: 0 rendered, 0 skipped, 1 failed"


def test_render_tile_tells_errors_from_kills(tmp_path, cirrus_bin):
    """Run in this process: an error is a result, a kill is an exception."""
    bad = tmp_path / "bad.vdb"
    bad.write_bytes(b"not a volume at all")
    outcome = render_tile(cirrus_bin, str(bad), str(tmp_path / "o.exr"), RENDER_FLAGS,
                          None, reuse_existing=False)
    assert outcome["status"] == "failed"
    assert outcome["error"].startswith(f"cirrus: {bad}: not an OpenVDB")

    missing = render_tile(str(tmp_path / "no-cirrus"), str(bad), str(tmp_path / "o.exr"),
                          [], None, reuse_existing=False)
    assert missing["status"] == "failed" and "no-cirrus" in missing["error"]

    with pytest.raises(CirrusKilled, match="signal 9"):
        render_tile(write_script(tmp_path / "dies", "kill -9 $$\n"), str(bad),
                    str(tmp_path / "o.exr"), [], None, reuse_existing=False)
    assert not (tmp_path / "o.exr").exists()


def test_merge_retried_after_its_rename_finds_the_frame_done(tmp_path, cirrus_bin):
    """Run in this process: a first merge attempt renamed the output and
    deleted a tile, then its worker died; the retry must not fail the frame."""
    source = str(tmp_path / "in.vdb")
    (tmp_path / "in.vdb").write_bytes((DATA / "cloud.vdb").read_bytes())
    tiles = [str(tmp_path / ".out.tile-0-0.exr"), str(tmp_path / ".out.tile-1-0.exr")]
    rendered = [render_tile(cirrus_bin, source, path, RENDER_FLAGS, crop, reuse_existing=True)
                for path, crop in zip(tiles, ["0,0,16,25", "16,0,33,25"])]
    assert [r["status"] for r in rendered] == ["rendered", "rendered"]

    output = tmp_path / "out.exr"
    first = merge_tiles(cirrus_bin, str(output), tiles, rendered)
    assert first["status"] == "merged"
    assert not any(os.path.exists(p) for p in tiles)
    reference = render_reference(cirrus_bin, source, tmp_path / "ref.exr")
    assert_same_pixels(output, reference)

    # The retry sees the output and the tiles gone: done, not "no such file".
    before = output.stat().st_mtime_ns
    assert merge_tiles(cirrus_bin, str(output), tiles, rendered)["status"] == "merged"
    assert output.stat().st_mtime_ns == before
    # Without the output, missing tiles are an error naming the tile.
    output.unlink()
    failed = merge_tiles(cirrus_bin, str(output), tiles, rendered)
    assert failed["status"] == "failed" and ".out.tile-0-0.exr" in failed["error"]
    assert not output.exists()

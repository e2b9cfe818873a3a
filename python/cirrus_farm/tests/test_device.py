"""The device a job names reaches every frame's and tile's render: a
tiled GPU frame matches the single-machine GPU render bit for bit, what
the GPU does not render fails its frames naming it, a worker's
$CIRRUS_DEVICE is its default, and a device cirrus does not know stops
the job before it starts."""

from __future__ import annotations

import os

import pytest

from cirrus_farm import render_job, worker_tasks
from cirrus_farm.cli import main
from cirrus_farm.plan import PlanError
from render_helpers import DATA, RENDER_FLAGS, assert_same_pixels, render_reference


def no_adapter(message: str) -> bool:
    """Whether cirrus said there is no Vulkan adapter; then CI (which
    installs lavapipe) fails, and elsewhere the install hint is named."""
    none = "no Vulkan adapter" in message
    if none:
        assert "CI" not in os.environ, message
        assert "mesa-vulkan-drivers" in message, message
    return none


def test_a_gpu_job_renders_tiles_that_merge_to_the_gpu_render(tmp_path, cirrus_bin, client):
    cloud = tmp_path / "cloud.vdb"
    cloud.write_bytes((DATA / "cloud.vdb").read_bytes())
    result = render_job(
        str(cloud), str(tmp_path / "out.exr"), [1], tiles=(2, 1), render_flags=RENDER_FLAGS,
        cirrus=cirrus_bin, client=client, threads_per_task=1, device="gpu",
    )
    [frame] = result.frames
    if frame.status == "failed" and no_adapter(frame.error or ""):
        pytest.skip(frame.error)
    assert (frame.status, frame.error, frame.tiles_rendered) == ("rendered", None, 2)
    reference = render_reference(cirrus_bin, str(cloud), tmp_path / "ref.exr",
                                 flags=[*RENDER_FLAGS, "--device", "gpu"])
    assert_same_pixels(tmp_path / "out.exr", reference)
    cpu = render_reference(cirrus_bin, str(cloud), tmp_path / "cpu.exr")
    assert (tmp_path / "out.exr").read_bytes() != cpu.read_bytes(), "the frame ran on the CPU"


def test_what_the_gpu_does_not_render_fails_the_frame_by_name(tmp_path, cirrus_bin, client):
    cloud = tmp_path / "cloud.vdb"
    cloud.write_bytes((DATA / "cloud.vdb").read_bytes())
    result = render_job(
        str(cloud), str(tmp_path / "out.exr"), [1],
        render_flags=["--res", "8x8", "--spp", "1", "--integrator", "raymarch"],
        cirrus=cirrus_bin, client=client, threads_per_task=1, device="gpu",
    )
    [frame] = result.frames
    assert frame.status == "failed"
    assert "the raymarch integrator" in frame.error or no_adapter(frame.error), frame.error
    assert not (tmp_path / "out.exr").exists()


def test_a_workers_cirrus_device_is_its_default(tmp_path, cirrus_bin, monkeypatch):
    """Run as a worker runs it: $CIRRUS_DEVICE reaches cirrus unless the
    job or the flags name a device."""
    flags = ["--res", "8x8", "--spp", "1", "--integrator", "raymarch"]
    out = str(tmp_path / "w.exr")
    monkeypatch.setenv("CIRRUS_DEVICE", "gpu")
    refused = worker_tasks.render_tile(cirrus_bin, str(DATA / "cloud.vdb"), out, flags, None, False)
    assert refused["status"] == "failed"
    assert "raymarch integrator" in refused["error"] or no_adapter(refused["error"]), refused
    for job_device, extra in (("cpu", []), (None, ["--device", "cpu"])):
        ok = worker_tasks.render_tile(cirrus_bin, str(DATA / "cloud.vdb"), out, flags + extra,
                                      None, False, device=job_device)
        assert ok["status"] == "rendered", ok
        os.remove(out)


def test_unknown_or_doubled_devices_stop_the_job(tmp_path, capsys):
    with pytest.raises(PlanError, match="use one of cpu, auto, gpu"):
        render_job(str(DATA / "cloud.vdb"), str(tmp_path / "o.exr"), [1], device="tpu")
    with pytest.raises(PlanError, match="given twice"):
        render_job(str(DATA / "cloud.vdb"), str(tmp_path / "o.exr"), [1], device="gpu",
                   render_flags=["--device", "cpu"])
    with pytest.raises(SystemExit) as exit_:
        main(["render", str(DATA / "cloud.vdb"), "-o", str(tmp_path / "o.exr"), "--frames", "1",
              "--device", "tpu"])
    assert exit_.value.code == 2
    assert "invalid choice: 'tpu'" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []

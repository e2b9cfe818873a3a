"""A cluster that cannot import cirrus_farm still runs its jobs: the task
functions travel by value, so render nodes need only `distributed` and
the cirrus binary."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import distributed
import pytest

from cirrus_farm import render_job
from render_helpers import RENDER_FLAGS, assert_same_pixels, make_frame_inputs, render_reference

# A scheduler and one in-process worker (no nanny, so no child process that
# could import the package again) for which `import cirrus_farm` fails.
_CLUSTER_WITHOUT_PACKAGE = textwrap.dedent("""
    import sys
    sys.modules["cirrus_farm"] = None  # any import of it now raises
    import asyncio, distributed

    async def main():
        async with distributed.Scheduler(host="127.0.0.1", port=0, dashboard_address=None) as s:
            async with distributed.Worker(s.address, nthreads=1, host="127.0.0.1"):
                print(s.address, flush=True)
                await asyncio.sleep(600)

    asyncio.run(main())
""")


@pytest.fixture
def scheduler_without_package():
    proc = subprocess.Popen([sys.executable, "-c", _CLUSTER_WITHOUT_PACKAGE],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        address = proc.stdout.readline().strip()
        assert address.startswith("tcp://127.0.0.1:"), "the cluster did not start"
        yield address
    finally:
        proc.kill()
        proc.wait()


def test_cluster_needs_no_copy_of_the_package(tmp_path, cirrus_bin, scheduler_without_package):
    with distributed.Client(scheduler_without_package) as client:
        # The cluster really cannot import it, so a by-name pickle would fail there.
        with pytest.raises(ModuleNotFoundError):
            client.run(__import__, "cirrus_farm")
        pattern = make_frame_inputs(tmp_path, {1: "cloud.vdb"})
        result = render_job(
            pattern, str(tmp_path / "out.####.exr"), "1", tiles=(1, 2),
            render_flags=RENDER_FLAGS, cirrus=cirrus_bin, client=client, threads_per_task=1,
        )
    assert [(f.status, f.error, f.tiles_rendered) for f in result.frames] == [("rendered", None, 2)]
    reference = render_reference(cirrus_bin, str(tmp_path / "cloud.0001.vdb"), tmp_path / "ref.exr")
    assert_same_pixels(tmp_path / "out.0001.exr", reference)

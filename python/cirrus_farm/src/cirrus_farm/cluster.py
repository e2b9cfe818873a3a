"""A throwaway Dask cluster on this machine, for `--local` and `render_job` without a client."""

from __future__ import annotations

import contextlib
from typing import Iterator

import distributed


@contextlib.contextmanager
def local_client(workers: int) -> Iterator[distributed.Client]:
    """A cluster of `workers` single-threaded worker processes on loopback.

    Processes rather than threads so that a crashing task takes down only
    its worker, which the nanny restarts and Dask retries elsewhere; bound
    to 127.0.0.1 with no dashboard so nothing listens beyond this machine.
    """
    if workers < 1:
        raise ValueError(f"a local cluster needs at least one worker, got {workers}")
    with distributed.LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster, distributed.Client(cluster) as client:
        yield client

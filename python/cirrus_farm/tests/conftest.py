"""Shared fixtures: the cirrus binary and one Dask cluster for the session.

The cluster is started once for the session because starting worker
processes costs more than most tests; a test that kills a worker waits
for the nanny to bring it back before the next test runs.
"""

from __future__ import annotations

import os
from pathlib import Path

import distributed
import pytest

from render_helpers import REPO


@pytest.fixture(scope="session")
def cirrus_bin() -> str:
    """$CIRRUS_BIN, else the release build; the tests cannot run without it."""
    path = Path(os.environ.get("CIRRUS_BIN") or REPO / "target" / "release" / "cirrus")
    if not path.is_file() or not os.access(path, os.X_OK):
        pytest.fail(f"no cirrus binary at {path}: set CIRRUS_BIN", pytrace=False)
    return str(path.resolve())


@pytest.fixture(scope="session")
def cluster() -> distributed.LocalCluster:
    with distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
    ) as running:
        yield running


@pytest.fixture(scope="session")
def client(cluster: distributed.LocalCluster) -> distributed.Client:
    with distributed.Client(cluster) as connected:
        yield connected

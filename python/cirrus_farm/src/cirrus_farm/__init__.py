"""cirrus-farm: render frame sequences with `cirrus` on a Dask cluster.

`render_job` is the whole API; the `cirrus-farm` command is a thin layer
over it (see `cli.py`).
"""

from .job import FrameResult, JobResult, TaskReport, render_job
from .plan import PlanError

__all__ = ["render_job", "JobResult", "FrameResult", "TaskReport", "PlanError"]

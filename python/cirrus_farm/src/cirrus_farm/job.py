"""Running a planned job on a Dask cluster and collecting what happened.

Each frame becomes a small task graph: one `render_tile` task per tile and
a `merge_tiles` task depending on them (or a single `render_tile` writing
the output when the frame is not tiled). Frames whose output already
exists are not submitted at all. Results are gathered as tasks finish so
progress can be reported over the whole job, and every frame ends as
"rendered", "skipped" or "failed", with the cirrus message when it failed.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import uuid
from dataclasses import dataclass, field
from typing import Callable, Iterable, Iterator, Sequence

import distributed

from . import worker_tasks
from .cluster import local_client
from .frames import FrameSpecError, parse_frame_range
from .plan import FramePlan, PlanError, check_device, plan_job, without_flag
from .shipping import ShippedByValue

RENDER_TILE = ShippedByValue(worker_tasks.render_tile, worker_tasks)
MERGE_TILES = ShippedByValue(worker_tasks.merge_tiles, worker_tasks)


@dataclass
class FrameResult:
    """How one frame ended: status "rendered", "skipped" or "failed"."""

    frame: int
    input: str
    output: str
    status: str
    error: str | None = None
    tiles_rendered: int = 0
    tiles_reused: int = 0


@dataclass
class JobResult:
    """Every frame's result, in frame order, with the counts the CLI prints."""

    frames: list[FrameResult] = field(default_factory=list)

    def count(self, status: str) -> int:
        return sum(1 for f in self.frames if f.status == status)

    @property
    def ok(self) -> bool:
        """True when no frame failed (skipped frames were done before)."""
        return self.count("failed") == 0

    @property
    def tiles_rendered(self) -> int:
        """cirrus render runs that produced a tile or a frame in this job."""
        return sum(f.tiles_rendered for f in self.frames)

    @property
    def tiles_reused(self) -> int:
        """Tile files an earlier run had finished, used without rendering."""
        return sum(f.tiles_reused for f in self.frames)

    def summary(self) -> str:
        """'5 frames: 3 rendered, 1 skipped, 1 failed'."""
        n = len(self.frames)
        return (
            f"{n} frame{'s' if n != 1 else ''}: {self.count('rendered')} rendered, "
            f"{self.count('skipped')} skipped, {self.count('failed')} failed"
        )


@dataclass(frozen=True)
class TaskReport:
    """One finished task, passed to the `on_task_done` callback."""

    done: int
    total: int
    frame: int
    kind: str  # "tile", "frame" (an untiled render) or "merge"
    tile: tuple[int, int] | None  # (column, row) of a tile task
    status: str  # "rendered", "reused", "merged" or "failed"
    seconds: float
    host: str | None
    error: str | None


@dataclass(frozen=True)
class _Submitted:
    """What a future stands for, to turn its result into reports."""

    plan: FramePlan
    kind: str
    tile: tuple[int, int] | None


def render_job(
    input_pattern: str,
    output_pattern: str,
    frames: str | Iterable[int],
    *,
    tiles: tuple[int, int] = (1, 1),
    render_flags: Sequence[str] = (),
    cirrus: str | None = None,
    client: distributed.Client | None = None,
    local_workers: int | None = None,
    overwrite: bool = False,
    retries: int = 3,
    threads_per_task: int | None = None,
    device: str | None = None,
    on_task_done: Callable[[TaskReport], None] | None = None,
) -> JobResult:
    """Renders `frames` of `input_pattern` into `output_pattern` on `client`.

    `frames` is 'A-B[:STEP]' or a list of frame numbers; `tiles` is the
    (columns, rows) grid each frame is split into; `render_flags` go to
    every `cirrus render`. `cirrus` is the binary as the workers see it
    (default: $CIRRUS_BIN, else 'cirrus' on the workers' PATH). Without a
    `client`, a local cluster of `local_workers` processes (default: one
    per core) runs the job, started only if some frame needs rendering.
    `threads_per_task` caps each cirrus run's threads (default: all cores
    of its machine, or an equal share of them on a local cluster).
    `device` ("cpu", "auto" or "gpu", as `cirrus render --device`) is
    where every frame's and tile's render runs; without it, each worker's
    $CIRRUS_DEVICE, else the scene's `[render] device` (the CPU unless it
    says otherwise). "auto" suits a mixed cluster: a hardware GPU where a
    worker has one, else its CPU.

    Plan errors (bad patterns, tiles, flags) raise `PlanError` before
    anything runs; a frame that fails does not stop the others and shows
    up in the result instead.
    """
    try:
        frame_list = parse_frame_range(frames) if isinstance(frames, str) else list(frames)
    except FrameSpecError as e:
        raise PlanError(str(e)) from None
    plans = plan_job(input_pattern, output_pattern, frame_list, tiles, render_flags)
    check_device(device, render_flags)
    cirrus = _binary_path(cirrus or os.environ.get("CIRRUS_BIN") or "cirrus")
    results = {p.frame: FrameResult(p.frame, p.input, p.output, "pending") for p in plans}
    todo = []
    for plan in plans:
        if not overwrite and os.path.exists(plan.output):
            results[plan.frame].status = "skipped"
        else:
            todo.append(plan)
    if todo:
        if client is None and threads_per_task is None:
            # Local workers share this machine's cores instead of each taking all.
            threads_per_task = max(1, (os.cpu_count() or 1) // (local_workers or os.cpu_count() or 1))
        with _client_or_local(client, local_workers) as running:
            submitted = _submit(running, todo, cirrus, render_flags, overwrite,
                                retries, threads_per_task, device)
            _collect(submitted, results, on_task_done)
    return JobResult([results[f] for f in sorted(results)])


def _binary_path(cirrus: str) -> str:
    """A path to the binary made absolute (workers have other working dirs);
    a bare name is left for each worker's PATH to resolve."""
    return os.path.abspath(cirrus) if os.sep in cirrus else cirrus


@contextlib.contextmanager
def _client_or_local(
    client: distributed.Client | None, local_workers: int | None
) -> Iterator[distributed.Client]:
    if client is not None:
        yield client
    else:
        with local_client(local_workers or os.cpu_count() or 1) as own:
            yield own


def _submit(
    client: distributed.Client,
    plans: Sequence[FramePlan],
    cirrus: str,
    render_flags: Sequence[str],
    overwrite: bool,
    retries: int,
    threads: int | None,
    device: str | None,
) -> dict[distributed.Future, _Submitted]:
    """Submits every frame's tasks; earlier frames get higher priority so
    finished frames (and their merges) appear in order, not all at the end."""
    job_id = uuid.uuid4().hex[:8]
    cwd = os.getcwd()
    # Each task gets its own deep file (`--deep` names the frames').
    flags = without_flag(render_flags, "--deep")

    def task_flags(deep: str | None) -> list[str]:
        return flags + ["--deep", deep] if deep else flags

    submitted: dict[distributed.Future, _Submitted] = {}
    for order, plan in enumerate(plans):
        priority = -order
        frame_key = f"cirrus-{job_id}-frame{plan.frame}"
        if plan.renders_straight_to_output:
            future = client.submit(
                RENDER_TILE, cirrus, plan.input, plan.output, task_flags(plan.deep),
                None, False, threads, cwd, device,
                key=f"{frame_key}-render", retries=retries, priority=priority,
            )
            submitted[future] = _Submitted(plan, "frame", None)
            continue
        tile_futures = []
        for task in plan.tiles:
            tile = task.tile
            assert tile is not None
            future = client.submit(
                RENDER_TILE, cirrus, plan.input, task.path, task_flags(task.deep),
                tile.crop_flag, not overwrite, threads, cwd, device,
                key=f"{frame_key}-tile-{tile.column}-{tile.row}",
                retries=retries, priority=priority,
            )
            submitted[future] = _Submitted(plan, "tile", (tile.column, tile.row))
            tile_futures.append(future)
        merge = client.submit(
            MERGE_TILES, cirrus, plan.output,
            [t.path for t in plan.tiles], tile_futures, threads, cwd,
            plan.deep, [t.deep for t in plan.tiles if t.deep],
            key=f"{frame_key}-merge", retries=retries, priority=priority + 1,
        )
        submitted[merge] = _Submitted(plan, "merge", None)
    return submitted


def _collect(
    submitted: dict[distributed.Future, _Submitted],
    results: dict[int, FrameResult],
    on_task_done: Callable[[TaskReport], None] | None,
) -> None:
    """Waits for every task, filling in `results` and reporting each one.

    A task that raised even after its retries (cirrus killed every time,
    workers dying too often) becomes a "failed" outcome with the exception
    as its message; Dask fails the frame's merge with the same exception.
    """
    total = len(submitted)
    for done, future in enumerate(distributed.as_completed(list(submitted)), start=1):
        what = submitted[future]
        if future.status == "finished":
            outcome = future.result()
        else:
            try:
                exc = future.exception()
            except (Exception, asyncio.CancelledError) as cancelled:
                exc = cancelled
            if exc is None:  # e.g. the scheduler could not unpickle the task
                error = f"task ended as {future.status!r}; see the scheduler's log"
            else:
                error = f"{type(exc).__name__}: {exc}"
            outcome = {"status": "failed", "error": error}
        frame = results[what.plan.frame]
        status = outcome["status"]
        if what.kind == "tile":
            frame.tiles_rendered += status == "rendered"
            frame.tiles_reused += status == "reused"
        else:
            frame.tiles_rendered += what.kind == "frame" and status == "rendered"
            frame.status = "failed" if status == "failed" else "rendered"
            frame.error = outcome.get("error")
        if on_task_done is not None:
            on_task_done(TaskReport(
                done, total, what.plan.frame, what.kind, what.tile, status,
                outcome.get("seconds", 0.0), outcome.get("host"), outcome.get("error"),
            ))

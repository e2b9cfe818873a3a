"""The functions that run on Dask workers: one `cirrus` process each.

This module uses the standard library only and returns plain dicts, and
the job ships it to the workers by value (cloudpickle), so a worker needs
`distributed` and the `cirrus` binary but not this package.

Two kinds of failure are told apart on purpose. cirrus exiting with an
error (a missing or broken input) is a fact about the frame that no retry
changes, so it comes back as a result with status "failed" and the
cirrus message. cirrus killed by a signal (the machine ran out of memory,
someone killed it) may well succeed elsewhere, so it raises, and Dask's
`retries` runs the task again.
"""

from __future__ import annotations

import os
import socket
import subprocess
import time
from typing import Sequence


class CirrusKilled(RuntimeError):
    """cirrus died from a signal: worth running again on another worker."""


def _cirrus_error(stderr: str, returncode: int) -> str:
    """The line that says what went wrong: cirrus's own 'cirrus: <file>: ...',
    else a command-line parser's 'error: ...', else the last line."""
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    for prefix in ("cirrus:", "error:"):
        for line in reversed(lines):
            if line.startswith(prefix):
                return line
    return lines[-1] if lines else f"cirrus exited with code {returncode}"


def _run_cirrus(args: Sequence[str], threads: int | None, cwd: str | None) -> dict:
    """Runs cirrus to completion; a dict with status "ok" or "failed".

    `threads` caps cirrus's thread pool (RAYON_NUM_THREADS) so that several
    workers on one machine do not each start one thread per core. `cwd` is
    the client's working directory, used when this machine has it too, so
    relative paths among the pass-through flags mean what the user meant.
    """
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    if cwd is not None and not os.path.isdir(cwd):
        cwd = None
    start = time.monotonic()
    try:
        proc = subprocess.run(
            list(args), capture_output=True, text=True, env=env, cwd=cwd, check=False
        )
    except OSError as e:
        # The binary is missing or not executable here: retrying elsewhere
        # would hide a broken worker setup, so report it with the host name.
        return {
            "status": "failed",
            "error": f"cannot run {args[0]} on {socket.gethostname()}: {e}",
        }
    seconds = time.monotonic() - start
    if proc.returncode < 0:
        raise CirrusKilled(
            f"{args[0]} {args[1]} was killed by signal {-proc.returncode} "
            f"on {socket.gethostname()}"
        )
    if proc.returncode != 0:
        return {"status": "failed", "error": _cirrus_error(proc.stderr, proc.returncode)}
    return {"status": "ok", "seconds": seconds}


def render_tile(
    cirrus: str,
    input_path: str,
    output_path: str,
    render_flags: Sequence[str],
    crop: str | None,
    reuse_existing: bool,
    threads: int | None = None,
    cwd: str | None = None,
    device: str | None = None,
) -> dict:
    """Renders one tile (or a whole frame if `crop` is None) to `output_path`.

    `device` is the job's (`cirrus render --device`); without one, and
    without `--device` among the flags, this worker's $CIRRUS_DEVICE (a
    GPU node's workers may set it to "gpu" or "auto").

    cirrus writes its output to a temporary name and renames it, so an
    existing file is a finished one: with `reuse_existing` it is kept and
    not rendered again, which is what lets a stopped job resume.
    """
    host = socket.gethostname()
    if reuse_existing and os.path.exists(output_path):
        return {"status": "reused", "seconds": 0.0, "host": host}
    args = [cirrus, "render", input_path, "-o", output_path, *render_flags]
    given = any(f == "--device" or f.startswith("--device=") for f in render_flags)
    device = device or (None if given else os.environ.get("CIRRUS_DEVICE") or None)
    if device is not None:
        args += ["--device", device]
    if crop is not None:
        args += ["--crop", crop]
    outcome = _run_cirrus(args, threads, cwd)
    if outcome["status"] == "ok":
        outcome["status"] = "rendered"
    outcome["host"] = host
    return outcome


def merge_tiles(
    cirrus: str,
    output_path: str,
    tile_paths: Sequence[str],
    tile_outcomes: Sequence[dict],
    threads: int | None = None,
    cwd: str | None = None,
    deep_output: str | None = None,
    deep_tiles: Sequence[str] = (),
) -> dict:
    """Merges a frame's tiles into `output_path`, then deletes the tiles.

    `tile_outcomes` are the results of the frame's `render_tile` tasks;
    taking them as arguments makes Dask run this only after all of them.
    If a tile failed, the frame failed with the tile's message, and the
    tiles that did render stay on disk for the next run to reuse.

    The merge writes to a temporary name in the output's folder and
    renames it, so the output exists only once it is complete, even if
    this worker dies mid-write. Deep tiles (`--deep`) merge into
    `deep_output` first, so a finished output means a finished deep image.
    """
    host = socket.gethostname()
    for outcome in tile_outcomes:
        if outcome["status"] == "failed":
            return {"status": "failed", "error": outcome["error"], "host": host}
    if os.path.exists(output_path) and not all(os.path.exists(p) for p in tile_paths):
        # An earlier attempt renamed the output into place and began deleting
        # the tiles before its worker died: the frame is done.
        return {"status": "merged", "seconds": 0.0, "host": host}
    merges = [(deep_output, list(deep_tiles))] if deep_output else []
    merges.append((output_path, list(tile_paths)))
    for target, parts in merges:
        folder, name = os.path.split(target)
        partial = os.path.join(folder, f".{name}.merging-{os.getpid()}.exr")
        outcome = _run_cirrus([cirrus, "merge", partial, *parts], threads, cwd)
        outcome["host"] = host
        if outcome["status"] != "ok":
            _remove_quietly(partial)
            return outcome
        os.replace(partial, target)
    for path in [*tile_paths, *deep_tiles]:
        _remove_quietly(path)
    outcome["status"] = "merged"
    return outcome


def _remove_quietly(path: str) -> None:
    """Deletes `path` if it is there; a retried merge may have done so first."""
    try:
        os.remove(path)
    except FileNotFoundError:
        pass

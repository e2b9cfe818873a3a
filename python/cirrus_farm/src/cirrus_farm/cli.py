"""`cirrus-farm render ...`: the command line over `render_job`.

Exit code 0 only when every frame is rendered or was already there, 1
when any frame failed (or the cluster could not be reached), 2 for a
command line that cannot be run at all.
"""

from __future__ import annotations

import argparse
import sys
from typing import Sequence

import distributed

from .frames import FrameSpecError, parse_frame_range
from .job import TaskReport, render_job
from .plan import PlanError, check_device, plan_job
from .tiles import TileSpecError, parse_size

USAGE_EXAMPLE = (
    "example: cirrus-farm render cloud.####.vdb --frames 1-24 --tiles 2x2 "
    "--local 2 -o out.####.exr -- --res 256x256 --spp 16"
)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cirrus-farm",
        description="Render frame sequences with cirrus on a Dask cluster.",
        epilog=USAGE_EXAMPLE,
    )
    commands = parser.add_subparsers(dest="command", required=True)
    render = commands.add_parser(
        "render",
        help="render frames, split into tiles, on local or remote workers",
        description=(
            "Render every frame of INPUT (a .vdb/.nvdb/.cbrk or .toml scene; '####' "
            "or '%04d' stands for the frame number) into OUT_PATTERN. Flags after "
            "'--' go to every 'cirrus render'. Frames whose output exists are "
            "skipped and finished tiles are reused, so rerunning resumes a job."
        ),
        epilog=USAGE_EXAMPLE,
    )
    render.add_argument("input", metavar="INPUT", help="input file pattern")
    render.add_argument("-o", "--output", required=True, metavar="OUT_PATTERN",
                        help="output EXR pattern, e.g. out.####.exr")
    render.add_argument("--frames", required=True, metavar="A-B[:STEP]",
                        help="frames to render, both ends included")
    render.add_argument("--tiles", default="1x1", metavar="CxR",
                        help="split each frame into C columns and R rows of tiles (default 1x1)")
    where = render.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="tcp://HOST:8786",
                       help="run on the workers of this Dask scheduler")
    where.add_argument("--local", type=int, metavar="N",
                       help="run on N worker processes on this machine (default: one per core)")
    render.add_argument("--cirrus", metavar="PATH",
                        help="the cirrus binary as the workers see it "
                             "(default: $CIRRUS_BIN, else 'cirrus' on their PATH)")
    render.add_argument("--overwrite", action="store_true",
                        help="render frames and tiles again even if their files exist")
    render.add_argument("--retries", type=int, default=3, metavar="N",
                        help="times a task that raised (its cirrus killed by a signal) is run "
                             "again (default 3); tasks of a dead worker are rerun by the scheduler")
    render.add_argument("--device", choices=("cpu", "auto", "gpu"),
                        help="where every render runs, as 'cirrus render --device': cpu, auto "
                             "(a hardware GPU where a worker has one, else its CPU) or gpu "
                             "(default: each worker's $CIRRUS_DEVICE, else the scene's "
                             "[render] device, else cpu)")
    render.add_argument("--threads-per-task", type=int, metavar="N",
                        help="cirrus threads per task (default: cores / N with --local, "
                             "all cores with --scheduler)")
    return parser


def _split_at_double_dash(argv: Sequence[str]) -> tuple[list[str], list[str]]:
    """The farm's own arguments and the flags after '--' meant for cirrus."""
    argv = list(argv)
    if "--" in argv:
        i = argv.index("--")
        return argv[:i], argv[i + 1 :]
    return argv, []


def _print_progress(report: TaskReport) -> None:
    """One line on stderr per finished task, so a long job shows it is alive."""
    what = {"tile": f"tile {report.tile[0]},{report.tile[1]}" if report.tile else "tile",
            "frame": "render", "merge": "merge"}[report.kind]
    width = len(str(report.total))
    line = f"[{report.done:>{width}}/{report.total}] frame {report.frame} {what}: {report.status}"
    if report.status in ("rendered", "merged"):
        line += f" in {report.seconds:.2f} s"
        if report.host:
            line += f" on {report.host}"
    if report.error and report.kind != "tile":
        line += f": {report.error}"
    print(line, file=sys.stderr, flush=True)


def main(argv: Sequence[str] | None = None) -> int:
    own, render_flags = _split_at_double_dash(sys.argv[1:] if argv is None else argv)
    parser = _parser()
    args = parser.parse_args(own)
    try:
        frames = parse_frame_range(args.frames)
        tiles = parse_size(args.tiles, "--tiles")
    except (FrameSpecError, TileSpecError) as e:
        parser.error(str(e))
    if args.local is not None and args.local < 1:
        parser.error("--local needs at least one worker")
    if args.retries < 0:
        parser.error("--retries must not be negative")

    job = dict(
        tiles=tiles, render_flags=render_flags, cirrus=args.cirrus,
        local_workers=args.local, overwrite=args.overwrite, retries=args.retries,
        threads_per_task=args.threads_per_task, device=args.device,
        on_task_done=_print_progress,
    )
    try:
        if args.scheduler:
            # Checked before connecting, so a typo does not wait on the network.
            plan_job(args.input, args.output, frames, tiles, render_flags)
            check_device(args.device, render_flags)
            try:
                client = distributed.Client(args.scheduler)
            except OSError as e:  # unreachable: distributed raises OSError or TimeoutError
                print(f"cirrus-farm: cannot reach {args.scheduler}: {e}", file=sys.stderr)
                return 1
            with client:
                result = render_job(args.input, args.output, frames, client=client, **job)
        else:
            result = render_job(args.input, args.output, frames, **job)
    except PlanError as e:
        print(f"cirrus-farm: {e}", file=sys.stderr)
        return 2

    for frame in result.frames:
        if frame.status == "failed":
            print(f"frame {frame.frame} failed: {frame.error}", file=sys.stderr)
    print(result.summary())
    return 0 if result.ok else 1


if __name__ == "__main__":
    sys.exit(main())

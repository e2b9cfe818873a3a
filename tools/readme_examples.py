"""Runs the README's shell examples that make files from what the
repository has, as written, and checks each wrote what it names.

A block is run when it is a ```sh block calling `cirrus` or a tools/
script on inputs the checkout has (data/, tools/); blocks about files a
reader brings (`shot.usda`, `cloud.####.vdb`, a farm's hosts) are listed
as skipped. Each block runs with bash -e in a fresh folder holding links
to data/ and tools/, with the release `cirrus` first on PATH and the
given Python (numpy and OpenEXR, as the README says) as `python`.

    usage: python tools/readme_examples.py [PYTHON]
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# What marks an example about the reader's own files or machines.
PLACEHOLDERS = ("####", "%04d", "shot.", "smoke.vdb", "hostA", "/shared/", "FILE", "OUT.")
# Examples another script already runs in the test suite.
ELSEWHERE = {
    "build_blender_addon.sh": "tools/test_blender.sh",
    "tools/render_default.sh": ".ci/run",
    "tools/test.sh": ".ci/run, which runs this script through it",
}


def blocks(readme: str) -> list[str]:
    return re.findall(r"```sh\n(.*?)```", readme, re.S)


def outputs(block: str) -> list[str]:
    """The files a block says it writes: `-o X`, `--png X`, `--deep X`,
    and a tools/ script's output arguments ending in an image suffix."""
    named = re.findall(r"(?:-o|--png|--deep)\s+(\S+)", block)
    named += re.findall(r"holdout_example\.py \w+ (?:\S+ )*?(\S+\.(?:exr|png))\s*(?:#|$|--)",
                        block, re.M)
    return sorted(set(named))


def main() -> int:
    python = sys.argv[1] if len(sys.argv) > 1 else sys.executable
    cirrus = ROOT / "target" / "release" / "cirrus"
    if not cirrus.exists():
        print(f"readme_examples: build {cirrus} first", file=sys.stderr)
        return 2
    readme = (ROOT / "README.md").read_text()
    ran = skipped = failed = 0
    for block in blocks(readme):
        if "cirrus " not in block and "tools/" not in block:
            continue
        first = block.strip().splitlines()[0]
        if any(p in block for p in PLACEHOLDERS):
            print(f"skipped (the reader's own files): {first}")
            skipped += 1
            continue
        covered = [f"{k} (run by {v})" for k, v in ELSEWHERE.items() if k in block]
        if covered:
            print(f"skipped, {covered[0]}: {first}")
            skipped += 1
            continue
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(tmp)
            for name in ("data", "tools"):
                (work / name).symlink_to(ROOT / name)
            bin_dir = work / "bin"
            bin_dir.mkdir()
            (bin_dir / "cirrus").symlink_to(cirrus)
            # The Python's own folder on PATH (not a link to it: a venv's
            # interpreter finds its packages by the path it was run from).
            py_dir = os.path.dirname(os.path.abspath(shutil.which(python) or python))
            if not (Path(py_dir) / "python").exists():
                (bin_dir / "python").symlink_to(os.path.join(py_dir, Path(python).name))
            env = dict(os.environ, PATH=f"{bin_dir}:{py_dir}:{os.environ['PATH']}")
            run = subprocess.run(["bash", "-e", "-c", block], cwd=work, env=env,
                                 capture_output=True, text=True)
            missing = [o for o in outputs(block) if not (work / o).is_file()]
            if run.returncode != 0 or missing:
                failed += 1
                print(f"FAILED: {first}\n  exit {run.returncode}, missing {missing}\n"
                      f"{run.stderr[-2000:]}")
            else:
                ran += 1
                print(f"ok ({', '.join(outputs(block))}): {first}")
    print(f"README examples: {ran} passed, {failed} failed, {skipped} skipped")
    return 1 if failed or ran == 0 else 0


if __name__ == "__main__":
    sys.exit(main())

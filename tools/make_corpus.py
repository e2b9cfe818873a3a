#!/usr/bin/python3
"""Generate the cirrus test corpus of OpenVDB (.vdb) and NanoVDB (.nvdb) files.

Usage (Debian's own interpreter, the only one that can import pyopenvdb):

    /usr/bin/python3 tools/make_corpus.py data

Every file is written with Debian's OpenVDB 10.0.1 stack (pyopenvdb, vdb_tool,
nanovdb_convert), read back, described in OUTDIR/manifest.json and cross-checked
against vdb_print / nanovdb_print / nanovdb_validate.  Content is deterministic
(seeded numpy RNGs, no clocks); only the random UUID that OpenVDB puts in every
.vdb header changes between runs.  See tools/README.md for the manifest schema.

The files are written by the cases of corpus_cases.py and described and
cross-checked by corpus_manifest.py; corpus_plumbing.py holds what both share
(the Product record, the output context, tool runs, seeded RNGs, CorpusError).
This script runs the cases in order, describes every product and writes the
manifest.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import pyopenvdb as vdb

sys.dont_write_bytecode = True  # keep tools/ free of __pycache__
sys.path.insert(0, str(Path(__file__).resolve().parent))
from corpus_cases import CASES  # noqa: E402
from corpus_manifest import cross_check_vdb_print, describe_nvdb, describe_vdb, dump_json  # noqa: E402
from corpus_plumbing import SEED, Ctx  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("outdir")
    args = ap.parse_args()
    t0 = time.time()
    out = Path(args.outdir)
    out.mkdir(parents=True, exist_ok=True)
    old = out / "manifest.json"
    if old.exists():  # remove what a previous run generated, nothing else
        for f in json.loads(old.read_text()).get("files", []):
            (out / f["file"]).unlink(missing_ok=True)
        old.unlink()
    vdb.setLoggingLevel("error")  # silence "more than one grid named" warnings

    with tempfile.TemporaryDirectory(prefix="cirrus_corpus_") as tmp:
        ctx = Ctx(out, Path(tmp))
        for case in CASES:
            t = time.time()
            case(ctx)
            print(f"  {case.__name__:<24} {time.time() - t:6.2f} s", flush=True)

        files, by_file = [], {}
        for prod in ctx.products:
            path = ctx.path(prod.file)
            if prod.format == "vdb":
                entry, vf = describe_vdb(prod, path)
                cross_check_vdb_print(entry, path)
                if prod.check:
                    prod.check(entry, vf)
            else:
                entry = describe_nvdb(prod, path, by_file, ctx.tmp)
            by_file[prod.file] = entry
            files.append(entry)

    manifest = {
        "generator": "tools/make_corpus.py",
        "openvdb_version": ".".join(map(str, vdb.LIBRARY_VERSION)),
        "file_format_version": vdb.FILE_FORMAT_VERSION,
        "seed": SEED,
        "files": files,
    }
    (out / "manifest.json").write_text(dump_json(manifest) + "\n")

    total = 0
    for f in files + [{"file": "manifest.json"}]:
        size = (out / f["file"]).stat().st_size
        total += size
        print(f"  {size:>10,}  {f['file']}")
    print(f"  {total:>10,}  total, {len(files)} corpus files, {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

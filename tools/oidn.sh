#!/usr/bin/env bash
# Installs Intel Open Image Denoise 2.x for cirrus-denoise and prints the
# directory holding libOpenImageDenoise.so.2, the value for CIRRUS_OIDN.
#
# OIDN 2.x is not packaged by Debian; PyPI's `pyoidn` wheel bundles it (with
# its CPU device, built-in weights and TBB) under pyoidn/oidn/lib.
#
#   usage: bash tools/oidn.sh VENV/bin/python
#   CIRRUS_OIDN=$(bash tools/oidn.sh target/venv/bin/python); export CIRRUS_OIDN
#
# (Assign, then export: `export X=$(...)` would hide a failure from set -e.)
# The venv is made with `python3 -m venv` when $1 does not exist yet. Only
# the path goes to stdout; pip's messages go to stderr.
set -euo pipefail

py=${1:?usage: bash tools/oidn.sh VENV/bin/python}
version=${PYOIDN_VERSION:-2.5.1.0}

if [ ! -x "$py" ]; then
  python3 -m venv "$(dirname "$(dirname "$py")")" >&2
fi
"$py" -m pip install --disable-pip-version-check -q "pyoidn==$version" >&2

# The same places, in the same order, that cirrus-denoise searches.
"$py" - <<'PY'
import importlib.util, os, sys
spec = importlib.util.find_spec("pyoidn")
if spec is None or not spec.submodule_search_locations:
    sys.exit("tools/oidn.sh: pyoidn is not importable after pip install")
pkg = list(spec.submodule_search_locations)[0]
for d in (os.path.join(pkg, "oidn", "lib"), pkg, os.path.join(pkg, "lib"),
          os.path.join(pkg, ".libs"), os.path.join(os.path.dirname(pkg), "pyoidn.libs")):
    if os.path.isfile(os.path.join(d, "libOpenImageDenoise.so.2")):
        print(os.path.realpath(d))
        break
else:
    sys.exit("tools/oidn.sh: no libOpenImageDenoise.so.2 in the pyoidn package at " + pkg)
PY

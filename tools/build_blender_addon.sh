#!/usr/bin/env bash
# Builds the Blender extension zip (python/cirrus_blender) with the cirrus
# wheel inside it, for Blender 4.2+'s "Install from Disk":
#   bash tools/build_blender_addon.sh [OUT.zip]   (default target/cirrus_blender.zip)
# Needs cargo and a Python with pip (for maturin); the wheel is abi3 for
# CPython 3.11+, which covers Blender 4.2-5.x's bundled Python.
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "${1:-target/cirrus_blender.zip}")
stage=target/blender_addon
rm -rf "$stage" && mkdir -p "$stage/wheels"
python=${PYTHON:-python3}
[ -x target/venv-build/bin/python ] || "$python" -m venv target/venv-build
target/venv-build/bin/python -m pip install -q "maturin>=1.9,<2"
target/venv-build/bin/maturin build --release -q -m crates/python/Cargo.toml -o "$stage/wheels" >&2
wheel=$(cd "$stage/wheels" && ls cirrus-*.whl | head -n 1)
cp python/cirrus_blender/*.py "$stage/"
sed "s|^# wheels = .*|wheels = [\"./wheels/$wheel\"]|" python/cirrus_blender/blender_manifest.toml \
  > "$stage/blender_manifest.toml"
rm -f "$out"
(cd "$stage" && target_out="$out" && "$OLDPWD/target/venv-build/bin/python" - "$target_out" <<'PY'
import sys, zipfile, pathlib
out = sys.argv[1]
with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
    for p in sorted(pathlib.Path(".").rglob("*")):
        if p.is_file():
            z.write(p, p.as_posix())
PY
)
echo "$out"

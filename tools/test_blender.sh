#!/usr/bin/env bash
# The Blender add-on's tests (python/cirrus_blender/tests) under PyPI's
# bpy 5.2.3, which is built for CPython 3.13: finds or installs a 3.13
# (tools/python313.sh), makes target/venv-blender with bpy and the cirrus
# module, installs the add-on from its zip inside Blender and renders
# against Cycles. Without any CPython 3.13 it says so and skips.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! py313=$(bash tools/python313.sh); then
  echo "SKIPPED: the Blender add-on tests need CPython 3.13 (bpy 5.2.3); none was found or installable"
  exit 0
fi
venv=target/venv-blender
[ -x "$venv/bin/python" ] || "$py313" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q "bpy==5.2.3" numpy pytest "maturin>=1.9,<2"
VIRTUAL_ENV="$PWD/$venv" PATH="$PWD/$venv/bin:$PATH" \
  "$venv/bin/maturin" develop --release -q -m crates/python/Cargo.toml
"$venv/bin/python" -m pytest -q -s python/cirrus_blender/tests

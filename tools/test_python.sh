#!/usr/bin/env bash
# Builds the Python module into a venv (target/venv, made if missing) with
# maturin and runs its pytest suite against the release `cirrus` binary.
# Usage: bash tools/test_python.sh [PYTHON]   (default: python3)
set -euo pipefail
cd "$(dirname "$0")/.."
python=${1:-python3}
venv=target/venv
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q "maturin>=1.9,<2" numpy pytest "OpenEXR>=3.5" mmh3 usd-core
VIRTUAL_ENV="$PWD/$venv" PATH="$PWD/$venv/bin:$PATH" \
  "$venv/bin/maturin" develop --release -q -m crates/python/Cargo.toml
[ -x target/release/cirrus ] || cargo build --release -p cirrus-cli
CIRRUS_BIN="$PWD/target/release/cirrus" "$venv/bin/python" -m pytest -q crates/python/tests

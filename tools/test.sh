#!/usr/bin/env bash
# Every test of the project, as CI runs them: the Rust workspace (the
# denoiser's tests with the real Open Image Denoise library from PyPI's
# pyoidn), the Python module (with Pixar's usd-core for the USD stages),
# the Dask farm driver, `cirrus preview` in headless Chromium, and the
# Blender add-on under PyPI's bpy (CPython 3.13, tools/python313.sh).
# Needs: cargo, python3 (3.11+) with venv and pip, and the package indexes;
# installs Debian's OpenEXR C library (for the deep images) when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
# OpenEXR's C library, which deep images (and their tests) load at run
# time: Debian's libopenexr-3-1-30, installed when missing.
if ! /sbin/ldconfig -p 2>/dev/null | grep -q 'libOpenEXRCore'; then
  if command -v apt-get >/dev/null; then
    SUDO=
    [ "$(id -u)" = 0 ] || SUDO=sudo
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
      libopenexr-3-1-30 >/dev/null
  else
    echo "tools/test.sh: the deep-image tests need OpenEXR 3.1+'s libOpenEXRCore" >&2
  fi
fi
[ -x target/venv/bin/python ] || "$python" -m venv target/venv
CIRRUS_OIDN=$(bash tools/oidn.sh target/venv/bin/python)
export CIRRUS_OIDN
cargo test --workspace --release
bash tools/test_python.sh "$python"
# The README's shell examples that make files, as written (numpy and
# OpenEXR from the venv the Python tests made).
target/venv/bin/python tools/readme_examples.py target/venv/bin/python
bash tools/test_farm.sh target/venv/bin/python
bash tools/browser_test.sh
bash tools/test_blender.sh

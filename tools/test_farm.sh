#!/usr/bin/env bash
# Installs python/cirrus_farm with its test extras into a virtualenv and runs
# its pytest suite against a built cirrus binary.
#
#   bash tools/test_farm.sh [VENV_PYTHON]
#
# VENV_PYTHON: the python of an existing virtualenv to install into; without
# it, target/farm-venv is created (or reused). CIRRUS_BIN: the binary to
# test with (default target/release/cirrus). Needs python3 >= 3.11 with pip
# and a package registry; never builds cirrus itself.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

cirrus_bin="${CIRRUS_BIN:-target/release/cirrus}"
if [[ ! -x "$cirrus_bin" ]]; then
    echo "test_farm: no cirrus binary at $cirrus_bin (build it, or set CIRRUS_BIN)" >&2
    exit 1
fi
cirrus_bin="$(cd "$(dirname "$cirrus_bin")" && pwd)/$(basename "$cirrus_bin")"

if [[ $# -ge 1 ]]; then
    python="$1"
else
    venv="$root/target/farm-venv"
    if [[ ! -x "$venv/bin/python" ]]; then
        # Debian's python3 lacks ensurepip until python3-venv is installed.
        if ! python3 -m venv "$venv" 2>/dev/null; then
            rm -rf "$venv"
            if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null; then
                version="$(python3 -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')"
                apt-get update -qq
                DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "python${version}-venv" >/dev/null
                python3 -m venv "$venv"
            else
                echo "test_farm: 'python3 -m venv' failed; install python3-venv or pass a venv's python" >&2
                exit 1
            fi
        fi
    fi
    python="$venv/bin/python"
fi

"$python" -c 'import sys; assert sys.version_info >= (3, 11), "cirrus-farm needs Python 3.11+"'

# Keep the source tree clean: no bytecode or pytest cache beside the tests.
export PYTHONDONTWRITEBYTECODE=1
"$python" -m pip install --quiet --disable-pip-version-check "$root/python/cirrus_farm[test]"

CIRRUS_BIN="$cirrus_bin" "$python" -m pytest -p no:cacheprovider -q "$root/python/cirrus_farm/tests"

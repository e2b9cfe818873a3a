#!/usr/bin/env bash
# Prints the path of a CPython 3.13 (what PyPI's bpy 5.2.3 is built for),
# finding one or installing one; exits 1 with a message when it cannot.
# Looks at $PYTHON313, python3.13 on PATH, pyenv's versions (this
# project's machine image has 3.13 under ~/.pyenv; the binary is called
# directly, as pyenv's shim can refuse a version not selected), then tries
# `pyenv install 3.13` and Debian's python3.13 (trixie and later).
set -uo pipefail
is313() { [ -x "$1" ] && "$1" -c 'import sys, venv; sys.exit(sys.version_info[:2] != (3, 13))' 2>/dev/null; }
pyenv_root=$(pyenv root 2>/dev/null || echo "$HOME/.pyenv")
candidates=("${PYTHON313:-}" "$(command -v python3.13 || true)")
for p in "$pyenv_root"/versions/3.13*/bin/python3.13; do candidates+=("$p"); done
candidates+=(/usr/bin/python3.13 /usr/local/bin/python3.13)
for c in "${candidates[@]}"; do
  if [ -n "$c" ] && is313 "$c"; then echo "$c"; exit 0; fi
done
if command -v pyenv >/dev/null; then
  pyenv install -s 3.13 >&2 || true
  for p in "$pyenv_root"/versions/3.13*/bin/python3.13; do
    if is313 "$p"; then echo "$p"; exit 0; fi
  done
fi
if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3.13 python3.13-venv >&2 2>/dev/null || true
  if is313 /usr/bin/python3.13; then echo /usr/bin/python3.13; exit 0; fi
fi
echo "no CPython 3.13 found or installable (set PYTHON313=/path/to/python3.13)" >&2
exit 1

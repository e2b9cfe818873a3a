#!/usr/bin/env bash
# Browser test of `cirrus preview` (tools/browser_test.py): headless
# Chromium on the page, checked against `cirrus render` of the same view.
#
#   bash tools/browser_test.sh                  # the test
#   bash tools/browser_test.sh --docs docs/preview.png   # README screenshot
#
# Installs what it needs: Debian's chromium (apt-get, as root or through
# sudo) and websocket-client, numpy and pillow from PyPI into
# $TARGET/browser-venv.
set -euo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-target}

if ! command -v chromium >/dev/null 2>&1; then
    SUDO=; [ "$(id -u)" = 0 ] || SUDO=sudo
    $SUDO apt-get update -q
    $SUDO apt-get install -y -q chromium
fi

VENV=$TARGET/browser-venv
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/pip" install -q websocket-client numpy pillow

cargo build --release -q -p cirrus-cli
TARGET=$(cd "$TARGET" && pwd)    # absolute: the server runs in a temporary directory
CIRRUS=$TARGET/release/cirrus
exec "$VENV/bin/python" tools/browser_test.py --cirrus "$CIRRUS" --preview "$CIRRUS preview" "$@"

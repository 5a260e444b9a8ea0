#!/usr/bin/env bash
# Idempotent set-up of the viewer's browser test (tests/test_viewer_browser.py):
# Debian's chromium (headless) and playwright-core from npm (package-lock.json
# pins it; no browser download: the test points it at /usr/bin/chromium).
# Called from .ci/run; each step is skipped when already done.
set -euo pipefail
cd "$(dirname "$0")"
if [ "$(id -u)" = "0" ]; then SUDO=""; else SUDO="sudo"; fi
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    echo "browser setup: node/npm not found, installing them with apt-get" >&2
    $SUDO apt-get update -qq >&2
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq nodejs npm >&2
fi
if [ ! -x /usr/bin/chromium ]; then
    echo "browser setup: /usr/bin/chromium not found, installing chromium with apt-get" >&2
    $SUDO apt-get update -qq >&2
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium >&2
fi
if [ ! -d node_modules/playwright-core ]; then
    npm ci --silent --no-audit --no-fund >&2
fi

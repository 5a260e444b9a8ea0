#!/usr/bin/env bash
# Idempotent set-up for a fresh machine: OSMesa and Mesa's EGL (the pyrender
# oracle's two GL platforms), a virtualenv in .venv, and the project installed
# editable with its dev extras.
# Safe to run every time: each step is skipped when already done.
set -euo pipefail
cd "$(dirname "$0")/.."

# 1. libOSMesa: pyrender renders off-screen through it (PYOPENGL_PLATFORM=osmesa).
if ! ldconfig -p 2>/dev/null | grep -q 'libOSMesa\.so'; then
    echo "setup: libOSMesa not found, installing libosmesa6 with apt-get" >&2
    if [ "$(id -u)" = "0" ]; then SUDO=""; else SUDO="sudo"; fi
    $SUDO apt-get update -qq >&2
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libosmesa6 >&2
fi

# 1b. Mesa's EGL: crosscheck --gl egl (PYOPENGL_PLATFORM=egl) draws through it,
# on the CPU (llvmpipe, from libgl1-mesa-dri) where there is no GPU.
if ! ldconfig -p 2>/dev/null | grep -q 'libEGL_mesa\.so' || ! ldconfig -p 2>/dev/null | grep -q 'libEGL\.so\.1'; then
    echo "setup: Mesa's EGL not found, installing libegl1 libegl-mesa0 libgl1-mesa-dri with apt-get" >&2
    if [ "$(id -u)" = "0" ]; then SUDO=""; else SUDO="sudo"; fi
    $SUDO apt-get update -qq >&2
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libegl1 libegl-mesa0 libgl1-mesa-dri >&2
fi

# 2. virtualenv + project. Re-install only when pyproject.toml changed.
PY="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ] && ! "$PY" -c "import ensurepip, venv" 2>/dev/null; then
    # Debian's python3 splits venv/ensurepip into python3-venv
    echo "setup: python3-venv missing, installing it with apt-get" >&2
    if [ "$(id -u)" = "0" ]; then SUDO=""; else SUDO="sudo"; fi
    $SUDO apt-get update -qq >&2
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq python3-venv >&2
fi
if [ ! -x .venv/bin/python ]; then
    "$PY" -m venv .venv
fi
stamp=".venv/.wirecheck-installed"
want="$(sha256sum pyproject.toml | cut -d' ' -f1)"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
    .venv/bin/python -m pip install -q --upgrade pip >&2
    .venv/bin/python -m pip install -q -e '.[dev]' >&2
    echo "$want" > "$stamp"
fi

# 3. The test suite's outside programs, each idempotent: Debian's chromium and
# playwright-core for the viewer's browser test (tests/browser/setup.sh); cc,
# node and three.js for the candidate-protocol clients (tests/clients/setup.sh).
bash tests/browser/setup.sh
bash tests/clients/setup.sh

#!/usr/bin/env bash
# Idempotent set-up of the reference candidate clients (tests/test_candidate_programs.py):
# a C compiler, node/npm, and three.js from npm at the version package-lock.json
# pins (npm ci: exactly the lock file). Called from .ci/run, where
# WIRECHECK_REQUIRE_CLIENTS=1 makes a missing client a failure instead of a skip.
set -euo pipefail
cd "$(dirname "$0")"
if [ "$(id -u)" = "0" ]; then SUDO=""; else SUDO="sudo"; fi
missing=()
command -v cc >/dev/null 2>&1 || missing+=(gcc libc6-dev)
{ command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1; } || missing+=(nodejs npm)
if [ ${#missing[@]} -gt 0 ]; then
    echo "clients setup: installing ${missing[*]} with apt-get" >&2
    $SUDO apt-get update -qq >&2
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >&2
fi
lock="$(sha256sum three/package-lock.json | cut -d' ' -f1)"
if [ ! -f three/node_modules/.wirecheck-lock ] || [ "$(cat three/node_modules/.wirecheck-lock)" != "$lock" ]; then
    (cd three && npm ci --silent --no-audit --no-fund >&2)
    echo "$lock" > three/node_modules/.wirecheck-lock
fi

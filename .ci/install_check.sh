#!/usr/bin/env bash
# wirecheck as a user gets it: the wheel built from this checkout, installed
# into a new virtualenv outside the checkout, used from a user's project folder
# that has its own `core/` and `oracles/` packages. Runs renderer on a bundled
# scene, crosscheck (must pass), crosscheck on a faulty candidate (must exit 1),
# and the user's own pytest suite through the plugin (one test passes, one
# fails), and fails if anything was imported from the checkout.
# Needs: .ci/setup.sh done (its .venv builds the wheel; libOSMesa installed).
set -euo pipefail
CHECKOUT="$(cd "$(dirname "$0")/.." && pwd -P)"
PY="${PYTHON:-python3}"
WORK="$(cd "$(mktemp -d "${TMPDIR:-/tmp}/wirecheck-install.XXXXXX")" && pwd -P)"
# kept when a step failed (its outputs are the evidence), removed otherwise
trap 'rc=$?; if [ "$rc" != 0 ]; then step "failed: $WORK kept"; else step "removing $WORK"; rm -rf "$WORK"; fi' EXIT
t0=$SECONDS

fail() { echo "install_check: FAIL: $*" >&2; exit 1; }
step() { echo "install_check: [$((SECONDS - t0)) s] $*" >&2; }
case "$WORK/" in "$CHECKOUT"/*) fail "the work folder $WORK is inside the checkout $CHECKOUT";; esac

# expect CODE NAME CMD...: run CMD in the user's project with the user's
# environment (no PYTHONPATH; every import traced by PYTHONVERBOSE), keep its
# output in $WORK/NAME.out, and fail unless it exits CODE and imported nothing
# from the checkout.
expect() {
    step "run $2"
    local want=$1 name=$2; shift 2
    local out="$WORK/$name.out" got=0
    (cd "$WORK/project" && env -u PYTHONPATH -u PYTHONHOME PYTHONVERBOSE=1 WIRECHECK_CHECKOUT="$CHECKOUT" "$@") \
        >"$out" 2>&1 || got=$?
    # the import trace; no user output names the checkout
    if grep -F "$CHECKOUT/" "$out" >"$WORK/$name.leak"; then
        head -5 "$WORK/$name.leak" >&2
        fail "$name: imported from the checkout $CHECKOUT (lines above)"
    fi
    if [ "$got" != "$want" ]; then
        grep -v '^#\|^import \|^    \|^Python \|^Type \|^\[' "$out" | tail -40 >&2 || true
        fail "$name: '$*' exited $got, expected $want (output above; all of it in $out)"
    fi
}
# has NAME TEXT: the output of run NAME contains TEXT
has() { grep -qF -- "$2" "$WORK/$1.out" || { tail -40 "$WORK/$1.out" >&2; fail "$1: output lacks '$2'"; }; }

# 1. The wheel: only the wirecheck package, with the bundled scenes and py.typed.
step "building the wheel"
"$CHECKOUT/.venv/bin/python" -m pip wheel -q --no-deps "$CHECKOUT" -w "$WORK/dist" >&2
WHEEL="$(ls "$WORK"/dist/wirecheck-*.whl)"
"$CHECKOUT/.venv/bin/python" - "$WHEEL" <<'EOF' || fail "the wheel's contents (above)"
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
top = sorted({n.split("/")[0] for n in names})
scenes = sorted(n for n in names if n.endswith(".scene"))
print(f"install_check: wheel top level {top}, {len(scenes)} scene files", file=sys.stderr)
assert len(top) == 2 and top[0] == "wirecheck" and top[1].endswith(".dist-info"), f"top level {top}"
assert {"wirecheck/scenes/cube.scene", "wirecheck/scenes/pyramid.scene"} <= set(scenes), scenes
# PEP 561: the package's annotations are shipped, for the users' type checkers
assert "wirecheck/py.typed" in names, "wirecheck/py.typed is not in the wheel (pyproject package-data)"
EOF

# 2. A new virtualenv outside the checkout: the wheel, its dependencies from
# the index (pip's cache makes a second run quick), and the user's pytest.
step "installing it into a new virtualenv in $WORK/venv"
"$PY" -m venv "$WORK/venv"
VENV="$WORK/venv"
"$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-compile "$WHEEL" "pytest>=8,<10" >&2
if grep -rlF "$CHECKOUT" "$VENV"/lib/python*/site-packages/*.pth 2>/dev/null; then
    fail "a .pth file in the new virtualenv points into the checkout"
fi

# 3. The user's project: its own core/ and oracles/ packages (tripwires where
# a bare `core`/`oracles` import by wirecheck would land), its projector in
# core/projection.py, settings in [tool.wirecheck], and a pytest suite.
P="$WORK/project"
mkdir -p "$P/core" "$P/oracles" "$P/tests"
echo '"""The user'"'"'s own package called core."""' >"$P/core/__init__.py"
for f in core/scene.py core/errors.py oracles/__init__.py oracles/api.py; do
    echo "raise ImportError('the user project\\'s $f was imported: wirecheck must import only wirecheck.*')" >"$P/$f"
done
{
    cat "$CHECKOUT/tests/data/user_projector.py"
    cat <<'EOF'


def mirrored(points, camera):
    """The classic fault: right = up x forward, so left and right are exchanged."""
    px = project(points, camera)
    px[:, 0] = (camera.width - 1) - px[:, 0]
    return px
EOF
} >"$P/core/projection.py"
cat >"$P/pyproject.toml" <<'EOF'
[project]
name = "users-project"
version = "0.1"

[tool.pytest.ini_options]
pythonpath = ["."]
testpaths = ["tests"]

[tool.wirecheck]
candidate = "core/projection.py:project"
scenes = ["cube", "pyramid"]
cases = ["on_axis", "near_plane", "orthographic"]
frames = 4
level = "pixels"
EOF
cat >"$P/tests/test_projection.py" <<'EOF'
from core.projection import mirrored, project   # the user's own `core` package


def test_projector_matches_the_references(wirecheck):
    report = wirecheck(project)
    assert report["summary"]["cases"] == 6 and report["level"] == "pixels"


def test_mirrored_projector_is_caught(wirecheck):
    wirecheck(mirrored)
EOF

# 4. From the user's project, with the new virtualenv's tools.
step "running renderer, crosscheck and the user's pytest from $P"
expect 0 where "$VENV/bin/python" -c "
import os, sys, wirecheck, wirecheck.oracles.api
checkout = os.environ['WIRECHECK_CHECKOUT'] + '/'
assert wirecheck.__file__.startswith(sys.prefix + '/'), wirecheck.__file__
assert not any(p.startswith(checkout) or p + '/' == checkout for p in sys.path), sys.path
print('wirecheck', wirecheck.__version__, 'from', os.path.dirname(wirecheck.__file__))"
has where "from $VENV/lib/"

expect 0 renderer "$VENV/bin/renderer" --scene cube --frames 3 --out frames
n_png=$(find "$P/frames" -name '*.png' | wc -l)
[ "$n_png" -ge 3 ] || fail "renderer: $n_png PNG frames in $P/frames, expected 3"

expect 0 crosscheck "$VENV/bin/crosscheck" --run pass --junit-xml junit-pass.xml
has crosscheck "PASS: 6/6 cases"
expect 1 crosscheck-faulty "$VENV/bin/crosscheck" --candidate core/projection.py:mirrored --run faulty \
    --junit-xml junit-faulty.xml
has crosscheck-faulty "FAIL: 0/6 cases"
has crosscheck-faulty "mirror_horizontal"
"$VENV/bin/python" - "$P" <<'EOF' || fail "the JUnit files (above)"
import sys, xml.etree.ElementTree as ET
for name, failures in (("junit-pass.xml", "0"), ("junit-faulty.xml", "6")):
    suite = ET.parse(f"{sys.argv[1]}/{name}").getroot().find("testsuite")
    got = (suite.get("tests"), suite.get("failures"), len(suite.findall("testcase")))
    assert got == ("6", failures, 6), (name, got)
EOF

expect 1 pytest "$VENV/bin/pytest" -q -p no:cacheprovider --wirecheck-report wc-reports
has pytest "1 failed, 1 passed"
has pytest "faults: mirror_horizontal"
has pytest "what to check, mirror_horizontal"
has pytest ">       wirecheck(mirrored)"
if grep -E "site-packages/wirecheck/.*\.py:[0-9]+" "$WORK/pytest.out" | grep -v '^#\|^import \|code object' >&2; then
    fail "pytest: the failure shows wirecheck's own frames (lines above)"
fi
# the folder: the test id made a name, then 8 hex digits of the id's SHA-1 (docs/pytest.md), computed here
id_hash=$(printf '%s' "tests/test_projection.py::test_mirrored_projector_is_caught" | sha1sum | cut -c1-8)
[ -f "$P/wc-reports/tests_test_projection.py_test_mirrored_projector_is_caught-$id_hash/report.json" ] \
    || fail "pytest --wirecheck-report: no report for the failing test under $P/wc-reports"
expect 0 pytest-pass "$VENV/bin/pytest" -q -p no:cacheprovider -k matches_the_references
has pytest-pass "1 passed, 1 deselected"

step "OK in $((SECONDS - t0)) s: wheel installed outside the checkout; renderer, crosscheck (pass, and exit 1 on a mirrored candidate) and the user's pytest (1 pass, 1 fail) ran beside the user's own core/ and oracles/"

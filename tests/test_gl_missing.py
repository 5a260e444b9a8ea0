"""Without the oracle's GL library, every entry point says which library is missing and how to install it.

The libraries are hidden from a subprocess by tests/data/hide_gl/sitecustomize.py (every
``ctypes.CDLL`` of ``libOSMesa.*`` or ``libEGL.*`` fails as the loader does when the library is
not installed). PyOpenGL does not fail then: it leaves its library None, and pyrender's import
dies with ``'NoneType' object has no attribute 'glGetError'`` -- which is what users saw, with a
``pip install`` hint for a package that was installed.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
HIDE = ROOT / "tests" / "data" / "hide_gl"
OSMESA_FIX = "apt-get install -y libosmesa6"
EGL_FIX = "apt-get install -y libegl1 libegl-mesa0 libgl1-mesa-dri"


def _env(hidden: str) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(HIDE), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["WIRECHECK_HIDE_LIBS"] = hidden
    env.pop("PYOPENGL_PLATFORM", None)
    for name in ("CI", "BUILD_NUMBER"):  # pytest prints its summary lines whole under CI: as on a terminal
        env.pop(name, None)
    return env


def _run(args, hidden, cwd=None):
    return subprocess.run(
        args, env=_env(hidden), cwd=cwd, capture_output=True, text=True, timeout=180, stdin=subprocess.DEVNULL
    )


def test_the_library_is_really_hidden():
    # the premise: in the subprocess, loading libOSMesa fails the way a missing library does
    code = (
        "import ctypes, ctypes.util\n"
        "try:\n    ctypes.CDLL('libOSMesa.so.8')\nexcept OSError as e:\n    print('hidden', e)\n"
    )
    done = _run([sys.executable, "-c", code], "OSMesa")
    assert done.stdout.startswith("hidden libOSMesa.so.8: cannot open shared object file")


def _one_line_with_fix(text: str, library: str, fix: str) -> str:
    lines = [line for line in text.splitlines() if line.strip()]
    hits = [line for line in lines if library in line and fix in line]
    assert len(hits) == 1, text
    assert "NoneType" not in text and "pip install" not in text and "Traceback" not in text, text
    return hits[0]


CLI = [sys.executable, "-m", "wirecheck.oracles.cli", "--scene", "cube", "--cases", "on_axis", "--frames", "1"]


def test_cli_without_osmesa_names_libosmesa_and_its_package(tmp_path):
    done = _run(CLI + ["--report-dir", str(tmp_path / "r")], "OSMesa")
    assert done.returncode == 2
    line = _one_line_with_fix(done.stderr, "libOSMesa cannot be loaded", OSMESA_FIX)
    assert done.stderr.strip() == line  # the whole of stderr is that one line
    assert not (tmp_path / "r").exists()  # and nothing is written


def test_cli_without_egl_names_libegl_and_its_packages(tmp_path):
    done = _run(CLI + ["--gl", "egl", "--report-dir", str(tmp_path / "r")], "EGL")
    assert done.returncode == 2
    assert done.stderr.strip() == _one_line_with_fix(done.stderr, "libEGL cannot be loaded", EGL_FIX)


def test_api_without_osmesa_raises_one_line():
    code = (
        "import sys; sys.path.insert(0, 'tests/data')\n"
        "from user_projector import project\n"
        "from wirecheck import check_projector\n"
        "try:\n"
        "    check_projector(project, scenes=['cube'], cases=['on_axis'], frames=1,"
        " oracles=('opencv', 'pyrender'))\n"
        "except RuntimeError as e:\n"
        "    print(type(e).__name__, e)\n"
    )
    done = _run([sys.executable, "-c", code], "OSMesa", cwd=ROOT)
    assert done.stdout.startswith("GLUnavailable libOSMesa cannot be loaded"), done.stdout + done.stderr
    _one_line_with_fix(done.stdout, "libOSMesa", OSMESA_FIX)


@pytest.mark.slow
def test_fixture_without_osmesa_fails_with_one_line_not_a_traceback(tmp_path):
    project = tmp_path / "myproj"
    shutil.copytree(ROOT / "tests" / "data" / "docs_project", project)
    done = _run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "--wirecheck-level",
            "pixels",
            "tests/test_projection.py::test_project",
        ],
        "OSMesa",
        cwd=project,
    )
    assert done.returncode == 1, done.stdout + done.stderr
    out = done.stdout
    assert _one_line_with_fix(out, "wirecheck: libOSMesa cannot be loaded", OSMESA_FIX).startswith("wirecheck:")
    # no wirecheck source or docstring: the report is the test's name, the line and pytest's summary
    assert "check_projector(" not in out and "Parameters" not in out
    assert len(out.splitlines()) < 15, out


def test_viewer_overlay_without_osmesa_says_which_library_in_the_page():
    # the viewer's page shows the overlay's error in its banner: the missing library and its fix,
    # not "see the server's stderr" (the browser is often not where the terminal is)
    code = "from wirecheck.core.app.viewer import LazyOverlay\nprint(LazyOverlay()(None, None, 1)['error'])\n"
    done = _run([sys.executable, "-c", code], "OSMesa", cwd=ROOT)
    line = _one_line_with_fix(done.stdout, "libOSMesa cannot be loaded", OSMESA_FIX)
    assert line.startswith("the oracle overlay is not available: libOSMesa"), done.stdout + done.stderr

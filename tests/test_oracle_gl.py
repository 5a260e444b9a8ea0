"""The pyrender oracle's GL: OSMesa and EGL, aliased lines whatever the driver, the GL named in every report.

The GL platform is fixed per process when PyOpenGL is imported, so each
platform is probed in its own interpreter (tests/data/gl_probe.py). The EGL
tests are skipped where no EGL context can be created, unless
WIRECHECK_REQUIRE_EGL=1 (.ci/run, after .ci/setup.sh installed Mesa's EGL),
where that is a failure. On this machine EGL is Mesa's llvmpipe on the CPU;
a GPU's driver takes the same path.
"""

import functools
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import run_crosscheck
from wirecheck.core.errors import InputError
from wirecheck.oracles import cli
from wirecheck.oracles.references.pyrender_oracle import osmesa_available, select_gl

PROBE = Path(__file__).parent / "data" / "gl_probe.py"
REQUIRED = {"egl": os.environ.get("WIRECHECK_REQUIRE_EGL") == "1"}

_OK, _WHY = osmesa_available()
needs_osmesa = pytest.mark.skipif(not _OK, reason=f"pyrender/OSMesa unavailable: {_WHY}")


def _env(platform: str) -> dict:
    return {**os.environ, "PYOPENGL_PLATFORM": platform}


@functools.cache
def _probe_answer(platform: str) -> dict:
    """gl_probe.py's JSON on ``platform``, run once per test process (an interpreter that loads pyrender: ~1.5 s)."""
    proc = subprocess.run([sys.executable, str(PROBE)], env=_env(platform), capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout)


def probe(platform: str) -> dict:
    """gl_probe.py's answer on ``platform``; skip (or fail, when required) where it has no GL.

    The answer is shared by the tests that ask (read-only): the probe is
    deterministic for a platform, and each run of it starts an interpreter.
    """
    answer = _probe_answer(platform)
    if not answer["available"]:
        if REQUIRED.get(platform):
            pytest.fail(f"{platform} required (WIRECHECK_REQUIRE_EGL=1) but {answer['why']}")
        pytest.skip(answer["why"])
    return answer


@pytest.fixture(scope="module", params=["osmesa", "egl"])
def probed(request):
    return request.param, probe(request.param)


def test_the_oracle_reports_the_gl_strings_of_its_own_context(probed):
    """gl_info equals glGetString of a plain pyrender context opened beside it, and names the platform."""
    platform, answer = probed
    info, fresh = answer["info"], answer["fresh"]
    assert info["platform"] == platform
    for key in ("vendor", "renderer", "version"):
        assert info[key] and info[key] == fresh[key]


def test_the_oracle_draws_aliased_lines_into_single_sample_buffers(probed):
    """Two slanted lines: every colour is 0 or 255 (no coverage levels), and the draw buffer has no samples.

    Control: pyrender's own set-up (4x multisample buffers, GL_MULTISAMPLE
    enabled every pass) on the same scene. On Mesa's EGL it anti-aliases
    (64/128/191 appear), so the fix is what makes the oracle aliased there;
    on OSMesa pyrender draws into the context's sample-less buffer anyway.
    """
    platform, answer = probed
    assert answer["levels"] == [0, 255]
    assert answer["info"]["samples"] == 0
    assert answer["drawn"] > 0
    if platform == "egl":
        assert set(answer["raw_levels"]) - {0, 255}, "control: pyrender's 4x buffers should anti-alias here"
    # closing one oracle (another image size) leaves the others drawing the same picture
    assert answer["same_after_close"]


def test_the_colour_only_read_gives_the_mask_read_with_depth(probed):
    """``render(depth=False)`` (the frames judge's read: red channel only) equals pyrender's colour-and-depth read.

    72 renders of the cube a platform (gl_probe.colour_only_agrees: 12 views,
    three occluder settings, two sizes, one of them 61 px wide); every mask
    must be the same to the pixel, and the masks are not empty (over 72 views
    of a cube's wireframe, thousands of pixels).
    """
    _platform, answer = probed
    got = answer["colour_only"]
    assert got["compared"] == 72 and got["differ"] == 0
    assert got["drawn"] > 1000


@needs_osmesa
def test_every_report_names_the_oracle_gl(tmp_path):
    """report.json, report.md, report.html and the JUnit properties carry what the context says (not a constant)."""
    fresh = probe("osmesa")["fresh"]
    xml = tmp_path / "junit.xml"
    code, report, out = run_crosscheck(
        tmp_path, "--scene", "cube", "--frames", "1", "--cases", "on_axis", "--junit-xml", str(xml)
    )
    assert code == 0
    gl = report["oracle_gl"]
    assert gl == {"platform": "osmesa", **fresh, "samples": 0}
    for text in ((out / "report.md").read_text(), (out / "report.html").read_text()):
        assert fresh["renderer"] in text and fresh["version"] in text and "single-sample buffers" in text
    junit = xml.read_text()
    for key in ("platform", "vendor", "renderer", "version"):
        assert f'name="oracle_gl_{key}" value="{gl[key]}"' in junit


@needs_osmesa
def test_no_gl_is_named_where_none_drew(tmp_path):
    code, report, out = run_crosscheck(
        tmp_path, "--scene", "cube", "--frames", "1", "--cases", "on_axis", "--level", "vertices"
    )
    assert code == 0 and report["oracle_gl"] is None
    assert "Oracle GL" not in (out / "report.md").read_text()


@pytest.mark.slow
def test_crosscheck_on_egl_passes_and_says_egl(tmp_path):
    """The bundled cube through ``crosscheck --gl egl``: every case passes at F1@1px = 1, drawn by EGL."""
    probe("egl")
    out = tmp_path / "r"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--gl",
            "egl",
            "--scene",
            "cube",
            "--frames",
            "2",
            "--report-dir",
            str(out),
        ],
        env={k: v for k, v in os.environ.items() if k != "PYOPENGL_PLATFORM"},
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    report = json.loads((out / "report.json").read_text())
    assert report["oracle_gl"]["platform"] == "egl" and report["oracle_gl"]["samples"] == 0
    assert report["compared"]["pixels"] > 0
    assert all(c["pixel_f1_1px"] == 1.0 for c in report["cases"])


def test_gl_options_that_cannot_apply_are_usage_errors(tmp_path, capsys):
    assert cli.main(["--gl", "egl", "--level", "vertices", "--scene", "cube", "--report-dir", str(tmp_path / "v")]) == 2
    assert "--gl egl with --level vertices" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        cli.main(["--gl", "glx", "--scene", "cube"])
    assert exc.value.code == 2
    assert not (tmp_path / "v").exists()


def test_the_platform_cannot_change_once_opengl_is_loaded(monkeypatch):
    monkeypatch.setitem(sys.modules, "OpenGL.platform", sys.modules.get("OpenGL.platform", object()))
    monkeypatch.setenv("PYOPENGL_PLATFORM", "osmesa")
    with pytest.raises(InputError, match="already loaded .* for 'osmesa'"):
        select_gl("egl")
    assert select_gl("osmesa") == "osmesa"


def test_no_usable_egl_is_one_line_with_the_install_hint(tmp_path):
    """glvnd given no EGL vendor (as on a machine without Mesa's EGL): exit 2, one line, nothing written."""
    out = tmp_path / "r"
    env = {**os.environ, "__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "no-vendor.json")}
    env.pop("PYOPENGL_PLATFORM", None)
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--gl",
            "egl",
            "--scene",
            "cube",
            "--frames",
            "1",
            "--report-dir",
            str(out),
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "no EGL context can be created" in lines[0]
    assert "apt-get install -y libegl1 libegl-mesa0 libgl1-mesa-dri" in lines[0]
    assert not out.exists()

"""A real renderer's frames of any line style: matplotlib's Agg (antialiased, 1 px and 2.5 px wide).

``tests/clients/matplotlib_frames.py`` draws a job as a matplotlib user would
(its own projection from the camera JSON's K, R, t; a LineCollection on axes
of the camera's size). A correct set-up passes whatever the width; the usual
mistake, y up (the image upside down), is named ``mirror_vertical``.
Split from tests/test_line_style.py (synthetic drawings) so each file runs in
well under a minute.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from test_line_style import ARGS
from wirecheck.oracles.cli import main
from wirecheck.oracles.diagnosis.diagnose import primary

pytest.importorskip("matplotlib")
SCRIPT = Path(__file__).parent / "clients" / "matplotlib_frames.py"


@pytest.fixture(scope="module")
def job_dir(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("mpl") / "job"
    assert main(["export", str(path)] + ARGS) == 0
    return path


def _render_and_judge(job_dir: Path, tmp_path: Path, *options) -> tuple[int, dict]:
    job = tmp_path / "job"
    shutil.copytree(job_dir, job)
    subprocess.run([sys.executable, str(SCRIPT), str(job), *options], check=True, timeout=120)
    rc = main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "rep")])
    return rc, json.loads((tmp_path / "rep" / "report.json").read_text())


@pytest.mark.parametrize("width, style", [("1", "antialiased"), ("2.5", "wide")])
def test_matplotlib_correct_setup_passes(job_dir, tmp_path, capsys, width, style):
    rc, report = _render_and_judge(job_dir, tmp_path, "--linewidth", width)
    assert rc == 0, capsys.readouterr().out
    for c in report["cases"]:
        assert c["line_style"]["style"] == style and c["faults"] == []
        # Agg's coverage across the line: the width asked for, to 0.05 px (measured 1.00-1.01, 2.50)
        assert c["line_style"]["width_px"] == pytest.approx(float(width), abs=0.05)
        # the centres: within 0.05 px of the oracle's lines (measured <= 0.003 px)
        assert max(map(abs, c["line_style"]["geometry"]["offset_px"])) < 0.05


def test_matplotlib_y_up_is_named_mirror_vertical(job_dir, tmp_path, capsys):
    rc, report = _render_and_judge(job_dir, tmp_path, "--mirror-y")
    assert rc == 1
    for c in report["cases"]:
        assert c["verdict"] == "fail" and primary(c["faults"]) == "mirror_vertical", c["faults"]
        assert not any(f.get("measured_by") == "line centroids" for f in c["faults"])


# ---- moderngl: OpenGL on EGL (Mesa's llvmpipe here), aliased and 4x MSAA ----

MODERNGL = Path(__file__).parent / "clients" / "moderngl_frames.py"


def _require_egl():
    moderngl = pytest.importorskip("moderngl")
    try:
        moderngl.create_standalone_context(backend="egl").release()
    except Exception as exc:  # no EGL display or driver: nothing to draw with
        pytest.skip(f"moderngl has no EGL context here: {exc}")


def _render_gl(job_dir: Path, tmp_path: Path, *options) -> tuple[int, dict]:
    job = tmp_path / "job"
    shutil.copytree(job_dir, job)
    subprocess.run([sys.executable, str(MODERNGL), str(job), *options], check=True, timeout=120)
    rc = main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "rep")])
    return rc, json.loads((tmp_path / "rep" / "report.json").read_text())


@pytest.mark.parametrize("samples, style", [("0", "aliased"), ("4", "antialiased")])
def test_moderngl_correct_setup_passes(job_dir, tmp_path, capsys, samples, style):
    _require_egl()
    rc, report = _render_gl(job_dir, tmp_path, "--samples", samples)
    assert rc == 0, capsys.readouterr().out
    for c in report["cases"]:
        assert c["line_style"]["style"] == style and c["faults"] == []
        if style == "aliased":  # GL's rule, as the oracle's (Mesa): pixel for pixel (measured >= 0.999)
            assert c["pixel_f1_0px"] >= 0.98
        else:  # 4x MSAA: coverage in quarters; GL's rule would fail it
            assert c["line_style"]["coverage_steps"] == 4 and c["pixel_f1_0px"] < 0.98


def test_moderngl_rows_not_flipped_is_named_mirror_vertical(job_dir, tmp_path, capsys):
    _require_egl()
    rc, report = _render_gl(job_dir, tmp_path, "--no-flip")
    assert rc == 1
    for c in report["cases"]:
        assert c["verdict"] == "fail" and primary(c["faults"]) == "mirror_vertical", c["faults"]

"""three.js's own WebGL pixels judged by crosscheck --candidate-frames (end to end).

tests/browser/frames_three.mjs draws an exported job with three.js's
WebGLRenderer (LineSegments, LineBasicMaterial, PerspectiveCamera /
OrthographicCamera from the job's camera fields, antialias off) in headless
Chromium (Debian's, driven by playwright-core; WebGL on SwiftShader), reads
each frame back with canvas.toDataURL, and crosscheck judges the PNGs.

What three.js reaches (measured; docs/frames.md): F1@1px = 1 on every case
but one, F1@0px 0.97-1.0 (GL's line rule picks a different pixel than core's
exact rasteriser where a line passes near a pixel corner; pyrender, also GL,
agrees with core to 0.999 because Mesa and SwiftShader differ there too), no
named fault anywhere (its camera conventions are ours once the image is read
top-down), and one edge crossing the near plane is not drawn in
prism / near_plane frame 13 (one end behind the camera; pyrender and core
draw it).

Needs node, /usr/bin/chromium, tests/browser/node_modules/playwright-core
(tests/browser/setup.sh) and three from tests/clients/three (tests/clients/setup.sh);
skipped without them unless WIRECHECK_REQUIRE_BROWSER=1 / WIRECHECK_REQUIRE_CLIENTS=1
(set by .ci/run), which make their absence a failure.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from wirecheck.oracles.cli import main

pytestmark = pytest.mark.slow  # an expensive module fixture (tests/conftest.py runs such files first)

TESTS = Path(__file__).parent
SCRIPT = TESTS / "browser" / "frames_three.mjs"
THREE = TESTS / "clients" / "three" / "node_modules" / "three" / "build" / "three.module.js"
CHROMIUM = os.environ.get("WIRECHECK_CHROMIUM", "/usr/bin/chromium")


def _require():
    browser = None
    if shutil.which("node") is None:
        browser = "node not found"
    elif not (TESTS / "browser" / "node_modules" / "playwright-core").is_dir():
        browser = "tests/browser/node_modules/playwright-core missing (run tests/browser/setup.sh)"
    elif not os.access(CHROMIUM, os.X_OK):
        browser = f"{CHROMIUM} not found (run tests/browser/setup.sh)"
    three = None if THREE.is_file() else "three missing (run tests/clients/setup.sh)"
    for why, var in ((browser, "WIRECHECK_REQUIRE_BROWSER"), (three, "WIRECHECK_REQUIRE_CLIENTS")):
        if why and os.environ.get(var) == "1":
            pytest.fail(f"three.js frames test required ({var}=1) but {why}")
    if browser or three:
        pytest.skip(f"three.js frames test skipped: {browser or three}")


def _draw(job: Path, *flags: str) -> None:
    """Draw ``job`` with three.js; Chromium's profile goes to a folder beside it and must be gone after (each run
    left a 2-3 MB wirecheck-chromium-* profile in the system temporary folder)."""
    profiles = job.parent / "profiles"
    profiles.mkdir(exist_ok=True)
    proc = subprocess.run(
        ["node", str(SCRIPT), str(job), str(THREE), *flags],
        capture_output=True,
        text=True,
        timeout=300,
        env=dict(os.environ, WIRECHECK_CHROMIUM=CHROMIUM, WIRECHECK_PROFILE_PARENT=str(profiles)),
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert sorted(p.name for p in profiles.iterdir()) == [], "Chromium's profile was left behind"


@pytest.fixture(scope="module")
def judged(tmp_path_factory):
    _require()
    tmp = tmp_path_factory.mktemp("three")
    job = tmp / "job"
    # frames 1 and 13 of 24: the cube square-on and half a turn later, every bundled scene and case
    assert main(["export", str(job), "--frames", "24", "--every", "12"]) == 0
    _draw(job)
    rc = main(["--candidate-frames", str(job), "--report-dir", str(tmp / "rep")])
    report = json.loads((tmp / "rep" / "report.json").read_text())
    return rc, report, job


def test_three_js_frames_are_judged_by_their_own_pixels(judged):
    rc, report, _job = judged
    by = {(c["scene"], c["camera"]): c for c in report["cases"]}
    assert len(by) == 21 and all(c["frames_checked"] == 2 for c in by.values())
    dropped = by.pop(("prism", "near_plane"))
    for key, c in by.items():
        # 1 px: every three.js line pixel is next to an oracle line pixel and vice versa
        assert c["pixel_f1_1px"] == 1.0, (key, c["pixel_f1_1px"])
        # 0 px: GL's line rule against exact lines; measured 0.973-1.0
        assert c["pixel_f1_0px"] >= 0.97, (key, c["pixel_f1_0px"])
    # the edge three.js (SwiftShader) does not draw: pixels only the oracle has
    worst = next(f for f in dropped["per_frame"] if f["frame"] == 13)
    assert worst["f1_1px"] < 0.95 and worst["oracle_pixels"] - worst["candidate_pixels"] > 150
    assert rc == 1  # so the run fails, by that case and the 0-px bound


def test_three_js_has_no_named_fault(judged):
    # three.js's cameras and read-back are our conventions: no mirror, swap, FOV, aspect or offset
    _rc, report, _job = judged
    named = {(c["scene"], c["camera"]): [f["name"] for f in c["faults"]] for c in report["cases"]}
    # cube / narrow_fov, frame 1: edge 3 runs within 0.01 px of the pixel edge x = 398.5 over rows
    # 201-209; SwiftShader takes the pixel right of it (x = 399, also the next edge's), Mesa the left one.
    # Ties that close are decided by the renderer's sub-pixel grid, coarser than the oracle's precision
    # (oracles.judge.line_ties), so they count as decided one-sided pixels: the line gate names
    # line_pixel_bias there (measured: 15 oracle-only vs 0 decided candidate-only pixels, edge 3 -10).
    # Known, for the tie rule to settle (issue 23); every other case names nothing.
    assert named.pop(("cube", "narrow_fov")) in ([], ["unexplained"], ["line_pixel_bias"], ["raster_rule"])
    # SwiftShader's line rule is not Mesa's: where it differs, a raster fault (raster_rule, or the
    # one-sided counts' line_pixel_bias where F1@0px itself holds), never a convention fault
    odd = {
        key: names
        for key, names in named.items()
        if names not in ([], ["unexplained"], ["raster_rule"], ["line_pixel_bias"])
    }
    assert not odd, odd
    # a case failing by F1@0px alone (SwiftShader's line rule, not Mesa's) is named for its rule
    for c in report["cases"]:
        if c["reasons"] and all(r.startswith("pixel F1@0px") for r in c["reasons"]):
            assert named.get((c["scene"], c["camera"]), ["raster_rule"]) == ["raster_rule"], (
                c["scene"],
                c["camera"],
                c["faults"],
            )


def test_a_mirrored_three_js_frame_set_is_named(judged, tmp_path):
    # the same three.js frames flipped top to bottom (a renderer that forgot the GL y flip)
    from PIL import Image, ImageOps

    _rc, _report, job = judged
    bad = tmp_path / "flipped"
    shutil.copytree(job, bad)
    for png in (bad / "frames").rglob("*.png"):
        ImageOps.flip(Image.open(png)).save(png)
    # judge a single oblique case by a job of its own: export it, copy its frames
    one = tmp_path / "one"
    assert (
        main(["export", str(one), "--scene", "cube", "--cases", "oblique_roll", "--frames", "24", "--every", "12"]) == 0
    )
    shutil.rmtree(one / "frames")
    (one / "frames" / "cube").mkdir(parents=True)
    shutil.copytree(bad / "frames" / "cube" / "oblique_roll", one / "frames" / "cube" / "oblique_roll")
    assert main(["--candidate-frames", str(one), "--report-dir", str(tmp_path / "rep")]) == 1
    (case,) = json.loads((tmp_path / "rep" / "report.json").read_text())["cases"]
    assert [f["name"] for f in case["faults"]] == ["mirror_vertical"]


def test_three_js_antialiased_frames_pass(tmp_path):
    """three.js's default, antialias on (multisampled lines of partial coverage): read as antialiased and
    judged by the lines' centres; before, F1@0px 0.69-0.94 failed every case as 'unexplained'."""
    _require()
    job = tmp_path / "job"
    assert main(["export", str(job), "--scene", "cube", "--scene", "pyramid", "--frames", "24", "--every", "12"]) == 0
    _draw(job, "--antialias")
    assert main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "rep")]) == 0
    report = json.loads((tmp_path / "rep" / "report.json").read_text())
    assert len(report["cases"]) == 14
    for c in report["cases"]:
        assert c["line_style"]["style"] == "antialiased" and c["faults"] == []
        # measured: centres within 0.1 px of the oracle's lines (0.095 at most, cube / orthographic)
        assert max(map(abs, c["line_style"]["geometry"]["offset_px"])) < 0.15
    assert min(c["pixel_f1_0px"] for c in report["cases"]) < 0.98  # GL's rule would have failed them

"""Precision-aware judgement: a float32 projector is held to a float32 bound, its faults named through its noise.

The candidates are tests/data/candidates/glm_f32.py (a glm-style float32 GL
pipeline: correct, and with gl_FragCoord pixels = a vertical mirror and a
half-pixel offset). Expected verdicts and fault names are derived by hand
from the conventions (core/conventions.py), never taken from the harness.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import run_crosscheck
from wirecheck.core.camera import look_at
from wirecheck.oracles import tolerances
from wirecheck.oracles.api import check_projector, failure_text
from wirecheck.oracles.candidates import protocol
from wirecheck.oracles.candidates.candidate import case_precision, returned_precision
from wirecheck.oracles.tolerances import VERTEX_ROUNDINGS, Tolerances, vertex_bound, vertex_scale

DATA = Path(__file__).parent / "data" / "candidates"
sys.path.insert(0, str(DATA))

import glm_f32  # noqa: E402

GLM = f"{DATA / 'glm_f32.py'}"
ALL_SCENES = ("cube", "pyramid", "prism")


def names(case: dict) -> list[str]:
    return [f["name"] for f in case["faults"]]


# ---- the precision: inferred, declared ------------------------------------------------


def test_returned_precision_is_the_answer_dtype():
    assert returned_precision(np.zeros((2, 2), np.float32)) == "float32"
    assert returned_precision(np.zeros((2, 2), np.float16)) == "float32"
    assert returned_precision(np.zeros((2, 2), np.float64)) == "float64"
    assert returned_precision([[1.0, 2.0]]) == "float64"  # a list has no dtype: the wire's float64
    assert returned_precision(np.zeros((2, 2), np.int64)) == "float64"


def test_declared_precision_wins_over_the_returned_one():
    assert case_precision("float64", {"float32"}) == ("float64", "declared")
    assert case_precision("float32", {"float64"}) == ("float32", "declared")
    assert case_precision(None, {"float64", "float32"}) == ("float32", "returned")  # the coarser one seen
    assert case_precision(None, {"float64"}) == ("float64", "returned")
    assert case_precision(None, set()) == ("float64", "default")
    with pytest.raises(ValueError, match="float16"):
        Tolerances(precision="float16")


# ---- the bound -------------------------------------------------------------------------


def test_vertex_bound_by_hand():
    """One point at the origin seen from (0, 0, 5), fov 60, 640x480: the formula of oracles/tolerances.py by hand."""
    cam = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=640, height=480)
    f = 240 / math.tan(math.radians(30))  # 415.69 px
    # u = 0 (the point is at the principal point (319.5, 239.5)); |X| = 0, |C| = 5, z = 5
    scale = f * 5 / 5 + (319.5 + 239.5) + (640 + 480)
    got = vertex_scale(np.zeros((1, 3)), np.array([[319.5, 239.5]]), cam)
    # the same few float64 operations in another order: equal to ~1e-13 relative
    assert got == pytest.approx(scale, rel=1e-12)
    assert vertex_bound("float32", got) == pytest.approx(VERTEX_ROUNDINGS * 2.0**-23 * scale, rel=1e-12)
    # float64: the floor (--tol-px) is the bound, 1e6 x VERTEX_ROUNDINGS eps64 scale ~ 1.9e-12 px; 0 stays 0
    assert vertex_bound("float64", got) == tolerances.VERTEX_TOL_PX
    assert vertex_bound("float64", got, floor=0.0) == 0.0
    assert vertex_bound("float32", got, floor=1.0) == 1.0  # a larger --tol-px wins
    assert vertex_scale(np.zeros((1, 3)), np.full((1, 2), np.nan), cam) == 0.0  # nothing visible


def test_float32_bound_sits_between_the_noise_and_the_smallest_fault():
    """On every bundled case: a correct float32 projector's error < the bound < a half pixel / 100."""
    report = check_projector(glm_f32.project, isolate=False, frames=3)
    for case in report["cases"]:
        assert case["precision"] == {"judged_as": "float32", "source": "returned", "returned": ["float32"]}
        assert case["max_vertex_error_px"] < case["vertex_bound_px"] < 0.005, case["camera"]


# ---- verdicts and faults at the vertex level ----------------------------------------


def test_correct_float32_projector_passes_every_case():
    report = check_projector(glm_f32.project, isolate=False, frames=4)
    assert report["verdict"] == "pass"
    assert len(report["cases"]) == 21 and all(c["faults"] == [] for c in report["cases"])
    # without the derived bound (the float64 one) the same answers fail: the check can fail
    strict = check_projector(glm_f32.project, isolate=False, frames=4, precision="float64")
    assert strict["verdict"] == "fail"


def test_float32_mirror_and_half_pixel_offset_are_named_on_every_case():
    """gl_FragCoord pixels: y = (ndc_y + 1) H/2 (y up) and x = (ndc_x + 1) W/2, a corner origin.

    Against y = (1 - ndc_y) H/2 - 0.5 that is y' = (H - 1) - y + 0.5 + ... : a vertical
    mirror about the image centre plus half a pixel on both axes.
    """
    report = check_projector(glm_f32.project_webgl, isolate=False, frames=4)
    for case in report["cases"]:
        assert names(case) == ["mirror_vertical", "pixel_offset"], case["faults"]
        off = case["faults"][1]
        # the fitted offset carries the float32 noise of the fit: within the case's bound
        assert abs(off["dx"] - 0.5) <= case["vertex_bound_px"] and abs(off["dy"] - 0.5) <= case["vertex_bound_px"]


def test_float64_candidate_with_float32_rounding_is_precision_limited():
    """Float32 arithmetic behind float64 arrays: judged at float64, its error is named for what it is."""
    report = check_projector(glm_f32.project_f64_view, isolate=False, frames=2, scenes=["cube"])
    for case in report["cases"]:
        assert case["precision"]["judged_as"] == "float64"
        assert names(case) == ["precision_limited"], case["faults"]
        f = case["faults"][0]
        assert f["float64_bound_px"] < f["residual_px"] <= f["float32_bound_px"]
    text = failure_text(report)
    assert "compute in float64 or declare float32" in text
    assert "rotation order" not in text


def test_declared_float64_returning_float32_is_judged_at_float64():
    report = check_projector(glm_f32.project_webgl, isolate=False, frames=2, scenes=["cube"], precision="float64")
    for case in report["cases"]:
        assert case["precision"] == {"judged_as": "float64", "source": "declared", "returned": ["float32"]}
        assert names(case) == ["mirror_vertical", "pixel_offset", "precision_limited"], case["faults"]


def test_declared_float32_loosens_a_float64_candidate():
    """A float64 projector declared float32 is held to the float32 bound (a 1e-5 px error then passes)."""
    from wirecheck.core.projector.projection import project_points

    def off_by_1e5(points, camera):
        return project_points(points, camera) + 1e-5  # 10x the float64 floor, ~100x below the float32 bound

    assert check_projector(off_by_1e5, isolate=False, frames=2, scenes=["cube"])["verdict"] == "fail"
    assert (
        check_projector(off_by_1e5, isolate=False, frames=2, scenes=["cube"], precision="float32")["verdict"] == "pass"
    )


def test_precision_travels_over_the_protocol():
    """Isolated in the candidate host, the float32 answer is declared in the reply and inferred here."""
    report = check_projector(GLM + ":project", frames=2, scenes=["cube"], cases=["on_axis", "near_plane"])
    assert report["verdict"] == "pass"
    assert {c["precision"]["judged_as"] for c in report["cases"]} == {"float32"}


def test_reply_precision_field():
    assert json.loads(protocol.encode_reply(np.zeros((1, 2)), "float32").split(b"\n")[0]) == {
        "n": 1,
        "precision": "float32",
    }
    assert protocol.encode_reply(np.zeros((1, 2))).split(b"\n")[0] == b'{"n": 1}'  # float64: as before
    assert protocol.reply_precision(b'{"n": 1}\n') == "float64"
    with pytest.raises(protocol.ProtocolError, match="precision"):
        protocol.reply_precision(b'{"n": 1, "precision": "float16"}\n')


def test_api_rejects_an_unknown_precision():
    with pytest.raises(ValueError, match="precision 'half'"):
        check_projector(glm_f32.project, isolate=False, precision="half")


# ---- the CLI ---------------------------------------------------------------------------


def test_cli_core_float32_passes_and_reports_its_precision(tmp_path, capsys):
    code, report, run_dir = run_crosscheck(tmp_path, "--dtype", "float32", "--level", "vertices", "--frames", "2")
    out = capsys.readouterr().out
    assert code == 0, out
    assert "Candidate precision: float32 (core --dtype); vertex bound" in out
    assert all(c["precision"]["judged_as"] == "float32" for c in report["cases"])
    assert "Candidate precision: float32 (core --dtype)" in (run_dir / "report.md").read_text()


def test_cli_declared_precision(tmp_path, capsys):
    code, report, _ = run_crosscheck(
        tmp_path,
        "--candidate",
        GLM + ":project",
        "--candidate-precision",
        "float64",
        "--level",
        "vertices",
        "--frames",
        "2",
        "--scene",
        "cube",
        "--cases",
        "on_axis",
    )
    out = capsys.readouterr().out
    assert code == 1, out
    assert "precision_limited" in out and "float64 (declared; returned float32)" in out
    with pytest.raises(SystemExit) as exc:  # argparse: one line, exit 2
        run_crosscheck(tmp_path, "--candidate-precision", "half", name="bad")
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--candidate-precision" in err and "Traceback" not in err


# ---- the pixel level: near-plane ends ----------------------------------------------


@pytest.fixture(scope="module")
def pixels_available():
    from wirecheck.oracles.references.pyrender_oracle import osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)


def _near_plane_crossings():
    """The cube's edges under the near_plane case camera, and the camera: some edges cross the near plane."""
    from wirecheck.core.scene.files import load_scene
    from wirecheck.oracles.cases import cameras_for

    scene = load_scene("cube")
    cam = next(c.camera for c in cameras_for(scene.radius) if c.name == "near_plane")
    edges = np.asarray(scene.edges)
    return scene.vertices[edges[:, 0]], scene.vertices[edges[:, 1]], cam


def _float32_near_rejects(ends, cam) -> int:
    """How many clipped ends a float32 glm projector's own depth test rejects."""
    out = glm_f32.project(ends.reshape(-1, 3), cam)
    return int(np.isnan(out).any(axis=1).sum())


def test_clipped_ends_survive_a_float32_depth_test(monkeypatch):
    from wirecheck.oracles.candidates import draw
    from wirecheck.oracles.references import opencv_oracle

    p0, p1, cam = _near_plane_crossings()
    d0, d1 = opencv_oracle.depth(p0, cam), opencv_oracle.depth(p1, cam)
    crossing = int(np.sum((d0 < cam.near) != (d1 < cam.near)))
    assert crossing >= 3  # the case does cross the near plane
    _, ends = draw.clip_depth(p0, p1, cam, "float32")
    assert _float32_near_rejects(ends, cam) == 0
    # the old nudge (1e-9 of the segment, below float32 resolution) loses ends to the float32 test
    monkeypatch.setattr(draw, "depth_margin", lambda p, camera, precision: np.zeros(len(p)))
    _, old = draw.clip_depth(p0, p1, cam, "float32")
    assert _float32_near_rejects(old, cam) >= 1


def test_correct_float32_projector_passes_every_case_at_the_pixel_level(pixels_available):
    report = check_projector(glm_f32.project, isolate=False, frames=2, oracles=("opencv", "pyrender"))
    assert report["verdict"] == "pass", failure_text(report)
    assert all(c["pixel_f1_1px"] == 1.0 for c in report["cases"])


def test_old_near_plane_nudge_fails_a_correct_float32_projector(pixels_available, monkeypatch):
    """Break on purpose: the 1e-9 nudge alone drops near-plane edges of a correct float32 projector
    (neither the precision's depth margin nor the probed planes' slack, oracles.diagnosis.clip_planes)."""
    from wirecheck.oracles.candidates import draw
    from wirecheck.oracles.diagnosis import clip_planes

    monkeypatch.setattr(draw, "depth_margin", lambda p, camera, precision: np.zeros(len(p)))
    monkeypatch.setattr(clip_planes, "depth_slack", lambda planes, camera: (0.0, None))
    report = check_projector(
        glm_f32.project, isolate=False, frames=2, oracles=("opencv", "pyrender"), cases=["near_plane"]
    )
    assert report["verdict"] == "fail"
    assert all(c["pixel_f1_1px"] < 0.9 for c in report["cases"])  # measured 0.59-0.82


def test_config_key_candidate_precision(tmp_path):
    from wirecheck.core.errors import InputError
    from wirecheck.oracles.config import load_config

    path = tmp_path / "pyproject.toml"
    path.write_text('[tool.wirecheck]\ncandidate-precision = "float32"\n')
    assert load_config(path).api_kwargs() == {"precision": "float32"}
    path.write_text('[tool.wirecheck]\ncandidate-precision = "double"\n')
    with pytest.raises(InputError, match="candidate-precision = 'double': expected 'float32' or 'float64'"):
        load_config(path)


def test_a_point_on_the_near_plane_may_go_either_way_in_float32():
    """A vertex on the near plane (to float32 rounding) clipped by the float32 candidate only is not a failure."""
    from wirecheck.core.scene.files import load_scene
    from wirecheck.core.scene.model import Scene
    from wirecheck.oracles.cases import cameras_for

    cube = load_scene("cube")
    cam = next(c.camera for c in cameras_for(cube.radius) if c.name == "near_plane")
    # depth near (1 + 1e-12): visible in float64 (rounding ~1e-16), not resolvable in float32 (eps 1.2e-7);
    # inside the cube's bounding sphere, so the case camera is the cube's
    tie = cam.position + cam.near * (1 + 1e-12) * cam.forward
    scene = Scene(name="tie", vertices=np.vstack([cube.vertices, tie]), edges=np.asarray(cube.edges))
    assert scene.radius == cube.radius

    def clips_the_tie(points, camera):
        out = glm_f32.project(points, camera)
        out[np.all(np.abs(points - tie) < 1e-12, axis=1)] = np.nan  # its rounding went the other way
        return out

    kwargs = dict(isolate=False, scenes=[scene], frames=1, cases=["near_plane"], turns=(0, 0, 0))
    (case,) = check_projector(clips_the_tie, **kwargs)["cases"]
    assert case["verdict"] == "pass" and case["depth_ties"] == 1, case["reasons"]
    # declared float64, the same answer fails: float64 leaves no room for a tie there
    (strict,) = check_projector(clips_the_tie, precision="float64", **kwargs)["cases"]
    assert strict["verdict"] == "fail" and "visible sets differ" in " ".join(strict["reasons"])


@pytest.mark.parametrize("limit", [1, 20, 1 << 16])
def test_scale_batch_is_the_largest_frame_scale(limit):
    """A case measures its frames' vertex scales together (oracles.judge.case.ScaleBatch): the largest of
    the frames' own scales, whether it measures each frame alone, a few together or all at the end."""
    from wirecheck.oracles.judge.case import ScaleBatch
    from wirecheck.oracles.references import opencv_oracle

    rng = np.random.default_rng(11)
    cam = look_at((0.0, 1.0, 6.0), (0.0, 0.0, 0.0), fov_y_deg=60.0, width=320, height=240, near=0.5, far=40.0)
    frames = [rng.uniform(-3, 3, (int(rng.integers(1, 15)), 3)) * rng.choice([1.0, 30.0]) for _ in range(9)]
    expected = max(vertex_scale(p, opencv_oracle.project(p, cam), cam) for p in frames)
    assert expected > 0
    batch = ScaleBatch(limit=limit)
    for p in frames:
        batch.add(p, opencv_oracle.project(p, cam), cam)
    assert batch.flush(cam) == expected


def test_float64_bound_is_its_own_rounding_where_that_exceeds_the_floor():
    # float64's derived term: VERTEX_ROUNDINGS (4) x eps64 (2^-52 = 2.22e-16) x the case's scale.
    # Scale 1e4 px (an ordinary scene): 8.9e-12 px, five orders under the 1e-6 floor: the floor.
    # Scale 1e12 px (a 1e-2 mesh 5e4 from the origin, seen from 0.1 away): 8.9e-4 px, the bound.
    assert vertex_bound("float64", 1e4) == tolerances.VERTEX_TOL_PX
    assert vertex_bound("float64", 1e12) == pytest.approx(4 * 2.0**-52 * 1e12, rel=1e-15)
    assert vertex_bound("float64", 1e12, floor=0.0) == 0.0  # --tol-px 0: any error fails
    assert vertex_bound("float64", 1e12, floor=1e-9) == 1e-9  # a --tol-px given is the bound

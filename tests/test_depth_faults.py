"""oracles.diagnosis.depth_faults: core's depth maps with one mistake each, named alone.

The reference is core's own depth buffer (core.projector.zbuffer: linear ``z_cam``, depth
along ``forward``, float64) of frame 2 of 7 of each bundled scene under each default case
camera, with the per-pixel bound of a 24-bit depth buffer (oracles.judge.metrics.depth_bound);
tests/test_depth_reference.py shows pyrender's linearised depth agrees with it within that
bound. Each candidate is that map written as a renderer with one classic mistake would write
it (float32, as a float32 ``.npy`` holds it), and must get exactly one name: the mistake's.
Three mistakes move pixels rather than values, each drawn by core with the mistaken camera:
rows flipped, the principal point at (W/2, H/2) (half a pixel), K from the FOV taken as the
horizontal one; the reference's face ids are given (oracles.diagnosis.depth_pixels).
The confusion matrix over them is printed in the terminal summary and must be diagonal.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.frames import SceneRenderer
from wirecheck.core.transforms import Motion
from wirecheck.oracles.candidates.depth_map import depth_from_array, read_depth_map
from wirecheck.oracles.cases import cases_for
from wirecheck.oracles.diagnosis.depth_faults import DEPTH_FAULTS, name_depth_faults
from wirecheck.oracles.faults import CATALOGUE, Fault
from wirecheck.oracles.judge.metrics import depth_bound
from wirecheck.oracles.tolerances import NAMING

SCENES = ("cube", "prism", "pyramid")
EPS32 = float(np.finfo(np.float32).eps)


def rays(camera) -> np.ndarray:
    """``|(x_n, y_n, 1)|`` per pixel, written here from K (not the module's ray_lengths)."""
    k = camera.K
    cols, rows = np.meshgrid(np.arange(camera.width), np.arange(camera.height))
    return np.hypot(np.hypot((cols - k[0, 2]) / k[0, 0], (rows - k[1, 2]) / k[1, 1]), 1.0)


def mistakes(r: np.ndarray, camera) -> dict:
    """The map as each renderer writes it (``r``: linear depth, 0 where empty), keyed by the expected name."""
    n, f = camera.near, camera.far
    persp = camera.projection == "perspective"
    with np.errstate(divide="ignore", invalid="ignore"):
        z_win = f * (r - n) / ((f - n) * r) if persp else (r - n) / (f - n)  # glDepthRange [0, 1]
        # reversed-Z (near -> 1, far -> 0) read back with the standard linearisation d = fn / (f - z (f - n))
        reversed_lin = f * n / (f - (1.0 - z_win) * (f - n)) if persp else n + (1.0 - z_win) * (f - n)
    out = {
        "pass": r,
        "depth_encoding": np.clip(z_win, 0.0, 1.0),  # a value at exactly near is 0: no surface
        "depth_scale": r * 1000.0,  # millimetres read as metres
        "depth_offset": r + n,  # measured from one near plane behind
        "depth_reversed": reversed_lin,
        "depth_precision": r.astype(np.float16),  # a half-float target
    }
    if persp:  # orthographic rays are all depth: no mistake
        out["depth_is_range"] = r * rays(camera)
    return {name: np.where(r > 0, m, np.nan).astype(np.float32) for name, m in out.items()}


def core_depth(scene_name: str, camera, k: int = 2, frames: int = 7):
    """Core's depth buffer of frame ``k`` through ``camera``: ``(depth (0 where empty), face ids)``."""
    renderer = SceneRenderer(load_scene(scene_name), Motion(turns=(1.0, 1.0, 0.0)), frames, style="shaded")
    frame, _ = renderer.render(k, camera)
    return np.where(np.isfinite(frame.depth_image), frame.depth_image, 0.0), frame.face_ids


def frame_depth(scene_name: str, case, k: int = 2, frames: int = 7):
    """Core's depth buffer of frame ``k``: ``(depth (0 where empty), covered, bound)``."""
    depth, _faces = core_depth(scene_name, case.camera, k, frames)
    covered = depth > 0
    return depth, covered, depth_bound(depth, covered, case.camera)


def pixel_mistakes(scene_name: str, camera) -> dict:
    """The maps a camera mistake draws (core, float32), keyed by the expected name."""
    depth, _ = core_depth(scene_name, camera)
    out = {"mirror_vertical": depth[::-1]}  # read back bottom row first
    if camera.projection == "perspective":
        fx, fy = camera.focal_xy
        out["pixel_offset"] = core_depth(
            scene_name, camera.with_intrinsics(fx, fy, camera.width / 2, camera.height / 2)
        )[0]
        f_h = (camera.width / 2) / math.tan(math.radians(camera.fov_y_deg) / 2)  # the FOV as the horizontal one
        out["fov_mismatch"] = core_depth(scene_name, camera.with_intrinsics(f_h, f_h))[0]
    return {name: np.where(m > 0, m, np.nan).astype(np.float32) for name, m in out.items()}


def judge(cand32: np.ndarray, depth, bound, camera, faces=None):
    """The candidate as read from a float32 file (its encoding's bound: eps32 |d|), judged."""
    dm = depth_from_array(cand32, camera.width, camera.height, "candidate", "npy float32", 0.0, EPS32)
    return name_depth_faults(
        dm.depth, np.where(depth > 0, depth, np.nan), bound, camera, dm.encoding_bound(), faces=faces
    )


@pytest.fixture(scope="module")
def results():
    """``[(scene, case, injected, diagnosis, camera)]`` over every scene, default case and mistake."""
    out = []
    for scene_name in SCENES:
        for case in cases_for(load_scene(scene_name)):
            depth, _covered, bound = frame_depth(scene_name, case)
            faces = core_depth(scene_name, case.camera)[1]
            maps = {**mistakes(depth, case.camera), **pixel_mistakes(scene_name, case.camera)}
            for injected, cand in maps.items():
                out.append(
                    (scene_name, case.name, injected, judge(cand, depth, bound, case.camera, faces), case.camera)
                )
    return out


def diagnosed(d) -> str:
    return "pass" if d.passed else "+".join(d.names) or d.verdict


def test_each_mistake_named_alone(results):
    wrong = [(s, c, i, diagnosed(d), d.measured.get("fit_ratios")) for s, c, i, d, _ in results if diagnosed(d) != i]
    assert not wrong, wrong
    # the orthographic case has no range mistake (its rays are all depth), and no K to move
    assert len(results) == 3 * (6 * 10 + 7)


def test_named_faults_are_the_catalogues_read_from_depth(results):
    named = [f for _, _, _, d, _ in results for f in d.faults]
    assert len(named) == len(results) - 21  # every mistake named (21 maps are correct)
    for f in named:
        assert isinstance(f, Fault) and f.source == "depth" and f.hint == CATALOGUE[f.name].hint_for("depth")
    # rows flipped: a depth map's hint (the buffer read back bottom row first), not a projector's (y_px = cy - f y / z)
    flipped = next(d for _, _, i, d, _ in results if i == "mirror_vertical")
    assert "glReadPixels returns the bottom row first" in flipped.faults[0].hint


def test_confusion_matrix_is_diagonal(results, summary_section):
    counts = Counter((i, diagnosed(d)) for _, _, i, d, _ in results)
    rows = list(dict.fromkeys(i for _, _, i, _, _ in results))
    cols = list(dict.fromkeys([*rows, *sorted({c for _, c in counts} - set(rows))]))
    short = {
        n: n.replace("depth_", "")
        .replace("mirror_vertical", "mirror_v")
        .replace("_mismatch", "")
        .replace("pixel_", "px_")
        for n in cols
    }
    lines = [
        "depth faults, core's maps with one mistake each (rows injected, columns named); "
        f"{len(SCENES)} scenes x 7 cases",
        " " * 16 + " ".join(f"{short[c]:>10}" for c in cols),
    ]
    lines += [f"{short[r]:<16}" + " ".join(f"{counts[(r, c)] or '.':>10}" for c in cols) for r in rows]
    summary_section("depth fault confusion matrix", "\n".join(lines))
    assert not {k: v for k, v in counts.items() if k[0] != k[1]}
    assert set(rows) == set(DEPTH_FAULTS) - {"ambiguous", "unexplained", "mirror_horizontal"} | {"pass"}


def test_fitted_numbers_are_the_mistakes(results):
    for scene_name, case_name, injected, d, cam in results:
        p = d.faults[0].params if d.faults else {}
        where = (scene_name, case_name, injected, p)
        if injected == "depth_scale":
            assert p["k"] == pytest.approx(1000.0, rel=4 * EPS32), where  # float32 rounding of the stored value
        elif injected == "depth_offset":
            assert p["b"] == pytest.approx(cam.near, rel=1e-5), where  # within the bound's 1e-5 of depth
            assert p["b_over_near"] == pytest.approx(1.0, rel=1e-5), where
        elif injected == "depth_encoding":
            assert p["stored"] == "window [0, 1]" and not p["reversed"], where
            # near and far read back from float32 window depths: 1e-3 relative (the values near 1 keep
            # ~7 digits, and far is read from their distance to 1)
            assert p["near"] == pytest.approx(cam.near, rel=1e-3) and p["far"] == pytest.approx(cam.far, rel=1e-3), (
                where
            )
        elif injected == "depth_reversed":
            key, want = (
                ("sum_of_inverses", 1 / cam.near + 1 / cam.far)
                if cam.projection == "perspective"
                else ("sum", cam.near + cam.far)
            )
            assert p[key] == pytest.approx(want, rel=1e-5), where
        elif injected == "depth_precision":
            assert p["format"] == "float16", where
        elif injected == "depth_is_range":
            assert p["stored"] == "range along the ray", where
        elif injected == "pixel_offset":
            # cx = W / 2: the map's pixel p shows the reference's p - 0.5; fitted to 0.01 px (measured 0.007)
            assert p["dx"] == pytest.approx(-0.5, abs=0.01) and p["dy"] == pytest.approx(-0.5, abs=0.01), where
        elif injected == "fov_mismatch":
            # f' = (W/2) / tan(fov/2): the scale f / f' is H / W, the implied FOV 2 atan((H/W) tan(fov/2))
            assert p["scale"] == pytest.approx(cam.height / cam.width, rel=1e-4), where
            want = math.degrees(2 * math.atan(cam.height / cam.width * math.tan(math.radians(cam.fov_y_deg) / 2)))
            assert p["implied_fov_y_deg"] == pytest.approx(want, rel=1e-4), where


def test_fit_slack_has_room(results):
    """Every named mistake fits well inside the slack, and every other model misses it by far."""
    for _, _, injected, d, _ in results:
        if injected == "pass":
            continue
        ratios = d.measured["fit_ratios"]
        assert ratios[injected] <= 0.5 * NAMING.depth_fit_slack, (injected, ratios)
        others = [v for name, v in ratios.items() if name != injected]
        assert min(others) > 4 * NAMING.depth_fit_slack, (injected, ratios)  # measured: 19 (offset, float16 map)


def test_ambiguous_when_one_depth(tmp_path):
    """Frame 1 of the cube on axis shows one face square-on: every pixel at depth 2r, scale and offset alike."""
    case = cases_for(load_scene("cube"))[0]
    depth, covered, bound = frame_depth("cube", case, k=1)
    assert np.ptp(depth[covered]) < 1e-12 * depth[covered].max()  # one depth: the premise
    d = judge(mistakes(depth, case.camera)["depth_scale"], depth, bound, case.camera)
    assert d.names == ("ambiguous",)
    assert set(d.faults[0].params["alternatives"].split(", ")) >= {"depth_scale", "depth_offset"}


def test_png_at_scale_1000_passes(tmp_path):
    """A correct 16-bit PNG at 1000 per unit (rounded, and truncated) passes: its 1 mm step is in the bound."""
    from PIL import Image

    case = cases_for(load_scene("prism"))[1]
    depth, covered, bound = frame_depth("prism", case)
    for name, values in (("round", np.round(depth * 1000.0)), ("trunc", np.floor(depth * 1000.0))):
        path = tmp_path / f"{name}.png"
        Image.fromarray(values.astype(np.uint16)).save(path)
        dm = read_depth_map(path, case.camera.width, case.camera.height)
        assert dm.step == 1e-3
        d = name_depth_faults(dm.depth, np.where(covered, depth, np.nan), bound, case.camera, dm.encoding_bound())
        assert d.passed, (name, d.measured)
        # the same file without its step in the bound fails: the step is what lets it pass
        assert not name_depth_faults(dm.depth, np.where(covered, depth, np.nan), bound, case.camera).passed
    # read at scale 1 (the file's millimetres taken for units): named depth_scale 1000
    dm = read_depth_map(tmp_path / "round.png", case.camera.width, case.camera.height, scale=1.0)
    d = name_depth_faults(dm.depth, np.where(covered, depth, np.nan), bound, case.camera, dm.encoding_bound())
    assert d.names == ("depth_scale",) and d.faults[0].params["k"] == pytest.approx(1000.0, rel=1e-3)


def test_never_vacuous():
    """Nothing compared is never a pass: a blank (all NaN or all 0) map, and maps that do not overlap."""
    case = cases_for(load_scene("cube"))[1]
    depth, covered, bound = frame_depth("cube", case)
    ref = np.where(covered, depth, np.nan)
    cam = case.camera
    for cand in (
        np.full(depth.shape, np.nan),
        np.zeros(depth.shape),
        np.full(depth.shape, np.inf),
        np.where(covered, np.nan, 5.0),
    ):  # surface only where the reference has none
        d = name_depth_faults(cand, ref, bound, cam)
        assert d.verdict == "vacuous" and not d.passed and d.measured["compared_px"] == 0
    # a blank reference too
    assert name_depth_faults(np.where(covered, depth, np.nan), np.zeros(depth.shape), bound, cam).verdict == "vacuous"


def test_unexplained_says_what_was_measured():
    case = cases_for(load_scene("cube"))[1]
    depth, covered, bound = frame_depth("cube", case)
    noise = np.random.default_rng(7).normal(0.0, 0.01, depth.shape)  # 1% noise: no model's shape
    d = name_depth_faults(
        np.where(covered, depth * (1 + noise), np.nan), np.where(covered, depth, np.nan), bound, case.camera
    )
    assert d.names == ("unexplained",)
    assert d.measured["max_error_ratio"] > 1 and d.measured["compared_px"] == int(covered.sum())
    assert set(d.measured["fit_ratios"]) >= {"depth_scale", "depth_offset", "depth_is_range", "depth_reversed"}


def test_a_flipped_map_is_not_reversed_z_by_chance():
    # pyramid / on_axis at the spin's start (frame 1 of 3: no rotation), rows flipped. Its planar faces'
    # 1/depth flipped fits 1/c + 1/r = 0.43 to 0.07 allowances, a reversed-Z map with a sum of inverses
    # unrelated to the camera's (1/near + 1/far = 5.83): named depth_reversed while that sum was fitted.
    # Reversed-Z swaps the camera's own near and far, so the model holds the sum to the camera's
    case = next(c for c in cases_for(load_scene("pyramid")) if c.name == "on_axis")
    depth, faces = core_depth("pyramid", case.camera, k=1, frames=3)
    bound = depth_bound(depth, depth > 0, case.camera)
    flipped = np.where(depth > 0, depth, np.nan)[::-1].astype(np.float32)
    d = judge(flipped, depth, bound, case.camera, faces)
    assert d.verdict == "fail"
    named = [f.name for f in d.faults]
    assert "depth_reversed" not in named and "depth_reversed" not in str(d.faults[0].params.get("alternatives"))
    assert "mirror_vertical" in named or "mirror_vertical" in d.faults[0].params.get("alternatives", ""), d.faults

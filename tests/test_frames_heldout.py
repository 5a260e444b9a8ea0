"""A held-out check of the frames judge: renderers and line styles no other test uses, drawn by code of our own.

``tests/clients/heldout_draw.py`` draws a ``crosscheck export`` job from the
job's camera contract alone (the GL matrices, or the camera fields; nothing of
wirecheck): Pillow's ``ImageDraw.line`` (1-3 px, and 4x supersampled),
matplotlib's Agg ``Line2D`` (0.5-2 px, antialiased on and off, in display
pixels), OpenCV's ``cv2.line`` (LINE_8, LINE_4, LINE_AA with 4 sub-pixel
bits), a Xiaolin Wu and a Bresenham line written here. The rule measured
(guide: a gate never fails correct code, on inputs nobody tuned it to): a
correct renderer passes, or, aliased by another rule than GL's, is named
``raster_rule`` under ``--line-rule gl`` and passes ``--line-rule geometry`` (and the default
``any`` when that rule rounds the ends to pixel centres); one typical mistake per
renderer fails with its own name. A correct renderer that fails is a finding
of the judge's, kept here as ``xfail(strict=True)`` with its measured numbers
(docs/frames.md, "Held-out renderers").

Small jobs keep the file near a minute on one core: one case, frames 1 and 4
of 6 (pyramid / oblique_roll: slanted lines, so an offset shows in x and y);
the findings use the case where each was measured to fail.
"""

from __future__ import annotations

import json
import math
import shutil
import sys
from functools import partial
from pathlib import Path

import pytest
from wirecheck.oracles.cli import main

sys.path.insert(0, str(Path(__file__).parent / "clients"))
import heldout_draw as hd  # noqa: E402

# about 40 crosscheck runs end to end (about a second of CPU each)
pytestmark = pytest.mark.slow

#: Each job: (scene, case); frames 1 and 4 of 6.
JOBS = {
    "slanted": ("pyramid", "oblique_roll"),
    "centre_line": ("prism", "on_axis"),
    "square_on": ("cube", "narrow_fov"),
    "rolled_cube": ("cube", "oblique_roll"),
    "ortho_pyramid": ("pyramid", "orthographic"),
    "wide_prism": ("prism", "wide_fov"),
}


@pytest.fixture(scope="module")
def jobs(tmp_path_factory) -> dict:
    out = {}
    for name, (scene, case) in JOBS.items():
        path = tmp_path_factory.mktemp("heldout") / name
        assert main(["export", str(path), "--scene", scene, "--cases", case, "--frames", "6", "--every", "3"]) == 0
        out[name] = path
    return out


def _judge(jobs, tmp_path, job, draw, project=hd.project_gl, rule="gl", **mistake) -> tuple[int, dict]:
    """The job drawn by ``draw`` through ``project`` (with the mistake, if any), judged: (exit, its one case)."""
    d = tmp_path / "job"
    shutil.copytree(jobs[job], d)
    hd.render(d, draw, project, **mistake)
    rc = main(["--candidate-frames", str(d), "--report-dir", str(tmp_path / "rep"), "--line-rule", rule])
    (case,) = json.loads((tmp_path / "rep" / "report.json").read_text())["cases"]
    assert case["frames_checked"] == 2  # both frames judged: not a pass on nothing
    return rc, case


@pytest.mark.parametrize("project", [hd.project_gl, hd.project_lookat])
def test_own_projections_are_the_oracle_lines(jobs, project):
    # what makes the renderers below "correct": both routes of heldout_draw give the oracle's segments
    # (OpenCV's projection of the depth-clipped edges). Bound 1e-5 px: ends clipped at the near plane
    # differ by up to 2e-6 px (measured over the full job's near_plane cases: the clip's parameter is
    # computed another way); every other end to 1e-9 px
    from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job
    from wirecheck.oracles.diagnosis.image_diagnose import oracle_segments

    for d in jobs.values():
        job = load_job(d)
        frames = list(hd.job_frames(d))
        assert len(frames) == 2
        for _case, _png, v, e, cam, model in frames:
            p, edges, camera, m = frame_inputs(d, job, cam["scene"], cam["case"], cam["frame"])
            ref = oracle_segments(p @ m[:3, :3].T + m[:3, 3], edges, camera)
            got = project(v, e, cam, model=model)
            assert got.shape == ref.shape and len(ref) >= 5
            assert abs(got - ref).max() < 1e-5


mpl = hd.draw_matplotlib
cv2_line = hd.draw_cv2

# (id, drawer, projection, the style read): correct set-ups that pass on GL's rule
PASSING = [
    ("pillow_supersampled_4x", hd.draw_pillow_supersampled, hd.project_gl, "antialiased"),
    ("matplotlib_aa_1.0px", partial(mpl, linewidth_px=1.0), hd.project_lookat, "antialiased"),
    ("matplotlib_aa_1.5px", partial(mpl, linewidth_px=1.5), hd.project_lookat, "antialiased"),
    ("matplotlib_aa_2.0px", partial(mpl, linewidth_px=2.0), hd.project_lookat, "wide"),
    ("matplotlib_aliased_1.0px", partial(mpl, linewidth_px=1.0, antialiased=False), hd.project_lookat, "wide"),
    ("matplotlib_aliased_1.5px", partial(mpl, linewidth_px=1.5, antialiased=False), hd.project_lookat, "wide"),
    ("matplotlib_aliased_2.0px", partial(mpl, linewidth_px=2.0, antialiased=False), hd.project_lookat, "wide"),
    ("wu", hd.draw_wu, hd.project_gl, "antialiased"),
    ("cv2_LINE_AA", partial(cv2_line, line_type="LINE_AA"), hd.project_gl, "antialiased"),
]


@pytest.mark.parametrize("draw, project, style", [p[1:] for p in PASSING], ids=[p[0] for p in PASSING])
def test_correct_renderer_passes(jobs, tmp_path, capsys, draw, project, style):
    rc, c = _judge(jobs, tmp_path, "slanted", draw, project)
    assert rc == 0 and c["verdict"] == "pass", (c["reasons"], c["faults"])
    assert c["faults"] == [] and c["line_style"]["style"] == style
    # the centres measured where the oracle's lines are: within OFFSET_TOL_PX (0.2); measured <= 0.09
    assert max(map(abs, c["line_style"]["geometry"]["offset_px"])) < 0.2


# aliased by another rule than GL's: every differing pixel off by one, the lines in place
OTHER_RULE = [
    ("pillow_1px", hd.draw_pillow, hd.project_gl),
    ("bresenham", hd.draw_bresenham, hd.project_lookat),
    ("cv2_LINE_8", partial(cv2_line, line_type="LINE_8"), hd.project_gl),
    ("cv2_LINE_4", partial(cv2_line, line_type="LINE_4"), hd.project_gl),
]


@pytest.mark.parametrize("draw, project", [p[1:] for p in OTHER_RULE], ids=[p[0] for p in OTHER_RULE])
def test_another_aliased_rule_is_raster_rule_and_passes_on_geometry(jobs, tmp_path, capsys, draw, project):
    rc, c = _judge(jobs, tmp_path, "slanted", draw, project)
    assert rc == 1 and c["line_style"]["style"] == "aliased"
    (f,) = c["faults"]
    assert f["name"] == "raster_rule" and f["share_farther"] == 0.0, c["faults"]
    assert c["pixel_f1_1px"] >= 0.999 and c["pixel_f1_0px"] < 0.98  # F1@0px alone failed
    shutil.rmtree(tmp_path / "job"), shutil.rmtree(tmp_path / "rep")
    rc, c = _judge(jobs, tmp_path, "slanted", draw, project, rule="geometry")
    assert rc == 0 and c["verdict"] == "pass" and c["faults"] == [], (c["reasons"], c["faults"])


@pytest.mark.parametrize("draw, project", [p[1:] for p in OTHER_RULE], ids=[p[0] for p in OTHER_RULE])
def test_another_aliased_rule_by_default(jobs, tmp_path, capsys, draw, project):
    # the default --line-rule any: the rules that round the ends to pixel centres (Pillow, Bresenham, LINE_8)
    # are correct drawings by the line model's rounded-ends rule and pass (F1@0px against it: 1.0 measured);
    # LINE_4 (4-connected) is no rule the model draws: it still fails, raster_rule
    rc, c = _judge(jobs, tmp_path, "slanted", draw, project, rule="any")
    if getattr(draw, "keywords", {}).get("line_type") == "LINE_4":
        assert rc == 1 and [f["name"] for f in c["faults"]] == ["raster_rule"], c["faults"]
        assert c["line_style"]["rounded_rule"]["pixel_f1_0px"] < 0.98
        return
    assert rc == 0 and c["faults"] == [] and c["line_style"]["rule_read"] == "rounded", (c["reasons"], c["faults"])
    assert c["line_style"]["rounded_rule"]["pixel_f1_0px"] >= 0.999 and c["pixel_f1_0px"] < 0.98


# ---- one typical mistake per renderer, named ----

HALF = {"half_pixel": True}
MISTAKES = [
    # the viewport without its -0.5 (GL route): lines 0.5 px right and down
    ("pillow_supersampled_4x_half_pixel", hd.draw_pillow_supersampled, hd.project_gl, HALF, (0.5, 0.5)),
    ("wu_half_pixel", hd.draw_wu, hd.project_gl, HALF, (0.5, 0.5)),
    ("cv2_LINE_AA_half_pixel", partial(cv2_line, line_type="LINE_AA"), hd.project_gl, HALF, (0.5, 0.5)),
    # matplotlib's display pixels without the +0.5 of a pixel's centre: 0.5 px left and up
    (
        "matplotlib_aa_1.5px_half_pixel",
        partial(mpl, linewidth_px=1.5, half_pixel=True),
        hd.project_lookat,
        {},
        (-0.5, -0.5),
    ),
]


@pytest.mark.parametrize("draw, project, mistake, offset", [m[1:] for m in MISTAKES], ids=[m[0] for m in MISTAKES])
def test_half_pixel_mistake_is_pixel_offset_measured(jobs, tmp_path, capsys, draw, project, mistake, offset):
    rc, c = _judge(jobs, tmp_path, "slanted", draw, project, **mistake)
    assert rc == 1 and c["verdict"] == "fail"
    (f,) = c["faults"]
    assert f["name"] == "pixel_offset" and f["measured_by"] == "line centroids", c["faults"]
    # the injected offset, recovered from the lines' centres to 0.05 px (issue 23's proof)
    assert f["dx"] == pytest.approx(offset[0], abs=0.05) and f["dy"] == pytest.approx(offset[1], abs=0.05)


NAMED = [
    (
        "matplotlib_aa_1.0px_rows_not_flipped",
        partial(mpl, linewidth_px=1.0),
        hd.project_lookat,
        {"flip_rows": False},
        "slanted",
        "mirror_vertical",
    ),
    # square-on (cube / narrow_fov): the FOV alone is named; on pyramid / oblique_roll see the findings
    (
        "bresenham_fov_of_the_wrong_axis",
        hd.draw_bresenham,
        hd.project_lookat,
        {"fov_axis": "x"},
        "square_on",
        "fov_mismatch",
    ),
    (
        "cv2_LINE_8_fov_of_the_wrong_axis",
        partial(cv2_line, line_type="LINE_8"),
        hd.project_lookat,
        {"fov_axis": "x"},
        "square_on",
        "fov_mismatch",
    ),
    # where the scaled lines' ends, rounded to pixel centres, sit 0.19-0.25 px off on average (the rule's own
    # bias): the FOV alone, no pixel_offset beside it (issue 24 item 4 for an aliased rule other than GL's)
    (
        "bresenham_fov_of_the_wrong_axis_rolled_cube",
        hd.draw_bresenham,
        hd.project_lookat,
        {"fov_axis": "x"},
        "rolled_cube",
        "fov_mismatch",
    ),
    (
        "cv2_LINE_8_fov_of_the_wrong_axis_ortho_pyramid",
        partial(cv2_line, line_type="LINE_8"),
        hd.project_lookat,
        {"fov_axis": "x"},
        "ortho_pyramid",
        "fov_mismatch",
    ),
]


def _wrong_axis(job: Path) -> tuple[str, float, float]:
    """What a renderer that spans the vertical FOV (or ortho height) over the width implies, with its bound.

    Perspective: ``("implied_fov_deg", 2 atan(tan(fov/2) H / W), 0.1)``: the FOV to 0.1 deg (0.2 % of a
    12-deg FOV: the fit's scale error, 1.331-1.337 measured for 4/3). Orthographic: ``("implied_ortho_height",
    height H / W, 0.3 %)``: the same relative scale error.
    """
    cam = json.loads(next((job / "cameras").rglob("frame_0001.json")).read_text())["camera"]
    if cam["projection"] != "perspective":
        value = cam["ortho_height"] * cam["height"] / cam["width"]
        return "implied_ortho_height", value, 0.003 * value
    half = math.tan(math.radians(cam["fov_y_deg"]) / 2)
    return "implied_fov_deg", math.degrees(2 * math.atan(half * cam["height"] / cam["width"])), 0.1


@pytest.mark.parametrize("draw, project, mistake, job, name", [m[1:] for m in NAMED], ids=[m[0] for m in NAMED])
def test_typical_mistake_is_named(jobs, tmp_path, capsys, draw, project, mistake, job, name):
    rc, c = _judge(jobs, tmp_path, job, draw, project, **mistake)
    assert rc == 1 and c["verdict"] == "fail"
    assert [f["name"] for f in c["faults"]] == [name], c["faults"]
    if name == "fov_mismatch":
        key, value, tol = _wrong_axis(jobs[job])
        assert c["faults"][0][key] == pytest.approx(value, abs=tol)


# ---- findings: correct renderers the judge fails (measured; docs/frames.md, "Held-out renderers") ----


@pytest.mark.parametrize("width", [2, 3])
def test_pillow_wide_lines_pass_on_f1_at_their_width(jobs, tmp_path, capsys, width):
    # Pillow's wide lines: ends snapped to pixel centres and an asymmetric even width; their centres within
    # RULE_OFFSET_MAX_PX (measured (0.03, -0.10) and (0.07, -0.05) px), and pixels 2 px from the oracle's 1-px
    # line: F1@1px 0.995 < 0.999 (the gate's), which failed them as `unexplained`. Read wide (width 2: 1.83,
    # 3: ~3), they are held to F1 at 1 + ceil((n - 1) / 2) = 2 px for n = 2 or 3 pixels across (f1_radius)
    rc, c = _judge(jobs, tmp_path, "slanted", partial(hd.draw_pillow, width=width), hd.project_gl)
    assert c["line_style"]["style"] == "wide" and c["f1_radius_px"] == 2 == c["line_style"]["f1_radius_px"]
    assert rc == 0 and c["verdict"] == "pass" and c["faults"] == [], (c["reasons"], c["faults"])
    assert c["pixel_f1_1px"] < 0.999 <= c["pixel_f1_radius"]  # the radius decided: F1@1px alone fails
    assert max(map(abs, c["line_style"]["geometry"]["offset_px"])) < 0.35
    if width == 2:  # each edge's half-pixel lean taken out (oracles.judge.even_lean): measured (0.08, -0.09)
        assert c["line_style"]["geometry"]["lean"]["leaning"]


def test_pillow_2px_half_pixel_is_pixel_offset(jobs, tmp_path, capsys):
    # Pillow width 2 with the viewport's -0.5 left out: each edge's band leans half a pixel (to the right of
    # the direction drawn) and its ends are rounded after the move, 0 or 1 px each: the one offset fitted with
    # each edge's lean (oracles.judge.even_lean) reads (0.63, 0.60), within 0.25 of (0.5, 0.5) (a mean over
    # this case's 32 ends, each moved 0 or 1 px: SD 0.5 / sqrt(32) = 0.09 per axis, plus the leans' choice);
    # the same renderer without the mistake passes (test_pillow_wide_lines_pass_on_f1_at_their_width)
    rc, c = _judge(jobs, tmp_path, "slanted", partial(hd.draw_pillow, width=2), hd.project_gl, half_pixel=True)
    assert rc == 1 and c["verdict"] == "fail" and c["line_style"]["geometry"]["lean"]["leaning"]
    (f,) = c["faults"]
    assert f["name"] == "pixel_offset" and f["measured_by"] == "line centroids", c["faults"]
    assert f["dx"] == pytest.approx(0.5, abs=0.25) and f["dy"] == pytest.approx(0.5, abs=0.25)


def test_cv2_line_8_end_ties_pass_on_geometry(jobs, tmp_path, capsys):
    # cv2 LINE_8 rounds its ends to whole pixels, ties up: two vertices at x = 319.5 (prism / on_axis) end four
    # slanted lines there, each moved (1 - t) / 2 px along x: pooled 0.36 px, over RULE_OFFSET_MAX_PX (0.35),
    # pixel_offset. A line with an end on a pixel boundary cannot tell that rounding from an offset, so its
    # samples are left out (line_ties.drop_end_ties): measured on the other lines (780 of 1994 samples),
    # (0.00, 0.00) px, no fault, under --line-rule geometry
    rc, c = _judge(jobs, tmp_path, "centre_line", partial(cv2_line, line_type="LINE_8"), hd.project_gl, rule="geometry")
    assert c["line_style"]["style"] == "aliased"
    assert rc == 0 and c["verdict"] == "pass" and c["faults"] == [], (c["faults"], c["line_style"]["geometry"])
    assert max(map(abs, c["line_style"]["geometry"]["offset_px"])) < 0.35


def test_cv2_line_8_centre_line_is_named_raster_rule(jobs, tmp_path, capsys):
    # the same under GL's rule fails F1@0px, as another rule must. The registration fits scales (0.99897,
    # 1.00371) over the rounded ends: an aspect of 0.53 px at 111 px reach, over the 0.5-px scale tolerance,
    # which named aspect_mismatch (confidence 0.12) beside it, and raster_rule gives way to a scale fault.
    # The pixels follow the rounded-ends rule (oracles.diagnosis.rule_read), whose ends may sit half a pixel
    # from where a scale puts them: under it a scale must move a pixel by 0.5 + 0.5 px. raster_rule alone
    rc, c = _judge(jobs, tmp_path, "centre_line", partial(cv2_line, line_type="LINE_8"), hd.project_gl)
    assert rc == 1
    assert [f["name"] for f in c["faults"]] == ["raster_rule"], c["faults"]
    assert c["faults"][0]["share_farther"] == 0.0


def draw_gl_rule(segs, w, h):
    """GL's rule: wirecheck core's exact raster (the pixels pyrender draws for these lines), white on black."""
    import numpy as np
    from wirecheck.core.projector.clipping import clip_to_image
    from wirecheck.core.projector.raster import line_pixels

    img = np.zeros((h, w), np.uint8)
    _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], w, h)
    rr, cc = line_pixels(q0, q1, w, h)
    img[rr, cc] = 255
    return img


ASPECT = [
    ("gl_rule", draw_gl_rule),
    ("cv2_LINE_8", partial(cv2_line, line_type="LINE_8")),
    ("bresenham", hd.draw_bresenham),
]


@pytest.mark.parametrize("job", ["centre_line", "slanted"])
@pytest.mark.parametrize("draw", [a[1] for a in ASPECT], ids=[a[0] for a in ASPECT])
def test_an_aspect_mistake_keeps_its_name_under_either_rule(jobs, tmp_path, capsys, draw, job):
    # fx = 1.03 fy (heldout_draw's aspect mistake), drawn by GL's rule and by two rules that round the ends:
    # the rounded ends' wider scale tolerance (0.5 + 0.5 px, rule_read) must not hide a real aspect. On
    # prism / on_axis (where a correct LINE_8 fits an aspect of 0.53 px) it moves the farthest pixel by
    # 0.03 x 111 = 3.3 px, on pyramid / oblique_roll more: aspect_mismatch alone, fails
    rc, c = _judge(jobs, tmp_path, job, draw, hd.project_lookat, aspect=1.03)
    assert rc == 1 and c["verdict"] == "fail"
    assert [f["name"] for f in c["faults"]] == ["aspect_mismatch"], c["faults"]
    # the aspect the image implies: (W / H) sy / sx = (W / H) / 1.03. Each axis's scale is fitted to half a
    # pixel at the reach (~110 px: 0.45 %) under a rule that rounds the ends, the ratio to twice that: 1 %
    cam = c["camera_spec"]
    assert c["faults"][0]["implied_aspect"] == pytest.approx(cam["width"] / cam["height"] / 1.03, rel=0.01)


THIN = [
    # a 0.5-px antialiased line peaks at coverage 0.5 (grey 127 < 128): by the 128 rule alone most of its
    # pixels were not drawn (F1@1px 0.87, unexplained)
    ("matplotlib_aa_0.5px", partial(mpl, linewidth_px=0.5), "slanted"),
    # the vertical edge at x = 319.5 (the principal point of a 640-wide image): coverage 127 | 127, by the
    # 128 rule alone not drawn (F1@1px 0.980, unexplained)
    ("matplotlib_aa_1.0px_centre_line", partial(mpl, linewidth_px=1.0), "centre_line"),
]


@pytest.mark.parametrize("draw, job", [t[1:] for t in THIN], ids=[t[0] for t in THIN])
def test_thin_antialiased_lines_under_half_coverage_are_drawn(jobs, tmp_path, capsys, draw, job):
    # the ridge across each line is drawn (oracles.judge.coverage_pixels): every row or column the line
    # crosses keeps a pixel, so F1@1px holds (>= 0.999, the gate's) and the centres are measured as before
    rc, c = _judge(jobs, tmp_path, job, draw, hd.project_lookat)
    assert c["line_style"]["style"] == "antialiased"
    assert rc == 0 and c["verdict"] == "pass" and c["faults"] == [], (c["pixel_f1_1px"], c["faults"])
    assert c["pixel_f1_1px"] >= 0.999
    # the centres where the oracle's lines are: within OFFSET_TOL_PX (0.2); measured <= 0.003 (0.5 px: 0.002)
    assert max(map(abs, c["line_style"]["geometry"]["offset_px"])) < 0.2


def test_wide_binary_square_on_is_held_to_another_rules_bound(jobs, tmp_path, capsys):
    # Agg's binary 1.5-px lines (read wide, 2-3 px across by their sub-pixel position), nearly axis-aligned,
    # square-on (cube / narrow_fov), held to RULE_OFFSET_MAX_PX (0.35; a rule that snaps ends moves a line up
    # to half a pixel). Referred to the band of their width rounded (2 px) their centres measured (0.27, 0.02)
    # px, over OFFSET_TOL_PX (0.2), which failed this correct renderer as pixel_offset when it held binary
    # wide lines; referred to the band centred on the line that holds their count of pixels
    # (line_model.band_holding) they measure (0.003, 0.003): a centred band reads under 0.05 px
    draw = partial(mpl, linewidth_px=1.5, antialiased=False)
    rc, c = _judge(jobs, tmp_path, "square_on", draw, hd.project_lookat)
    assert c["line_style"]["style"] == "wide" and c["line_style"]["offset_tol_px"] == 0.35
    assert rc == 0 and c["verdict"] == "pass" and c["faults"] == [], (c["faults"], c["line_style"]["geometry"])
    assert max(map(abs, c["line_style"]["geometry"]["offset_px"])) < 0.05


def test_pillow_half_pixel_is_pixel_offset_against_its_rules_bias(jobs, tmp_path, capsys):
    # Pillow 1 px with the viewport's -0.5 left out: its ends are rounded to pixel centres (the rule read
    # first, "snapped"; GL's is read too, its cost within the tie margin: rule_read), whose free fit has a
    # shear of its own (0.35 px) that is no rotation. Named pixel_offset alone, standing against both rules'
    # biases, the injected (0.5, 0.5) to 0.25 px: the rounded ends' bias at the offset lines and at the
    # correct ones differ by up to a snapped rule's pooled bias (0.19-0.25 px measured); (0.62, 0.42)
    rc, c = _judge(jobs, tmp_path, "slanted", hd.draw_pillow, hd.project_gl, half_pixel=True)
    assert rc == 1 and c["verdict"] == "fail"
    (f,) = c["faults"]
    assert f["name"] == "pixel_offset" and f["rules_read"][0] == "snapped", c["faults"]
    assert f["bias_rule"] in f["rules_read"]
    assert f["dx"] == pytest.approx(0.5, abs=0.25) and f["dy"] == pytest.approx(0.5, abs=0.25)


@pytest.mark.parametrize(
    "draw",
    [hd.draw_bresenham, partial(cv2_line, line_type="LINE_8"), hd.draw_pillow],
    ids=["bresenham", "cv2_LINE_8", "pillow_1px"],
)
def test_fov_of_the_wrong_axis_on_prism_wide_fov_is_the_fov_alone(jobs, tmp_path, capsys, draw):
    # the wrong-axis FOV drawn by a rule that rounds the ends, prism / wide_fov: the registration's offset
    # (0.02, 0.19) px is over GL's bias (-0.01, -0.02) by 0.21 (> 0.2) and within the rounded ends' own
    # (-0.05, 0.14); the pixels fit GL's lines a little closer (cost 0.361 against 0.368), within the tie
    # margin (NAMING.rule_tie): the offset must stand against both rules' biases, and does not.
    # fov_mismatch alone, no pixel_offset beside it
    rc, c = _judge(jobs, tmp_path, "wide_prism", draw, hd.project_lookat, fov_axis="x")
    assert rc == 1 and c["verdict"] == "fail"
    assert [f["name"] for f in c["faults"]] == ["fov_mismatch"], c["faults"]
    key, value, tol = _wrong_axis(jobs["wide_prism"])
    assert c["faults"][0][key] == pytest.approx(value, abs=tol)


def test_fov_of_the_wrong_axis_on_a_slanted_view_is_named(jobs, tmp_path, capsys):
    # Bresenham with the FOV spanned over the width, pyramid / oblique_roll (2 frames): the free fit's shear
    # (0.35 px, over the 0.3 of a rotation) is the rounded ends' own, measured on the model drawn by that rule
    rc, c = _judge(jobs, tmp_path, "slanted", hd.draw_bresenham, hd.project_lookat, fov_axis="x")
    assert rc == 1
    assert [f["name"] for f in c["faults"]] == ["fov_mismatch"], c["faults"]
    key, value, tol = _wrong_axis(jobs["slanted"])
    assert c["faults"][0][key] == pytest.approx(value, abs=tol)

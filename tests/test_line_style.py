"""Any line style on the frames path: antialiased, wide and other aliased rules judged by their geometry.

Frames are drawn here from the job's exact segments (the oracle's lines,
``oracles.diagnosis.image_diagnose.oracle_segments``: OpenCV's projection of the depth-
clipped edges, equal to core's to ~1e-13 px): antialiased as 4x4 supersampled
coverage of a 1-px line, wide as every pixel centre within 1.5 px of the line
(3 px), and with Pillow's ``ImageDraw.line`` (ends rounded to pixel centres,
Pillow's own aliased rule). A half-pixel convention error is the same lines
shifted by (0.5, 0.5).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageDraw
from wirecheck.core.projector.clipping import clip_to_image
from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job, read_grey
from wirecheck.oracles.cli import main
from wirecheck.oracles.diagnosis.image_diagnose import oracle_segments
from wirecheck.oracles.judge.decide import decide
from wirecheck.oracles.judge.evidence import CaseEvidence
from wirecheck.oracles.judge.line_style import RULE_OFFSET_MAX_PX, measure, pooled_offset, style_record
from wirecheck.oracles.judge.name_faults import name_faults
from wirecheck.oracles.tolerances import NAMING, OFFSET_TOL_PX, Tolerances

# oblique views: the lines slant, so every frame shows both offset components
ARGS = ["--scene", "cube", "--scene", "pyramid", "--cases", "oblique_roll,non_square", "--frames", "6", "--every", "3"]


def style_judged(style, tol=None):
    """A CaseStyle's frames judged alone: pixels that agree (F1 1.0), only the style's own limits deciding;
    ``(verdict, fault names, line_style record)`` (oracles.judge.decide, name_faults, line_style.style_record)."""
    tol = Tolerances() if tol is None else tol
    ev = CaseEvidence(
        level="frames",
        compared={"frames": 1, "vertices": 0, "pixels": 1},
        frames_checked=1,
        pixels={"pixel_f1_0px": 1.0, "pixel_f1_1px": 1.0, "worst_pixel_frame": 1},
        style=style.read((), tol),
    )
    verdict = decide(ev, tol)
    return verdict, [f.name for f in name_faults(ev, verdict, tol)], style_record(ev.style, verdict.style, 1)


def free_ends_scene():
    """Three separate lines (six free ends) seen by an orthographic camera at 1 px per unit, 220 x 140:
    ``(camera, p_world, edges, oracle segments)``."""
    from wirecheck.core.camera import Camera

    cam = Camera(
        position=[0.0, 0.0, 10.0],
        forward=[0.0, 0.0, -1.0],
        up=[0.0, 1.0, 0.0],
        width=220,
        height=140,
        projection="orthographic",
        ortho_height=140.0,
    )
    p = np.array(
        [
            [-90.0, 50.0, 0.0],
            [10.0, 13.0, 0.0],
            [-80.0, -30.0, 0.0],
            [-70.0, 20.0, 0.0],
            [40.0, 40.0, 0.0],
            [80.3, -40.7, 0.0],
        ]
    )
    edges = np.array([[0, 1], [2, 3], [4, 5]])
    return cam, p, edges, oracle_segments(p, edges, cam)


def _band(segs, w, h, half, ss):
    """Coverage (uint8) of lines of half-width ``half`` px: pixels' ``ss x ss`` sub-centres within it."""
    hi_w, hi_h = w * ss, h * ss
    acc = np.zeros((hi_h, hi_w), bool)
    for a, b in segs:
        a, b = (a + 0.5) * ss - 0.5, (b + 0.5) * ss - 0.5  # pixel centres at integers, in sub-pixels
        lo = np.maximum(np.floor(np.minimum(a, b) - half * ss - 1), 0).astype(int)
        top = np.minimum(np.ceil(np.maximum(a, b) + half * ss + 1), [hi_w - 1, hi_h - 1]).astype(int)
        if np.any(top < lo):
            continue
        yy, xx = np.mgrid[lo[1] : top[1] + 1, lo[0] : top[0] + 1]
        q = np.stack([xx.ravel(), yy.ravel()], axis=1).astype(float)
        ab = b - a
        t = np.clip(((q - a) @ ab) / max(ab @ ab, 1e-300), 0.0, 1.0)
        near = np.hypot(*(a + t[:, None] * ab - q).T) <= half * ss
        acc[yy.ravel()[near], xx.ravel()[near]] = True
    return np.floor(acc.reshape(h, ss, w, ss).mean(axis=(1, 3)) * 255 + 0.5).astype(np.uint8)


def draw_antialiased(segs, w, h):
    return _band(segs, w, h, 0.5, 4)


def draw_wide(segs, w, h):
    return _band(segs, w, h, 1.5, 1)


def draw_pillow(segs, w, h, width=1):
    im = Image.new("L", (w, h), 0)
    d = ImageDraw.Draw(im)
    _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], w, h)
    for a, b in zip(q0, q1):
        d.line([tuple(np.rint(a)), tuple(np.rint(b))], fill=255, width=width)
    return np.asarray(im)


@pytest.fixture(scope="module")
def job_dir(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("style") / "job"
    assert main(["export", str(path)] + ARGS) == 0
    return path


def _fill(job_dir: Path, tmp_path: Path, draw, shift=(0.0, 0.0)) -> Path:
    d = tmp_path / "filled"
    shutil.copytree(job_dir, d)
    job = load_job(d)
    for c in job["cases"]:
        for rel in c["frames"]:
            k = int(Path(rel).stem.split("_")[-1])
            p, e, cam, m = frame_inputs(d, job, c["scene"], c["case"], k)
            segs = oracle_segments(p @ m[:3, :3].T + m[:3, 3], e, cam) + np.asarray(shift)
            (d / rel).parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(draw(segs, cam.width, cam.height)).save(d / rel)
    return d


def _judge(job: Path, tmp_path: Path, *extra) -> tuple[int, dict]:
    rc = main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "rep"), *extra])
    return rc, json.loads((tmp_path / "rep" / "report.json").read_text())


@pytest.mark.parametrize(
    "draw, style", [(draw_antialiased, "antialiased"), (draw_wide, "wide")], ids=["antialiased", "3px"]
)
def test_correct_antialiased_and_wide_lines_pass(job_dir, tmp_path, capsys, draw, style):
    rc, report = _judge(_fill(job_dir, tmp_path, draw), tmp_path)
    out = capsys.readouterr().out
    assert rc == 0, out
    assert len(report["cases"]) == 4
    for c in report["cases"]:
        assert c["line_style"]["style"] == style
        # GL's pixel rule would fail them (the bound is 0.98): it is reported, not judged
        assert c["pixel_f1_0px"] < 0.98 and c["pixel_f1_1px"] >= 0.999
        assert c["verdict"] == "pass" and c["faults"] == [], c["faults"]
        # 3 px: each pixel centre within 1.5 px of the line, about 3 pixels across; 1 px antialiased: 1
        assert c["line_style"]["width_px"] == pytest.approx(3.0 if style == "wide" else 1.0, abs=0.1)
        assert "GL's pixel rule" in c["line_style"]["cannot_show"]
    # the report says which style was read, how it was judged and what it cannot show
    said = f"Line style read: {style} (4 cases"
    md = (tmp_path / "rep" / "report.md").read_text()
    assert said in out and said in md and "cannot show GL's pixel rule" in md


@pytest.mark.parametrize("draw", [draw_antialiased, draw_wide], ids=["antialiased", "3px"])
def test_half_pixel_offset_is_measured(job_dir, tmp_path, capsys, draw):
    rc, report = _judge(_fill(job_dir, tmp_path, draw, shift=(0.5, 0.5)), tmp_path)
    assert rc == 1
    for c in report["cases"]:
        assert c["verdict"] == "fail"
        (f,) = c["faults"]
        assert f["name"] == "pixel_offset"
        # the lines were drawn 0.5 px right and down: their measured centres within 0.05 px of it
        assert f["dx"] == pytest.approx(0.5, abs=0.05) and f["dy"] == pytest.approx(0.5, abs=0.05)
        assert any("line centres offset" in r for r in c["reasons"])


def test_a_small_scale_error_of_antialiased_lines_fails(job_dir, tmp_path, capsys):
    # the lines scaled about the principal point so that the farthest end moves 0.8 px: within F1@1px's
    # 1 px, so only the measured centres can fail it (0.8 > SCALE_TOL_PX, 0.5)
    def scaled(segs, w, h):
        c = np.array([(w - 1) / 2.0, (h - 1) / 2.0])  # the principal point of the job's centred cameras
        reach = np.max(np.hypot(*(segs.reshape(-1, 2) - c).T))
        return draw_antialiased(c + (segs - c) * (1.0 + 0.8 / reach), w, h)

    rc, report = _judge(_fill(job_dir, tmp_path, scaled), tmp_path)
    assert rc == 1
    for c in report["cases"]:
        assert c["verdict"] == "fail", c["line_style"]["geometry"]
        assert any("moved by up to" in r for r in c["reasons"]), c["reasons"]
        assert 0.5 < c["line_style"]["geometry"]["warp_px"] <= 0.8 + 0.05


def test_pillow_rule_passes_by_default_and_is_raster_rule_under_gl(job_dir, tmp_path, capsys):
    job = _fill(job_dir, tmp_path, draw_pillow)
    # by default (--line-rule any) a correct drawing by the rounded-ends rule passes, with one line saying so
    rc, report = _judge(job, tmp_path)
    out = capsys.readouterr().out
    assert rc == 0 and report["line_rule"] == "any", [c["reasons"] for c in report["cases"]]
    for c in report["cases"]:
        assert c["line_style"]["rule_read"] == "rounded" and c["faults"] == [] and c["pixel_f1_0px"] < 0.98
    assert out.count("Line rule read: ends rounded to pixel centres") == 1 and "--line-rule gl holds them" in out
    # --line-rule gl holds them to GL's: raster_rule, a correct drawing by another rule, no count deficit
    shutil.rmtree(tmp_path / "rep")
    rc, report = _judge(job, tmp_path, "--line-rule", "gl")
    assert rc == 1
    for c in report["cases"]:
        assert c["line_style"]["style"] == "aliased"
        assert c["verdict"] == "fail" and c["pixel_f1_1px"] >= 0.999 and c["pixel_f1_0px"] < 0.98
        (f,) = c["faults"]  # no rotation, mirror or offset
        assert f["name"] == "raster_rule" and f["rule"] == "rounded", c["faults"]
        assert f["share_off_by_one_across"] > 0.1 and f["share_farther"] == 0.0
        assert f["share_off_by_one_at_ends"] < f["share_off_by_one_across"]
        assert "rotation" not in f["note"] and "--line-rule gl" in f["note"]
        assert not any("against the oracle's count" in r for r in c["reasons"]), c["reasons"]
    # the user's choice: the geometry only
    shutil.rmtree(tmp_path / "rep")
    rc, report = _judge(job, tmp_path, "--line-rule", "geometry")
    assert rc == 0, [c["reasons"] for c in report["cases"]]
    assert report["line_rule"] == "geometry"
    assert all(c["faults"] == [] for c in report["cases"])


def test_half_pixel_offset_of_aliased_lines_is_no_raster_rule(job_dir, tmp_path, capsys):
    # core's GL-like lines drawn 0.5 px off: every differing pixel is off by one too, but the lines
    # moved as a whole (0.5 > RULE_OFFSET_MAX_PX): a pixel offset, not a rule
    from wirecheck.core.projector.raster import line_pixels

    def draw_gl(segs, w, h):
        img = np.zeros((h, w), np.uint8)
        _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], w, h)
        rr, cc = line_pixels(q0, q1, w, h)
        img[rr, cc] = 255
        return img

    rc, report = _judge(_fill(job_dir, tmp_path, draw_gl, shift=(0.5, 0.5)), tmp_path)
    assert rc == 1 and 0.5 > RULE_OFFSET_MAX_PX
    for c in report["cases"]:
        names = [f["name"] for f in c["faults"]]
        assert "raster_rule" not in names and "pixel_offset" in names, names


def test_measure_recovers_a_known_offset():
    # one antialiased line at 20 degrees, drawn 0.3 px along its normal: the centroid finds 0.3
    # (coverage of a 4x4 supersampled box filter is symmetric about the line: no bias above ~0.01 px)
    a, b = np.array([20.0, 30.0]), np.array([180.0, 30.0 + 160.0 * np.tan(np.radians(20))])
    n = np.array([-(b - a)[1], (b - a)[0]]) / np.hypot(*(b - a))
    img = _band(np.array([[a, b]]) + 0.3 * n, 200, 120, 0.5, 4) / 255.0
    got = measure(img, np.array([[a, b]]))
    normal, offset, width = got["normal"], got["offset"], got["width"]
    assert len(offset) > 100 and NAMING.profile_min_mass < 1.0
    assert np.median(offset) == pytest.approx(0.3, abs=0.01)
    assert np.median(width) == pytest.approx(1.0, abs=0.05)
    d, determined = pooled_offset(normal, offset)
    # one direction of normal: the offset along the line is not determined; along n it is 0.3
    assert float(d @ n) == pytest.approx(0.3, abs=0.01) and OFFSET_TOL_PX < 0.3


def test_read_grey_keeps_coverage_and_the_rule(tmp_path):
    rgba = np.zeros((1, 4, 4), np.uint8)
    rgba[0, :, :3] = 255
    rgba[0, :, 3] = [0, 100, 129, 255]  # white at alpha 100: 255 * 100 / 255 = 100
    path = tmp_path / "f.png"
    Image.fromarray(rgba, "RGBA").save(path)
    assert read_grey(path, 4, 1).tolist() == [[0, 100, 129, 255]]
    Image.fromarray(np.array([[127, 128, 64]], np.uint8)).save(path)
    assert read_grey(path, 3, 1).tolist() == [[127, 128, 64]]
    # opaque 8-bit RGB: the luminance L = 0.299 R + 0.587 G + 0.114 B (ITU-R 601-2) in Pillow's fixed point,
    # (R 19595 + G 38470 + B 7471 + 2^15) >> 16: red 76.7 -> 76, green 150.2 -> 150, blue 29.6 -> 29
    rgb = np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]]], np.uint8)
    Image.fromarray(rgb, "RGB").save(path)
    assert read_grey(path, 4, 1).tolist() == [[76, 150, 29, 255]]


def test_line_rule_needs_frames(tmp_path, capsys):
    rc = main(
        ["--line-rule", "geometry", "--scene", "cube", "--level", "vertices", "--report-dir", str(tmp_path / "rep")]
    )
    err = capsys.readouterr().err
    assert rc == 2 and "--line-rule geometry without --candidate-frames" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    "short_px, named", [(0.0, False), (1.0, True), (-1.0, True)], ids=["correct", "dropped", "extra"]
)
def test_a_dropped_or_extra_end_is_named(short_px, named):
    # three separate lines (six free ends) seen by an orthographic camera at 1 px per unit, drawn
    # antialiased (round caps of radius 0.5: the cap's chord is half the width 0.43 px past the end;
    # measured 0.27-0.46 with the end's sub-pixel phase), with 1 px dropped from (or added to) each
    # end: measured -0.73..-0.54 / 1.25..1.51, beyond -END_TOL_PX (-0.5) / width / 2 + END_TOL_PX (1.0)
    from wirecheck.oracles.judge.line_style import CaseStyle

    cam, p, edges, segs = free_ends_scene()
    u = (segs[:, 1] - segs[:, 0]) / np.hypot(*(segs[:, 1] - segs[:, 0]).T)[:, None]
    drawn = np.stack([segs[:, 0] + short_px * u, segs[:, 1] - short_px * u], axis=1)
    style = CaseStyle()
    style.frame(draw_antialiased(drawn, 220, 140), np.zeros((140, 220), bool), p, edges, cam, np.eye(4))
    verdict, names, line_style = style_judged(style)
    geo = line_style["geometry"]
    assert line_style["style"] == "antialiased" and geo["ends_measured"] == 6
    assert geo["end_px"] == pytest.approx(0.37 - short_px, abs=0.15)
    assert names == (["line_end_bias"] if named else [])
    assert any("line ends" in r for r in verdict.reasons) == named


def test_a_case_keeps_a_bounded_number_of_samples(monkeypatch):
    # past MAX_SAMPLES_PER_CASE every frame's samples are halved: memory bounded whatever the number of
    # frames, the counts that say how much line was found kept (found_share stays 1: a correct drawing)
    from wirecheck.core.camera import Camera
    from wirecheck.oracles.judge import line_style

    monkeypatch.setattr(line_style, "MAX_SAMPLES_PER_CASE", 600)
    cam = Camera(
        position=[0.0, 0.0, 10.0],
        forward=[0.0, 0.0, -1.0],
        up=[0.0, 1.0, 0.0],
        width=220,
        height=140,
        projection="orthographic",
        ortho_height=140.0,
    )
    p = np.array([[-90.0, 50.0, 0.0], [10.0, 13.0, 0.0], [-80.0, -30.0, 0.0], [-70.0, 20.0, 0.0]])
    edges = np.array([[0, 1], [2, 3]])
    image = draw_antialiased(oracle_segments(p, edges, cam), 220, 140)
    style = line_style.CaseStyle()
    for _ in range(8):
        style.frame(image, np.zeros((140, 220), bool), p, edges, cam, np.eye(4))
        assert style.samples.kept + style.reference.kept <= 600
        # the halved samples hold their own memory: a view (x[::2]) would keep every frame's whole arrays
        # alive, and the case's memory would grow with its frames whatever the samples kept
        assert all(v.base is None for v in style.samples.arrays() + style.reference.arrays())
    _, names, line_style = style_judged(style)
    geo = line_style["geometry"]
    assert geo["found_share"] == 1.0 and max(map(abs, geo["offset_px"])) < 0.05 and names == []


@pytest.mark.parametrize("row", [0, -1], ids=["first_row", "last_row"])
def test_off_by_one_pixels_at_the_image_border(row):
    # the raster-rule counts of line_style._off_by_one on a 4 x 5 image, by hand: the oracle draws a line
    # along a border row, the candidate draws it one row inwards and one pixel longer at the right. Each of
    # the 4 + 5 differing pixels has a pixel of the other side among its 8 neighbours (those beyond the
    # image are none): all off by one; a mutant that looks past the border fails on the border row
    from wirecheck.oracles.judge.line_style import _off_by_one
    from wirecheck.oracles.judge.metrics import FramePixels

    h, w = 4, 5
    inner = 1 if row == 0 else h - 2
    orac = np.zeros((h, w), bool)
    cand = np.zeros((h, w), bool)
    orac[row, 0:4] = True
    cand[inner, 0:5] = True
    ends = np.array([[0.0, row % h], [4.0, row % h]])  # the segment's ends (x, y)
    got = _off_by_one(FramePixels(cand, orac), ends)
    # at the ends: within END_RADIUS_PX = 1.5 px of (0, row): (0, row), (1, row), (0, inner), (1, inner); of (4, row):
    # (3, row), (3, inner), (4, inner): 7 of the 9, the other 2 ((2, row), (2, inner)) across
    assert got == {"oracle_pixels": 4, "differing": 9, "off_by_one_across": 2, "off_by_one_at_ends": 7, "farther": 0}


def test_only_binary_frames_get_a_reference_drawing():
    # the quantisation of binary lines is measured on a correct binary drawing of the same lines and
    # subtracted (module docstring); grey (antialiased) frames are not quantised and get none. The frames:
    # two lines antialiased (4 x 4 supersampled: a third or more of the drawn pixels grey), and the same
    # thresholded at 128 (binary: no grey at all)
    from wirecheck.core.camera import Camera
    from wirecheck.oracles.judge import line_style

    cam = Camera(
        position=[0.0, 0.0, 10.0],
        forward=[0.0, 0.0, -1.0],
        up=[0.0, 1.0, 0.0],
        width=220,
        height=140,
        projection="orthographic",
        ortho_height=140.0,
    )
    p = np.array([[-90.0, 50.0, 0.0], [10.0, 13.0, 0.0], [-80.0, -30.0, 0.0], [-70.0, 20.0, 0.0]])
    edges = np.array([[0, 1], [2, 3]])
    grey = draw_antialiased(oracle_segments(p, edges, cam), 220, 140)
    drawn = grey[grey > 0]
    assert np.mean((drawn > 255 / 8) & (drawn < 255 * 7 / 8)) > 0.3  # the frame is grey
    binary = np.where(grey >= 128, 255, 0).astype(np.uint8)
    for image, references in ((grey, 0), (binary, 2)):
        style = line_style.CaseStyle()
        for _ in range(2):
            style.frame(image, np.zeros((140, 220), bool), p, edges, cam, np.eye(4))
        assert len(style.reference) == references


def test_summary_lines_one_per_style_and_rule():
    # report.md / stdout: one line per (style, line rule) read in a run's cases, by hand for three cases:
    # two antialiased ones (widths 1.02 and 0.98) and one aliased under --line-rule geometry; a case with
    # no line style (a projector's) adds nothing
    from wirecheck.oracles.judge.line_style import CANNOT_SHOW, summary_lines

    def case(style, rule, width, judged_by):
        return {"line_style": {"style": style, "line_rule": rule, "width_px": width, "judged_by": judged_by}}

    by_centres = "the geometry (line centres); F1@0px is reported, not judged"
    cases = [
        case("antialiased", "gl", 1.02, by_centres),
        {"faults": []},
        case("aliased", "geometry", 1.0, by_centres),
        case("antialiased", "gl", 0.98, by_centres),
    ]
    assert summary_lines(cases) == [
        f"Line style read: aliased (1 case, 1.00-1.00 px wide, --line-rule geometry): judged by {by_centres}; "
        f"cannot show {CANNOT_SHOW['aliased']}",
        f"Line style read: antialiased (2 cases, 0.98-1.02 px wide, --line-rule gl): judged by {by_centres}; "
        f"cannot show {CANNOT_SHOW['antialiased']}",
    ]
    assert summary_lines([{"faults": []}]) == []

"""oracles.sweep: every dtype x clip x raster setting against the oracles.

Small runs (the cube, two cameras, two frames) keep this fast; the full sweep
is `crosscheck --sweep` (README, "Speed against accuracy").
"""

import copy
import json

import numpy as np
import pytest
from wirecheck.core.scene.files import load_scene
from wirecheck.oracles import sweep
from wirecheck.oracles.references.pyrender_oracle import osmesa_available

needs_osmesa = pytest.mark.skipif(not osmesa_available()[0], reason="libOSMesa not available")


def _strip_timing(report):
    report = copy.deepcopy(report)
    for r in report["settings"]:
        r.pop("timing")
    return report


@pytest.fixture(scope="module")
def small_sweep():
    return sweep.run_sweep(
        [load_scene("cube")], frames=2, case_names=["on_axis", "near_plane"], large=sweep.large_mesh(1), repeats=1
    )


def test_all_twelve_settings_once():
    keys = [s.key for s in sweep.all_settings()]
    assert len(keys) == len(set(keys)) == 2 * 2 * 3
    assert "float64/clip/exact" in keys


@needs_osmesa
def test_sweep_accuracy_by_setting(small_sweep):
    rows = {r["setting"]: r for r in small_sweep["settings"]}
    assert len(rows) == 12
    assert sum(r["default"] for r in rows.values()) == 1 and rows["float64/clip/exact"]["default"]
    # float64: the crosscheck tolerance (1e-6 px; its basis is in oracles/tolerances.py).
    # float32: each coordinate passes ~6 roundings (rotation: 3 products + 2 sums;
    # translation; divide; f*; cx+) of relative size eps32/2, on pixel values up
    # to ~|x_px| <= 640 (the image) and on the camera-relative coordinates scaled
    # by f/z: bound 8 * eps32 * 640 ~ 6.1e-4 px. It must also be clearly above
    # float64's error (float32 really ran).
    bound32 = 8 * np.finfo(np.float32).eps * 640
    for key, r in rows.items():
        assert r["visibility_mismatches"] == 0, key
        if r["dtype"] == "float64":
            assert r["max_vertex_error_px"] <= 1e-6, key
        else:
            assert 1e-9 < r["max_vertex_error_px"] <= bound32, key
    # the default setting meets crosscheck's gates (oracles/tolerances.py)
    d = rows["float64/clip/exact"]
    assert d["pixel_f1_1px"] >= 0.999 and d["pixel_f1_0px"] >= 0.98
    # near_plane crosses the near plane: "endpoint" drops the crossing edges that
    # Mesa draws clipped, so its recall, hence F1, is lower than "clip"'s.
    assert rows["float64/endpoint/exact"]["pixel_f1_0px"] < d["pixel_f1_0px"]
    # "fast" rounds ends to whole pixels and draws both ends: within 1 px of Mesa
    # but not pixel-exact.
    fast = rows["float64/clip/fast"]
    assert fast["pixel_f1_1px"] >= 0.99 and fast["pixel_f1_0px"] < d["pixel_f1_0px"]


@needs_osmesa
def test_sweep_is_deterministic_apart_from_timing(small_sweep):
    again = sweep.run_sweep(
        [load_scene("cube")], frames=2, case_names=["on_axis", "near_plane"], large=sweep.large_mesh(1), repeats=1
    )
    assert json.dumps(_strip_timing(again), sort_keys=True) == json.dumps(_strip_timing(small_sweep), sort_keys=True)


def test_pareto_front_by_hand():
    def row(name, ms, err, f1):
        return {"setting": name, "max_vertex_error_px": err, "pixel_f1_0px": f1, "timing": {"ms_per_frame_large": ms}}

    rows = [
        row("a", 1.0, 1e-3, 0.9),  # fastest: on the front
        row("b", 2.0, 1e-12, 0.99),  # most accurate: on the front
        row("c", 2.5, 1e-12, 0.98),  # slower and worse F1 than b: dominated
        row("d", 1.0, 1e-3, 0.8),
    ]  # same time and error as a, worse F1: dominated
    sweep._pareto(rows)
    assert [r["timing"]["pareto"] for r in rows] == [True, True, False, False]


@needs_osmesa
def test_plot_and_markdown(small_sweep, tmp_path):
    path = tmp_path / "sweep.png"
    sweep.plot_png(small_sweep, path)
    from PIL import Image

    with Image.open(path) as im:
        assert im.size == (1100, 420)  # figsize (11, 4.2) at dpi 100
        px = np.asarray(im.convert("L"))
    assert (px < 128).mean() > 0.001  # something was drawn, not a blank canvas
    md = sweep.markdown(small_sweep)
    rows = [ln for ln in md.splitlines() if ln.startswith("| ") and ("float64/" in ln or "float32/" in ln)]
    assert len(rows) == 12 and "| **float64/clip/exact** (default) |" in md


def test_cli_sweep_writes_table_and_plot(tmp_path, capsys):
    from wirecheck.oracles.cli import main

    out = tmp_path / "sw"
    rc = main(
        [
            "--sweep",
            "--level",
            "vertices",
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            "--frames",
            "2",
            "--report-dir",
            str(out),
        ]
    )
    assert rc == 0
    assert sorted(p.name for p in out.iterdir()) == [
        ".wirecheck-output",
        "sweep.html",
        "sweep.json",
        "sweep.md",
        "sweep.png",
    ]
    data = json.loads((out / "sweep.json").read_text())
    assert len(data["settings"]) == 12 and data["oracles"] == ["opencv"]
    assert data["frames_checked"] == 2
    assert "PASS: the default setting" in capsys.readouterr().out


@pytest.mark.parametrize(
    "extra", [["--candidate", "tests/data/user_projector.py:project"], ["--dtype", "float32"], ["--suite", "extremes"]]
)
def test_cli_sweep_rejects_candidate_settings_and_suite(extra, tmp_path, capsys):
    from wirecheck.oracles.cli import main

    with pytest.raises(SystemExit) as exc:  # argparse: --suite and --sweep are exclusive
        rc = main(["--sweep", *extra, "--report-dir", str(tmp_path / "x")])
        raise SystemExit(rc)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("crosscheck: error:")
    assert not (tmp_path / "x").exists()


@needs_osmesa
def test_sweep_composes_each_objects_motion():
    # The orrery's planet sits at x = 2.5 with its own spin: a sweep that ignored
    # object motion put every object at the origin (3 units off) and still
    # "passed" against an oracle making the same mistake. Now the oracle builds
    # each object's matrix with scipy and core renders world points, as renderer
    # does: the default setting meets the tolerances.
    from wirecheck.core.scene.model import world_points
    from wirecheck.core.transforms import Motion

    orrery = load_scene("orrery")
    assert not orrery.is_single_static
    motion = Motion()
    from wirecheck.oracles.references.faces import frame_geometry

    ref = frame_geometry(orrery, motion, 2 / 8)[0]  # frame 3 of 8: t = 2/8
    # scipy's composition equals core's to rounding (entries ~3, a few eps each)
    np.testing.assert_allclose(ref, world_points(orrery, motion, 3, 8), rtol=0, atol=1e-12)
    naive = orrery.vertices @ motion.frame_matrix(3, 8)[:3, :3].T  # object motion ignored
    assert np.abs(ref - naive).max() > 1.0
    result = sweep.run_sweep([orrery], frames=2, case_names=["oblique_roll"], repeats=1)
    d = next(r for r in result["settings"] if r["default"])
    assert d["max_vertex_error_px"] <= 1e-6 and d["visibility_mismatches"] == 0
    assert d["pixel_f1_1px"] >= 0.999 and d["pixel_f1_0px"] >= 0.98

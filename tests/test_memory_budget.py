"""A dataset run's memory budget (oracles.datasets.memory_budget): a mesh over it is one load error, the run goes on."""

from __future__ import annotations

import contextlib
import io
import json

import pytest
from wirecheck.oracles import cli


def _cli(argv) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = cli.main([str(a) for a in argv])
    return code, o.getvalue(), e.getvalue()


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    import trimesh

    root = tmp_path_factory.mktemp("budget") / "meshes"
    root.mkdir()
    trimesh.creation.box(extents=(1, 1, 1)).export(root / "box.obj")  # 8 vertices, 18 edges, 12 faces
    trimesh.creation.icosphere(subdivisions=3).export(root / "ico.ply")  # 642 vertices, 1,920 edges, 1,280 faces
    return root


# The estimate (bytes): 2^29 + 200 V + 400 E + 300 F. box.obj: 2^29 + 12,400 (512.01 MiB); ico.ply: 2^29 +
# 128,400 + 768,000 + 384,000 = 538,151,312 (513.2 MiB). A budget of 0.5001 GiB (512.05 MiB) holds the box only.
BUDGET = "0.5001"


def test_a_mesh_over_the_budget_is_a_load_error_and_the_run_goes_on(folder, tmp_path):
    code, out, err = _cli(
        [
            "--scene",
            folder,
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--memory-budget",
            BUDGET,
            "--report-dir",
            tmp_path / "r",
        ]
    )
    assert code == 1, err  # a mesh not checked is never a pass
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    why = (
        "needs about 513 MiB to check (642 vertices, 1920 edges, 1280 faces): over the memory budget of "
        "512 MiB a mesh (--memory-budget GIB to change it)"
    )
    assert report["summary"]["errors"] == [{"mesh": "ico.ply", "error": why}]
    box, ico = report["meshes"]
    assert box["verdict"] == "pass" and box["cases"][0]["compared"]["frames"] == 1  # checked
    assert ico["verdict"] == "error" and "cases" not in ico  # not checked
    assert f"ico.ply: {why}" in out
    code, _, err = _cli(
        [
            "--scene",
            folder,
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--memory-budget",
            BUDGET,
            "--allow-load-errors",
            "--report-dir",
            tmp_path / "allowed",
        ]
    )
    assert code == 0, err


def test_the_default_budget_checks_small_meshes(folder, tmp_path):
    code, _, err = _cli(["--scene", folder, "--frames", "1", "--cases", "on_axis", "--report-dir", tmp_path / "r"])
    assert code == 0, err
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    assert report["summary"]["passed"] == 2 and report["summary"]["load_errors"] == 0


@pytest.mark.parametrize(
    "value, needle",
    [
        ("0", "--memory-budget 0: expected a number of GiB > 0"),
        ("-1", "--memory-budget -1: expected a number of GiB > 0"),
        ("nan", "--memory-budget nan: expected a number of GiB > 0"),
    ],
)
def test_a_budget_that_is_not_a_size_is_one_line_exit_2(folder, tmp_path, value, needle):
    code, _, err = _cli(
        [
            "--scene",
            folder,
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--memory-budget",
            value,
            "--report-dir",
            tmp_path / "r",
        ]
    )
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "r").exists()


def test_a_budget_without_a_dataset_is_refused(tmp_path):
    code, _, err = _cli(["--scene", "cube", "--memory-budget", "1", "--report-dir", tmp_path / "r"])
    assert code == 2 and "--memory-budget without a dataset" in err


@pytest.mark.slow
@pytest.mark.parametrize(
    "value, budget_bytes",
    [
        ("1e300", int(1e300) * 2**30),  # int(float) is the float's exact integer value; 2^30 B a GiB
        ("1e-300", 0),  # 1e-300 GiB is 1.07e-291 bytes: 0 whole bytes
    ],
    ids=["1e300", "1e-300"],
)
def test_a_huge_or_tiny_budget_is_a_budget(folder, tmp_path, value, budget_bytes):
    # 1e300 GiB: int(1e300 * 2^30) was int(inf), an OverflowError (exit 3, internal error); the budget is the
    # float 1e300 times 2^30 exactly, so every mesh fits. 1e-300 GiB: every mesh is over it, the run compared nothing.
    from wirecheck.oracles.datasets.memory_budget import gib_bytes

    assert gib_bytes(float(value)) == budget_bytes
    code, _, err = _cli(
        [
            "--scene",
            folder,
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--memory-budget",
            value,
            "--report-dir",
            tmp_path / "r",
        ]
    )
    assert "Traceback" not in err and "internal error" not in err
    if value == "1e-300":  # no mesh checked: nothing compared, an input error, no report
        assert code == 2 and "none of the 2 meshes could be loaded" in err and len(err.splitlines()) == 1
        assert not (tmp_path / "r").exists()
        return
    assert code == 0, err
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    assert report["summary"]["load_errors"] == 0 and report["summary"]["passed"] == 2

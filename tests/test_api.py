"""oracles.api: the same judgement as the CLI, from a user's own pytest."""

from pathlib import Path

import pytest
from wirecheck.oracles.api import assert_projector, check_projector

DATA = Path(__file__).parent / "data"


def test_correct_external_projector_passes():
    report = assert_projector(f"{DATA / 'user_projector.py'}:project", scenes=["cube"], frames=3)
    # float64 on both sides: ~1e-11 px at most (oracles/tolerances.py derivation)
    assert report["verdict"] == "pass" and report["summary"]["max_vertex_error_px"] < 1e-9


def test_faulty_projector_raises_with_the_fault_and_the_hint():
    import importlib.util

    spec = importlib.util.spec_from_file_location("user_projector_api", DATA / "user_projector.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    with pytest.raises(AssertionError) as info:
        assert_projector(mod.project_corner, scenes=["pyramid"], frames=2, cases=["on_axis", "orthographic"])
    text = str(info.value)
    assert text.startswith(
        "Compared: level vertices (OpenCV), 2 frames per case, 2 cases (1 scene x 2 cameras)\n"
        "2 of 2 crosscheck cases failed for project_corner"
    )
    assert "pixel_offset(dx=0.5, dy=0.5)" in text and "pixel-corner convention" in text


def test_check_projector_with_pixels():
    report = check_projector(
        f"{DATA / 'user_projector.py'}:project",
        scenes=["prism"],
        frames=2,
        cases=["near_plane"],
        oracles=("opencv", "pyrender"),
    )
    assert report["cases"][0]["pixel_f1_1px"] == 1.0  # measured 1.0 everywhere (README)


def test_an_importable_callable_runs_in_the_host_and_a_lambda_in_a_fork():
    from wirecheck.core.projector.projection import project_points
    from wirecheck.oracles.candidates.isolation import api_candidate
    from wirecheck.oracles.candidates.subprocess_candidate import SubprocessCandidate

    name, cand = api_candidate(project_points)  # a module-level function: the host imports it
    assert name == "project_points" and isinstance(cand, SubprocessCandidate)
    assert cand.python_spec == "wirecheck.core.projector.projection:project_points"
    lam = lambda p, c: project_points(p, c)  # noqa: E731 - no other process can import it
    name, cand = api_candidate(lam)
    assert name == "test_an_importable_callable_runs_in_the_host_and_a_lambda_in_a_fork.<locals>.<lambda>"
    assert isinstance(cand, SubprocessCandidate) and cand.forked is lam
    cand.close()
    assert api_candidate(lam, isolate=False) == (name, lam)


def test_a_lambda_that_kills_its_process_fails_instead_of_ending_pytest():
    # In a separate interpreter: if the closure ran in-process, os._exit(0) would end this
    # pytest run with status 0 (a pass); there it ends the script before it prints.
    import subprocess
    import sys

    script = """if True:
        import os
        from wirecheck import check_projector

        def dies(points, camera):        # a closure: run in a forked copy of this process
            os._exit(0)

        report = check_projector(dies, scenes=["cube"], frames=1, cases=["on_axis"])
        print(report["verdict"], report["cases"][0]["reasons"])
    """
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "fail ['frame 1: candidate exited with status 0 during a request of 8 points']"


def test_a_closure_in_a_fork_gives_the_in_process_results():
    from wirecheck.core.projector.projection import project_points

    offset = 0.5  # a closure over a local: not importable

    def shifted(points, camera):
        return project_points(points, camera) + offset

    kw = dict(scenes=["cube"], frames=2, cases=["on_axis", "oblique_roll"])
    forked = check_projector(shifted, **kw)
    here = check_projector(shifted, isolate=False, **kw)
    assert forked["verdict"] == here["verdict"] == "fail"
    assert [c["faults"] for c in forked["cases"]] == [c["faults"] for c in here["cases"]]
    assert [c["max_vertex_error_px"] for c in forked["cases"]] == [c["max_vertex_error_px"] for c in here["cases"]]


def test_a_callable_that_kills_its_process_fails_instead_of_ending_pytest():
    from data.hostile_projector import exits  # tests/ is on sys.path (rootdir conftest)

    report = check_projector(exits, scenes=["cube"], frames=1, cases=["on_axis"])
    assert report["verdict"] == "fail"
    assert report["cases"][0]["reasons"] == ["frame 1: candidate exited with status 0 during a request of 8 points"]


def test_a_program_is_judged_through_the_api_too(tmp_path):
    import shutil
    import subprocess

    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc)")
    exe = tmp_path / "candidate"
    subprocess.run(
        [cc, "-O2", "-o", str(exe), str(Path(__file__).parent / "clients" / "candidate.c"), "-lm"], check=True
    )
    report = assert_projector(cmd=str(exe), scenes=["cube"], frames=2)
    # float64 from the same R, t, K as OpenCV (tests/test_candidate_programs.py): < 1e-9 px
    assert report["summary"]["cases"] == 7 and report["summary"]["max_vertex_error_px"] < 1e-9
    assert report["candidate"] == str(exe) and report["candidate_settings"]["command"] == [str(exe)]

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
    assert text.startswith("2 of 2 crosscheck cases failed for project_corner")
    assert "pixel_offset(dx=0.5, dy=0.5)" in text and "pixel-corner convention" in text


def test_check_projector_with_pixels():
    report = check_projector(f"{DATA / 'user_projector.py'}:project", scenes=["prism"], frames=2,
                             cases=["near_plane"], oracles=("opencv", "pyrender"))
    assert report["cases"][0]["pixel_f1_1px"] == 1.0      # measured 1.0 everywhere (README)

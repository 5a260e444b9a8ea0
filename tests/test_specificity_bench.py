"""The specificity benchmark's parts (benchmarks/specificity_dataset.py, bench_specificity.py): the seeded
dataset is the same bytes every time and holds every kind and format; the interval is Clopper-Pearson's."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_specificity  # noqa: E402
import specificity_dataset as sd  # noqa: E402


def test_the_dataset_is_seeded_and_varied(tmp_path):
    n = len(sd.KINDS) * len(sd.SUFFIXES)  # 35: the format changes every len(KINDS) meshes
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    made = sd.make_dataset(a, n)
    assert sd.make_dataset(b, n) == made
    assert all((a / m.name).read_bytes() == (b / m.name).read_bytes() for m in made)
    assert {m.kind for m in made} == set(sd.KINDS)
    assert {Path(m.name).suffix for m in made} == set(sd.SUFFIXES)
    # one in FAR_EVERY moved; the file's bounds centre is that far from the origin, to within the mesh's
    # own reach: centred, then turned, every point lies within R = (sqrt(3)/2) size of the origin, so each
    # coordinate of the bounds centre within R, its norm within sqrt(3) R = 1.5 size; and the float32
    # rounding of the coordinates in STL/GLB: 2^-24 relative, 2^-23 with the centre's own rounding
    import trimesh

    far = [m for m in made if m.far]
    assert len(far) == n // sd.FAR_EVERY  # meshes 3, 7, ..., 31
    for m in made:
        centre = trimesh.load(a / m.name, force="mesh").bounds.mean(axis=0)
        assert abs(np.linalg.norm(centre) - m.offset) <= 1.5 * m.size + 2.0**-23 * m.offset, m
        assert (m.offset == 0.0) or 1e3 <= m.offset <= 1e5


def test_clopper_pearson_by_hand():
    # 0 of n: the upper end solves (1 - p)^n = 0.025, p = 1 - 0.025^(1/n) (about 3.7/n; rule of three: 3/n)
    for n in (10, 490, 2387):
        lo, hi = bench_specificity.clopper_pearson(0, n)
        assert lo == 0.0 and hi == pytest.approx(1 - 0.025 ** (1 / n), rel=1e-9)
    # n of n: symmetric
    lo, hi = bench_specificity.clopper_pearson(10, 10)
    assert hi == 1.0 and lo == pytest.approx(0.025 ** (1 / 10), rel=1e-9)
    # 5 of 10: the tabulated exact interval 0.1871 .. 0.8129
    lo, hi = bench_specificity.clopper_pearson(5, 10)
    assert (round(lo, 4), round(hi, 4)) == (0.1871, 0.8129)


def test_tally_counts_vacuous_cases_apart_from_false_fails():
    # an oracle_precision case is "vacuous": no false fail of the candidate, but the gate's run does not pass,
    # so the benchmark must count it (hand-made rows: mesh a fails one case, b is vacuous once, c passes)
    rows = {
        "a": [("on_axis", "fail", ["x"], []), ("wide_fov", "pass", [], [])],
        "b": [("on_axis", "vacuous", ["oracle_precision: ..."], []), ("wide_fov", "vacuous", ["..."], [])],
        "c": [("on_axis", "pass", [], []), ("wide_fov", "pass", [], [])],
    }
    t = bench_specificity.tally(rows, ["a", "b", "c"])
    assert t == {
        "cases": 6,
        "cases_failed": 1,
        "cases_vacuous": 2,
        "meshes": 3,
        "meshes_failed": 1,
        "meshes_not_passed": 2,
    }
    assert bench_specificity.tally(rows, ["c"])["meshes_not_passed"] == 0

"""The compiled owner search (oracles.judge.owner_kernel) against the numpy pairing and the definition.

oracles.judge.segment_pixels defines a pixel's owner: the segment nearest its centre within the radius
(``hypot`` of the offset from the segment's nearest point, ``u = clip((ex dx + ey dy) / dd, 0, 1)``, 0
for a segment of no length), ties to the lower index. The kernel must give exactly the numpy pairing's
owners (the same floats in the same order): any difference is a bug. These frames are hostile on
purpose: several frames stacked with different edge counts (none too), NaN and infinite rows, segments
1e4-1e7 px outside the image, of no length or 1e-9 px, ends on half and quarter pixels (exact ties),
soups of long edges (the 1/8-first levels), images of one row or one column, pixels only on the first
or last row or column, pixels no segment owns.

The definition (:func:`_owners_naive`) is taken over the pairing's clipped ends (``_Segments.q0, q1``):
the pairing clips every segment to the image's box grown by ``radius + 1`` first, and the distances are
those of the clipped floats.
"""

import os
import subprocess
import sys
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pairing_reference import owners_naive
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles.candidates.core_candidate import CoreCandidate
from wirecheck.oracles.cases import cases_for
from wirecheck.oracles.judge import owner_kernel, segment_pixels
from wirecheck.oracles.judge.segment_pixels import _Pixels, _Segments
from wirecheck.oracles.references.pyrender_oracle import osmesa_available
from wirecheck.oracles.runner import CaseRunner, RunParams
from wirecheck.oracles.tolerances import Tolerances

#: the pairing's paths, forced: (LEVEL_PIXELS, CROWDED) -> radius only; within 1/2 first; within 1/8, 1/2 first
PATHS = {"radius only": (10**9, 10**9), "1/2 first": (0, 10**9), "1/8 first": (0, 0)}


def _owners_naive(q0, q1, w, h, pixels, radius=1.0):
    """``{pixel: segment}``: tests/pairing_reference.owners_naive over the clipped ends ``q0, q1`` (every pair
    measured as the module defines it, the least within ``radius``, ties to the lower index)."""
    if len(q0) == 0 or len(pixels) == 0:
        return {}
    rows, _dist = owners_naive(q0, q1, w, h, np.asarray(pixels), radius)
    return {pixel: segment for segment, pixel in rows}


def _pairings(monkeypatch, frames, pixels, w, h, every=True, large=False):
    """``(compiled, numpy, segments)``: ``_Segments.nearest``'s ``(sid, pos)`` by each pairing."""
    px = _Pixels.of_frames(pixels, w, h)
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 0)
    segs = _Segments(frames, w, h, 1.0)
    compiled = segs.nearest(px, every=every, large=large)
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 10**12)
    numpy_ = _Segments(frames, w, h, 1.0).nearest(px, every=every)
    return compiled, numpy_, segs, px


def _assert_same(compiled, numpy_):
    for got, want in zip(compiled, numpy_):
        np.testing.assert_array_equal(got, want)


def _assert_definition(segs, px, pixels, w, h, sid, pos):
    """Each frame's owners (frame-local segment positions) are the definition's over its clipped segments."""
    got = dict(zip(px.stacked[pos].tolist(), sid.tolist()))
    want = {}
    for f, flat in enumerate(pixels):
        mine = np.flatnonzero(segs.frame == f)
        naive = _owners_naive(segs.q0[mine], segs.q1[mine], w, h, np.asarray(flat, np.int64))
        want.update({p + f * w * h: int(mine[s]) for p, s in naive.items()})
    assert got == want


def _segments(rng, w, h, n):
    """``n`` hostile segments (and a few more reversed), of one of several kinds."""
    kind = int(rng.integers(0, 7))
    if kind == 0:  # a mesh: shared ends on a grid of halves or quarters (exact ties)
        step = (0.5, 0.25)[int(rng.integers(0, 2))]
        pts = np.round(rng.uniform(-2, [w + 1, h + 1], (max(2, n // 3), 2)) / step) * step
        e = rng.integers(0, len(pts), (n, 2))
        p0, p1 = pts[e[:, 0]], pts[e[:, 1]]
    elif kind == 1:  # a soup of long edges (the 1/8-first levels)
        p0, p1 = rng.uniform(-1, 2, (n, 2)) * [w, h], rng.uniform(-1, 2, (n, 2)) * [w, h]
    elif kind == 2:  # 1e4-1e7 px outside, some crossing the image
        scale = 10.0 ** rng.uniform(4, 7, (n, 1))
        p0, p1 = rng.uniform(-1, 1, (n, 2)) * scale, rng.uniform(-1, 1, (n, 2)) * scale
    elif kind == 3:  # of no length, 1e-9 or 1e-12 px, on quarter pixels
        p0 = np.round(rng.uniform(-1.5, [w + 0.5, h + 0.5], (n, 2)) * 4) / 4
        p1 = p0 + rng.choice([0.0, 1e-9, -1e-9, 1e-12], (n, 2))
    elif kind == 4:  # along a row or a column, from the image's borders and the clipping box's
        p0 = np.column_stack(
            [rng.choice([-2.0, -1.0, -0.5, 0.0, 0.5, w - 1.0, w - 0.5, w, w + 1.0], n),
             rng.choice([-2.0, -1.0, -0.5, 0.0, 0.5, h - 1.0, h - 0.5, h, h + 1.0], n)]
        )  # fmt: skip
        p1 = p0.copy()
        p1[:, int(rng.integers(0, 2))] += rng.uniform(-40, 40, n)
    elif kind == 5:  # one end inside, one ~1e6 px away
        p0, p1 = rng.uniform(-1.5, [w + 0.5, h + 0.5], (n, 2)), rng.uniform(-1e6, 1e6, (n, 2))
    else:  # short segments anywhere (near ties: shared ends off the grid)
        c = rng.uniform([-1, -1], [w, h], (n, 2))
        p0, p1 = c + rng.uniform(-3, 3, (n, 2)), c + rng.uniform(-3, 3, (n, 2))
    if n and rng.random() < 0.4:  # rows not drawn
        bad = rng.random(n) < 0.15
        p0[bad, int(rng.integers(0, 2))] = (np.nan, np.inf, -np.inf)[int(rng.integers(0, 3))]
    k = rng.integers(0, max(n, 1), min(n, 3))
    return np.concatenate([p0, p1[k]]), np.concatenate([p1, p0[k]])  # reversed repeats: ties at every pixel


def _pixels(rng, w, h):
    """Ascending flat indices: all, some, none, only the first or last row or column, the corners."""
    kind = int(rng.integers(0, 6))
    n = w * h
    if kind == 0:
        return np.arange(n)
    if kind == 1:
        return np.unique(rng.integers(0, n, int(rng.integers(1, min(n, 800) + 1))))
    if kind == 2:
        return np.zeros(0, np.int64)
    if kind == 3:
        return (np.arange(w), np.arange((h - 1) * w, n), np.arange(h) * w, np.arange(h) * w + w - 1)[
            int(rng.integers(0, 4))
        ]
    if kind == 4:
        return np.unique([0, w - 1, (h - 1) * w, n - 1])
    return np.unique(rng.integers(0, n, min(n, 40)))


SIZES = [(1, 1), (1, 9), (9, 1), (1, 40), (40, 1), (2, 2), (3, 5), (17, 9), (40, 30), (9, 33)]


# infinite ends on purpose: segment_geometry.clip_to_box's numpy warns on inf * 0 while it drops those rows
@pytest.mark.filterwarnings("ignore:invalid value encountered in multiply:RuntimeWarning")
@pytest.mark.parametrize("path", PATHS)
@pytest.mark.parametrize("seed", range(3))
def test_compiled_owners_equal_the_numpy_pairings_and_the_definitions_on_hostile_stacked_frames(
    monkeypatch, path, seed
):
    """Forty cases a seed: 1-4 frames of one size stacked, each with its own segments (0 to 120 of one hostile
    kind) and pixels; every pixel's owner by the compiled pairing equals the numpy pairing's (every drawn pixel,
    row by row; and a third of them, as _known_owners asks) and the definition's."""
    assert owner_kernel.available(), owner_kernel.why_not()
    monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", PATHS[path][0])
    monkeypatch.setattr(segment_pixels, "CROWDED", PATHS[path][1])
    rng = np.random.default_rng(seed)
    owned = ties = 0
    for _ in range(40):
        w, h = SIZES[int(rng.integers(0, len(SIZES)))]
        frames, pixels = [], []
        for _f in range(int(rng.integers(1, 5))):
            frames.append(_segments(rng, w, h, int(rng.choice([0, 1, 4, 30, 120]))))
            pixels.append(_pixels(rng, w, h))
        compiled, numpy_, segs, px = _pairings(monkeypatch, frames, pixels, w, h)
        _assert_same(compiled, numpy_)
        _assert_definition(segs, px, pixels, w, h, *compiled)
        some = np.flatnonzero(rng.random(len(px)) < 1 / 3)
        monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 10**12)
        want = _Segments(frames, w, h, 1.0).nearest(px.subset(some))
        _assert_same(_Segments(frames, w, h, 1.0).nearest(px.subset(some), large=True), want)
        owned += len(compiled[0])
        ties += int(len(segs) > 0)
    assert owned > 500 and ties > 20  # the cases hold owned pixels to compare


@pytest.mark.parametrize("w, h", [(1, 1), (1, 37), (37, 1), (3000, 2000)], ids=["1x1", "1xN", "Nx1", "3000x2000"])
def test_compiled_owners_on_one_pixel_one_row_one_column_and_a_large_image(monkeypatch, w, h):
    """Segments through, along and just outside a degenerate image (or a large one's first and last rows and
    columns), some 1e7 px long, of no length, NaN; the middle frame of three has no segment: the owners are the
    numpy pairing's and the definition's."""
    x, y = w - 1.0, h - 1.0
    p0 = np.array([[0, 0], [x, 0], [-0.5, y / 2], [0, -1e7], [x + 1, y], [x / 2, y / 2], [np.nan, 0], [x + 0.5, -0.5]])
    p1 = np.array(
        [[x, y], [0, y], [x + 0.5, y / 2], [0, 1e7], [x + 1, -1.0], [x / 2, y / 2], [1, 1], [x + 0.5, y + 0.5]]
    )
    border = np.unique(
        np.concatenate([np.arange(w), np.arange(h) * w, np.arange(h) * w + w - 1, np.arange((h - 1) * w, w * h)])
    )
    frames = [(p0, p1), (p0[:0], p1[:0]), (p1[::-1], p0[::-1])]
    pixels = [border, border, border]
    for levels in PATHS.values():
        monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", levels[0])
        monkeypatch.setattr(segment_pixels, "CROWDED", levels[1])
        compiled, numpy_, segs, px = _pairings(monkeypatch, frames, pixels, w, h)
        _assert_same(compiled, numpy_)
        _assert_definition(segs, px, pixels, w, h, *compiled)
        assert len(compiled[0]) > 0
        assert not np.isin(px.at(compiled[1])[0], [1]).any()  # no pixel of the empty frame is owned


def test_pixels_no_segment_owns_have_no_owner_by_either_pairing(monkeypatch):
    """Every pixel more than 1 px from every segment (segments on a grid of columns 3 px apart, the pixels on
    the columns between, 1.5 px off): no owner, by either pairing; then one segment moved onto them owns them."""
    w, h = 31, 20
    cols = np.arange(0.0, w, 3.0)
    p0, p1 = np.column_stack([cols, np.zeros_like(cols)]), np.column_stack([cols, np.full_like(cols, h - 1.0)])
    off = np.array([[1.5, 0.0]])
    p0, p1 = p0 + off, p1 + off  # columns 1.5, 4.5, ...: 1.5 px from the columns 0, 3, 6, ...
    pixels = [np.flatnonzero((np.arange(w * h) % w) % 3 == 0)]
    compiled, numpy_, _, _ = _pairings(monkeypatch, [(p0, p1)], pixels, w, h)
    assert len(compiled[0]) == len(numpy_[0]) == 0
    moved = (np.vstack([p0, [[3.0, 0.0]]]), np.vstack([p1, [[3.0, h - 1.0]]]))  # column 3, exactly
    compiled, numpy_, _, _ = _pairings(monkeypatch, [moved], pixels, w, h)
    _assert_same(compiled, numpy_)
    assert compiled[0].tolist() == [len(p0)] * h  # column 3's pixels, each 0 px from the new segment


def test_a_pair_on_the_radius_by_its_distance_is_owned_though_its_square_is_over(monkeypatch):
    """A segment of no length at offsets (ex, ey) from a pixel centre whose ``hypot`` is exactly 1 (the radius)
    while ``ex^2 + ey^2`` rounds to 1 + 2^-52: within the radius by the definition (the distance), so the pixel
    is owned, by both pairings; a pairing deciding by the square alone would leave it unowned. (The offsets
    were found by sampling points on the unit circle around (10, 10); both facts are checked here.)"""
    w, h = 20, 20
    q = np.array([[10.972821318188133, 10.23155708341293]])
    ex, ey = 10.0 - q[0, 0], 10.0 - q[0, 1]
    assert ex * ex + ey * ey > 1.0 and np.hypot(ex, ey) == 1.0
    pixels = [np.arange(w * h)]
    compiled, numpy_, _, px = _pairings(monkeypatch, [(q, q.copy())], pixels, w, h)
    _assert_same(compiled, numpy_)
    owned = set(px.stacked[compiled[1]].tolist())
    assert 10 * w + 10 in owned and owned == set(_owners_naive(q, q, w, h, pixels[0]))


def test_a_later_segment_nearer_by_its_distance_wins_though_its_square_is_not_less(monkeypatch):
    """Two segments of no length 0.4009523432057133 px from pixel (10, 10): the second (higher index) nearer by
    ``hypot`` by one ulp while its ``ex^2 + ey^2`` is one ulp larger. The definition (the distance) gives the
    pixel to the second, by both pairings; a pairing dropping a pair whose square is not less than the best's
    would keep the first. (Found by sampling pairs of points at one distance; both facts are checked here.)"""
    w, h = 20, 20
    farther, nearer = (10.398939790423073, 10.040122626276785), (10.31452456665754, 10.248670622492966)
    q = np.array([farther, nearer])
    (ex0, ey0), (ex1, ey1) = 10.0 - q[0], 10.0 - q[1]
    assert np.hypot(ex1, ey1) < np.hypot(ex0, ey0) and ex1 * ex1 + ey1 * ey1 > ex0 * ex0 + ey0 * ey0
    pixels = [np.arange(w * h)]
    compiled, numpy_, _, px = _pairings(monkeypatch, [(q, q.copy())], pixels, w, h)
    _assert_same(compiled, numpy_)
    owner = dict(zip(px.stacked[compiled[1]].tolist(), compiled[0].tolist()))
    assert owner[10 * w + 10] == 1 == _owners_naive(q, q, w, h, pixels[0])[10 * w + 10]


quarter = st.integers(-12, 44).map(lambda q: q / 4)  # ends on quarter pixels around a 9 x 7 image: exact ties
far = st.sampled_from([-1e7, -1e4, 1e4, 1e7])


@settings(max_examples=300, deadline=None)
@given(
    ends=st.lists(
        st.tuples(st.one_of(quarter, far), quarter, quarter, st.one_of(quarter, far)), min_size=1, max_size=12
    ),
    repeat=st.booleans(),
)
def test_compiled_owners_of_quarter_pixel_segments_are_the_definitions(ends, repeat):
    """Segments with ends on quarter pixels (some an end 1e4-1e7 px away), repeated and reversed: every pixel of
    a 9 x 7 image has the definition's owner by the compiled pairing, within 1/2 first and within 1 only."""
    w, h = 9, 7
    a = np.array(ends, np.float64)
    p0, p1 = a[:, :2], a[:, 2:]
    if repeat:
        p0, p1 = np.concatenate([p0, p1]), np.concatenate([p1, p0])
    pixels = np.arange(w * h)
    for radii in ((1.0,), (0.5, 1.0)):
        segs = _Segments([(p0, p1)], w, h, 1.0)
        px = _Pixels.of_frames([pixels], w, h)
        owner = owner_kernel.owners(
            px.stacked, w, h, 1, segs.q0, segs.q1, segs._cols, None, radii,
            segment_pixels.GROW_PX, segment_pixels.D2_SLACK, segment_pixels.D2_TINY,
        )  # fmt: skip
        got = {int(p): int(s) for p, s in zip(pixels, owner) if s >= 0}
        assert got == _owners_naive(segs.q0, segs.q1, w, h, pixels)


def test_without_numba_the_numpy_pairing_gives_the_owners(monkeypatch):
    """The kernel unavailable (numba not importable, or told not to compile): nearest takes the numpy pairing,
    for every drawn pixel and for ``large``, with the same owners."""
    rng = np.random.default_rng(5)
    w, h = 40, 30
    frames = [_segments(rng, w, h, 200) for _ in range(2)]
    pixels = [np.arange(w * h)] * 2
    compiled, numpy_, _, px = _pairings(monkeypatch, frames, pixels, w, h)
    monkeypatch.setattr(owner_kernel, "_KERNEL", None)
    monkeypatch.setattr(owner_kernel, "_STATE", {"tried": True, "why": "numba not importable (a test)"})
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 0)
    assert not owner_kernel.available()
    _assert_same(_Segments(frames, w, h, 1.0).nearest(px, every=True), numpy_)
    _assert_same(_Segments(frames, w, h, 1.0).nearest(px, large=True), numpy_)
    _assert_same(compiled, numpy_)


def test_numba_disable_jit_turns_the_kernel_off_quietly():
    """``NUMBA_DISABLE_JIT=1`` (the loop would run as Python): not available, saying why, nothing on stderr."""
    code = "from wirecheck.oracles.judge import owner_kernel as k\nprint(k.available(), k.warm(), k.why_not())\n"
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False False NUMBA_DISABLE_JIT is set"
    assert done.stderr == ""


def _dust(path, triangles: int = 600, size: float = 0.012):
    """A mesh of ``triangles`` tiny triangles scattered over a cube (1,800 short edges: a few pixels each on the
    cases' 640 x 480 images, so that its frames are dense: more than one edge per 8 drawn pixels)."""
    import trimesh

    rng = np.random.default_rng(0)
    centre = rng.uniform(-1, 1, (triangles, 3))
    v = (centre[:, None, :] + rng.uniform(-size, size, (triangles, 3, 3))).reshape(-1, 3)
    trimesh.Trimesh(v, np.arange(3 * triangles).reshape(-1, 3), process=False).export(path)
    return str(path)


@pytest.mark.skipif(not osmesa_available()[0], reason="no OSMesa")
@pytest.mark.parametrize("scene, frames, used", [("dust", 10, True), ("cube", 24, False)])
def test_the_kernel_made_ready_inside_a_case_is_one_time_set_up_not_the_frames_time(
    tmp_path, monkeypatch, scene, frames, used
):
    """A scene of 1,800 short edges over 10 frames: its line scores pair ~10,800 drawn pixels of a dense batch
    with the kernel, made ready on that first use (numba's import and its compile or cache load, here made
    0.4 s longer): that time is the case's one-time set-up (``one_time_setup_ms``), not its pixel stage's
    (~5 ms a frame). The bundled cube over 24 frames (288 segments: never a dense batch of 8,192 pixels)
    neither makes it ready nor uses it."""
    delay = 0.4
    events = []
    make, owners = owner_kernel._make, owner_kernel.owners

    def slow_make():
        time.sleep(delay)
        events.append("ready")
        make()

    monkeypatch.setattr(owner_kernel, "_KERNEL", None)
    monkeypatch.setattr(owner_kernel, "_STATE", {"tried": False, "why": None})
    monkeypatch.setattr(owner_kernel, "_make", slow_make)
    monkeypatch.setattr(owner_kernel, "owners", lambda *a: events.append("owners") or owners(*a))
    s = load_scene(_dust(tmp_path / "dust.ply") if scene == "dust" else scene)
    motion = Motion(turns=(1.0, 1.0, 0.0))
    case = next(c for c in cases_for(s, motion) if c.name == "on_axis")
    params = RunParams(frames, 1, "pixels", motion, Tolerances(), CoreCandidate())
    runner = CaseRunner()
    try:
        result = runner.run(s, case, params)
    finally:
        runner.close()
    assert ("owners" in events) == used  # the case did use the kernel (else the test shows nothing)
    assert events[:1] == (["ready"] if used else [])
    t = result.timing
    if used:
        assert t["one_time_setup_ms"] >= 1e3 * delay
        # the stage's frames hold none of it: 10 frames of ~5 ms, far under the 400 ms made ready meanwhile
        assert t["pixel_stage_ms_per_frame"] * frames < 1e3 * delay
    else:
        assert "one_time_setup_ms" not in t

"""core.projector.raster._line_pixels (the "exact" rule, two exit tests per segment) against the
candidate-by-candidate reference of tests/raster_reference.py, which tests every pixel
the rule could draw.

The two must return the same arrays (same pixels, same order) on every input: the
reference's float decisions are the rule's, and core claims to make the same ones
while skipping the tests whose outcome the rule fixes. Inputs are mixed on purpose:
ends on pixel centres, pixel edges, quarter and 1/256 grids (exact ties of the
rounding and of the exit test), zero-length, horizontal, vertical, diagonal and
steep segments, negative coordinates and segments partly or wholly off the image,
and ends far enough out (> 2^23 grid units = 32,768 px) to take the int64 path.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_array_equal
from raster_reference import candidates_reference
from wirecheck.core.projector import raster

W, H = 40, 30

# one coordinate: anywhere around the image, or on a grid that makes ties
_any = st.floats(-60.0, 100.0, allow_nan=False, allow_infinity=False)
_grid = st.builds(lambda k, q: k / q, st.integers(-240, 400), st.sampled_from([1, 2, 4, 256]))
coord = st.one_of(_any, _grid)
# the second end: anywhere, or the first end moved along a chosen direction
_direction = st.sampled_from([(0, 0), (1, 0), (0, 1), (1, 1), (1, -1), (1, 3), (3, 1), (-1, -7), (2, 1)])


@st.composite
def segment(draw):
    p0 = (draw(coord), draw(coord))
    if draw(st.booleans()):
        return p0, (draw(coord), draw(coord))
    dx, dy = draw(_direction)
    k = draw(st.one_of(st.integers(-12, 12), st.floats(-12.0, 12.0)))
    return p0, (p0[0] + k * dx, p0[1] + k * dy)


def both(p0, p1, w, h):
    """(core, reference) on snapped ends, as line_pixels calls them."""
    p0 = raster.snap_subpixel(np.asarray(p0, float).reshape(-1, 2))
    p1 = raster.snap_subpixel(np.asarray(p1, float).reshape(-1, 2))
    return raster._line_pixels(p0, p1, w, h), candidates_reference(p0, p1, w, h)


def assert_same(got, want):
    assert_array_equal(got[0], want[0])
    assert_array_equal(got[1], want[1])
    assert got[0].dtype == got[1].dtype == np.intp


@settings(max_examples=500, deadline=None)
@given(seg=segment())
def test_one_segment_equals_reference(seg):
    assert_same(*both(*seg, W, H))


@settings(max_examples=150, deadline=None)
@given(segs=st.lists(segment(), min_size=1, max_size=40))
def test_a_batch_equals_reference_and_the_single_segment_calls(segs):
    p0 = np.array([s[0] for s in segs], float)
    p1 = np.array([s[1] for s in segs], float)
    got, want = both(p0, p1, W, H)
    assert_same(got, want)
    # segment after segment: the batch is the concatenation of one call per segment
    per = [raster.line_pixels(p0[m : m + 1], p1[m : m + 1], W, H) for m in range(len(p0))]
    assert_same(
        raster.line_pixels(p0, p1, W, H), (np.concatenate([p[0] for p in per]), np.concatenate([p[1] for p in per]))
    )


# Far ends: 2^23 grid units is 32,768 px; beyond it core computes in int64. The offset
# is a whole number of pixels, and the image is large enough to hold the pixels.
FAR = 40_000.0


@settings(max_examples=200, deadline=None)
@given(seg=segment(), ox=st.sampled_from([0.0, FAR, -FAR]), oy=st.sampled_from([0.0, FAR, -FAR]))
def test_far_ends_int64_path_equals_reference(seg, ox, oy):
    (x0, y0), (x1, y1) = seg
    p0, p1 = (x0 + ox, y0 + oy), (x1 + ox, y1 + oy)
    assert_same(*both(p0, p1, int(FAR) + 200, int(FAR) + 200))


def test_both_arithmetic_paths_are_taken():
    # the float64 path up to 2^23 grid units, int64 beyond: one segment just inside and
    # one just outside, each against the reference (a path never taken tests nothing)
    limit_px = raster._FLOAT_GRID_LIMIT / raster.SUBPIXEL
    seen = []
    real = raster._floor_div_int

    def spy(a, b):
        seen.append(a.dtype)
        return real(a, b)

    for x in (limit_px - 7, limit_px + 1):
        seen.clear()
        raster._floor_div_int = spy
        try:
            got, want = both((x, 3.0), (x - 5, 7.0), int(limit_px) + 10, 20)
        finally:
            raster._floor_div_int = real
        assert_same(got, want)
        # between pixel centres: max(|di|, |dj|) = 5 pixels, the start's and not the end's
        assert len(got[0]) == 5 and (got[0][-1], got[1][-1]) == (3, x)
        assert bool(seen) == (x > limit_px)


@pytest.mark.parametrize("chunk", [1, 3, 7])
def test_chunked_batches_equal_one_batch(monkeypatch, chunk):
    rng = np.random.default_rng(5)
    p0 = rng.uniform(-5, 45, size=(50, 2))
    p1 = p0 + rng.uniform(-6, 6, size=(50, 2))
    p1[::9] = p0[::9]  # zero length
    whole = raster.line_pixels(p0, p1, W, H)
    monkeypatch.setattr(raster, "CHUNK_SEGMENTS", chunk)
    assert_same(raster.line_pixels(p0, p1, W, H), whole)
    assert len(whole[0]) > 50  # not an empty comparison


def test_icosphere_frame_segments_equal_reference():
    # the benchmark's case: 122,880 short segments (~1.2 px) of a projected icosphere
    trimesh = pytest.importorskip("trimesh")
    from wirecheck.core.camera import camera_z
    from wirecheck.core.projector.pipeline import render_frame
    from wirecheck.core.transforms import Motion

    ico = trimesh.creation.icosphere(subdivisions=6)
    e = np.asarray(ico.edges_unique)
    cam = camera_z(4.0, fov_y_deg=70, width=640, height=480)
    f = render_frame(np.asarray(ico.vertices), e, cam, Motion().frame_matrix(7, 180))
    p0, p1 = f.p_px[e[:, 0]], f.p_px[e[:, 1]]
    got = raster.line_pixels(p0, p1, 640, 480)
    want = candidates_reference(raster.snap_subpixel(p0), raster.snap_subpixel(p1), 640, 480)
    assert_same(got, want)
    assert len(got[0]) > len(e)

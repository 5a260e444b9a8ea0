"""core.projector.clipping (cases 1-5 of its docstring) and clip safety of the whole frame pipeline.

Unless stated otherwise the camera is camera_z(10, fov 90, 640x480, near 1):
p_cam = (x, y, 10 - z_world) exactly, f = 240 / tan(45 deg) = 240 (1 + 1.1e-16),
(cx, cy) = (319.5, 239.5). ``world()`` turns camera-space points into world points.
"""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from wirecheck.core.camera import camera_z
from wirecheck.core.projector.clipping import apply_clip, clip_segments, frustum_planes
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import cam_to_px
from wirecheck.core.projector.raster import line_pixels
from wirecheck.core.scene.files import load_scene

EPS = np.finfo(np.float64).eps  # 2.2e-16
D = 10.0
W, H = 640, 480
F = 240.0
CX, CY = 319.5, 239.5


def cam(**kw):
    kw = {"fov_y_deg": 90.0, "width": W, "height": H, "near": 1.0, "far": 100.0, **kw}
    return camera_z(D, **kw)


def world(p_cam):
    p = np.asarray(p_cam, dtype=float).reshape(-1, 3)
    return np.column_stack([p[:, 0], p[:, 1], D - p[:, 2]])


def render(p_cam, edges, camera=None, clip_mode="clip"):
    camera = camera or cam()
    with np.errstate(all="raise"):  # any overflow / invalid op outside clip_segments raises
        return render_frame(world(p_cam), np.asarray(edges, dtype=np.intp).reshape(-1, 2), camera, np.eye(4), clip_mode)


def drawn(image):
    return {(int(r), int(c)) for r, c in zip(*np.nonzero(image))}


def raster_image(segments_px, w=W, h=H):
    """Expected image: the HAND-DERIVED pixel-space ends of each (clipped) segment,
    rasterised with core.projector.raster (tested on its own in test_raster.py). This isolates
    what these tests check, the clipping, from the raster rule's end-pixel choices."""
    img = np.zeros((h, w), np.uint8)
    for p0, p1 in segments_px:
        rr, cc = line_pixels(np.array([p0], float), np.array([p1], float), w, h)
        img[rr, cc] = 255
    return img


# ---- the numbered cases, one plane z >= 1 ([0, 0, 1, -1]) -----------------------------

Z_GE_1 = np.array([[0.0, 0.0, 1.0, -1.0]])


def clip1(p0, p1, planes=Z_GE_1):
    kept, t0, t1 = clip_segments(np.array([[p0, p1]], dtype=float), planes)
    return bool(kept[0]), float(t0[0]), float(t1[0])


def test_case1_both_inside_kept_whole():
    assert clip1([0, 0, 2], [0, 0, 3]) == (True, 0.0, 1.0)


def test_case2_both_outside_dropped():
    assert clip1([0, 0, 0], [0, 0, -1])[0] is False


def test_case3_entering():
    # d0 = -1, d1 = 1: t_enter = d0/(d0-d1) = 0.5 (exact in binary)
    assert clip1([0, 0, 0], [0, 0, 2]) == (True, 0.5, 1.0)


def test_case4_leaving():
    # d0 = 2, d1 = -1: t_exit = 2/3
    kept, t0, t1 = clip1([0, 0, 3], [0, 0, 0])
    assert (kept, t0) == (True, 0.0)
    assert_allclose(t1, 2 / 3, rtol=EPS)


def test_case5_disjoint_pieces_dropped():
    # planes x >= 1 and y >= 1. Segment (0,1.5) -> (1.5,0) passes beside the corner (1,1):
    # x: d0 = -1, d1 = 0.5 -> enters at t = 1/1.5 = 2/3; y: d0 = .5, d1 = -1 -> leaves
    # at t = 0.5/1.5 = 1/3. t_enter > t_exit: dropped.
    planes = np.array([[1.0, 0, 0, -1.0], [0, 1.0, 0, -1.0]])
    assert clip1([0, 1.5, 0], [1.5, 0, 0], planes)[0] is False
    # (0,2.5) -> (2.5,0) crosses the quadrant: enters at 1/2.5 = 0.4, leaves at 1.5/2.5 = 0.6
    kept, t0, t1 = clip1([0, 2.5, 0], [2.5, 0, 0], planes)
    assert kept
    assert_allclose([t0, t1], [0.4, 0.6], rtol=EPS)


def test_point_on_plane_is_inside():
    assert clip1([0, 0, 1], [5, 0, 1]) == (True, 0.0, 1.0)  # lying on the plane: drawn
    assert clip1([0, 0, 1], [0, 0, 2]) == (True, 0.0, 1.0)  # one end on it


def test_nan_segment_dropped():
    assert clip1([0, 0, math.nan], [0, 0, 2])[0] is False


def test_vectorised_cases_together():
    segs = np.array(
        [[[0, 0, 2], [0, 0, 3]], [[0, 0, 0], [0, 0, -1]], [[0, 0, 0], [0, 0, 2]], [[0, 0, 2], [0, 0, 0]]], dtype=float
    )
    kept, t0, t1 = clip_segments(segs, Z_GE_1)
    assert_array_equal(kept, [True, False, True, True])
    out = apply_clip(segs, kept, t0, t1)
    assert_array_equal(out, [[[0, 0, 2], [0, 0, 3]], [[0, 0, 1], [0, 0, 2]], [[0, 0, 2], [0, 0, 1]]])


# ---- frustum planes ----------------------------------------------------------------


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
@pytest.mark.parametrize("guard", [0.0, 3.0])
def test_side_planes_pass_through_image_border(projection, guard):
    c = cam(projection=projection, ortho_height=4.0)
    planes = frustum_planes(c, guard_px=guard)
    assert_array_equal(planes[:2], [[0, 0, 1, -1.0], [0, 0, -1, 100.0]])
    z = 7.0
    s = F / z if projection == "perspective" else H / 4.0  # pixels per camera unit at depth z
    g = guard
    # border points (x_px, y_px) -> camera (x, y, z) with x = (x_px - cx)/s, y = (cy - y_px)/s
    border = {2: (-0.5 - g, CY), 3: (W - 0.5 + g, CY), 4: (CX, -0.5 - g), 5: (CX, H - 0.5 + g)}
    for k, (xp, yp) in border.items():
        p = np.array([(xp - CX) / s, (CY - yp) / s, z, 1.0])
        # the plane coefficients are ~f ~ 240 times coordinates ~ 50 / 320:
        # ~4 roundings of values <= 240 * 3 * 320/240: 4 EPS * 1e3
        assert abs(planes[k] @ p) <= 4 * EPS * 1e3 * max(1.0, s), (k, planes[k] @ p)
        # and 1 pixel inside is strictly inside
        q = np.array([(xp - CX - np.sign(xp - CX)) / s, (CY - yp + np.sign(yp - CY)) / s, z, 1.0])
        assert planes[k] @ q > 0


# ---- near plane --------------------------------------------------------------------


def test_near_crossing_edge_clipped_exactly_at_near():
    c = cam()
    seg = np.array([[[0.11, 0.07, 3.0], [0.11, 0.07, -1.0]]])
    kept, t0, t1 = clip_segments(seg, frustum_planes(c))
    # near plane: d0 = 3 - 1 = 2, d1 = -1 - 1 = -2 -> t_exit = 0.5; sides do not cut
    # (x/z <= 0.11 << 4/3)
    assert kept[0] and t0[0] == 0.0
    assert_allclose(t1[0], 0.5, rtol=0, atol=2 * EPS)
    end = apply_clip(seg, kept, t0, t1)[0, 1]
    # z = 3 + 0.5 * (-4) = 1 = near (exact if t is)
    assert_allclose(end, [0.11, 0.07, 1.0], rtol=0, atol=4 * EPS * 3)
    px = cam_to_px(end[None], c)[0]
    # near-plane point (0.11, 0.07, 1): (319.5 + 240*0.11, 239.5 - 240*0.07) = (345.9, 222.7)
    assert_allclose(px, [345.9, 222.7], rtol=0, atol=8 * EPS * 400)


EDGE_CROSSING_NEAR = [[0.11, 0.07, 3.0], [0.11, 0.07, -1.0]]
EDGE_ON_NEAR = [[-0.301, -0.07, 1.0], [0.401, -0.07, 1.0]]


def test_near_crossing_edge_drawn_up_to_near_plane():
    fr = render(EDGE_CROSSING_NEAR, [[0, 1]])
    # ends: (0.11, 0.07, 3) -> (319.5 + 240*0.11/3, 239.5 - 240*0.07/3) = (328.3, 233.9);
    # clipped end at the near plane (0.11, 0.07, 1) -> (345.9, 222.7).
    assert_array_equal(fr.image, raster_image([((328.3, 233.9), (345.9, 222.7))]))
    got = drawn(fr.image)
    # rule-independent: pixels only between the two end pixels, and the segment is
    # drawn to within a pixel of the near-plane point (col 346 / row 223)
    assert {c for _, c in got} <= set(range(328, 347)) and {r for r, _ in got} <= set(range(223, 235))
    assert max(c for _, c in got) >= 345 and min(r for r, _ in got) <= 224
    assert fr.visible_vertices == 1 and fr.clipped_vertices == 1 and fr.clipped_edges == 1
    assert np.isnan(fr.p_px[1]).all() and np.isfinite(fr.p_px[0]).all()


def test_point_exactly_on_near_plane_is_visible_and_edge_on_near_plane_is_drawn():
    fr = render(EDGE_ON_NEAR, [[0, 1]])
    assert_array_equal(fr.depth, [1.0, 1.0])  # 10 - 9 = 1 exactly
    assert fr.visible.all()
    # x: 319.5 - 240*0.301 = 247.26 ... 319.5 + 240*0.401 = 415.74; y: 239.5 + 16.8 = 256.3
    assert_allclose(fr.p_px, [[247.26, 256.3], [415.74, 256.3]], rtol=0, atol=8 * EPS * 416)
    assert_array_equal(fr.image, raster_image([((247.26, 256.3), (415.74, 256.3))]))
    # the whole run between the end pixels is drawn, on row 256 only
    assert fr.image[256, 248:416].all() and np.count_nonzero(fr.image) == np.count_nonzero(fr.image[256])
    assert not fr.image[256, :247].any() and not fr.image[256, 417:].any()


def test_edge_on_near_plane_running_off_image_is_drawn_to_border():
    # (-5, -0.07, 1) projects to x = 319.5 - 1200: the left side plane cuts it at
    # x = -0.5 while the near plane (d = 0 at both ends) keeps it.
    fr = render([[-5.0, -0.07, 1.0], [0.401, -0.07, 1.0]], [[0, 1]])
    assert_array_equal(fr.image, raster_image([((-0.5, 256.3), (415.74, 256.3))]))
    assert fr.image[256, 0:416].all()


def test_clip_modes_endpoint_drops_edge_clip_keeps_part():
    p = EDGE_CROSSING_NEAR + EDGE_ON_NEAR
    edges = [[0, 1], [2, 3]]
    clip = render(p, edges, clip_mode="clip")
    endpoint = render(p, edges, clip_mode="endpoint")
    crossing = raster_image([((328.3, 233.9), (345.9, 222.7))])  # see test above
    on_near = raster_image([((247.26, 256.3), (415.74, 256.3))])
    assert np.count_nonzero(crossing) >= 17  # the run 328..346 less at most both ends
    # clip: both edges (disjoint rows: 223..234 and 256); endpoint: only the one with both ends visible
    assert np.count_nonzero(clip.image) == np.count_nonzero(crossing) + np.count_nonzero(on_near)
    assert np.count_nonzero(endpoint.image) == np.count_nonzero(on_near)
    assert_array_equal(clip.image, np.maximum(crossing, on_near))
    assert_array_equal(endpoint.image, on_near)
    for fr in (clip, endpoint):
        assert (fr.visible_vertices, fr.clipped_vertices, fr.clipped_edges) == (3, 1, 1)


# ---- behind the camera ---------------------------------------------------------------


def test_camera_inside_cube_no_inf_nan_pixels_only_expected_ones():
    """camera_z(0.5), fov 70: the z = -1 face is 1.5 in front, the z = +1 face 0.5 behind."""
    c = camera_z(0.5, fov_y_deg=70.0, width=W, height=H, near=0.1, far=100.0)
    cube = load_scene("cube")
    with np.errstate(all="raise"):
        fr = render_frame(cube.vertices, cube.edges, c, np.eye(4))
    assert_array_equal(fr.depth, 0.5 - cube.vertices[:, 2])
    assert fr.visible_vertices == 4 and fr.clipped_vertices == 4
    # 4 edges of the z=+1 face (both ends behind) + 4 edges along z (crossing near)
    assert fr.clipped_edges == 8
    assert_array_equal(np.isfinite(fr.p_px).all(axis=1), fr.visible)
    assert_array_equal(np.isnan(fr.p_px).all(axis=1), ~fr.visible)
    # f = 240/tan(35) = 342.7555; r = f/1.5 = 228.5037: back-face corners at
    # (319.5 +- r, 239.5 +- r) ~ (90.996 | 548.004, 10.996 | 468.004).
    r = (240.0 / math.tan(math.radians(35.0))) / 1.5
    L, R, T, B = CX - r, CX + r, CY - r, CY + r
    # The edges along z run from each corner away from the centre at 45 degrees in
    # pixels (|x_cam| = |y_cam|, so x_px - cx = +-(y_px - cy)) and are cut by rows
    # y = -0.5 / 479.5 (H < W), at x = cx +- (cy + 0.5) = 559.5 / 79.5.
    segs = [
        ((L, T), (R, T)),
        ((R, T), (R, B)),
        ((R, B), (L, B)),
        ((L, B), (L, T)),
        ((R, T), (559.5, -0.5)),
        ((L, T), (79.5, -0.5)),
        ((R, B), (559.5, 479.5)),
        ((L, B), (79.5, 479.5)),
    ]
    assert_array_equal(fr.image, raster_image(segs))
    # rule-independent: the square's sides are drawn between the corners' pixels
    assert fr.image[11, 92:548].all() and fr.image[468, 92:548].all()
    assert fr.image[12:468, 91].all() and fr.image[12:468, 548].all()


# ---- huge coordinates and image sides --------------------------------------------------

HUGE = [
    # (p0_cam, p1_cam, which border the clipped p1 (and p0) end lands on)
    ([0.0, 0.3, 5.0], [1e12, 0.3, 5.0], ("right",)),
    ([-1e12, -1e12, 5.0], [1e12, 1e12, 5.0], ("bottom", "top")),
    ([0.0, 0.3, 5.0], [0.0, 1e12, 5.0], ("top",)),
    ([-1e12, 0.3, 5.0], [0.0, 0.3, 5.0], ("left", None)),
    # through depth: x/z -> 20 leaves the right side (x/z = 4/3) long before far
    ([0.2, 0.1, 5.0], [2e12, -1e12, 1e11], ("right",)),
]


def border_residual(px, side):
    return {"left": px[0] + 0.5, "right": px[0] - (W - 0.5), "top": px[1] + 0.5, "bottom": px[1] - (H - 0.5)}[side]


@pytest.mark.parametrize("p0,p1,sides", HUGE)
def test_huge_segment_clipped_end_on_image_border(p0, p1, sides):
    c = cam()
    seg = np.array([[p0, p1]], dtype=float)
    kept, t0, t1 = clip_segments(seg, frustum_planes(c))
    assert kept[0]
    ends_px = cam_to_px(apply_clip(seg, kept, t0, t1)[0], c)
    assert np.all(np.isfinite(ends_px))
    # p0 + t (p1 - p0) loses ~ 4 EPS * max|p| = 8.9e-4 absolute in camera space when
    # |p| ~ 1e12 (cancellation), magnified by f/z <= 240/5 = 48 pixels per unit:
    # 4 EPS * 1e12 * 48 ~ 0.043 px.
    tol = 4 * EPS * 1e12 * 48
    assert np.all(ends_px[:, 0] >= -0.5 - tol) and np.all(ends_px[:, 0] <= W - 0.5 + tol)
    assert np.all(ends_px[:, 1] >= -0.5 - tol) and np.all(ends_px[:, 1] <= H - 0.5 + tol)
    if len(sides) == 2:
        first, last = sides
        if last is not None:
            assert abs(border_residual(ends_px[1], last)) <= tol
        assert abs(border_residual(ends_px[0], first)) <= tol
    else:
        assert abs(border_residual(ends_px[1], sides[0])) <= tol


def test_huge_segment_renders_one_row_to_right_border():
    # (0, 0.3, 5) -> (1e12, 0.3, 5): y = 239.5 - 240*0.3/5 = 225.1 (row 225);
    # x from 319.5 to the border 639.5.
    fr = render([[0.0, 0.3, 5.0], [1e12, 0.3, 5.0]], [[0, 1]])
    assert_array_equal(fr.image, raster_image([((319.5, 225.1), (639.5, 225.1))]))
    assert fr.image[225, 320:639].all() and np.count_nonzero(fr.image) == np.count_nonzero(fr.image[225])
    assert fr.visible.all()  # far off-image but within near..far
    assert_allclose(fr.p_px[1, 0], CX + F * 1e12 / 5, rtol=4 * EPS)


def test_huge_diagonal_renders_within_bounds():
    # (-1e12,-1e12,5) -> (1e12,1e12,5): through the principal point at 45 deg in pixels
    # (x_px - cx = -(y_px - cy)), cut at (79.5, 479.5) and (559.5, -0.5).
    fr = render([[-1e12, -1e12, 5.0], [1e12, 1e12, 5.0]], [[0, 1]])
    assert_array_equal(fr.image, raster_image([((79.5, 479.5), (559.5, -0.5))]))
    got = drawn(fr.image)
    # rule-independent: every drawn pixel's centre is within half a pixel (diagonal
    # distance |r + c - 559| / sqrt 2 <= 0.5) of the line, and every row but the ends is hit
    assert all(abs((r + c) - 559) <= 1 for r, c in got)
    assert {r for r, _ in got} >= set(range(1, H - 1))


def test_segment_entirely_outside_one_side_draws_nothing():
    fr = render([[1e12, 0.3, 5.0], [1e12, -0.3, 6.0], [0.0, 0.0, -5.0], [0.1, 0.1, -1e12]], [[0, 1], [2, 3]])
    assert not fr.image.any()
    assert fr.visible_vertices == 2  # the first two are in [near, far], just off-image


def test_far_plane_clips():
    # (0.1, 0.1, 2) -> (0.1, 0.1, 1e12): cut at z = far = 100, whose pixel is
    # (319.5 + 0.24, 239.5 - 0.24); (0.1, 0.1, 2) projects to (331.5, 227.5).
    c = cam()
    seg = np.array([[[0.1, 0.1, 2.0], [0.1, 0.1, 1e12]]])
    kept, t0, t1 = clip_segments(seg, frustum_planes(c))
    end = apply_clip(seg, kept, t0, t1)[0, 1]
    # t = 98/(1e12 - 2) ~ 1e-10; z = 2 + t*(1e12-2): ~4 roundings of values ~100
    assert_allclose(end[2], 100.0, rtol=0, atol=4 * EPS * 100 * 2)
    fr = render(seg[0], [[0, 1]])
    assert fr.clipped_edges == 1
    assert_array_equal(fr.image, raster_image([((331.5, 227.5), (319.74, 239.26))]))
    assert np.count_nonzero(fr.image) >= 11  # |331.5 - 319.74| ~ 11.8 px along x


# ---- precision of the clipped ends at extreme coordinates ------------------------------

DEPTH_SPANNING = [
    # camera-space segments that cross far, the visible depth range and near within a
    # tiny fraction of their length: (p0, p1)
    pytest.param([0.3, 0.2, 1e12], [0.3, 0.2, -1e12], id="1e12"),
    pytest.param([0.3, 0.2, 1e16], [0.3, 0.2, -1e16], id="1e16"),
    pytest.param([0.3, 0.2, 1e17], [0.3, 0.2, -1e17], id="1e17"),
    # the frame-2 case of a scene vertex (1e200, 1e200, 0) spun by the default motion:
    # t_enter rounds to exactly 1 and p0 + 1 * (p1 - p0) cancels to z = 0
    pytest.param([-1e200, -1e200, 2.4492935982947065e184], [0.0, 0.0, 4.0], id="1e200"),
]


@pytest.mark.parametrize("p0,p1", DEPTH_SPANNING)
def test_clipped_ends_never_have_nonpositive_depth(p0, p1):
    """Docstring of core.projector.clipping: no point with z < near is ever divided by.

    The exact clipped ends have z in [near, far] = [1, 100]; apply_clip's
    p0 + t (p1 - p0) can be off by ~ EPS * |p| (cancellation), which is harmless at
    1e12 (1e-4) but reaches the whole near distance at 1e16 (ulp(1e16) = 2).
    """
    c = cam()
    seg = np.array([[p0, p1]], dtype=float)
    kept, t0, t1 = clip_segments(seg, frustum_planes(c))
    ends = apply_clip(seg, kept, t0, t1, (c.near, c.far)).reshape(-1, 3)
    assert np.all(ends[:, 2] > 0), ends
    with np.errstate(all="raise"):  # cam_to_px must never divide by z <= 0
        fr = render_frame(world([p0, p1]), np.array([[0, 1]]), c, np.eye(4))
    assert np.all(np.isfinite(fr.p_px[fr.visible]))


# ---- the last guard: clip_to_image --------------------------------------------------


@pytest.mark.parametrize(
    "p1, want",
    [
        ((10.0, 100.0), (10.0, 29.5)),  # down: stops at the bottom edge, y = H - 1/2
        ((10.0, -100.0), (10.0, -0.5)),  # up: the top edge, y = -1/2
        ((100.0, 5.0), (19.5, 5.0)),  # right: x = W - 1/2
        ((-100.0, 5.0), (-0.5, 5.0)),  # left: x = -1/2
    ],
)
def test_clip_to_image_stops_at_each_image_edge(p1, want):
    from wirecheck.core.projector.clipping import clip_to_image

    # from (10, 5) inside a 20 x 30 image; axis-parallel, so t is exact on the grid of halves
    kept, q0, q1 = clip_to_image(np.array([[10.0, 5.0]]), np.array([p1]), 20, 30)
    assert kept.tolist() == [True]
    assert_array_equal(q0, [[10.0, 5.0]])
    assert_allclose(q1, [want], rtol=0, atol=1e-12)  # t = (edge - 5) / 95 etc.: one rounding of ~100


def test_clip_to_image_moves_a_start_outside_onto_the_edge():
    from wirecheck.core.projector.clipping import clip_to_image

    # reversed: from (10, 100) below a 20 x 30 image up to (10, 5): the start moves to y = 29.5
    kept, q0, q1 = clip_to_image(np.array([[10.0, 100.0]]), np.array([[10.0, 5.0]]), 20, 30)
    assert kept.tolist() == [True]
    assert_allclose(q0, [[10.0, 29.5]], rtol=0, atol=1e-12)
    assert_array_equal(q1, [[10.0, 5.0]])

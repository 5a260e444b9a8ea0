"""The OpenCV and pyrender oracles against hand-derived values and core."""

import numpy as np
import pytest
from wirecheck.core.camera import camera_z, look_at
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import project_points
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles.references import opencv_oracle
from wirecheck.oracles.references.pyrender_oracle import osmesa_available

EPS = np.finfo(np.float64).eps
EPS32 = float(np.finfo(np.float32).eps)

# camera at (0,0,4) looking at the origin: f = 240 / tan(45 deg) = 240,
# (cx, cy) = (319.5, 239.5), depth = 4 - z.
CAM = camera_z(4.0, fov_y_deg=90.0, width=640, height=480, near=1.0, far=10.0)
# Pixel tolerance for CAM: f carries 2 ulp (tan(pi/4) = 1 - 1 ulp) and
# cv2.projectPoints rounds a few more times; coordinates are < 640, so
# 16 eps * 640 ~ 2e-12 px bounds it.
PX_TOL = 16 * EPS * 640


# ---- OpenCV oracle ------------------------------------------------------


def test_opencv_hand_values():
    p_world = np.array(
        [
            [1.0, 1.0, 0.0],  # depth 4: (319.5 + 60, 239.5 - 60)
            [2.0, -1.0, 2.0],  # depth 2: (319.5 + 240, 239.5 + 120)
            [0.0, 0.0, -6.0],  # depth 10 = far: the centre
            [-3.0, 0.5, 3.0],
        ]
    )  # depth 1 = near: (319.5 - 720, 239.5 - 120)
    expected = [[379.5, 179.5], [559.5, 359.5], [319.5, 239.5], [-400.5, 119.5]]
    np.testing.assert_allclose(opencv_oracle.project(p_world, CAM), expected, rtol=0, atol=PX_TOL)
    np.testing.assert_array_equal(opencv_oracle.depth(p_world, CAM), [4.0, 2.0, 10.0, 1.0])


def test_opencv_masks_outside_near_far():
    import cv2
    from wirecheck.oracles.references.convert import camera_to_opencv

    p_world = np.array(
        [
            [1.0, 1.0, 8.0],  # behind the camera (depth -4)
            [0.0, 0.0, 4.0],  # at the camera (depth 0)
            [0.0, 0.0, 3.0],  # exactly on near (depth 1): visible
            [0.0, 0.0, np.nextafter(3.0, 4.0)],  # depth 1 - 4.4e-16: before near
            [0.0, 0.0, -6.0],  # exactly on far: visible
            # depth = 1 ulp of 10 beyond far (z = 4 - that is exact;
            # 1 ulp of z = -6 would round back to depth 10)
            [0.0, 0.0, 4.0 - np.nextafter(10.0, 11.0)],
        ]
    )
    p_px = opencv_oracle.project(p_world, CAM)
    assert np.isnan(p_px[[0, 1, 3, 5]]).all()
    np.testing.assert_allclose(p_px[[2, 4]], [[319.5, 239.5], [319.5, 239.5]], rtol=0, atol=PX_TOL)
    # why the mask is needed: OpenCV projects the point behind the camera
    # mirrored, to (319.5 - 60, 239.5 + 60), as if it were in front.
    rvec, tvec, k = camera_to_opencv(CAM)
    mirrored, _ = cv2.projectPoints(p_world[:1], rvec, tvec, k, np.zeros(5))
    np.testing.assert_allclose(mirrored.reshape(2), [259.5, 299.5], rtol=0, atol=PX_TOL)


def test_opencv_empty():
    assert opencv_oracle.project(np.zeros((0, 3)), CAM).shape == (0, 2)
    assert opencv_oracle.depth(np.zeros((0, 3)), CAM).shape == (0,)


def test_opencv_orthographic_hand_values():
    cam = camera_z(4.0, projection="orthographic", ortho_height=2.0, width=640, height=480, near=0.5, far=10.0)
    # s = 480 / 2 = 240 px per unit, independent of depth
    p_world = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, -5.0], [0.5, -0.25, 3.5], [0.0, 0.0, 3.6]])
    expected = [[559.5, -0.5], [559.5, -0.5], [439.5, 299.5], [np.nan, np.nan]]
    np.testing.assert_allclose(opencv_oracle.project(p_world, cam), expected, rtol=0, atol=PX_TOL)


def test_opencv_agrees_with_core_oblique():
    # Not a hand value, a cross-check of two independent codes on a rolled,
    # oblique camera; pixel coordinates up to ~1e3 -> 64 eps * 1e3 px.
    cam = look_at(
        (3.0, -2.0, 5.0),
        (0.3, 0.1, -0.2),
        up=(0.4, 1.0, 0.3),
        fov_y_deg=47.5,
        width=320,
        height=200,
        near=0.25,
        far=50.0,
    )
    p_world = np.random.default_rng(7).uniform(-2, 2, size=(200, 3))
    ours, theirs = project_points(p_world, cam), opencv_oracle.project(p_world, cam)
    np.testing.assert_array_equal(np.isnan(ours), np.isnan(theirs))
    np.testing.assert_allclose(theirs, ours, rtol=0, atol=64 * EPS * 1e3)


# ---- pyrender oracle ----------------------------------------------------

_OK, _WHY = osmesa_available()
needs_osmesa = pytest.mark.skipif(not _OK, reason=f"pyrender/OSMesa unavailable: {_WHY}")


def _dilate(mask):
    """3x3 dilation (Chebyshev radius 1) without scipy."""
    out = mask.copy()
    p = np.pad(mask, 1)
    for dy in range(3):
        for dx in range(3):
            out |= p[dy : dy + mask.shape[0], dx : dx + mask.shape[1]]
    return out


def _distance_to_segment(q, a, b):
    ab = b - a
    t = np.clip(((q - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(q - (a + t[:, None] * ab), axis=1)


def test_osmesa_message_is_one_line():
    ok, msg = osmesa_available()
    assert isinstance(ok, bool) and msg and "\n" not in msg
    if not ok:
        assert "apt-get install -y libosmesa6" in msg or "PYOPENGL_PLATFORM" in msg


@needs_osmesa
def test_pyrender_empty_edges_blank(oracle):
    mask, depth = oracle.render(np.zeros((0, 3)), np.zeros((0, 2), int), CAM)
    assert mask.shape == (480, 640) and not mask.any()
    assert depth.dtype == np.float32 and not depth.any()


@needs_osmesa
def test_pyrender_orthographic_lines_follow_closed_form(oracle):
    cam = look_at(
        (2.0, 1.5, 3.0),
        (0.0, 0.0, 0.0),
        up=(0.2, 1.0, 0.0),
        projection="orthographic",
        ortho_height=3.0,
        width=640,
        height=480,
        near=0.5,
        far=20.0,
    )
    p_world = np.array([[-1.0, -0.7, 0.2], [1.1, 0.4, -0.3], [0.3, 1.2, 0.9], [-0.2, -1.1, -0.8]])
    edges = np.array([[0, 1], [2, 3], [0, 2]])
    p_px = opencv_oracle.project(p_world, cam)
    for e in edges:
        mask, _ = oracle.render(p_world, e[None], cam)
        rows, cols = np.nonzero(mask)
        a, b = p_px[e[0]], p_px[e[1]]
        # GL's diamond-exit rule lights a pixel only if the segment passes
        # through its diamond |dx| + |dy| < 1/2 around the centre, so every
        # lit centre is within 1/2 px of the closed-form segment; 1e-3 px of
        # slack covers float32 vertex and matrix rounding (~1e-7 * 640 px).
        d = _distance_to_segment(np.c_[cols, rows].astype(float), a, b)
        assert d.max() < 0.5 + 1e-3
        # one pixel per column (or row) along the major axis, give or take
        # the two end pixels
        major = np.abs(b - a).max()
        assert major - 2 <= len(rows) <= major + 2


@needs_osmesa
def test_pyrender_depth_readback(oracle):
    # Two horizontal edges, at depth 3 (z = 1) and depth 7 (z = -3), away from
    # row ties: y_px = 239.5 - 240 y / depth.
    #   y = 0.31 at depth 3:  239.5 - 24.8      = 214.7   -> row 215
    #   y = -0.5 at depth 7:  239.5 + 17.142857 = 256.64  -> row 257
    p_world = np.array([[-1.0, 0.31, 1.0], [1.0, 0.31, 1.0], [-1.0, -0.5, -3.0], [1.0, -0.5, -3.0]])
    mask, depth = oracle.render(p_world, np.array([[0, 1], [2, 3]]), CAM)
    col = 320
    assert list(np.nonzero(mask[:, col])[0]) == [215, 257]
    # 24-bit depth buffer, linearised by pyrender: one step of window z is
    # 2^-24, i.e. 2^-23 in NDC z, and d(depth)/d(z_ndc) = depth^2 (far - near)
    # / (2 far near) = depth^2 * 9 / 20 here (~2.6e-6 at depth 7); plus float32
    # rounding of the result (a few eps32 relative).
    for row, d in ((215, 3.0), (257, 7.0)):
        tol = d * d * (10.0 - 1.0) / (2 * 10.0 * 1.0) * 2.0**-23 + 4 * EPS32 * d
        assert depth[row, col] == pytest.approx(d, abs=tol)
        assert np.abs(depth[row][mask[row]] - d).max() <= tol  # the whole line
    assert not depth[~mask].any()  # 0 where nothing drawn


def _cube_frames():
    w, h = 640, 480
    cams = {
        "front": camera_z(5.0, width=w, height=h),
        "oblique_roll": look_at((3.0, 2.5, 5.0), (0, 0, 0), up=(0.3, 1.0, 0.1), fov_y_deg=50.0, width=w, height=h),
        "ortho": look_at((4.0, 3.0, 4.0), (0, 0, 0), projection="orthographic", ortho_height=4.0, width=w, height=h),
    }
    for name, cam in cams.items():
        for k in (1, 4, 7, 11):
            yield pytest.param(cam, k, id=f"{name}-{k}")


@needs_osmesa
@pytest.mark.parametrize("cam,k", list(_cube_frames()))
def test_pyrender_cube_matches_core_within_1px(oracle, cam, k):
    scene = load_scene("cube")
    m = Motion().frame_matrix(k, 12)
    gl, _ = oracle.render(scene.vertices, scene.edges, cam, model_matrix=m)
    ours = render_frame(scene.vertices, scene.edges, cam, m).image > 0
    assert gl.sum() > 500 and ours.sum() > 500  # the cube is in view
    # recall@1px: every oracle pixel has a core pixel in its 3x3 neighbourhood;
    # precision@1px: the converse. Both must be exactly 1.
    assert (gl & ~_dilate(ours)).sum() == 0
    assert (ours & ~_dilate(gl)).sum() == 0


@needs_osmesa
def test_pyrender_faces_hide_back_edges(oracle):
    # Cube seen face-on from z = 5: front square at depth 4 (half size
    # f/4 = 103.9 px), back square at depth 6 (69.3 px). With faces, the back
    # square and the four depth edges are hidden behind the front face.
    cam = camera_z(5.0, width=640, height=480)
    scene = load_scene("cube")
    wire, _ = oracle.render(scene.vertices, scene.edges, cam)
    solid, depth = oracle.render(scene.vertices, scene.edges, cam, faces=scene.faces)
    f = 240.0 / np.tan(np.radians(30.0))
    back_top_row = int(np.floor(239.5 - f / 6 + 0.5))
    front_top_row = int(np.floor(239.5 - f / 4 + 0.5))
    assert wire[back_top_row, 320] and not solid[back_top_row, 320]
    assert wire[front_top_row, 320] and solid[front_top_row, 320]
    assert not (solid & ~wire).any()
    # The front face is drawn (black) at depth 4 in the middle of the image,
    # pushed back by glPolygonOffset(1, 1): face-on, that is ~1 unit of the
    # 24-bit depth buffer (2^-24 of window z) plus 1 unit of quantisation;
    # one unit is depth^2 (far - near) / (far near) 2^-24 = 16 * 999 * 2^-24
    # ~ 9.5e-6 at depth 4 (near 0.1, far 100). Allow 4 units.
    unit = 16.0 * (100.0 - 0.1) / (100.0 * 0.1) * 2.0**-24
    assert depth[240, 320] == pytest.approx(4.0, abs=4 * unit)


def test_opencv_oracle_conversion_cache_follows_the_camera():
    # The oracle keeps the last camera's OpenCV conversion. Alternating two cameras must give
    # each its own projection: compared with cv2.projectPoints called here directly on
    # hand-built R, t, K (rows right, -up, forward; f = (H/2)/tan(fov/2); c = (W-1)/2, (H-1)/2).
    import cv2
    from scipy.spatial.transform import Rotation
    from wirecheck.core.camera import look_at
    from wirecheck.oracles.references import opencv_oracle

    pts = np.array([[0.3, -0.2, 0.1], [-0.5, 0.4, -0.3]])
    cams = [
        look_at((0, 0, 4), (0, 0, 0), (0, 1, 0), fov_y_deg=60),
        look_at((3, 1, 2), (0, 0, 0), (0, 1, 0), fov_y_deg=40, width=320, height=240),
    ]

    def by_hand(cam):
        fwd = -np.asarray(cam.position) / np.linalg.norm(cam.position)
        right = np.cross(fwd, (0, 1, 0))
        right /= np.linalg.norm(right)
        up = np.cross(right, fwd)
        r = np.stack([right, -up, fwd])
        f = (cam.height / 2) / np.tan(np.radians(cam.fov_y_deg) / 2)
        k = np.array([[f, 0, (cam.width - 1) / 2], [0, f, (cam.height - 1) / 2], [0, 0, 1]])
        out, _ = cv2.projectPoints(
            pts.reshape(-1, 1, 3), Rotation.from_matrix(r).as_rotvec(), -r @ np.asarray(cam.position), k, np.zeros(5)
        )
        return out.reshape(-1, 2)

    for cam in cams + cams[::-1] + cams:
        # 1e-9 px: both sides are float64 projectPoints on matrices equal to ~1e-16 relative,
        # at pixel magnitudes < 1e3
        np.testing.assert_allclose(opencv_oracle.project(pts, cam), by_hand(cam), rtol=0, atol=1e-9)


@needs_osmesa
def test_closing_the_oracle_frees_its_context_without_a_full_collection(monkeypatch):
    # pyrender's OffscreenRenderer.delete() ends with gc.collect(): ~0.1 s in a process holding
    # a test suite's objects, on every crosscheck run. close() frees the same GL resources and
    # destroys the context, and collects nothing itself; a second oracle draws the same pixels.
    import gc

    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    edges = np.array([[0, 1], [1, 2]])
    p_world = np.array([[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0]])
    cam = camera_z(3.0, fov_y_deg=60.0, width=64, height=48)
    first = PyrenderOracle(64, 48)
    before, _ = first.render(p_world, edges, cam)
    renderer = first._renderer
    freed = []

    def spy(obj, name):
        real = getattr(type(obj), name)
        monkeypatch.setattr(type(obj), name, lambda self, *a: freed.append(name) or real(self, *a))

    spy(renderer._renderer, "delete")
    spy(renderer._platform, "delete_context")
    collections = []
    monkeypatch.setattr(gc, "collect", lambda *a: collections.append(a) or 0)
    first.close()
    assert collections == []  # no full collection
    # pyrender's order: GL objects, then the context (the platform's __del__ may destroy it again)
    assert freed[:2] == ["delete", "delete_context"]
    assert renderer._platform is None and renderer._renderer is None
    monkeypatch.undo()
    with PyrenderOracle(64, 48) as second:
        again, _ = second.render(p_world, edges, cam)
    assert before.sum() > 20 and np.array_equal(before, again)

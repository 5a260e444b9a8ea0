"""core.projector.culling: triangulation, winding checks, back faces, bounding-sphere culling."""

from __future__ import annotations

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.projector.culling import (
    backface_keep,
    face_of_triangle,
    sphere_outside_frustum,
    triangulate,
    winding_problem,
)
from wirecheck.core.projector.projection import world_to_cam

# scenes/cube.scene, faces counter-clockwise seen from outside
CUBE_V = np.array(
    [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float
)
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
FRONT = 1  # the z = +1 face


def _face_keep(camera, faces=CUBE_F, vertices=CUBE_V, mirrored=False):
    tris = triangulate(faces)
    owner = face_of_triangle(faces)
    keep = backface_keep(world_to_cam(vertices, camera)[tris], camera.projection, mirrored=mirrored)
    kept = np.zeros(len(faces), bool)
    kept[owner[keep]] = True
    return kept


# ---- triangulation ---------------------------------------------------------


def test_triangulate_fans_from_the_first_vertex_and_maps_back():
    faces = [(0, 1, 2, 3), (4, 5, 6), (7, 8, 9, 10, 11)]
    assert triangulate(faces).tolist() == [[0, 1, 2], [0, 2, 3], [4, 5, 6], [7, 8, 9], [7, 9, 10], [7, 10, 11]]
    assert face_of_triangle(faces).tolist() == [0, 0, 1, 2, 2, 2]
    assert triangulate(faces).dtype == np.intp


def test_triangulate_array_input_and_degenerate_polygons():
    arr = np.array([[0, 1, 2], [2, 1, 3]])
    assert triangulate(arr).tolist() == arr.tolist()
    assert face_of_triangle(arr).tolist() == [0, 1]
    # polygons with fewer than 3 vertices give no triangle, indices stay those of the input
    assert face_of_triangle([(0, 1), (0, 1, 2)]).tolist() == [1]
    assert triangulate([]).shape == (0, 3)


# ---- winding ------------------------------------------------------------------


def test_consistent_cube_winding_has_no_problem():
    assert winding_problem(CUBE_F) is None
    assert winding_problem(triangulate(CUBE_F).tolist()) is None


def test_flipped_face_is_named_with_the_shared_edge():
    faces = list(CUBE_F)
    faces[3] = tuple(reversed(faces[3]))  # top face (3, 7, 6, 2) -> (2, 6, 7, 3)
    # The reversed top face traverses 2->6, 6->7, 7->3, 3->2. Among earlier faces,
    # the front face (4, 5, 6, 7) traverses 6->7 and the back face (0, 3, 2, 1)
    # traverses 3->2; the first in face 3's own order is 6->7, against face 1.
    assert winding_problem(faces) == (
        "faces 1 and 3 both traverse edge 6->7 in the same direction: inconsistent winding"
    )
    faces = list(CUBE_F)
    faces[5] = tuple(reversed(faces[5]))  # right face -> (5, 6, 2, 1): 5->6 as the front face
    assert winding_problem(faces) == (
        "faces 1 and 5 both traverse edge 5->6 in the same direction: inconsistent winding"
    )


def test_winding_message_exact_text():
    faces = [(0, 1, 2), (0, 1, 3)]  # both traverse 0->1
    assert winding_problem(faces) == (
        "faces 0 and 1 both traverse edge 0->1 in the same direction: inconsistent winding"
    )
    assert winding_problem([(0, 1, 2), (1, 0, 3)]) is None
    assert "twice" in winding_problem([(0, 1, 0, 1)])


# ---- back faces --------------------------------------------------------------


def test_cube_seen_from_plus_z_keeps_exactly_the_front_face():
    """The pin: reversing the sign of the rule keeps the other five (or the back face)."""
    for projection in ("perspective", "orthographic"):
        cam = look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), projection=projection, ortho_height=4.0)
        kept = _face_keep(cam)
        assert kept.tolist() == [i == FRONT for i in range(6)], projection


def test_cube_from_an_oblique_corner_keeps_the_three_faces_facing_it():
    cam = look_at((4.0, 3.0, 5.0), (0.0, 0.0, 0.0))
    # faces z = +1 (1), y = +1 (3), x = +1 (5) face the camera
    assert np.flatnonzero(_face_keep(cam)).tolist() == [1, 3, 5]
    cam = look_at((-4.0, -3.0, -5.0), (0.0, 0.0, 0.0), projection="orthographic")
    assert np.flatnonzero(_face_keep(cam)).tolist() == [0, 2, 4]


def test_reversed_winding_or_mirror_flips_the_decision():
    cam = look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0))
    reversed_faces = [tuple(reversed(f)) for f in CUBE_F]
    kept = _face_keep(cam, reversed_faces)
    assert kept.sum() == 5 and not kept[FRONT]  # the rule follows the winding
    # A mirror (negative determinant) reverses the winding of the transformed vertices;
    # mirrored=True restores the outward normals: x -> -x maps the front face to itself.
    mirror = CUBE_V * [-1, 1, 1]
    assert _face_keep(cam, vertices=mirror, mirrored=True).tolist() == [i == FRONT for i in range(6)]


def test_perspective_uses_the_view_vector_not_the_forward_axis():
    # Camera at (0, 0, 5) looking along -z but shifted to x = 3: the right face
    # (x = +1) is seen (camera x > 1) in perspective; orthographic sees only the
    # direction, so only the front face.
    cam = look_at((3.0, 0.0, 5.0), (3.0, 0.0, 0.0))
    assert np.flatnonzero(_face_keep(cam)).tolist() == [1, 5]
    ortho = look_at((3.0, 0.0, 5.0), (3.0, 0.0, 0.0), projection="orthographic", ortho_height=10.0)
    assert np.flatnonzero(_face_keep(ortho)).tolist() == [1]


# ---- bounding spheres -------------------------------------------------------


def test_sphere_frustum_culling_by_hand():
    # camera at the origin looking down -z; 90 deg vertical fov, square image:
    # the side planes are x = +-z', y = +-z' (z' = depth), up to the half-pixel
    # border (the planes pass through the image edges, -0.5 and W - 0.5).
    cam = look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), fov_y_deg=90.0, width=101, height=101, near=1.0, far=10.0)
    out = lambda c, r: sphere_outside_frustum(np.asarray(c, float), r, cam)
    assert not out((0, 0, -5), 0.5)  # in the middle
    assert out((0, 0, 3), 1.0)  # behind the camera
    # centre at depth z' = -0.5 (behind): near plane z' >= 1 is 1.5 away
    assert out((0, 0, 0.5), 1.4) and not out((0, 0, 0.5), 1.6)
    assert out((0, 0, -0.5), 0.4)  # in front of the camera but before near
    assert out((0, 0, -11.0), 0.9)  # beyond far
    assert not out((0, 0, -11.0), 1.1)  # reaches back past far
    # side plane x = z' (distance (z' - x) / sqrt 2): centre (7, 0, -5) is
    # 2/sqrt2 = 1.414 outside the right plane
    assert out((7, 0, -5), 1.4)
    assert not out((7, 0, -5), 1.42)  # straddles it
    assert out((0, -7, -5), 1.4) and not out((0, -7, -5), 1.42)
    # the sphere of the unit cube seen from 5 units away is never culled
    cam2 = look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0))
    assert not sphere_outside_frustum(np.zeros(3), np.sqrt(3), cam2)


def test_sphere_culling_is_conservative_at_a_frustum_corner():
    # Outside the frustum near a corner but within radius of both side planes: not culled.
    cam = look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), fov_y_deg=90.0, width=101, height=101, near=1.0, far=10.0)
    # 0.566 outside the right and top planes, 0.653 from the frustum's edge x = y = z'
    centre = np.array([5.8, 5.8, -5.0])
    assert not sphere_outside_frustum(centre, 0.6, cam)


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_sphere_culling_never_culls_a_visible_point(projection):
    rng = np.random.default_rng(0)
    cam = look_at((1.0, 2.0, 6.0), (0.0, 0.0, 0.0), near=0.5, far=12.0, projection=projection, ortho_height=4.0)
    from wirecheck.core.projector.projection import project_points

    for _ in range(300):
        c = rng.normal(size=3) * 5
        r = rng.uniform(0.1, 2.0)
        pts = c + r * rng.uniform(-1, 1, size=(200, 3)) / np.sqrt(3)  # inside the sphere
        px = project_points(pts, cam)
        seen = (
            ~np.isnan(px).any(axis=1)
            & (px[:, 0] >= -0.5)
            & (px[:, 0] <= cam.width - 0.5)
            & (px[:, 1] >= -0.5)
            & (px[:, 1] <= cam.height - 0.5)
        )
        if seen.any():
            assert not sphere_outside_frustum(c, r, cam)


def test_directed_edges_in_polygon_order():
    from wirecheck.core.projector.culling import directed_edges

    i, j, face, pos = directed_edges([(0, 1, 2, 3), (4, 5, 6)])
    assert list(zip(i.tolist(), j.tolist())) == [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 4)]
    assert face.tolist() == [0, 0, 0, 0, 1, 1, 1] and pos.tolist() == [0, 1, 2, 3, 0, 1, 2]
    i2, j2, _, _ = directed_edges(np.array([[4, 5, 6]]))
    assert list(zip(i2.tolist(), j2.tolist())) == [(4, 5), (5, 6), (6, 4)]


@pytest.mark.parametrize("kw", [{"hidden_lines": True}, {"style": "shaded"}])
def test_every_face_culled_renders_an_empty_face_buffer(kw):
    # A camera inside the cube sees every face from behind (outward normals point
    # away from it), so back-face culling keeps none: no face covers any pixel,
    # and with hidden lines every remaining edge (none: all belong to faces) is gone.
    from wirecheck.core.camera import camera_z
    from wirecheck.core.projector.pipeline import render_frame
    from wirecheck.core.scene.files import load_scene

    cube = load_scene("cube")
    cam = camera_z(0.5, near=0.1, far=10.0)
    frame = render_frame(cube.vertices, cube.edges, cam, np.eye(4), faces=cube.faces, cull="backface", **kw)
    assert frame.faces_culled == 6
    assert (frame.face_ids == -1).all() and np.isinf(frame.depth_image).all()
    assert not frame.image.any()

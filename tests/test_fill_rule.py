"""oracles.references.fill_rule: GL's fill rule in float64, ties, near-plane cuts, object ids.

Expected values are derived by hand (small triangles, drawn below) or by a naive ray caster
kept at the top of this module; the bundled scenes are compared with pyrender (Mesa) and with
core's shaded frames, which may differ from the reference only at ties.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from wirecheck.core.camera import Camera, look_at
from wirecheck.core.projector import pipeline
from wirecheck.core.scene.files import builtin_names, example_names, load_scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles import tolerances
from wirecheck.oracles.cases import case_motion, cases_for
from wirecheck.oracles.references import faces as oface
from wirecheck.oracles.references import fill_rule
from wirecheck.oracles.references.fill_rule import (
    GL_TIE_PX,
    ID_TIE,
    NO_OBJECT,
    corner_edges,
    coverage,
    open_edges,
    silhouette,
)

# ---- a naive reference: one ray per pixel centre, Moller-Trumbore, in camera space -------------


def _ray_cast(tri_cam: np.ndarray, camera: Camera) -> np.ndarray:
    """(H, W) bool: the ray through each pixel centre hits some triangle at near <= z <= far."""
    h, w = camera.height, camera.width
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    if camera.projection == "perspective":
        f = (h / 2) / math.tan(math.radians(camera.fov_y_deg) / 2)
        origin = np.zeros((h, w, 3))
        direction = np.stack([(x - (w - 1) / 2) / f, -(y - (h - 1) / 2) / f, np.ones_like(x)], axis=-1)
    else:
        s = h / camera.ortho_height
        origin = np.stack([(x - (w - 1) / 2) / s, -(y - (h - 1) / 2) / s, np.zeros_like(x)], axis=-1)
        direction = np.broadcast_to(np.array([0.0, 0.0, 1.0]), origin.shape)
    hit = np.zeros((h, w), dtype=bool)
    for a, b, c in tri_cam:
        e1, e2 = b - a, c - a
        pv = np.cross(direction, e2)
        det = pv @ e1
        with np.errstate(divide="ignore", invalid="ignore"):
            tv = origin - a
            u = np.einsum("hwk,hwk->hw", tv, pv) / det
            qv = np.cross(tv, e1)
            v = np.einsum("hwk,hwk->hw", direction, qv) / det
            t = (qv @ e2) / det
        z = origin[..., 2] + t * direction[..., 2]
        hit |= (u >= 0) & (v >= 0) & (u + v <= 1) & (z >= camera.near) & (z <= camera.far)
    return hit


def _cam_to_world(p_cam):
    """The camera of :func:`_camera` (at the origin, forward -Z, up +Y): world = (x, y, -z)."""
    p_cam = np.asarray(p_cam, dtype=np.float64)
    return p_cam * np.array([1.0, 1.0, -1.0])


def _camera(**kw) -> Camera:
    kw.setdefault("width", 64)
    kw.setdefault("height", 48)
    return look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0), **kw)


# ---- hand-derived coverage ---------------------------------------------------------------------


def test_right_triangle_top_left_rule_and_ties_on_every_edge():
    # (0,0), (4,0), (0,4): the top edge y = 0 and the left edge x = 0 own their centres, the
    # hypotenuse x + y = 4 does not (module docstring's picture); each of the three edges passes
    # through centres, all of them ties, and no other centre is within GL_TIE_PX of an edge
    # (the next ones are 1/sqrt 2 px from the hypotenuse, 1 px from the legs)
    inside, ties = coverage([[[0, 0], [4, 0], [0, 4]]], (6, 6))
    y, x = np.mgrid[0:6, 0:6]
    np.testing.assert_array_equal(inside, (x + y < 4))
    on_edge = ((x == 0) & (y <= 4)) | ((y == 0) & (x <= 4)) | (x + y == 4)
    np.testing.assert_array_equal(ties, on_edge)


def test_winding_does_not_matter():
    a = coverage([[[0, 0], [4, 0], [0, 4]]], (6, 6))
    b = coverage([[[0, 0], [0, 4], [4, 0]]], (6, 6))
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])


def test_axis_aligned_rectangle_owns_top_and_left_rows_only():
    # rectangle x in [1, 5], y in [2, 4] as two triangles: centres on the top row (y = 2) and the
    # left column (x = 1) are in, those on the bottom row (y = 4) and right column (x = 5) out
    tris = [[[1, 2], [5, 2], [5, 4]], [[1, 2], [5, 4], [1, 4]]]
    inside, ties = coverage(tris, (7, 8))
    expected = np.zeros((7, 8), dtype=bool)
    expected[2:4, 1:5] = True
    np.testing.assert_array_equal(inside, expected)
    # the outline's centres are ties; the shared diagonal (1,2)-(5,4) is closed: the centre (3, 3)
    # on it is no tie
    outline = np.zeros((7, 8), dtype=bool)
    outline[2:5, 1:6] = True
    outline[3:4, 2:5] = False
    np.testing.assert_array_equal(ties, outline)


def test_two_triangles_sharing_an_edge_own_its_centres_once():
    # the square [0, 4] x [0, 4] cut along its diagonal through the centres (0,0) ... (4,4). The
    # upper triangle's edge (4,4) -> (0,0) goes up the screen (a left edge): it owns the diagonal;
    # for the lower one the same edge runs (0,0) -> (4,4), neither top nor left
    lower, _ = coverage([[[0, 0], [4, 4], [0, 4]]], (6, 6))
    upper, _ = coverage([[[0, 0], [4, 0], [4, 4]]], (6, 6))
    y, x = np.mgrid[0:6, 0:6]
    np.testing.assert_array_equal(upper, (y <= x) & (x < 4))
    np.testing.assert_array_equal(lower, (y > x) & (y < 4))
    assert not (lower & upper).any()


def test_a_centre_within_the_tie_distance_of_an_edge_is_a_tie():
    # a vertical edge at x = 2 + d: the centres of column 2 are d px from it
    for d, tie in ((0.5 * GL_TIE_PX, True), (0.99 * GL_TIE_PX, True), (1.01 * GL_TIE_PX, False), (0.3, False)):
        x_edge = 2.0 + d
        tris = [[[x_edge, -20.0], [x_edge, 25.0], [-30.0, 2.0]]]  # other edges far away
        inside, ties = coverage(tris, (5, 5))
        assert ties[:, 2].all() == tie and ties[:, 2].any() == tie, d
        np.testing.assert_array_equal(inside[:, :3], True)  # x = 2 < x_edge: inside
        assert not inside[:, 3:].any()


def test_tie_px_zero_leaves_only_centres_on_an_open_edge():
    inside, ties = coverage([[[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]]], (6, 6), tie_px=0.0)
    y, x = np.mgrid[0:6, 0:6]
    assert ties.sum() == 5 + 5 + 5 - 3  # three edges of 5 centres, the corners counted once


def test_zero_area_triangle_covers_nothing_but_its_centres_are_ties():
    inside, ties = coverage([[[0, 1], [4, 1], [2, 1]]], (3, 6))
    assert not inside.any()
    np.testing.assert_array_equal(ties[1, :5], True)
    assert ties.sum() == 5


def test_a_centre_near_an_open_edge_but_deep_inside_another_triangle_is_decided():
    # a small triangle whose edges pass through centres, lying inside a big one: the small one's
    # edges are open, but every centre on them is held by the big triangle 10+ px from its edges
    big = [[-20.0, -20.0], [60.0, -20.0], [-20.0, 60.0]]
    small = [[5.0, 5.0], [9.0, 5.0], [5.0, 9.0]]
    inside, ties = coverage([big, small], (20, 20))
    assert inside.all() and not ties.any()
    _, ties_small = coverage([small], (20, 20))
    assert ties_small.sum() == 12  # alone, its edges' centres are ties


def test_open_edges_closed_only_between_triangles_on_both_sides():
    tris = np.array(
        [
            [[0, 0], [4, 0], [0, 4]],  # shares (4,0)-(0,4) with the next, on the other side
            [[4, 0], [4, 4], [0, 4]],
            [[0, 0], [4, 0], [2, -3]],  # shares (0,0)-(4,0) with the first, other side
            [[0, 0], [2, 2], [0, 4]],
        ],  # shares no edge ((0,0)-(0,4) is not an edge above)
        dtype=np.float64,
    )
    expected = np.array(
        [
            [False, False, True],  # edges v0v1, v1v2, v2v0
            [True, True, False],
            [False, True, True],
            [True, True, True],
        ]
    )
    np.testing.assert_array_equal(open_edges(tris), expected)
    # a fold: two triangles sharing an edge with both third vertices on one side keep it open
    fold = np.array([[[0, 0], [4, 0], [2, 3]], [[0, 0], [4, 0], [1, 1]]], dtype=np.float64)
    assert open_edges(fold)[:, 0].all()


def test_open_edges_grouped_by_corner_numbers_once_and_by_points_where_two_numbers_meet():
    # the square (0,0) (4,0) (4,4) (0,4) as two triangles on either side of the diagonal (0,0)-(4,4);
    # numbered as a mesh (the diagonal's ends shared: 0 and 2) the diagonal is closed, the rim open
    tris = np.array([[[0, 0], [4, 0], [4, 4]], [[0, 0], [4, 4], [0, 4]]], dtype=np.float64)
    shared = np.array([[0, 1, 2], [0, 2, 3]])
    expected = np.array([[True, True, False], [False, True, True]])  # edges v0v1, v1v2, v2v0
    grouped = corner_edges(shared)
    np.testing.assert_array_equal(open_edges(tris, shared, grouped), expected)
    np.testing.assert_array_equal(open_edges(tris, shared), expected)
    # the same points numbered apart (an OBJ with split vertices: 0 and 4, 2 and 5 are one point each): the
    # edges are grouped by points again, and the diagonal is still closed, given the split numbers' groups
    split = np.array([[0, 1, 2], [4, 5, 3]])
    np.testing.assert_array_equal(open_edges(tris, split, corner_edges(split)), expected)


def test_a_shared_edge_through_centres_leaves_no_crack_and_no_tie():
    # a fan of 8 triangles about (10, 10), spokes through centres, rim at (4, 10), (6, 6), (10, 4),
    # ...: the spokes' centres short of the rim are neither holes nor ties
    angles = np.arange(8) * np.pi / 4
    rim = np.stack([10 + 6 * np.cos(angles), 10 + 6 * np.sin(angles)], axis=1).round()
    tris = np.stack([np.broadcast_to([10.0, 10.0], (8, 2)), rim, np.roll(rim, -1, axis=0)], axis=1)
    inside, ties = coverage(tris, (21, 21))
    assert inside[10, 5:16].all() and inside[5:16, 10].all()
    assert inside[np.arange(7, 14), np.arange(7, 14)].all() and inside[np.arange(7, 14), np.arange(13, 6, -1)].all()
    assert not ties[5:16, 10].any() and not ties[10, 5:16].any()
    assert not ties[np.arange(7, 14), np.arange(7, 14)].any()
    assert ties[10, 4] and ties[4, 10] and ties[6, 6]  # rim vertices, on open edges


# ---- the scene path: projection, near-plane cut, object ids -----------------------------------


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_triangles_crossing_the_near_plane_match_a_ray_caster(projection):
    rng = np.random.default_rng(35)
    cam = _camera(near=1.0, far=8.0, fov_y_deg=70.0, projection=projection, ortho_height=4.0)
    tri_cam = rng.uniform([-3, -2.5, -1.0], [3, 2.5, 10.0], size=(12, 3, 3))  # many cross near or far
    tri_cam[0] = [[-1.5, -1.0, -2.0], [2.0, -1.2, 3.0], [0.0, 1.5, 3.0]]  # one vertex behind the eye
    faces = [tuple(range(3 * i, 3 * i + 3)) for i in range(len(tri_cam))]
    world = _cam_to_world(tri_cam.reshape(-1, 3))
    inside, ties, _ = silhouette(world, faces, cam, (cam.height, cam.width))
    expected = _ray_cast(tri_cam, cam)
    decided = ~ties
    assert decided.sum() > 0.95 * decided.size
    np.testing.assert_array_equal(inside[decided], expected[decided])
    assert 0.1 * inside.size < inside.sum() < 0.95 * inside.size  # the frame says something
    # a case's edges grouped once (corner_edges of the fan) are not used on a frame with cut triangles (their
    # corners are numbered otherwise): the same silhouette as the one held to the ray caster above
    again = silhouette(world, faces, cam, (cam.height, cam.width), edges=corner_edges(np.array(faces)))
    np.testing.assert_array_equal(again[0], inside)
    np.testing.assert_array_equal(again[1], ties)


def test_a_triangle_wholly_behind_or_beyond_is_not_drawn():
    cam = _camera(near=1.0, far=5.0)
    tri_cam = np.array([[[-1, -1, 0.5], [1, -1, 0.5], [0, 1, 0.9]], [[-1, -1, 6.0], [1, -1, 6.0], [0, 1, 7.0]]])
    inside, ties, ids = silhouette(_cam_to_world(tri_cam.reshape(-1, 3)), [(0, 1, 2), (3, 4, 5)], cam, (48, 64))
    assert not inside.any() and not ties.any() and (ids == NO_OBJECT).all()


def test_nearest_object_owns_the_pixel_and_equal_depths_are_id_ties():
    cam = _camera(near=0.5, far=20.0)
    f = (48 / 2) / math.tan(math.radians(60.0) / 2)

    def square(x0, x1, y0, y1, z):
        p = [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]]
        return [[a * z / f if i == 0 else a for i, a in enumerate(q)] for q in p]

    # object 0: pixel columns ~10..40 at depth 4; object 1: columns ~30..55 at depth 2 (nearer);
    # object 2: same square as object 0 at the same depth, drawn twice: an id tie wherever they overlap
    def cam_square(xa, xb, z):
        # pixel x -> x_cam = (x - cx) z / f
        cx = (64 - 1) / 2
        return np.array(
            [
                [(xa - cx) * z / f, -1.0, z],
                [(xb - cx) * z / f, -1.0, z],
                [(xb - cx) * z / f, 1.0, z],
                [(xa - cx) * z / f, 1.0, z],
            ]
        )

    pts = np.concatenate([cam_square(10.3, 40.3, 4.0), cam_square(30.3, 55.3, 2.0)])
    faces = [(0, 1, 2, 3), (4, 5, 6, 7)]
    inside, ties, ids = silhouette(_cam_to_world(pts), faces, cam, (48, 64), face_objects=[0, 1])
    row = 24
    np.testing.assert_array_equal(ids[row, 11:31], 0)  # columns 11..30: object 0 only
    np.testing.assert_array_equal(ids[row, 31:56], 1)  # 31..55: object 1 in front
    assert (ids[row, :11] == NO_OBJECT).all() and (ids[row, 56:] == NO_OBJECT).all()
    # the same square twice, as two objects at one depth: every covered pixel an id tie
    pts2 = np.concatenate([cam_square(10.3, 40.3, 4.0), cam_square(10.3, 40.3, 4.0)])
    _, _, ids2 = silhouette(_cam_to_world(pts2), faces, cam, (48, 64), face_objects=[0, 1])
    np.testing.assert_array_equal(ids2[row, 11:41], ID_TIE)
    # one object in front of the other by 1e-3 (far above the depth bound, ~1e-5 at z = 4): decided
    pts3 = np.concatenate([cam_square(10.3, 40.3, 4.0), cam_square(10.3, 40.3, 4.001)])
    _, _, ids3 = silhouette(_cam_to_world(pts3), faces, cam, (48, 64), face_objects=[0, 1])
    np.testing.assert_array_equal(ids3[row, 11:41], 0)


def test_the_tie_distance_is_the_tolerances():
    # fill_rule may not import the tolerances (they sit above the references): the same numbers
    assert GL_TIE_PX == tolerances.FILL_TIE_PX == tolerances.Tolerances().fill_tie_px
    assert (fill_rule._DEPTH_STEPS, fill_rule._DEPTH_SNAP_PX, fill_rule._DEPTH_EPS32) == (
        tolerances.DEPTH_STEPS,
        tolerances.DEPTH_SNAP_PX,
        tolerances.DEPTH_EPS32,
    )


def test_face_objects_of_another_length_are_refused():
    cam = _camera()
    with pytest.raises(ValueError, match="1 entries for 2 faces"):
        silhouette(np.eye(4, 3), [(0, 1, 2), (1, 2, 3)], cam, (48, 64), face_objects=[0])


def test_a_distorted_camera_is_refused():
    cam = _camera(distortion=(0.1, 0.0, 0.0, 0.0, 0.0), intrinsics=(40.0, 40.0, 31.5, 23.5))
    with pytest.raises(ValueError, match="distorted"):
        silhouette(np.zeros((3, 3)), [(0, 1, 2)], cam, (48, 64))


# ---- the bundled scenes: pyrender and core differ from the reference only at ties -------------


def _scene_frames(frames: int):
    """Every bundled scene x default case camera x ``frames`` frames: (label, scene, camera, geometry)."""
    names = list(builtin_names()) + [f"scenes/examples/{n}.scene" for n in example_names()]
    motion0 = Motion(turns=(1.0, 1.0, 0.0))
    for name in names:
        scene = load_scene(name)
        for case in cases_for(scene, motion0):
            motion = case_motion(motion0, case)
            for k in range(frames):
                yield f"{name}/{case.name}/{k}", scene, case.camera, oface.frame_geometry(scene, motion, k / frames)


def _face_objects(scene) -> np.ndarray:
    starts = np.array([o.vertex_start for o in scene.objects])
    return np.searchsorted(starts, [f[0] for f in scene.faces], side="right") - 1


FRAMES = 2  # 6 scenes x 7 cameras x 2 frames: 84 frames


@pytest.mark.slow
def test_core_shaded_frames_differ_from_the_reference_only_at_ties(summary_section):
    decided_diff, tie_diff, ties_px, ref_px, n = 0, 0, 0, 0, 0
    for label, scene, cam, (p_world, _m, pr_vertices, pr_pose) in _scene_frames(FRAMES):
        inside, ties, _ = silhouette(p_world, scene.faces, cam, (cam.height, cam.width))
        frame = pipeline.render_frame(
            pr_vertices, scene.edges, cam, np.eye(4) if pr_pose is None else pr_pose, faces=scene.faces, style="shaded"
        )
        core = np.isfinite(frame.depth_image)
        assert not ((core != inside) & ~ties).any(), label
        decided_diff += int(((core != inside) & ~ties).sum())
        tie_diff += int(((core != inside) & ties).sum())
        ties_px += int(ties.sum())
        ref_px += int(inside.sum())
        n += 1
    assert n == 6 * 7 * FRAMES and ref_px > 0
    summary_section(
        "fill rule: core --style shaded",
        f"{n} frames, {ref_px} reference pixels, {ties_px} ties; "
        f"core differs at {decided_diff} decided pixels, {tie_diff} ties",
    )


@pytest.mark.slow
def test_pyrender_silhouettes_and_object_ids_differ_from_the_reference_only_at_ties(summary_section):
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)
    oracles = {}
    tie_diff, ties_px, ref_px, id_px, n = 0, 0, 0, 0, 0
    try:
        for label, scene, cam, (p_world, _m, pr_vertices, pr_pose) in _scene_frames(FRAMES):
            objects = _face_objects(scene)
            inside, ties, ids = silhouette(p_world, scene.faces, cam, (cam.height, cam.width), objects)
            tris, owner = oface.fan(scene.faces)
            key = (cam.width, cam.height)
            if key not in oracles:
                oracles[key] = PyrenderOracle(*key)
            covered, _depth, tri_ids = oracles[key].render_faces(
                pr_vertices, tris, cam, model_matrix=pr_pose, cull=False, with_ids=True
            )
            gl_ids = np.where(tri_ids >= 0, objects[owner[np.maximum(tri_ids, 0)]], NO_OBJECT)
            assert not ((covered != inside) & ~ties).any(), label
            both = covered & inside & ~ties & (ids != ID_TIE)
            assert (gl_ids[both] == ids[both]).all(), label
            tie_diff += int(((covered != inside) & ties).sum())
            ties_px += int(ties.sum())
            ref_px += int(inside.sum())
            id_px += int(both.sum()) if len(scene.objects) > 1 else 0
            n += 1
    finally:
        for o in oracles.values():
            o.close()
    assert n == 6 * 7 * FRAMES and id_px > 0
    summary_section(
        "fill rule: pyrender",
        f"{n} frames, {ref_px} reference pixels, {ties_px} ties; pyrender "
        f"differs at 0 decided pixels, {tie_diff} ties; object ids equal at {id_px} decided pixels",
    )


@pytest.mark.slow
def test_pyrender_object_ids_where_objects_hide_each_other(summary_section):
    # two interpenetrating icospheres and a box in front of both: the ids along the occlusion
    # boundaries and the intersection curve are decided by depth, and equal pyrender's except at ties
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)
    trimesh = pytest.importorskip("trimesh")
    parts = [
        trimesh.creation.icosphere(subdivisions=3),
        trimesh.creation.icosphere(subdivisions=2, radius=0.6),
        trimesh.creation.box(extents=(0.5, 0.4, 0.3)),
    ]
    offsets = [(0.0, 0.0, 0.0), (0.9, 0.35, 0.5), (-0.4, -0.2, 1.4)]
    vertices, faces, objects, start = [], [], [], 0
    for i, (m, off) in enumerate(zip(parts, offsets)):
        vertices.append(np.asarray(m.vertices) + off)
        faces.append(np.asarray(m.faces) + start)
        objects += [i] * len(m.faces)
        start += len(m.vertices)
    p_world, tris, objects = np.concatenate(vertices), np.concatenate(faces), np.asarray(objects)
    decided_ids, id_ties, n = 0, 0, 0
    with PyrenderOracle(640, 480) as oracle:
        for position in ((0.3, 0.4, 4.0), (2.5, 1.0, 3.0), (-1.0, -0.5, 3.5)):
            cam = look_at(position, (0.2, 0.1, 0.3), near=0.5, far=20.0)
            inside, ties, ids = silhouette(p_world, [tuple(t) for t in tris], cam, (480, 640), objects)
            covered, _depth, tri_ids = oracle.render_faces(p_world, tris, cam, cull=False, with_ids=True)
            gl_ids = np.where(tri_ids >= 0, objects[np.maximum(tri_ids, 0)], NO_OBJECT)
            assert not ((covered != inside) & ~ties).any()
            both = covered & inside & ~ties & (ids != ID_TIE)
            assert (gl_ids[both] == ids[both]).all(), position
            assert len(np.unique(ids[both])) == 3  # all three objects seen
            decided_ids += int(both.sum())
            id_ties += int((ids == ID_TIE).sum())
            n += 1
    summary_section(
        "fill rule: object ids",
        f"{n} views of 3 overlapping objects: ids equal pyrender's at {decided_ids} decided pixels; {id_ties} id ties",
    )


def test_docs_depth_picture_is_what_coverage_gives():
    # docs/depth.md, "Filled frames: the fill rule and ties": the right triangle's two 5 x 5 pictures
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "depth.md").read_text()
    lines = text[text.index("inside        ties\n") :].splitlines()[1:6]
    inside, ties = coverage([[[0, 0], [4, 0], [0, 4]]], (5, 5))
    for row, line in enumerate(lines):
        cells = line.split()
        assert cells[:5] == ["*" if v else "." for v in inside[row]], line
        assert cells[5:10] == ["t" if v else "." for v in ties[row]], line


# ---- the batched pass against a naive one: every triangle over the whole image ----------------


def _naive_coverage(tris_px, is_open, shape, tie_px):
    """``(inside, ties)`` by the module docstring's rule, one triangle at a time over every centre.

    Written from the rule, not from the batched pass: each triangle turned so that its edge functions
    ``E = (Qx - Px)(py - Py) - (Qy - Py)(px - Px)`` are positive inside (its open flags carried with
    its edges), a centre inside when every ``E > 0`` or ``E == 0`` on a top or left edge; near an open
    edge when within tie_px of its line (``|E| <= tie_px |PQ|``) and of the segment; held robustly
    when inside and ``|E| > tie_px |PQ|`` for all three edges. Ties: near an open edge, held by none.
    """
    height, width = shape
    py, px = np.mgrid[0:height, 0:width].astype(np.float64)
    inside = np.zeros(shape, dtype=bool)
    near_open = np.zeros(shape, dtype=bool)
    robust = np.zeros(shape, dtype=bool)
    for tri, opened in zip(np.asarray(tris_px, dtype=np.float64), is_open):
        a, b, c = tri
        area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        if area2 < 0:  # v1 <-> v2: edges 0, 1, 2 become 2, 1, 0
            tri, opened = np.stack([a, c, b]), opened[::-1]
        tri_in = np.full(shape, area2 != 0)
        tri_far = tri_in.copy()
        for k in range(3):
            p, q = tri[k], tri[(k + 1) % 3]
            dx, dy = q[0] - p[0], q[1] - p[1]
            e = dx * (py - p[1]) - dy * (px - p[0])
            top_left = dy < 0 or (dy == 0 and dx > 0)
            tri_in &= (e > 0) | ((e == 0) & top_left)
            reach = tie_px * math.sqrt(dx * dx + dy * dy)
            tri_far &= np.abs(e) > reach
            if opened[k]:
                rx, ry = px - p[0], py - p[1]
                length2 = dx * dx + dy * dy
                t = np.clip((rx * dx + ry * dy) / length2, 0.0, 1.0) if length2 > 0 else np.zeros(shape)
                near_open |= (np.abs(e) <= reach) & (np.hypot(rx - t * dx, ry - t * dy) <= tie_px)
        inside |= tri_in
        robust |= tri_in & tri_far
    return inside, near_open & ~robust


def _snapped_soup(rng, count, size, shape, step):
    """``count`` triangles of about ``size`` px with corners on a ``step``-px grid (centres fall on edges: E == 0,
    ties), half of them in strips sharing edges (closed edges), in and partly out of the image."""
    height, width = shape
    corner = rng.uniform([0, 0], [width, height], size=(count, 1, 2))
    tris = np.round((corner + rng.uniform(-size, size, size=(count, 3, 2))) / step) * step
    half = count // 2
    tris[1:half:2, 0] = tris[0 : half - 1 : 2, 1]  # each odd triangle shares its neighbour's edge v1 -> v2
    tris[1:half:2, 1] = tris[0 : half - 1 : 2, 2]
    return tris


@pytest.mark.parametrize(
    "count, size, shape, step",
    [
        (600, 3.0, (40, 56), 0.25),  # many small boxes: the triangle axis the longest (innermost)
        (4, 40.0, (48, 64), 1.0),  # few large boxes: the column axis the longest
        (60, 12.0, (33, 45), 0.5),
    ],
)
@pytest.mark.parametrize("tie_px", [GL_TIE_PX, 0.3])
def test_coverage_equals_a_naive_pass_bit_for_bit(count, size, shape, step, tie_px):
    rng = np.random.default_rng(count)
    for _ in range(3):
        tris = _snapped_soup(rng, count, size, shape, step)
        is_open = open_edges(tris)
        inside, ties = coverage(tris, shape, tie_px=tie_px)
        want_inside, want_ties = _naive_coverage(tris, is_open, shape, tie_px)
        assert want_inside.any() and want_ties.any() and is_open.any() and not is_open.all()
        np.testing.assert_array_equal(inside, want_inside)
        np.testing.assert_array_equal(ties, want_ties)


def _naive_open_edges(tris_px):
    """Edge ``k`` of each triangle is closed when the triangles with the same two end points (as floats:
    -0.0 == 0.0, NaN equal to nothing) have third vertices strictly on both sides of its line."""
    tris = np.asarray(tris_px, dtype=np.float64)
    p = tris.reshape(-1, 2)  # edge k runs p -> q, opposite third
    q = np.roll(tris, -1, axis=1).reshape(-1, 2)
    third = np.roll(tris, -2, axis=1).reshape(-1, 2)

    def equal(a, b):
        return (a[:, None] == b[None]).all(axis=2)

    same = (equal(p, p) & equal(q, q)) | (equal(p, q) & equal(q, p))
    d = q - p
    side = np.sign(
        d[:, None, 0] * (third[None, :, 1] - p[:, None, 1]) - d[:, None, 1] * (third[None, :, 0] - p[:, None, 0])
    )  # edge i's line, edge j's third
    closed = (same & (side > 0)).any(axis=1) & (same & (side < 0)).any(axis=1)
    return ~closed.reshape(-1, 3)


def test_open_edges_equal_a_naive_pairing():
    rng = np.random.default_rng(7)
    tris = _snapped_soup(rng, 300, 3.0, (40, 56), 0.25)
    tris[::7] *= -1.0  # -0.0 corners where a corner was 0.0
    # an edge (0, 0) -> (0, 4) shared across, written with 0.0 in one triangle and -0.0 in the other: closed
    tris = np.concatenate([tris, [[[0.0, 0.0], [0.0, 4.0], [-3.0, 2.0]], [[-0.0, 4.0], [-0.0, -0.0], [3.0, 2.0]]]])
    want = _naive_open_edges(tris)
    assert want.any() and not want.all()
    assert not want[-2, 0] and not want[-1, 0]
    np.testing.assert_array_equal(open_edges(tris), want)
    # numbered corners (one number: one point), each its own or one per distinct point, change nothing
    _, same = np.unique(tris.reshape(-1, 2) + 0.0, axis=0, return_inverse=True)
    for corners in (np.arange(tris.size // 2).reshape(-1, 3), same.reshape(-1, 3)):
        np.testing.assert_array_equal(open_edges(tris, corners), want)
    # NaN corners equal nothing: the edges through one are open, even between triangles that share it
    nan_pair = np.array([[[0.0, 0.0], [np.nan, 4.0], [-3.0, 2.0]], [[np.nan, 4.0], [0.0, 0.0], [3.0, 2.0]]])
    np.testing.assert_array_equal(open_edges(nan_pair), _naive_open_edges(nan_pair))
    assert open_edges(nan_pair)[:, :2].all()


# ---- a hint of triangle ids (pyrender's) spares work and changes nothing ----------------------


def _grid_and_soup(rng):
    """A 12 x 9 grid of quads (shared edges: closed) at depth 3 beside a soup of 12 triangles that cross the
    near and far planes, in camera space; ``(points, faces)``."""
    xs, ys = np.meshgrid(np.linspace(-2.2, 0.7, 13), np.linspace(-1.4, 1.2, 10))
    grid = np.stack([xs.ravel(), ys.ravel(), 3.0 + 0.2 * xs.ravel()], axis=1)
    quads = [(r * 13 + c, r * 13 + c + 1, (r + 1) * 13 + c + 1, (r + 1) * 13 + c) for r in range(9) for c in range(12)]
    soup = rng.uniform([-3, -2.5, -1.0], [3, 2.5, 10.0], size=(12, 3, 3)).reshape(-1, 3)
    start = len(grid)
    faces = quads + [tuple(range(start + 3 * i, start + 3 * i + 3)) for i in range(12)]
    return np.concatenate([grid, soup]), faces


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_a_hint_of_triangle_ids_changes_nothing(projection):
    """silhouette(hint=ids) checks each hinted run of centres against its triangle by the rule and rasterizes
    the triangles only around the centres it does not hold: the result is the unhinted one (itself the naive
    pass's, above) whatever the hint says: the fan's first covering triangle per centre, that hint moved by a
    pixel (runs that overhang their triangle), random ids (out of range too), none."""
    rng = np.random.default_rng(3)
    cam = _camera(near=1.0, far=8.0, fov_y_deg=70.0, projection=projection, ortho_height=4.0)
    p_cam, faces = _grid_and_soup(rng)
    p_world = _cam_to_world(p_cam)
    shape = (cam.height, cam.width)
    want = silhouette(p_world, faces, cam, shape)
    tris, _owner = oface.fan(faces)
    first, count = np.full(shape, -1), np.zeros(shape, dtype=int)
    for t in range(len(tris) - 1, -1, -1):  # the fan's first triangle covering each centre wins
        alone = silhouette(p_world, [tuple(tris[t])], cam, shape)[0]
        first[alone] = t
        count += alone
    assert (first >= 0).sum() > 0.3 * first.size and len(np.unique(first)) > 100
    # one centre deep in the grid left unhinted, none of the soup near it: the boxes around it (the grid's
    # triangles are ~3 px) hold that one centre alone unchecked
    grid = (first >= 0) & (first < 2 * 108) & (count == 1)
    y, x = next((y, x) for y, x in np.argwhere(grid) if y > 4 and x > 4 and grid[y - 4 : y + 5, x - 4 : x + 5].all())
    dropped = first.copy()
    dropped[y, x] = -1
    hints = {
        "first": first,
        "one dropped": dropped,
        "moved": np.roll(first, 1, axis=1),
        "random": rng.integers(-1, len(tris) + 5, size=shape),
        "none": np.full(shape, -1),
    }
    for name, hint in hints.items():
        got = silhouette(p_world, faces, cam, shape, hint=hint, fanned=(tris, _owner))
        for a, b in zip(got, want):
            np.testing.assert_array_equal(a, b, err_msg=name)
    assert want[1].any()  # ties on the soup's open edges: the hint path decides them too


def _first_cover(tris_px, shape):
    """``(H, W)`` int: the first of ``tris_px`` covering each centre by the naive pass, -1 where none does."""
    first = np.full(shape, -1)
    for t in range(len(tris_px) - 1, -1, -1):
        first[_naive_coverage(tris_px[t : t + 1], np.ones((1, 3), dtype=bool), shape, 0.0)[0]] = t
    return first


def test_hinted_silhouettes_of_random_soups_equal_the_naive_pass():
    """silhouette(hint=ids) on 20 soups of 300 triangles (corners on a quarter-pixel grid, so centres lie on
    edges; half of them in strips sharing edges; in and partly out of the image) is the naive pass's, bit for
    bit, whatever the hint: each centre's first covering triangle (every run held but the ties'), that hint
    moved a pixel (runs overhanging their triangle), random ids (out of range too). The hint path's own
    parts (the runs checked and painted, the box rows left to rasterize, the robust rows) meet 6,000
    triangles and about 20,000 runs here."""
    rng = np.random.default_rng(35)
    shape = (40, 56)
    cam = _camera(width=56, height=40, projection="orthographic", ortho_height=40.0, near=0.5, far=5.0)
    cx, cy = (shape[1] - 1) / 2, (shape[0] - 1) / 2  # orthographic, 1 px a unit: x = cx + x_cam, y = cy - y_cam
    faces = [(3 * i, 3 * i + 1, 3 * i + 2) for i in range(300)]
    runs = 0
    for _ in range(20):
        soup = _snapped_soup(rng, 300, 3.0, shape, 0.25)
        depth = rng.uniform(1.0, 4.0, size=(300, 3, 1))
        p_world = _cam_to_world(np.concatenate([soup[..., :1] - cx, cy - soup[..., 1:], depth], axis=2).reshape(-1, 3))
        tris_px = fill_rule.project_clipped(p_world, faces, cam)[0]
        want_inside, want_ties = _naive_coverage(tris_px, open_edges(tris_px), shape, GL_TIE_PX)
        assert want_ties.any()
        first = _first_cover(tris_px, shape)
        runs += int(np.count_nonzero(np.diff(first, axis=1)) + shape[0])
        hints = {"first": first, "moved": np.roll(first, 1, axis=1), "random": rng.integers(-1, 310, size=shape)}
        for name, hint in hints.items():
            inside, ties, ids = silhouette(p_world, faces, cam, shape, hint=hint)
            np.testing.assert_array_equal(inside, want_inside, err_msg=name)
            np.testing.assert_array_equal(ties, want_ties, err_msg=name)
            np.testing.assert_array_equal(ids, np.where(want_inside, 0, NO_OBJECT), err_msg=name)
    assert runs > 15_000  # the first cover's runs along the rows (20,139): each hint checks as many

"""core.projector.zbuffer: triangle clipping, coverage (top-left rule), perspective-correct depth.

Checked by hand on tiny cases, against a brute-force exact reference, and
against pyrender (OSMesa / llvmpipe) on a cube and an icosphere.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.projector import zbuffer
from wirecheck.core.projector.clipping import clip_triangles_near
from wirecheck.core.projector.projection import unproject, world_to_cam
from wirecheck.core.projector.zbuffer import project_triangles, rasterize_triangles

EPS32 = float(np.finfo(np.float32).eps)


def _raster(tri_px, z, w, h, projection="perspective"):
    return rasterize_triangles(
        np.asarray(tri_px, float).reshape(-1, 3, 2), np.asarray(z, float).reshape(-1, 3), w, h, projection
    )


# ---- hand-derived cases -------------------------------------------------------


def test_single_triangle_top_left_rule_on_exact_ties():
    # Vertices on pixel centres (1, 1), (5, 1), (1, 5): the top edge y = 1 and the
    # left edge x = 1 own their centres, the hypotenuse x + y = 6 does not.
    depth, face = _raster([[1, 1], [5, 1], [1, 5]], [3.0, 3.0, 3.0], 8, 8)
    y, x = np.mgrid[0:8, 0:8]
    expected = (x >= 1) & (y >= 1) & (x + y < 6)
    assert np.array_equal(face == 0, expected)
    assert expected.sum() == 10
    assert np.all(depth[expected] == 3.0) and np.all(np.isinf(depth[~expected]))
    assert np.all(face[~expected] == -1) and face.dtype == np.int32
    # Winding does not matter.
    _, face_rev = _raster([[1, 1], [1, 5], [5, 1]], [3.0, 3.0, 3.0], 8, 8)
    assert np.array_equal(face_rev, face)
    # The other half of the square: bottom (y = 5) and right (x = 5) edges are
    # excluded, the hypotenuse is now a top-left edge and is included.
    _, face2 = _raster([[5, 5], [1, 5], [5, 1]], [3.0, 3.0, 3.0], 8, 8)
    expected2 = (x < 5) & (y < 5) & (x + y >= 6)
    assert np.array_equal(face2 == 0, expected2) and expected2.sum() == 6


def test_shared_edges_partition_the_pixels():
    # Square [1, 5]^2 split along its diagonal: every centre of [1, 4]^2 is
    # covered exactly once (top and left edges of the square in, bottom and right out).
    _, face = _raster([[[1, 1], [5, 1], [1, 5]], [[5, 5], [1, 5], [5, 1]]], np.full((2, 3), 2.0), 8, 8)
    y, x = np.mgrid[0:8, 0:8]
    square = (x >= 1) & (x <= 4) & (y >= 1) & (y <= 4)
    assert np.array_equal(face >= 0, square)
    assert np.array_equal(face == 1, square & (x + y >= 6))
    # A fan of triangles around an interior point: each centre exactly once.
    centre = np.array([10.0, 10.0])
    ang = np.linspace(0, 2 * np.pi, 9)[:-1]
    ring = centre + 6 * np.stack([np.cos(ang), np.sin(ang)], 1).round(0)
    tris = np.stack([np.repeat(centre[None], 8, 0), ring, np.roll(ring, -1, 0)], 1)
    single = [(_raster(t, [1.0, 1.0, 1.0], 21, 21)[1] >= 0) for t in tris]
    counts = np.sum(single, axis=0)
    assert counts.max() == 1


def test_two_overlapping_triangles_nearest_wins_ties_go_to_the_lower_index():
    big = [[0, 0], [20, 0], [0, 20]]
    small = [[2, 2], [8, 2], [2, 8]]
    d, f = _raster([big, small], [[5.0] * 3, [2.0] * 3], 24, 24)
    y, x = np.mgrid[0:24, 0:24]
    in_small = (x >= 2) & (y >= 2) & (x + y < 10)
    in_big = x + y < 20
    assert np.array_equal(f == 1, in_small)
    assert np.array_equal(f == 0, in_big & ~in_small)
    assert np.all(d[in_small] == 2.0) and np.all(d[in_big & ~in_small] == 5.0)
    # drawn in the other order, the nearer one still wins
    d2, f2 = _raster([small, big], [[2.0] * 3, [5.0] * 3], 24, 24)
    assert np.array_equal(f2 == 0, in_small) and np.array_equal(d2, d)
    # equal depth: the lower index wins
    _, f3 = _raster([big, small], [[5.0] * 3, [5.0] * 3], 24, 24)
    assert np.all(f3[in_big] == 0)
    _, f4 = _raster([small, big], [[5.0] * 3, [5.0] * 3], 24, 24)
    assert np.all(f4[in_small] == 0) and np.all(f4[in_big & ~in_small] == 1)


def _plane_depth_along_rays(p_cam_tri, camera, rr, cc):
    """Exact depth of the triangle's plane along the rays of pixel centres (rr, cc)."""
    a, b, c = p_cam_tri
    n = np.cross(b - a, c - a)
    # a point on the ray of pixel (x, y) at depth z is unproject(px, z) (camera space: use z = 1)
    px = np.stack([cc, rr], 1).astype(float)
    # by hand (core/conventions.py), not from core's Camera: the principal point
    # ((W - 1) / 2, (H - 1) / 2) and f = (H / 2) / tan(fov_y / 2)
    cx, cy = (camera.width - 1) / 2.0, (camera.height - 1) / 2.0
    if camera.projection == "perspective":
        f = (camera.height / 2.0) / math.tan(math.radians(camera.fov_y_deg) / 2.0)
        x1 = (px[:, 0] - cx) / f
        y1 = -(px[:, 1] - cy) / f
        d = np.stack([x1, y1, np.ones_like(x1)], 1)  # ray direction with z = 1
        return (n @ a) / (d @ n)  # t = depth
    s = camera.height / camera.ortho_height
    x = (px[:, 0] - cx) / s
    y = -(px[:, 1] - cy) / s
    return (n @ a - n[0] * x - n[1] * y) / n[2]


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_depth_is_the_plane_depth_at_pixel_centres(projection):
    """Perspective-correct: 1/z interpolated in screen space is exactly the plane's depth."""
    cam = look_at(
        (0.0, 0.0, 0.0),
        (0.0, 0.0, -1.0),
        width=64,
        height=48,
        near=0.1,
        far=100.0,
        projection=projection,
        ortho_height=6.0,
    )
    tri_cam = np.array([[[-2.0, -1.5, 3.0], [2.5, -1.0, 9.0], [0.0, 2.0, 5.0]]])  # strongly tilted
    tri_px, tri_z, src = project_triangles(tri_cam, cam)
    depth, face = rasterize_triangles(tri_px, tri_z, 64, 48, projection)
    rr, cc = np.nonzero(face >= 0)
    assert len(rr) > 300
    exact = _plane_depth_along_rays(tri_cam[0], cam, rr, cc)
    np.testing.assert_allclose(depth[rr, cc], exact, rtol=1e-12)
    # and unprojecting the buffer lands on the plane
    p_world = unproject(np.stack([cc, rr], 1), depth[rr, cc], cam)
    p_cam = world_to_cam(p_world, cam)
    n = np.cross(tri_cam[0, 1] - tri_cam[0, 0], tri_cam[0, 2] - tri_cam[0, 0])
    assert np.abs((p_cam - tri_cam[0, 0]) @ n / np.linalg.norm(n)).max() < 1e-12


# ---- brute-force reference ----------------------------------------------------


def _reference(tri_px, tri_z, w, h):
    """Per triangle, per pixel, in integers (1/256 px units): the documented rules verbatim."""
    depth = np.full((h, w), np.inf)
    face = np.full((h, w), -1)
    y, x = np.mgrid[0:h, 0:w]
    X, Y = x * 256, y * 256
    for t, (p, z) in enumerate(zip(tri_px, tri_z)):
        q = np.round(p * 256).astype(np.int64)
        area = (q[1, 0] - q[0, 0]) * (q[2, 1] - q[0, 1]) - (q[1, 1] - q[0, 1]) * (q[2, 0] - q[0, 0])
        if area == 0:
            continue
        order = [0, 1, 2] if area > 0 else [0, 2, 1]
        q, zz, praw = q[order], z[order], p[order]
        inside = np.ones((h, w), bool)
        for k in range(3):
            P, Q = q[(k + 1) % 3], q[(k + 2) % 3]
            dx, dy = Q[0] - P[0], Q[1] - P[1]
            e = dx * (Y - P[1]) - dy * (X - P[0])
            top_left = dy < 0 or (dy == 0 and dx > 0)
            inside &= (e >= 0) if top_left else (e > 0)
        # depth: barycentric on the unsnapped vertices, 1/z linear
        a, b, c = praw
        ar = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        l0 = ((c[0] - b[0]) * (y - b[1]) - (c[1] - b[1]) * (x - b[0])) / ar
        l1 = ((a[0] - c[0]) * (y - c[1]) - (a[1] - c[1]) * (x - c[0])) / ar
        l2 = 1 - l0 - l1
        zt = 1 / (l0 / zz[0] + l1 / zz[1] + l2 / zz[2])
        win = inside & (zt < depth)
        depth[win] = zt[win]
        face[win] = t
    return depth, face


def test_matches_a_brute_force_reference_including_ties():
    rng = np.random.default_rng(7)
    w, h = 40, 30
    n = 300
    c = rng.uniform([0, 0], [w, h], size=(n, 1, 2))
    tri = c + rng.normal(scale=5, size=(n, 3, 2))
    tri[:100] = np.round(tri[:100])  # on pixel centres: exact ties
    tri[100:150] = np.round(tri[100:150] * 2) / 2  # on half-integers
    tri[150:170, 2] = tri[150:170, 1]  # degenerate
    z = rng.uniform(1, 10, size=(n, 3))
    z[:100] = z[:100, :1]  # flat, to make depth ties between triangles rare but not absent
    depth, face = rasterize_triangles(tri, z, w, h)
    ref_d, ref_f = _reference(tri, z, w, h)
    assert np.array_equal(np.isinf(depth), np.isinf(ref_d))
    np.testing.assert_allclose(depth[np.isfinite(depth)], ref_d[np.isfinite(ref_d)], rtol=1e-12)
    same = face == ref_f
    # where faces differ the two depths must tie (to rounding): either answer is nearest
    assert np.all(np.abs(depth[~same] - ref_d[~same]) <= 1e-12 * depth[~same])
    assert same.mean() > 0.999


def test_batches_and_row_slabs_do_not_change_the_result(monkeypatch):
    trimesh = pytest.importorskip("trimesh")
    ico = trimesh.creation.icosphere(subdivisions=3)
    cam = look_at((2.0, 1.5, 2.5), (0.0, 0.0, 0.0), width=160, height=120)
    tri_px, tri_z, _ = project_triangles(world_to_cam(np.asarray(ico.vertices), cam)[np.asarray(ico.faces)], cam)
    big = np.array([[[-50.0, -40.0], [400.0, 10.0], [30.0, 300.0]]])  # larger than a small batch
    tri_px = np.concatenate([tri_px, big])
    tri_z = np.concatenate([tri_z, [[5.0, 5.0, 5.0]]])
    d1, f1 = rasterize_triangles(tri_px, tri_z, 160, 120)
    monkeypatch.setattr(zbuffer, "CHUNK_SAMPLES", 97)
    d2, f2 = rasterize_triangles(tri_px, tri_z, 160, 120)
    assert np.array_equal(f1, f2) and np.array_equal(d1, d2)


def test_non_finite_and_off_image_triangles_are_skipped():
    tri = np.array(
        [
            [[1, 1], [5, 1], [1, 5]],
            [[np.nan, 1], [5, 1], [1, 5]],
            [[1e300, 1], [np.inf, 1], [1, 5]],
            [[-50, -50], [-40, -50], [-50, -40]],
        ],
        float,
    )
    d, f = rasterize_triangles(tri, np.ones((4, 3)), 8, 8)
    assert set(np.unique(f)) == {-1, 0}


# ---- clipping ---------------------------------------------------------------


def test_clip_near_counts_winding_and_exact_plane():
    tri = np.array(
        [
            [[0, 0, 2.0], [1, 0, 2.0], [0, 1, 2.0]],  # inside: kept as is
            [[0, 0, 0.5], [1, 0, 0.5], [0, 1, 0.5]],  # before near: dropped
            [[0, 0, 2.0], [1, 0, 0.5], [0, 1, 0.5]],  # one inside: one triangle
            [[0, 0, 0.5], [1, 0, 2.0], [0, 1, 2.0]],  # two inside: two triangles
            [[0, 0, 1.0], [1, 0, 1.0], [0, 1, 0.9]],  # only an edge on the plane: zero area, dropped
            [[0, 0, 1.0], [1, 0, 1.5], [0, 1, 0.9]],  # a vertex on the plane: one triangle
        ]
    )
    out, src = clip_triangles_near(tri, 1.0)
    assert src.tolist() == [0, 2, 3, 3, 5]
    assert np.all(out[..., 2] >= 1.0)
    np.testing.assert_array_equal(out[0], tri[0])
    # new vertices lie exactly on z = near; the cut of triangle 2 along its edges
    # from (0, 0, 2) to the z = 0.5 vertices: t = (2 - 1) / 1.5 = 2/3
    np.testing.assert_allclose(out[1], [[0, 0, 2], [2 / 3, 0, 1], [0, 2 / 3, 1]], atol=1e-15)
    assert out[1, 1, 2] == 1.0 and out[1, 2, 2] == 1.0
    # winding (normal direction) is kept: every output normal is parallel to its source's
    n_in = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[src]
    n_out = np.cross(out[:, 1] - out[:, 0], out[:, 2] - out[:, 0])
    assert np.all(np.einsum("ij,ij->i", n_in, n_out) > 0)
    # the two pieces of triangle 3 cover its part beyond near: area of the
    # triangle (0,0)-(1,0)-(0,1) minus the corner cut at 1/3 along both legs
    pieces = out[src == 3]
    area = 0.5 * np.linalg.norm(np.cross(pieces[:, 1] - pieces[:, 0], pieces[:, 2] - pieces[:, 0]), axis=1).sum()
    full = 0.5 * np.linalg.norm(np.cross(tri[3, 1] - tri[3, 0], tri[3, 2] - tri[3, 0]))
    assert area == pytest.approx(full * (1 - (1 / 3) ** 2), rel=1e-12)


def test_clip_far_and_a_triangle_spanning_both_planes():
    tri = np.array([[[0, 0, 0.5], [1, 0, 50.0], [0, 1, 5.0]]])
    out, src = clip_triangles_near(tri, 1.0, 10.0)
    assert len(out) >= 2 and np.all(src == 0)
    assert out[..., 2].min() == 1.0 and out[..., 2].max() == 10.0


def test_huge_projected_coordinates_are_guard_band_clipped():
    # A wall at depth 2..6 reaching 1e6 units sideways (millions of pixels off the image)
    cam = look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), width=64, height=48, near=0.1, far=100.0)
    tri_cam = np.array([[[-1e6, -3.0, 2.0], [1e6, -3.0, 2.0], [0.0, 1e6, 6.0]]])
    tri_px, tri_z, src = project_triangles(tri_cam, cam)
    assert np.abs(tri_px).max() < 64 + 2 * zbuffer.GUARD_PX
    depth, face = rasterize_triangles(tri_px, tri_z, 64, 48)
    rr, cc = np.nonzero(face >= 0)
    assert len(rr) > 0
    exact = _plane_depth_along_rays(tri_cam[0], cam, rr, cc)
    np.testing.assert_allclose(depth[rr, cc], exact, rtol=1e-9)


# ---- speed ------------------------------------------------------------------


def test_100k_triangles_at_640x480_cover_the_image(summary_section):
    # Its time is printed, not asserted: speed lives in benchmarks/ (bench_scale), not in timed tests.
    trimesh = pytest.importorskip("trimesh")
    ico = trimesh.creation.icosphere(subdivisions=6)  # 81920 triangles
    faces = np.asarray(ico.faces)
    faces = np.concatenate([faces, faces[: 100_000 - len(faces)]])  # 100k (some drawn twice)
    cam = look_at((1.5, 1.25, 1.55), (0.0, 0.0, 0.0), near=0.1, far=100.0)  # fills most of the image
    tri_px, tri_z, _ = project_triangles(world_to_cam(np.asarray(ico.vertices), cam)[faces], cam)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        _, face = rasterize_triangles(tri_px, tri_z, 640, 480)
        best = min(best, time.perf_counter() - t0)
    summary_section(
        "zbuffer speed",
        f"rasterize_triangles: {len(faces)} triangles at 640x480, "
        f"{int((face >= 0).sum())} pixels covered: {best * 1e3:.0f} ms (best of 3)",
    )
    assert (face >= 0).sum() > 100_000


# ---- against pyrender ---------------------------------------------------------


def _pyrender_faces(vertices, triangles, camera, renderer):
    """White flat faces (double sided) with pyrender: (covered mask, linear depth, 0 = empty)."""
    import pyrender
    from wirecheck.oracles.references.convert import camera_to_pyrender

    scene = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
    mat = pyrender.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0], doubleSided=True)
    scene.add(
        pyrender.Mesh(
            [
                pyrender.Primitive(
                    positions=vertices.astype(np.float32),
                    indices=triangles.astype(np.uint32),
                    mode=pyrender.constants.GLTF.TRIANGLES,
                    material=mat,
                )
            ]
        )
    )
    pose, cam = camera_to_pyrender(camera)
    scene.add(cam, pose=pose)
    colour, depth = renderer.render(scene, pyrender.RenderFlags.FLAT)
    depth = depth.astype(np.float64)
    if camera.projection == "orthographic":
        # pyrender linearises every depth buffer with the *perspective* formula
        # D = 2 n f / (f + n - z_ndc (f - n)); undo it (z_ndc = (f + n - 2 n f / D) / (f - n))
        # and apply the orthographic one, z = (z_ndc (f - n) + f + n) / 2 = f + n - n f / D.
        n, f = camera.near, camera.far
        depth = np.where(depth > 0, f + n - n * f / np.where(depth > 0, depth, 1.0), 0.0)
    return colour[:, :, 0] > 127, depth


def _meshes():
    trimesh = pytest.importorskip("trimesh")
    return {
        "cube": trimesh.creation.box(extents=(2.0, 2.0, 2.0)),
        "icosphere": trimesh.creation.icosphere(subdivisions=3),
    }


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
@pytest.mark.parametrize("name", ["cube", "icosphere"])
def test_against_pyrender(name, projection, pyrender_renderer, summary_section):
    from scipy import ndimage

    mesh = _meshes()[name]
    v, tris = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    cam = look_at((3.0, 2.2, 4.1), (0.1, -0.2, 0.0), near=0.5, far=20.0, projection=projection, ortho_height=4.0)
    tri_px, tri_z, src = project_triangles(world_to_cam(v, cam)[tris], cam)
    depth, face = rasterize_triangles(tri_px, tri_z, 640, 480, projection)
    g = zbuffer.triangle_gradients(tri_px, tri_z, projection)
    theirs, their_depth = _pyrender_faces(v, tris, cam, pyrender_renderer)
    ours = face >= 0

    # Silhouette. Both sample coverage at pixel centres, with vertices snapped to
    # 1/256 px and the top-left rule, so they can only differ where a centre lies
    # within llvmpipe's float32 vertex error (~1e-4 px at 640 px) of a silhouette
    # edge: a few pixels at most out of a ~1000-pixel outline. Measured: 0 pixels
    # differ here (0 or 1 in 64 random poses). Asserted: IoU >= 0.999, and at
    # most 0.5 % of the outline pixels differ.
    iou = (ours & theirs).sum() / (ours | theirs).sum()
    outline = (ours & ~ndimage.binary_erosion(ours)).sum()
    xor = int((ours ^ theirs).sum())
    assert iou >= 0.999
    assert xor <= 0.005 * outline

    # Depth, at pixels interior to both silhouettes (eroded by 1 px). pyrender's
    # depth went through (a) llvmpipe's float32 window depth z_w in [0, 1],
    # (b) a 24-bit depth buffer, (c) float32 linearisation. In units of
    #     u(z) = 2^-24 dz/dz_w = 2^-24 (f - n) z^2 / (f n)   (orthographic: 2^-24 (f - n)),
    # (b) is <= 1 u (rounding or truncation); (a) per vertex, a few half-ulp
    # roundings of numbers < 1 (ulp <= 2^-24): <= 1 u; (c) 2 d - 1 and the
    # cancellation in f + n - z_ndc (f - n) (one float32 ulp of ~f + n, relative
    # to the denominator ~2 n f / z): ~(f + n)/(f - n) u <= 2 u (and our
    # orthographic inversion of it adds ~1 u more, within the same 2).
    # llvmpipe also evaluates the depth plane in float32 as z0 + dzdx x + dzdy y
    # with x, y up to W, H: relative eps32 of terms of size |dz_w/dx| W, i.e.
    # eps32 (W |dz/dx| + H |dz/dy|) in linear depth (<= eps32 (W + H) (|dz/dx| + |dz/dy|)).
    # Ours is float64 (~1e-15 relative). Bound per pixel:
    #     4 u(z) + eps32 (W + H) (|dz/dx| + |dz/dy|).
    # Measured over 64 random poses (near 0.05..1, far 20..1000): at most 0.81 of it.
    both = ndimage.binary_erosion(ours) & ndimage.binary_erosion(their_depth > 0)
    z = depth[both]
    n, f = cam.near, cam.far
    if projection == "perspective":
        u = 2.0**-24 * (f - n) * z**2 / (f * n)
        slope = np.abs(g[face[both]]).sum(axis=1) * z**2  # |dz/dx| + |dz/dy| = z^2 |d(1/z)|
    else:
        u = np.full_like(z, 2.0**-24 * (f - n))
        slope = np.abs(g[face[both]]).sum(axis=1)
    bound = 4 * u + EPS32 * (640 + 480) * slope
    err = np.abs(z - their_depth[both])
    ratio = float((err / bound).max())
    summary_section(
        f"zbuffer vs pyrender: {name} {projection}",
        f"silhouette IoU {iou:.6f} ({xor} of {outline} outline px differ); "
        f"depth max error {err.max():.3g} (max {err.max() / u.max():.2f} u), "
        f"max error / bound = {ratio:.2f} over {both.sum()} px",
    )
    assert both.sum() > 10_000
    assert ratio <= 1.0

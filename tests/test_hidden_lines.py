"""Hidden-line suppression and back-face culling in core.projector.pipeline.render_frame."""

from __future__ import annotations

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.projector import hidden_lines, pipeline, raster, zbuffer
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.oracles.judge.metrics import pixel_scores

CUBE_V = np.array(
    [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float
)
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
CUBE_E = np.array(sorted({tuple(sorted((f[k], f[(k + 1) % 4]))) for f in CUBE_F for k in range(4)}))


def _oblique_cameras(n, seed):
    """Cameras outside the cube seeing exactly three faces; the hidden corner is -sign(position)."""
    rng = np.random.default_rng(seed)
    for k in range(n):
        s = rng.choice([-1, 1], size=3)
        pos = s * rng.uniform(1.6, 6.0, size=3)  # |x|, |y|, |z| > 1: three faces seen
        projection = ("perspective", "orthographic")[k % 2]
        cam = look_at(pos, rng.normal(size=3) * 0.2, projection=projection, ortho_height=5.0)
        hidden = int(np.flatnonzero((CUBE_V == -s).all(axis=1))[0])
        yield cam, hidden


# ---- line pixels with their segment -----------------------------------------------


@pytest.mark.parametrize("mode", ["exact", "fast", "aa"])
def test_line_samples_are_core_raster_pixels_per_segment(mode):
    rng = np.random.default_rng(1)
    w, h = 57, 43
    p0 = rng.uniform(-0.5, [w - 0.5, h - 0.5], size=(400, 2))
    p1 = rng.uniform(-0.5, [w - 0.5, h - 0.5], size=(400, 2))
    p0[:100], p1[:100] = np.round(p0[:100] * 2) / 2, np.round(p1[:100] * 2) / 2  # ties
    p1[100:120] = p0[100:120]  # zero length
    seg, rr, cc, weight = hidden_lines.line_samples(p0, p1, w, h, mode)
    fn = {"exact": raster.line_pixels, "fast": raster.line_pixels_fast, "aa": raster.line_coverage_aa}[mode]
    for m in range(len(p0)):
        ref = fn(p0[m : m + 1], p1[m : m + 1], w, h)
        sel = seg == m
        got = sorted(zip(rr[sel].tolist(), cc[sel].tolist()))
        assert got == sorted(zip(ref[0].tolist(), ref[1].tolist())), m
        if mode == "aa":
            # shifted by whole bands, Wu's float minor coordinate rounds at a larger
            # magnitude (~2^-52 * offset): weights agree to ~1e-10
            order_g = np.lexsort((cc[sel], rr[sel]))
            order_r = np.lexsort((ref[1], ref[0]))
            np.testing.assert_allclose(weight[sel][order_g], ref[2][order_r], atol=1e-9)


def test_line_sample_depth_is_perspective_correct():
    # segment from depth 2 to depth 8 along x: 1/z is linear in screen space
    a, b = np.array([[0.0, 5.0]]), np.array([[10.0, 5.0]])
    cc = np.arange(11)
    z = hidden_lines.line_sample_depth(np.zeros(11, int), np.full(11, 5), cc, a, b, [2.0], [8.0], "perspective")
    np.testing.assert_allclose(1 / z, 0.5 + (0.125 - 0.5) * cc / 10, rtol=1e-15)
    z = hidden_lines.line_sample_depth(np.zeros(11, int), np.full(11, 5), cc, a, b, [2.0], [8.0], "orthographic")
    np.testing.assert_allclose(z, 2 + 6 * cc / 10, rtol=1e-15)


# ---- the cube -------------------------------------------------------------------


def test_oblique_cube_draws_its_nine_visible_edges():
    """Hidden lines = the 9 edges not at the hidden corner, drawn alone, except near 3 vertices.

    The 3 hidden edges run from the hidden corner to the three silhouette
    vertices next to it. A hidden edge's depth equals the front faces' at the
    silhouette vertex and falls behind them as it leaves it; its pixels are
    shown while the depth excess is within the bias (k times the face's depth
    slope per pixel, k = 1 for "exact", 2 for "fast"/"aa"), i.e. within about k
    pixels of the vertex, plus the pixel grid (1 px). So the frames agree
    exactly outside (k + 1)-pixel squares around those 3 vertices, and inside
    them hidden lines only *add* pixels (no visible pixel is lost anywhere).
    Measured over 300 random poses: extras within 0.85 px ("exact") and 1.85 px
    ("fast", "aa") of those vertices.
    """
    for mode, k in (("exact", 1), ("fast", 2), ("aa", 2)):
        extra_total = 0
        for cam, hidden in _oblique_cameras(12, seed=5):
            visible_edges = np.array([e for e in CUBE_E if hidden not in e])
            assert len(visible_edges) == 9
            fr = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, hidden_lines=True, raster=mode)
            nine = render_frame(CUBE_V, visible_edges, cam, np.eye(4), raster=mode)
            assert not (nine.mask & ~fr.mask).any()  # nothing visible is lost
            sil = [int(v) for e in CUBE_E if hidden in e for v in e if v != hidden]
            near = np.zeros_like(fr.mask)
            for v in sil:
                x, y = fr.p_px[v]
                near[
                    max(0, int(np.floor(y - k - 1))) : int(np.ceil(y + k + 1)) + 1,
                    max(0, int(np.floor(x - k - 1))) : int(np.ceil(x + k + 1)) + 1,
                ] = True
            assert np.array_equal(fr.mask & ~near, nine.mask & ~near)
            extra_total += int((fr.mask & ~nine.mask).sum())
            assert fr.hidden_pixels > 0 and fr.faces_total == 6 and fr.faces_culled == 0
            assert fr.depth_image is not None and np.isinf(fr.depth_image).any()
        assert extra_total <= 12 * 3 * (2 * k + 3) ** 2  # never more than those squares


def test_backface_culled_wireframe_draws_exactly_the_front_faces_edges():
    for mode in ("exact", "fast", "aa"):
        for cam, hidden in _oblique_cameras(8, seed=2):
            visible_edges = np.array([e for e in CUBE_E if hidden not in e])
            fr = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, cull="backface", raster=mode)
            nine = render_frame(CUBE_V, visible_edges, cam, np.eye(4), raster=mode)
            assert np.array_equal(fr.image, nine.image)  # F1@0 = 1
            assert fr.faces_culled == 3 and fr.edges_culled == 3
            assert fr.depth_image is None  # culling alone needs no depth buffer


def test_edges_in_no_face_are_kept_by_culling():
    v = np.concatenate([CUBE_V, [[3.0, 0.0, 0.0]]])
    edges = np.concatenate([CUBE_E, [[6, 8]]])  # a free edge to a new vertex
    cam = look_at((0.0, 0.0, 6.0), (0.0, 0.0, 0.0))
    fr = render_frame(v, edges, cam, np.eye(4), faces=CUBE_F, cull="backface")
    only = render_frame(v, np.array([[4, 5], [5, 6], [6, 7], [4, 7], [6, 8]]), cam, np.eye(4))
    assert np.array_equal(fr.image, only.image)
    assert fr.faces_culled == 5


def test_nothing_hidden_gives_the_plain_wireframe_byte_for_byte():
    # A face far behind everything hides nothing: every mode is unchanged.
    v = np.concatenate([CUBE_V, [[-50, -50, -30], [50, -50, -30], [50, 50, -30], [-50, 50, -30]]])
    cam = look_at((4.0, 3.0, 5.0), (0.0, 0.0, 0.0))
    clipped = look_at((1.5, 0.3, 1.4), (0.0, 0.0, 0.0), near=0.5)  # edges cut by near and the image
    for c in (cam, clipped):
        for mode in ("exact", "fast", "aa"):
            a = render_frame(v, CUBE_E, c, np.eye(4), faces=[(8, 9, 10, 11)], hidden_lines=True, raster=mode)
            b = render_frame(v, CUBE_E, c, np.eye(4), raster=mode)
            assert np.array_equal(a.image, b.image), mode
            assert a.hidden_pixels == 0 and np.isfinite(a.depth_image).any()


def test_defaults_are_unchanged_and_do_no_face_work(monkeypatch):
    cam = look_at((4.0, 3.0, 5.0), (0.0, 0.0, 0.0))
    plain = render_frame(CUBE_V, CUBE_E, cam, np.eye(4))

    def boom(*a, **k):
        raise AssertionError("face work in a plain wireframe")

    monkeypatch.setattr(zbuffer, "rasterize_triangles", boom)
    monkeypatch.setattr(pipeline, "_faces_stage", boom)
    with_faces = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F)
    assert np.array_equal(with_faces.image, plain.image)
    assert with_faces.depth_image is None and with_faces.shaded is None and with_faces.face_ids is None
    assert with_faces.faces_total == 6 and with_faces.faces_culled == 0 and with_faces.hidden_pixels == 0
    assert plain.faces_total == 0 and plain.faces_visible is None


def test_camera_inside_and_near_clipped_faces():
    # Inside the cube every edge is on the boundary of the faces around it: nothing hidden.
    cam = look_at((0.0, 0.0, 0.5), (0.0, 0.0, -1.0), near=0.1)
    fr = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, hidden_lines=True)
    plain = render_frame(CUBE_V, CUBE_E, cam, np.eye(4))
    assert fr.hidden_pixels == 0 and np.array_equal(fr.image, plain.image)
    assert np.isfinite(fr.depth_image).all()  # walls all around
    # Just outside a face, looking at it closely: everything behind it is hidden.
    cam = look_at((0.3, 0.2, 1.3), (0.0, 0.0, -1.0), near=0.1)
    fr = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, hidden_lines=True)
    assert not fr.mask.any() and fr.hidden_pixels == render_frame(CUBE_V, CUBE_E, cam, np.eye(4)).mask.sum()


def test_argument_checks():
    cam = look_at((4.0, 3.0, 5.0), (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="style"):
        render_frame(CUBE_V, CUBE_E, cam, np.eye(4), style="solid")
    with pytest.raises(ValueError, match="cull"):
        render_frame(CUBE_V, CUBE_E, cam, np.eye(4), cull="front")
    with pytest.raises(ValueError, match="out of range"):
        render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=[(0, 1, 9)], hidden_lines=True)


# ---- against pyrender -------------------------------------------------------------


def test_hidden_lines_against_pyrender(oracle, summary_section):
    """pyrender draws the faces black with glPolygonOffset(1, 1) and the lines on top.

    Our bias is that offset in linear depth (core.projector.hidden_lines), so the same line
    pixels pass. Measured on 16 poses of a cube and an icosphere, both
    projections: F1@1px = 1.000 everywhere and F1@0 >= 0.998 (a pixel or two of
    a few thousand differ where a line grazes a face and the float32/24-bit
    depth of GL decides the other way). Asserted: F1@1px >= 0.99 per frame.
    """
    trimesh = pytest.importorskip("trimesh")
    ico = trimesh.creation.icosphere(subdivisions=2)
    meshes = {
        "cube": (CUBE_V, CUBE_E, CUBE_F),
        "icosphere": (
            np.asarray(ico.vertices),
            np.asarray(ico.edges_unique),
            [tuple(f) for f in np.asarray(ico.faces)],
        ),
    }
    rng = np.random.default_rng(3)
    lines = []
    for name, (v, e, f) in meshes.items():
        for projection in ("perspective", "orthographic"):
            worst0, worst1 = 1.0, 1.0
            for _ in range(4):
                d = rng.normal(size=3)
                d /= np.linalg.norm(d)
                cam = look_at(
                    d * rng.uniform(4, 9), (0.0, 0.0, 0.0), near=0.5, far=50.0, projection=projection, ortho_height=4.0
                )
                ours = render_frame(v, e, cam, np.eye(4), faces=f, hidden_lines=True)
                theirs, _ = oracle.render(v, e, cam, faces=f)
                s = pixel_scores(ours.mask, theirs)
                worst0, worst1 = min(worst0, s["f1_0px"]), min(worst1, s["f1_1px"])
                assert s["f1_1px"] >= 0.99
                assert ours.hidden_pixels > 0
            lines.append(f"{name} {projection}: min F1@0 {worst0:.4f}, min F1@1 {worst1:.4f}")
    summary_section("hidden lines vs pyrender (faces + polygon offset)", "\n".join(lines))

"""core.projector.shading and render_frame(style="shaded"): flat Lambert shading on our own z-buffer."""

from __future__ import annotations

import math

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.shading import DEFAULT_AMBIENT, default_light_dir, face_intensity, shade

CUBE_V = np.array(
    [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float
)
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
CUBE_E = np.array(sorted({tuple(sorted((f[k], f[(k + 1) % 4]))) for f in CUBE_F for k in range(4)}))


def _level(intensity):
    return int(math.floor(255 * intensity + 0.5))


def test_lambert_levels_are_exact():
    # light travelling along -z at 60 degrees from the +z normal: cos = 1/2
    light = np.array([0.0, -math.sin(math.radians(60)), -math.cos(math.radians(60))])
    n = np.array([[0, 0, 1.0], [0, 0, -1.0], [0, 0, 7.0], [0, 0, 0.0]])
    i = face_intensity(n, light)
    a = DEFAULT_AMBIENT
    np.testing.assert_allclose(i, [a + (1 - a) * 0.5, a, a + (1 - a) * 0.5, a], rtol=1e-15)
    img = shade(np.array([[0, 1], [2, -1], [3, 0]], dtype=np.int32), n, light)
    # 255 (0.15 + 0.85 / 2) = 146.625 -> 147 (halves up); ambient 38.25 -> 38; no face -> 0
    assert img.tolist() == [[147, 38], [147, 0], [38, 147]] and img.dtype == np.uint8
    assert shade(np.zeros((1, 1), np.int32), n[:1], -n[0], ambient=0.0).item() == 255
    with pytest.raises(ValueError):
        shade(np.zeros((1, 1), np.int32), n[:1], [0.0, 0.0, 0.0])


def test_shaded_cube_face_has_the_exact_lambert_level():
    cam = look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0))
    for deg in (0.0, 30.0, 60.0, 75.0):
        light = np.array([math.sin(math.radians(deg)), 0.0, -math.cos(math.radians(deg))])
        fr = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, style="shaded", light_dir=light)
        cos = math.cos(math.radians(deg))  # front face normal (0, 0, 1) . (-light)
        expected = _level(DEFAULT_AMBIENT + (1 - DEFAULT_AMBIENT) * cos)
        front = fr.face_ids == 1
        assert front.sum() > 5000
        assert set(np.unique(fr.image[front])) == {expected}
        assert np.all(fr.image[fr.face_ids < 0] == 0)
        assert fr.shaded is fr.image and np.isfinite(fr.depth_image[front]).all()
        # the face ids seen from +Z: only the front face (the z-buffer decides)
        assert set(np.unique(fr.face_ids)) == {-1, 1}


def test_default_light_comes_from_the_cameras_upper_left():
    cam = look_at((4.0, 3.0, 5.0), (0.0, 0.0, 0.0))
    d = default_light_dir(cam)
    assert np.linalg.norm(d) == pytest.approx(1.0)
    # travels forward (into the scene), to the right and down the image
    assert d @ cam.forward > 0 and d @ cam.right > 0 and d @ cam.up < 0
    fr = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, style="shaded")
    lv = {f: set(np.unique(fr.image[fr.face_ids == f])) for f in (1, 3, 5)}
    assert all(len(v) == 1 for v in lv.values())  # flat: one level per face
    assert fr.faces_visible == 3
    # the top face (+y) faces the upper light more than the right face (+x) does
    assert lv[3].pop() > lv[5].pop()


def test_mirrored_model_keeps_outward_normals():
    # x -> -x maps the cube onto itself; with its winding reversed by the mirror,
    # the outward normals (and so the shading) must be those of the plain cube.
    cam = look_at((4.0, 3.0, 5.0), (0.0, 0.0, 0.0))
    plain = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, style="shaded")
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    mirrored = render_frame(CUBE_V, CUBE_E, cam, mirror, faces=CUBE_F, style="shaded")
    # Same faces and levels; the pixels agree exactly too (measured: 0 differ),
    # since the mirrored triangles are the same geometric triangles.
    assert np.array_equal(plain.image, mirrored.image)
    culled = render_frame(CUBE_V, CUBE_E, cam, mirror, faces=CUBE_F, style="shaded", cull="backface")
    assert culled.faces_culled == 3
    assert np.array_equal(culled.image, plain.image)


def test_backface_culling_does_not_change_a_closed_mesh():
    cam = look_at((4.0, -3.0, 5.0), (0.0, 0.0, 0.0), projection="orthographic", ortho_height=5.0)
    a = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, style="shaded")
    b = render_frame(CUBE_V, CUBE_E, cam, np.eye(4), faces=CUBE_F, style="shaded", cull="backface")
    assert np.array_equal(a.image, b.image) and b.faces_culled == 3 and a.faces_culled == 0


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_shaded_silhouette_against_pyrender(projection, pyrender_renderer, summary_section):
    """Silhouette of the shaded image vs pyrender's faces (white, flat, double sided).

    Both take pixel-centre coverage with vertices snapped to 1/256 px and the
    top-left rule, so they can only differ where a centre is within llvmpipe's
    float32 vertex error of an outline edge: measured 0 differing pixels
    (tests/test_zbuffer.py). Bound asserted: IoU >= 0.999.
    """
    import pyrender

    trimesh = pytest.importorskip("trimesh")

    from wirecheck.oracles.references.convert import camera_to_pyrender

    ico = trimesh.creation.icosphere(subdivisions=3)
    v, f = np.asarray(ico.vertices), np.asarray(ico.faces)
    cam = look_at((2.5, 1.8, 3.3), (0.0, 0.0, 0.0), near=0.5, far=20.0, projection=projection, ortho_height=3.0)
    fr = render_frame(v, np.asarray(ico.edges_unique), cam, np.eye(4), faces=[tuple(t) for t in f], style="shaded")
    scene = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
    mat = pyrender.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0], doubleSided=True)
    scene.add(
        pyrender.Mesh(
            [
                pyrender.Primitive(
                    positions=v.astype(np.float32),
                    indices=f.astype(np.uint32),
                    mode=pyrender.constants.GLTF.TRIANGLES,
                    material=mat,
                )
            ]
        )
    )
    pose, pc = camera_to_pyrender(cam)
    scene.add(pc, pose=pose)
    colour, _ = pyrender_renderer.render(scene, pyrender.RenderFlags.FLAT)
    theirs = colour[:, :, 0] > 127
    ours = fr.image > 0  # every face gets >= ambient 38 > 0
    iou = (ours & theirs).sum() / (ours | theirs).sum()
    summary_section(
        f"shaded silhouette vs pyrender ({projection})",
        f"IoU {iou:.6f}, {int((ours ^ theirs).sum())} px differ of {int(ours.sum())}",
    )
    assert iou >= 0.999

"""A real renderer's depth: moderngl on EGL, its depth attachment read back (tests/clients/moderngl_depth.py).

Drawn as a moderngl user would, in its own process, from the contract's OpenGL matrices, written
as float32 ``.npy`` and read by oracles.candidates.depth_map, on every bundled scene under
the seven default cameras (frame 2 of 7), and judged against pyrender's depth
(oracles.judge.depth_reference) by oracles.diagnosis.depth_faults: made linear, it passes; the
window depth stored as read is ``depth_encoding`` with the camera's near and far; GL's rows
written bottom first are ``mirror_vertical``. Skipped where moderngl's EGL context or OSMesa is
missing (failed under WIRECHECK_REQUIRE_EGL=1, as the other real-renderer tests).
"""

from __future__ import annotations

import helpers  # tests/ is on sys.path (rootdir conftest)
import pytest
from wirecheck.core.transforms import Motion

PROBE = "import moderngl; moderngl.create_standalone_context(backend='egl').release()"
MOTION = Motion(turns=(1.0, 1.0, 0.0))


@pytest.fixture(scope="module")
def judged(tmp_path_factory):
    helpers.require_renderer(PROBE, "moderngl on EGL")
    from wirecheck.oracles.references.pyrender_oracle import osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)
    folder = tmp_path_factory.mktemp("moderngl_depth")
    return helpers.depth_client_judged(
        folder,
        "moderngl_depth.py",
        lambda cam: {"projection_matrix": cam.projection_matrix, "view_matrix": cam.view_matrix},
        ("correct", "zbuffer", "no_flip"),
        MOTION,
    )


def test_correct_passes(judged):
    rows = [(n, c, d.verdict, d.measured.get("max_error_ratio")) for n, c, m, d, _ in judged if m is None]
    assert len(rows) == 21 and all(v == "pass" for _, _, v, _ in rows), rows
    assert all(d.measured["compared_px"] > 1000 for _, _, m, d, _ in judged if m is None)
    # measured: the largest error is 0.61 of the bound (its 24-bit buffer read as float32 by moderngl)
    assert max(r for *_, r in rows) > 0


def test_zbuffer_stored_is_depth_encoding(judged):
    for name, case, mistake, d, cam in judged:
        if mistake == "zbuffer":
            assert d.names == ("depth_encoding",), (name, case, d.names)
            p = d.faults[0].params
            assert p["stored"] == "window [0, 1]" and not p["reversed"]
            # near and far read back from float32 window depths of a 24-bit buffer: 1 % (measured: 5.5e-5 at most)
            assert p["near"] == pytest.approx(cam.near, rel=1e-2) and p["far"] == pytest.approx(cam.far, rel=1e-2)


def test_rows_not_flipped_is_mirror_vertical(judged):
    for name, case, mistake, d, _ in judged:
        if mistake == "no_flip":
            assert d.names == ("mirror_vertical",), (name, case, d.names)

"""The pyrender oracle and the viewer's oracle overlay draw at flat memory (issue 25, item 6).

pyrender keyed its shader programs by a ctypes pointer to the context, a new
object (equal to no other) on every call: each frame compiled and kept a new
program, 0.4-0.8 MB (measured here: 0.77 MB per 160x120 frame on OSMesa; the
issue: 0.4 MB a frame, 0.6 MB an overlay request). oracles/references/pyrender_programs.py
keys them by the context's address.

Memory is read from /proc/self/statm (resident pages) after a warm-up, so
that the one-time costs (shaders, Mesa's caches, numpy's) are paid before.

The bound: 0.05 MB per frame, 8x below the smallest leak measured (0.4 MB),
so a leak of one program per frame fails by 8x, yet 50 MB over 1,000 frames
leaves room for allocator noise (malloc arenas growing in steps of ~1 MB).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from wirecheck.core.camera import Camera
from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, osmesa_available

_OK, _WHY = osmesa_available()
needs_gl = pytest.mark.skipif(not _OK, reason=f"pyrender/OSMesa unavailable: {_WHY}")

#: MB per frame (module docstring: 8x below the 0.4 MB a frame that the leak cost).
MAX_GROWTH_MB_PER_FRAME = 0.05


def rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


TETRA = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
TETRA_EDGES = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])
TETRA_FACES = ((0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3))


def _camera(w=64, h=48):
    return Camera(
        position=(3.0, 2.0, 4.0),
        forward=(-3.0, -2.0, -4.0),
        up=(0.0, 1.0, 0.0),
        width=w,
        height=h,
        near=0.1,
        far=100.0,
        fov_y_deg=45.0,
    )


def _pose(k: int) -> np.ndarray:
    m = np.eye(4)
    c, s = np.cos(0.01 * k), np.sin(0.01 * k)
    m[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    return m


@needs_gl
def test_a_thousand_oracle_frames_grow_memory_by_less_than_0_05_mb_each():
    cam = _camera()
    with PyrenderOracle(cam.width, cam.height) as oracle:

        def frame(k):  # the three kinds of frame a case draws: lines, hidden lines, filled triangles
            if k % 3 == 0:
                return oracle.render(TETRA, TETRA_EDGES, cam, model_matrix=_pose(k))[0]
            if k % 3 == 1:
                return oracle.render(TETRA, TETRA_EDGES, cam, model_matrix=_pose(k), faces=TETRA_FACES)[0]
            return oracle.render_faces(TETRA, np.array(TETRA_FACES), cam, model_matrix=_pose(k))[0]

        for k in range(60):
            frame(k)
        programs = len(oracle._renderer._renderer._program_cache._program_cache)
        before = rss_mb()
        drawn = sum(int(frame(k).sum() > 0) for k in range(60, 1060))
        growth = (rss_mb() - before) / 1000
        assert drawn == 1000  # every frame drew the tetrahedron
        # one program per shader variant for the oracle's life, not one per frame
        assert len(oracle._renderer._renderer._program_cache._program_cache) == programs
    assert growth < MAX_GROWTH_MB_PER_FRAME, f"{growth:.3f} MB per frame"


@needs_gl
def test_the_viewer_overlay_grows_memory_by_less_than_0_05_mb_a_request(tmp_path):
    from wirecheck.core.app.cli import build_parser, settings_from_args
    from wirecheck.core.app.viewer import Viewer
    from wirecheck.oracles.live import LiveOverlay

    s = settings_from_args(
        build_parser().parse_args(["--frames", "10", "--width", "96", "--height", "72", "--out", str(tmp_path / "out")])
    )
    overlay = LiveOverlay()
    try:
        viewer = Viewer(s, overlay=overlay)

        def request(k):
            return viewer.respond([{"op": "orbit", "dx": 7, "dy": 3}, {"op": "step", "n": 1}], want_overlay=True)[
                "overlay"
            ]

        for k in range(30):
            request(k)
        before = rss_mb()
        verdicts = [request(k)["verdict"] for k in range(300)]
        growth = (rss_mb() - before) / 300
    finally:
        overlay.close()
    assert verdicts == ["pass"] * 300  # a real comparison each time: core agrees
    assert growth < MAX_GROWTH_MB_PER_FRAME, f"{growth:.3f} MB per request"

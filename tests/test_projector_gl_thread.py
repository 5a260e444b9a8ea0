"""A projector's frames with pyrender drawing on the run's GL thread (oracles.judge.case.ProjectorFrames).

pyrender draws a frame on the GL thread while this thread draws the candidate's frame and measures the
frame before; the drawings, and every number measured of them, must be those of pyrender drawing in
this thread when asked (the reference: a PyrenderOracle handed to run_case itself), in every drawing
mode, for core and for another projector; a failing frame must raise or end the case as before, and
leave no drawing running nor any thread behind.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles.candidates.candidate import load_candidate
from wirecheck.oracles.candidates.core_candidate import CoreCandidate, RenderMode
from wirecheck.oracles.cases import cases_for
from wirecheck.oracles.judge.case import run_case
from wirecheck.oracles.references.gl_thread import THREAD_NAME, GLThread, ThreadOracle
from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, osmesa_available
from wirecheck.oracles.tolerances import Tolerances

HAVE_OSMESA = osmesa_available()[0]
needs_gl = pytest.mark.skipif(not HAVE_OSMESA, reason="no OSMesa")
FAULTY = str(Path(__file__).parent / "data" / "faulty_projectors.py")
MOTION = Motion(turns=(0.1, 0.25, 0.0))


def _case(scene_name: str = "cube"):
    scene = load_scene(scene_name)
    case = next(c for c in cases_for(scene, MOTION) if c.name == "on_axis")
    return scene, case


def _run(oracle, candidate, mode: RenderMode, frames: int = 4):
    scene, case = _case()
    return run_case(scene, case, frames, candidate, MOTION, Tolerances(), pyrender_oracle=oracle, mode=mode)


def _workers() -> list:
    return [t for t in threading.enumerate() if t.name.startswith(THREAD_NAME)]


@needs_gl
@pytest.mark.parametrize(
    "mode",
    [
        RenderMode(),
        RenderMode(hidden_lines=True),
        RenderMode(hidden_lines=True, cull="backface"),
        RenderMode(style="shaded"),
        RenderMode(style="shaded", cull="backface"),
    ],
    ids=["plain", "hidden lines", "hidden lines, culled", "shaded", "shaded, culled"],
)
def test_cores_frames_are_measured_alike_with_pyrender_on_the_gl_thread(monkeypatch, mode):
    """Every field of the case's record and its worst frame's images are those of the same case with pyrender
    drawing in this thread; pyrender drew each frame on the GL thread."""
    threads: list = []
    for name in ("render", "render_faces"):
        method = getattr(PyrenderOracle, name)

        def spy(self, *args, _method=method, **kwargs):
            threads.append(threading.current_thread().name)
            return _method(self, *args, **kwargs)

        monkeypatch.setattr(PyrenderOracle, name, spy)
    _scene, case = _case()
    own = PyrenderOracle(case.camera.width, case.camera.height)
    try:
        expected = _run(own, CoreCandidate(), mode)
    finally:
        own.close()
    assert threads and all(not t.startswith(THREAD_NAME) for t in threads)
    threads.clear()
    gl = GLThread()
    try:
        got = _run(ThreadOracle(gl, case.camera.width, case.camera.height), CoreCandidate(), mode)
    finally:
        gl.close()
    assert len(threads) == 4 and all(t.startswith(THREAD_NAME) for t in threads)  # one drawing a frame, there
    assert got.record == expected.record
    for key in ("candidate", "oracle"):
        np.testing.assert_array_equal(got.worst_images[key], expected.worst_images[key])
    assert got.record["verdict"] == "pass"  # the frames compared: core matches pyrender
    assert _workers() == []


@needs_gl
def test_another_projectors_faults_are_measured_alike_with_pyrender_on_the_gl_thread():
    """A mirrored projector (drawn by the harness from its own ends): the same record, failing by the same
    fault, with pyrender on the GL thread or in this thread."""
    candidate = load_candidate(f"{FAULTY}:mirrored")
    _scene, case = _case()
    own = PyrenderOracle(case.camera.width, case.camera.height)
    try:
        expected = _run(own, candidate, RenderMode())
    finally:
        own.close()
    gl = GLThread()
    try:
        got = _run(ThreadOracle(gl, case.camera.width, case.camera.height), candidate, RenderMode())
    finally:
        gl.close()
    assert got.record == expected.record
    assert got.record["verdict"] == "fail"


class _Failing:
    """A stand-in OracleCache whose oracle draws frames but raises at its ``fail_at``-th drawing."""

    def __init__(self, fail_at: int):
        self.fail_at, self.calls, self.closed = fail_at, 0, False

    def get(self, width, height):
        return self

    def __contains__(self, size):
        return True

    def render(self, vertices, edges, camera, **kwargs):
        self.calls += 1
        if self.calls == self.fail_at:
            raise RuntimeError(f"GL failed at drawing {self.calls}")
        return np.zeros((camera.height, camera.width), bool), None

    def close(self):
        self.closed = True


@pytest.mark.parametrize("threaded", [False, True], ids=["in this thread", "on the GL thread"])
def test_a_drawing_that_fails_raises_at_its_frame_and_leaves_no_thread(threaded):
    """pyrender failing at the second frame's drawing (asked for while the first frame is measured) raises
    its error when that frame is measured, with the GL thread or without it; the thread is closed after."""
    oracles = _Failing(fail_at=2)
    gl = GLThread(oracles, threaded=threaded)
    _scene, case = _case()
    oracle = ThreadOracle(gl, case.camera.width, case.camera.height) if threaded else oracles
    try:
        with pytest.raises(RuntimeError, match="GL failed at drawing 2"):
            _run(oracle, CoreCandidate(), RenderMode(), frames=3)
    finally:
        gl.close()
    assert oracles.closed and _workers() == []


def _fails_at_second_frame():
    """A projector that answers the first frame and raises at the second (its calls counted)."""
    sys.path.insert(0, str(Path(FAULTY).parent))
    from user_projector import project

    calls = {"n": 0}

    def candidate(points, camera):
        calls["n"] += 1
        if calls["n"] > 2:  # the first frame: its points, then its clipped ends
            raise ValueError("boom")
        return project(points, camera)

    return candidate


def test_a_candidate_failing_at_a_frame_ends_the_case_there_and_drops_the_drawing_asked_for():
    """A projector raising at frame 2 ends the case with frame 1 measured, as without the thread; frame 2's
    drawing (asked for before the projector was called) is dropped, not waited for, and frame 3's never
    asked for."""
    oracles = _Failing(fail_at=10**9)
    gl = GLThread(oracles)
    _scene, case = _case()
    try:
        result = _run(ThreadOracle(gl, case.camera.width, case.camera.height), _fails_at_second_frame(), RenderMode())
    finally:
        gl.close()
    assert result.record["frames_checked"] == 1
    assert "frame 2" in str(result.record) and "boom" in str(result.record)  # the error names its frame
    assert oracles.calls <= 2  # frames 1 and 2 at most: nothing after the failing frame
    assert _workers() == []


@pytest.fixture(scope="module")
def icosphere(tmp_path_factory):
    """An icosphere of 5,120 faces (7,680 edges) as a PLY: ~20,000 drawn pixels a 640x480 frame, over
    case.OWNERS_AHEAD_PX and segment_pixels.KERNEL_PIXELS (the large-frame paths)."""
    import trimesh

    path = tmp_path_factory.mktemp("ico") / "ico4.ply"
    trimesh.creation.icosphere(subdivisions=4).export(path)
    return load_scene(str(path))


@needs_gl
@pytest.mark.parametrize("projector", ["core", "mirrored"])
def test_a_large_frame_is_measured_alike_with_its_metrics_made_beside_pyrender(monkeypatch, icosphere, projector):
    """On a large frame the candidate pixels' owners are found while pyrender draws (compiled) and the frame's
    pixels and their places are made on the GL thread after its drawing (case.pixels_beside): the record is
    that of pyrender drawing in this thread, where none of that is done beside (the numpy pairing throughout)."""
    from wirecheck.oracles.judge import case as case_module
    from wirecheck.oracles.judge import segment_pixels

    calls = {"beside": 0}
    sizes: list = []
    made = case_module.pixels_beside

    def counted(*args):
        calls["beside"] += 1
        out = made(*args)
        sizes.append(len(out[0].oracle_idx))
        return out

    monkeypatch.setattr(case_module, "pixels_beside", counted)
    candidate = CoreCandidate() if projector == "core" else load_candidate(f"{FAULTY}:mirrored")
    case = next(c for c in cases_for(icosphere, MOTION) if c.name == "on_axis")

    def run(oracle):
        return run_case(icosphere, case, 3, candidate, MOTION, Tolerances(), pyrender_oracle=oracle)

    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 10**9)  # the reference: the numpy pairing
    own = PyrenderOracle(case.camera.width, case.camera.height)
    try:
        expected = run(own)
    finally:
        own.close()
    assert calls["beside"] == 0
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 1 << 13)
    gl = GLThread()
    try:
        got = run(ThreadOracle(gl, case.camera.width, case.camera.height))
    finally:
        gl.close()
    assert calls["beside"] == 3  # each frame's pixels made beside
    assert got.record == expected.record
    frames = got.record["per_frame"]
    assert min(sizes) >= 1 << 13  # the frames are large
    if projector == "core":
        assert got.record["verdict"] == "pass"
        assert sum(f["candidate_only"] + f["oracle_only"] for f in frames) > 0  # one-sided pixels placed
    else:
        assert got.record["verdict"] == "fail"

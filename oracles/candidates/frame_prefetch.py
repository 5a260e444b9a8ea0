"""The frames judge's reading ahead: a frame's inputs, its pyrender drawing and its PNG's grey levels, made
on the run's GL thread while the judge scores the frames before it.

The judge's own work on frame ``k`` (numpy) and the oracle's drawing of frame
``k + 1`` (pyrender on OSMesa/EGL: much of it inside the GL library, which
PyOpenGL's ctypes calls run without the GIL) and the decoding of its PNG
(zlib, also without the GIL) then overlap, on two cores. A job with filled
frames or depth maps has more of the judge's work that needs the frame's geometry
and pyrender's drawing alone made there too, after its drawing (``reference``:
numpy, whose array loops run without the GIL): the depth reference where the
job asks for depth maps, else the fill rule's silhouette (oracles.judge.frames_judge
chooses, to keep the two threads' work near even).

What stays as it was:

- **One GL thread.** Every GL call of a run is made on the references' one
  GL thread (oracles.references.gl_thread.GLThread: the oracles made, used
  and closed there, first in, first out); this module only says what is read
  ahead on it, and when.
- **The same bytes.** Each frame's inputs, drawing and grey levels are
  computed by the same functions on the same files, one frame after the other,
  as without the thread; only when they are computed changes.
- **The same errors, at the same frame.** What a frame's reading raises
  (a camera file, the oracle, a PNG that cannot be decoded: FramesError,
  listing every problem of the job as :func:`oracles.candidates.frames_candidate.read_frame`
  does) is kept with that frame and raised in the judge's thread when the judge
  reaches that step of that frame, so frames before it are judged first and
  the message is the same.
- **Flat memory.** At most :data:`AHEAD` frames are read ahead of the one
  being judged (a 640x480 frame: ~0.3 MB of drawing and of grey levels).
- **Nothing left running.** :meth:`FramePrefetch.close` (``run_frames``' ``finally``,
  on an error or Ctrl-C too) drops the frames not yet begun, waits for the one
  being read (milliseconds), closes the oracles on the worker and joins it.

:func:`reader_for` gives judge_case the same reading without a thread when it
is handed an OracleCache (its callers' older form).
"""

from __future__ import annotations

from concurrent.futures import Future
from functools import partial
from pathlib import Path

from ..references.faces import fan
from ..references.gl_thread import GLThread
from .export import job_outputs
from .frames_candidate import frame_faces, frame_inputs, read_frame

#: Frames read ahead of the one being judged (each: the oracle's drawing and the PNG's grey levels).
AHEAD = 2


class FrameAhead:
    """One frame as read ahead: each step's result, or the exception it raised (raised again when asked)."""

    __slots__ = ("_inputs", "_oracle", "_grey", "_faces", "_reference")

    def __init__(self, inputs, oracle, grey, faces=None, reference=None):
        self._inputs, self._oracle, self._grey, self._faces = inputs, oracle, grey, faces
        self._reference = reference

    @staticmethod
    def _value(step):
        if isinstance(step, BaseException):
            raise step
        return step

    def inputs(self) -> tuple:
        """``(p_model, edges, camera, model_matrix)`` (oracles.candidates.frames_candidate.frame_inputs)."""
        return self._value(self._inputs)

    def oracle(self):
        """pyrender's drawing of the frame: ``(H, W)`` bool, its line pixels (None: the job asks for no wireframe)."""
        return self._value(self._oracle)

    def grey(self):
        """The frame's PNG as grey levels (oracles.candidates.frames_candidate.read_frame; None: no wireframe)."""
        return self._value(self._grey)

    def faces(self):
        """pyrender's drawing of the frame's faces, ``(covered, depth, ids, triangles, faces)``
        (PyrenderOracle.render_faces with ids, of the OBJ's ``faces`` fanned: ``triangles`` (T, 3)); None when
        the job asks for no filled frame nor depth map."""
        return self._value(self._faces)

    def reference(self):
        """What the judge's ``reference`` made of the frame's drawing of its faces (:meth:`FramePrefetch.frames`);
        None when it was given none."""
        return self._value(self._reference)


def read_ahead(oracles, job_dir, job, c: dict, k: int, rel: str | None, cache: dict, reference=None) -> FrameAhead:
    """Frame ``k`` of case ``c`` read as the judge reads it, each step's exception kept in its place.

    The steps run in the judge's order: the frame's inputs, pyrender's
    drawing, the PNG (``rel``: the wireframe's, None when the job asks for no
    wireframe), then pyrender's drawing of the faces when the job asks for filled
    frames or depth maps, then ``reference(inputs, faces)`` of the frame's inputs and that
    drawing when given (the judge's own work on them, done here beside its work on the
    frames before: :meth:`FramePrefetch.frames`); a step that fails ends the frame's
    reading (the judge raises it before it would need the next).
    """
    try:
        inputs = frame_inputs(job_dir, job, c["scene"], c["case"], k, cache)
    except Exception as exc:  # noqa: BLE001 - raised again in the judge's thread, at this frame
        return FrameAhead(exc, None, None)
    p_model, edges, camera, m = inputs
    orac = grey = None
    if rel is not None:
        try:
            orac = oracles.get(camera.width, camera.height).render(p_model, edges, camera, model_matrix=m, depth=False)[
                0
            ]
        except Exception as exc:  # noqa: BLE001
            return FrameAhead(inputs, exc, None)
        try:
            grey = read_frame(Path(job_dir) / rel, c["width"], c["height"], (job_dir, job))
        except Exception as exc:  # noqa: BLE001
            return FrameAhead(inputs, orac, exc)
    if not set(job_outputs(job)) & {"filled", "depth"}:
        return FrameAhead(inputs, orac, grey)
    try:
        polygons = frame_faces(job_dir, job, c["scene"], k, cache)
        if cache.get("fanned") is not polygons:  # a model-space scene's faces: fanned once a case
            cache.update(fanned=polygons, tris=fan(polygons)[0])
        tris = cache["tris"]
        drawn = oracles.get(camera.width, camera.height).render_faces(
            p_model, tris, camera, model_matrix=m, with_ids=True
        )
        faces = (*drawn, tris, polygons)
    except Exception as exc:  # noqa: BLE001
        return FrameAhead(inputs, orac, grey, exc)
    made = None
    if reference is not None:
        try:
            made = reference(inputs, faces)
        except Exception as exc:  # noqa: BLE001
            made = exc
    return FrameAhead(inputs, orac, grey, faces, made)


class FramePrefetch:
    """The frames of a run read :data:`AHEAD` ahead on the run's GL thread (oracles.references.gl_thread), which
    owns every GL call (module docstring).

    ``oracles``: the run's OracleCache (made here when None); it is used and
    closed on the GL thread only. ``threaded=False`` reads each frame in the
    calling thread when it is asked for (the same results, nothing overlapped).
    """

    def __init__(self, oracles=None, threaded: bool = True, ahead: int = AHEAD):
        self.gl = GLThread(oracles, threaded)
        self.ahead = int(ahead)

    @property
    def oracles(self):
        """The run's OracleCache (used on the GL thread only)."""
        return self.gl.oracles

    def call(self, fn, *args):
        """``fn(*args)`` on the GL thread, waited for (``gl_info``)."""
        return self.gl.call(fn, *args)

    def frames(self, job_dir, job, c: dict, numbers: list, reference=None):
        """Case ``c``'s frames (``numbers``, ``c["frames"]`` in order) as :class:`FrameAhead`, read ahead.

        ``reference``: a function of a frame's inputs and pyrender's drawing of its faces (:meth:`FrameAhead.inputs`,
        :meth:`FrameAhead.faces`) run on the worker after the drawing (the fill rule's silhouette: the judge's
        work that needs only the frame's geometry), its result or exception kept for :meth:`FrameAhead.reference`.
        It must not share state with the judge's thread."""
        cache: dict = {}  # frame_inputs' OBJ and camera, kept over the case (used on the worker only)
        todo = iter(zip(numbers, c["frames"] or [None] * len(numbers)))  # no wireframe asked: no PNG
        queued: list[Future] = []
        read = read_ahead if reference is None else partial(read_ahead, reference=reference)
        if not self.gl.threaded:  # read each frame when it is asked for
            for k, rel in todo:
                yield read(self.oracles, job_dir, job, c, k, rel, cache)
            return
        try:
            while True:
                while len(queued) <= self.ahead:
                    nxt = next(todo, None)
                    if nxt is None:
                        break
                    queued.append(self.gl.submit(read, self.oracles, job_dir, job, c, nxt[0], nxt[1], cache))
                if not queued:
                    return
                yield queued.pop(0).result()
        finally:
            for f in queued:  # the judge stopped early (an error): drop what it will not ask for
                f.cancel()

    def close(self) -> None:
        """Drop the frames not begun, close the oracles (on the GL thread) and join it; no thread is left."""
        self.gl.close()


def reader_for(oracles) -> FramePrefetch:
    """judge_case's reader: ``oracles`` itself when it is a FramePrefetch, else one reading in this thread."""
    return oracles if isinstance(oracles, FramePrefetch) else FramePrefetch(oracles, threaded=False)

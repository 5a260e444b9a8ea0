"""The viewer's oracle overlay: crosscheck for the one view on the screen.

:class:`LiveOverlay` runs :func:`oracles.judge.case.run_case` (crosscheck's own case
runner) on the viewer's camera for its current frame only (``first=k,
every=frames``), so its F1@0/@1, vertex error, faults and verdict are the ones
crosscheck reports for that view. It returns pyrender's frame and the diff
(white both, red core only, blue oracle only; oracles.judge.metrics.diff_image) as
PNGs for the page.

Every OpenGL call runs on one worker thread: an OSMesa context is made current
on the thread that renders, and the HTTP server answers each request on a new
thread.
"""

from __future__ import annotations

import base64
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from wirecheck.core.outputs.output import png_bytes

from .candidates.core_candidate import CoreCandidate, RenderMode
from .cases import Case
from .judge import metrics
from .judge.case import run_case
from .references.pyrender_oracle import OracleCache, osmesa_available
from .reports.fault_text import case_cell
from .tolerances import Tolerances


def _b64_png(image: np.ndarray) -> str:
    return base64.b64encode(png_bytes(image)).decode("ascii")


class LiveOverlay:
    """``overlay(settings, camera, frame) -> dict`` for :class:`wirecheck.core.app.viewer.Viewer`."""

    def __init__(self):
        ok, message = osmesa_available()
        if not ok:
            raise RuntimeError(message)
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="wirecheck-oracle")
        self._cache = OracleCache()

    def __call__(self, s, camera, frame: int) -> dict:
        return self._pool.submit(self._run, s, camera, frame).result()

    def _run(self, s, camera, frame: int) -> dict:
        mode = RenderMode(style=s.style, hidden_lines=s.hidden_lines, cull=s.cull or "none")
        cand = CoreCandidate(dtype=s.dtype, clip=s.clip, raster=s.raster)
        res = run_case(
            s.scene,
            Case("interactive", camera),
            s.frames,
            cand,
            s.motion,
            Tolerances(),
            pyrender_oracle=self._cache.get(camera.width, camera.height),
            want_images=True,
            every=s.frames,
            mode=mode,
            first=frame,
        )
        rec = res.record
        out = {
            "frame": frame,
            "verdict": rec["verdict"],
            "reasons": rec["reasons"],
            "f1_0px": rec.get("pixel_f1_0px"),
            "f1_1px": rec.get("pixel_f1_1px"),
            "max_vertex_error_px": rec.get("max_vertex_error_px"),
            "faults": [f["name"] for f in rec["faults"]],
            "faults_text": case_cell(rec["faults"], rec.get("camera_spec")),
            "silhouette_iou": rec.get("silhouette_iou"),
            "depth_error_ratio": rec.get("depth_error_ratio"),
            "oracle_image": None,
            "diff_image": None,
        }
        if res.worst_images is not None:
            cand_img, orac_img = res.worst_images["candidate"], res.worst_images["oracle"]
            out["oracle_image"] = _b64_png(np.where(orac_img, 255, 0).astype(np.uint8))
            out["diff_image"] = _b64_png(metrics.diff_image(cand_img, orac_img))
        return out

    def close(self) -> None:
        self._pool.submit(self._cache.close).result()
        self._pool.shutdown(wait=True)

"""Weigh OpenCV 5 as a second reference (docs/depth.md, "OpenCV 5 as a second reference", cites this run).

The project pins ``opencv-contrib-python-headless < 5``; this script runs in a separate
environment whose cv2 is 5.x (docs/depth.md says how to make one) and measures two things:

1. **The vertex path** (``--vertices``): ``crosscheck --level vertices`` (``cv2.projectPoints``)
   over the bundled scenes, the default and the calibrated cases, and each faulty projector of
   ``tests/data/faulty_projectors.py`` over every case; with ``--baseline PYTHON`` the same runs
   under that interpreter (one whose cv2 is 4.x) and each case of the two reports compared:
   verdict, faults, max vertex error, worst vertex, every per-frame field. One line per run.
2. **The rasterizer** (``--depth``): ``cv2.triangleRasterizeDepth`` (the 3d module) drawing
   each bundled scene's faces, frames 1..7 of 7, under every default case camera it can express,
   in both of its modes: ``RASTERIZE_COMPAT_DISABLED`` (linear float32 depth out) and
   ``RASTERIZE_COMPAT_INVDEPTH`` (GL's window depth, made linear here in float64). Each map is
   judged against pyrender's depth (oracles.judge.depth_reference) by
   oracles.diagnosis.depth_faults, and its coverage compared with pyrender's: the pixels only
   one of them covers, and how far each such pixel's centre lies from the nearest projected
   triangle edge (a centre on an edge is a tie that GL's top-left rule gives to one side only,
   and OpenCV's inclusive test to both). One line per case camera.

    /tmp/cv5/bin/python benchmarks/measure_opencv5.py [--vertices] [--depth] [--baseline PYTHON]

With neither flag, both: about 2.5 minutes for the vertex runs with a baseline and 0.5 to 4 for the
rasterizer's 252 maps, on 2 shared cores. The rasterizer has a vertical FOV and nothing else: no orthographic
projection and no principal point off the centre, so the orthographic case is reported as not
expressible. Exits 2 with one line where cv2 is not 5.x (or has no ``triangleRasterizeDepth``).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles.cases import case_motion, cases_for
from wirecheck.oracles.diagnosis.depth_faults import name_depth_faults
from wirecheck.oracles.judge.depth_reference import reference_depth
from wirecheck.oracles.references import faces as oface
from wirecheck.oracles.references.convert import centre_of, gl_eye_pose

ROOT = Path(__file__).resolve().parents[1]

VERTEX_RUNS = [
    ("core, default cases", ["--cases", "default"]),
    ("core, calibrated cases", ["--cases", "calibrated"]),
] + [
    (
        f"faulty_projectors.py:{f}, all cases",
        ["--cases", "all", "--frames", "6", "--candidate", str(ROOT / "tests" / "data" / f"faulty_projectors.py:{f}")],
    )
    for f in (
        "mirrored",
        "horizontal_fov",
        "offset_when_large",
        "no_clipping",
        "fixed_orientation",
        "depth_clamped",
        "divides_before_clipping",
        "clips_at_camera",
    )
]
SCENES = ("cube", "prism", "pyramid")
FRAMES = 7
#: a differing pixel whose centre is this close to a projected edge is a tie: llvmpipe snaps
#: vertices to 1/256 px (core.projector.raster.SUBPIXEL), so an edge moves by up to half that.
TIE_PX = 1.0 / 256


def _vertex_report(python: str, args: list) -> dict:
    """report.json's cases and verdict of ``crosscheck --level vertices ARGS`` under ``python``."""
    with tempfile.TemporaryDirectory() as tmp:
        code = "import sys; from wirecheck.oracles.cli import main; sys.exit(main(sys.argv[1:]))"
        proc = subprocess.run(
            [python, "-c", code, "--level", "vertices", "--report-dir", tmp, *args],
            capture_output=True,
            text=True,
            cwd=ROOT,
        )
        if proc.returncode not in (0, 1):
            raise SystemExit(
                f"measure_opencv5: crosscheck under {python} exited {proc.returncode}: "
                f"{(proc.stderr.strip().splitlines() or ['no output'])[-1]}"
            )
        report = json.loads((Path(tmp) / "report.json").read_text())
    return {"verdict": report["verdict"], "cases": report["cases"]}


def _cv2_version(python: str) -> str:
    return subprocess.run(
        [python, "-c", "import cv2; print(cv2.__version__)"], capture_output=True, text=True, check=True
    ).stdout.strip()


def measure_vertices(baseline: str | None) -> None:
    print(
        f"vertex path: cv2 {_cv2_version(sys.executable)} here"
        + (f", cv2 {_cv2_version(baseline)} under {baseline}" if baseline else "")
    )
    for label, args in VERTEX_RUNS:
        here = _vertex_report(sys.executable, args)
        worst = max((c["max_vertex_error_px"] or 0.0) for c in here["cases"])
        faults = sorted({f["name"] for c in here["cases"] for f in c["faults"]})
        line = (
            f"  {label:48s} {here['verdict']:4s} {len(here['cases']):2d} cases, max vertex error "
            f"{worst:.3e} px, faults {','.join(faults) or '-'}"
        )
        if baseline:
            base = _vertex_report(baseline, args)
            same = sum(a == b for a, b in zip(here["cases"], base["cases"]))
            moved = max(
                abs((a["max_vertex_error_px"] or 0.0) - (b["max_vertex_error_px"] or 0.0))
                for a, b in zip(here["cases"], base["cases"])
            )
            line += (
                f"; baseline {base['verdict']}, {same}/{len(here['cases'])} cases identical, "
                f"max error moved {moved:.1e} px"
            )
        print(line)


def _opencv_depth(vertices, triangles, eye_pose, camera, mode) -> tuple[np.ndarray, np.ndarray]:
    """``(covered, depth)`` of ``cv2.triangleRasterizeDepth`` in ``mode``; depth float64, linear."""
    import cv2

    settings = cv2.TriangleRasterizeSettings()
    settings.setCullingMode(cv2.RASTERIZE_CULLING_NONE)  # pyrender draws both sides too
    settings.setShadingType(cv2.RASTERIZE_SHADING_WHITE)
    settings.setGlCompatibleMode(mode)
    n, f = float(camera.near), float(camera.far)
    inv = mode == cv2.RASTERIZE_COMPAT_INVDEPTH

    def draw(tris):
        # an empty buffer is far (1.0 in window depth), as the function's documentation asks
        buf = np.full((camera.height, camera.width), 1.0 if inv else f, dtype=np.float32)
        return np.asarray(
            cv2.triangleRasterizeDepth(
                np.ascontiguousarray(vertices, dtype=np.float32),
                np.ascontiguousarray(tris, dtype=np.int32),
                buf,
                np.ascontiguousarray(eye_pose, dtype=np.float64),
                math.radians(camera.fov_y_deg),
                n,
                f,
                settings,
            ),
            dtype=np.float64,
        )

    out = draw(triangles)
    # covered: what a triangle wrote, against what an empty draw leaves (COMPAT_DISABLED's far goes
    # through float32 window depth and back, not exactly far)
    covered = out != draw(np.zeros((0, 3)))
    depth = n * f / (f - out * (f - n)) if inv else out  # window depth to depth along forward
    return covered, np.where(covered, depth, np.nan)


def _edge_distance(pixels_yx: np.ndarray, p_px: np.ndarray, in_front: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """``(N,)``: each pixel centre's distance (px) to the nearest edge of a triangle wholly in front."""
    if len(pixels_yx) == 0:
        return np.zeros(0)
    keep = in_front[triangles].all(axis=1)
    tri = triangles[keep]
    a = np.concatenate([p_px[tri[:, 0]], p_px[tri[:, 1]], p_px[tri[:, 2]]])
    b = np.concatenate([p_px[tri[:, 1]], p_px[tri[:, 2]], p_px[tri[:, 0]]])
    q = pixels_yx[:, ::-1].astype(np.float64)[:, None, :]  # (N, 1, 2) as x, y
    ab = (b - a)[None]
    t = np.clip(((q - a[None]) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0.0, 1.0)
    return np.linalg.norm(q - (a[None] + t[..., None] * ab), axis=-1).min(axis=1)


def _tally(rows) -> dict:
    """Verdicts (a fail by its names), the largest error / bound, pixels compared, coverage differences."""
    verdicts = {}
    for d, *_ in rows:
        key = d.verdict if d.verdict != "fail" else ",".join(d.names)
        verdicts[key] = verdicts.get(key, 0) + 1
    dists = np.concatenate([r[3] for r in rows]) if rows else np.zeros(0)
    return {
        "maps": len(rows),
        "verdicts": verdicts,
        "worst": max((d.measured.get("max_error_ratio", 0.0) for d, *_ in rows), default=0.0),
        "compared": sum(d.measured["compared_px"] for d, *_ in rows),
        "cv_only": sum(r[1] for r in rows),
        "gl_only": sum(r[2] for r in rows),
        "ties": int((dists <= TIE_PX).sum()),
        "max_dist": float(dists.max()) if len(dists) else 0.0,
    }


def _line(label: str, t: dict) -> str:
    verdicts = " ".join(f"{k}:{v}" for k, v in sorted(t["verdicts"].items()))
    return (
        f"  {label:30s} {verdicts:28s} {t['worst']:11.3g} {t['compared']:9,d} {t['cv_only']:7d} "
        f"{t['gl_only']:7d} {t['ties']:5d} {t['max_dist']:9.2e}"
    )


def measure_depth() -> None:
    import cv2
    from wirecheck.oracles.references.pyrender_oracle import OracleCache, osmesa_available  # GL: lazily

    ok, msg = osmesa_available()
    if not ok:
        raise SystemExit(f"measure_opencv5: pyrender cannot render here ({msg})")
    motion = Motion(turns=(1.0, 1.0, 0.0))
    modes = {"linear": cv2.RASTERIZE_COMPAT_DISABLED, "window": cv2.RASTERIZE_COMPAT_INVDEPTH}
    eps32 = float(np.finfo(np.float32).eps)
    print(
        f"rasterizer: cv2.triangleRasterizeDepth (cv2 {cv2.__version__}), frames 1..{FRAMES} of {FRAMES}, "
        "against pyrender's depth; modes linear (COMPAT_DISABLED: its float32 depth) and window "
        "(COMPAT_INVDEPTH: window depth made linear here); '+near': frames with a triangle across the near plane"
    )
    print(
        f"  {'scene / camera / mode':30s} {'verdicts':28s} {'err/bound':>11s} {'compared':>9s} {'cv only':>7s} "
        f"{'gl only':>7s} {'ties':>5s} {'edge dist':>9s}"
    )
    every = {(m, x): [] for m in modes for x in (False, True)}  # (mode, crosses near): rows
    cache = OracleCache()
    try:
        for name in SCENES:
            scene = load_scene(name)
            tris, _ = oface.fan(scene.faces)
            for case in cases_for(scene):
                cam = case.camera
                if cam.projection != "perspective":
                    print(f"  {name + ' / ' + case.name:30s} not expressible: the rasterizer takes a vertical FOV only")
                    continue
                rows = {key: [] for key in every}
                for k in range(1, FRAMES + 1):
                    ref = reference_depth(cache.get(cam.width, cam.height), scene, case, motion, k, FRAMES)
                    p_world, matrices, pr_vertices, pr_pose = oface.frame_geometry(
                        scene, case_motion(motion, case), (k - 1) / FRAMES
                    )
                    centre = centre_of(pr_vertices)
                    eye = gl_eye_pose(cam, pr_pose, centre)
                    gl_tris = oface.gl_triangles(tris, oface.mirrored_vertices(scene, matrices))
                    p_cv = (np.asarray(p_world, dtype=np.float64) - cam.position) @ np.asarray(cam.R).T
                    in_front = p_cv[:, 2] > cam.near
                    crosses = bool((~in_front[tris]).any())
                    k_mat = np.asarray(cam.K, dtype=np.float64)
                    p_px = (
                        p_cv[:, :2] / np.where(in_front, p_cv[:, 2], 1.0)[:, None] * np.diag(k_mat)[:2] + k_mat[:2, 2]
                    )
                    for mode, flag in modes.items():
                        covered, depth = _opencv_depth(np.asarray(pr_vertices) - centre, gl_tris, eye, cam, flag)
                        enc = eps32 * np.abs(np.nan_to_num(depth)) if mode == "linear" else 0.0  # float32 out
                        d = name_depth_faults(
                            depth, ref.compared_depth(), ref.bound, cam, enc, faces=ref.compared_faces()
                        )
                        differ = covered ^ ref.covered
                        dist = _edge_distance(np.argwhere(differ), p_px, in_front, tris)
                        rows[mode, crosses].append(
                            (d, int((covered & ~ref.covered).sum()), int((ref.covered & ~covered).sum()), dist)
                        )
                for (mode, crosses), rs in rows.items():
                    if rs:
                        print(_line(f"{name} / {case.name} / {mode}{' +near' if crosses else ''}", _tally(rs)))
                    every[mode, crosses] += rs
    finally:
        cache.close()
    print("  all:")
    for (mode, crosses), rs in every.items():
        print(_line(f"{mode}{' +near' if crosses else ''}", _tally(rs)))


def run(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vertices", action="store_true", help="measure the vertex path (projectPoints)")
    ap.add_argument("--depth", action="store_true", help="measure cv2.triangleRasterizeDepth against pyrender")
    ap.add_argument("--baseline", metavar="PYTHON", help="an interpreter whose cv2 is 4.x, for the vertex runs")
    args = ap.parse_args(argv)
    try:
        import cv2
    except ImportError as exc:
        print(f"measure_opencv5: cv2 is not importable ({exc})", file=sys.stderr)
        return 2
    if int(cv2.__version__.split(".")[0]) < 5 or not hasattr(cv2, "triangleRasterizeDepth"):
        print(
            f"measure_opencv5: cv2 {cv2.__version__} here; this measures OpenCV 5 (run it in an environment "
            "with opencv-contrib-python-headless 5.x: docs/depth.md)",
            file=sys.stderr,
        )
        return 2
    both = not (args.vertices or args.depth)
    if args.vertices or both:
        measure_vertices(args.baseline)
    if args.depth or both:
        measure_depth()
    return 0


if __name__ == "__main__":
    raise SystemExit(run())

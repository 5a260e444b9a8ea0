"""Speed against accuracy: projecting in float64 vs float32, at the extremes.

For each stress case, the same world points are projected by

- ``ours f64``: ``core.projector.projection.project_points(dtype="float64")`` (the default);
- ``ours f32``: ``project_points(dtype="float32")``: camera-relative, the camera
  position subtracted in float64 before the cast (core/projector/projection.py);
- ``naive f32``: the same formula in float32 *without* the camera-relative
  step (points and position cast first), what a projector that stores world
  coordinates and matrices in float32, as GPUs and many engines do, gets;
- ``opencv f64`` / ``opencv f32``: cv2.projectPoints fed float64 / float32;

and compared with an extended-precision reference (``np.longdouble``, 64-bit
mantissa on x86-64) computed from the conventions, in one run. It prints the
max pixel error and the time per call, so the trade is visible.

    python benchmarks/bench_precision.py [--json PATH]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from wirecheck.core.camera import look_at  # noqa: E402
from wirecheck.core.projector.projection import project_points  # noqa: E402
from wirecheck.oracles.extremes import reference_project  # noqa: E402
from wirecheck.oracles.references import opencv_oracle  # noqa: E402
from wirecheck.oracles.references.convert import camera_to_opencv  # noqa: E402


def reference(p_world, camera):
    """The conventions' formula in np.longdouble, NaN outside [near, far] (oracles.extremes)."""
    return reference_project(p_world, camera)[1].astype(np.float64)


def project_f32(p_world, camera):
    return project_points(p_world, camera, dtype="float32")


def naive_f32(p_world, camera):
    """core's formula, in float32 throughout, position cast before subtracting."""
    p = np.asarray(p_world, np.float32)
    r = np.stack([camera.right, camera.up, camera.forward]).astype(np.float32)
    p_cam = (p - camera.position.astype(np.float32)) @ r.T
    z = p_cam[:, 2]
    vis = (z >= np.float32(camera.near)) & (z <= np.float32(camera.far))
    f = np.float32(camera.focal_px)
    cx, cy = (np.float32(c) for c in camera.principal_point)
    out = np.full((len(p), 2), np.nan, np.float32)
    out[vis, 0] = cx + f * p_cam[vis, 0] / z[vis]
    out[vis, 1] = cy - f * p_cam[vis, 1] / z[vis]
    return out.astype(np.float64)


def opencv_f32(p_world, camera):
    import cv2

    rvec, tvec, k = camera_to_opencv(camera)
    vis = ~np.isnan(opencv_oracle.project(p_world, camera)[:, 0])
    out = np.full((len(p_world), 2), np.nan)
    if vis.any():
        px, _ = cv2.projectPoints(
            np.asarray(p_world[vis], np.float32),
            rvec.astype(np.float32),
            tvec.astype(np.float32),
            k.astype(np.float32),
            None,
        )
        out[vis] = px.reshape(-1, 2)
    return out


def sphere(n, radius, rng):
    v = rng.normal(size=(n, 3))
    return radius * v / np.linalg.norm(v, axis=1, keepdims=True)


def cases(rng):
    n = 40_962
    unit = sphere(n, 1.0, rng)
    yield "baseline: unit sphere at 4", unit, look_at((0.3, 0.4, 4), (0, 0, 0), (0, 1, 0), fov_y_deg=60)
    yield (
        "huge coords: radius 1e6 at 4e6",
        unit * 1e6,
        look_at((0.3e6, 0.4e6, 4e6), (0, 0, 0), (0, 1, 0), fov_y_deg=60, near=1.0, far=1e8),
    )
    yield (
        "offset origin: unit sphere at x=1e7",
        unit + [1e7, 0, 0],
        look_at((1e7 + 0.3, 0.4, 4), (1e7, 0, 0), (0, 1, 0), fov_y_deg=60),
    )
    yield (
        "far: unit sphere at 1e8, camera 4 away",
        unit + [1e8, 0, 0],
        look_at((1e8 + 0.3, 0.4, 4), (1e8, 0, 0), (0, 1, 0), fov_y_deg=60),
    )
    yield (
        "tiny fov: 0.01 deg at 1e4",
        unit,
        look_at((0, 0, 1e4), (0, 0, 0), (0, 1, 0), fov_y_deg=0.01, near=1.0, far=2e4),
    )
    yield "huge fov: 179 deg at 4", unit, look_at((0, 0, 4), (0, 0, 0), (0, 1, 0), fov_y_deg=179.0)
    near_pts = unit * [1, 1, 0] + [0, 0, 4 - 0.1 * (1 + 1e-9)]  # a disc 1e-10 in front of the near plane
    yield (
        "near plane: depth = near (1 + 1e-9)",
        near_pts,
        look_at((0, 0, 4), (0, 0, 0), (0, 1, 0), fov_y_deg=60, near=0.1),
    )


def timed(fn, *args, reps=7):
    fn(*args)
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn(*args)
        ts.append(time.perf_counter() - t0)
    return out, float(np.median(ts))


def max_err(px, ref):
    both = ~np.isnan(px[:, 0]) & ~np.isnan(ref[:, 0])
    mismatch = int((np.isnan(px[:, 0]) != np.isnan(ref[:, 0])).sum())
    if not both.any():
        return float("nan"), mismatch
    return float(np.max(np.hypot(*(px[both] - ref[both]).T))), mismatch


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(7)
    rows = []
    print("speed vs accuracy: error against a np.longdouble reference, 40,962 points, median of 7 calls\n")
    print(f"{'case':<38} {'impl':<11} {'max err px':>11} {'vis. diff':>9} {'ms/call':>8} {'x opencv':>10}")
    for name, p_world, cam in cases(rng):
        ref = reference(p_world, cam)
        _, t_ref = timed(opencv_oracle.project, p_world, cam)
        for impl, fn in (
            ("ours f64", project_points),
            ("ours f32", project_f32),
            ("naive f32", naive_f32),
            ("opencv f64", opencv_oracle.project),
            ("opencv f32", opencv_f32),
        ):
            px, t = timed(fn, p_world, cam)
            err, mismatch = max_err(px, ref)
            rows.append(
                {
                    "case": name,
                    "impl": impl,
                    "max_error_px": err,
                    "visibility_mismatches": mismatch,
                    "timing": {"ms_per_call": 1e3 * t, "reference_ms_per_call": 1e3 * t_ref},
                }
            )
            print(f"{name:<38} {impl:<11} {err:>11.3g} {mismatch:>9d} {1e3 * t:>8.3f} {t / t_ref:>10.2f}")
        print()
    print("vis. diff: points whose clipped/visible status differs from the reference;")
    print("x opencv: time per call / cv2.projectPoints float64's time per call.")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The specification's critical and edge cases, as named checks of a candidate projector.

Every check calls the candidate through the contract (oracles.candidates.candidate:
``FUNC(points (N, 3) world, camera) -> (N, 2) px``, NaN where clipped; core is
``core.projector.projection.project_points``), on points whose pixels are derived
by hand below from the conventions (core/conventions.py), never by a projector:

    camera at (0, 0, D) looking at the origin, up +Y  ->  forward (0, 0, -1), up (0, 1, 0),
    right = forward x up = (1, 0, 0), so p_cam = (X, Y, D - Z): depth z = D - Z, and
    x_n = X / z,  y_n = Y / z                                 (normalised coordinates)
    x_px = cx + f x_n,  y_px = cy - f y_n,  cx = (W - 1) / 2 = 319.5,  cy = (H - 1) / 2 = 239.5
    FOV 90 at H = 480:  f = (H / 2) / tan(45 deg) = 240 px  (tan(pi / 4) rounds to 1 - 1.1e-16: under
                                                           1e-13 px at any point here)

Critical (the specification's four): ``known_point``, ``rotation_invariance``,
``depth_monotonicity``, ``clip_safety``. Edge cases: ``near_plane_depth``,
``behind_camera``, ``empty_mesh``. Each returns a dict: ``name``, ``kind``,
``proves``, ``verdict`` (``"pass"`` / ``"fail"``), ``error_px`` and ``bound_px``
(where a pixel error is measured), ``reasons`` (why it failed), ``faults`` (named
by oracles.diagnosis against the hand-derived pixels, or the candidate's own
clipping planes probed) and ``expected`` (the derived values, for the report).

A pixel bound is the crosscheck vertex bound of the candidate's precision at
the check's points (oracles.tolerances.vertex_bound: 1e-6 px in float64,
~1e-3 px in float32), so a check never holds a candidate tighter than the runs do.
"""

from __future__ import annotations

import math

import numpy as np
from wirecheck.core.camera import Camera, look_at
from wirecheck.core.scene.model import Scene
from wirecheck.core.transforms import Motion  # core's motion: under test for the core candidate only

from ..candidates.candidate import CandidateError, call_candidate_precision
from ..candidates.core_candidate import CoreCandidate
from ..candidates.draw import draw_candidate
from ..cases import Case
from ..diagnosis.clip_planes import clip_fault, depth_slack, probe_planes
from ..diagnosis.diagnose import diagnose
from ..runner import run_crosscheck
from ..tolerances import EPS, NAMING, Tolerances, vertex_bound, vertex_scale
from .matrix import CAMERA, TURNS

W, H = CAMERA["width"], CAMERA["height"]
CX, CY = (W - 1) / 2, (H - 1) / 2  # 319.5, 239.5: integers are pixel centres
F90 = 240.0  # (480 / 2) / tan(90 deg / 2)
D = 3.0  # the specification's nearer camera distance


def spec_camera(z: float = D, fov: float = 90.0) -> Camera:
    """``renderer --camera-z z --fov fov``: at (0, 0, z) looking at the origin, up +Y."""
    return look_at((0.0, 0.0, z), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=fov, **CAMERA)


def expected_px(x_n, y_n) -> np.ndarray:
    """``(N, 2)`` pixels of normalised coordinates at FOV 90, 640x480 (module docstring)."""
    return np.stack([CX + F90 * np.asarray(x_n, float), CY - F90 * np.asarray(y_n, float)], axis=1)


class _Check:
    """One check's outcome, built as it runs."""

    def __init__(self, name: str, declared: str | None, kind: str, proves: str):
        self.declared = declared  # --candidate-precision: wins over the dtype the candidate returns
        self.out = {
            "name": name,
            "kind": kind,
            "proves": proves,
            "verdict": "pass",
            "error_px": None,
            "bound_px": None,
            "reasons": [],
            "faults": [],
            "expected": {},
        }

    def fail(self, reason: str) -> None:
        self.out["verdict"] = "fail"
        self.out["reasons"].append(reason)

    def error(self, error_px: float, bound_px: float) -> None:
        old = self.out["error_px"]
        self.out["error_px"] = error_px if old is None else max(old, error_px)
        self.out["bound_px"] = bound_px if self.out["bound_px"] is None else max(self.out["bound_px"], bound_px)

    def faults(self, faults) -> None:
        for f in faults or ():
            if f not in self.out["faults"]:
                self.out["faults"].append(f)

    def call(self, func, points, camera, what: str):
        """``(px, precision)``, or None after failing the check: a crash or a contract violation."""
        try:
            px, returned = call_candidate_precision(func, np.asarray(points, dtype=np.float64).reshape(-1, 3), camera)
        except CandidateError as exc:
            self.fail(f"{what}: {exc}")
            return None
        return px, self.declared or returned

    def clip_faults(self, func, camera) -> None:
        """Name the candidate's own clipping planes, probed (oracles.diagnosis.clip_planes)."""
        fault = clip_fault(probe_planes(func, camera), camera)
        if fault is not None:
            self.faults([fault])


def _bound(precision: str, points, px, camera) -> float:
    """The crosscheck vertex bound of ``precision`` at these points (module docstring)."""
    return vertex_bound(precision, vertex_scale(points, px, camera))


def _named(func, got_px, want_px, camera, precision: str, scale: float, tol_px: float, clipping: bool) -> list:
    """Faults of ``got_px`` against ``want_px``, named as a crosscheck case names them (oracles.judge.verdict):
    a float64 answer whose error is float32 rounding is ``precision_limited``; with ``clipping``, a visible set
    that differs is named by the candidate's own planes, probed."""
    bound32 = vertex_bound("float32", scale) if precision == "float64" else None
    planes = probe_planes(func, camera) if clipping else None
    return diagnose(got_px, want_px, camera, tol_px=tol_px, float32_px=bound32, planes=planes)


def _worst(got: np.ndarray, want: np.ndarray) -> tuple[float, int]:
    """The largest pixel distance between two ``(N, 2)`` arrays (inf where one side is NaN), and its row."""
    d = np.linalg.norm(got - want, axis=1)
    d = np.where(np.isnan(d), np.inf, d)
    k = int(np.argmax(d))
    return float(d[k]), k


# ---------------------------------------------------------------- 1. known-point projection

#: World points seen from (0, 0, 3) and their normalised coordinates (X / z, Y / z), z = 3 - Z:
KNOWN_POINTS = np.array(
    [
        [0.0, 0.0, 0.0],  # z = 3: (0, 0), the principal point
        [1.0, 0.5, 0.0],  # z = 3: (1/3, 1/6)
        [-1.0, 0.5, 0.0],  # z = 3: (-1/3, 1/6)
        [1.0, -0.5, 0.0],  # z = 3: (1/3, -1/6)
        [-1.5, 0.75, -3.0],  # z = 6: (-1/4, 1/8)
        [1.5, -0.75, -3.0],  # z = 6: (1/4, -1/8)
        [0.6, -0.9, 1.5],  # z = 1.5: (0.4, -0.6)
        [-0.3, 0.6, 1.5],  # z = 1.5: (-0.2, 0.4)
    ]
)
KNOWN_NORMALISED = np.array(
    [
        [0.0, 0.0],
        [1 / 3, 1 / 6],
        [-1 / 3, 1 / 6],
        [1 / 3, -1 / 6],
        [-0.25, 0.125],
        [0.25, -0.125],
        [0.4, -0.6],
        [-0.2, 0.4],
    ]
)


def known_point(func, declared: str | None = None) -> dict:
    check = _Check(
        "known_point",
        declared,
        "critical",
        "points of known depth (1.5, 3, 6) land on their normalised coordinates (X/z, Y/z): "
        "the divide, the focal length of the vertical FOV, the principal point and both axes' signs",
    )
    camera = spec_camera()
    want = expected_px(KNOWN_NORMALISED[:, 0], KNOWN_NORMALISED[:, 1])
    check.out["expected"] = {
        "camera": "z 3, FOV 90, 640x480",
        "points": KNOWN_POINTS.tolist(),
        "normalised": KNOWN_NORMALISED.tolist(),
        "pixels": want.tolist(),
    }
    got = check.call(func, KNOWN_POINTS, camera, "projecting the known points")
    if got is None:
        return check.out
    px, precision = got
    bound = _bound(precision, KNOWN_POINTS, want, camera)
    err, k = _worst(px, want)
    check.error(err, bound)
    check.out["got_normalised"] = [[(x - CX) / F90, (CY - y) / F90] for x, y in px.tolist()]
    if not err <= bound:
        x_n, y_n = KNOWN_NORMALISED[k]
        check.fail(
            f"point {KNOWN_POINTS[k].tolist()} (depth {D - KNOWN_POINTS[k][2]:g}) projects to "
            f"{px[k].tolist()}, expected ({x_n:.6g}, {y_n:.6g}) normalised = {want[k].tolist()} px: "
            f"{err:.3g} px > {bound:.3g} px"
        )
        check.faults(
            _named(func, px, want, camera, precision, vertex_scale(KNOWN_POINTS, want, camera), bound, clipping=True)
        )
    return check.out


# ---------------------------------------------------------------- 2. rotation invariance

#: Scene A's corners: the unit cube (side 1) centred at the origin.
UNIT_CUBE = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
#: The turn is taken in steps of 360 / ROTATION_STEPS degrees (the renderer's spin: about X and Y at once).
ROTATION_STEPS = 8
#: Roundings of eps64 (|X| + |C|) the turn adds to a point and to the camera (each entry of R_y R_x is
#: within ~2 eps of the exact rotation, a row of three terms 3x that, 2x for point and camera): 12 x 2.
ROTATION_ROUNDINGS = 24.0


def turn(theta: float) -> np.ndarray:
    """``R_y(theta) @ R_x(theta)``: the renderer's spin (about X, then Y) at angle ``theta``, the angle not
    reduced (at 2 pi the matrix is the identity to ~2.4e-16, not exactly); the suite's own, not core's."""
    c, s = math.cos(theta), math.sin(theta)
    r_x = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    r_y = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return r_y @ r_x


def rotation_invariance(func, declared: str | None = None) -> dict:
    check = _Check(
        "rotation_invariance",
        declared,
        "critical",
        "a 360 deg turn returns every vertex to its start: turned in 45 deg steps with the camera "
        "turned alike, the picture stays the start's at every step (the projector uses the "
        "camera's orientation, not a fixed one), and the scene turned a full turn alone comes "
        "back where it began",
    )
    camera = spec_camera()
    start = check.call(func, UNIT_CUBE, camera, "projecting the cube at rest")
    if start is None:
        return check.out
    px0, precision = start
    # Two projections, each within the precision's bound of the exact pixels, differ by at most twice
    # it; the turn's own float64 rounding (ROTATION_ROUNDINGS eps64 x the scale) is ~1e-11 px here.
    scale = vertex_scale(UNIT_CUBE, px0, camera)
    bound = 2.0 * vertex_bound(precision, scale) + ROTATION_ROUNDINGS * EPS["float64"] * scale
    check.out["expected"] = {
        "camera": "z 3, FOV 90",
        "points": "the unit cube's 8 corners",
        "steps_deg": [360.0 * k / ROTATION_STEPS for k in range(1, ROTATION_STEPS + 1)],
        "pixels": px0.tolist(),
    }
    worst = (0.0, None, None, None)
    for k in range(1, ROTATION_STEPS + 1):
        r = turn(2.0 * math.pi * k / ROTATION_STEPS)
        turned = Camera(
            position=r @ camera.position, forward=r @ camera.forward, up=r @ camera.up, fov_y_deg=90.0, **CAMERA
        )
        got = check.call(func, UNIT_CUBE @ r.T, turned, f"projecting the cube turned {360 * k // ROTATION_STEPS} deg")
        if got is None:
            return check.out
        err, row = _worst(got[0], px0)
        if err > worst[0]:
            worst = (err, k, row, got[0])
    # the scene alone turned one whole turn, the camera fixed: core by its own motion (frame N + 1 of N is
    # one period after frame 1), any other candidate by the oracle side's turn
    if isinstance(func, CoreCandidate):
        m = Motion(turns=TURNS).frame_matrix(ROTATION_STEPS + 1, ROTATION_STEPS)
        how = "core's motion, frame 9 of 8"
    else:
        m = np.eye(4)
        m[:3, :3] = turn(2.0 * math.pi)
        how = "turned 360 deg, sin(2 pi) = -2.4e-16 unreduced"
    got = check.call(func, UNIT_CUBE @ m[:3, :3].T + m[:3, 3], camera, f"projecting the cube after a full turn ({how})")
    if got is None:
        return check.out
    err_full, row_full = _worst(got[0], px0)
    check.error(max(worst[0], err_full), bound)
    if worst[0] > bound:
        _, k, row, px = worst
        check.fail(
            f"scene and camera turned {360 * k // ROTATION_STEPS} deg together: corner "
            f"{UNIT_CUBE[row].tolist()} at {px[row].tolist()}, at rest {px0[row].tolist()}: "
            f"{worst[0]:.3g} px > {bound:.3g} px (the picture must not change)"
        )
        check.faults(_named(func, px, px0, camera, precision, scale, bound, clipping=False))
    if err_full > bound:
        check.fail(
            f"after a full turn ({how}) corner {UNIT_CUBE[row_full].tolist()} is at "
            f"{got[0][row_full].tolist()}, at rest {px0[row_full].tolist()}: {err_full:.3g} px > {bound:.3g} px"
        )
    return check.out


# ---------------------------------------------------------------- 3. depth monotonicity

#: Depths of the same (x, y): doubling from 0.5 to 64, all inside [near 0.1, far 100].
MONOTONIC_DEPTHS = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0)
#: The (x, y) of camera space every depth shares (world X, Y: the camera looks down -Z).
MONOTONIC_XY = ((0.25, 0.25), (-0.5, 0.125))


def depth_monotonicity(func, declared: str | None = None) -> dict:
    check = _Check(
        "depth_monotonicity",
        declared,
        "critical",
        "for identical x, y a farther z lands closer to the centre: the distance from the principal "
        "point is f |(x, y)| / z, halving at each doubling of depth from 0.5 to 64",
    )
    camera = spec_camera()
    points = np.array([[x, y, D - z] for x, y in MONOTONIC_XY for z in MONOTONIC_DEPTHS])
    # expected distance from (cx, cy): f sqrt(x^2 + y^2) / z; the smallest step, between z 32 and 64 of
    # (0.25, 0.25), is 240 * 0.354 * (1/32 - 1/64) = 1.3 px, far above any precision's bound (~1e-3 px)
    radius = [[F90 * math.hypot(x, y) / z for z in MONOTONIC_DEPTHS] for x, y in MONOTONIC_XY]
    check.out["expected"] = {
        "camera": "z 3, FOV 90",
        "xy": [list(p) for p in MONOTONIC_XY],
        "depths": list(MONOTONIC_DEPTHS),
        "distance_px": radius,
    }
    got = check.call(func, points, camera, "projecting points along the depth")
    if got is None:
        return check.out
    px, precision = got
    want = np.array([[CX, CY]])
    exact = expected_px(points[:, 0] / (D - points[:, 2]), points[:, 1] / (D - points[:, 2]))
    bound = 2.0 * _bound(precision, points, exact, camera)  # two points' errors, each within the bound
    dist = np.linalg.norm(px - want, axis=1).reshape(len(MONOTONIC_XY), len(MONOTONIC_DEPTHS))
    check.out["got_distance_px"] = dist.tolist()
    for i, (x, y) in enumerate(MONOTONIC_XY):
        for j in range(len(MONOTONIC_DEPTHS) - 1):
            a, b = dist[i, j], dist[i, j + 1]
            if not b < a - bound:  # NaN (clipped) fails too: every depth is inside [near, far]
                check.fail(
                    f"(x, y) = ({x:g}, {y:g}): depth {MONOTONIC_DEPTHS[j]:g} -> {MONOTONIC_DEPTHS[j + 1]:g} "
                    f"moves {a:.6g} px -> {b:.6g} px from the centre: expected closer (by "
                    f"{radius[i][j] - radius[i][j + 1]:.3g} px: {radius[i][j]:.6g} -> {radius[i][j + 1]:.6g})"
                )
                break
    return check.out


# ---------------------------------------------------------------- 4. clip safety

#: In front of the camera at (0, 0, 3): depths 3 and 4.
FRONT = np.array([[0.5, 0.5, 0.0], [-0.25, 0.1, -1.0]])
#: Behind it (depth 3 - Z < 0): -3 (through the divide it would land at (-1/6, -1/6), inside the image),
#: -0.05, -50, -3997.
BEHIND = np.array([[0.5, 0.5, 6.0], [0.0, 0.0, 3.05], [1.0, -1.0, 53.0], [0.2, 0.1, 4000.0]])
#: On the camera's own plane (depth 0): a divide by zero unless clipped first.
AT_CAMERA = np.array([[0.5, 0.5, 3.0]])
#: On the edge FRONT[0] -> BEHIND[0], in front of the camera: x_cam = y_cam = 0.5 at depth 1.
ON_EDGE = np.array([[0.5, 0.5, 2.0]])


def _frame(func, points, edges, camera, precision: str) -> np.ndarray:
    """The frame crosscheck judges: core's own pipeline, or the harness's drawing of the candidate's pixels
    (oracles.candidates.draw: edges clipped in world space, the clipped ends projected by the candidate and
    moved inside its own probed planes where those differ from the camera's by float32 rounding, as a run
    moves them: oracles.diagnosis.clip_planes.depth_slack)."""
    if isinstance(func, CoreCandidate):
        return func.draw(points, edges, camera, np.eye(4))
    slack, _ = depth_slack(probe_planes(func, camera), camera) if len(edges) else (0.0, None)
    return draw_candidate(func, points, edges, camera, precision, slack)


def clip_safety(func, declared: str | None = None) -> dict:
    check = _Check(
        "clip_safety",
        declared,
        "critical",
        "points behind the camera are not drawn and do not crash the projection: NaN for them and "
        "for a point on the camera's plane (a divide by zero), the points in front beside them "
        "unchanged, and an edge that passes behind the camera drawn only in front of it",
    )
    camera = spec_camera()
    check.out["expected"] = {
        "camera": "z 3, FOV 90",
        "front": FRONT.tolist(),
        "behind": BEHIND.tolist(),
        "behind_depths": (D - BEHIND[:, 2]).tolist(),
        "behind_pixels": "NaN",
        "at_camera": AT_CAMERA.tolist(),
    }
    alone = check.call(func, FRONT, camera, "projecting points in front of the camera")
    got = check.call(func, np.concatenate([FRONT, BEHIND]), camera, "projecting points in front and behind")
    precision = "float64"
    if got is not None:
        px, precision = got
        shown = np.flatnonzero(np.isfinite(px[len(FRONT) :]).any(axis=1))
        if len(shown):
            k = int(shown[0])
            check.fail(
                f"{len(shown)} of {len(BEHIND)} points behind the camera projected, e.g. "
                f"{BEHIND[k].tolist()} (depth {D - BEHIND[k][2]:g}) to {px[len(FRONT) + k].tolist()}: "
                "expected NaN (clipped before the divide)"
            )
        if alone is not None:
            # the same points, the same camera: the same pixels, to each call's rounding
            bound = 2.0 * _bound(precision, FRONT, alone[0], camera)
            err, k = _worst(px[: len(FRONT)], alone[0])
            check.error(err, bound)
            if not err <= bound:
                check.fail(
                    f"front point {FRONT[k].tolist()} projects to {px[k].tolist()} beside points behind "
                    f"the camera, to {alone[0][k].tolist()} alone: {err:.3g} px > {bound:.3g} px"
                )
    got = check.call(func, AT_CAMERA, camera, "projecting a point on the camera's plane (depth 0)")
    if got is not None and np.isfinite(got[0]).any():
        check.fail(f"a point on the camera's plane (depth 0) projects to {got[0][0].tolist()}: expected NaN")
    check.out.update(_edge_behind(check, func, camera, precision))
    if check.out["verdict"] == "fail":
        check.clip_faults(func, camera)
    return check.out


def _edge_behind(check: _Check, func, camera, precision: str) -> dict:
    """The edge FRONT[0] (depth 3) -> BEHIND[0] (depth -3), drawn: only its part in front of near.

    That part runs from a = FRONT[0]'s pixel through b = ON_EDGE's (depth 1) and on out of the image
    (x_n = y_n = 0.5 / z, z from 3 down to 0.1: from (359.5, 199.5) up and right, leaving at row -0.5,
    column 559.5: ~280 px of diagonal). Projected through the divide, the part behind the camera would
    run the other way from a (toward (-1/6, -1/6) normalised). A drawn line strays at most half a
    pixel from its segment, so no pixel may lie more than 1.5 px behind a along b - a; and the part in
    front must be drawn (> 100 px). a and b are the candidate's own pixels: this checks clipping, not
    the placement known_point checks.
    """
    ends = check.call(func, np.concatenate([FRONT[:1], ON_EDGE]), camera, "projecting the edge's front part")
    if ends is None or not np.isfinite(ends[0]).all():
        if ends is not None:
            check.fail(
                f"points in front of the camera, {FRONT[0].tolist()} and {ON_EDGE[0].tolist()}, project "
                f"to {ends[0].tolist()}: expected pixels"
            )
        return {}
    a, b = ends[0]
    try:
        image = _frame(func, np.array([FRONT[0], BEHIND[0]]), np.array([[0, 1]], dtype=np.intp), camera, precision)
    except (CandidateError, ValueError, ArithmeticError) as exc:
        check.fail(f"drawing an edge that passes behind the camera: {type(exc).__name__}: {exc}")
        return {}
    rows, cols = np.nonzero(image)
    u = (b - a) / np.linalg.norm(b - a)
    along = (cols - a[0]) * u[0] + (rows - a[1]) * u[1]
    behind = along < -1.5
    if behind.any():
        check.fail(
            f"the edge through the camera's back drew {int(behind.sum())} pixels beyond its front end "
            f"{a.tolist()}, where only its part behind the camera projects (e.g. row "
            f"{int(rows[behind][0])}, column {int(cols[behind][0])})"
        )
    if len(rows) <= 100:
        check.fail(
            f"the edge's part in front of the camera drew {len(rows)} pixels: expected it drawn "
            "(~280 px from its front end to the top of the image)"
        )
    return {"drawn_px": int(len(rows))}


# ---------------------------------------------------------------- edge cases


def _near_delta(precision: str) -> float:
    """Relative distance from near that a correct candidate of ``precision`` resolves: twice the plane
    tolerance crosscheck gives its clipping (oracles.diagnosis.clip_planes: 1e-9 in float64, 4 eps32 in float32)."""
    return 2.0 * (NAMING.plane_rel_tol if precision == "float64" else NAMING.float32_plane_roundings * EPS["float32"])


def near_plane_depth(func, declared: str | None = None) -> dict:
    check = _Check(
        "near_plane_depth",
        declared,
        "edge",
        "the near plane is where clipping starts: a point just inside near is kept, one just "
        "outside is NaN, one exactly at near may be either (a rounding decides), and none crashes",
    )
    # camera at the origin looking down -Z: depth = -Z exactly, so near is hit to the bit; (x, y) = (0.01,
    # -0.005) at depth 0.1 is normalised (0.1, -0.05), (343.5, 251.5) px: inside the image, so a point kept
    # is a finite pixel (where it lands is known_point's business)
    camera = look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0), fov_y_deg=90.0, **CAMERA)
    near = float(camera.near)
    xy = (0.01, -0.005)
    got = check.call(func, [[*xy, -near]], camera, "projecting a point at the near plane")
    if got is None:
        return check.out
    delta = _near_delta(got[1])
    depths = (near * (1 + delta), near * (1 - delta))
    check.out["expected"] = {
        "camera": "at the origin looking down -Z, near 0.1, FOV 90",
        "at_near": "either",
        "depths": list(depths),
        "relative_delta": delta,
        "kept": [True, False],
    }
    got = check.call(func, [[*xy, -z] for z in depths], camera, "projecting points about the near plane")
    if got is None:
        return check.out
    px = got[0]
    if not np.isfinite(px[0]).all():
        check.fail(f"a point at depth near (1 + {delta:.2g}) is clipped: expected it kept (near <= z)")
    if np.isfinite(px[1]).any():
        check.fail(
            f"a point at depth near (1 - {delta:.2g}) projects to {px[1].tolist()}: expected NaN (clipped: z < near)"
        )
    if check.out["verdict"] == "fail":
        check.clip_faults(func, camera)
    return check.out


def behind_camera(func, declared: str | None = None) -> dict:
    check = _Check(
        "behind_camera",
        declared,
        "edge",
        "a mesh wholly behind the camera shows nothing: every vertex NaN and an empty frame, "
        "where through the divide its mirror image would fill the middle of the picture",
    )
    camera = spec_camera()
    # the unit cube centred 3 behind the camera at (0, 0, 3): depths -2.5 to -3.5
    points = UNIT_CUBE + np.array([0.0, 0.0, 6.0])
    edges = np.array(
        [[i, j] for i in range(8) for j in range(i + 1, 8) if np.count_nonzero(UNIT_CUBE[i] != UNIT_CUBE[j]) == 1],
        dtype=np.intp,
    )  # its 12 edges
    check.out["expected"] = {
        "camera": "z 3, FOV 90",
        "depths": sorted({D - z for z in points[:, 2]}),
        "pixels": "NaN for all 8",
        "drawn_px": 0,
    }
    got = check.call(func, points, camera, "projecting a cube behind the camera")
    if got is None:
        return check.out
    shown = np.flatnonzero(np.isfinite(got[0]).any(axis=1))
    if len(shown):
        check.fail(
            f"{len(shown)} of 8 vertices behind the camera projected, e.g. {points[shown[0]].tolist()} "
            f"to {got[0][shown[0]].tolist()}: expected NaN"
        )
    try:
        image = _frame(func, points, edges, camera, got[1])
    except (CandidateError, ValueError, ArithmeticError) as exc:
        check.fail(f"drawing a cube behind the camera: {type(exc).__name__}: {exc}")
    else:
        check.out["drawn_px"] = int(image.sum())
        if image.any():
            check.fail(f"a cube behind the camera drew {int(image.sum())} pixels: expected none")
    if check.out["verdict"] == "fail":
        check.clip_faults(func, camera)
    return check.out


#: A scene with nothing in it (a valid .scene file of one name line).
EMPTY = Scene(name="empty_mesh", vertices=np.zeros((0, 3)), edges=np.zeros((0, 2), dtype=np.int64))


def empty_mesh(func, declared: str | None = None) -> dict:
    check = _Check(
        "empty_mesh",
        declared,
        "edge",
        "an empty mesh is projected without a crash ((0, 3) points -> (0, 2) pixels), draws nothing, "
        "and a crosscheck of it is vacuous: a gate never passes on nothing",
    )
    camera = spec_camera()
    check.out["expected"] = {"pixels_shape": [0, 2], "drawn_px": 0, "run_verdict": "fail", "case_verdict": "vacuous"}
    got = check.call(func, np.zeros((0, 3)), camera, "projecting an empty mesh")
    try:
        image = _frame(func, np.zeros((0, 3)), np.zeros((0, 2), dtype=np.intp), camera, got[1] if got else "float64")
    except (CandidateError, ValueError, ArithmeticError) as exc:
        check.fail(f"drawing an empty mesh: {type(exc).__name__}: {exc}")
    else:
        if image.any():
            check.fail(f"an empty mesh drew {int(image.sum())} pixels: expected none")
    # the runner on it, at level vertices (nothing to draw): the case compares nothing
    report, _ = run_crosscheck(
        [EMPTY],
        func,
        frames=1,
        level="vertices",
        turns=TURNS,
        animation=False,
        tol=Tolerances(precision=declared),
        cases=(Case("z3_fov90", camera),),
    )
    case = report["cases"][0]
    check.out["run"] = {"verdict": report["verdict"], "case_verdict": case["verdict"], "reasons": case["reasons"]}
    if report["verdict"] != "fail" or case["verdict"] != "vacuous":
        check.fail(
            f"a crosscheck of the empty mesh is {report['verdict']} (case {case['verdict']}): expected "
            "fail, the case vacuous (nothing compared)"
        )
    return check.out


#: The checks in report order: the four critical cases, then the three edge cases.
CHECKS = (
    known_point,
    rotation_invariance,
    depth_monotonicity,
    clip_safety,
    near_plane_depth,
    behind_camera,
    empty_mesh,
)
CHECK_NAMES = tuple(c.__name__ for c in CHECKS)
CRITICAL = CHECK_NAMES[:4]


def run_checks(func, names=CHECK_NAMES, precision: str | None = None) -> list[dict]:
    """The named checks of ``func`` (a contract callable; core: a CoreCandidate), in :data:`CHECKS` order.

    ``precision`` (``--candidate-precision``): what the candidate computes in, when its answers' dtype does
    not say (oracles.candidates.candidate.case_precision); default: that dtype.
    """
    by_name = {c.__name__: c for c in CHECKS}
    unknown = [n for n in names if n not in by_name]
    if unknown:
        raise ValueError(f"checks {unknown}: expected some of {', '.join(CHECK_NAMES)}")
    return [by_name[n](func, precision) for n in CHECK_NAMES if n in names]

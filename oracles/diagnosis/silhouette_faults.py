r"""A filled frame's camera mistakes named from its silhouette against the fill-rule reference.

A renderer with a camera mistake draws the right faces at the wrong pixels. Each mistake is a
map ``M`` of the reference's image triangles (oracles.references.fill_rule.project_clipped) to
the candidate's, and the model's silhouette is the fill rule's coverage of ``M(triangles)``
with its own ties (exact: no resampling of a mask). ``c`` is the principal point; the fitted
numbers are reported as depth_pixels reports them, as the map ``T = M^-1`` from a candidate
pixel to the reference pixel it shows::

    name               M(p) (reference -> candidate)        params  reported
    (none)             p                                     0       -
    mirror_horizontal  (W - 1 - x, y)                        0       -
    mirror_vertical    (x, H - 1 - y)                        0       -   (rows read back bottom first)
    axis_flip          (W - 1 - x, H - 1 - y)                0       -   (right and up negated: 180 degrees)
    axis_swap          c + (v, u),  (u, v) = p - c           0       -
    depth_flip         the faces seen by the camera looking  0       -   (oracles.diagnosis.image_diagnose.
                       backward                                           flipped_camera)
    fov_mismatch       c + (p - c) / s                       1       scale s (K from the horizontal FOV:
                                                                     H / W), implied_fov_deg
    pixel_offset       p - (dx, dy)                          2       dx, dy (cx = W / 2: -0.5, -0.5)
    aspect_mismatch    c + (p - c) / (sx, sy)                2       implied_aspect

The fitted models start at the identity and take :data:`STEPS` fixed-point steps on the masks'
moments over the pixels the model decides (its ties left out of both masks): the centroid for
``dx, dy``, the spread about ``c`` (root mean square distance) for ``s``, per axis for ``sx, sy``.
At the true parameters the two masks agree at every decided pixel, so the true values are a
fixed point. Where the image's border cuts the silhouette the moments are biased (a tenth of a
pixel of offset at near_plane), so a fit that misses a few pixels is then polished on its misses
themselves (coordinate descent, steps down to 0.01 px of edge movement); the scales also start
from the ratios convention mistakes give (H / W, W / H).

Counted over all frames together (the parameters are shared: one camera mistake), a model's
*misses* are the decided pixels (not its ties) where its silhouette and the candidate differ,
and its ``miss_ratio`` is misses over the reference's boundary pixels (decided covered pixels
with an uncovered 4-neighbour in the image: the silhouette's length in pixels). A model **explains** the
frames when ``miss_ratio <= NAMING.silhouette_allowance`` (oracles.tolerances: its derivation; read when
called, as ``silhouette_polish_below``, which fits are polished). Among the models that
explain, the fewest parameters win, then the fewest misses; the identity with no miss names
nothing (a correct frame, or a mistake that moves no decided pixel: a symmetric silhouette under
its mirror), with a few misses within the allowance ``unexplained`` (in place: no camera mistake
moves them; a rasteriser's own rule); two names explaining with as few parameters are ``ambiguous`` (a silhouette
symmetric about the vertical axis shows ``mirror_vertical`` and ``axis_flip`` alike); nothing
explaining is ``unexplained``, with every model's ``miss_ratio`` (``fit_ratios``).

Every name is the fault catalogue's, read from ``"silhouettes"`` (oracles.faults: its hints).
The mirrors are about the image's centre, as a buffer read back the wrong way round mirrors it;
for a camera whose principal point is off-centre a mirrored camera axis is a mirror about ``c``
and shows as ``unexplained``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..faults import Fault, hint_text
from ..references.fill_rule import coverage, open_edges, project_clipped
from ..tolerances import NAMING
from .image_diagnose import flipped_camera

__all__ = ["STEPS", "SILHOUETTE_FAULTS", "SilhouetteFrame", "name_silhouette_faults"]

#: Fixed-point steps of the fitted models (the moments' ratio converges linearly; 6 leave the
#: bundled cases' parameters moving by under 1e-4 px).
STEPS = 4

#: Every name this module gives, the catalogue's order.
SILHOUETTE_FAULTS = (
    "depth_flip",
    "axis_swap",
    "ambiguous",
    "axis_flip",
    "mirror_horizontal",
    "mirror_vertical",
    "aspect_mismatch",
    "fov_mismatch",
    "pixel_offset",
    "unexplained",
)


@dataclass(frozen=True)
class SilhouetteFrame:
    """One filled frame to name: the candidate's covered pixels and what its reference was drawn from.

    ``cand``: ``(H, W)`` bool (any non-black pixel); ``inside``, ``ties``: the reference's
    (oracles.references.fill_rule.silhouette of ``p_world``, ``faces``, ``camera``);
    ``p_world``: ``(N, 3)`` world points of the frame; ``faces``: polygons (index tuples).
    """

    cand: np.ndarray
    inside: np.ndarray
    ties: np.ndarray
    camera: object
    p_world: np.ndarray
    faces: tuple


@dataclass(frozen=True)
class _Prepared:
    """A frame's triangles in pixels, open edges, principal point and boundary count."""

    frame: SilhouetteFrame
    tris_px: np.ndarray
    is_open: np.ndarray
    centre: np.ndarray
    boundary_px: int


def _boundary_px(inside: np.ndarray, ties: np.ndarray) -> int:
    """Decided covered pixels with an uncovered 4-neighbour (off the image counts as the pixel itself: where the
    image's border cuts a silhouette no camera mistake moves an edge)."""
    pad = np.pad(inside, 1, mode="edge")
    edge = inside & ~(pad[:-2, 1:-1] & pad[2:, 1:-1] & pad[1:-1, :-2] & pad[1:-1, 2:])
    return int((edge & ~ties).sum())


def _prepare(frame: SilhouetteFrame) -> _Prepared:
    tris_px, _z, _owner = project_clipped(frame.p_world, frame.faces, frame.camera)
    centre = np.array(frame.camera.principal_point, dtype=np.float64)
    return _Prepared(frame, tris_px, open_edges(tris_px), centre, _boundary_px(frame.inside, frame.ties))


def _model(prep: _Prepared, name: str, theta) -> tuple[np.ndarray, np.ndarray]:
    """``(inside, ties)`` of model ``name`` with parameters ``theta`` on one frame (module docstring's table)."""
    h, w = prep.frame.inside.shape
    c = prep.centre
    p = prep.tris_px
    if name == "depth_flip":
        p, _z, _o = project_clipped(prep.frame.p_world, prep.frame.faces, flipped_camera(prep.frame.camera))
        return coverage(p, (h, w))
    if name == "mirror_horizontal":
        p = np.stack([w - 1 - p[..., 0], p[..., 1]], axis=-1)
    elif name == "mirror_vertical":
        p = np.stack([p[..., 0], h - 1 - p[..., 1]], axis=-1)
    elif name == "axis_flip":
        p = np.stack([w - 1 - p[..., 0], h - 1 - p[..., 1]], axis=-1)
    elif name == "axis_swap":
        p = c + (p - c)[..., ::-1]
    elif name == "fov_mismatch":
        p = c + (p - c) / theta[0]
    elif name == "aspect_mismatch":
        p = c + (p - c) / np.asarray(theta)
    elif name == "pixel_offset":
        p = p - np.asarray(theta)
    return coverage(p, (h, w), is_open=prep.is_open)


def _moments(mask: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """``[n, sum x, sum y, sum (x - cx)^2, sum (y - cy)^2]`` of a mask's True pixels."""
    rows, cols = np.nonzero(mask)
    u, v = cols - centre[0], rows - centre[1]
    return np.array([len(rows), cols.sum(), rows.sum(), (u * u).sum(), (v * v).sum()], dtype=np.float64)


def _step(name: str, theta: np.ndarray, m_model: np.ndarray, m_cand: np.ndarray) -> np.ndarray:
    """One fixed-point step: move ``theta`` so that the model's moments become the candidate's."""
    if min(m_model[0], m_cand[0]) == 0:
        return theta
    if name == "pixel_offset":  # T = p + d: the candidate's centroid is the reference's - d
        return theta + (m_model[1:3] / m_model[0] - m_cand[1:3] / m_cand[0])
    spread_model = m_model[3:5] / m_model[0]
    spread_cand = m_cand[3:5] / m_cand[0]
    if name == "fov_mismatch":  # T = c + s (p - c): the candidate's spread is the model's / s
        return theta * math.sqrt(spread_model.sum() / spread_cand.sum()) if spread_cand.sum() > 0 else theta
    ok = spread_cand > 0
    return np.where(ok, theta * np.sqrt(np.where(ok, spread_model / np.where(ok, spread_cand, 1.0), 1.0)), theta)


def _fit(preps, name: str, theta0) -> np.ndarray:
    """The model's parameters after :data:`STEPS` fixed-point steps on the moments, pooled over the frames."""
    theta = np.asarray(theta0, dtype=np.float64)
    for _ in range(STEPS):
        m_model, m_cand = np.zeros(5), np.zeros(5)
        for prep in preps:
            inside, ties = _model(prep, name, theta)
            m_model += _moments(inside & ~ties, prep.centre)
            m_cand += _moments(prep.frame.cand & ~ties, prep.centre)
        new = _step(name, theta, m_model, m_cand)
        if not np.all(np.isfinite(new)):
            break
        theta = new
    return theta


def _polish(preps, name: str, theta: np.ndarray, misses: int) -> tuple[np.ndarray, int]:
    """Coordinate descent on the misses from the moments' fit, while any remain: steps moving the silhouette's
    edge by ~0.1, 0.03, 0.01 px (a scale's step relative to the silhouette's reach from ``c``). The moments
    are biased where the image's border cuts the silhouette (near_plane: 0.1 px of offset); this takes the
    fit to the misses' own minimum."""
    if misses == 0 or not np.all(np.isfinite(theta)):
        return theta, misses
    reach = max(float(np.abs(p.tris_px - p.centre).max(initial=1.0)) for p in preps)
    unit = 1.0 if name == "pixel_offset" else 1.0 / min(reach, max(max(p.frame.inside.shape) for p in preps))
    for step in (0.1, 0.03, 0.01):
        for i in range(len(theta)):
            for sign in (1.0, -1.0):
                while misses:
                    trial = theta.copy()
                    trial[i] += sign * step * unit
                    m = _misses(preps, name, trial)
                    if m >= misses:
                        break
                    theta, misses = trial, m
    return theta, misses


def _misses(preps, name: str, theta) -> int:
    """Decided pixels where the model's silhouette and the candidate differ, over every frame."""
    total = 0
    for prep in preps:
        if name == "none":
            inside, ties = prep.frame.inside, prep.frame.ties
        else:
            inside, ties = _model(prep, name, theta)
        total += int(((prep.frame.cand != inside) & ~ties).sum())
    return total


_FIXED = ("none", "depth_flip", "axis_swap", "axis_flip", "mirror_horizontal", "mirror_vertical")
_FITTED = ("fov_mismatch", "pixel_offset", "aspect_mismatch")


def _starts(name: str, camera) -> list[tuple[float, ...]]:
    """Where a fitted model's steps start: the identity, and for the scales the ratios convention mistakes
    give (H / W, W / H: the FOV or the aspect taken along the other axis), from which a silhouette clipped
    by the image's border converges where the identity's moments do not (prism and pyramid, near_plane)."""
    if name == "pixel_offset":
        return [(0.0, 0.0)]
    r = int(camera.height) / int(camera.width)
    ratios = [1.0] + ([r, 1.0 / r] if r != 1.0 else [])
    if name == "fov_mismatch":
        return [(k,) for k in ratios]
    return [(1.0, 1.0)] + [(k, 1.0) for k in ratios[1:]] + [(1.0, k) for k in ratios[1:]]


def _params(name: str, theta: np.ndarray, camera) -> dict:
    """The fields of a fitted fault (module docstring's table), with the horizontal-FOV hint where it fits."""
    h, w = int(camera.height), int(camera.width)
    if name == "pixel_offset":
        return {"dx": float(theta[0]), "dy": float(theta[1])}
    if name == "fov_mismatch":
        s = float(theta[0])
        out = {"scale": s}
        if camera.projection == "perspective":
            fy = camera.focal_xy[1]
            out["implied_fov_deg"] = float(np.degrees(2.0 * np.arctan((h / 2.0) * s / fy)))
        else:
            out["implied_ortho_height"] = float(camera.ortho_height * s)
        if any(abs(s - r) <= 1e-3 * r for r in (h / w, w / h)) and h != w:
            out["hint"] = hint_text("fov_mismatch", "horizontal_fov")
        return out
    if name == "aspect_mismatch":
        sx, sy = float(theta[0]), float(theta[1])
        fx, fy = camera.focal_xy if camera.projection == "perspective" else (1.0, 1.0)
        return {"implied_aspect": (w / h) * (sx / sy) * (fy / fx), "scale_x": sx, "scale_y": sy}
    return {}


def name_silhouette_faults(frames) -> tuple[Fault, ...]:
    """Name the camera mistake that draws the candidates' silhouettes (module docstring); ``()`` when none.

    Parameters
    ----------
    frames : sequence of SilhouetteFrame
        One or more frames of one candidate (one camera mistake shared by all of them).

    Returns
    -------
    tuple of oracles.faults.Fault, each read from ``"silhouettes"``: one named fault, or ``ambiguous``
    (``alternatives``), or ``unexplained`` (``fit_ratios``: each model's misses over the boundary pixels;
    ``boundary_px``); ``()`` when the identity explains the frames with no miss.
    """
    frames = list(frames)
    if not frames:
        raise ValueError("name_silhouette_faults: no frame to name (expected one or more SilhouetteFrame)")
    for f in frames:
        if not (
            np.shape(f.cand) == np.shape(f.inside) == np.shape(f.ties) == (int(f.camera.height), int(f.camera.width))
        ):
            raise ValueError(
                f"silhouettes of shapes {np.shape(f.cand)}, {np.shape(f.inside)}, ties "
                f"{np.shape(f.ties)}: expected ({f.camera.height}, {f.camera.width}), the camera's"
            )
    frames = [
        SilhouetteFrame(
            np.asarray(f.cand, dtype=bool),
            np.asarray(f.inside, dtype=bool),
            np.asarray(f.ties, dtype=bool),
            f.camera,
            np.asarray(f.p_world, dtype=np.float64),
            tuple(tuple(face) for face in f.faces),
        )
        for f in frames
    ]
    if not any(f.cand.any() for f in frames):
        return (
            Fault("unexplained", {"note": "the candidate's frames are blank: no silhouette to name"}, "silhouettes"),
        )
    preps = [_prepare(f) for f in frames]
    in_place = _misses(preps, "none", None)
    if in_place == 0:
        return ()
    boundary = sum(p.boundary_px for p in preps)
    if boundary == 0:
        return (
            Fault(
                "unexplained",
                {
                    "note": f"{in_place} decided pixels differ, but the reference's silhouette has "
                    "no edge in the image (nothing covered, or all of it): no camera "
                    "mistake of the family can be seen"
                },
                "silhouettes",
            ),
        )
    fits = [("none", 0, np.zeros(0), in_place)]  # (name, n_params, theta, misses)
    for name in _FIXED[1:]:
        fits.append((name, 0, np.zeros(0), _misses(preps, name, None)))
    for name in _FITTED:
        tried = []
        for theta0 in _starts(name, frames[0].camera):
            theta = _fit(preps, name, theta0)
            misses = _misses(preps, name, theta)
            if misses <= NAMING.silhouette_polish_below * NAMING.silhouette_allowance * boundary:
                theta, misses = _polish(preps, name, theta, misses)
            tried.append((name, len(theta0), theta, misses))
            if tried[-1][3] == 0:
                break
        fits.append(min(tried, key=lambda f: f[3]))
    ratios = {name: misses / boundary for name, _n, _t, misses in fits}
    explaining = sorted((f for f in fits if ratios[f[0]] <= NAMING.silhouette_allowance), key=lambda f: (f[1], f[3]))
    if not explaining:
        best = min(fits, key=lambda f: f[3])
        return (
            Fault(
                "unexplained",
                {
                    "best": best[0],
                    "fit_ratios": ratios,
                    "boundary_px": boundary,
                    "allowance": NAMING.silhouette_allowance,
                },
                "silhouettes",
            ),
        )
    first = explaining[0]
    if first[0] == "none":
        if first[3] == 0:
            return ()
        return (
            Fault(
                "unexplained",
                {
                    "note": f"the silhouette is in place: {first[3]} decided pixels differ, "
                    "and no camera mistake of the family moves them",
                    "fit_ratios": ratios,
                    "boundary_px": boundary,
                },
                "silhouettes",
            ),
        )
    rivals = [f for f in explaining if f[1] == first[1] and f[0] != first[0]]
    if rivals:
        names = [first[0]] + [r[0] for r in rivals]
        return (
            Fault(
                "ambiguous",
                {"alternatives": ", ".join(names), "fit_ratios": ratios, "boundary_px": boundary},
                "silhouettes",
            ),
        )
    name, _n, theta, misses = first
    return (
        Fault(
            name,
            {
                **_params(name, theta, frames[0].camera),
                "miss_ratio": ratios[name],
                "misses": misses,
                "boundary_px": boundary,
                "fit_ratios": ratios,
            },
            "silhouettes",
        ),
    )

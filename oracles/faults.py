"""The fault vocabulary: one catalogue of names, and the :class:`Fault` record.

Every fault wirecheck names is an entry of :data:`CATALOGUE`, in precedence
order (the first fault of a case is its primary one: a depth flip hides
everything else, a swap or mirror changes the picture more than a scale, an
offset is the smallest visible effect; a depth map's values come after the
camera's faults, their encoding first, a float16 step last), a depth map's and
an unprojector's names included. An entry says

- ``family``: what the fault is about, so code asks for a family, never for a
  list of name strings (:data:`FAMILIES`);
- ``source``: where it is read (:data:`SOURCES`: ``any``; ``vertices`` only; ``pixels``: the
  drawn lines; ``images``: a renderer's frames only; ``depth``: a depth map's values; ``points``:
  an unprojector's world points; ``silhouettes``: a filled frame's covered pixels); a name read from other
  sources too has a hint keyed by each of
  them in ``hints`` (``mirror_vertical``'s ``depth`` and ``points`` hints), its :attr:`FaultKind.sources`;
- ``shown``: the fields a table cell may show, with their labels ("": the value alone), of which a
  cell shows the first two a fault has (oracles.reports.fault_text; the full record is report.json's);
- ``cell``: what a cell shows instead, in words (``unexplained``: which kind, its residual);
- ``hint``: what to check, one line; ``frames_hint``: what else to check
  when the pixels are a renderer's own frames; ``hints``: the hints a
  fault's values select (a FOV scale of W/H, a clipping plane's kind), each a
  template filled from the fault's fields, and the hint of each further source
  (:meth:`FaultKind.hint_for`: a depth map's rows flipped are read back bottom row first, an
  unprojector's are a sign in y_cam).

A fault travels as a plain dict in the case records and report.json
(``{"name": ..., field: value, ...}``; a public format, docs/crosscheck.md);
:class:`Fault` is that dict read through the catalogue. This module imports
nothing of wirecheck: every layer may use it. docs/diagnosis.md's table of
names, cells and hints is :func:`markdown_table` (tests/test_faults.py).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

__all__ = [
    "FaultKind",
    "Fault",
    "CATALOGUE",
    "FAMILIES",
    "SOURCES",
    "NAMES",
    "kind",
    "family",
    "names",
    "precedence",
    "ordered",
    "hint_text",
    "markdown_table",
]

#: The families, each a question about the picture.
FAMILIES: Mapping[str, str] = MappingProxyType(
    {
        "orientation": "the picture is turned, mirrored or seen from behind as a whole",
        "ambiguous": "two orientations fit the images equally well",
        "clipping": "the points kept differ from near <= z <= far",
        "scale": "the focal length or the aspect",
        "offset": "a constant shift",
        "lens": "the lens distortion",
        "line_count": "the drawn lines gain or lose pixels (GL's rule, counted against the oracle's)",
        "line_rule": "the lines are right but drawn under another rule than GL's",
        "precision": "float32 rounding, not a convention error",
        "depth": "a depth map's values: their unit, origin, ray, direction, encoding or precision",
        "rotation": "the world-to-camera rotation applied the wrong way round on the way back",
        "unexplained": "no simple image-space fault",
    }
)

#: Where a fault is read, each with the words docs/diagnosis.md's table uses for its own hint.
SOURCES: Mapping[str, str] = MappingProxyType(
    {
        "any": "vertices or pixels",
        "vertices": "the projected vertices only",
        "pixels": "the drawn lines",
        "images": "a renderer's frames only",
        "depth": "depth maps",
        "points": "unprojectors",
        "silhouettes": "filled frames",
    }
)


@dataclass(frozen=True)
class FaultKind:
    """One name of the catalogue: what it is about, what a cell shows, what to check."""

    name: str
    family: str
    source: str
    hint: str
    shown: tuple[tuple[str, str], ...] = ()
    frames_hint: str = ""
    cell: str = ""
    hints: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))

    @property
    def precedence(self) -> int:
        """0 for the primary-most fault (depth_flip), larger for smaller effects."""
        return _ORDER[self.name]

    @property
    def sources(self) -> tuple[str, ...]:
        """Where the name is read: its ``source``, then each source with a hint of its own in ``hints``."""
        return (self.source, *(s for s in self.hints if s in SOURCES and s != self.source))

    def hint_for(self, source: str | None = None) -> str:
        """What to check when the fault was read from ``source`` (its hint there, else ``hint``)."""
        return self.hints[source] if source in self.sources and source in self.hints else self.hint


_MINUS_ONE = (
    "the scale is (W - 1) / W (or (H - 1) / H): the pixel count minus one was used as the image "
    "size (x = (ndc + 1) (W - 1) / 2); use x = (ndc + 1) W / 2 - 0.5"
)
_NEAR_FAR = "Check the near/far test (near <= z <= far, z = forward . (p - position)), points behind the camera, "

_KINDS = (
    FaultKind(
        "depth_flip",
        "orientation",
        "any",
        "the camera looks backward: depth must be positive in front, z = forward . (p - position)",
    ),
    FaultKind(
        "clipping_plane",
        "clipping",
        "vertices",
        "the points kept differ from near <= z <= far (z = forward . (p - position)): kind and "
        "near_fit/far_fit say where the candidate clips (z_positive: at z > 0, not near; "
        "float32_near: near rounded to float32; none: never; swapped: near and far exchanged)",
        shown=(("kind", ""),),
        hints=MappingProxyType(
            {
                "z_positive": "the candidate keeps every point with z > 0: clip at the near plane, near <= z <= far "
                "(z = forward . (p - position)), not at the camera",
                "float32_near": "the near plane went through float32 (a float32 near or GL projection matrix): "
                "near_fit is where it clips; build the matrix in float64, or declare float32",
                "float32_far": "the far plane went through float32 (a float32 GL projection matrix, whose far is "
                "ill-conditioned): build the matrix in float64, or declare float32",
                "near": "the near plane is another value: near_fit is where the candidate clips; use the camera's near",
                "far": "the far plane is another value (far_fit; None: never clips far): use the camera's far",
                "none": "the candidate never clips (no NaN, even behind the camera): return NaN unless "
                "near <= z <= far",
                "swapped": "the candidate keeps no depth at all: near and far exchanged in near <= z <= far "
                "(or the test inverted)",
            }
        ),
    ),
    FaultKind("axis_swap", "orientation", "any", "x and y are exchanged: return columns [x, y], not [row, col]"),
    FaultKind(
        "ambiguous",
        "ambiguous",
        "images",
        "the images fit two faults equally well (a symmetric view cannot tell them apart): "
        "check both, see alternatives",
        shown=(("alternatives", ""),),
        hints=MappingProxyType(
            {
                "alternatives": "the images fit {first} and {second} equally well (a symmetric view cannot tell "
                "them apart): {each}",
                "depth": "the compared depths fit several of these models alike (a surface at one depth, seen "
                "square-on): judge more frames, or a view whose depth varies",
                "points": "the points fit several of these mistakes alike on this view: see the alternatives",
                "silhouettes": "the silhouettes fit several of these camera mistakes alike (a silhouette symmetric "
                "about an axis looks the same mirrored): see the alternatives, or judge a view that "
                "is not symmetric",
            }
        ),
    ),
    FaultKind(
        "axis_flip",
        "orientation",
        "any",
        "the picture is turned 180 degrees: x and y are both negated (e.g. right and up "
        "both negated in the world-to-camera rotation)",
    ),
    FaultKind(
        "mirror_horizontal",
        "orientation",
        "any",
        "left and right are exchanged: check right = forward x up (not up x forward) and x_px = cx + f x / z",
        hints=MappingProxyType(
            {
                "depth": "columns flipped: right = forward x up, and x_px grows to the right",
                "points": "pixel x grows to the right: x_cam = (u - cx) d / fx, and right = forward x up",
                "silhouettes": "columns flipped: right = forward x up, x_px = cx + f x / z (a texture or buffer "
                "read back with its u axis reversed mirrors it too)",
            }
        ),
    ),
    FaultKind(
        "mirror_vertical",
        "orientation",
        "any",
        "the picture is upside down: pixel y grows downward, so y_px = cy - f y / z",
        hints=MappingProxyType(
            {
                "depth": "rows flipped: GL's window y is up, an image's row 0 is the top: flip the rows once "
                "when reading the buffer back (glReadPixels returns the bottom row first)",
                "points": "pixel y grows downward: y_cam = -(v - cy) d / fy (rows are not flipped; OpenCV's camera "
                "y is down, the contract's up)",
                "silhouettes": "rows flipped: GL's window y is up, an image's row 0 is the top: flip the rows once "
                "when reading the frame back (glReadPixels returns the bottom row first)",
            }
        ),
    ),
    FaultKind(
        "rotation_transposed",
        "rotation",
        "points",
        "R maps world to camera (p_cv = R X + t, rows right, -up, forward): the way back is X = R^T (p_cv - t)",
        shown=(("form", ""),),
    ),
    FaultKind(
        "aspect_mismatch",
        "scale",
        "any",
        "x and y are scaled differently: use one focal length for both axes (square "
        "pixels); implied_aspect is the width/height ratio that was used",
        shown=(("implied_aspect", "aspect"),),
        hints=MappingProxyType(
            {
                "minus_one": _MINUS_ONE,
                "inverted": "implied_aspect is H/W: the aspect was taken the wrong way round (height / width "
                "where width / height is expected)",
                "width": "x is scaled by W/H (or H/W) against y: fx was taken from the width (aspect 1): "
                "fx = fy for square pixels",
            }
        ),
    ),
    FaultKind(
        "fov_mismatch",
        "scale",
        "any",
        "the focal length is off: f = (H / 2) / tan(fov_y / 2) with the vertical FOV in "
        "radians; implied_fov_deg is the FOV that was used",
        shown=(("implied_fov_deg", "fov"), ("implied_ortho_height", "ortho_height"), ("implied_fov_y_deg", "fov")),
        hints=MappingProxyType(
            {
                "horizontal_fov": "the scale is W/H (or H/W): you used the horizontal FOV (or the width) where the "
                "vertical one is expected: f = (H / 2) / tan(fov_y / 2)",
                "minus_one": _MINUS_ONE,
                "depth": "the image is scaled about the principal point: fov_y_deg is the vertical FOV, "
                "f = (H / 2) / tan(fov_y / 2) (a renderer given it as its horizontal view angle scales by "
                "W / H)",
                "points": "fov_y_deg is the full vertical FOV: f = (H / 2) / tan(fov_y / 2), the same for x "
                "(not (W / 2) / tan(fov / 2))",
                "silhouettes": "the silhouette is scaled about the principal point (scale: a candidate pixel shows "
                "the reference's at c + scale (p - c)): f = (H / 2) / tan(fov_y / 2) with the vertical "
                "FOV (a renderer given it as its horizontal view angle scales by H / W)",
            }
        ),
    ),
    FaultKind(
        "pixel_offset",
        "offset",
        "any",
        "a constant shift: integer pixel coordinates are pixel centres and the principal "
        "point is ((W - 1) / 2, (H - 1) / 2); 0.5 is the pixel-corner convention",
        shown=(("dx", "dx"), ("dy", "dy")),
        frames_hint="a renderer that snaps lines to pixel centres (matplotlib: draw with snap=False) or truncates "
        "float coordinates (Pillow: round them) moves its lines too",
        hints=MappingProxyType(
            {
                "depth": "the depth is half a pixel (or more) off: pixel centres are integers, cx = (W - 1) / 2 "
                "(W / 2 is the corner convention); a GL projection from K puts cx + 0.5 in it",
                "points": "pixel centres are integers: a centred camera has cx = (W - 1) / 2, cy = (H - 1) / 2 "
                "(W / 2 is GL's window convention, pixel centres at half-integers: subtract 0.5)",
                "silhouettes": "the silhouette is shifted (a candidate pixel p shows the reference's p + (dx, dy)): "
                "pixel centres are integers, cx = (W - 1) / 2 (W / 2 gives -0.5); a GL projection "
                "built from K puts cx + 0.5 in it",
            }
        ),
    ),
    FaultKind(
        "distortion_mismatch",
        "lens",
        "vertices",
        "the lens distortion differs from the camera's (kind: ignored, k1's sign, or a "
        "coefficient's size): apply OpenCV's model to x/z, y/z with y down, before K: "
        "r2 = x^2 + y^2, x (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x y + p2 (r2 + 2 x^2)",
        shown=(("kind", ""), ("radial_error_px", "error_px")),
        hints=MappingProxyType(
            {
                "points": "undo the lens distortion before unprojecting: cv2.undistortPointsIter (the "
                "default cv2.undistortPoints stops after 5 iterations, ~4e-3 px off on this lens)"
            }
        ),
    ),
    FaultKind(
        "depth_encoding",
        "depth",
        "depth",
        "the depth buffer's non-linear value was stored: linearise it, d = f n / (f - z (f - n)) for window "
        "z in [0, 1] (NDC z: z_win = (z + 1) / 2 first; orthographic: d = n + z (f - n))",
        shown=(("near", "near"), ("far", "far")),
    ),
    FaultKind(
        "depth_reversed",
        "depth",
        "depth",
        "a reversed-Z buffer (near -> 1, far -> 0) linearised with the standard formula: near and far swap; "
        "linearise it as d = n f / (n + z (f - n)), or read 1 - z",
        shown=(("sum_of_inverses", "1/n+1/f"), ("sum", "n+f")),
    ),
    FaultKind(
        "depth_scale",
        "depth",
        "depth",
        "depth is a constant factor off: k = 1000 is millimetres read as metres (a 16-bit PNG not divided by "
        "its scale; 5000 for TUM files); divide by the scale the file was written with",
        shown=(("k", "k"),),
    ),
    FaultKind(
        "depth_is_range",
        "depth",
        "depth",
        "distance from the eye along the pixel's ray was stored where depth along forward was asked (or the "
        "reverse): depth = range / |(x_n, y_n, 1)| with x_n = (x - cx) / fx, y_n = (y - cy) / fy",
        shown=(("stored", ""),),
        hints=MappingProxyType(
            {
                "points": "the depth given is along forward (z_cam), not along the ray: p_cam = d (x_n, y_n, 1), "
                "not d (x_n, y_n, 1) / |(x_n, y_n, 1)|"
            }
        ),
    ),
    FaultKind(
        "depth_offset",
        "depth",
        "depth",
        "a constant is added: depth measured from the near plane (b = -near) or from a point other than the "
        "camera centre; depth is z_cam = dot(p - position, forward)",
        shown=(("b", "b"), ("b_over_near", "b/near")),
    ),
    FaultKind(
        "depth_precision",
        "depth",
        "depth",
        "depth values are quantised (a float16 or 8-bit target or texture): render and store depth as "
        "float32, or as a 16-bit PNG with a scale",
        shown=(("format", ""), ("step", "step")),
    ),
    FaultKind(
        "line_end_bias",
        "line_count",
        "pixels",
        "the vertices agree but the lines lose (or gain) pixels at one end: check the "
        "rasterizer's end rule (GL diamond exit: the start pixel is drawn when the start point "
        "is inside its diamond, the end pixel is not drawn when the end point is inside its own)",
        shown=(("end", "end"), ("pixels_per_line", "pixels_per_line"), ("end_px", "end_px")),
        frames_hint="the pixels lose or gain end pixels against both GL's rule and ends rounded to pixel "
        "centres (Bresenham, Pillow), which pass by default; --line-rule geometry judges the geometry only",
    ),
    FaultKind(
        "line_pixel_bias",
        "line_count",
        "pixels",
        "the vertices agree but the candidate draws systematically more (or fewer) line pixels "
        "than the oracle along the lines: check the line width (1 px) and the rounding of the "
        "minor coordinate (nearest pixel centre)",
        shown=(("candidate_only", "candidate_only"), ("oracle_only", "oracle_only")),
    ),
    FaultKind(
        "raster_rule",
        "line_rule",
        "pixels",
        "the lines are where the oracle's are but their pixels follow another aliased line rule than "
        "GL's (Pillow's, TinyGL's: ends snapped to pixel centres, another choice across the line): check "
        "the line rasteriser, not the camera; without --line-rule gl a correct drawing with ends rounded to "
        "pixel centres passes, and --line-rule geometry judges the geometry only",
    ),
    FaultKind(
        "precision_limited",
        "precision",
        "vertices",
        "the error is the size of float32 rounding, not a convention error: compute in "
        "float64 or declare float32 (--candidate-precision float32)",
        shown=(("residual_px", "residual_px"),),
    ),
    FaultKind(
        "unexplained",
        "unexplained",
        "any",
        "not a simple image-space fault: check the rotation order, a transposed "
        "world-to-camera matrix, the up vector (roll) and the near/far test",
        cell="which kind, in a few words (nothing drawn, the sets that differ, the residual and rotation)",
        hints=MappingProxyType(
            {
                "visible_sets": "the pixels agree (residual {residual:.2g} px <= the {tol:.2g} px bound); only the "
                "visible sets differ: {candidate_only} points shown only by the candidate, "
                "{oracle_only} only by the oracle. " + _NEAR_FAR + "and any visibility or raster "
                "step, not the rotation",
                "drawn_sets": "{where}; only the drawn sets differ: {candidate_only} pixels drawn only by the candidate, "
                "{oracle_only} only by the oracle (no pixel of the other within {near:g} px). "
                + _NEAR_FAR
                + "and any visibility or raster step, not the rotation",
                "dim_lines": "the frames hold lines, at level {level} of 255 (luminance x alpha / 255), under the "
                "{drawn} from which a pixel counts as drawn: nothing was drawn by the rule. Draw the "
                "lines white and opaque (a grey colour or a partial alpha dims them)",
                "depth": "the depth differs from the reference in no way this diagnosis knows: see what was measured "
                "(fit_ratios: each model's worst residual over its allowance)",
                "silhouettes": "the silhouette differs from the reference in no way this diagnosis knows (a roll, a "
                "wrong pose, missing faces): see what was measured (fit_ratios: each camera mistake's "
                "missed pixels per boundary pixel)",
                "points": "the points differ from the exact inverse in no way this diagnosis knows: see what was "
                "measured (the median pixel shift, scale and depth ratio)",
            }
        ),
    ),
)

#: Every fault name's entry, in precedence order (the primary fault first).
CATALOGUE: Mapping[str, FaultKind] = MappingProxyType({k.name: k for k in _KINDS})
#: Every fault name, in precedence order.
NAMES = tuple(CATALOGUE)
_ORDER = {name: i for i, name in enumerate(NAMES)}


def kind(name: str) -> FaultKind:
    """The catalogue's entry of ``name``; KeyError naming the catalogue for a name it does not hold."""
    try:
        return CATALOGUE[name]
    except KeyError:
        raise KeyError(f"fault {name!r} is not in the catalogue (oracles.faults.CATALOGUE)") from None


def family(name: str) -> str:
    return kind(name).family


def names(*families: str, source: str | None = None) -> tuple[str, ...]:
    """The names of ``families`` (all when none given), read from ``source`` when given (one of its
    :attr:`FaultKind.sources`), in precedence order."""
    unknown = set(families) - set(FAMILIES)
    if unknown:
        raise KeyError(f"families {sorted(unknown)}: expected among {', '.join(FAMILIES)}")
    if source is not None and source not in SOURCES:
        raise KeyError(f"source {source!r}: expected one of {', '.join(SOURCES)}")
    return tuple(
        k.name for k in _KINDS if (not families or k.family in families) and (source is None or source in k.sources)
    )


def precedence(name: str) -> int:
    return kind(name).precedence


def ordered(faults: Iterable[Mapping]) -> list:
    """``faults`` (dicts or :class:`Fault`) sorted by precedence, the primary fault first (a stable sort)."""
    return sorted(faults, key=lambda f: precedence(f["name"] if isinstance(f, Mapping) else f.name))


def hint_text(name: str, which: str, **values: Any) -> str:
    """The hint ``which`` of fault ``name`` (its ``hints``), filled with ``values``."""
    return kind(name).hints[which].format(**values)


@dataclass(frozen=True)
class Fault:
    """One fault as named: its ``name`` and ``params`` (the fields after the name, in record order:
    a per-fault ``hint`` or ``note`` among them), read through the catalogue; ``source``: where it was
    read when that selects its hint (``"depth"``, ``"points"``: :meth:`FaultKind.hint_for`), not part
    of the record."""

    name: str
    params: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    source: str | None = None

    def __post_init__(self):
        kind(self.name)  # a name outside the catalogue is a bug
        if self.source is not None and self.source not in SOURCES:
            raise KeyError(f"source {self.source!r}: expected one of {', '.join(SOURCES)}")
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))

    @classmethod
    def of(cls, record: Mapping, source: str | None = None) -> Fault:
        """A record's fault dict (``{"name": ..., ...}``) as a Fault, read from ``source``."""
        return cls(record["name"], {k: v for k, v in record.items() if k != "name"}, source)

    def as_dict(self) -> dict:
        """The record form, as report.json holds it: the name first, then the params in order."""
        return {"name": self.name, **self.params}

    @property
    def kind(self) -> FaultKind:
        return CATALOGUE[self.name]

    @property
    def family(self) -> str:
        return self.kind.family

    @property
    def precedence(self) -> int:
        return self.kind.precedence

    @property
    def hint(self) -> str:
        """What to check: the fault's own ``hint`` (set where its values say more) or its name's, for its source."""
        return self.params.get("hint") or self.kind.hint_for(self.source)

    def shown(self, limit: int = 2) -> list[tuple[str, str, Any]]:
        """``(field, label, value)`` of the first ``limit`` of the catalogue's shown fields this fault has
        (not None): the key numbers of its table cell (formatted by oracles.reports.fault_text.cell)."""
        return [(key, label, self.params[key]) for key, label in self.kind.shown if self.params.get(key) is not None][
            :limit
        ]

    @property
    def note(self) -> str | None:
        """What the naming step adds about this fault in words (a measured end, a rule), if anything."""
        return self.params.get("note")


def markdown_table() -> str:
    """docs/diagnosis.md's table of names: family, sources, what a cell shows, what to check (precedence order;
    a further source's hint after the name's own, as *depth maps:* ...)."""
    rows = ["| fault | family | read from | a cell shows | what to check |", "|---|---|---|---|---|"]
    for k in _KINDS:
        shown = ", ".join(f"`{f}`" + (f" as `{label}`" if label not in ("", f) else "") for f, label in k.shown)
        hint = " <br>".join([k.hint] + [f"*{SOURCES[s]}:* {k.hints[s]}" for s in k.sources[1:]]).replace("|", "\\|")
        rows.append(f"| `{k.name}` | {k.family} | {', '.join(k.sources)} | {k.cell or shown or 'the name'} | {hint} |")
    return "\n".join(rows)

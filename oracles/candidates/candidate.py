"""The candidate contract: any projector crosscheck can judge.

``FUNC(points, camera) -> ndarray (N, 2)``

- ``points``: ``(N, 3)`` float64 world coordinates.
- ``camera``: an object with ``position`` (3,), ``forward`` (3,) unit, ``up``
  (3,) unit and orthogonal to forward, ``fov_y_deg``, ``width``, ``height``,
  ``near``, ``far``, ``projection`` ("perspective" or "orthographic") and
  ``ortho_height`` (world units visible vertically; orthographic only),
  ``intrinsics`` (``(fx, fy, cx, cy)`` or None) and ``distortion`` (OpenCV's
  coefficients or None); and, built from those, ``K`` (3x3), ``R``, ``t``
  (world -> OpenCV camera: ``p_cv = R @ X + t``), ``view_matrix`` and
  ``projection_matrix`` (OpenGL) -- a :class:`core.camera.Camera`.
- returns pixel coordinates in the project's pixel convention (x right, y down,
  integer coordinates at pixel centres; core/conventions.py), NaN rows for the
  points it clips (depth outside [near, far]).

The candidate's precision (oracles.tolerances.PRECISIONS) is inferred from
the dtype of the array it returns: ``float32`` (or ``float16``) means float32,
anything else float64. A program over the candidate protocol says it in its
reply (docs/protocol.md). A precision declared by the user
(``--candidate-precision``) wins over the inferred one
(:func:`case_precision`).

Given as ``--candidate FILE.py:FUNC`` or ``--candidate MODULE:FUNC``.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.machinery
import importlib.util
import inspect
import sys
import warnings
from pathlib import Path

import numpy as np
from wirecheck.core.errors import InputError
from wirecheck.core.user_files import expected, problem, read_regular


@contextlib.contextmanager
def _candidate_imports(folder: str | None = None):
    """While wirecheck imports or calls a candidate it loaded: no bytecode written, and ``folder`` importable.

    The candidate's folder (and its package's) are the user's, and wirecheck
    changes nothing it did not write (Python would add ``__pycache__`` beside
    each source it imports, at load or lazily inside a call). A ``FILE.py``
    candidate's own folder is importable, as when running a script, only
    meanwhile: left first on ``sys.path``, its ``helper.py`` or ``utils.py``
    would shadow the caller's own modules of those names after the check.
    """
    before = sys.dont_write_bytecode
    sys.dont_write_bytecode = True
    added = folder is not None and folder not in sys.path
    if added:
        sys.path.insert(0, folder)
    try:
        yield
    finally:
        sys.dont_write_bytecode = before
        if added and folder in sys.path:
            sys.path.remove(folder)


class _RegularSourceLoader(importlib.machinery.SourceFileLoader):
    """Python's source loader, reading the candidate's file through core.user_files (never blocking, limited)."""

    def get_data(self, path):
        if path == self.path:
            return read_regular(path, "candidate")
        return super().get_data(path)


class _Loaded:
    """A candidate :func:`load_candidate` imported: each call inside :func:`_candidate_imports` (its folder)."""

    def __init__(self, func, folder: str | None):
        self.func, self.folder = func, folder

    def __call__(self, *args):
        with _candidate_imports(self.folder):
            return self.func(*args)

    def __repr__(self) -> str:
        return repr(self.func)


def load_candidate(spec: str, option: str = "--candidate", params: tuple = ("points", "camera")):
    """Resolve ``FILE.py:FUNC`` or ``MODULE:FUNC`` to a callable; InputError otherwise.

    The callable calls the candidate as :func:`_candidate_imports` says (its
    folder importable meanwhile, no bytecode written). ``option`` names the option
    in messages; ``params`` are the contract's arguments (an unprojector's are
    ``("pixels", "depth", "camera")``).
    """
    if ":" not in spec:
        raise InputError(f"{option} {spec!r}: expected FILE.py:FUNC or MODULE:FUNC")
    target, func_name = spec.rsplit(":", 1)
    folder = None
    if target.endswith(".py") or "/" in target:
        path = Path(target)
        refused = problem(path, "candidate")
        if refused == "missing":
            raise InputError(f"{option} {spec!r}: file {target!r} not found")
        if refused is not None:  # a FIFO, a device, a folder: never opened (reading it could block forever)
            raise InputError(f"{option} {spec!r}: {target}: {refused}: expected {expected('candidate')}")
        mod_name = f"wirecheck_candidate_{path.stem}"
        folder = str(path.resolve().parent)  # like running a script: the candidate's own folder is importable
        try:
            with _candidate_imports(folder):
                module_spec = importlib.util.spec_from_file_location(
                    mod_name, path, loader=_RegularSourceLoader(mod_name, str(path))
                )
                module = importlib.util.module_from_spec(module_spec)
                sys.modules[mod_name] = module
                module_spec.loader.exec_module(module)
        except (Exception, SystemExit) as exc:  # the user's file: report, don't trace back, don't exit
            raise InputError(f"{option} {spec!r}: importing {target} failed: {type(exc).__name__}: {exc}") from None
    else:
        try:
            with _candidate_imports():
                module = importlib.import_module(target)
        except (Exception, SystemExit) as exc:
            raise InputError(
                f"{option} {spec!r}: importing module {target!r} failed: {type(exc).__name__}: {exc}"
            ) from None
    func = getattr(module, func_name, None)
    if not callable(func):
        raise InputError(f"{option} {spec!r}: {target} has no callable {func_name!r}")
    try:
        inspect.signature(func).bind(*(None,) * len(params))
    except TypeError:
        call = f"{func_name}({', '.join(params)})"
        raise InputError(
            f"{option} {spec!r}: {func_name}{inspect.signature(func)} cannot be called as "
            f"{call}: expected the contract FUNC({', '.join(params)})"
        ) from None
    except ValueError:  # builtins without a signature: find out when called
        pass
    return _Loaded(func, folder)


class CandidateError(RuntimeError):
    """The candidate raised or returned something outside the contract."""


#: Array kinds that numpy casts to float64 but that are not pixel coordinates.
_KINDS = {"b": "booleans", "U": "strings", "S": "bytes", "M": "datetimes", "m": "time deltas", "V": "records"}


def _as_pixels(out) -> np.ndarray:
    """The answer as a float64 array, or CandidateError: never a warning, never a silent cast.

    Complex values (numpy would drop the imaginary part with a ComplexWarning),
    booleans, strings, datetimes and records (numpy would cast them to numbers),
    integers too large for a float, and objects whose ``__array__`` or
    ``__float__`` raise are contract violations.
    """
    what = type(out).__name__
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            arr = np.asarray(out)
            if arr.dtype.kind == "c":
                raise CandidateError(
                    f"candidate returned complex numbers ({arr.dtype}): expected an (N, 2) real float array"
                )
            if arr.dtype.kind in "bUSMmV":  # would cast to numbers that are not pixels (True: 1.0, "3": 3.0)
                raise CandidateError(
                    f"candidate returned an array of {arr.dtype} ({_KINDS[arr.dtype.kind]}): "
                    "expected an (N, 2) float array"
                )
            return arr.astype(np.float64)
    except CandidateError:
        raise
    except Exception as exc:  # OverflowError, a raising __array__/__float__, ragged lists, warnings
        raise CandidateError(
            f"candidate returned {what} that is not an array of floats "
            f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]}): "
            "expected an (N, 2) float array"
        ) from exc


def returned_precision(out) -> str:
    """The precision an answer's dtype shows: ``"float32"`` for float32 (or float16), else ``"float64"``."""
    dtype = getattr(out, "dtype", None)
    return "float32" if dtype is not None and dtype.kind == "f" and dtype.itemsize <= 4 else "float64"


def case_precision(declared: str | None, returned: set) -> tuple[str, str]:
    """``(precision, source)`` a case is judged at.

    ``declared`` (the user's ``--candidate-precision``) wins; else float32 when
    any answer of the case was float32 (``returned``: the precisions seen),
    else float64. ``source`` is ``"declared"``, ``"returned"`` or ``"default"``
    (nothing returned yet, e.g. the candidate failed at once).
    """
    if declared is not None:
        return declared, "declared"
    if not returned:
        return "float64", "default"
    return ("float32" if "float32" in returned else "float64"), "returned"


def call_candidate(func, points: np.ndarray, camera) -> np.ndarray:
    """Call the candidate and check its answer against the contract."""
    return call_candidate_precision(func, points, camera)[0]


def call_candidate_precision(func, points: np.ndarray, camera) -> tuple[np.ndarray, str]:
    """:func:`call_candidate`, and the precision of the answer (:func:`returned_precision`).

    A candidate with ``answer_precision()`` (a program over the protocol,
    oracles.candidates.subprocess_candidate) says its own, the wire being float64.
    """
    try:
        out = func(np.array(points, dtype=np.float64, copy=True), camera)
    except CandidateError:  # an isolated candidate's own one-line reason
        raise
    except (Exception, SystemExit) as exc:  # a candidate must not end the run (nor pass CI by exiting 0)
        raise CandidateError(f"candidate raised {type(exc).__name__}: {exc}") from exc
    told = getattr(func, "answer_precision", None)
    precision = told() if callable(told) else returned_precision(out)
    out = _as_pixels(out)
    if len(points) == 0 and out.shape == (0,):  # [] from a list-of-lists projector: no points, no pixels
        out = out.reshape(0, 2)
    if out.shape != (len(points), 2):
        raise CandidateError(f"candidate returned shape {out.shape}: expected ({len(points)}, 2)")
    infinite = np.isinf(out).any(axis=1)
    if infinite.any():
        k = int(np.flatnonzero(infinite)[0])
        raise CandidateError(
            f"candidate returned {out[k].tolist()} for point {k} {np.asarray(points)[k].tolist()}: "
            "expected finite pixel coordinates, or NaN for a clipped point"
        )
    half = np.isnan(out).any(axis=1) & ~np.isnan(out).all(axis=1)
    if half.any():
        k = int(np.flatnonzero(half)[0])
        raise CandidateError(
            f"candidate returned {out[k].tolist()} for point {k}: expected both coordinates "
            "NaN (clipped) or both finite"
        )
    return out, precision
